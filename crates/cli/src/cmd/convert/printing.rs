//! What `convert` says of each input: a line on standard error, or a JSON record.

use super::Args;
use crate::records;
use crate::stdio::{serialize_path, StdoutFailed};
use serde::Serialize;
use specconv_conversion::{Converter, Report};
use std::path::{Path, PathBuf};

/// One input's record (`--json`): every key on every record, null where it does not apply
/// (docs/json.md).
#[derive(Serialize)]
struct Record {
    /// Paths are written losslessly, bytes outside UTF-8 as `\udcXX` (docs/json.md).
    #[serde(serialize_with = "serialize_path")]
    input: PathBuf,
    #[serde(serialize_with = "serialize_path")]
    output: PathBuf,
    /// `ok`, `skipped` or `failed`.
    status: &'static str,
    /// Why a skipped input was skipped.
    skip_reason: Option<&'static str>,
    /// Why a failed input failed, without its path (the record has it).
    error: Option<String>,
    seconds: f64,
    /// Pixels uplifted, over all levels.
    pixels: Option<u64>,
    width: Option<usize>,
    height: Option<usize>,
    levels: Option<usize>,
    bands: Option<usize>,
    /// The input colour space (the config's name) and the rule that chose it.
    colorspace: Option<String>,
    colorspace_rule: Option<&'static str>,
    /// The subimage read, and the colour (then alpha) channels.
    subimage: Option<u32>,
    channels: Option<Vec<String>>,
    /// `colour`, `achromatic` (one channel its colour space calls colour) or `data`.
    role: Option<&'static str>,
    /// Pixels (all levels) projected into [0, 1] and outside the object-colour solid; null
    /// with --unbounded or --emissive.
    bounded: Option<BoundedCounts>,
    non_finite: Option<u64>,
    above_one: Option<u64>,
    saturated: Option<u64>,
    /// Input pixels with NaN or infinite values repaired (--fixnan black or box3).
    non_finite_repaired: Option<u64>,
    /// The wrap modes the texture records (`s,t`); null for scanline outputs.
    wrap: Option<String>,
    /// The filter the MIP levels (and a resized level 0) were made with; null when none was
    /// made.
    filter: Option<&'static str>,
    /// Pixels of made levels clamped after a filter's negative lobes pushed them out of range.
    clamped: Option<u64>,
    /// Every pixel was the same: written as one tile.
    constant: Option<bool>,
    /// Alpha was 1 everywhere and was left out.
    alpha_dropped: Option<bool>,
    /// The hash of the source pixels that -u compares.
    source_hash: Option<String>,
    /// The model that made the spectra, as the output's `specconvModel` records it.
    model: Option<String>,
}

impl Record {
    /// A record of an input that was not converted.
    fn not_converted(input: &Path, output: &Path, status: &'static str, seconds: f64) -> Record {
        Record {
            input: input.to_path_buf(),
            output: output.to_path_buf(),
            status,
            skip_reason: None,
            error: None,
            seconds,
            pixels: None,
            width: None,
            height: None,
            levels: None,
            bands: None,
            colorspace: None,
            colorspace_rule: None,
            subimage: None,
            channels: None,
            role: None,
            bounded: None,
            non_finite: None,
            above_one: None,
            saturated: None,
            non_finite_repaired: None,
            wrap: None,
            filter: None,
            clamped: None,
            constant: None,
            alpha_dropped: None,
            source_hash: None,
            model: None,
        }
    }
}

#[derive(Serialize)]
struct BoundedCounts {
    projected: usize,
    outside_solid: usize,
}

/// Reports an input skipped because its output is up to date.
pub(super) fn skipped(args: &Args, input: &Path, output: &Path) -> Result<(), StdoutFailed> {
    let record = Record {
        skip_reason: Some("up to date"),
        ..Record::not_converted(input, output, "skipped", 0.0)
    };
    emit(args, record, "")
}

/// Reports a failed input (its error line is printed by the caller unless `--json`).
pub(super) fn failed(
    args: &Args,
    (input, output): (&Path, &Path),
    error: String,
    seconds: f64,
) -> Result<(), StdoutFailed> {
    let record = Record {
        error: Some(error),
        ..Record::not_converted(input, output, "failed", seconds)
    };
    emit(args, record, "")
}

/// Reports a converted input: its warnings, its record or line.
pub(super) fn converted(
    args: &Args,
    converter: &Converter,
    (input, output): (&Path, &Path),
    r: &Report,
) -> Result<(), StdoutFailed> {
    if !args.quiet {
        for w in &r.warnings {
            let w = records::warning(w);
            errln!("specconv: warning: {}: {w}", input.display());
        }
    }
    let line = summary_line(r)
        + &r.bounded.map_or(String::new(), |c| {
            format!(
                ", {} pixels projected into [0, 1], {} outside the object-colour solid \
                 (nearest colour in CIELAB)",
                c.projected, c.outside
            )
        })
        + &range_notes(r, converter);
    let record = Record {
        pixels: Some(r.pixels),
        width: Some(r.width),
        height: Some(r.height),
        levels: Some(r.levels),
        bands: Some(r.bands),
        colorspace: Some(r.colorspace.clone()),
        colorspace_rule: Some(records::colorspace_rule(&r.colorspace_rule)),
        subimage: Some(r.selection.subimage),
        channels: Some(r.selection.channels.names.clone()),
        role: Some(r.role.name()),
        bounded: r.bounded.map(|c| BoundedCounts {
            projected: c.projected,
            outside_solid: c.outside,
        }),
        non_finite: Some(r.non_finite),
        above_one: Some(r.above_one),
        saturated: Some(r.saturated),
        non_finite_repaired: Some(if r.non_finite_input.1 {
            r.non_finite_input.0
        } else {
            0
        }),
        wrap: r.wrap.map(|((s, t), _)| format!("{s},{t}")),
        filter: r.filter.map(|f| f.name()),
        clamped: Some(r.clamped),
        constant: Some(r.constant),
        alpha_dropped: Some(r.opaque_dropped),
        source_hash: Some(r.source_hash.clone()).filter(|h| !h.is_empty()),
        model: Some(converter.model_description().to_string()),
        ..Record::not_converted(input, output, "ok", r.seconds)
    };
    emit(args, record, &line)
}

