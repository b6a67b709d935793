//! A loaded, validated config: where it came from (a file, `$OCIO`, a built-in name), its
//! colour spaces and roles, the processors it builds, and the answers the input colour space's
//! rule asks of it.

use std::ffi::OsString;
use std::fmt;
use std::path::{Path, PathBuf};
use std::ptr::NonNull;

use ocio_sys as sys;

use crate::builtin::{
    lookup, BuiltinConfig, ConfigSource, ACES_CONFIG_NAME, BUILTIN_NAMES, SCHEME,
};
use crate::error::{Error, Result};
use crate::processor::{Processor, XyzRoute};
use crate::shim::{config_str, cstring, last_error};

/// One colour space of a config.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ColorSpace {
    /// The canonical name.
    pub name: String,
    /// Its other names, which the config also accepts.
    pub aliases: Vec<String>,
    /// Its `family` in the config, empty when none.
    pub family: String,
    /// Its `encoding` in the config (`scene-linear`, `sdr-video`, `log`, ...), empty when
    /// none.
    pub encoding: String,
    /// Its description, trimmed; empty when none.
    pub description: String,
    /// Data, not colour (`Raw`): never converted, never uplifted.
    pub is_data: bool,
    /// Display-referred (connected to the scene through the default view transform).
    pub is_display: bool,
}

/// A loaded, validated OCIO config. Immutable, so shared freely between threads.
pub struct Config {
    pub(crate) raw: NonNull<sys::specconv_ocio_config>,
    source: ConfigSource,
    /// The built-in config this one is, content for content, once asked
    /// ([`Config::builtin_twin`]).
    twin: std::sync::OnceLock<Option<BuiltinConfig>>,
}

// SAFETY: an OCIO config is immutable after loading and OCIO documents const configs as
// safe to use from several threads; the shim only reads it.
unsafe impl Send for Config {}
unsafe impl Sync for Config {}

impl Drop for Config {
    fn drop(&mut self) {
        // SAFETY: raw came from the shim and is freed exactly once, here.
        unsafe { sys::specconv_ocio_config_free(self.raw.as_ptr()) }
    }
}

impl fmt::Debug for Config {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Config")
            .field("source", &self.source)
            .finish()
    }
}

impl Config {
    /// Loads a config file.
    pub fn from_file(path: impl AsRef<Path>) -> Result<Config> {
        let path = path.as_ref();
        Self::load_file(path, ConfigSource::File(path.to_path_buf()))
    }

    fn load_file(path: &Path, source: ConfigSource) -> Result<Config> {
        // OCIO would say "could not read"; a missing file deserves a plainer message.
        let kind = specconv_atomic_file::Kind::of(path);
        if kind != specconv_atomic_file::Kind::File {
            return Err(Error::ConfigNotFound {
                path: path.to_path_buf(),
                kind,
            });
        }
        let c_path = cstring(&path.to_string_lossy())?;
        let mut raw = std::ptr::null_mut();
        // SAFETY: valid C string; raw receives an owned config on success.
        let status = unsafe { sys::specconv_ocio_config_from_file(c_path.as_ptr(), &mut raw) };
        Self::adopt(status, raw, source)
    }

    /// A config from YAML text; relative file references resolve against `working_dir`.
    pub fn from_yaml(
        yaml: &str,
        working_dir: Option<&Path>,
        source: ConfigSource,
    ) -> Result<Config> {
        let c_yaml = cstring(yaml)?;
        let c_dir = working_dir
            .map(|d| cstring(&d.to_string_lossy()))
            .transpose()?;
        let mut raw = std::ptr::null_mut();
        // SAFETY: valid C strings (or NULL for no directory); raw receives an owned config.
        let status = unsafe {
            sys::specconv_ocio_config_from_yaml(
                c_yaml.as_ptr(),
                c_dir.as_ref().map_or(std::ptr::null(), |d| d.as_ptr()),
                &mut raw,
            )
        };
        Self::adopt(status, raw, source)
    }

    fn adopt(
        status: i32,
        raw: *mut sys::specconv_ocio_config,
        source: ConfigSource,
    ) -> Result<Config> {
        match (status as u32, NonNull::new(raw)) {
            (sys::SPECCONV_OCIO_OK, Some(raw)) => Ok(Config {
                raw,
                source,
                twin: std::sync::OnceLock::new(),
            }),
            _ => Err(Error::ConfigLoad {
                origin: source.to_string(),
                message: last_error(),
            }),
        }
    }

    /// Where the config came from.
    pub fn source(&self) -> &ConfigSource {
        &self.source
    }

    fn origin(&self) -> String {
        self.source.to_string()
    }

