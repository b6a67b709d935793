//! A conversion's inputs ([`Job`]) and the rules on what it may read and write.

use crate::error::Result;
use crate::storage::Storage;
use crate::Options;
use specconv_atomic_file::Replace;
use specconv_ocio::Config;
use specconv_spectral::stack::Stack;
use specconv_spectral::Method;
use std::path::Path;
use std::sync::atomic::AtomicBool;

/// A conversion: one input, one output.
pub struct Job<'a> {
    /// The image to read.
    pub input: &'a Path,
    /// The spectral OpenEXR to write.
    pub output: &'a Path,
    /// The OCIO config the input's colour is managed with.
    pub config: &'a Config,
    /// The method stack that uplifts every pixel.
    pub stack: &'a Stack,
    /// What the conversion is asked to do.
    pub options: &'a Options,
    /// How the spectra are stored.
    pub storage: &'a Storage,
    /// Write over an existing output (the options', or a batch's update of its own output).
    pub overwrite: bool,
    /// Set from another thread (a signal handler) to stop the job.
    pub cancel: &'a AtomicBool,
}

impl Job<'_> {
    /// The method every pixel is uplifted with.
    pub(crate) fn method(&self) -> &dyn Method {
        self.stack.method()
    }

    /// Values a pixel of the output holds beside alpha: bands, or a compact texel's.
    pub(crate) fn values(&self) -> usize {
        self.storage.values(self.method().grid().len())
    }

    /// The tile size, or `None` for scanlines.
    pub(crate) fn tile(&self) -> Option<(usize, usize)> {
        match self.options.blocks {
            specconv_description::Blocks::Tiles(w, h) => Some((w, h)),
            specconv_description::Blocks::Scanlines => None,
        }
    }
}

/// Refuses a special file as input (before anything probes it), writing over the input, and
/// over an existing output unless asked to: the rules every writer shares
/// (specconv_atomic_file::plan).
pub(crate) fn refuse_overwrites(input: &Path, output: &Path, overwrite: bool) -> Result<()> {
    specconv_atomic_file::readable_file(input)?;
    Ok(specconv_atomic_file::check_plan(
        &[input],
        &[output],
        Replace::when(overwrite),
    )?)
}
