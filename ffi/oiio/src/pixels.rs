//! What a read asks for and returns: a region of a level, and its pixels as `f32`.

/// A rectangle of pixels `[x0, x1) × [y0, y1)` of one level.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Region {
    /// First column.
    pub x0: u32,
    /// First row.
    pub y0: u32,
    /// One past the last column.
    pub x1: u32,
    /// One past the last row.
    pub y1: u32,
}

impl Region {
    /// Width in pixels, `x1 - x0`.
    pub fn width(&self) -> u32 {
        self.x1 - self.x0
    }
    /// Height in pixels, `y1 - y0`.
    pub fn height(&self) -> u32 {
        self.y1 - self.y0
    }
}

/// Pixels read from a level: `width × height × channels` interleaved `f32`, rows top down.
#[derive(Debug, Clone, PartialEq)]
pub struct Pixels {
    /// Width of the block, in pixels.
    pub width: u32,
    /// Height of the block, in pixels.
    pub height: u32,
    /// Values per pixel: every channel of the image, in file order.
    pub channels: usize,
    /// The values, `width × height × channels` of them.
    pub data: Vec<f32>,
}

impl Pixels {
    /// The channel values of pixel `(x, y)` of this block.
    pub fn pixel(&self, x: u32, y: u32) -> &[f32] {
        let i = (y as usize * self.width as usize + x as usize) * self.channels;
        &self.data[i..i + self.channels]
    }

    /// Copies `region` (in this block's coordinates) out into a new block.
    pub fn crop(&self, region: Region) -> Pixels {
        let row = region.width() as usize * self.channels;
        let mut data = Vec::with_capacity(row * region.height() as usize);
        for y in region.y0..region.y1 {
            let start = (y as usize * self.width as usize + region.x0 as usize) * self.channels;
            data.extend_from_slice(&self.data[start..start + row]);
        }
        Pixels {
            width: region.width(),
            height: region.height(),
            channels: self.channels,
            data,
        }
    }
}