    fn describe(&self, cs: &sys::specconv_ocio_color_space) -> Result<ColorSpace> {
        let name = config_str(cs.name);
        let c_name = cstring(&name)?;
        let mut aliases = Vec::with_capacity(cs.num_aliases.max(0) as usize);
        for i in 0..cs.num_aliases {
            let mut alias = std::ptr::null();
            // SAFETY: live config, valid C string, index below the alias count.
            let status = unsafe {
                sys::specconv_ocio_color_space_alias(
                    self.raw.as_ptr(),
                    c_name.as_ptr(),
                    i,
                    &mut alias,
                )
            };
            if status as u32 == sys::SPECCONV_OCIO_OK {
                aliases.push(config_str(alias));
            }
        }
        Ok(ColorSpace {
            name,
            aliases,
            family: config_str(cs.family),
            encoding: config_str(cs.encoding),
            description: config_str(cs.description).trim().to_owned(),
            is_data: cs.is_data != 0,
            is_display: cs.is_display != 0,
        })
    }

    /// The config's active colour spaces, scene- and display-referred, in config order.
    pub fn color_spaces(&self) -> Result<Vec<ColorSpace>> {
        // SAFETY: live config.
        let n = unsafe { sys::specconv_ocio_num_color_spaces(self.raw.as_ptr()) };
        let mut out = Vec::with_capacity(n.max(0) as usize);
        for i in 0..n {
            let mut cs = std::mem::MaybeUninit::<sys::specconv_ocio_color_space>::zeroed();
            // SAFETY: live config; cs is a valid out-pointer, filled on success.
            let status =
                unsafe { sys::specconv_ocio_color_space_at(self.raw.as_ptr(), i, cs.as_mut_ptr()) };
            if status as u32 != sys::SPECCONV_OCIO_OK {
                return Err(Error::ConfigLoad {
                    origin: self.origin(),
                    message: last_error(),
                });
            }
            // SAFETY: filled by the shim on success (and zeroed before).
            out.push(self.describe(&unsafe { cs.assume_init() })?);
        }
        Ok(out)
    }

    /// Looks a colour space up by name, alias or role, ignoring case as OCIO does.
    pub fn color_space(&self, name: &str) -> Result<ColorSpace> {
        self.find_color_space(name)?
            .ok_or_else(|| Error::UnknownColorSpace {
                name: name.to_owned(),
                origin: self.origin(),
                close: self.close_names(name),
            })
    }

    /// Looks a colour space up by name, alias or role; `None` when the config lacks it.
    pub fn find_color_space(&self, name: &str) -> Result<Option<ColorSpace>> {
        let c_name = cstring(name)?;
        let mut cs = std::mem::MaybeUninit::<sys::specconv_ocio_color_space>::zeroed();
        // SAFETY: live config, valid C string, valid out-pointer.
        let status = unsafe {
            sys::specconv_ocio_color_space_named(
                self.raw.as_ptr(),
                c_name.as_ptr(),
                cs.as_mut_ptr(),
            )
        } as u32;
        match status {
            // SAFETY: filled by the shim on success.
            sys::SPECCONV_OCIO_OK => Ok(Some(self.describe(&unsafe { cs.assume_init() })?)),
            sys::SPECCONV_OCIO_ERR_NOT_FOUND => Ok(None),
            _ => Err(Error::Argument(last_error())),
        }
    }

    /// The colour space a role points to, if the config defines the role.
    pub fn role(&self, role: &str) -> Result<Option<String>> {
        let c_role = cstring(role)?;
        let mut out = std::ptr::null();
        // SAFETY: live config, valid C string, valid out-pointer.
        let status =
            unsafe { sys::specconv_ocio_role(self.raw.as_ptr(), c_role.as_ptr(), &mut out) };
        if status as u32 != sys::SPECCONV_OCIO_OK {
            return Err(Error::ConfigLoad {
                origin: self.origin(),
                message: last_error(),
            });
        }
        Ok((!out.is_null()).then(|| config_str(out)))
    }

    /// Up to five colour-space names close to `name`: names or aliases that contain it or
    /// that it contains, then those within a few edits, ignoring case.
    pub fn close_names(&self, name: &str) -> Vec<String> {
        let Ok(spaces) = self.color_spaces() else {
            return Vec::new();
        };
        let wanted = name.to_lowercase();
        let mut scored: Vec<(usize, String)> = Vec::new();
        for cs in &spaces {
            let best = std::iter::once(&cs.name)
                .chain(&cs.aliases)
                .map(|candidate| {
                    let c = candidate.to_lowercase();
                    if !wanted.is_empty() && (c.contains(&wanted) || wanted.contains(&c)) {
                        0
                    } else {
                        edit_distance(&c, &wanted)
                    }
                })
                .min()
                .unwrap_or(usize::MAX);
            if best <= (wanted.chars().count() / 3).max(2) {
                scored.push((best, cs.name.clone()));
            }
        }
        scored.sort_by_key(|(score, _)| *score);
        scored.into_iter().take(5).map(|(_, n)| n).collect()
    }

    /// A processor between two colour spaces of the config.
    pub fn processor(&self, src: &str, dst: &str) -> Result<Processor> {
        let src_cs = self.color_space(src)?;
        let dst_cs = self.color_space(dst)?;
        self.make_processor(&src_cs.name, &dst_cs.name, None)
    }

