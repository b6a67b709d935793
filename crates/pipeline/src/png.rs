//! The colour chunks of a PNG file (`sRGB`, `gAMA`, `cHRM`), read from the file itself:
//! OpenImageIO 2.4 reports `sRGB` and `gAMA` only through its own colour-space guess and
//! drops `cHRM`. (`iCCP` comes through OpenImageIO as `ICCProfile`.)

use std::io::{Read, Seek, SeekFrom};
use std::path::Path;

/// The largest ICC profile read, from a PNG's iCCP or a JPEG's APP2 segments (a real one is a
/// few KB to a few MB).
pub(crate) const ICC_MAX: usize = 64 << 20;

/// What a PNG says about its colour; chunk values as the PNG specification (3rd ed., 11.3.2)
/// defines them.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct PngColour {
    /// An `sRGB` chunk: the image is sRGB (its rendering intent does not matter here).
    pub srgb: bool,
    /// `gAMA`: the encoding exponent (e.g. 0.45455), so stored = linear^gamma.
    pub gamma: Option<f64>,
    /// `cHRM`: white x, y, then red, green, blue x, y.
    pub chrm: Option<[f64; 8]>,
}

/// `gAMA` as the PNG specification writes it beside `sRGB` (3rd ed., 11.3.3.5: 45455).
pub const SRGB_GAMMA: f64 = 0.45455;

/// `cHRM` as the PNG specification writes it beside `sRGB` (white, red, green, blue x, y:
/// ITU-R BT.709 with the D65 white).
pub const SRGB_CHRM: [f64; 8] = [0.3127, 0.329, 0.64, 0.33, 0.3, 0.6, 0.15, 0.06];

impl PngColour {
    /// Whether `gAMA` and `cHRM` (each, where present) are what the PNG specification
    /// recommends writing beside an `sRGB` chunk, for decoders that do not know it: the
    /// same declaration, not a second one. Within 1e-4 for the exponent (45454 and 45455
    /// both round 1/2.2) and 5e-4 for the chromaticities.
    pub fn companions_of_srgb(&self) -> bool {
        let gamma = self.gamma.is_none_or(|g| (g - SRGB_GAMMA).abs() <= 1e-4);
        let chrm = self
            .chrm
            .is_none_or(|c| c.iter().zip(SRGB_CHRM).all(|(a, b)| (a - b).abs() <= 5e-4));
        self.srgb && gamma && chrm
    }
}

const SIGNATURE: [u8; 8] = [0x89, b'P', b'N', b'G', b'\r', b'\n', 0x1a, b'\n'];

/// The colour chunks of the PNG at `path`; `None` when it is not a PNG file or its chunks
/// before the image data cannot be read (OpenImageIO then says what is wrong).
pub fn colour_chunks(path: &Path) -> Option<PngColour> {
    let mut f = std::io::BufReader::new(specconv_atomic_file::open_file(path).ok()?);
    let mut sig = [0u8; 8];
    f.read_exact(&mut sig).ok()?;
    if sig != SIGNATURE {
        return None;
    }
    let mut out = PngColour::default();
    // Colour chunks must come before IDAT; stop there.
    loop {
        let mut head = [0u8; 8];
        f.read_exact(&mut head).ok()?;
        let len = u32::from_be_bytes([head[0], head[1], head[2], head[3]]);
        let kind = &head[4..8];
        if kind == b"IDAT" || kind == b"IEND" {
            return Some(out);
        }
        let wanted = matches!(kind, b"sRGB" | b"gAMA" | b"cHRM");
        if !wanted || len > 64 {
            f.seek(SeekFrom::Current(i64::from(len) + 4)).ok()?;
            continue;
        }
        let mut data = vec![0u8; len as usize];
        f.read_exact(&mut data).ok()?;
        f.seek(SeekFrom::Current(4)).ok()?; // CRC
        let be = |i: usize| -> Option<f64> {
            let b = data.get(i..i + 4)?;
            Some(f64::from(u32::from_be_bytes([b[0], b[1], b[2], b[3]])) / 100000.0)
        };
        match kind {
            b"sRGB" => out.srgb = true,
            b"gAMA" => out.gamma = be(0).filter(|g| *g > 0.0),
            _ => {
                let v: Option<Vec<f64>> = (0..8).map(|k| be(4 * k)).collect();
                out.chrm = v.and_then(|v| v.try_into().ok());
            }
        }
    }
}