/// Reports a data texture: skipped (status `data`) or written through (status `copied`).
pub(super) fn data(
    args: &Args,
    (input, output): (&Path, &Path),
    r: &Report,
) -> Result<(), StdoutFailed> {
    let copied = r.data == Some(specconv_conversion::DataOutcome::Copied);
    let why = records::colorspace_reason(&r.colorspace_rule);
    let line = if copied {
        format!(
            "a data texture (colour space {}, {why}): written through, {} levels, not uplifted",
            r.colorspace, r.levels
        )
    } else {
        format!(
            "a data texture (colour space {}, {why}): skipped, never uplifted (--data copy writes \
             it through)",
            r.colorspace
        )
    };
    let status = if copied { "copied" } else { "data" };
    let record = Record {
        width: Some(r.width),
        height: Some(r.height),
        levels: copied.then_some(r.levels),
        colorspace: Some(r.colorspace.clone()),
        colorspace_rule: Some(records::colorspace_rule(&r.colorspace_rule)),
        subimage: Some(r.selection.subimage),
        channels: (!r.selection.channels.names.is_empty())
            .then(|| r.selection.channels.names.clone()),
        role: Some(r.role.name()),
        ..Record::not_converted(input, output, status, r.seconds)
    };
    if args.json {
        return emit(args, record, "");
    }
    if !args.quiet {
        errln!("{} → {}: {line}", input.display(), output.display());
    }
    Ok(())
}

/// `W×H, L levels, N bands, colour space …, …, S s` of a converted input.
fn summary_line(r: &Report) -> String {
    let plural = if r.levels == 1 { "" } else { "s" };
    let mut line = format!(
        "{}×{}, {} level{plural}, {} bands, colour space {} ({}), {}",
        r.width,
        r.height,
        r.levels,
        r.bands,
        r.colorspace,
        records::colorspace_reason(&r.colorspace_rule),
        records::selection(&r.selection),
    );
    if r.role == specconv_conversion::Role::Achromatic {
        line += ", one channel read as achromatic colour (its colour space says colour)";
    }
    if r.premultiplied {
        line += ", straight alpha premultiplied";
    }
    if r.opaque_dropped {
        line += ", alpha 1 everywhere (left out)";
    }
    if r.constant {
        line += ", one colour (written as one tile)";
    }
    if let (n, true) = r.non_finite_input {
        line += &format!(", {n} pixels with NaN or infinite values repaired");
    }
    if let Some(((s, t), declared)) = r.wrap {
        let from = if declared { " (the input's)" } else { "" };
        line += &format!(", wrap {s},{t}{from}");
    }
    match r.filter {
        Some(f) if f != specconv_conversion::Filter::Box => line += &format!(", filter {f}"),
        _ => {}
    }
    if r.clamped > 0 {
        line += &format!(
            ", {} filtered pixels clamped (the filter's negative lobes)",
            r.clamped
        );
    }
    if r.non_finite > 0 {
        line += &format!(", {} pixels NaN or infinite (written as NaN)", r.non_finite);
    }
    line + &format!(", {:.2} s", r.seconds)
}

/// The summary's notes on values out of range: pixels above 1 in reflectance mode (and the
/// --emissive hint when they are at least 1 % of the image), emission colours no spectrum of
/// the method matched, values saturated at the half range.
fn range_notes(r: &Report, converter: &Converter) -> String {
    let mut notes = String::new();
    match (r.unmatched, converter.emission_method_name()) {
        (Some(unmatched), Some(inner)) if unmatched > 0 => {
            notes += &format!(
                ", {unmatched} pixels no emission of {inner} matches (outside the spectral locus or \
                 negative luminance: written with the nearest colour it reached)",
            );
        }
        (Some(_), _) => {}
        _ if r.above_one > 0 => {
            let what = if converter.keeps_range() {
                "moved to the closest colour a reflectance can have"
            } else {
                "spectra above 1, not physical reflectances"
            };
            notes += &format!(", {} pixels above 1 ({what})", r.above_one);
            if r.above_one * 100 >= r.pixels {
                notes += "; an emission or HDR texture? convert it with --emissive";
            }
        }
        _ => {}
    }
    if r.saturated > 0 {
        notes += &format!(
            ", {} pixels beyond the half range (stored as ±65504; use -d float)",
            r.saturated
        );
    }
    notes
}

/// A record on standard output (`--json`), else a line on standard error.
fn emit(args: &Args, record: Record, line: &str) -> Result<(), StdoutFailed> {
    if args.json {
        // Every field serialises (paths included, by serialize_path): nothing to fail.
        return outln!("{}", serde_json::to_string(&record).unwrap_or_default());
    }
    if !args.quiet && record.status != "failed" {
        errln!(
            "{} → {}: {}{line}",
            record.input.display(),
            record.output.display(),
            record
                .skip_reason
                .map_or(String::new(), |r| format!("skipped, {r}"))
        );
    }
    Ok(())
}
