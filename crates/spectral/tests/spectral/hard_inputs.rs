//! Hard inputs through the library: every family of the policy table in `specconv_spectral::otsu2018::hard_inputs`, in
//! f64 and f32, table-driven, plus properties over all finite and non-finite colours.

use proptest::prelude::*;
use specconv_colour::mat3::mul_vec as apply;
use specconv_colour::rgb::{RgbSpace, ACES2065_1, ACESCG, REC2020, SRGB};
use specconv_colour::Colorimetry;
use specconv_spectral::otsu2018::hard_inputs::DARK;
use specconv_spectral::{Method, Model, Uplifter};
use specconv_testkit::*;

fn setup() -> &'static (Colorimetry, Uplifter) {
    static U: std::sync::OnceLock<(Colorimetry, Uplifter)> = std::sync::OnceLock::new();
    U.get_or_init(|| {
        (
            Model::builtin().colorimetry().unwrap(),
            Uplifter::new(Model::builtin()).unwrap(),
        )
    })
}

fn up64(c: [f64; 3]) -> Vec<f64> {
    let (a, up) = setup();
    let mut r = vec![0.0; a.bands()];
    up.uplift_f64(&c, &mut r);
    r
}

fn up32(c: [f32; 3]) -> Vec<f32> {
    let (a, up) = setup();
    let mut r = vec![0.0f32; a.bands()];
    up.uplift_f32(&c, &mut r);
    r
}

fn rgb(space: RgbSpace, v: [f64; 3]) -> [f64; 3] {
    apply(&space.to_xyz(setup().0.white_xyz()), v)
}

/// Finite spectrum whose XYZ is c to `rel` of the colour's size (absolute below 1e-300).
fn assert_round_trip(c: [f64; 3], r: &[f64], rel: f64, what: &str) {
    let (a, _) = setup();
    assert!(
        r.iter().all(|v| v.is_finite()),
        "{what} {c:?}: non-finite band"
    );
    let back = a.xyz(r);
    let size = c.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    for k in 0..3 {
        assert!(
            (back[k] - c[k]).abs() <= rel * size.max(1e-300),
            "{what} {c:?}: XYZ back {back:?}"
        );
    }
}

fn check_both(c: [f64; 3], what: &str) -> Vec<f64> {
    let r = up64(c);
    assert_round_trip(c, &r, 1e-12, what);
    // In f32 where the colour is a normal f32 (denormal outputs cannot hold 1e-5).
    let c32 = c.map(|v| v as f32);
    if c32
        .iter()
        .all(|v| v.is_finite() && (*v == 0.0 || v.abs() >= 1e-30))
    {
        let r32: Vec<f64> = up32(c32).iter().map(|&v| v as f64).collect();
        assert_round_trip(c32.map(|v| v as f64), &r32, 1e-5, what);
    }
    r
}

#[test]
fn black_is_the_zero_spectrum() {
    for c in [[0.0, 0.0, 0.0], [-0.0, 0.0, -0.0], [-0.0, -0.0, -0.0]] {
        assert!(up64(c).iter().all(|&v| v == 0.0), "{c:?}");
        assert!(up32(c.map(|v| v as f32)).iter().all(|&v| v == 0.0), "{c:?}");
    }
}

#[test]
fn near_black_keeps_its_shape_and_shrinks_to_zero() {
    let grey = rgb(SRGB, [1.0; 3]);
    let colours = [
        ("grey", grey),
        ("dark red", rgb(SRGB, [1.0, 0.02, 0.02])),
        ("dark green", rgb(SRGB, [0.0, 1.0, 0.0])),
        ("dark blue", rgb(SRGB, [0.0, 0.0, 1.0])),
        ("ACEScg dark cyan", rgb(ACESCG, [0.0, 1.0, 1.0])),
    ];
    for (name, c) in colours {
        let s = c[0] + c[1] + c[2];
        // The same chromaticity at X+Y+Z = DARK, uplifted by the ordinary path.
        let at_dark = up64(c.map(|v| v * DARK / s));
        for k in [1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-30, 1e-300] {
            let dim = c.map(|v| v * k);
            let r = check_both(dim, name);
            let ks = k * s / DARK;
            for (b, (&v, &w)) in r.iter().zip(&at_dark).enumerate() {
                assert!(
                    (v - ks * w).abs() <= 1e-12 * ks * w.abs().max(1.0),
                    "{name} × {k}, band {b}: {v} vs {}",
                    ks * w
                );
            }
        }
    }
}

