//! Where a conversion's output goes, from its input and what it holds ([`Holds`]): `-o DIR`
//! gives `DIR/STEM_spectral.exr` for an uplifted texture and `DIR/STEM_data.exr` for a data
//! texture written through, an output template replaces its fields ([`FIELDS`]; `{role}` is
//! `spectral` or `data`). One definition for the command line and
//! the farm's check of a job's outputs. Names are kept byte for byte: an input named in bytes
//! that are not UTF-8 gets an output of those bytes, not of replacement characters.
//!
//! A template is checked whole before any input is planned ([`Template::parse`]): a field
//! that is not one of [`FIELDS`] (a typo such as `{stme}`) is refused, never written literally.

use crate::udim;
use std::ffi::OsString;
use std::os::unix::ffi::{OsStrExt, OsStringExt};
use std::path::{Path, PathBuf};

/// The fields of an output template, as `{name}`.
pub const FIELDS: [&str; 7] = ["dir", "stem", "name", "ext", "udim", "tile", "role"];

/// What an output holds, which names it apart: a texture is known to be data only once it is
/// read, so a plan names both outputs of each input and the conversion writes one.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Holds {
    /// The spectral (or compact) texture uplifted from a colour texture.
    Spectral,
    /// A data texture (roughness, normals) written through, its values unconverted.
    Data,
}

impl Holds {
    /// Both, in the order plans list them.
    pub const ALL: [Holds; 2] = [Holds::Spectral, Holds::Data];

    /// The word its default name and a template's `{role}` give: `spectral` or `data`.
    pub fn word(self) -> &'static str {
        match self {
            Holds::Spectral => "spectral",
            Holds::Data => "data",
        }
    }
}

/// `DIR/STEM_spectral.exr` (or `STEM_data.exr`) for `input`.
pub fn in_directory(dir: &Path, input: &Path, holds: Holds) -> PathBuf {
    let mut name = udim::stem(input);
    name.extend_from_slice(format!("_{}.exr", holds.word()).as_bytes());
    dir.join(OsString::from_vec(name))
}

/// Why a template cannot name an output.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum TemplateError {
    /// A `{field}` that is not one of [`FIELDS`].
    #[error(
        "the output template {template:?} has an unknown field {{{field}}}; its fields are {}",
        known_fields()
    )]
    UnknownField {
        /// The template.
        template: String,
        /// The field as written, without braces.
        field: String,
    },
    /// A field written with more braces than one on each side (`{{stem}}`, as in Jinja or
    /// Mustache templates): fields take one, and a brace is never written literally.
    #[error(
        "the output template {template:?} has {written}, {}; its fields are {}",
        match known {
            Some(f) => format!("which writes the field {{{f}}} with braces doubled: fields take one brace on each side"),
            None => "which is no field: fields take one brace on each side, and no brace is written literally".to_string(),
        },
        known_fields()
    )]
    Braces {
        /// The template.
        template: String,
        /// The braces and what they hold, as written (`{{stem}}`).
        written: String,
        /// The field they hold, when it is one of [`FIELDS`].
        known: Option<&'static str>,
    },
    /// A `{` with no `}` after it.
    #[error(
        "the output template {template:?} has a '{{' that no '}}' closes; its fields are {}",
        known_fields()
    )]
    Unclosed {
        /// The template.
        template: String,
    },
    /// `{udim}` or `{tile}` for an input without a tile number in its name.
    #[error(
        "the output template {template:?} names the UDIM tile, but {} has no tile number \
         ({}–{}) in its name",
        input.display(), udim::FIRST, udim::LAST
    )]
    NoTile {
        /// The template.
        template: String,
        /// The input.
        input: PathBuf,
    },
}

/// [`TemplateError::Braces`] for `written` (`{{stem}}`, `{a{b}`).
fn braces(template: &str, written: &str) -> TemplateError {
    let inner = written.trim_start_matches('{').trim_end_matches('}');
    TemplateError::Braces {
        template: template.to_owned(),
        written: written.to_owned(),
        known: FIELDS.into_iter().find(|f| *f == inner),
    }
}

fn known_fields() -> String {
    FIELDS.map(|f| format!("{{{f}}}")).join(", ")
}

/// One piece of a template.
#[derive(Debug, Clone, PartialEq, Eq)]
enum Piece {
    Text(Vec<u8>),
    Dir,
    Stem,
    Name,
    Ext,
    Udim,
    Tile,
    Role,
}

