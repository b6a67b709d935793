//! Reading inputs and writing outputs safely: an output is written to a temporary file beside
//! it and renamed into place, so a failed run leaves no partial file.

use anyhow::Result;
use specconv_atomic_file::Replace;
use specconv_colour::SpectralTable;
use specconv_convert_cmd::errors::{explain, usage};
use std::path::Path;

/// Reads a spectra CSV file (the library's reader).
pub fn read_spectra(path: &Path) -> Result<SpectralTable> {
    Ok(specconv_conversion::models::read_spectra(path)?)
}

/// Refuses an output that is `-` (no command writes to standard output) or whose extension is
/// not one of `extensions` (the library's rule, [`specconv_atomic_file::check_extension`]);
/// `what` says what the command writes, e.g. "to-rgb writes OpenEXR". A usage error (exit
/// status 2): nothing was read or written.
pub fn check_output(
    path: &Path,
    extensions: &'static [&'static str],
    what: &'static str,
) -> Result<()> {
    specconv_atomic_file::check_extension(path, extensions, what)
        .map_err(|e| usage(anyhow::Error::new(e)))
}

/// Refuses, before any work, an output that may not be written by a command reading `inputs`
/// (the library's rules: never an input, in an existing directory, an existing file only
/// with `replace`): a usage error.
pub fn check_writable(output: &Path, inputs: &[&Path], replace: Replace) -> Result<()> {
    specconv_atomic_file::check_plan(inputs, &[output], replace)
        .map_err(|e| usage(anyhow::anyhow!(explain(&e.into()))))
}

/// The OpenEXR a command makes of one input (`what`: why it must end in .exr): its name, and
/// that it may be written (`force` replaces an existing one, never the input).
pub fn check_exr_output(
    output: &Path,
    input: &Path,
    force: bool,
    what: &'static str,
) -> Result<()> {
    check_output(output, specconv_conversion::plan::SPECTRAL_EXTENSIONS, what)?;
    check_writable(output, &[input], Replace::when(force))
}

/// Writes `bytes` to `path` atomically under the same rules, checked again at the write.
pub fn write_atomically(
    path: &Path,
    bytes: &[u8],
    inputs: &[&Path],
    replace: Replace,
) -> Result<()> {
    use specconv_atomic_file::WriteError;
    specconv_atomic_file::write_checked(path, bytes, inputs, replace).map_err(|e| match e {
        WriteError::Plan(p) => anyhow::anyhow!(explain(&p.into())),
        io => anyhow::Error::new(io),
    })
}

/// The model from `--model FILE`, or the built-in one. A model that cannot be read is a
/// usage error: nothing can be done with it.
pub fn load_model(path: Option<&Path>) -> Result<specconv_spectral::Model> {
    specconv_conversion::models::load(path).map_err(usage)
}

/// Why a trained model has fewer clusters than were asked for; `None` when it has them all.
/// Training stops when no leaf has a split that lowers the error with both sides of at least
/// `min_cluster_size` spectra, three real components and M's condition within `max_condition`
/// (specconv_spectral::train); which of these stopped it shows in the leaves' sizes.
pub fn fewer_clusters(m: &specconv_spectral::Model) -> Option<String> {
    let t = &m.training;
    if m.leaves.len() >= t.clusters_requested {
        return None;
    }
    let splittable = m
        .leaves
        .iter()
        .filter(|l| l.count >= 2 * t.min_cluster_size)
        .count();
    let why = if splittable == 0 {
        format!(
            "every cluster has fewer than 2 × --min-cluster-size {} = {} spectra, so none can be split; \
             give more spectra or lower --min-cluster-size",
            t.min_cluster_size,
            2 * t.min_cluster_size
        )
    } else {
        format!(
            "no split of the {splittable} cluster{} of at least {} spectra lowers the error with both sides \
             of at least --min-cluster-size {}, three principal components and the condition of M within \
             --max-condition {}; add more varied spectra or relax those bounds",
            if splittable == 1 { "" } else { "s" },
            2 * t.min_cluster_size,
            t.min_cluster_size,
            t.max_condition
        )
    };
    Some(format!(
        "{} clusters asked for, {} grown: {why}",
        t.clusters_requested,
        m.leaves.len()
    ))
}