#[test]
fn dark_scaling_is_continuous_at_the_threshold() {
    let c = rgb(SRGB, [0.2, 0.5, 0.9]);
    let s = c[0] + c[1] + c[2];
    let below = up64(c.map(|v| v * DARK / s * (1.0 - 1e-12)));
    let at = up64(c.map(|v| v * DARK / s));
    let jump = below
        .iter()
        .zip(&at)
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
    assert!(jump < 1e-10, "jump {jump}");
}

#[test]
fn no_chromaticity_is_linear_in_the_colour() {
    // X+Y+Z ≤ 0 but not black: zero and negative luminance.
    let cases = [
        [0.1, 0.0, -0.1],
        [-0.1, -0.2, 0.05],
        [-1e-6, 0.0, 0.0],
        [0.0, -0.5, 0.0],
        [-3.0, -1.0, -2.0],
        [1e300, -1e300, -1e300],
    ];
    for c in cases {
        let r = check_both(c, "no chromaticity");
        let half = up64(c.map(|v| v * 0.5));
        for (v, h) in r.iter().zip(&half) {
            assert!((0.5 * v - h).abs() <= 1e-12 * v.abs().max(1e-300), "{c:?}");
        }
    }
}

/// Red, green, blue, yellow, cyan, magenta at full intensity.
const PRIMARIES_AND_SECONDARIES: [[f64; 3]; 6] = [
    [1.0, 0.0, 0.0],
    [0.0, 1.0, 0.0],
    [0.0, 0.0, 1.0],
    [1.0, 1.0, 0.0],
    [0.0, 1.0, 1.0],
    [1.0, 0.0, 1.0],
];

#[test]
fn negative_components_and_colours_outside_the_locus() {
    // Wide-gamut colours whose XYZ has negative components or xy outside the spectral locus
    // and the training data: AP0 and AP1 primaries and secondaries, Rec.2020 corners.
    let mut cases = vec![];
    for space in [ACES2065_1, ACESCG, REC2020] {
        let beyond = [[2.0, -0.5, 0.1], [-0.2, 0.1, 1.5]];
        for v in PRIMARIES_AND_SECONDARIES.into_iter().chain(beyond) {
            cases.push(rgb(space, v));
        }
    }
    // AP0 blue has Y < 0 (its primary's y is negative).
    assert!(rgb(ACES2065_1, [0.0, 0.0, 1.0])[1] < 0.0);
    for c in cases {
        check_both(c, "wide gamut");
    }
}

#[test]
fn saturated_primaries_secondaries_white_and_greys() {
    for v in PRIMARIES_AND_SECONDARIES {
        check_both(rgb(SRGB, v), "sRGB primary/secondary");
    }
    let (a, _) = setup();
    for g in [1.0, 0.5, 0.18, 0.05, 0.01] {
        let r = check_both(rgb(SRGB, [g; 3]), "grey");
        // Light greys come out within 10 % of flat at their level from 430 to 680 nm; below
        // 420 nm they fall (the Munsell greys reflect little near UV). Dark greys (0.05 and
        // below) are less flat: the affine map's o weighs more as c shrinks.
        for (b, v) in r.iter().enumerate() {
            let nm = a.grid.wavelength(b);
            if g >= 0.18 && (430.0..=680.0).contains(&nm) {
                assert!((v - g).abs() <= 0.1 * g, "grey {g} at {nm} nm: {v}");
            }
        }
    }
}

#[test]
fn colours_outside_the_training_domain() {
    // Chromaticities beyond every training colour, and past the locus: xy corners.
    for xy in [
        [0.0, 0.0],
        [1.0, 0.0],
        [0.0, 1.0],
        [0.9, 0.9],
        [-0.5, 0.3],
        [0.3, -2.0],
        [5.0, 5.0],
    ] {
        let c = [xy[0], xy[1], 1.0 - xy[0] - xy[1]].map(|v| v * 0.5);
        check_both(c, "outside training domain");
    }
}

#[test]
fn hdr_values_stay_finite_and_round_trip() {
    let white = rgb(SRGB, [1.0; 3]);
    let red = rgb(SRGB, [1.0, 0.0, 0.0]);
    for k in [1e2, 1e4, 65504.0, 1e30] {
        check_both(white.map(|v| v * k), "HDR white");
        check_both(red.map(|v| v * k), "HDR red");
        let at1 = up64(red);
        // Above 1 the affine map still applies: r(k·c) = k·T·c + o.
        let r = up64(red.map(|v| v * k));
        let shape: Vec<f64> = r.iter().map(|v| v / k).collect();
        let diff = shape
            .iter()
            .zip(&at1)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(diff < 2.0, "shape of red × {k} drifts by {diff}");
    }
}

