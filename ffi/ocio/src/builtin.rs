//! specconv's built-in configs and the names that pick a config: `--ocio`, `$OCIO`.
//!
//! OpenColorIO 2.2 and later compile in the Academy's ACES CG and Studio configs and serve
//! them under `ocio://` names; `ocio://default` is the CG config there. Debian's OCIO 2.1
//! has none, so specconv embeds configs of its own (`config/cg.ocio`, `config/studio.ocio`,
//! written by `scripts/make_configs.py` from published primaries and curves) with the same
//! colour spaces, aliases, roles, displays, views, looks and file rules, and answers the
//! same names with them. `aces` stays the short name of the CG config.

use std::ffi::OsString;
use std::fmt;
use std::path::PathBuf;

use crate::{Config, Error, Result};

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
const SCHEME: &str = "ocio://";

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

impl Config {
    /// Picks and loads the config: `--ocio` (a file, `aces` or an `ocio://` name), else
    /// `$OCIO` (the same), else the built-in CG config.
    pub fn resolve(ocio_arg: Option<&str>) -> Result<Config> {
        Self::resolve_with_env(ocio_arg, std::env::var_os("OCIO"))
    }

    /// [`Config::resolve`] with the value of `$OCIO` passed in (tests must not set
    /// process-wide variables).
    pub fn resolve_with_env(ocio_arg: Option<&str>, env: Option<OsString>) -> Result<Config> {
        if let Some(arg) = ocio_arg {
            return Self::by_name(arg, false);
        }
        match env.filter(|v| !v.is_empty()) {
            Some(value) => match value.to_str() {
                Some(name) => Self::by_name(name, true),
                None => {
                    let path = PathBuf::from(value);
                    Self::load_file(&path, ConfigSource::Env(path.clone()))
                }
            },
            None => Self::by_name(ACES_CONFIG_NAME, false),
        }
    }

    /// A built-in config by any of its names, else a config file.
    fn by_name(name: &str, from_env: bool) -> Result<Config> {
        if let Some(config) = lookup(name) {
            return Self::builtin_named(config?, name, from_env);
        }
        let path = PathBuf::from(name);
        let source = if from_env {
            ConfigSource::Env(path.clone())
        } else {
            ConfigSource::File(path.clone())
        };
        Self::load_file(&path, source)
    }

    /// A built-in config.
    pub fn builtin(config: BuiltinConfig) -> Result<Config> {
        let name = BUILTIN_NAMES
            .iter()
            .find(|&&(n, c)| c == config && n.starts_with(SCHEME) && n.ends_with("ocio-v2.1"))
            .map_or(ACES_CONFIG_NAME, |(n, _)| n);
        Self::builtin_named(config, name, false)
    }

    /// The built-in CG config (`--ocio aces`).
    pub fn builtin_aces() -> Result<Config> {
        Self::builtin_named(BuiltinConfig::Cg, ACES_CONFIG_NAME, false)
    }

    /// The built-in config this config is: itself for a built-in one; for a file (the
    /// Academy's official config, as `../shared/ocio` holds it) the built-in config with the
    /// same colour spaces, roles and file rules, so that both decide a file's colour space
    /// alike; `None` for any other (a studio's config, an edited copy). Asked once per config.
    pub fn builtin_twin(&self) -> Result<Option<BuiltinConfig>> {
        if let ConfigSource::Builtin { config, .. } = self.source() {
            return Ok(Some(*config));
        }
        if let Some(twin) = self.twin.get() {
            return Ok(*twin);
        }
        let mut twin = None;
        for kind in [BuiltinConfig::Cg, BuiltinConfig::Studio] {
            let ours = Config::builtin(kind)?;
            if self.all_color_space_names()? == ours.all_color_space_names()?
                && self.roles()? == ours.roles()?
                && self.file_rules()? == ours.file_rules()?
            {
                twin = Some(kind);
                break;
            }
        }
        Ok(*self.twin.get_or_init(|| twin))
    }

    fn builtin_named(config: BuiltinConfig, name: &str, from_env: bool) -> Result<Config> {
        let source = ConfigSource::Builtin {
            name: name.to_owned(),
            config,
            from_env,
        };
        Self::from_yaml(config.yaml(), None, source)
    }
}
