//! Config selection, the built-in ACES config, input colour-space rules and every failure
//! the issue lists: each an error value with a message that says what to do.

use std::ffi::OsString;
use std::path::{Path, PathBuf};
use std::process::Command;

use specconv_ocio::{BuiltinConfig, Config, ConfigSource, Error};

fn testdata(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../testdata")
        .join(rel)
}

fn config_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("config")
}

fn aces_file() -> PathBuf {
    config_dir().join("cg.ocio")
}

#[test]
fn builtin_configs_pass_ociocheck() {
    for file in ["cg.ocio", "studio.ocio"] {
        let out = Command::new("ociocheck")
            .arg("--iconfig")
            .arg(config_dir().join(file))
            .output()
            .expect("ociocheck not found on PATH (Debian: opencolorio-tools)");
        let text = String::from_utf8_lossy(&out.stdout).into_owned()
            + &String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "{file}: {text}");
        assert!(text.contains("** Validation **\npassed"), "{file}: {text}");
        assert!(!text.contains("ERROR"), "{file}: {text}");
    }
}

#[test]
fn builtin_configs_are_what_the_script_generates() {
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scripts/make_configs.py");
    for (kind, embedded) in [
        ("cg", specconv_ocio::CG_CONFIG_YAML),
        ("studio", specconv_ocio::STUDIO_CONFIG_YAML),
    ] {
        let out = Command::new("python3")
            .arg(&script)
            .arg(kind)
            .output()
            .expect("python3 not found");
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        assert_eq!(
            String::from_utf8(out.stdout).unwrap(),
            embedded,
            "ffi/ocio/config/{kind}.ocio is stale: \
             python3 scripts/make_configs.py {kind} > ffi/ocio/config/{kind}.ocio"
        );
    }
}

#[test]
fn builtin_aces_config_has_the_aces_cg_names_aliases_and_roles() {
    let config = Config::builtin_aces().unwrap();
    let names: Vec<String> = config
        .color_spaces()
        .unwrap()
        .into_iter()
        .map(|c| c.name)
        .collect();
    for name in [
        "ACES2065-1",
        "ACEScg",
        "ACEScct",
        "ACEScc",
        "Linear Rec.709 (sRGB)",
        "sRGB - Texture",
        "Linear Rec.2020",
        "Linear P3-D65",
        "Rec.1886 Rec.709 - Display",
        "Raw",
        "CIE-XYZ-D65",
    ] {
        assert!(
            names.iter().any(|n| n == name),
            "{name} missing from {names:?}"
        );
    }
    for (alias, canonical) in [
        ("lin_rec709", "Linear Rec.709 (sRGB)"),
        ("lin_srgb", "Linear Rec.709 (sRGB)"),
        ("srgb_tx", "sRGB - Texture"),
        ("srgb_texture", "sRGB - Texture"),
        ("sRGB Encoded Rec.709 (sRGB)", "sRGB - Texture"),
        ("acescg", "ACEScg"),
        ("scene_linear", "ACEScg"),
    ] {
        assert_eq!(
            config.color_space(alias).unwrap().name,
            canonical,
            "{alias}"
        );
    }
    for (role, space) in [
        ("scene_linear", "ACEScg"),
        ("aces_interchange", "ACES2065-1"),
        ("cie_xyz_d65_interchange", "CIE-XYZ-D65"),
        ("color_picking", "sRGB - Texture"),
        ("data", "Raw"),
    ] {
        assert_eq!(config.role(role).unwrap().as_deref(), Some(space), "{role}");
    }
    assert_eq!(config.role("no_such_role").unwrap(), None);
    assert!(config.color_space("Raw").unwrap().is_data);
    assert!(config.color_space("CIE-XYZ-D65").unwrap().is_display);
}

fn builtin(name: &str, config: BuiltinConfig, from_env: bool) -> ConfigSource {
    ConfigSource::Builtin {
        name: name.into(),
        config,
        from_env,
    }
}

