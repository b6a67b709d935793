//! Where a conversion's output goes, from its input: `-o DIR` gives `DIR/STEM_spectral.exr`, an
//! output template replaces `{dir}`, `{stem}` and `{name}`. One definition for the command line
//! and the farm's check of a job's outputs. Names are kept byte for byte: an input named in
//! bytes that are not UTF-8 gets an output of those bytes, not of replacement characters.

use std::ffi::OsString;
use std::os::unix::ffi::{OsStrExt, OsStringExt};
use std::path::{Path, PathBuf};

/// `DIR/STEM_spectral.exr` for `input`.
pub fn in_directory(dir: &Path, input: &Path) -> PathBuf {
    let mut name = stem(input);
    name.extend_from_slice(b"_spectral.exr");
    dir.join(OsString::from_vec(name))
}

/// `template` with `{dir}` (the input's directory, `.` for none), `{stem}` (its name without
/// the extension) and `{name}` (its file name) replaced.
pub fn from_template(template: &str, input: &Path) -> PathBuf {
    let dir = input
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let name = input.file_name().map(|n| n.as_bytes()).unwrap_or_default();
    let mut out = Vec::new();
    let mut rest = template.as_bytes();
    while !rest.is_empty() {
        let field: Option<(&[u8], Vec<u8>)> = [
            (&b"{dir}"[..], dir.as_os_str().as_bytes().to_vec()),
            (b"{stem}", stem(input)),
            (b"{name}", name.to_vec()),
        ]
        .into_iter()
        .find(|(key, _)| rest.starts_with(key));
        match field {
            Some((key, value)) => {
                out.extend_from_slice(&value);
                rest = &rest[key.len()..];
            }
            None => {
                out.push(rest[0]);
                rest = &rest[1..];
            }
        }
    }
    PathBuf::from(OsString::from_vec(out))
}

/// The input's name without its extension; `output` for a path without a name.
fn stem(input: &Path) -> Vec<u8> {
    input
        .file_stem()
        .map_or_else(|| b"output".to_vec(), |s| s.as_bytes().to_vec())
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::ffi::OsStr;

    #[test]
    fn names_are_kept_byte_for_byte() {
        let input = Path::new(OsStr::from_bytes(b"tex/a\xff.png"));
        assert_eq!(
            in_directory(Path::new("out"), input).as_os_str().as_bytes(),
            b"out/a\xff_spectral.exr"
        );
        assert_eq!(
            from_template("{dir}/../o/{stem}.{name}.exr", input)
                .as_os_str()
                .as_bytes(),
            b"tex/../o/a\xff.a\xff.png.exr"
        );
        assert_eq!(
            from_template("{stem}.exr", Path::new("x.png")),
            Path::new("x.exr")
        );
        assert_eq!(
            from_template("{dir}/{stem}", Path::new("x.png")),
            Path::new("./x")
        );
    }
}
