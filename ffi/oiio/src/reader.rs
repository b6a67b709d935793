//! An open image file: its header read once, pixels read by tile, rows, region or level, and
//! its attributes.

use std::ffi::CString;
use std::fmt;
use std::ops::Range;
use std::path::Path;
use std::ptr::NonNull;

use oiio_sys as sys;

use crate::error::{Error, Result};
use crate::info::{Channel, ImageInfo, Level, PixelFormat, Window};
use crate::pixels::{Pixels, Region};
use crate::shim::{last_error, path_to_cstring, shim_str};

/// An open image file. Closing happens on drop.
pub struct ImageReader {
    shim: &'static sys::SpecconvOiio,
    raw: NonNull<sys::specconv_oiio_input>,
    info: ImageInfo,
}

// SAFETY: the shim's handle owns its OIIO ImageInput and nothing thread-bound; it may move
// between threads. It is not Sync: reads take &mut self, one thread at a time.
unsafe impl Send for ImageReader {}

impl Drop for ImageReader {
    fn drop(&mut self) {
        // SAFETY: raw came from specconv_oiio_open and is freed exactly once, here.
        unsafe { self.shim.specconv_oiio_close(self.raw.as_ptr()) }
    }
}

impl fmt::Debug for ImageReader {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("ImageReader")
            .field("info", &self.info)
            .finish()
    }
}

impl ImageReader {
    /// Opens `path` and reads its header.
    pub fn open(path: impl AsRef<Path>) -> Result<Self> {
        let path = path.as_ref().to_path_buf();
        // OIIO's message for a missing file varies by plugin; say it plainly ourselves. A
        // special file (/dev/zero, a FIFO, a terminal) would keep the format probes reading or
        // waiting for ever: refused by kind before OpenImageIO sees it. One `stat` for both.
        match specconv_atomic_file::Kind::of(&path) {
            specconv_atomic_file::Kind::File => {}
            specconv_atomic_file::Kind::Missing => return Err(Error::NotFound { path }),
            kind => {
                return Err(Error::Open {
                    path,
                    message: format!("it is {kind}, not a file"),
                })
            }
        }
        let Some(c_path) = path_to_cstring(&path) else {
            return Err(Error::Open {
                path,
                message: "the path contains a NUL byte".into(),
            });
        };
        let shim = match sys::shim() {
            Ok(shim) => shim,
            Err(source) => return Err(Error::Unavailable { path, source }),
        };
        let mut raw = std::ptr::null_mut();
        // SAFETY: c_path is a valid C string for the call; raw receives an owned handle.
        let status = unsafe { shim.specconv_oiio_open(c_path.as_ptr(), &mut raw) } as u32;
        if status != sys::SPECCONV_OIIO_OK {
            let message = last_error(shim);
            return Err(match status {
                sys::SPECCONV_OIIO_ERR_UNSUPPORTED => Error::Unsupported { path, message },
                sys::SPECCONV_OIIO_ERR_OPEN => Error::Open { path, message },
                _ => Error::Internal { path, message },
            });
        }
        let Some(raw) = NonNull::new(raw) else {
            return Err(Error::Internal {
                path,
                message: "the shim returned no handle".into(),
            });
        };
        let mut reader = ImageReader {
            shim,
            raw,
            info: ImageInfo {
                path,
                format_name: String::new(),
                channels: Vec::new(),
                alpha_channel: None,
                levels: Vec::new(),
                subimages: 1,
                subimage: 0,
                subimage_names: Vec::new(),
                declared_color_space: None,
                unassociated_alpha: false,
            },
        };
        reader.info = reader.read_info()?;
        Ok(reader)
    }

    /// Opens the same file again, on the same subimage: a second, independent reader for
    /// another worker.
    pub fn reopen(&self) -> Result<Self> {
        let mut again = Self::open(&self.info.path)?;
        if self.info.subimage != 0 {
            again.select_subimage(self.info.subimage)?;
        }
        Ok(again)
    }

