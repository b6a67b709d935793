//! The record of one input that `convert --json` prints and the Python package's `convert`
//! returns (docs/json.md): every key on every record, `null` where it does not apply, so that
//! every front-end says the same of the same conversion.

use crate::{Converter, DataOutcome, Report};
use serde::Serialize;
use std::path::{Path, PathBuf};

/// One input's record.
#[derive(Debug, Clone, Serialize)]
pub struct Record {
    /// Paths are written losslessly, bytes outside UTF-8 as `\udcXX` ([`json_path`]).
    #[serde(serialize_with = "serialize_path")]
    input: PathBuf,
    #[serde(serialize_with = "serialize_path")]
    output: PathBuf,
    /// `ok`, `clipped` (converted, with pixels above 1 in a reflectance conversion),
    /// `skipped`, `failed`, `data` or `copied`.
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
    /// The row of the precedence of colour evidence that decided (1 to 6; null for the
    /// data-map rule), and the evidence of a lower row it overruled.
    colorspace_row: Option<u8>,
    colorspace_overrides: Option<String>,
    /// The subimage read, and the colour (then alpha) channels.
    subimage: Option<u32>,
    channels: Option<Vec<String>>,
    /// `colour`, `achromatic` (one channel its colour space calls colour) or `data`.
    role: Option<&'static str>,
    /// Pixels (all levels) projected into [0, 1] and outside the object-colour solid; null
    /// for unbounded or emissive conversions.
    bounded: Option<BoundedCounts>,
    non_finite: Option<u64>,
    above_one: Option<u64>,
    saturated: Option<u64>,
    /// Input pixels with NaN or infinite values repaired.
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
    /// The hash of the source pixels that the up-to-date check compares.
    source_hash: Option<String>,
    /// The model that made the spectra, as the output's `specconvModel` records it.
    model: Option<String>,
    /// The conversion's warnings ([`crate::Report::notices`]), in words; null when nothing
    /// was read.
    warnings: Option<Vec<String>>,
}

#[derive(Debug, Clone, Serialize)]
struct BoundedCounts {
    projected: usize,
    outside_solid: usize,
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
            colorspace_row: None,
            colorspace_overrides: None,
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
            warnings: None,
        }
    }

    /// A compact texture expanded into the spectral layout ([`crate::Expansions`]): its size,
    /// levels and bands; `pixels` is level 0's texels.
    pub fn expanded(input: &Path, output: &Path, e: &crate::Expanded, seconds: f64) -> Record {
        Record {
            pixels: Some((e.width * e.height) as u64),
            width: Some(e.width),
            height: Some(e.height),
            levels: Some(e.levels),
            bands: Some(e.wavelengths.len()),
            ..Record::not_converted(input, output, "ok", seconds)
        }
    }

    /// An input skipped because its output is up to date.
    pub fn skipped(input: &Path, output: &Path) -> Record {
        Record {
            skip_reason: Some("up to date"),
            ..Record::not_converted(input, output, "skipped", 0.0)
        }
    }

    /// An input that failed, with why (the front-end's words for the error, without the
    /// input's path: see [`without_input`]).
    pub fn failed(input: &Path, output: &Path, error: String, seconds: f64) -> Record {
        Record {
            error: Some(error),
            ..Record::not_converted(input, output, "failed", seconds)
        }
    }

    /// An input converted by `converter`, as `report` says.
    pub fn converted(converter: &Converter, input: &Path, output: &Path, r: &Report) -> Record {
        Record {
            pixels: Some(r.pixels),
            width: Some(r.width),
            height: Some(r.height),
            levels: Some(r.levels),
            bands: Some(r.bands),
            colorspace: Some(r.colorspace.clone()),
            colorspace_rule: Some(r.colorspace_rule.kind()),
            colorspace_row: r.colorspace_rule.row(),
            colorspace_overrides: r.colorspace_rule.overrides().map(str::to_owned),
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
            filter: r.filter.map(crate::Named::name),
            clamped: Some(r.clamped),
            constant: Some(r.constant),
            alpha_dropped: Some(r.opaque_dropped),
            source_hash: Some(r.source_hash.clone()).filter(|h| !h.is_empty()),
            model: Some(converter.model_description().to_string()),
            warnings: Some(notices(r)),
            ..Record::not_converted(
                input,
                output,
                if r.clipped() > 0 { "clipped" } else { "ok" },
                r.seconds,
            )
        }
    }

    /// A data texture: skipped (status `data`) or written through (status `copied`).
    pub fn data(input: &Path, output: &Path, r: &Report) -> Record {
        let copied = r.data == Some(DataOutcome::Copied);
        Record {
            width: Some(r.width),
            height: Some(r.height),
            levels: copied.then_some(r.levels),
            colorspace: Some(r.colorspace.clone()),
            colorspace_rule: Some(r.colorspace_rule.kind()),
            colorspace_row: r.colorspace_rule.row(),
            colorspace_overrides: r.colorspace_rule.overrides().map(str::to_owned),
            subimage: Some(r.selection.subimage),
            channels: (!r.selection.channels.names.is_empty())
                .then(|| r.selection.channels.names.clone()),
            role: Some(r.role.name()),
            warnings: Some(notices(r)),
            ..Record::not_converted(
                input,
                output,
                if copied { "copied" } else { "data" },
                r.seconds,
            )
        }
    }

    /// The record as one line of JSON. Every field serialises (paths by [`serialize_path`]).
    pub fn to_json(&self) -> String {
        serde_json::to_string(self).unwrap_or_default()
    }

    /// Its input.
    pub fn input(&self) -> &Path {
        &self.input
    }

    /// Its output.
    pub fn output(&self) -> &Path {
        &self.output
    }

    /// `ok`, `clipped`, `skipped`, `failed`, `data` or `copied`.
    pub fn status(&self) -> &'static str {
        self.status
    }

    /// Why it was skipped, when it was.
    pub fn skip_reason(&self) -> Option<&'static str> {
        self.skip_reason
    }
}

