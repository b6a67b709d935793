//! [`Converter`]: options checked once, then any number of conversions, each with its own
//! [`Report`].

use crate::error::{ConversionError, Error};
use crate::options::{settings_tag, Blocks, DataPolicy, Layout, Options, Resolved};
use crate::pipeline::{Job, Storage};
use crate::plan::Pair;
use crate::provenance::{recorded, Provenance};
use crate::report::{DataOutcome, Report, Role};
use specconv_atomic_file::outputs::Holds;
use specconv_colour::EmissionUnits;
use specconv_exr::Sample;
use specconv_ocio::Config;
use specconv_spectral::compact::Compact;
use specconv_spectral::stack::Stack;
use specconv_spectral::Model;

/// The most worker threads a converter starts: far more than any machine's cores, so a typo
/// (`-j 100000`) is refused instead of starting a hundred thousand threads.
pub const MAX_THREADS: usize = 1024;
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;
use std::time::Instant;

pub use crate::pipeline::in_memory::{Image as InMemory, Samples, Texels};
pub use crate::pipeline::input::Selection;
pub use crate::pipeline::{Rule, Warning};

/// A conversion set up once: the config loaded, the colour space checked, the model loaded and
/// the method built. Every call of [`Converter::convert`] is independent: the same input gives
/// the same bytes, whatever was converted before or at the same time.
///
/// ```no_run
/// use specconv_conversion::{Converter, Options};
/// let converter = Converter::new(Options::default())?;
/// let report = converter.convert("albedo.png".as_ref(), "albedo_spectral.exr".as_ref())?;
/// println!("{} pixels in {}", report.pixels, report.colorspace);
/// # Ok::<(), specconv_conversion::Error>(())
/// ```
pub struct Converter {
    options: Options,
    config: Config,
    model: Model,
    model_description: String,
    stack: Stack,
    storage: Storage,
    provenance: Provenance,
    pool: Option<rayon::ThreadPool>,
    config_notes: Vec<String>,
}

impl Converter {
    /// Checks `options` and sets everything up that does not depend on an input: the worker
    /// threads, the OCIO config and the named colour space's route to XYZ, the model, the
    /// method stack, the output's settings and provenance.
    pub fn new(options: Options) -> Result<Converter, Error> {
        if let Some(level) = options.zip_level {
            if !options.compression.deflates() {
                return Err(Error::ZipLevelWithoutZip {
                    compression: options.compression,
                });
            }
            if level > 9 {
                return Err(Error::ZipLevel { level });
            }
        }
        if let Blocks::Tiles(width, height) = options.blocks {
            if width == 0 || height == 0 {
                return Err(Error::EmptyTile { width, height });
            }
        }
        let pool = match options.threads {
            Some(0) => return Err(Error::NoThreads),
            Some(n) if n > MAX_THREADS => {
                return Err(Error::TooManyThreads {
                    threads: n,
                    limit: MAX_THREADS,
                    cores: std::thread::available_parallelism().map_or(1, |c| c.get()),
                })
            }
            Some(n) => Some(
                rayon::ThreadPoolBuilder::new()
                    .num_threads(n)
                    .build()
                    .map_err(|e| Error::Threads(e.to_string()))?,
            ),
            None => None,
        };
        let config = Config::resolve(options.ocio.as_deref())?;
        if let Some(name) = options.colorspace.as_deref() {
            let cs = config.color_space(name)?;
            // A data space names data textures, which the data policy takes care of, unless
            // every input would fail.
            if !cs.is_data || options.data == DataPolicy::Fail {
                config.processor_to_xyz(&cs.name)?;
            }
        }
        let model = crate::models::load(options.model.as_deref())?;
        let tables = crate::tables::in_dir(options.table_dir.clone(), crate::tables::print_note);
        let spec = options.stack_spec();
        let build = || Stack::build(&spec, &model, &tables);
        let stack = match &pool {
            Some(pool) => pool.install(build),
            None => build(),
        }?;
        // Alpha counted in: refused here, before any input, not at the first one with alpha.
        specconv_exr::check_channels(stack.method().grid().len(), true)?;
        if let Blocks::Tiles(width, height) = options.blocks {
            let channels = stack.method().grid().len() + 1;
            specconv_exr::check_block(width, height, channels, options.sample)?;
            let threads = pool
                .as_ref()
                .map_or_else(rayon::current_num_threads, |p| p.current_num_threads());
            check_memory(width * height, channels, threads)?;
        }
        let model_description = crate::models::describe(options.model.as_deref(), &model);
        let compact = compact(&options, &model, &model_description)?;
        let storage = Storage::of(&options, &stack, compact);
        let provenance = Provenance {
            model: Some(model_description.clone()),
            model_attribution: crate::models::attribution(&model),
            commercial: Some(model.training.commercial().to_string()),
            method: Some(stack.method().name().to_string()),
            blend: Some(stack.blend().to_string()),
            observer: Some(model.observer),
            illuminant: Some(model.illuminant),
            settings: Some(settings_tag(
                &options,
                Resolved {
                    model: &model_description,
                    method: stack.method().name(),
                    blend: stack.blend(),
                    config: &config.source().to_string(),
                },
            )),
            emission_units: stack.emission().map(|e| e.units),
            version: Some(env!("CARGO_PKG_VERSION").to_string()),
            ..Provenance::default()
        };
        Ok(Converter {
            options,
            config,
            model,
            model_description,
            stack,
            storage,
            provenance,
            pool,
            config_notes: config_notes(specconv_ocio::take_log()),
        })
    }

