//! A job's input opened and checked ([`open`]), then every pixel uplifted and the output
//! written ([`Opened::write`]).

use crate::attributes::{average_text, windows_of, AVERAGE, CONSTANT};
use crate::choices::Mip;
use crate::colour::{self, texture_space, InputSpace};
use crate::error::{Error, Result};
use crate::job::{refuse_overwrites, Job};
use crate::report::{Report, Role};
use crate::storage::{COMPACT_ATTRIBUTE, EXPAND_ATTRIBUTE, LAYOUT_ATTRIBUTE};
use crate::uplift::Reading;
use crate::write::write_file;
use crate::{expand, input, metadata, png, survey, texture};
use specconv_exr::{Blocks, Spec, SpectralFile};
use std::path::Path;

/// An input opened for a job: the output may be written, the input's header is sound, its
/// channels and colour space are chosen. Nothing is written yet.
pub struct Opened<'a> {
    job: &'a Job<'a>,
    reader: specconv_oiio::ImageReader,
    info: specconv_oiio::ImageInfo,
    selection: input::Selection,
    space: InputSpace,
    premultiply: bool,
    /// The wrap modes, and whether the input declared them.
    wrap: (texture::WrapModes, bool),
    survey: survey::Survey,
    /// The input's metadata the output carries and what it drops (none when stripped).
    metadata: metadata::Carry,
}

/// Opens `job`'s input: refuses to write over the input or an existing output (unless the
/// settings allow it), checks an OpenEXR input's header, chooses channels and colour space.
pub fn open<'a>(job: &'a Job<'a>) -> Result<Opened<'a>> {
    refuse_overwrites(job.input, job.output, job.overwrite)?;
    specconv_exr::check::check_input(job.input)?;
    png::check_whole(job.input)?;
    let (reader, selection) = input::open(job.input, &input::Request::of(job.options))?;
    let info = reader.info().clone();
    let space = match texture_space(
        job.config,
        &reader,
        &selection,
        job.options.colorspace.as_deref(),
    ) {
        // A data texture to be copied meets a conversion's rule on NaN and infinities: every
        // channel surveyed as a conversion's are, before anything is written.
        Err(Error::Data(data))
            if job.options.data == crate::DataPolicy::Copy
                && job.options.non_finite != crate::NonFinite::Keep =>
        {
            let mut reader = reader;
            let every: Vec<usize> = (0..reader.info().channels.len()).collect();
            survey::survey(job.into(), &mut reader, (&every, None))?;
            return Err(Error::Data(data));
        }
        other => other?,
    };
    if let (true, Some(w)) = (job.options.strict, space.warnings.first()) {
        return Err(Error::Strict {
            input: job.input.to_path_buf(),
            warning: w.to_string(),
        });
    }
    let premultiply = colour::premultiply(job.options.alpha, &reader, selection.channels.alpha);
    let declared = texture::declared(&reader);
    let metadata = match job.options.strip_metadata {
        true => metadata::Carry::default(),
        false => texture::metadata(&reader, job.input)?,
    };
    if job.options.strict && !metadata.dropped.is_empty() {
        return Err(Error::Strict {
            input: job.input.to_path_buf(),
            warning: metadata::describe(&metadata.dropped),
        });
    }
    let wrap = match (job.options.wrap, declared) {
        (Some(w), _) => (w, false),
        (None, Some(w)) => (w, true),
        (None, None) => (texture::DEFAULT_WRAP, false),
    };
    let mut reader = reader;
    let survey = survey::survey(
        job.into(),
        &mut reader,
        (&selection.channels.colour, selection.channels.alpha),
    )?;
    Ok(Opened {
        job,
        reader,
        info,
        selection,
        space,
        premultiply,
        wrap,
        survey,
        metadata,
    })
}

impl Opened<'_> {
    /// The colour space the input is read in (the config's name, or a description).
    pub fn colorspace(&self) -> &str {
        &self.space.name
    }

    /// Uplifts every pixel and writes the output with `attributes` in its header (the caller's
    /// provenance). `progress` hears (pixels done, pixels in all) after every window.
    pub fn write(
        self,
        attributes: &[(String, String)],
        progress: &mut dyn FnMut(u64, u64),
    ) -> Result<Report> {
        let Opened {
            job,
            mut reader,
            info,
            selection,
            space,
            premultiply,
            wrap,
            survey,
            metadata,
        } = self;
        // The caller's attributes first; the input's metadata where they name nothing.
        let mut attributes = attributes.to_vec();
        let metadata_dropped = metadata.dropped;
        for (name, value) in metadata.kept {
            if !attributes.iter().any(|(n, _)| *n == name) {
                attributes.push((name, value));
            }
        }
        let dropped = job.options.opaque_detect && survey.opaque;
        let alpha = selection.channels.alpha.filter(|_| !dropped);
        let constant = survey
            .constant
            .as_deref()
            .filter(|_| job.options.constant_detect && job.tile().is_some());
        let (file, source) = output_file(
            job,
            &info,
            (alpha.is_some(), constant.is_some()),
            &attributes,
            wrap.0,
            &survey,
        )?;
        let reading = Reading {
            to_xyz: &space.to_xyz,
            colour: &selection.channels.colour,
            alpha,
            premultiply: premultiply && alpha.is_some(),
            repair: &survey.repair,
        };
        let (total, counts) = write_file(
            job,
            (&file, source),
            &mut reader,
            &reading,
            constant,
            progress,
        )?;
        let levels = file.levels();
        let stack = job.stack;
        Ok(Report {
            role: if selection.channels.colour.len() == 1 {
                Role::Achromatic
            } else {
                Role::Colour
            },
            data: None,
            width: info.width() as usize,
            height: info.height() as usize,
            pixels: total,
            levels,
            wrap: job.tile().map(|_| wrap),
            non_finite_input: (survey.non_finite, survey.repaired),
            constant: constant.is_some(),
            opaque_dropped: dropped,
            source_hash: survey.hash.clone(),
            bands: stack.method().grid().len(),
            selection,
            colorspace: space.name,
            colorspace_rule: space.rule,
            warnings: space.warnings,
            metadata_dropped,
            premultiplied: premultiply && alpha.is_some(),
            non_finite: counts.non_finite,
            above_one: counts.above_one,
            saturated: counts.saturated,
            clamped: counts.clamped,
            filter: (levels > 1 || job.options.resize).then_some(job.options.filter),
            bounded: stack.counts_bounded().then_some(counts.tally.bounded),
            unmatched: stack.emissive().map(|_| counts.tally.unmatched),
            // The converter times the whole call.
            seconds: 0.0,
        })
    }
}

