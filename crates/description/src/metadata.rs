//! The texture metadata an output carries from its input, as maketx carries it: every string
//! attribute of the input's header that says something of the texture (Copyright,
//! DocumentName, ImageDescription, Artist, a studio's own such as `studio:assetId`), and none
//! that describes the file it was read from (its format's and OpenImageIO's namespaces) or
//! that the writer makes itself (the software, the date, the texture's and specconv's own
//! attributes). One rule for `convert` (input to spectral EXR) and `to-rgb` (spectral EXR
//! back to RGB), so that metadata round-trips.
//!
//! Of that metadata, an output carries what it can ([`Carry`]): text that arrives as UTF-8
//! ([`Encoding`]), under names OpenEXR takes as free text ([`fits`]), within bounds of count
//! and size ([`MAX_ATTRIBUTES`], [`MAX_VALUE_BYTES`], [`MAX_TOTAL_BYTES`]) checked before a
//! value is read. The rest is dropped, each attribute by name ([`Dropped`]), and the
//! conversion says so once.

/// Namespaces (`NS:name`) of attributes that describe a file's format or how OpenImageIO read
/// it, not the texture: the formats', Exif's, IPTC's and XMP's, OpenImageIO's and maketx's.
const FILE_NAMESPACES: [&str; 22] = [
    "oiio",
    "openexr",
    "tiff",
    "png",
    "jpeg",
    "jpeg2000",
    "exif",
    "gps",
    "iptc",
    "xmp",
    "photoshop",
    "icc",
    "dpx",
    "targa",
    "bmp",
    "heif",
    "raw",
    "ffmpeg",
    "webp",
    "gif",
    "psd",
    "maketx",
];

/// Attributes without a namespace that the writer makes itself (the texture's description,
/// the spectral layout's, the software and date of this writing) or that say how the file was
/// stored.
const WRITTEN: [&str; 13] = [
    "Software",
    "DateTime",
    "HostComputer",
    "compression",
    "planarconfig",
    "textureformat",
    "wrapmodes",
    "fovcot",
    "spectralLayoutVersion",
    "emissiveUnits",
    "polarisationHandedness",
    "name",
    // How the input's values encode colour (a Color Interop Forum ID): true of the input's
    // pixels only; an output says its own (a data copy `data`, a spectral file none).
    "colorInteropID",
];

/// Whether `name` is, or passes for, one of specconv's own provenance attributes: it starts
/// with `specconv` once case and every character but ASCII letters and digits are ignored
/// (`SpecconvModel`, `specconv:Source`, ` specconv_Model`, `SPEC-CONV…`).
pub fn reserved(name: &str) -> bool {
    let mut letters = name
        .chars()
        .filter(char::is_ascii_alphanumeric)
        .map(|c| c.to_ascii_lowercase());
    "specconv".chars().all(|c| letters.next() == Some(c))
}

/// Whether an output carries the input's string attribute `name`.
pub fn carried(name: &str) -> bool {
    // specconv's own provenance is written anew by each conversion: no input attribute may
    // overwrite, shadow or imitate it.
    if reserved(name) || WRITTEN.contains(&name) {
        return false;
    }
    match name.split_once(':') {
        Some((space, _)) => !FILE_NAMESPACES.contains(&space.to_ascii_lowercase().as_str()),
        None => true,
    }
}

/// Of `attributes` (name, value), those an output carries ([`Carry`]), in order.
pub fn of(attributes: impl IntoIterator<Item = (String, String)>) -> Vec<(String, String)> {
    let mut carry = Carry::default();
    for (name, value) in attributes {
        if carry.admit(&name, value.len()) {
            carry.push(name, value.as_bytes(), Encoding::Utf8);
        }
    }
    carry.kept
}

/// The most attributes an output carries from its input.
pub const MAX_ATTRIBUTES: usize = 64;
/// The most bytes of one carried attribute's value (UTF-8).
pub const MAX_VALUE_BYTES: usize = 64 * 1024;
/// The most bytes of all carried attributes together (names and values, UTF-8).
pub const MAX_TOTAL_BYTES: usize = 256 * 1024;

