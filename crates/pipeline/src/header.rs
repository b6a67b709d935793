//! What a file's header says of its colour, read once into one type ([`Header`]) for the
//! precedence of colour evidence ([`crate::colour`]) to weigh: through OpenImageIO for a
//! conversion ([`Header::of_reader`]), or from the file itself, without OpenImageIO, for
//! pixels a renderer's reader decoded ([`Header::read`]: Mitsuba's `specconv_rgb`), so that
//! both decide by the same rule on the same evidence. What the second reads is what
//! OpenImageIO 2.4 reports of PNG, JPEG and OpenEXR files (tests compare the two).

use crate::error::{Error, Result};
use crate::png;
use specconv_oiio::ImageReader;
use std::io::{Read, Seek, SeekFrom};
use std::path::{Path, PathBuf};

/// A file's colour evidence, as stored: the rule's filters (OpenImageIO's own guesses, blank
/// names, a flag that is not 1) apply when it is weighed.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Header {
    /// The file (file rules match its path).
    pub path: PathBuf,
    /// OpenImageIO's name of its format ("png", "openexr", "jpeg"), "" for another.
    pub format: String,
    /// Width and height of its full-resolution level.
    pub size: (u32, u32),
    /// Integer pixels (display-encoded by default); else float.
    pub integer: bool,
    /// An embedded ICC profile (PNG `iCCP`, JPEG APP2, TIFF tag 34675).
    pub icc: Option<Vec<u8>>,
    /// OpenEXR `colorInteropID`.
    pub interop_id: Option<String>,
    /// OpenEXR `chromaticities`: red, green, blue, white x, y.
    pub chromaticities: Option<[f64; 8]>,
    /// OpenEXR `acesImageContainerFlag`.
    pub aces_container: Option<f64>,
    /// `oiio:ColorSpace`: a name a tool wrote, or OpenImageIO's guess.
    pub named: Option<String>,
    /// A PNG's colour chunks (`sRGB`, `gAMA`, `cHRM`).
    pub png: Option<png::PngColour>,
}

impl Header {
    /// The evidence OpenImageIO reports of the open file (and its PNG chunks, which it drops).
    pub fn of_reader(reader: &ImageReader) -> Result<Header> {
        let info = reader.info();
        Ok(Header {
            path: info.path.clone(),
            format: info.format_name.clone(),
            size: (info.width(), info.height()),
            integer: info.pixel_format().is_integer(),
            icc: reader.bytes_attribute("ICCProfile")?,
            interop_id: reader.string_attribute("colorInteropID")?,
            chromaticities: reader
                .numeric_attribute("chromaticities")?
                .and_then(|c| c.try_into().ok()),
            aces_container: reader
                .numeric_attribute("acesImageContainerFlag")?
                .and_then(|v| v.first().copied()),
            named: info.declared_color_space.clone(),
            png: (info.format_name == "png")
                .then(|| png::colour_chunks(&info.path))
                .flatten(),
        })
    }

    /// The evidence of the file at `path` (`size`, integer or float pixels, as its pixels were
    /// decoded), read from the file without OpenImageIO: a PNG's colour chunks and `iCCP`, a
    /// JPEG's ICC profile, an OpenEXR header's colour attributes. Other formats declare
    /// nothing here. A PNG, JPEG or OpenEXR header that cannot be read is an error: what it
    /// declares is unknown.
    pub fn read(path: &Path, size: (u32, u32), integer: bool) -> Result<Header> {
        let unreadable = |what: &str, why: String| {
            Error::InMemory(format!(
                "{}: its {what}, which says what its colour is, cannot be read ({why})",
                path.display()
            ))
        };
        let mut header = Header {
            path: path.to_path_buf(),
            size,
            integer,
            ..Header::default()
        };
        let mut first = [0u8; 8];
        let mut file = specconv_atomic_file::open_file(path)
            .map_err(|e| unreadable("header", e.to_string()))?;
        let n =
            read_up_to(&mut file, &mut first).map_err(|e| unreadable("header", e.to_string()))?;
        match &first[..n] {
            [0x89, b'P', b'N', b'G', ..] => {
                header.format = "png".into();
                let chunks = png::colour_chunks(path)
                    .ok_or_else(|| unreadable("PNG chunks", "damaged or truncated".into()))?;
                header.png = Some(chunks);
                header.icc = png::icc_profile(path).map_err(|e| unreadable("PNG iCCP", e))?;
            }
            [0xff, 0xd8, ..] => {
                header.format = "jpeg".into();
                header.icc = jpeg_icc(path).map_err(|e| unreadable("JPEG ICC profile", e))?;
            }
            [0x76, 0x2f, 0x31, 0x01, ..] => {
                header.format = "openexr".into();
                let a = specconv_exr::colour_attributes(path)
                    .map_err(|e| unreadable("OpenEXR header", e.to_string()))?
                    .unwrap_or_default();
                header.chromaticities = a.chromaticities.map(|c| c.map(f64::from));
                header.aces_container = a.aces_container;
                header.interop_id = a.interop_id;
                header.named = a.colour_space;
            }
            _ => {}
        }
        Ok(header)
    }
}

