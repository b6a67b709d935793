//! specconv's built-in configs and the names that pick a config: `--ocio`, `$OCIO`.
//!
//! OpenColorIO 2.2 and later compile in the Academy's ACES CG and Studio configs and serve
//! them under `ocio://` names; `ocio://default` is the CG config there. Debian's OCIO 2.1
//! has none, so specconv embeds configs of its own (`config/cg.ocio`, `config/studio.ocio`,
//! written by `scripts/make_configs.py` from published primaries and curves) with the same
//! colour spaces, aliases, roles, displays, views, looks and file rules, and answers the
//! same names with them. `aces` stays the short name of the CG config.

use std::fmt;
use std::path::PathBuf;

use crate::error::{Error, Result};

/// The YAML of the built-in CG config.
pub const CG_CONFIG_YAML: &str = include_str!("../config/cg.ocio");
/// The YAML of the built-in Studio config.
pub const STUDIO_CONFIG_YAML: &str = include_str!("../config/studio.ocio");

/// What `--ocio` names the built-in CG config by, for short.
pub const ACES_CONFIG_NAME: &str = "aces";

/// One of specconv's built-in configs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BuiltinConfig {
    /// After the ACES CG config v1.0.0 (ACES 1.3, OCIO 2.1).
    Cg,
    /// After the ACES Studio config v1.0.0 (ACES 1.3, OCIO 2.1): the CG config plus camera
    /// log spaces, more displays and views.
    Studio,
}

impl BuiltinConfig {
    /// The config's YAML ([`CG_CONFIG_YAML`] or [`STUDIO_CONFIG_YAML`]).
    pub fn yaml(self) -> &'static str {
        match self {
            Self::Cg => CG_CONFIG_YAML,
            Self::Studio => STUDIO_CONFIG_YAML,
        }
    }

    /// The name of the official config this one follows.
    pub fn official_name(self) -> &'static str {
        match self {
            Self::Cg => "cg-config-v1.0.0_aces-v1.3_ocio-v2.1",
            Self::Studio => "studio-config-v1.0.0_aces-v1.3_ocio-v2.1",
        }
    }
}

impl fmt::Display for BuiltinConfig {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let what = match self {
            Self::Cg => "ACES CG config",
            Self::Studio => "ACES Studio config",
        };
        write!(f, "{what} v1.0.0, as {}", self.official_name())
    }
}

/// Every name that picks a built-in config, as OCIO 2.2+ names them (plus `aces`).
pub const BUILTIN_NAMES: [(&str, BuiltinConfig); 6] = [
    (ACES_CONFIG_NAME, BuiltinConfig::Cg),
    // OCIO 2.2 and 2.3 map the default to the CG config; so does specconv.
    ("ocio://default", BuiltinConfig::Cg),
    ("ocio://cg-config-latest", BuiltinConfig::Cg),
    (
        "ocio://cg-config-v1.0.0_aces-v1.3_ocio-v2.1",
        BuiltinConfig::Cg,
    ),
    ("ocio://studio-config-latest", BuiltinConfig::Studio),
    (
        "ocio://studio-config-v1.0.0_aces-v1.3_ocio-v2.1",
        BuiltinConfig::Studio,
    ),
];

/// The `ocio://` scheme of OCIO's built-in config names.
pub(crate) const SCHEME: &str = "ocio://";

/// Whether `--ocio` names a built-in config (`aces` or any `ocio://` name, known or not)
/// rather than a file.
pub fn is_builtin_name(name: &str) -> bool {
    name == ACES_CONFIG_NAME || name.starts_with(SCHEME)
}

/// The built-in config `name` picks; `None` when it names a file. An `ocio://` name that is
/// not known is an error listing the known ones.
pub fn lookup(name: &str) -> Option<Result<BuiltinConfig>> {
    if !is_builtin_name(name) {
        return None;
    }
    Some(
        BUILTIN_NAMES
            .iter()
            .find(|(n, _)| *n == name)
            .map(|&(_, c)| c)
            .ok_or_else(|| Error::UnknownBuiltinConfig {
                name: name.to_owned(),
                known: BUILTIN_NAMES.iter().map(|(n, _)| n.to_string()).collect(),
            }),
    )
}

/// Where a config came from.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum ConfigSource {
    /// `--ocio FILE`
    File(PathBuf),
    /// `$OCIO`
    Env(PathBuf),
    /// A built-in config, by the name that picked it (`aces` when none was given).
    Builtin {
        /// The name that picked it (`aces` or an `ocio://` name).
        name: String,
        /// Which built-in config.
        config: BuiltinConfig,
        /// Whether the name came from `$OCIO` rather than `--ocio` (or no choice at all).
        from_env: bool,
    },
}

impl fmt::Display for ConfigSource {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::File(p) => write!(f, "{}", p.display()),
            Self::Env(p) => write!(f, "{} (from $OCIO)", p.display()),
            Self::Builtin {
                name,
                config,
                from_env,
            } => {
                let env = if *from_env { "from $OCIO; " } else { "" };
                write!(f, "'{name}' ({env}built in: {config})")
            }
        }
    }
}
