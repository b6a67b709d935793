//! A texture that holds data, not colour ([`DataTexture`]): what the colour rules refuse to
//! uplift, and why in words.

use crate::report::{Rule, Selection};
use std::path::PathBuf;

/// A texture that holds data, not colour: never uplifted (the module's rules).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{}: a data texture ({}): it holds numbers, not colour, and is never uplifted to a spectrum", path.display(), self.why())]
pub struct DataTexture {
    /// The input.
    pub path: PathBuf,
    /// The data colour space (the config's name, `Raw` in most configs).
    pub name: String,
    /// The rule that chose it; [`Rule::OneChannel`] for one channel no row from 1 to 3
    /// calls colour.
    pub rule: Rule,
    /// The subimage and channels it would be read as; `None` where not chosen yet.
    pub selection: Option<Selection>,
    /// Width and height of its full-resolution level.
    pub size: (u32, u32),
}

/// Why one channel is data: the data-map rule [`texture_space`](crate::texture_space) applies.
pub const ONE_CHANNEL: &str = "one channel (with or without alpha), and neither the caller, \
     the config's explicit file rules nor a strong declaration in the file call it colour";

impl DataTexture {
    /// Why it is data, in words.
    pub fn why(&self) -> String {
        let over = self
            .rule
            .overrides()
            .map(|o| format!(", over {o}"))
            .unwrap_or_default();
        match &self.rule {
            Rule::Flag { .. } => format!("colour space '{}', as asked{over}", self.name),
            Rule::Declared { what, .. } => format!(
                "colour space '{}', declared by its {}{over}",
                self.name,
                what.join(", ")
            ),
            Rule::FileRule { rule, .. } | Rule::ConfigDefault { rule, .. } => format!(
                "colour space '{}', by the OCIO config's file rule '{rule}'{over}",
                self.name
            ),
            Rule::OneChannel { .. } => format!("{ONE_CHANNEL}{over}"),
            Rule::Default(why) => (*why).to_owned(),
        }
    }
}
