//! The built-in configs against the Academy's official ACES CG and Studio configs v1.0.0
//! (../shared/ocio, the files OCIO 2.2+ compiles in): every colour space, alias, role,
//! display, view, view transform, look, named transform and file rule, as OpenColorIO 2.1
//! reads both, and the same CIE XYZ for every colour space and the same display values
//! for every view.

use std::path::{Path, PathBuf};

use specconv_ocio::{BuiltinConfig, Config, Processor};

/// `../shared/ocio` beside the checkout (or `$SPECCONV_SHARED/ocio`).
fn official(file: &str) -> PathBuf {
    let dir = std::env::var_os("SPECCONV_SHARED")
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared"));
    let p = dir.join("ocio").join(file);
    assert!(
        p.is_file(),
        "{} not found: tests need ../shared beside the checkout (or SPECCONV_SHARED)",
        p.display()
    );
    p
}

/// Each built-in config with the official file it follows.
fn pairs() -> Vec<(BuiltinConfig, Config, Config)> {
    [BuiltinConfig::Cg, BuiltinConfig::Studio]
        .into_iter()
        .map(|kind| {
            let file = official(&format!("{}.ocio", kind.official_name()));
            (
                kind,
                Config::builtin(kind).unwrap(),
                Config::from_file(file).unwrap(),
            )
        })
        .collect()
}

/// Aliases the built-in configs add to the official ones: the name later ACES configs
/// (v2.0.0) give 'sRGB - Texture', which specconv accepted before.
const EXTRA_ALIASES: [(&str, &str); 1] = [("sRGB - Texture", "sRGB Encoded Rec.709 (sRGB)")];

#[test]
fn every_official_colour_space_and_alias_is_in_the_builtin_config() {
    for (kind, ours, theirs) in pairs() {
        let names = theirs.all_color_space_names().unwrap();
        assert!(names.len() >= 20, "{kind:?}: only {names:?}");
        assert_eq!(ours.all_color_space_names().unwrap(), names, "{kind:?}");
        for name in &names {
            let want = theirs.color_space(name).unwrap();
            let got = ours.color_space(name).unwrap();
            assert_eq!(
                (&got.name, &got.family, &got.encoding),
                (&want.name, &want.family, &want.encoding),
                "{kind:?}: {name}"
            );
            assert_eq!(
                (got.is_data, got.is_display),
                (want.is_data, want.is_display),
                "{kind:?}: {name}"
            );
            let extra: Vec<&str> = EXTRA_ALIASES
                .iter()
                .filter(|(n, _)| n == name)
                .map(|(_, a)| *a)
                .collect();
            let mut expected: Vec<&str> = want.aliases.iter().map(String::as_str).collect();
            expected.extend(&extra);
            assert_eq!(got.aliases, expected, "{kind:?}: aliases of {name}");
            for alias in &want.aliases {
                assert_eq!(&ours.color_space(alias).unwrap().name, name, "{alias}");
            }
        }
    }
}

#[test]
fn the_cg_config_has_the_texture_spaces_users_missed() {
    let cg = Config::builtin(BuiltinConfig::Cg).unwrap();
    for (name, alias) in [
        ("Gamma 2.2 Rec.709 - Texture", "g22_rec709_tx"),
        ("Gamma 1.8 Rec.709 - Texture", "g18_rec709"),
        ("Gamma 2.2 AP1 - Texture", "g22_ap1"),
        ("sRGB Encoded AP1 - Texture", "srgb_ap1"),
    ] {
        assert_eq!(cg.color_space(alias).unwrap().name, name);
    }
    let studio = Config::builtin(BuiltinConfig::Studio).unwrap();
    for name in [
        "ARRI LogC4",
        "S-Log3 S-Gamut3.Cine",
        "V-Log V-Gamut",
        "slog3_sgamutcine",
    ] {
        studio.processor_to_xyz(name).unwrap();
        assert!(cg.color_space(name).is_err(), "{name} is a studio space");
    }
}

#[test]
fn roles_displays_views_looks_and_rules_agree() {
    for (kind, ours, theirs) in pairs() {
        let sorted = |c: &Config| {
            let mut r = c.roles().unwrap();
            r.sort();
            r
        };
        let roles = sorted(&theirs);
        assert!(roles.len() >= 9, "{kind:?}: {roles:?}");
        assert_eq!(sorted(&ours), roles, "{kind:?}: roles");

        let displays = theirs.displays().unwrap();
        assert!(displays.len() >= 5, "{kind:?}: {displays:?}");
        assert_eq!(ours.displays().unwrap(), displays, "{kind:?}: displays");
        for d in &displays {
            let views = theirs.views(d).unwrap();
            assert!(views.len() >= 3, "{kind:?}: {d}: {views:?}");
            assert_eq!(ours.views(d).unwrap(), views, "{kind:?}: views of {d}");
        }
        assert_eq!(
            ours.view_transforms().unwrap(),
            theirs.view_transforms().unwrap(),
            "{kind:?}: view transforms"
        );
        assert_eq!(ours.looks().unwrap(), theirs.looks().unwrap(), "{kind:?}");
        assert_eq!(
            ours.named_transforms().unwrap(),
            theirs.named_transforms().unwrap(),
            "{kind:?}: named transforms"
        );
        let rules = theirs.file_rules().unwrap();
        assert_eq!(rules.len(), 1, "{kind:?}: {rules:?}");
        assert_eq!(ours.file_rules().unwrap(), rules, "{kind:?}: file rules");
    }
}