    /// The files a conversion reads besides its inputs: the model file ([`crate::models::file_read`],
    /// the site default's too) and the OCIO config file (`--ocio FILE`, `$OCIO`). A batch counts
    /// them among its inputs, so no output, even with `overwrite`, replaces one.
    pub fn files_read(&self) -> Vec<PathBuf> {
        let config = match self.config.source() {
            specconv_ocio::ConfigSource::File(p) | specconv_ocio::ConfigSource::Env(p) => {
                Some(p.clone())
            }
            _ => None,
        };
        crate::models::file_read(self.options.model.as_deref())
            .into_iter()
            .chain(config)
            .collect()
    }

    /// Converts `input` to `output`.
    pub fn convert(&self, input: &Path, output: &Path) -> Result<Report, Error> {
        self.convert_with(input, output, &AtomicBool::new(false), &mut |_, _| {})
    }

    /// As [`Converter::convert`]; setting `cancel` (from a signal handler, another thread)
    /// stops it between windows, leaving no output; `progress` hears (pixels done, pixels in
    /// all) as it goes.
    pub fn convert_with(
        &self,
        input: &Path,
        output: &Path,
        cancel: &AtomicBool,
        progress: &mut (dyn FnMut(u64, u64) + Send),
    ) -> Result<Report, Error> {
        let pair = Pair::new(input, output);
        crate::plan::check_files(std::slice::from_ref(&pair), &self.files_read())?;
        self.run(&pair, self.options.overwrite, cancel, progress)
    }

    /// The compact texels of pixels a renderer's reader decoded (six values a pixel, into
    /// `out`), made in memory as a conversion with these options makes them
    /// ([`crate::pipeline::in_memory`]: the colour space chosen from the file's header by the
    /// rule a conversion uses); with the colour space chosen. The options must ask for the
    /// compact layout. With `palette`, a renderer's palette of them where the pixels repeat
    /// enough ([`Texels::Palette`]).
    pub fn compact_texels(&self, image: &InMemory, palette: bool) -> Result<TexelsMade, Error> {
        let Some(compact) = &self.storage.compact else {
            return Err(ConversionError::InMemory(
                "texels in memory are compact texels: ask for layout 'compact'".into(),
            )
            .into());
        };
        let run = || {
            crate::pipeline::in_memory::compact_texels(
                &self.config,
                image,
                &self.options,
                compact,
                palette,
            )
        };
        let made = match &self.pool {
            Some(pool) => pool.install(run),
            None => run(),
        }?;
        Ok(TexelsMade {
            text: compact.to_text(),
            colorspace: made.space.name,
            rule: made.space.rule,
            texels: made.texels,
        })
    }