/// The output's description: its size and windows, bands, blocks and levels, with
/// `attributes`, the texture's and what the survey found; and the size of the spectra level 0
/// is made of (the input's, or a constant texture's tile). `(alpha, constant)`: whether alpha
/// is written, and whether the texture is written as one tile of its constant colour.
fn output_file(
    job: &Job,
    info: &specconv_oiio::ImageInfo,
    (alpha, constant): (bool, bool),
    attributes: &[(String, String)],
    wrap: texture::WrapModes,
    survey: &survey::Survey,
) -> Result<(SpectralFile, (usize, usize))> {
    // Every tiled output is a MIP map made from its own spectra (module `mip`); the input's
    // smaller levels, if any, are not read.
    let blocks = match job.tile() {
        None => Blocks::Scanlines,
        Some((width, height)) => Blocks::Tiles {
            width,
            height,
            mip_levels: job.options.mip == Mip::All,
        },
    };
    let top = info.levels[0];
    let (mut width, mut height) = (info.width() as usize, info.height() as usize);
    let mut windows = windows_of(&top);
    if let (true, Some((tw, th))) = (constant, job.tile()) {
        // One tile, as maketx --constant-color-detect: the display window is the data
        // window, so that lookups over [0, 1] read it all.
        (width, height) = (width.min(tw), height.min(th));
        windows.display = (top.x, top.y, width, height);
    }
    let source = (width, height);
    if job.options.resize {
        // maketx --resize: each size up to a power of two, and the texture spans it.
        (width, height) = (width.next_power_of_two(), height.next_power_of_two());
        windows.display = (windows.display.0, windows.display.1, width, height);
    }
    // A tiled output is a texture: its wrap modes and format, as maketx writes them.
    let (mut extra, fovcot) = match blocks {
        Blocks::Tiles { .. } => (
            texture::attributes(wrap),
            vec![(
                "fovcot".to_string(),
                texture::fovcot(windows.display.2, windows.display.3),
            )],
        ),
        Blocks::Scanlines => (Vec::new(), Vec::new()),
    };
    extra.push((survey::SOURCE_HASH.to_string(), survey.hash.clone()));
    if let Some(compact) = &job.storage.compact {
        extra.push((
            LAYOUT_ATTRIBUTE.into(),
            specconv_spectral::compact::VERSION.into(),
        ));
        extra.push((COMPACT_ATTRIBUTE.into(), compact.to_text()));
        extra.push((EXPAND_ATTRIBUTE.into(), expand::settings(job.options)));
    }
    let spec = Spec {
        width,
        height,
        windows: Some(windows),
        wavelengths: match &job.storage.compact {
            Some(_) => (1..=job.values()).map(|i| i as f64).collect(),
            None => job.method().grid().wavelengths(),
        },
        kind: job.storage.kind.clone(),
        alpha,
        sample: job.options.sample,
        compression: job.options.compression.exr(),
        zip_level: job
            .options
            .zip_level
            .unwrap_or(specconv_exr::zip::DEFAULT_LEVEL),
        blocks,
        attributes: attributes.iter().cloned().chain(extra).collect(),
        float_attributes: fovcot,
    };
    // The average of each channel, known once level 0 is made: its place kept here, its
    // value written then (`average_attributes`).
    let mut spec = spec;
    let placeholder = average_text(&vec![0.0; usize::from(alpha) + spec.wavelengths.len()]);
    spec.attributes.push((AVERAGE.into(), placeholder.clone()));
    if constant {
        spec.attributes.push((CONSTANT.into(), placeholder));
    }
    Ok((SpectralFile::new(spec)?, source))
}

/// The hash of `input`'s full-resolution pixels in the subimage `request` names, as
/// conversions record it ([`survey::Survey::hash`]).
pub fn source_hash(input: &Path, request: &input::Request) -> Result<String> {
    specconv_atomic_file::readable_file(input)?;
    let (mut reader, _) = input::open(input, request)?;
    survey::source_hash(&mut reader)
}