    /// A processor from colour space `src` to CIE XYZ (D65), through the
    /// `cie_xyz_d65_interchange` role or else the `aces_interchange` role. Data colour
    /// spaces are refused.
    pub fn processor_to_xyz(&self, src: &str) -> Result<Processor> {
        let src_cs = self.color_space(src)?;
        if src_cs.is_data {
            return Err(Error::DataColorSpace { name: src_cs.name });
        }
        if let Some(xyz) = self.role("cie_xyz_d65_interchange")? {
            let mut p = self.make_processor(&src_cs.name, &xyz, None)?;
            p.route = XyzRoute::CieXyzD65Interchange(xyz);
            return Ok(p);
        }
        if let Some(aces) = self.role("aces_interchange")? {
            let mut p = self.make_processor(&src_cs.name, &aces, Some(AP0_TO_XYZ_D65))?;
            p.route = XyzRoute::AcesInterchange(aces);
            return Ok(p);
        }
        Err(Error::NoInterchangeRole {
            origin: self.origin(),
        })
    }

    fn make_processor(&self, src: &str, dst: &str, post: Option<&str>) -> Result<Processor> {
        let (c_src, c_dst) = (cstring(src)?, cstring(dst)?);
        let c_post = post.map(cstring).transpose()?;
        let mut raw = std::ptr::null_mut();
        // SAFETY: live config, valid C strings (post may be NULL), raw receives an owned
        // processor on success.
        let status = unsafe {
            sys::specconv_ocio_processor_new(
                self.raw.as_ptr(),
                c_src.as_ptr(),
                c_dst.as_ptr(),
                c_post.as_ref().map_or(std::ptr::null(), |p| p.as_ptr()),
                &mut raw,
            )
        };
        match (status as u32, NonNull::new(raw)) {
            (sys::SPECCONV_OCIO_OK, Some(raw)) => Ok(Processor {
                raw,
                src: src.to_owned(),
                route: XyzRoute::Direct(dst.to_owned()),
            }),
            _ => Err(Error::Processor {
                src: src.to_owned(),
                dst: dst.to_owned(),
                message: last_error(),
            }),
        }
    }

    /// The config's sRGB-encoded Rec.709 texture space, by the names configs use for it.
    pub fn srgb_texture(&self) -> Result<Option<String>> {
        for candidate in SRGB_TEXTURE_NAMES {
            if let Some(cs) = self.find_color_space(candidate)? {
                return Ok(Some(cs.name));
            }
        }
        Ok(None)
    }

    /// The colour space the config's `file_rules` give `path` (canonical name) and the
    /// rule's name; `None` when only the default rule matches, so the config says nothing
    /// particular about this file.
    pub fn file_rule(&self, path: &Path) -> Result<Option<(String, String)>> {
        let c_path = cstring(&path.to_string_lossy())?;
        let (mut cs, mut rule) = (std::ptr::null(), std::ptr::null());
        // SAFETY: live config, valid C string, valid out-pointers; the strings belong to
        // the config.
        let status = unsafe {
            sys::specconv_ocio_file_rule(self.raw.as_ptr(), c_path.as_ptr(), &mut cs, &mut rule)
        };
        if status as u32 != sys::SPECCONV_OCIO_OK {
            return Err(Error::ConfigLoad {
                origin: self.origin(),
                message: last_error(),
            });
        }
        if cs.is_null() {
            return Ok(None);
        }
        let name = self.color_space(&config_str(cs))?.name;
        Ok(Some((name, config_str(rule))))
    }
}

/// Names of the sRGB texture space in the ACES CG config and other common configs, in
/// order of preference.
const SRGB_TEXTURE_NAMES: [&str; 5] = [
    "sRGB - Texture",
    "srgb_tx",
    "srgb_texture",
    "Utility - sRGB - Texture",
    "sRGB",
];

/// OCIO 2.1 built-in transform from ACES2065-1 to CIE XYZ with Bradford adaptation to D65.
const AP0_TO_XYZ_D65: &str = "UTILITY - ACES-AP0_to_CIE-XYZ-D65_BFD";

/// Levenshtein distance over characters.
fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut prev: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut cur = vec![i + 1; b.len() + 1];
        for (j, &cb) in b.iter().enumerate() {
            cur[j + 1] = (prev[j] + usize::from(ca != cb))
                .min(prev[j + 1] + 1)
                .min(cur[j] + 1);
        }
        prev = cur;
    }
    prev[b.len()]
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

#[cfg(test)]
mod tests {
    use super::edit_distance;

    #[test]
    fn edit_distance_counts_single_character_edits() {
        assert_eq!(edit_distance("acescg", "acescg"), 0);
        assert_eq!(edit_distance("acecg", "acescg"), 1);
        assert_eq!(edit_distance("kitten", "sitting"), 3);
        assert_eq!(edit_distance("", "abc"), 3);
    }
}
