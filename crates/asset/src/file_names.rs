//! What the paths an asset run meets are: a USD stage or a MaterialX document by its extension,
//! the record in the output folder by its name.

use std::path::Path;

/// Whether `path` names a USD stage by its extension (`.usd`, `.usda`, `.usdc`, `.usdz`): what
/// `farm submit` plans as an asset rather than as a texture.
pub fn is_stage(path: &Path) -> bool {
    let ext = path.extension().map(|e| e.to_ascii_lowercase());
    matches!(
        ext.as_ref().and_then(|e| e.to_str()),
        Some("usd" | "usda" | "usdc" | "usdz")
    )
}

/// Whether `path` names a MaterialX document (`.mtlx`), which is read by the MaterialX package
/// and gets an override copy rather than a USD layer.
pub fn is_document(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("mtlx"))
}

/// The record's name in the output folder.
pub const RECORD: &str = ".specconv-asset.json";