    pub(crate) fn run(
        &self,
        pair: &Pair,
        overwrite: bool,
        cancel: &AtomicBool,
        progress: &mut (dyn FnMut(u64, u64) + Send),
    ) -> Result<Report, Error> {
        let start = Instant::now();
        let (input, output) = (pair.input.as_path(), pair.output.as_path());
        let job = Job {
            input,
            output,
            config: &self.config,
            stack: &self.stack,
            options: &self.options,
            storage: &self.storage,
            overwrite,
            cancel,
        };
        let mut run = || -> Result<Report, ConversionError> {
            let opened = crate::pipeline::open(&job)?;
            let provenance = Provenance {
                source_colorspace: Some(opened.colorspace().to_string()),
                config: Some(self.config.source().to_string()),
                source: Some(file_name(input)),
                source_stat: crate::provenance::source_stat(input),
                ..self.provenance.clone()
            };
            opened.write(&provenance.to_attributes(), progress)
        };
        let report = match &self.pool {
            Some(pool) => pool.install(run),
            None => run(),
        };
        match report {
            Err(ConversionError::Data(data)) => {
                let output = pair.output(Holds::Data);
                self.data_texture((input, output), overwrite, *data, (start, cancel))
            }
            Err(e) => Err(e.into()),
            Ok(report) => Ok(Report {
                seconds: start.elapsed().as_secs_f64(),
                ..report
            }),
        }
    }

    /// A data texture, by the data policy: skipped, written through, or a failure.
    fn data_texture(
        &self,
        (input, output): (&Path, &Path),
        overwrite: bool,
        data: crate::pipeline::DataTexture,
        (start, cancel): (Instant, &AtomicBool),
    ) -> Result<Report, Error> {
        let mut dropped = Vec::new();
        let outcome = match self.options.data {
            DataPolicy::Fail => {
                return Err(Error::Conversion(ConversionError::Data(Box::new(data))))
            }
            DataPolicy::Skip => (DataOutcome::Skipped, 0),
            DataPolicy::Copy => {
                let (tile_width, tile_height) = match self.options.blocks {
                    Blocks::Tiles(w, h) => (w, h),
                    // A texture is tiled whatever the colour outputs are.
                    Blocks::Scanlines => (64, 64),
                };
                let compression = self.options.compression.to_string();
                let selection = data.selection.as_ref();
                let mut attributes = self.copy_attributes(input, &data);
                let subimage = selection.map_or(0, |s| s.subimage);
                let (carried, not_carried) =
                    copied_metadata(input, subimage, self.options.strip_metadata)
                        .map_err(|e| Error::Conversion(ConversionError::Input(e.into())))?;
                attributes.extend(carried);
                dropped = not_carried;
                let how = crate::pipeline::data::Copy {
                    subimage: selection.map_or(0, |s| s.subimage),
                    tile: (
                        u32::try_from(tile_width).unwrap_or(u32::MAX),
                        u32::try_from(tile_height).unwrap_or(u32::MAX),
                    ),
                    compression: &compression,
                    overwrite,
                    attributes: &attributes,
                    cancel,
                };
                let levels =
                    crate::pipeline::data::copy(input, output, &how).map_err(Error::Conversion)?;
                (DataOutcome::Copied, levels)
            }
        };
        let selection = data.selection.clone().unwrap_or_else(|| Selection {
            subimage: 0,
            subimages: 1,
            subimage_name: String::new(),
            channels: crate::pipeline::input::Channels {
                colour: Vec::new(),
                alpha: None,
                names: Vec::new(),
                reason: crate::pipeline::input::ChannelReason::Named,
            },
        });
        Ok(Report {
            width: data.size.0 as usize,
            height: data.size.1 as usize,
            pixels: 0,
            levels: outcome.1,
            wrap: None,
            non_finite_input: (0, false),
            constant: false,
            opaque_dropped: false,
            source_hash: String::new(),
            bands: 0,
            selection,
            colorspace: data.name,
            colorspace_rule: data.rule,
            warnings: Vec::new(),
            metadata_dropped: dropped,
            premultiplied: false,
            non_finite: 0,
            above_one: 0,
            saturated: 0,
            clamped: 0,
            filter: (outcome.1 > 1).then_some(self.options.filter),
            bounded: None,
            unmatched: None,
            seconds: start.elapsed().as_secs_f64(),
            role: Role::Data,
            data: Some(outcome.0),
        })
    }