/// An output template, its fields checked: `{dir}` (the input's directory, `.` for none),
/// `{stem}` (its name without the extension), `{name}` (its file name), `{ext}` (its extension
/// without the dot, empty for none), `{udim}` (its UDIM tile number, 1001…), `{tile}` (the
/// same tile as `u1_v1`, OpenImageIO's `<UVTILE>`) and `{role}` (`spectral`, or `data` for a
/// data texture written through: [`Holds`]). Without `{role}` both are one file. In a
/// template that names the tile, `{stem}` leaves the tile number out: `{stem}_spectral.{udim}.exr`
/// makes `wood_spectral.1001.exr` of `wood.1001.png`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Template {
    text: String,
    pieces: Vec<Piece>,
}

impl Template {
    /// Checks `text`: every `{` opens one of [`FIELDS`].
    pub fn parse(text: &str) -> Result<Template, TemplateError> {
        let mut pieces = Vec::new();
        let mut literal = Vec::new();
        let mut rest = text;
        while let Some(open) = rest.find('{') {
            literal.extend_from_slice(&rest.as_bytes()[..open]);
            let after = &rest[open + 1..];
            let close = after.find('}').ok_or_else(|| TemplateError::Unclosed {
                template: text.to_owned(),
            })?;
            let field = &after[..close];
            if field.contains('{') {
                // The braces as written: up to the first `}` and the `}` that follow it.
                let closing = after[close..].len() - after[close..].trim_start_matches('}').len();
                return Err(braces(text, &rest[open..open + 1 + close + closing]));
            }
            let piece = match field {
                "dir" => Piece::Dir,
                "stem" => Piece::Stem,
                "name" => Piece::Name,
                "ext" => Piece::Ext,
                "udim" => Piece::Udim,
                "tile" => Piece::Tile,
                "role" => Piece::Role,
                _ => {
                    return Err(TemplateError::UnknownField {
                        template: text.to_owned(),
                        field: field.to_owned(),
                    })
                }
            };
            if !literal.is_empty() {
                pieces.push(Piece::Text(std::mem::take(&mut literal)));
            }
            pieces.push(piece);
            rest = &after[close + 1..];
        }
        literal.extend_from_slice(rest.as_bytes());
        if !literal.is_empty() {
            pieces.push(Piece::Text(literal));
        }
        Ok(Template {
            text: text.to_owned(),
            pieces,
        })
    }

    /// Whether the template names the UDIM tile (`{udim}` or `{tile}`).
    pub fn names_tile(&self) -> bool {
        self.pieces
            .iter()
            .any(|p| matches!(p, Piece::Udim | Piece::Tile))
    }

    /// The output of `input` when it holds `holds`.
    pub fn apply(&self, input: &Path, holds: Holds) -> Result<PathBuf, TemplateError> {
        let dir = input
            .parent()
            .filter(|d| !d.as_os_str().is_empty())
            .unwrap_or(Path::new("."));
        let name = input.file_name().map(|n| n.as_bytes()).unwrap_or_default();
        let tile = if self.names_tile() {
            Some(
                udim::tile_number(input).ok_or_else(|| TemplateError::NoTile {
                    template: self.text.clone(),
                    input: input.to_path_buf(),
                })?,
            )
        } else {
            None
        };
        let mut out = Vec::new();
        for piece in &self.pieces {
            match piece {
                Piece::Text(t) => out.extend_from_slice(t),
                Piece::Dir => out.extend_from_slice(dir.as_os_str().as_bytes()),
                Piece::Stem if tile.is_some() => out.extend(udim::stem_without_tile(input)),
                Piece::Stem => out.extend(udim::stem(input)),
                Piece::Name => out.extend_from_slice(name),
                Piece::Ext => out
                    .extend_from_slice(input.extension().map(|e| e.as_bytes()).unwrap_or_default()),
                Piece::Udim => {
                    out.extend_from_slice(tile.unwrap_or_default().to_string().as_bytes())
                }
                Piece::Tile => {
                    out.extend_from_slice(udim::uv_tile(tile.unwrap_or(udim::FIRST)).as_bytes())
                }
                Piece::Role => out.extend_from_slice(holds.word().as_bytes()),
            }
        }
        Ok(PathBuf::from(OsString::from_vec(out)))
    }

    /// The template as written.
    pub fn as_str(&self) -> &str {
        &self.text
    }
}