/// A PNG's ICC profile (its `iCCP` chunk before the image data, PNG specification 3rd ed.,
/// 11.3.3.3: a name, a compression method 0 and a zlib stream), decompressed; `None`
/// without one. OpenImageIO reads it as `ICCProfile`; the RGB route reads it here.
pub fn icc_profile(path: &Path) -> Result<Option<Vec<u8>>, String> {
    let file = specconv_atomic_file::open_file(path).map_err(|e| e.to_string())?;
    let mut f = std::io::BufReader::new(file);
    let mut sig = [0u8; 8];
    if f.read_exact(&mut sig).is_err() || sig != SIGNATURE {
        return Ok(None);
    }
    loop {
        let mut head = [0u8; 8];
        f.read_exact(&mut head).map_err(|e| e.to_string())?;
        let len = u32::from_be_bytes([head[0], head[1], head[2], head[3]]) as usize;
        match &head[4..8] {
            b"IDAT" | b"IEND" => return Ok(None),
            b"iCCP" => {}
            _ => {
                f.seek_relative(len as i64 + 4).map_err(|e| e.to_string())?;
                continue;
            }
        }
        if len > ICC_MAX {
            return Err(format!("an iCCP chunk of {len} bytes"));
        }
        let mut data = vec![0u8; len];
        f.read_exact(&mut data).map_err(|e| e.to_string())?;
        let name_end = data
            .iter()
            .take(80)
            .position(|&b| b == 0)
            .ok_or("an iCCP chunk without its profile name")?;
        let stream = data
            .get(name_end + 2..)
            .ok_or("an iCCP chunk without a profile")?;
        let profile = miniz_oxide::inflate::decompress_to_vec_zlib_with_limit(stream, ICC_MAX)
            .map_err(|e| format!("its zlib stream does not decompress: {e}"))?;
        return Ok(Some(profile));
    }
}

/// Refuses a PNG file whose chunks run past its end or that ends before its `IEND` chunk,
/// from the chunk headers alone (seeking over their data): libpng, reading such a file,
/// prints its own "libpng error" line to the terminal before OpenImageIO's error comes back.
/// Anything that is not a PNG file passes.
pub fn check_whole(path: &Path) -> Result<(), specconv_exr::check::Problem> {
    let io = |source| specconv_exr::check::Problem::Io {
        path: path.to_path_buf(),
        source,
    };
    let file = specconv_atomic_file::open_file(path).map_err(|e| io(std::io::Error::other(e)))?;
    let size = file.metadata().map_err(io)?.len();
    let mut f = std::io::BufReader::new(file);
    let mut sig = [0u8; 8];
    if f.read_exact(&mut sig).is_err() || sig != SIGNATURE {
        return Ok(());
    }
    let mut at = 8u64;
    let damaged = |message: String| {
        Err(specconv_exr::check::Problem::Damaged {
            path: path.to_path_buf(),
            message,
        })
    };
    loop {
        let mut head = [0u8; 8];
        if at + 8 > size || f.read_exact(&mut head).is_err() {
            return damaged(format!(
                "the PNG file ends at byte {size}, before its IEND chunk: it is truncated \
                 (written or copied only in part); write it again"
            ));
        }
        let len = u64::from(u32::from_be_bytes([head[0], head[1], head[2], head[3]]));
        // Length, type, data, CRC.
        let end = at + 8 + len + 4;
        if end > size {
            let kind = String::from_utf8_lossy(&head[4..8]).into_owned();
            return damaged(format!(
                "the PNG file ends at byte {size}, inside its {kind} chunk (which ends at byte \
                 {end}): it is truncated (written or copied only in part); write it again"
            ));
        }
        if &head[4..8] == b"IEND" {
            return Ok(());
        }
        f.seek_relative(len as i64 + 4).map_err(io)?;
        at = end;
    }
}