    /// Makes `subimage` the one described by [`ImageReader::info`] and read.
    pub fn select_subimage(&mut self, subimage: u32) -> Result<()> {
        if subimage >= self.info.subimages {
            return Err(self.invalid(format!(
                "it has no subimage {subimage}; its subimages are {}",
                self.info.describe_subimages()
            )));
        }
        let index = i32::try_from(subimage).unwrap_or(i32::MAX);
        // SAFETY: live handle; the shim checks the index.
        self.check(unsafe {
            self.shim
                .specconv_oiio_select_subimage(self.raw.as_ptr(), index)
        })?;
        self.info = self.read_info()?;
        self.info.subimage = subimage;
        Ok(())
    }

    /// What the header says about the file and its selected subimage.
    pub fn info(&self) -> &ImageInfo {
        &self.info
    }

    fn status_error(&self, status: u32) -> Error {
        let path = self.info.path.clone();
        let message = last_error(self.shim);
        match status {
            sys::SPECCONV_OIIO_ERR_READ => Error::Read { path, message },
            sys::SPECCONV_OIIO_ERR_ARGUMENT => Error::InvalidRequest { path, message },
            sys::SPECCONV_OIIO_ERR_UNSUPPORTED => Error::Unsupported { path, message },
            _ => Error::Internal { path, message },
        }
    }

    fn check(&self, status: i32) -> Result<()> {
        // The C enum's values are small and non-negative; the functions return int32_t.
        match status as u32 {
            sys::SPECCONV_OIIO_OK => Ok(()),
            other => Err(self.status_error(other)),
        }
    }

    fn read_info(&self) -> Result<ImageInfo> {
        let (shim, raw) = (self.shim, self.raw.as_ptr());
        // SAFETY (this block): raw is a live handle; out-pointers point at locals; strings
        // returned are owned by the handle and copied before it can go away.
        let format_name = shim_str(unsafe { shim.specconv_oiio_format_name(raw) });
        let subimages = unsafe { shim.specconv_oiio_num_subimages(raw) }.max(1) as u32;
        let nlevels = unsafe { shim.specconv_oiio_num_levels(raw) };
        let mut levels = Vec::with_capacity(nlevels.max(0) as usize);
        let mut top = None;
        for level in 0..nlevels {
            let mut l = std::mem::MaybeUninit::<sys::specconv_oiio_level>::zeroed();
            self.check(unsafe { shim.specconv_oiio_level_info(raw, level, l.as_mut_ptr()) })?;
            // SAFETY: the shim filled every field on success (and zeroed() covers the rest).
            let l = unsafe { l.assume_init() };
            if l.width <= 0 || l.height <= 0 || l.nchannels <= 0 {
                return Err(Error::Unsupported {
                    path: self.info.path.clone(),
                    message: format!(
                        "MIP level {level} is empty ({}x{}, {} channels)",
                        l.width, l.height, l.nchannels
                    ),
                });
            }
            let tile = (l.tile_width > 0 && l.tile_height > 0)
                .then_some((l.tile_width as u32, l.tile_height as u32));
            levels.push(Level {
                width: l.width as u32,
                height: l.height as u32,
                x: l.x,
                y: l.y,
                display: Window {
                    x: l.full_x,
                    y: l.full_y,
                    width: l.full_width.max(0) as u32,
                    height: l.full_height.max(0) as u32,
                },
                tile,
            });
            top.get_or_insert(l);
        }
        let Some(top) = top else {
            return Err(Error::Open {
                path: self.info.path.clone(),
                message: "the file holds no image".into(),
            });
        };
        let mut channels = Vec::with_capacity(top.nchannels as usize);
        for c in 0..top.nchannels {
            let mut name = std::ptr::null();
            let mut format = std::ptr::null();
            self.check(unsafe { shim.specconv_oiio_channel_name(raw, c, &mut name) })?;
            self.check(unsafe { shim.specconv_oiio_channel_format(raw, c, &mut format) })?;
            channels.push(Channel {
                name: shim_str(name),
                format: PixelFormat::from_oiio(&shim_str(format)),
            });
        }
        let alpha_channel = usize::try_from(top.alpha_channel)
            .ok()
            .filter(|&a| a < channels.len());
        let mut subimage_names = Vec::with_capacity(subimages as usize);
        for i in 0..subimages as i32 {
            let mut name = std::ptr::null();
            self.check(unsafe { shim.specconv_oiio_subimage_name(raw, i, &mut name) })?;
            subimage_names.push(shim_str(name));
        }
        Ok(ImageInfo {
            path: self.info.path.clone(),
            format_name,
            channels,
            alpha_channel,
            levels,
            subimages,
            subimage: self.info.subimage,
            subimage_names,
            declared_color_space: self
                .string_attribute("oiio:ColorSpace")?
                .filter(|s| !s.is_empty()),
            unassociated_alpha: alpha_channel.is_some()
                && self
                    .numeric_attribute("oiio:UnassociatedAlpha")?
                    .is_some_and(|v| v.first().is_some_and(|&a| a != 0.0)),
        })
    }