#[test]
fn config_resolution_order() {
    let file = aces_file();
    let file_str = file.to_str().unwrap();
    let env = || Some(OsString::from(testdata("ocio/no_interchange.ocio")));
    // --ocio FILE beats $OCIO.
    let c = Config::resolve_with_env(Some(file_str), env()).unwrap();
    assert_eq!(c.source(), &ConfigSource::File(file.clone()));
    // --ocio aces is the built-in CG config, whatever $OCIO says.
    let c = Config::resolve_with_env(Some("aces"), env()).unwrap();
    assert_eq!(c.source(), &builtin("aces", BuiltinConfig::Cg, false));
    // Then $OCIO.
    let c = Config::resolve_with_env(None, env()).unwrap();
    assert!(matches!(c.source(), ConfigSource::Env(_)));
    assert_eq!(c.role("scene_linear").unwrap().as_deref(), Some("linear"));
    // Then the built-in config; an empty $OCIO counts as unset.
    for unset in [None, Some(OsString::new())] {
        let c = Config::resolve_with_env(None, unset).unwrap();
        assert_eq!(c.source(), &builtin("aces", BuiltinConfig::Cg, false));
    }
}

#[test]
fn missing_config_file_is_reported_plainly() {
    let err = Config::resolve_with_env(Some("/no/such/config.ocio"), None).unwrap_err();
    assert!(matches!(err, Error::ConfigNotFound { .. }), "{err:?}");
    assert_eq!(
        err.to_string(),
        "OCIO config /no/such/config.ocio: no such file"
    );
    let err = Config::resolve_with_env(None, Some("/no/such/env.ocio".into())).unwrap_err();
    assert!(matches!(err, Error::ConfigNotFound { .. }), "{err:?}");
    // A device is named as what it is, never read (OpenColorIO would read /dev/zero for ever).
    let err = Config::resolve_with_env(Some("/dev/zero"), None).unwrap_err();
    assert_eq!(
        err.to_string(),
        "OCIO config /dev/zero: a character device, not a config file"
    );
}

#[test]
fn configs_that_fail_to_load_say_why() {
    for (name, expect) in [
        ("ocio/broken_yaml.ocio", "end of sequence flow not found"),
        ("ocio/dangling_role.ocio", "no_such_space"),
        ("images/srgb8.png", "failed to load"),
    ] {
        let err = Config::from_file(testdata(name)).unwrap_err();
        assert!(matches!(err, Error::ConfigLoad { .. }), "{name}: {err:?}");
        let msg = err.to_string();
        assert!(
            msg.contains("failed to load") && msg.contains(expect),
            "{name}: {msg}"
        );
        assert!(!msg.contains('\n'), "one line: {msg}");
    }
}

#[test]
fn config_without_interchange_roles_is_refused() {
    let config = Config::from_file(testdata("ocio/no_interchange.ocio")).unwrap();
    let err = config.processor_to_xyz("linear").unwrap_err();
    assert!(matches!(err, Error::NoInterchangeRole { .. }), "{err:?}");
    assert!(err
        .to_string()
        .contains("neither a cie_xyz_d65_interchange nor an aces_interchange role"));
}

#[test]
fn unknown_colour_space_lists_close_names() {
    let config = Config::builtin_aces().unwrap();
    let err = config.processor_to_xyz("ACEScgg").unwrap_err();
    let msg = err.to_string();
    assert!(matches!(err, Error::UnknownColorSpace { .. }), "{err:?}");
    assert!(
        msg.contains("unknown colour space 'ACEScgg'") && msg.contains("'ACEScg'"),
        "{msg}"
    );
    let Error::UnknownColorSpace { close, .. } = config.color_space("srgb").unwrap_err() else {
        panic!("expected UnknownColorSpace")
    };
    assert!(close.contains(&"sRGB - Texture".to_string()), "{close:?}");
    let msg = config.color_space("zzzzzzzzzzzz").unwrap_err().to_string();
    assert!(msg.contains("specconv colorspaces"), "{msg}");
}

#[test]
fn raw_is_refused_for_uplifting() {
    let config = Config::builtin_aces().unwrap();
    for name in ["Raw", "raw", "data"] {
        let err = config.processor_to_xyz(name).unwrap_err();
        assert!(
            matches!(err, Error::DataColorSpace { .. }),
            "{name}: {err:?}"
        );
        assert!(err.to_string().contains("holds data, not colour"), "{err}");
    }
}