    /// What a data copy records and how make_texture is to make it: the provenance, `--wrap`,
    /// the filter, `--resize` and the non-finite repair, as maketx's settings.
    fn copy_attributes(
        &self,
        input: &Path,
        data: &crate::pipeline::DataTexture,
    ) -> Vec<(String, String)> {
        let provenance = Provenance {
            source_colorspace: Some(data.name.clone()),
            config: Some(self.config.source().to_string()),
            source: Some(file_name(input)),
            source_stat: crate::provenance::source_stat(input),
            settings: self.provenance.settings.clone(),
            version: self.provenance.version.clone(),
            ..Provenance::default()
        };
        // `--wrap` names the copy's wrap modes too (else make_texture keeps the input's).
        let mut attributes = provenance.to_attributes();
        // Its role, in the attribute OpenEXR and OpenImageIO 3 read a colour space from
        // (make_texture would leave the input's, or none: read as linear Rec.709 colour).
        attributes.push((
            "colorInteropID".into(),
            crate::pipeline::interop::DATA.into(),
        ));
        if let Some((s, t)) = self.options.wrap {
            attributes.push(("wrapmodes".into(), format!("{s},{t}")));
        }
        // Its levels with the same filter (maketx filters the data as it is).
        attributes.push(("maketx:filtername".into(), self.options.filter.to_string()));
        // And level 0 resized to powers of two as maketx's --resize (OpenImageIO reads
        // the integer from the string).
        if self.options.resize {
            attributes.push(("maketx:resize".into(), "1".into()));
        }
        // Non-finite values repaired as a conversion repairs them (the survey refused
        // them already where the policy refuses).
        if let Some(fix) = self.options.non_finite.maketx_fixnan() {
            attributes.push(("maketx:fixnan".into(), fix.into()));
        }
        attributes
    }

    /// Whether `output` is newer than `input`, whole (every chunk inside the file: one cut
    /// short by a full disk or a copy is rebuilt), was written with these same settings from
    /// an input of this name, and from these pixels: the input's size and change times are
    /// the ones recorded, or else the hash of its pixels is (a source replaced by another
    /// image with an older time is rebuilt; a library copied elsewhere is not).
    pub fn is_up_to_date(&self, input: &Path, output: &Path) -> bool {
        let modified = |p: &Path| std::fs::metadata(p).and_then(|m| m.modified()).ok();
        let Some(p) = (match (modified(input), modified(output)) {
            (Some(i), Some(o)) if o >= i => recorded(output),
            _ => None,
        }) else {
            return false;
        };
        if specconv_exr::check::check_complete(output).is_err() {
            return false;
        }
        if p.settings != self.provenance.settings || p.source != Some(file_name(input)) {
            return false;
        }
        if p.source_stat.is_some() && p.source_stat == crate::provenance::source_stat(input) {
            return true;
        }
        p.source_hash.is_some()
            && crate::pipeline::source_hash(
                input,
                &crate::pipeline::input::Request::of(&self.options),
            )
            .ok()
                == p.source_hash
    }

    /// The options it was built from.
    pub fn options(&self) -> &Options {
        &self.options
    }

    /// The OCIO config's source (a file, `aces`, an `ocio://` name).
    pub fn config_source(&self) -> String {
        self.config.source().to_string()
    }

    /// The model, described as outputs record it.
    pub fn model_description(&self) -> &str {
        &self.model_description
    }

    /// The model.
    pub fn model(&self) -> &Model {
        &self.model
    }

    /// The method stack's name, as outputs record it (`otsu2018+bounded`, …).
    pub fn method_name(&self) -> &str {
        self.stack.method().name()
    }

    /// Emission: the name of the method each colour is uplifted by (inside the scaling).
    pub fn emission_method_name(&self) -> Option<&str> {
        self.stack.emissive().map(|e| e.inner().name())
    }

    /// Whether every reflectance stays in [0, 1] (bounded, or bounded by its own design).
    pub fn keeps_range(&self) -> bool {
        self.stack.keeps_range(self.options.method)
    }

    /// The provenance every output records, but for the input's own fields.
    pub fn provenance(&self) -> &Provenance {
        &self.provenance
    }

    /// What OpenColorIO said loading the config, where it concerns a colour space that may be
    /// used (every line but those about inactive colour spaces): a front-end prints it as its own
    /// lines.
    pub fn config_notes(&self) -> &[String] {
        &self.config_notes
    }

    /// What these options will cost in accuracy, said before any input is read.
    pub fn advice(&self) -> Vec<Advice> {
        let o = &self.options;
        let mut advice = Vec::new();
        if o.emission == Some(EmissionUnits::Photometric) && o.sample == Sample::Half {
            advice.push(Advice::PhotometricHalf);
        }
        advice
    }
}

/// Of OpenColorIO's log, what concerns a colour space a conversion may use: every line but
/// those about inactive colour spaces (the official configs list display spaces they leave
/// inactive, and OCIO says so of each on every load), which no conversion can use.
fn config_notes(log: Vec<String>) -> Vec<String> {
    log.into_iter()
        .filter(|l| !(l.starts_with("Inactive '") && l.ends_with("nor a named transform.")))
        .collect()
}