/// Test pixels: every combination of negatives, zero, small, mid-grey, one and HDR values
/// up to 100 on the three channels.
fn test_image() -> Vec<f32> {
    const VALUES: [f32; 12] = [
        -0.5, -0.01, 0.0, 1e-4, 0.005, 0.05, 0.18, 0.5, 1.0, 4.0, 16.0, 100.0,
    ];
    let mut px = Vec::with_capacity(VALUES.len().pow(3) * 3);
    for r in VALUES {
        for g in VALUES {
            for b in VALUES {
                px.extend([r, g, b]);
            }
        }
    }
    px
}

/// The worst difference of `ours` from `theirs`, per pixel relative to the pixel's
/// largest component (at least 1e-2, so that values near zero are held to 1e-8
/// absolute), or None when a pixel is finite in one and not the other.
fn worst_difference(ours: &[f32], theirs: &[f32]) -> Option<f64> {
    let mut worst = 0f64;
    for (a, b) in ours.chunks(3).zip(theirs.chunks(3)) {
        let scale = b.iter().map(|v| v.abs() as f64).fold(1e-2, f64::max);
        for (&x, &y) in a.iter().zip(b) {
            if !x.is_finite() || !y.is_finite() {
                // Log encodings of 100 overflow; both must overflow alike.
                if x.is_nan() != y.is_nan() || (!x.is_nan() && x != y) {
                    return None;
                }
                continue;
            }
            worst = worst.max((x as f64 - y as f64).abs() / scale);
        }
    }
    Some(worst)
}

fn check(what: &str, ours: &Processor, theirs: &Processor, image: &[f32]) -> f64 {
    let (mut a, mut b) = (image.to_vec(), image.to_vec());
    ours.apply_rgb(&mut a).unwrap();
    theirs.apply_rgb(&mut b).unwrap();
    let worst = worst_difference(&a, &b)
        .unwrap_or_else(|| panic!("{what}: finite in one config, not in the other"));
    assert!(worst <= 1e-6, "{what}: differs by {worst:e}");
    worst
}

#[test]
fn every_colour_space_converts_to_the_same_xyz() {
    let image = test_image();
    for (kind, ours, theirs) in pairs() {
        let mut worst = 0f64;
        let mut n = 0;
        let names = theirs.all_color_space_names().unwrap();
        for name in &names {
            if theirs.color_space(name).unwrap().is_data {
                continue;
            }
            let what = format!("{kind:?}: {name}");
            let w = check(
                &what,
                &ours.processor_to_xyz(name).unwrap(),
                &theirs.processor_to_xyz(name).unwrap(),
                &image,
            );
            worst = worst.max(w);
            n += 1;
        }
        assert_eq!(n, names.len() - 1, "{kind:?}: every colour space but Raw");
        eprintln!("{kind:?}: {n} colour spaces, worst XYZ difference {worst:e}");
    }
}

#[test]
fn every_view_gives_the_same_display_values() {
    let image = test_image();
    for (kind, ours, theirs) in pairs() {
        let mut worst = 0f64;
        for display in theirs.displays().unwrap() {
            for view in theirs.views(&display).unwrap() {
                let what = format!("{kind:?}: {display} / {}", view.name);
                let w = check(
                    &what,
                    &ours
                        .display_view_processor("ACES2065-1", &display, &view.name)
                        .unwrap(),
                    &theirs
                        .display_view_processor("ACES2065-1", &display, &view.name)
                        .unwrap(),
                    &image,
                );
                worst = worst.max(w);
            }
        }
        eprintln!("{kind:?}: worst display-value difference {worst:e}");
    }
}

#[test]
fn the_official_files_are_the_built_in_configs_twins_and_edited_ones_are_not() {
    for (kind, ours, theirs) in pairs() {
        assert_eq!(ours.builtin_twin().unwrap(), Some(kind));
        assert_eq!(theirs.builtin_twin().unwrap(), Some(kind), "{kind:?}");
        // Asked again: the same answer (kept).
        assert_eq!(theirs.builtin_twin().unwrap(), Some(kind));
        let text =
            std::fs::read_to_string(official(&format!("{}.ocio", kind.official_name()))).unwrap();
        let default = "  - !<Rule> {name: Default, colorspace: ACES2065-1}";
        assert!(text.contains(default));
        let added = format!(
            "  - !<Rule> {{name: n, colorspace: Raw, pattern: \"*_n*\", extension: \"*\"}}\n{default}"
        );
        for edited in [
            text.replace(default, "  - !<Rule> {name: Default, colorspace: ACEScg}"),
            text.replace(default, &added),
            text.replace("  data: Raw", "  data: ACEScg"),
        ] {
            assert_ne!(edited, text);
            let config = Config::from_yaml(
                &edited,
                None,
                specconv_ocio::ConfigSource::File("edited.ocio".into()),
            )
            .unwrap();
            assert_eq!(config.builtin_twin().unwrap(), None, "{kind:?}");
        }
    }
}