/// How an input declares its text's bytes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Encoding {
    /// UTF-8: a PNG's `iTXt`, and what OpenImageIO reports of other formats.
    Utf8,
    /// ISO 8859-1: a PNG's `tEXt` and `zTXt` (PNG specification, 3rd ed., 11.3.3), except
    /// bytes that are valid UTF-8, which are read as UTF-8: OpenImageIO writes UTF-8 into
    /// `tEXt` and reads it back as such (issue 57, item 9), and Latin-1 text with a byte above
    /// 0x7F is almost never valid UTF-8.
    Latin1,
}

impl Encoding {
    /// `bytes` as text, or `None` when they are not text in this encoding (invalid UTF-8).
    pub fn decode(self, bytes: &[u8]) -> Option<String> {
        let utf8 = std::str::from_utf8(bytes).ok().map(str::to_owned);
        match self {
            Encoding::Utf8 => utf8,
            Encoding::Latin1 => {
                utf8.or_else(|| Some(bytes.iter().map(|&b| char::from(b)).collect()))
            }
        }
    }
}

/// Why an attribute of the input's texture metadata is not carried.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Why {
    /// Its name is one of OpenEXR's own attributes (`tiles`, `view`, `owner`, …), which have a
    /// type and a meaning in the file.
    OpenExrName,
    /// Its name is empty or longer than OpenEXR's names.
    NameLength,
    /// Its value is not text in the input's declared encoding.
    NotText(Encoding),
    /// Its value is longer than [`MAX_VALUE_BYTES`] (its length in bytes).
    TooLong(usize),
    /// It comes after [`MAX_ATTRIBUTES`] others.
    TooMany,
    /// It would take the metadata past [`MAX_TOTAL_BYTES`].
    PastTotal,
}

impl Why {
    /// The reason in words, for a list of names that share it.
    fn words(&self) -> String {
        match self {
            Why::OpenExrName => "OpenEXR's own attribute names".into(),
            Why::NameLength => format!(
                "names of 0 or more than {} bytes",
                specconv_exr::MAX_NAME_BYTES
            ),
            Why::NotText(Encoding::Utf8) => "not UTF-8 text".into(),
            Why::NotText(Encoding::Latin1) => "not Latin-1 text".into(),
            Why::TooLong(_) => format!("values over {} KiB", MAX_VALUE_BYTES / 1024),
            Why::TooMany => format!("past {MAX_ATTRIBUTES} attributes"),
            Why::PastTotal => format!("past {} KiB in all", MAX_TOTAL_BYTES / 1024),
        }
    }
}

/// An attribute of the input's texture metadata that the output does not carry.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Dropped {
    /// Its name, as the input has it.
    pub name: String,
    /// Why.
    pub why: Why,
}

/// Whether OpenEXR takes `name` as the name of a free text attribute: 1 to 255 bytes, not
/// one of OpenEXR's own attributes ([`specconv_exr::standard_attribute`]).
pub fn fits(name: &str) -> Result<(), Why> {
    if name.is_empty() || name.len() > specconv_exr::MAX_NAME_BYTES {
        Err(Why::NameLength)
    } else if specconv_exr::standard_attribute(name) {
        Err(Why::OpenExrName)
    } else {
        Ok(())
    }
}

/// The texture metadata an output carries, gathered attribute by attribute: [`Carry::admit`]
/// with the value's length before it is read, then [`Carry::push`] with its bytes.
#[derive(Debug, Clone, Default)]
pub struct Carry {
    /// Carried (name, value), in the input's order.
    pub kept: Vec<(String, String)>,
    /// Not carried, in the input's order.
    pub dropped: Vec<Dropped>,
    bytes: usize,
}

impl Carry {
    /// Whether an attribute `name` whose value is `len` bytes may be read: texture metadata
    /// ([`carried`]) that fits OpenEXR ([`fits`]) and the bounds. Records why not, but for
    /// attributes that are not texture metadata, which are left out silently.
    pub fn admit(&mut self, name: &str, len: usize) -> bool {
        if !carried(name) {
            return false;
        }
        let why = match fits(name) {
            Err(why) => why,
            Ok(()) if self.kept.len() >= MAX_ATTRIBUTES => Why::TooMany,
            Ok(()) if len > MAX_VALUE_BYTES => Why::TooLong(len),
            Ok(()) if self.bytes + name.len() + len > MAX_TOTAL_BYTES => Why::PastTotal,
            Ok(()) => return true,
        };
        self.refuse(name, why);
        false
    }