/// A setting that works but costs accuracy.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum Advice {
    /// Photometric emission in half samples: Y = 683·∫ S0·ȳ dλ puts S0 ≈ Y/73000 a band, below
    /// half's normal range (6.1e-5) for scenes under ≈4 cd/m², with few digits left far above.
    PhotometricHalf,
}

impl std::fmt::Display for Advice {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Advice::PhotometricHalf => f.write_str(
                "photometric S0 of scenes below a few cd/m² falls below what half resolves",
            ),
        }
    }
}

/// The compact layout's encoder, when it is the layout: the clustered methods' reflectance,
/// not resized (level 0 would be the filtered colour, not the filtered spectra).
fn compact(options: &Options, model: &Model, name: &str) -> Result<Option<Compact>, Error> {
    if options.layout != Layout::Compact {
        return Ok(None);
    }
    if options.resize {
        return Err(Error::Compact {
            why: "a resized level 0 is filtered from the spectra, which texels cannot hold; resize the input first".into(),
        });
    }
    Ok(Some(Compact::new(model, name, &options.stack_spec())?))
}

/// The attributes a data copy writes of the input's metadata, and the metadata it drops.
type CopiedMetadata = (Vec<(String, String)>, Vec<crate::metadata::Dropped>);

/// For make_texture, which keeps the input's header: of the texture metadata of the input's
/// `subimage` ([`crate::metadata::Carry`]), the shim's `specconv:erase` setting naming (a line
/// each) what the copy leaves out, then what it carries, written over the header's copy as
/// UTF-8; and what it drops. A stripped copy leaves out all of it, silently.
fn copied_metadata(
    input: &Path,
    subimage: u32,
    strip: bool,
) -> specconv_oiio::Result<CopiedMetadata> {
    let mut reader = specconv_oiio::ImageReader::open(input)?;
    reader.select_subimage(subimage)?;
    let carry = crate::pipeline::texture::metadata(&reader, input)?;
    let mut names: Vec<&str> = carry.dropped.iter().map(|d| d.name.as_str()).collect();
    if strip {
        names.extend(carry.kept.iter().map(|(name, _)| name.as_str()));
    }
    let mut attributes = vec![("specconv:erase".to_string(), names.join("\n"))];
    if strip {
        return Ok((attributes, Vec::new()));
    }
    attributes.extend(carry.kept);
    Ok((attributes, carry.dropped))
}

/// The input's file name, as `specconvSource` records it.
fn file_name(p: &Path) -> String {
    p.file_name().map_or_else(
        || p.display().to_string(),
        |n| n.to_string_lossy().into_owned(),
    )
}

impl std::fmt::Debug for Converter {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Converter")
            .field("options", &self.options)
            .field("method", &self.method_name())
            .finish_non_exhaustive()
    }
}

/// Refuses settings whose blocks in flight need more memory than the machine has: each worker
/// holds one block's spectra as f32 and as written samples, and its compressed chunk (a fine
/// `bands` grid makes a 64×64 tile hundreds of megabytes).
fn check_memory(block_pixels: usize, channels: usize, threads: usize) -> Result<(), Error> {
    let needed = threads as u64 * block_pixels as u64 * channels as u64 * 12;
    // What the machine can give, as the pipeline reads it for a whole file.
    match crate::pipeline::memory::available() {
        Some((have, _)) if needed > have => Err(Error::TooMuchMemory { needed, have }),
        _ => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn only_lines_about_inactive_spaces_are_left_out_of_the_config_s_notes() {
        let log = vec![
            "Inactive 'P3-DCI - Display' is neither a color space nor a named transform.".into(),
            "Color space 'ACEScg' has a transform that cannot be inverted.".into(),
        ];
        assert_eq!(
            super::config_notes(log),
            ["Color space 'ACEScg' has a transform that cannot be inverted."]
        );
    }
}

/// What [`Converter::compact_texels`] made.
#[derive(Debug)]
#[non_exhaustive]
pub struct TexelsMade {
    /// The texels, or their palette.
    pub texels: Texels,
    /// The text that decodes them (docs/compact.md).
    pub text: String,
    /// The colour space the pixels were read in.
    pub colorspace: String,
    /// The rule that chose it.
    pub rule: Rule,
}