    /// A numeric attribute of the file's header (top level) as its values in order: a
    /// scalar, an array, or an aggregate such as OpenEXR's `chromaticities` (8 values).
    pub fn numeric_attribute(&self, name: &str) -> Result<Option<Vec<f64>>> {
        self.attribute(name, 0, self.shim.specconv_oiio_numeric_attribute)
    }

    /// A byte-array attribute of the file's header (top level), such as `ICCProfile`.
    pub fn bytes_attribute(&self, name: &str) -> Result<Option<Vec<u8>>> {
        self.attribute(name, 0, self.shim.specconv_oiio_bytes_attribute)
    }

    /// A string attribute of the file's header (top level), if present (bytes that are not
    /// UTF-8 replaced: [`ImageReader::string_attribute_bytes`] has them as they are).
    pub fn string_attribute(&self, name: &str) -> Result<Option<String>> {
        Ok(self
            .string_attribute_bytes(name.as_bytes())?
            .map(|bytes| String::from_utf8_lossy(&bytes).into_owned()))
    }

    /// A string attribute of the file's header (top level) as OpenImageIO holds its bytes,
    /// if present; `name` as [`ImageReader::string_attribute_names_raw`] has it.
    pub fn string_attribute_bytes(&self, name: &[u8]) -> Result<Option<Vec<u8>>> {
        // One more byte for the terminator the shim writes.
        let Some(mut buf) = self.attribute(name, 1, self.shim.specconv_oiio_string_attribute)?
        else {
            return Ok(None);
        };
        buf.pop();
        Ok(Some(buf.into_iter().map(|c| c as u8).collect()))
    }

    /// The length in bytes of a string attribute of the file's header (top level), if
    /// present, without copying its value out; `name` as
    /// [`ImageReader::string_attribute_names_raw`] has it.
    pub fn string_attribute_len(&self, name: &[u8]) -> Result<Option<usize>> {
        let Ok(c_name) = CString::new(name) else {
            return Ok(None);
        };
        let mut len = -1i64;
        let read = self.shim.specconv_oiio_string_attribute;
        // SAFETY: live handle, valid C string; a null buffer only asks for the length.
        self.check(unsafe {
            read(
                self.raw.as_ptr(),
                c_name.as_ptr(),
                std::ptr::null_mut(),
                0,
                &mut len,
            )
        })?;
        Ok(usize::try_from(len).ok())
    }

    /// The names of the file's string attributes (top level), in the header's order (bytes
    /// that are not UTF-8 replaced).
    pub fn string_attribute_names(&self) -> Result<Vec<String>> {
        Ok(self
            .string_attribute_names_raw()?
            .iter()
            .map(|n| String::from_utf8_lossy(n).into_owned())
            .collect())
    }