/// `template` ([`Template`]) applied to `input` holding `holds`.
pub fn from_template(template: &str, input: &Path, holds: Holds) -> Result<PathBuf, TemplateError> {
    Template::parse(template)?.apply(input, holds)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::ffi::OsStr;

    #[test]
    fn names_are_kept_byte_for_byte() {
        let input = Path::new(OsStr::from_bytes(b"tex/a\xff.png"));
        assert_eq!(
            in_directory(Path::new("out"), input, Holds::Spectral)
                .as_os_str()
                .as_bytes(),
            b"out/a\xff_spectral.exr"
        );
        assert_eq!(
            from_template("{dir}/../o/{stem}.{name}.exr", input, Holds::Spectral)
                .unwrap()
                .as_os_str()
                .as_bytes(),
            b"tex/../o/a\xff.a\xff.png.exr"
        );
        assert_eq!(
            from_template("{stem}.exr", Path::new("x.png"), Holds::Spectral).unwrap(),
            Path::new("x.exr")
        );
        assert_eq!(
            from_template("{dir}/{stem}", Path::new("x.png"), Holds::Spectral).unwrap(),
            Path::new("./x")
        );
    }

    #[test]
    fn data_textures_are_named_apart_by_default_and_by_role() {
        let input = Path::new("tex/rough.1001.png");
        let named = |holds| in_directory(Path::new("out"), input, holds);
        assert_eq!(
            named(Holds::Spectral),
            Path::new("out/rough.1001_spectral.exr")
        );
        assert_eq!(named(Holds::Data), Path::new("out/rough.1001_data.exr"));
        let t = Template::parse("{dir}/{role}/{stem}.{udim}.{role}.exr").unwrap();
        assert_eq!(
            t.apply(input, Holds::Data).unwrap(),
            Path::new("tex/data/rough.1001.data.exr")
        );
        assert_eq!(
            t.apply(input, Holds::Spectral).unwrap(),
            Path::new("tex/spectral/rough.1001.spectral.exr")
        );
        // Without {role} the user named one file for both.
        let one = Template::parse("{dir}/{stem}.exr").unwrap();
        assert_eq!(
            one.apply(input, Holds::Data).unwrap(),
            one.apply(input, Holds::Spectral).unwrap()
        );
    }

    #[test]
    fn tiles_keep_the_studio_convention() {
        let t = "{dir}/{stem}_spectral.{udim}.exr";
        assert_eq!(
            from_template(t, Path::new("tex/wood.1012.png"), Holds::Spectral).unwrap(),
            Path::new("tex/wood_spectral.1012.exr")
        );
        assert_eq!(
            from_template(
                "{stem}_{tile}.exr",
                Path::new("wood_1012.png"),
                Holds::Spectral
            )
            .unwrap(),
            Path::new("wood_u2_v2.exr")
        );
        // Without a tile field the stem keeps its number, so tiles stay apart.
        assert_eq!(
            from_template(
                "{stem}_spectral.exr",
                Path::new("wood.1012.png"),
                Holds::Spectral
            )
            .unwrap(),
            Path::new("wood.1012_spectral.exr")
        );
        let e = from_template(t, Path::new("wood.png"), Holds::Spectral)
            .unwrap_err()
            .to_string();
        assert!(e.contains("wood.png has no tile number"), "{e}");
    }

    #[test]
    fn an_unknown_field_is_refused_with_the_known_ones() {
        let e = Template::parse("{dir}/{stme}.exr").unwrap_err();
        assert_eq!(
            e,
            TemplateError::UnknownField {
                template: "{dir}/{stme}.exr".into(),
                field: "stme".into()
            }
        );
        let text = e.to_string();
        assert!(
            text.contains("{stme}")
                && text.contains("{dir}, {stem}, {name}, {ext}, {udim}, {tile}, {role}"),
            "{text}"
        );
        assert!(matches!(
            Template::parse("{stem.exr"),
            Err(TemplateError::Unclosed { .. })
        ));
        assert!(matches!(
            Template::parse("{}.exr"),
            Err(TemplateError::UnknownField { .. })
        ));
    }

    #[test]
    fn doubled_braces_are_refused_as_written() {
        // Issue 31: `{{stem}}` was reported as the unknown field `{{stem}`.
        for (template, written, known) in [
            ("{{stem}}.exr", "{{stem}}", Some("stem")),
            ("x/{{stem}.exr", "{{stem}", Some("stem")),
            ("{dir}/{{{name}}}", "{{{name}}}", Some("name")),
            ("{a{b}.exr", "{a{b}", None),
        ] {
            let e = Template::parse(template).unwrap_err();
            assert_eq!(
                e,
                TemplateError::Braces {
                    template: template.into(),
                    written: written.into(),
                    known
                },
                "{template}"
            );
        }
        assert_eq!(
            Template::parse("{{stem}}.exr").unwrap_err().to_string(),
            "the output template \"{{stem}}.exr\" has {{stem}}, which writes the field {stem} \
             with braces doubled: fields take one brace on each side; its fields are {dir}, \
             {stem}, {name}, {ext}, {udim}, {tile}, {role}"
        );
    }
}