impl Header {
    /// The colour-space name a tool wrote in `oiio:ColorSpace`; not OpenImageIO's own labels,
    /// which are no declarations: "Linear" for every OpenEXR file, "sRGB" for integer files
    /// by default, and anything for a PNG (whose chunks are read instead).
    pub fn declared_name(&self) -> Option<&str> {
        let name = self.named.as_deref()?;
        let guess = name.eq_ignore_ascii_case("linear")
            || name.eq_ignore_ascii_case("srgb")
            || self.format == "png";
        (!guess).then_some(name)
    }
}

/// Reads up to `buf.len()` bytes; how many.
fn read_up_to(f: &mut impl Read, buf: &mut [u8]) -> std::io::Result<usize> {
    let mut n = 0;
    while n < buf.len() {
        match f.read(&mut buf[n..])? {
            0 => break,
            k => n += k,
        }
    }
    Ok(n)
}

/// A JPEG's ICC profile: the `ICC_PROFILE` APP2 segments before the image data, joined in
/// their sequence order (ICC.1:2010, B.4); `None` without one.
fn jpeg_icc(path: &Path) -> std::result::Result<Option<Vec<u8>>, String> {
    let file = specconv_atomic_file::open_file(path).map_err(|e| e.to_string())?;
    let mut f = std::io::BufReader::new(file);
    let mut parts: Vec<(u8, Vec<u8>)> = Vec::new();
    f.seek(SeekFrom::Start(2)).map_err(|e| e.to_string())?;
    loop {
        let mut marker = [0u8; 2];
        if f.read_exact(&mut marker).is_err() || marker[0] != 0xff {
            break; // the end, or not a marker: no more header segments
        }
        // Start of scan, end of image: the header is over.
        if marker[1] == 0xda || marker[1] == 0xd9 {
            break;
        }
        let mut len = [0u8; 2];
        f.read_exact(&mut len).map_err(|e| e.to_string())?;
        let len = usize::from(u16::from_be_bytes(len)).saturating_sub(2);
        if marker[1] != 0xe2 || len < 14 {
            f.seek(SeekFrom::Current(len as i64))
                .map_err(|e| e.to_string())?;
            continue;
        }
        let mut data = vec![0u8; len];
        f.read_exact(&mut data).map_err(|e| e.to_string())?;
        if &data[..12] == b"ICC_PROFILE\0" {
            parts.push((data[12], data[14..].to_vec()));
            if parts.iter().map(|p| p.1.len()).sum::<usize>() > png::ICC_MAX {
                return Err(format!("an ICC profile over {} bytes", png::ICC_MAX));
            }
        }
    }
    if parts.is_empty() {
        return Ok(None);
    }
    parts.sort_by_key(|p| p.0);
    Ok(Some(parts.into_iter().flat_map(|p| p.1).collect()))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn crc(bytes: &[u8]) -> u32 {
        let mut c = !0u32;
        for &b in bytes {
            c ^= u32::from(b);
            for _ in 0..8 {
                c = if c & 1 == 1 {
                    0xedb8_8320 ^ (c >> 1)
                } else {
                    c >> 1
                };
            }
        }
        !c
    }

    /// A 2×1 8-bit RGB PNG with `chunks` before its image data, CRCs and all.
    fn png(chunks: &[(&[u8; 4], Vec<u8>)]) -> Vec<u8> {
        let chunk = |kind: &[u8; 4], data: &[u8]| {
            let mut v = (data.len() as u32).to_be_bytes().to_vec();
            let mut body = kind.to_vec();
            body.extend_from_slice(data);
            v.extend_from_slice(&body);
            v.extend_from_slice(&crc(&body).to_be_bytes());
            v
        };
        let mut out = vec![0x89, b'P', b'N', b'G', b'\r', b'\n', 0x1a, b'\n'];
        out.extend(chunk(b"IHDR", &[0, 0, 0, 2, 0, 0, 0, 1, 8, 2, 0, 0, 0]));
        for (kind, data) in chunks {
            out.extend(chunk(kind, data));
        }
        let rows = [0u8, 10, 20, 30, 200, 100, 50];
        out.extend(chunk(
            b"IDAT",
            &miniz_oxide::deflate::compress_to_vec_zlib(&rows, 6),
        ));
        out.extend(chunk(b"IEND", &[]));
        out
    }

    /// An OpenEXR file with colour attributes, written by the `exr` crate.
    fn exr(path: &Path) {
        use exr::prelude::*;
        let mut layer = Layer::new(
            (2, 1),
            LayerAttributes::default(),
            Encoding::UNCOMPRESSED,
            SpecificChannels::rgb(|_: Vec2<usize>| (0.25f32, 0.5f32, 0.75f32)),
        );
        let other = &mut layer.attributes.other;
        let text = |s: &str| Text::from(s);
        other.insert(
            text("colorInteropID"),
            AttributeValue::Text(text("lin_ap1_scene")),
        );
        other.insert(
            text("oiio:ColorSpace"),
            AttributeValue::Text(text("ACEScg")),
        );
        other.insert(text("acesImageContainerFlag"), AttributeValue::I32(1));
        let mut image = Image::from_layer(layer);
        image.attributes.chromaticities = Some(attribute::Chromaticities {
            red: Vec2(0.713, 0.293),
            green: Vec2(0.165, 0.830),
            blue: Vec2(0.128, 0.044),
            white: Vec2(0.32168, 0.33767),
        });
        image.write().to_file(path).unwrap();
    }

    /// The evidence the precedence weighs, as `a` and `b` give it.
    fn assert_same_evidence(a: &Header, b: &Header, file: &Path) {
        let f = file.display();
        assert_eq!(a.format == "png", b.format == "png", "{f}");
        assert_eq!((a.size, a.integer), (b.size, b.integer), "{f}");
        assert_eq!(a.icc, b.icc, "{f}");
        assert_eq!(a.interop_id, b.interop_id, "{f}");
        assert_eq!(a.chromaticities, b.chromaticities, "{f}");
        assert_eq!(a.aces_container, b.aces_container, "{f}");
        assert_eq!(a.declared_name(), b.declared_name(), "{f}");
        assert_eq!(a.png, b.png, "{f}");
    }

    /// What [`Header::read`] reads without OpenImageIO is what OpenImageIO reports of the
    /// same files (OpenImageIO 2.4 is the anchor): PNGs with `iCCP` (Debian's sRGB.icc and
    /// Adobe RGB profiles), `cHRM` and `gAMA`, and `sRGB`; an OpenEXR with chromaticities, the
    /// ACES flag, colorInteropID and oiio:ColorSpace; and the test images (8- and 16-bit PNG,
    /// a JPEG, half and float OpenEXR).
    #[test]
    fn the_header_read_without_openimageio_is_what_openimageio_reports() {
        let dir = std::env::temp_dir().join(format!("specconv-header-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let mut files = Vec::new();
        let icc = std::path::Path::new("/usr/share/color/icc");
        for (name, profile) in [
            ("srgb", "sRGB.icc"),
            ("adobe", "compatibleWithAdobeRGB1998.icc"),
        ] {
            let bytes = std::fs::read(icc.join(profile)).unwrap();
            let mut data = b"profile\0\0".to_vec();
            data.extend(miniz_oxide::deflate::compress_to_vec_zlib(&bytes, 6));
            let path = dir.join(format!("icc_{name}.png"));
            std::fs::write(&path, png(&[(b"iCCP", data)])).unwrap();
            files.push(path);
        }
        let chrm: Vec<u8> = [31270u32, 32900, 68000, 32000, 26500, 69000, 15000, 6000]
            .iter()
            .flat_map(|v| v.to_be_bytes())
            .collect();
        let gama = 55556u32.to_be_bytes().to_vec();
        let path = dir.join("chrm_gama.png");
        std::fs::write(&path, png(&[(b"gAMA", gama), (b"cHRM", chrm)])).unwrap();
        files.push(path);
        let path = dir.join("srgb_chunk.png");
        std::fs::write(&path, png(&[(b"sRGB", vec![0])])).unwrap();
        files.push(path);
        let path = dir.join("declared.exr");
        exr(&path);
        files.push(path);
        let images = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../testdata/images");
        for name in [
            "srgb8.png",
            "rgb16.png",
            "photo.jpg",
            "half_scanline.exr",
            "float_scanline.exr",
        ] {
            files.push(images.join(name));
        }
        for file in &files {
            let reader = ImageReader::open(file).unwrap();
            let by_oiio = Header::of_reader(&reader).unwrap();
            let ours = Header::read(file, by_oiio.size, by_oiio.integer).unwrap();
            assert_same_evidence(&by_oiio, &ours, file);
        }
        // The files carry the evidence they were made with: the comparison compares something.
        let declared = |i: usize| {
            let h = Header::of_reader(&ImageReader::open(&files[i]).unwrap()).unwrap();
            (
                h.icc.is_some(),
                h.png.clone(),
                h.chromaticities.is_some(),
                h.declared_name().map(str::to_owned),
            )
        };
        assert!(declared(0).0 && declared(1).0);
        assert!(declared(2)
            .1
            .is_some_and(|p| p.chrm.is_some() && p.gamma.is_some()));
        assert!(declared(4).2 && declared(4).3.as_deref() == Some("ACEScg"));
        std::fs::remove_dir_all(&dir).ok();
    }
}