    /// The names of the file's string attributes (top level), in the header's order, as
    /// OpenImageIO holds their bytes (a PNG's keywords are Latin-1).
    pub fn string_attribute_names_raw(&self) -> Result<Vec<Vec<u8>>> {
        let raw = self.raw.as_ptr();
        let mut len = -1i64;
        let list = self.shim.specconv_oiio_string_attribute_names;
        // SAFETY: live handle; a null buffer only asks for the length.
        self.check(unsafe { list(raw, std::ptr::null_mut(), 0, &mut len) })?;
        let mut buf = vec![0 as std::os::raw::c_char; usize::try_from(len).unwrap_or(0)];
        // SAFETY: buf holds the length told to the shim.
        self.check(unsafe { list(raw, buf.as_mut_ptr(), buf.len(), &mut len) })?;
        let bytes: Vec<u8> = buf.into_iter().map(|c| c as u8).collect();
        Ok(bytes
            .split(|&b| b == 0)
            .filter(|n| !n.is_empty())
            .map(<[u8]>::to_vec)
            .collect())
    }

    /// The shim's two calls for a header attribute: its length (a null buffer), then its
    /// values into a buffer of that length plus `extra`. None when absent or not of that kind.
    fn attribute<T: Copy + Default>(
        &self,
        name: impl Into<Vec<u8>>,
        extra: usize,
        read: unsafe extern "C" fn(
            *const sys::specconv_oiio_input,
            *const std::os::raw::c_char,
            *mut T,
            usize,
            *mut i64,
        ) -> i32,
    ) -> Result<Option<Vec<T>>> {
        let Ok(c_name) = CString::new(name) else {
            return Ok(None);
        };
        let raw = self.raw.as_ptr();
        let mut len = -1i64;
        // SAFETY: live handle, valid C string; a null buffer only asks for the length.
        self.check(unsafe { read(raw, c_name.as_ptr(), std::ptr::null_mut(), 0, &mut len) })?;
        let Ok(n) = usize::try_from(len) else {
            return Ok(None);
        };
        let mut values = vec![T::default(); n + extra];
        // SAFETY: values holds n + extra elements, the length told to the shim.
        self.check(unsafe {
            read(
                raw,
                c_name.as_ptr(),
                values.as_mut_ptr(),
                values.len(),
                &mut len,
            )
        })?;
        Ok(Some(values))
    }

    /// MIP level `level`'s size and layout, or why it does not exist.
    fn level(&self, level: usize) -> Result<Level> {
        self.info
            .levels
            .get(level)
            .copied()
            .ok_or_else(|| Error::InvalidRequest {
                path: self.info.path.clone(),
                message: format!(
                    "MIP level {level} does not exist; the file has {} (0 to {})",
                    self.info.levels.len(),
                    self.info.levels.len() - 1
                ),
            })
    }

    fn invalid(&self, message: String) -> Error {
        Error::InvalidRequest {
            path: self.info.path.clone(),
            message,
        }
    }

    /// A zeroed buffer for a block, refusing (rather than aborting) when it cannot exist.
    fn buffer(&self, width: u32, height: u32) -> Result<Pixels> {
        let channels = self.info.channels.len();
        let too_large = || Error::TooLarge {
            path: self.info.path.clone(),
            width,
            height,
            channels,
        };
        let len = (width as usize)
            .checked_mul(height as usize)
            .and_then(|n| n.checked_mul(channels))
            .ok_or_else(too_large)?;
        let mut data = Vec::new();
        data.try_reserve_exact(len).map_err(|_| too_large())?;
        data.resize(len, 0.0);
        Ok(Pixels {
            width,
            height,
            channels,
            data,
        })
    }

    /// Reads tile `(tx, ty)` (tile indices, not pixels) of a tiled level. Edge tiles are
    /// cut to the image.
    pub fn read_tile(&mut self, level: usize, tx: u32, ty: u32) -> Result<Pixels> {
        let l = self.level(level)?;
        let Some((tw, th)) = l.tile else {
            return Err(self.invalid(
                "the image is stored as scanlines, not tiles; read rows or regions instead".into(),
            ));
        };
        let (nx, ny) = l.tile_count().unwrap_or((0, 0));
        if tx >= nx || ty >= ny {
            return Err(self.invalid(format!(
                "tile ({tx}, {ty}) is outside MIP level {level}, which has {nx}x{ny} tiles"
            )));
        }
        let region = Region {
            x0: tx * tw,
            y0: ty * th,
            x1: ((tx + 1) * tw).min(l.width),
            y1: ((ty + 1) * th).min(l.height),
        };
        self.read_tiles_aligned(level, region)
    }

