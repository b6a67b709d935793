//! What `convert` says of each input: a line on standard error, or a JSON record.

use super::Reporting as Args;
use crate::records;
use crate::stdio::StdoutFailed;
use specconv_conversion::record::Record;
use specconv_conversion::{Converter, Report};
use std::path::Path;

/// Reports an input skipped because its output is up to date.
pub fn skipped(args: &Args, input: &Path, output: &Path) -> Result<(), StdoutFailed> {
    emit(args, Record::skipped(input, output), "")
}

/// Reports a failed input (its error line is printed by the caller unless `--json`).
pub fn failed(
    args: &Args,
    (input, output): (&Path, &Path),
    error: String,
    seconds: f64,
) -> Result<(), StdoutFailed> {
    emit(args, Record::failed(input, output, error, seconds), "")
}

/// Reports an expanded compact texture (`expand`): its record or line.
pub fn expanded(
    args: &Args,
    (input, output): (&Path, &Path),
    e: &specconv_conversion::Expanded,
    seconds: f64,
) -> Result<(), StdoutFailed> {
    let wl = &e.wavelengths;
    let line = format!(
        "{}×{}, {} levels, {} bands {}–{} nm ({} texels projected), {seconds:.2} s",
        e.width,
        e.height,
        e.levels,
        wl.len(),
        wl.first().copied().unwrap_or_default(),
        wl.last().copied().unwrap_or_default(),
        e.projected,
    );
    emit(args, Record::expanded(input, output, e, seconds), &line)
}

/// Reports a converted input: its warnings, its record or line.
pub(super) fn converted(
    args: &Args,
    converter: &Converter,
    (input, output): (&Path, &Path),
    r: &Report,
) -> Result<(), StdoutFailed> {
    let line = converted_line(r)
        + &r.bounded.map_or(String::new(), |c| {
            format!(
                ", {} pixels projected into [0, 1], {} outside the object-colour solid \
                 (nearest colour in CIELAB)",
                c.projected, c.outside
            )
        })
        + &range_notes(r, converter);
    let record = Record::converted(converter, input, output, r);
    emit(args, record, &line)
}

/// Each kind of warning of the batch once, with how many inputs had it and the first.
pub(super) fn warnings(counts: &[specconv_conversion::NoticeCount]) {
    use specconv_conversion::NoticeKind;
    for c in counts {
        let what = match &c.kind {
            NoticeKind::Colour(w) => records::warning(w),
            NoticeKind::Clipped => format!("{} with --emissive", c.text),
            NoticeKind::Metadata => c.text.clone(),
        };
        let whom = match c.inputs {
            1 => format!("{}: ", c.first.display()),
            n => format!("{n} inputs (the first {}): ", c.first.display()),
        };
        errln!("specconv: warning: {whom}{what}");
    }
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
            "a data texture (colour space {}, {why}): skipped, never uplifted ({})",
            r.colorspace,
            records::data_remedy(&r.colorspace_rule)
        )
    };
    let record = Record::data(input, output, r);
    if args.json {
        return emit(args, record, "");
    }
    if !args.quiet {
        errln!("{} → {}: {line}", input.display(), output.display());
    }
    Ok(())
}

/// `W×H, L levels, N bands, colour space …, …, S s` of a converted input.
fn converted_line(r: &Report) -> String {
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
            if r.clipped() > 0 {
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
        let json = record.to_json();
        return match args.annotate.as_ref().and_then(|a| a(&record)) {
            // The record is one object: its members, then the annotation's.
            Some(more) => {
                let members = json.trim_end().strip_suffix('}').unwrap_or(&json);
                outln!("{members},{more}}}")
            }
            None => outln!("{json}"),
        };
    }
    if let Some(annotate) = &args.annotate {
        annotate(&record);
    }
    if !args.quiet && record.status() != "failed" {
        errln!(
            "{} → {}: {}{line}",
            record.input().display(),
            record.output().display(),
            record
                .skip_reason()
                .map_or(String::new(), |r| format!("skipped, {r}"))
        );
    }
    Ok(())
}