#[test]
fn largest_floats_saturate_instead_of_overflowing() {
    for c in [
        [f64::MAX, f64::MAX, f64::MAX],
        [f64::MAX, -f64::MAX, 1.0],
        [1e300, 1e300, 1e300],
    ] {
        assert!(up64(c).iter().all(|v| v.is_finite()), "{c:?}");
    }
    for c in [
        [f32::MAX, f32::MAX, f32::MAX],
        [f32::MAX, -f32::MAX, 1.0],
        [1e38, 0.0, 0.0],
    ] {
        assert!(up32(c).iter().all(|v| v.is_finite()), "{c:?}");
    }
}

#[test]
fn denormals_are_tiny_finite_spectra() {
    let tiny = f64::MIN_POSITIVE / 4.0;
    for c in [
        [tiny, tiny, tiny],
        [5e-324, 0.0, 0.0],
        [tiny, -tiny, 5e-324],
    ] {
        let r = up64(c);
        assert!(r.iter().all(|v| v.is_finite() && v.abs() < 1e-300), "{c:?}");
    }
    let t32 = f32::MIN_POSITIVE / 8.0;
    for c in [[t32, t32, t32], [1e-45, 0.0, 0.0], [0.0, t32, -1e-45]] {
        let r = up32(c);
        assert!(r.iter().all(|v| v.is_finite() && v.abs() < 1e-30), "{c:?}");
        check_both(c.map(|v| v as f64), "f32 denormal");
    }
}

#[test]
fn nan_and_infinity_in_any_channel_give_nan_in_every_band() {
    for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        for k in 0..3 {
            let mut c = [0.3, 0.4, 0.2];
            c[k] = bad;
            assert!(up64(c).iter().all(|v| v.is_nan()), "{c:?}");
            assert!(
                up32(c.map(|v| v as f32)).iter().all(|v| v.is_nan()),
                "{c:?}"
            );
        }
    }
    assert!(up64([f64::INFINITY, f64::NEG_INFINITY, 0.0])
        .iter()
        .all(|v| v.is_nan()));
}

#[test]
fn training_colours_are_not_touched_by_the_dark_policy() {
    // DARK lies below every measured colour, so Table 1 and eval are unchanged.
    let (a, _) = setup();
    for file in [MUNSELL, COLORCHECKER] {
        let s = set(file, &a.grid);
        let darkest = s
            .spectra
            .iter()
            .map(|r| a.xyz(r).iter().sum::<f64>())
            .fold(f64::INFINITY, f64::min);
        assert!(darkest > 2.0 * DARK, "{file}: darkest X+Y+Z {darkest}");
    }
}

fn any_f64() -> impl Strategy<Value = f64> {
    prop_oneof![
        -2.0..2.0f64,
        (-300i32..300, -1.0..1.0f64).prop_map(|(e, m)| m * 10f64.powi(e)),
        Just(0.0),
        Just(-0.0),
        Just(5e-324),
        Just(f64::MAX),
        Just(-f64::MAX),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]

    #[test]
    fn every_finite_colour_gives_a_finite_spectrum_with_its_xyz(
        x in any_f64(), y in any_f64(), z in any_f64()
    ) {
        let c = [x, y, z];
        let r = up64(c);
        prop_assert!(r.iter().all(|v| v.is_finite()));
        let size = c.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        if size < 1e300 {
            let back = setup().0.xyz(&r);
            // Relative to the colour's size; the dark policy and huge values included.
            for k in 0..3 {
                prop_assert!((back[k] - c[k]).abs() <= 1e-10 * size.max(1e-290), "{:?} {:?}", c, back);
            }
        }
        let c32 = c.map(|v| v as f32);
        if c32.iter().all(|v| v.is_finite()) {
            prop_assert!(up32(c32).iter().all(|v| v.is_finite()));
        }
    }

    #[test]
    fn any_non_finite_component_gives_nan_everywhere(
        x in any_f64(), y in any_f64(), k in 0usize..3,
        bad in prop_oneof![Just(f64::NAN), Just(f64::INFINITY), Just(f64::NEG_INFINITY)]
    ) {
        let mut c = [x, y, 0.5];
        c[k] = bad;
        prop_assert!(up64(c).iter().all(|v| v.is_nan()));
        prop_assert!(up32(c.map(|v| v as f32)).iter().all(|v| v.is_nan()));
    }

    #[test]
    fn below_dark_the_uplift_is_scale_invariant(
        x in 0.0..1.0f64, y in 0.01..1.0f64, z in 0.0..1.0f64, k in 1e-12..1.0f64
    ) {
        let s = x + y + z;
        let c = [x, y, z].map(|v| v / s * DARK * 0.5);
        let r = up64(c);
        let rk = up64(c.map(|v| v * k));
        for (a, b) in r.iter().zip(&rk) {
            prop_assert!((a * k - b).abs() <= 1e-12 * a.abs().max(1e-3) * k.max(1e-300) + 1e-300);
        }
    }
}