/// The encoding a PNG at `path` declares for each of its text keywords, by OpenImageIO's
/// name for it: Latin-1 for `tEXt` and `zTXt`, UTF-8 for `iTXt` (PNG specification, 3rd ed.,
/// 11.3.3); the last chunk of a keyword decides, as it does OpenImageIO's value. Empty when
/// the file is not a PNG; only the keywords are read, never the text.
pub fn text_encodings(path: &Path) -> Vec<(Vec<u8>, crate::metadata::Encoding)> {
    use crate::metadata::Encoding;
    let mut out: Vec<(Vec<u8>, Encoding)> = Vec::new();
    let Some(mut f) = specconv_atomic_file::open_file(path)
        .ok()
        .map(std::io::BufReader::new)
    else {
        return out;
    };
    let mut sig = [0u8; 8];
    if f.read_exact(&mut sig).is_err() || sig != SIGNATURE {
        return out;
    }
    let mut head = [0u8; 8];
    while f.read_exact(&mut head).is_ok() && &head[4..8] != b"IEND" {
        let len = u32::from_be_bytes([head[0], head[1], head[2], head[3]]) as usize;
        let encoding = match &head[4..8] {
            b"tEXt" | b"zTXt" => Encoding::Latin1,
            b"iTXt" => Encoding::Utf8,
            _ => {
                if f.seek_relative(len as i64 + 4).is_err() {
                    break;
                }
                continue;
            }
        };
        // A keyword is 1 to 79 bytes and its terminator.
        let mut key = vec![0u8; len.min(80)];
        if f.read_exact(&mut key).is_err() || f.seek_relative((len - key.len()) as i64 + 4).is_err()
        {
            break;
        }
        let Some(end) = key.iter().position(|&b| b == 0) else {
            continue;
        };
        key.truncate(end);
        let name = oiio_name(key);
        out.retain(|(n, _)| *n != name);
        out.push((name, encoding));
    }
    out
}