/// The words of every warning of `r`.
fn notices(r: &Report) -> Vec<String> {
    r.notices().into_iter().map(|n| n.text).collect()
}

/// An error message about an input without the leading `PATH: ` that the record (or the line)
/// already names; paths inside the message stay, so every path it names is the real one.
pub fn without_input(message: &str, input: &Path) -> String {
    let p = input.display().to_string();
    message
        .strip_prefix(&format!("{p}: "))
        .unwrap_or(message)
        .to_string()
}

/// A path as a JSON string, losslessly: valid UTF-8 as `serde_json` writes it, and each byte
/// that is not part of valid UTF-8 as `\udcXX`, the lone low surrogate U+DC00 + byte (Python's
/// "surrogateescape": `os.fsencode(json.loads(line)["input"])` gives back the exact bytes).
/// docs/json.md.
pub fn json_path(path: &Path) -> String {
    use std::os::unix::ffi::OsStrExt;
    let mut json = String::from("\"");
    for chunk in path.as_os_str().as_bytes().utf8_chunks() {
        let valid = serde_json::to_string(chunk.valid()).unwrap_or_default();
        // Without its quotes; a &str always serialises.
        json += valid
            .get(1..valid.len().saturating_sub(1))
            .unwrap_or_default();
        for byte in chunk.invalid() {
            json += &format!("\\udc{byte:02x}");
        }
    }
    json + "\""
}

/// `#[serde(serialize_with = "…")]` for path fields of JSON records: [`json_path`], written
/// as it is (serde_json makes no lone surrogates from a `String`).
pub fn serialize_path<S: serde::Serializer>(path: &Path, serializer: S) -> Result<S::Ok, S::Error> {
    serde_json::value::RawValue::from_string(json_path(path))
        .map_err(serde::ser::Error::custom)?
        .serialize(serializer)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::ffi::OsStr;
    use std::os::unix::ffi::OsStrExt;

    #[test]
    fn paths_are_json_strings_and_bytes_outside_utf8_are_lone_surrogates() {
        let p = |b: &[u8]| json_path(Path::new(OsStr::from_bytes(b)));
        assert_eq!(p(b"a/b.png"), r#""a/b.png""#);
        assert_eq!(p("é \"q\"\\\n".as_bytes()), r#""é \"q\"\\\n""#);
        assert_eq!(p(b"a\xffb\xc3.png"), r#""a\udcffb\udcc3.png""#);
        assert_eq!(p(b"\x80"), r#""\udc80""#);
    }

    #[test]
    fn the_input_path_is_left_out() {
        let p = Path::new("/tex/gone.png");
        assert_eq!(
            without_input("/tex/gone.png: no such file", p),
            "no such file"
        );
        assert_eq!(
            without_input("cannot read /tex/gone.png: truncated", p),
            "cannot read /tex/gone.png: truncated"
        );
        // A path that contains the input's (`./x` holds `x`) is left whole.
        assert_eq!(
            without_input(
                "the output ./x is the input x; choose another",
                Path::new("x")
            ),
            "the output ./x is the input x; choose another"
        );
    }
}