/// A colour of one class of the policy table in `specconv_spectral::otsu2018::hard_inputs`, generated from its own
/// distribution, so that every class is exercised (a generic float rarely lands near black or
/// outside the locus at a chosen luminance).
fn class_colour() -> impl Strategy<Value = (&'static str, [f64; 3])> {
    // A chromaticity anywhere (inside the locus or far outside it) as XYZ with X+Y+Z = 1.
    let xy = (-1.0..2.0f64, -1.0..2.0f64).prop_map(|(x, y)| [x, y, 1.0 - x - y]);
    let locus = (0.1..0.6f64, 0.1..0.6f64).prop_map(|(x, y)| [x, y, 1.0 - x - y]);
    let unit = (-0.5..1.5f64, -0.5..1.5f64, -0.5..1.5f64);
    prop_oneof![
        prop::sample::select(vec![[0.0; 3], [-0.0, 0.0, -0.0], [-0.0; 3]])
            .prop_map(|c| ("black", c)),
        (locus.clone(), -8.0..-4.0f64)
            .prop_map(|(c, e)| ("near black", c.map(|v| v * 10f64.powf(e)))),
        (
            0u64..1 << 52,
            0u64..1 << 52,
            0u64..1 << 52,
            any::<[bool; 3]>()
        )
            .prop_map(|(a, b, c, s)| {
                // Subnormal f64s: the exponent bits zero, any mantissa and sign.
                let d = |m: u64, neg: bool| f64::from_bits(m | (neg as u64) << 63);
                ("denormal", [d(a, s[0]), d(b, s[1]), d(c, s[2])])
            }),
        (-2.0..2.0f64, -2.0..2.0f64, -4.0..0.0f64)
            .prop_map(|(x, y, s)| ("negative luminance", [x, y, s - x - y])),
        (
            unit,
            prop::sample::select(vec![ACES2065_1, ACESCG, REC2020])
        )
            .prop_map(|((r, g, b), space)| ("wide gamut", rgb(space, [r, g, b]))),
        (locus, 2.0..30.0f64).prop_map(|(c, e)| ("HDR", c.map(|v| v * 10f64.powf(e)))),
        (xy, -2.0..1.0f64).prop_map(|(c, e)| ("outside the locus", c.map(|v| v * 10f64.powf(e)))),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(3000))]

    #[test]
    fn every_class_gives_finite_spectra_that_keep_the_colour((class, c) in class_colour()) {
        let r = up64(c);
        prop_assert!(r.iter().all(|v| v.is_finite()), "{class} {c:?}");
        let back = setup().0.xyz(&r);
        let size = c.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        for k in 0..3 {
            // Relative to the colour's size; subnormal colours to the smallest normal float.
            prop_assert!(
                (back[k] - c[k]).abs() <= 1e-10 * size.max(f64::MIN_POSITIVE),
                "{class} {c:?}: XYZ back {back:?}"
            );
        }
        if class == "black" {
            prop_assert!(r.iter().all(|&v| v == 0.0));
        }
        // In f32: finite always; the colour kept where it is a normal f32.
        let c32 = c.map(|v| v as f32);
        let r32 = up32(c32);
        prop_assert!(r32.iter().all(|v| v.is_finite()), "{class} {c32:?}");
        let size32 = c32.iter().fold(0.0f32, |m, v| m.max(v.abs())) as f64;
        if c32.iter().all(|v| *v == 0.0 || v.abs() >= f32::MIN_POSITIVE) && size32 < 1e30 {
            let back = setup().0.xyz(&r32.iter().map(|&v| v as f64).collect::<Vec<_>>());
            for k in 0..3 {
                prop_assert!(
                    (back[k] - c32[k] as f64).abs() <= 1e-4 * size32,
                    "{class} {c32:?}: f32 XYZ back {back:?}"
                );
            }
        }
    }
}