/// OpenImageIO's name for a PNG text keyword: it reads `Description`, `Author` and `Title`
/// as `ImageDescription`, `Artist` and `DocumentName` (OpenImageIO 2.4, pngimageio).
fn oiio_name(keyword: Vec<u8>) -> Vec<u8> {
    let renamed: &[u8] = match keyword.to_ascii_lowercase().as_slice() {
        b"description" => b"ImageDescription",
        b"author" => b"Artist",
        b"title" => b"DocumentName",
        _ => return keyword,
    };
    renamed.to_vec()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn chunk(kind: &[u8; 4], data: &[u8]) -> Vec<u8> {
        let mut v = (data.len() as u32).to_be_bytes().to_vec();
        v.extend_from_slice(kind);
        v.extend_from_slice(data);
        v.extend_from_slice(&[0; 4]); // the CRC is not checked here
        v
    }

    #[test]
    fn a_png_cut_short_is_damaged_and_a_whole_one_passes() {
        let dir = std::env::temp_dir().join(format!("specconv-png-cut-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("c.png");
        let mut bytes = SIGNATURE.to_vec();
        bytes.extend(chunk(b"IHDR", &[0; 13]));
        bytes.extend(chunk(b"IDAT", &[7; 100]));
        bytes.extend(chunk(b"IEND", &[]));
        std::fs::write(&path, &bytes).unwrap();
        assert!(check_whole(&path).is_ok());
        for cut in [1, 12, 50, bytes.len() - 9] {
            std::fs::write(&path, &bytes[..bytes.len() - cut]).unwrap();
            let e = check_whole(&path).unwrap_err().to_string();
            assert!(e.contains("truncated"), "cut {cut}: {e}");
        }
        std::fs::write(&path, b"not a png").unwrap();
        assert!(check_whole(&path).is_ok());
        std::fs::remove_dir_all(&dir).ok();
    }

    #[test]
    fn reads_gama_and_chrm_before_idat_and_stops_there() {
        let dir = std::env::temp_dir().join(format!("specconv-png-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("c.png");
        let mut bytes = SIGNATURE.to_vec();
        bytes.extend(chunk(b"IHDR", &[0; 13]));
        bytes.extend(chunk(b"gAMA", &45455u32.to_be_bytes()));
        let chrm: Vec<u8> = [31270u32, 32900, 64000, 33000, 30000, 60000, 15000, 6000]
            .iter()
            .flat_map(|v| v.to_be_bytes())
            .collect();
        bytes.extend(chunk(b"cHRM", &chrm));
        bytes.extend(chunk(b"IDAT", &[1, 2, 3]));
        bytes.extend(chunk(b"sRGB", &[0])); // after IDAT: not a colour chunk any more
        std::fs::write(&path, bytes).unwrap();
        let c = colour_chunks(&path).unwrap();
        std::fs::remove_dir_all(&dir).ok();
        assert!(!c.srgb);
        assert_eq!(c.gamma, Some(0.45455));
        assert_eq!(
            c.chrm,
            Some([0.3127, 0.329, 0.64, 0.33, 0.3, 0.6, 0.15, 0.06])
        );
    }

    #[test]
    fn the_chunks_writers_put_beside_srgb_are_its_companions_and_others_are_not() {
        let written = PngColour {
            srgb: true,
            gamma: Some(0.45455),
            chrm: Some(SRGB_CHRM),
        };
        assert!(written.companions_of_srgb());
        assert!(PngColour {
            gamma: Some(0.45454),
            ..written.clone()
        }
        .companions_of_srgb());
        assert!(PngColour {
            chrm: None,
            ..written.clone()
        }
        .companions_of_srgb());
        // A gamma of 1.8, or P3 primaries, beside sRGB is a second, different declaration.
        assert!(!PngColour {
            gamma: Some(0.55556),
            ..written.clone()
        }
        .companions_of_srgb());
        let mut p3 = SRGB_CHRM;
        p3[2..4].copy_from_slice(&[0.68, 0.32]);
        assert!(!PngColour {
            chrm: Some(p3),
            ..written.clone()
        }
        .companions_of_srgb());
        // Without sRGB there is nothing to be a companion of.
        assert!(!PngColour {
            srgb: false,
            ..written
        }
        .companions_of_srgb());
    }

    #[test]
    fn text_keywords_have_their_chunk_s_encoding_the_last_one_deciding() {
        use crate::metadata::Encoding;
        let dir = std::env::temp_dir().join(format!("specconv-png-text-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("t.png");
        let mut bytes = SIGNATURE.to_vec();
        bytes.extend(chunk(b"IHDR", &[0; 13]));
        bytes.extend(chunk(b"tEXt", b"Copyright\0Caf\xe9"));
        bytes.extend(chunk(b"iTXt", b"Author\0\0\0\0\0\xe5\xb1\xb1"));
        bytes.extend(chunk(b"zTXt", b"Comment\0\0xyz"));
        bytes.extend(chunk(b"IDAT", &[1, 2, 3]));
        bytes.extend(chunk(b"iTXt", b"Copyright\0\0\0\0\0x"));
        bytes.extend(chunk(b"tEXt", b"no terminator"));
        bytes.extend(chunk(b"IEND", &[]));
        std::fs::write(&path, bytes).unwrap();
        let found = text_encodings(&path);
        std::fs::remove_dir_all(&dir).ok();
        assert_eq!(
            found,
            [
                (b"Artist".to_vec(), Encoding::Utf8),
                (b"Comment".to_vec(), Encoding::Latin1),
                (b"Copyright".to_vec(), Encoding::Utf8),
            ]
        );
        assert!(text_encodings(Path::new(file!())).is_empty());
    }

    #[test]
    fn not_a_png_is_none() {
        assert_eq!(colour_chunks(Path::new("/nonexistent.png")), None);
        assert_eq!(colour_chunks(Path::new(file!())), None);
    }
}