#[test]
fn file_rules_name_a_colour_space_only_when_a_rule_other_than_the_default_matches() {
    // The built-in config with one rule before its Default rule.
    let yaml = specconv_ocio::CG_CONFIG_YAML.replace(
        "  - !<Rule> {name: Default, colorspace: ACES2065-1}",
        "  - !<Rule> {name: acescg files, colorspace: ACEScg, pattern: \"*_acescg\", extension: \"exr\"}\n  - !<Rule> {name: Default, colorspace: ACES2065-1}",
    );
    assert_ne!(
        yaml,
        specconv_ocio::CG_CONFIG_YAML,
        "the Default rule moved"
    );
    let config = Config::from_yaml(&yaml, None, ConfigSource::File("rules.ocio".into())).unwrap();
    assert_eq!(
        config
            .file_rule(Path::new("/textures/wall_acescg.exr"))
            .unwrap(),
        Some(("ACEScg".to_owned(), "acescg files".to_owned()))
    );
    assert_eq!(
        config.file_rule(Path::new("/textures/wall.exr")).unwrap(),
        None
    );
    // The plain built-in config has the Default rule only.
    let builtin = Config::builtin_aces().unwrap();
    assert_eq!(builtin.file_rule(Path::new("x_acescg.exr")).unwrap(), None);
    assert_eq!(
        builtin.srgb_texture().unwrap().as_deref(),
        Some("sRGB - Texture")
    );
    assert_eq!(
        builtin.find_color_space("lin_srgb").unwrap().unwrap().name,
        "Linear Rec.709 (sRGB)"
    );
    assert_eq!(builtin.find_color_space("nope").unwrap(), None);
    let bare = Config::from_file(testdata("ocio/aces_interchange_only.ocio")).unwrap();
    assert_eq!(bare.srgb_texture().unwrap(), None);
}

#[test]
fn ocio_names_pick_the_builtin_configs_from_the_flag_and_from_ocio() {
    for (name, kind, has_camera_spaces) in [
        ("ocio://default", BuiltinConfig::Cg, false),
        ("ocio://cg-config-latest", BuiltinConfig::Cg, false),
        (
            "ocio://cg-config-v1.0.0_aces-v1.3_ocio-v2.1",
            BuiltinConfig::Cg,
            false,
        ),
        ("ocio://studio-config-latest", BuiltinConfig::Studio, true),
        (
            "ocio://studio-config-v1.0.0_aces-v1.3_ocio-v2.1",
            BuiltinConfig::Studio,
            true,
        ),
    ] {
        // From --ocio, even with a file in $OCIO.
        let env = Some(OsString::from(testdata("ocio/no_interchange.ocio")));
        let c = Config::resolve_with_env(Some(name), env).unwrap();
        assert_eq!(c.source(), &builtin(name, kind, false));
        assert_eq!(
            c.color_space("S-Log3 S-Gamut3").is_ok(),
            has_camera_spaces,
            "{name}"
        );
        assert_eq!(c.role("scene_linear").unwrap().as_deref(), Some("ACEScg"));
        // From $OCIO.
        let c = Config::resolve_with_env(None, Some(name.into())).unwrap();
        assert_eq!(c.source(), &builtin(name, kind, true));
        assert_eq!(
            c.source().to_string(),
            format!("'{name}' (from $OCIO; built in: {kind})")
        );
        assert_eq!(c.color_space("S-Log3 S-Gamut3").is_ok(), has_camera_spaces);
    }
    assert_eq!(
        Config::builtin_aces().unwrap().source().to_string(),
        "'aces' (built in: ACES CG config v1.0.0, as cg-config-v1.0.0_aces-v1.3_ocio-v2.1)"
    );
}

#[test]
fn unknown_ocio_names_list_the_known_ones() {
    for (flag, env) in [
        (Some("ocio://studio-config-v9"), None),
        (None, Some(OsString::from("ocio://nope"))),
    ] {
        let err = Config::resolve_with_env(flag, env).unwrap_err();
        assert!(matches!(err, Error::UnknownBuiltinConfig { .. }), "{err:?}");
        let msg = err.to_string();
        for known in specconv_ocio::BUILTIN_NAMES.iter().map(|(n, _)| n) {
            assert!(
                msg.contains(&format!("'{known}'")),
                "{known} missing: {msg}"
            );
        }
        assert!(
            msg.starts_with("unknown built-in OCIO config 'ocio://"),
            "{msg}"
        );
    }
}
