//! What an image is, as its header says: the pixel format and channels, the windows and MIP
//! levels of the subimage read, and its other subimages.

use std::fmt;
use std::path::PathBuf;

use crate::error::{Error, Result};

/// The stored data type of a channel, as OIIO names it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum PixelFormat {
    /// 8-bit unsigned integer (`uint8`).
    U8,
    /// 8-bit signed integer (`int8`).
    I8,
    /// 16-bit unsigned integer (`uint16`).
    U16,
    /// 16-bit signed integer (`int16`).
    I16,
    /// 32-bit unsigned integer (`uint` or `uint32`).
    U32,
    /// 32-bit signed integer (`int` or `int32`).
    I32,
    /// 16-bit float (`half`).
    Half,
    /// 32-bit float (`float`).
    Float,
    /// 64-bit float (`double`).
    Double,
    /// Any other type, by OpenImageIO's name for it.
    Other(String),
}

impl PixelFormat {
    pub(crate) fn from_oiio(name: &str) -> Self {
        match name {
            "uint8" => Self::U8,
            "int8" => Self::I8,
            "uint16" => Self::U16,
            "int16" => Self::I16,
            "uint" | "uint32" => Self::U32,
            "int" | "int32" => Self::I32,
            "half" => Self::Half,
            "float" => Self::Float,
            "double" => Self::Double,
            other => Self::Other(other.to_owned()),
        }
    }

    /// Integer formats store display-referred code values; float formats scene values.
    pub fn is_integer(&self) -> bool {
        matches!(
            self,
            Self::U8 | Self::I8 | Self::U16 | Self::I16 | Self::U32 | Self::I32
        )
    }
}

impl fmt::Display for PixelFormat {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::U8 => "uint8",
            Self::I8 => "int8",
            Self::U16 => "uint16",
            Self::I16 => "int16",
            Self::U32 => "uint32",
            Self::I32 => "int32",
            Self::Half => "half",
            Self::Float => "float",
            Self::Double => "double",
            Self::Other(s) => s,
        })
    }
}

/// One channel of the image.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Channel {
    /// The channel's name as OpenImageIO reports it (`R`, `A`, `Y`, ...).
    pub name: String,
    /// The channel's stored data type (it is read as `f32` whatever it is).
    pub format: PixelFormat,
}

/// A rectangle of the file's pixel space: its origin (which may be negative) and size.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Window {
    /// Left edge (first column).
    pub x: i32,
    /// Top edge (first row).
    pub y: i32,
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
}

/// Geometry of one MIP level (level 0 is full resolution).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Level {
    /// Width of the data window (the stored pixels), in pixels.
    pub width: u32,
    /// Height of the data window, in pixels.
    pub height: u32,
    /// Data window origin in the file's pixel space: its left edge.
    pub x: i32,
    /// Data window origin in the file's pixel space: its top edge.
    pub y: i32,
    /// The display window ("full" window) of the level, as OpenImageIO reports it. OpenEXR
    /// has one per file (part), which OIIO gives level 0; other levels get their data window.
    pub display: Window,
    /// Tile width and height, `None` for scanline storage.
    pub tile: Option<(u32, u32)>,
}

impl Level {
    /// The data window: where the stored pixels sit in the file's pixel space.
    pub fn data(&self) -> Window {
        Window {
            x: self.x,
            y: self.y,
            width: self.width,
            height: self.height,
        }
    }

    /// Number of tiles across and down (`None` for scanline storage).
    pub fn tile_count(&self) -> Option<(u32, u32)> {
        self.tile
            .map(|(tw, th)| (self.width.div_ceil(tw), self.height.div_ceil(th)))
    }
}

/// Everything the reader learns from the header.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ImageInfo {
    /// The path the image was opened from.
    pub path: PathBuf,
    /// OIIO's name of the format plugin ("openexr", "tiff", "png", ...).
    pub format_name: String,
    /// The channels of the subimage (of its level 0), in file order.
    pub channels: Vec<Channel>,
    /// Index of the alpha channel, if the file marks one.
    pub alpha_channel: Option<usize>,
    /// Every MIP level; a plain image has one.
    pub levels: Vec<Level>,
    /// Subimages (parts) in the file.
    pub subimages: u32,
    /// The subimage described and read (0 unless selected).
    pub subimage: u32,
    /// Each subimage's name (an OpenEXR part's `name`), empty where it has none.
    pub subimage_names: Vec<String>,
    /// The colour space the file declares (`oiio:ColorSpace`), if any. OpenImageIO also
    /// puts its own guess here ("Linear" for every OpenEXR file, "sRGB" for most integer
    /// formats), so it is a declaration only where the format can store one.
    pub declared_color_space: Option<String>,
    /// The colour is stored unassociated from alpha (straight: PNG, some TIFFs); it is read
    /// as stored, not premultiplied.
    pub unassociated_alpha: bool,
}

impl ImageInfo {
    /// Width of level 0 (full resolution), in pixels.
    pub fn width(&self) -> u32 {
        self.levels[0].width
    }
    /// Height of level 0 (full resolution), in pixels.
    pub fn height(&self) -> u32 {
        self.levels[0].height
    }
    /// The pixel format of the first channel; see [`ImageInfo::channels`] for mixed files.
    pub fn pixel_format(&self) -> &PixelFormat {
        &self.channels[0].format
    }
    /// Tile width and height of level 0, `None` for scanline storage.
    pub fn tile_size(&self) -> Option<(u32, u32)> {
        self.levels[0].tile
    }

    /// `N` or `NAME`: the subimage with that index or (part) name.
    pub fn find_subimage(&self, which: &str) -> Result<u32> {
        let found = match which.parse::<u32>() {
            Ok(n) => (n < self.subimages).then_some(n),
            Err(_) => self
                .subimage_names
                .iter()
                .position(|n| n == which)
                .map(|i| i as u32),
        };
        found.ok_or_else(|| Error::InvalidRequest {
            path: self.path.clone(),
            message: format!(
                "it has no subimage {which:?}; its subimages are {}",
                self.describe_subimages()
            ),
        })
    }

    /// `0 'beauty', 1 'albedo'`: every subimage, for messages.
    pub fn describe_subimages(&self) -> String {
        describe_subimages(self.subimages, &self.subimage_names)
    }
}

/// `0 'beauty', 1 'albedo'`: `count` subimages by index and (where they have one) name.
pub fn describe_subimages(count: u32, names: &[String]) -> String {
    (0..count as usize)
        .map(|i| match names.get(i).filter(|n| !n.is_empty()) {
            Some(name) => format!("{i} '{name}'"),
            None => i.to_string(),
        })
        .collect::<Vec<_>>()
        .join(", ")
}
