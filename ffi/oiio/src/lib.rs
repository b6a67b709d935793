//! Reading images through OpenImageIO: any format OIIO has a plugin for (OpenEXR, TIFF
//! and `.tx`, PNG, JPEG, Radiance HDR, ...), any MIP level, by tile or by rows, always
//! converted to `f32`.
//!
//! An [`ImageReader`] owns one OIIO `ImageInput`. It is `Send` but not `Sync`: each
//! worker opens its own (see [`ImageReader::reopen`]), so tiles decode in parallel
//! without contending for one file handle. The header (every MIP level's geometry,
//! channels, declared colour space) is read once at open and kept in [`ImageInfo`].
//!
//! Coordinates are pixel offsets from the data window origin of the level, so `(0, 0)` is
//! the first stored pixel whatever the file's data window is; [`Level::data`] and
//! [`Level::display`] say where that sits in the file's pixel space.
//!
//! Files with several subimages (OpenEXR parts) are read one subimage at a time: subimage 0
//! unless [`ImageReader::select_subimage`] picks another.
//!
//! All `unsafe` is in this file and only calls the C shim of `oiio-sys`, which catches
//! every C++ exception and reports failures as status codes. The shim, and OpenImageIO with
//! it, is loaded when the first image is opened ([`oiio_sys::shim`]), from the file installed
//! beside the program or module, not when the program starts; where it cannot be, opening says
//! so, naming where it looked ([`Error::Unavailable`]).
#![warn(missing_docs)]

use std::ffi::{CStr, CString};
use std::fmt;
use std::ops::Range;
use std::path::{Path, PathBuf};
use std::ptr::NonNull;

use oiio_sys as sys;

/// What can go wrong opening or reading an image.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// The file does not exist (checked before OpenImageIO is asked).
    #[error("{}: no such file", path.display())]
    NotFound {
        /// The path asked for.
        path: PathBuf,
    },
    /// The file cannot be opened as an image or its header cannot be read: OpenImageIO fails
    /// to open it, it is a directory, its path holds a NUL byte, or it holds no image.
    #[error("{}: cannot be read as an image: {message}", path.display())]
    Open {
        /// The image's path.
        path: PathBuf,
        /// OpenImageIO's message, or specconv's where it refused the file itself.
        message: String,
    },
    /// A valid image of a kind specconv does not read: deep or volume (3D) images, or a MIP
    /// level without pixels or channels.
    #[error("{}: {message}", path.display())]
    Unsupported {
        /// The image's path.
        path: PathBuf,
        /// What the image is that cannot be read.
        message: String,
    },
    /// Pixel data cannot be read: a corrupt or truncated file, or an I/O error.
    #[error("{}: reading pixels failed (is the file truncated or corrupt?): {message}", path.display())]
    Read {
        /// The image's path.
        path: PathBuf,
        /// OpenImageIO's message.
        message: String,
    },
    /// The caller asked for what the image does not have: a subimage, MIP level, tile, rows
    /// or region outside it, or tiles of a scanline image.
    #[error("{}: {message}", path.display())]
    InvalidRequest {
        /// The image's path.
        path: PathBuf,
        /// What was asked for and what the image has, or the shim's message where it refused
        /// the call.
        message: String,
    },
    /// The buffer for a block of pixels cannot be allocated (or its size overflows `usize`).
    #[error("{}: {width}x{height}x{channels} pixels do not fit in memory", path.display())]
    TooLarge {
        /// The image's path.
        path: PathBuf,
        /// Width of the block, in pixels.
        width: u32,
        /// Height of the block, in pixels.
        height: u32,
        /// Channels per pixel (every channel of the image).
        channels: usize,
    },
    /// OpenImageIO raised a C++ exception (caught by the shim), or the shim failed in a way
    /// this crate does not expect there.
    #[error("{}: OpenImageIO failed unexpectedly: {message}", path.display())]
    Internal {
        /// The image's path.
        path: PathBuf,
        /// The shim's message (the exception's text, for an exception).
        message: String,
    },
    /// OpenImageIO's libraries could not be loaded (at the first image opened).
    #[error("{}: cannot be read: {source}", path.display())]
    Unavailable {
        /// The image's path.
        path: PathBuf,
        /// Why the shim or OpenImageIO could not be loaded.
        source: LoadError,
    },
}

/// A result whose error is, by default, this crate's [`Error`].
pub type Result<T, E = Error> = std::result::Result<T, E>;