    /// Carries `bytes`, the value of an attribute [`Carry::admit`] let in, decoded from
    /// `encoding`: dropped when they are not text in it, or when their UTF-8 is past the
    /// bounds (Latin-1 grows in UTF-8).
    pub fn push(&mut self, name: String, bytes: &[u8], encoding: Encoding) {
        let Some(value) = encoding.decode(bytes) else {
            return self.refuse(&name, Why::NotText(encoding));
        };
        if value.len() > MAX_VALUE_BYTES {
            return self.refuse(&name, Why::TooLong(value.len()));
        }
        if self.bytes + name.len() + value.len() > MAX_TOTAL_BYTES {
            return self.refuse(&name, Why::PastTotal);
        }
        self.bytes += name.len() + value.len();
        self.kept.push((name, value));
    }

    /// Records that `name` is not carried, and why.
    pub fn refuse(&mut self, name: &str, why: Why) {
        self.dropped.push(Dropped {
            name: name.to_owned(),
            why,
        });
    }
}

/// The words of one warning about `dropped`: each reason once with the names it drops (the
/// first few, escaped: one attribute cannot write a line of its own), and the remedy.
pub fn describe(dropped: &[Dropped]) -> String {
    // Enough for every one of OpenEXR's own names; a flood is counted.
    const NAMES: usize = 64;
    let mut groups: Vec<(String, Vec<&str>)> = Vec::new();
    for d in dropped {
        let words = d.why.words();
        match groups.iter_mut().find(|(w, _)| *w == words) {
            Some((_, names)) => names.push(&d.name),
            None => groups.push((words, vec![&d.name])),
        }
    }
    let parts: Vec<String> = groups
        .iter()
        .map(|(words, names)| {
            let mut shown: Vec<String> = names
                .iter()
                .take(NAMES)
                .map(|n| format!("'{}'", n.escape_debug()))
                .collect();
            if names.len() > NAMES {
                shown.push(format!("{} more", names.len() - NAMES));
            }
            format!("{} ({words})", shown.join(", "))
        })
        .collect();
    format!(
        "{} input metadata attribute{} not carried into the output: {}; the rest is carried \
         (--strip-metadata leaves out all of the input's metadata)",
        dropped.len(),
        if dropped.len() == 1 { "" } else { "s" },
        parts.join("; ")
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_texture_s_metadata_is_carried_and_the_file_s_is_not() {
        for name in [
            "Copyright",
            "DocumentName",
            "ImageDescription",
            "Artist",
            "studio:assetId",
            "owner",
            "spec",
            "studio:specconvNote",
        ] {
            assert!(carried(name), "{name}");
        }
        for name in [
            "Software",
            "DateTime",
            "oiio:ColorSpace",
            "colorInteropID",
            "Exif:ImageHistory",
            "tiff:Compression",
            "png:sRGB",
            "specconvModel",
            "SpecconvModel",
            "SPECCONVSOURCE",
            "specconv:Source",
            " specconvSource",
            "spec_conv Commercial Use",
            "specconv\nModel",
            "wrapmodes",
            "spectralLayoutVersion",
        ] {
            assert!(!carried(name), "{name}");
        }
    }

    #[test]
    fn every_name_of_openexr_s_own_is_dropped_by_name_and_others_are_carried() {
        let own = [
            "view",
            "type",
            "tiles",
            "channels",
            "dataWindow",
            "displayWindow",
            "lineOrder",
            "compression",
            "pixelAspectRatio",
            "screenWindowCenter",
            "screenWindowWidth",
            "chunkCount",
            "version",
            "maxSamplesPerPixel",
            "owner",
            "comments",
            "capDate",
            "multiView",
            "chromaticities",
            "preview",
        ];
        let mut carry = Carry::default();
        for name in own {
            assert!(!carry.admit(name, 1), "{name}");
        }
        // `compression`, which the writer makes itself, is left out silently; the others are
        // named.
        let named: Vec<&str> = carry.dropped.iter().map(|d| d.name.as_str()).collect();
        assert_eq!(named.len(), own.len() - 1, "{named:?}");
        assert!(carry.dropped.iter().all(|d| d.why == Why::OpenExrName));
        for name in ["studio:名前", "Artist", "ImageDescription", "x"] {
            assert!(carry.admit(name, 3), "{name}");
            carry.push(name.into(), "值 é".as_bytes(), Encoding::Utf8);
        }
        assert_eq!(carry.kept.len(), 4);
        assert!(!carry.admit(&"n".repeat(256), 1));
        assert!(carry.admit(&"n".repeat(255), 1));
    }

    #[test]
    fn text_is_decoded_from_its_declared_encoding_or_dropped() {
        let mut carry = Carry::default();
        carry.push("Copyright".into(), b"Caf\xe9 \xa9", Encoding::Latin1);
        carry.push(
            "Artist".into(),
            "山田 太郎 — Café ☃".as_bytes(),
            Encoding::Utf8,
        );
        carry.push("Bad".into(), b"Caf\xe9", Encoding::Utf8);
        assert_eq!(
            carry.kept,
            [
                ("Copyright".to_string(), "Café ©".to_string()),
                ("Artist".to_string(), "山田 太郎 — Café ☃".to_string())
            ]
        );
        assert_eq!(carry.dropped[0].why, Why::NotText(Encoding::Utf8));
    }

    #[test]
    fn metadata_is_bounded_in_count_size_and_total_before_it_is_read() {
        let mut carry = Carry::default();
        assert!(!carry.admit("Big", MAX_VALUE_BYTES + 1));
        assert_eq!(carry.dropped[0].why, Why::TooLong(MAX_VALUE_BYTES + 1));
        // Latin-1 that grows past the bound in UTF-8.
        assert!(carry.admit("Grows", MAX_VALUE_BYTES));
        carry.push(
            "Grows".into(),
            &vec![0xe9; MAX_VALUE_BYTES],
            Encoding::Latin1,
        );
        assert!(matches!(carry.dropped[1].why, Why::TooLong(_)));
        let value = vec![b'a'; MAX_VALUE_BYTES / 2];
        let mut n = 0;
        while carry.admit(&format!("c{n}"), value.len()) {
            carry.push(format!("c{n}"), &value, Encoding::Utf8);
            n += 1;
        }
        assert_eq!(carry.dropped.last().unwrap().why, Why::PastTotal);
        let total: usize = carry.kept.iter().map(|(k, v)| k.len() + v.len()).sum();
        assert!(total <= MAX_TOTAL_BYTES && total + value.len() + 3 > MAX_TOTAL_BYTES);
        let mut carry = Carry::default();
        for n in 0..MAX_ATTRIBUTES + 5 {
            if carry.admit(&format!("a{n}"), 1) {
                carry.push(format!("a{n}"), b"v", Encoding::Utf8);
            }
        }
        assert_eq!(carry.kept.len(), MAX_ATTRIBUTES);
        assert_eq!(carry.dropped.len(), 5);
        assert!(carry.dropped.iter().all(|d| d.why == Why::TooMany));
    }

    #[test]
    fn the_warning_names_the_attributes_escaped_and_the_option() {
        let dropped: Vec<Dropped> = (0..68)
            .map(|n| Dropped {
                name: format!("c{n}"),
                why: Why::TooMany,
            })
            .chain([Dropped {
                name: "evil\nspecconvSource: x".into(),
                why: Why::OpenExrName,
            }])
            .collect();
        let text = describe(&dropped);
        assert!(!text.contains('\n'), "{text}");
        assert!(text.contains("69 input metadata attributes"), "{text}");
        assert!(text.contains("'c63'") && text.contains("4 more"), "{text}");
        assert!(!text.contains("'c64'"), "{text}");
        assert!(text.contains("--strip-metadata"), "{text}");
    }
}