    fn read_tiles_aligned(&mut self, level: usize, r: Region) -> Result<Pixels> {
        let shim = self.shim;
        self.read_block(r.width(), r.height(), |raw, nch, out, len| {
            // SAFETY: live handle; `out` holds `len` = width*height*channels floats, and the
            // shim writes no more than the region asks for.
            unsafe {
                shim.specconv_oiio_read_tiles(
                    raw,
                    level as i32,
                    r.x0 as i32,
                    r.x1 as i32,
                    r.y0 as i32,
                    r.y1 as i32,
                    0,
                    nch,
                    out,
                    len,
                )
            }
        })
    }

    /// A buffer for a `width` × `height` block of every channel, filled by one shim call.
    fn read_block(
        &mut self,
        width: u32,
        height: u32,
        read: impl FnOnce(*mut sys::specconv_oiio_input, i32, *mut f32, usize) -> i32,
    ) -> Result<Pixels> {
        let mut px = self.buffer(width, height)?;
        let status = read(
            self.raw.as_ptr(),
            px.channels as i32,
            px.data.as_mut_ptr(),
            px.data.len(),
        );
        self.check(status)?;
        Ok(px)
    }

    /// Reads whole rows `rows` of a level (tiled levels too, through their tiles).
    pub fn read_scanlines(&mut self, level: usize, rows: Range<u32>) -> Result<Pixels> {
        let l = self.level(level)?;
        if rows.start >= rows.end || rows.end > l.height {
            return Err(self.invalid(format!(
                "rows {}..{} are outside MIP level {level}, which has {} rows",
                rows.start, rows.end, l.height
            )));
        }
        if l.tile.is_some() {
            let region = Region {
                x0: 0,
                y0: rows.start,
                x1: l.width,
                y1: rows.end,
            };
            return self.read_region(level, region);
        }
        let shim = self.shim;
        self.read_block(l.width, rows.end - rows.start, |raw, nch, out, len| {
            // SAFETY: as in read_tiles_aligned; the buffer covers full rows of the level.
            unsafe {
                shim.specconv_oiio_read_scanlines(
                    raw,
                    level as i32,
                    rows.start as i32,
                    rows.end as i32,
                    0,
                    nch,
                    out,
                    len,
                )
            }
        })
    }

    /// Reads any rectangle of a level, from whole tiles or whole rows as the file is
    /// stored, cropped to `region`.
    pub fn read_region(&mut self, level: usize, region: Region) -> Result<Pixels> {
        let l = self.level(level)?;
        if region.x0 >= region.x1
            || region.y0 >= region.y1
            || region.x1 > l.width
            || region.y1 > l.height
        {
            return Err(self.invalid(format!(
                "region [{}, {}) x [{}, {}) is outside MIP level {level} ({}x{})",
                region.x0, region.x1, region.y0, region.y1, l.width, l.height
            )));
        }
        let covering = match l.tile {
            Some((tw, th)) => Region {
                x0: region.x0 / tw * tw,
                y0: region.y0 / th * th,
                x1: region.x1.div_ceil(tw).saturating_mul(tw).min(l.width),
                y1: region.y1.div_ceil(th).saturating_mul(th).min(l.height),
            },
            None => Region {
                x0: 0,
                y0: region.y0,
                x1: l.width,
                y1: region.y1,
            },
        };
        let block = match l.tile {
            Some(_) => self.read_tiles_aligned(level, covering)?,
            None => self.read_scanlines(level, covering.y0..covering.y1)?,
        };
        if covering == region {
            return Ok(block);
        }
        Ok(block.crop(Region {
            x0: region.x0 - covering.x0,
            y0: region.y0 - covering.y0,
            x1: region.x1 - covering.x0,
            y1: region.y1 - covering.y0,
        }))
    }

    /// Reads a whole level.
    pub fn read_level(&mut self, level: usize) -> Result<Pixels> {
        let l = self.level(level)?;
        self.read_region(
            level,
            Region {
                x0: 0,
                y0: 0,
                x1: l.width,
                y1: l.height,
            },
        )
    }
}