pub use sys::LoadError;

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
    fn from_oiio(name: &str) -> Self {
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

/// Ends the process with `code` once standard output and error are flushed (Rust's streams
/// and every C stream), without running the C++ libraries' exit-time destructors. Debian's
/// OpenImageIO loads log4cplus (through DCMTK), whose thread cleanup at exit
/// (`log4cplus::threadCleanup`) dereferenced null now and then: a refusal that was exit 1
/// ended in SIGSEGV. A command's files are committed or removed before it returns its code,
/// so nothing is left to those destructors.
pub fn exit(code: i32) -> ! {
    use std::io::Write;
    let _ = std::io::stdout().flush();
    let _ = std::io::stderr().flush();
    // SAFETY: fflush(NULL) flushes every open C output stream; _exit then ends the process
    // at once, which is what is wanted.
    unsafe {
        libc::fflush(std::ptr::null_mut());
        libc::_exit(code)
    }
}

/// The shim's message for the last failure on this thread.
fn last_error(shim: &sys::SpecconvOiio) -> String {
    // SAFETY: the shim returns a NUL-terminated thread-local string, valid until the next
    // shim call on this thread; it is copied at once.
    unsafe { CStr::from_ptr(shim.specconv_oiio_last_error()) }
        .to_string_lossy()
        .trim()
        .to_owned()
}

/// Borrows a NUL-terminated string that the shim keeps alive as long as the input.
fn shim_str(ptr: *const std::os::raw::c_char) -> String {
    if ptr.is_null() {
        return String::new();
    }
    // SAFETY: non-null pointers from the shim point at NUL-terminated strings owned by an
    // open input, which outlives this call; the contents are copied.
    unsafe { CStr::from_ptr(ptr) }
        .to_string_lossy()
        .into_owned()
}

#[cfg(unix)]
fn path_to_cstring(path: &Path) -> Option<CString> {
    use std::os::unix::ffi::OsStrExt;
    CString::new(path.as_os_str().as_bytes()).ok()
}

#[cfg(not(unix))]
fn path_to_cstring(path: &Path) -> Option<CString> {
    CString::new(path.to_str()?).ok()
}

/// How [`make_texture`] stores the texture.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TextureSpec {
    /// The subimage of the input to write through.
    pub subimage: u32,
    /// Tile width and height.
    pub tile: (u32, u32),
    /// OpenEXR compression, as OpenImageIO names it (`zip`, `piz`, …).
    pub compression: String,
    /// String attributes added to the header.
    pub attributes: Vec<(String, String)>,
}

/// Writes `input` through, its values unconverted, as a tiled, MIP-mapped OpenEXR texture at
/// `output` with OpenImageIO's `ImageBufAlgo::make_texture` (what maketx runs): box-filtered
/// levels, the input's metadata and wrap modes kept, `spec`'s attributes added. OpenImageIO
/// writes its own temporary beside `output` (`output`'s extension replaced by
/// `.XXXXXXXX.temp` and the extension) and renames it over `output`, so `output` should be a
/// temporary path of the caller's, published when this returns.
pub fn make_texture(input: &Path, output: &Path, spec: &TextureSpec) -> Result<()> {
    let path = input.to_path_buf();
    let refuse = |message: &str| Error::InvalidRequest {
        path: path.clone(),
        message: message.into(),
    };
    let (Some(c_in), Some(c_out)) = (path_to_cstring(input), path_to_cstring(output)) else {
        return Err(refuse("the path contains a NUL byte"));
    };
    let c_compression =
        CString::new(spec.compression.as_str()).map_err(|_| refuse("bad compression"))?;
    let mut names = Vec::new();
    let mut values = Vec::new();
    for (k, v) in &spec.attributes {
        names.push(CString::new(k.as_str()).map_err(|_| refuse("an attribute holds a NUL byte"))?);
        values.push(CString::new(v.as_str()).map_err(|_| refuse("an attribute holds a NUL byte"))?);
    }
    let name_ptrs: Vec<*const std::os::raw::c_char> = names.iter().map(|c| c.as_ptr()).collect();
    let value_ptrs: Vec<*const std::os::raw::c_char> = values.iter().map(|c| c.as_ptr()).collect();
    let shim = sys::shim().map_err(|source| Error::Unavailable {
        path: path.clone(),
        source,
    })?;
    let to_i32 = |v: u32| i32::try_from(v).map_err(|_| refuse("tile or subimage out of range"));
    // SAFETY: every pointer is a valid C string, or an array of `count` of them, alive for
    // the call; the shim copies what it keeps.
    let status = unsafe {
        shim.specconv_oiio_make_texture(
            c_in.as_ptr(),
            to_i32(spec.subimage)?,
            c_out.as_ptr(),
            to_i32(spec.tile.0)?,
            to_i32(spec.tile.1)?,
            c_compression.as_ptr(),
            name_ptrs.as_ptr(),
            value_ptrs.as_ptr(),
            name_ptrs.len(),
        )
    } as u32;
    match status {
        sys::SPECCONV_OIIO_OK => Ok(()),
        sys::SPECCONV_OIIO_ERR_ARGUMENT => Err(refuse(&last_error(shim))),
        sys::SPECCONV_OIIO_ERR_READ => Err(Error::Read {
            path,
            message: last_error(shim),
        }),
        _ => Err(Error::Internal {
            path,
            message: last_error(shim),
        }),
    }
}

/// Ends the process at once with `code`, as `_exit(2)` does: no exit handlers, no C++ static
/// destructors. For the thread of a signal handler: `std::process::exit` would run
/// OpenImageIO's and OpenColorIO's static destructors while another thread may still be inside
/// those libraries (a crash or a hang instead of the exit status).
pub fn exit_now(code: i32) -> ! {
    extern "C" {
        fn _exit(status: std::ffi::c_int) -> !;
    }
    // SAFETY: _exit takes any status, touches no memory of ours and does not return.
    unsafe { _exit(code) }
}

/// Makes a write past the file size limit (`ulimit -f`, which Slurm passes on to its jobs by
/// default) fail with `EFBIG`, which the writer reports and cleans up after, instead of
/// SIGXFSZ ending the process with its temporary file left behind. CPython does the same at
/// start, so the Python package needs no call.
pub fn ignore_file_size_signal() {
    // SAFETY: SIG_IGN installs no code of ours; signal(2) touches no memory of ours.
    unsafe {
        libc::signal(libc::SIGXFSZ, libc::SIG_IGN);
    }
}

/// Runtime OpenImageIO version as (major, minor, patch); loads OpenImageIO if no image has
/// been opened yet.
pub fn oiio_version() -> Result<(u32, u32, u32), LoadError> {
    let shim = sys::shim()?;
    // SAFETY: a plain query without arguments.
    let v = unsafe { shim.specconv_oiio_version() }.max(0) as u32;
    Ok((v / 10000, v / 100 % 100, v % 100))
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
