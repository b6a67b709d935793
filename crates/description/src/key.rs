//! The options of a conversion by name: [`Key`], beneath their definitions and values.

/// One option of a conversion. [`Key::about`] says how every front-end names it; the
/// compiler makes every `match` on it (the text of a value, its parsing, the tag) cover a new
/// one.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[allow(missing_docs)]
pub enum Key {
    Ocio,
    Colorspace,
    Alpha,
    Subimage,
    Channels,
    Method,
    Model,
    Blend,
    Bounded,
    Bands,
    Emission,
    Layout,
    Sample,
    Rounding,
    Compression,
    ZipLevel,
    Tile,
    Mip,
    Filter,
    Resize,
    Wrap,
    NonFinite,
    ConstantDetect,
    OpaqueDetect,
    Threads,
    Overwrite,
    TableDir,
    Data,
    StripMetadata,
    Strict,
}

impl Key {
    /// Every option, in the order help lists them.
    pub const ALL: [Key; 30] = [
        Key::Ocio,
        Key::Colorspace,
        Key::Alpha,
        Key::Subimage,
        Key::Channels,
        Key::Method,
        Key::Model,
        Key::Blend,
        Key::Bounded,
        Key::Bands,
        Key::Emission,
        Key::Layout,
        Key::Sample,
        Key::Rounding,
        Key::Compression,
        Key::ZipLevel,
        Key::Tile,
        Key::Mip,
        Key::Filter,
        Key::Resize,
        Key::Wrap,
        Key::NonFinite,
        Key::ConstantDetect,
        Key::OpaqueDetect,
        Key::Threads,
        Key::Overwrite,
        Key::TableDir,
        Key::Data,
        Key::StripMetadata,
        Key::Strict,
    ];
}
