//! Bounded reflectances: in [0, 1] with the input XYZ, or shown outside the object-colour solid.

use proptest::prelude::*;
use spectral::bounded::{project, Bounded, Counts, Outcome, Solve};
use spectral::primaries::{apply, RgbSpace, ACESCG, REC2020, SRGB};
use spectral::{Colorimetry, Method, Model, Uplifter};

fn setup() -> &'static (Colorimetry, Bounded<Uplifter>) {
    static U: std::sync::OnceLock<(Colorimetry, Bounded<Uplifter>)> = std::sync::OnceLock::new();
    U.get_or_init(|| {
        let a = Model::builtin().colorimetry().unwrap();
        let up = Uplifter::new(Model::builtin()).unwrap();
        (a.clone(), Bounded::new(up, a).unwrap())
    })
}

fn cube(space: RgbSpace, steps: usize) -> Vec<[f64; 3]> {
    let m = space.to_xyz(setup().0.white_xyz());
    let s = (steps - 1) as f64;
    let mut out = vec![];
    for r in 0..steps {
        for g in 0..steps {
            for b in 0..steps {
                out.push(apply(&m, [r as f64 / s, g as f64 / s, b as f64 / s]));
            }
        }
    }
    out
}

/// u certifies c outside the solid: u·c > Σᵢ max(0, (Aᵀu)ᵢ), checked here independently.
fn certifies(a: &Colorimetry, c: [f64; 3], u: [f64; 3]) -> bool {
    let support: f64 = (0..a.bands())
        .map(|i| (0..3).map(|k| a.weights[k][i] * u[k]).sum::<f64>().max(0.0))
        .sum();
    (0..3).map(|k| u[k] * c[k]).sum::<f64>() > support
}

fn in_range_with_xyz(a: &Colorimetry, c: [f64; 3], r: &[f64], rel: f64) -> bool {
    let back = a.xyz(r);
    let size = c.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    r.iter().all(|v| (0.0..=1.0).contains(v))
        && (0..3).all(|k| (back[k] - c[k]).abs() <= rel * size.max(1e-300))
}

#[test]
fn every_srgb_colour_of_a_17_cube_is_in_range_with_its_xyz_or_outside_the_solid() {
    let (a, bounded) = setup();
    let (mut counts, mut outside) = (Counts::default(), vec![]);
    for c in cube(SRGB, 17) {
        let mut r = vec![0.0; a.bands()];
        bounded.inner().uplift_f64(&c, &mut r);
        let outcome = bounded.bound(c, &mut r);
        match outcome {
            Outcome::InRange | Outcome::Projected => {
                assert!(in_range_with_xyz(a, c, &r, 1e-6), "{c:?} {outcome:?}");
            }
            Outcome::Outside {
                certificate,
                reached,
            } => {
                let u = certificate.expect("a certificate for every sRGB colour outside");
                assert!(certifies(a, c, u), "{c:?}: {u:?} certifies nothing");
                assert!(in_range_with_xyz(a, reached, &r, 1e-6), "{c:?}");
                outside.push(c);
            }
            Outcome::NotFinite => panic!("{c:?}"),
        }
        match outcome {
            Outcome::InRange => counts.in_range += 1,
            Outcome::Projected => counts.projected += 1,
            _ => counts.outside += 1,
        }
    }
    eprintln!("sRGB 17³: {counts:?}; outside: {outside:?}");
    // The projection is needed (the method leaves [0, 1] for saturated colours) and works.
    assert!(counts.projected > 0, "{counts:?}");
}

#[test]
fn counted_uplift_agrees_in_f64_and_f32() {
    let (a, bounded) = setup();
    let xyz: Vec<f64> = cube(REC2020, 9).into_iter().flatten().collect();
    let n = a.bands();
    let mut r64 = vec![0.0; xyz.len() / 3 * n];
    let c64 = bounded.uplift_f64_counted(&xyz, &mut r64);
    let xyz32: Vec<f32> = xyz.iter().map(|&v| v as f32).collect();
    let mut r32 = vec![0.0f32; xyz.len() / 3 * n];
    let c32 = bounded.uplift_f32_counted(&xyz32, &mut r32);
    assert_eq!(c64.in_range + c64.projected + c64.outside, 729);
    assert!(r32.iter().all(|v| (0.0..=1.0).contains(v)));
    assert!(r64.iter().all(|v| (0.0..=1.0).contains(v)));
    assert_eq!(c32.not_finite, 0);
    assert!(c64.projected > 0 && c64.outside > 0, "{c64:?}");
}

#[test]
fn outside_the_solid_moves_towards_grey_keeping_luminance() {
    let (a, bounded) = setup();
    let m = ACESCG.to_xyz(a.white_xyz());
    for rgb in [[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]] {
        let c = apply(&m, rgb);
        let mut r = vec![0.0; a.bands()];
        bounded.inner().uplift_f64(&c, &mut r);
        match bounded.bound(c, &mut r) {
            Outcome::Outside {
                certificate: Some(u),
                reached,
            } => {
                assert!(certifies(a, c, u), "{rgb:?}");
                assert!((reached[1] - c[1]).abs() < 1e-9, "luminance kept");
                assert!(in_range_with_xyz(a, reached, &r, 1e-6));
            }
            other => panic!("ACEScg primary {rgb:?}: {other:?}"),
        }
    }
}

#[test]
fn hard_inputs_through_bounded() {
    let (a, bounded) = setup();
    let n = a.bands();
    let mut r = vec![0.0; n];
    // Black: the zero spectrum, in range.
    bounded.uplift_f64(&[0.0, 0.0, 0.0], &mut r);
    assert!(r.iter().all(|&v| v == 0.0));
    // NaN passes through; counted.
    let counts = bounded.uplift_f64_counted(&[f64::NAN, 0.5, 0.5], &mut r);
    assert_eq!(counts.not_finite, 1);
    assert!(r.iter().all(|v| v.is_nan()));
    // Negative luminance, HDR, huge: outside, in range, finite.
    for c in [[-0.1, -0.2, 0.05], [95.0, 100.0, 108.0], [1e30, 1e30, 1e30]] {
        let counts = bounded.uplift_f64_counted(&c, &mut r);
        assert_eq!(counts.outside, 1, "{c:?}");
        assert!(r.iter().all(|v| (0.0..=1.0).contains(v)), "{c:?}");
    }
    // White exactly: the perfect reflector.
    let counts = bounded.uplift_f64_counted(&a.white_xyz(), &mut r);
    assert!(counts.outside == 0, "{counts:?}");
    assert!(r.iter().all(|v| (v - 1.0).abs() < 1e-9), "{r:?}");
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    /// Any in-range spectrum's colour is inside the solid: the projection of any start must
    /// succeed, be in range, keep the colour, and be no farther from r0 than that spectrum.
    #[test]
    fn projection_is_feasible_and_optimal_against_a_known_point(
        s in prop::collection::vec(0.0..1.0f64, 36),
        noise in prop::collection::vec(-0.6..0.6f64, 36),
    ) {
        let (a, _) = setup();
        let c = a.xyz(&s);
        let r0: Vec<f64> = s.iter().zip(&noise).map(|(v, e)| v + e).collect();
        let mut r = vec![0.0; 36];
        prop_assert_eq!(project(&a.weights, c, &r0, &mut r), Solve::Solved);
        prop_assert!(in_range_with_xyz(a, c, &r, 1e-9));
        let d = |x: &[f64]| x.iter().zip(&r0).map(|(p, q)| (p - q) * (p - q)).sum::<f64>();
        prop_assert!(d(&r) <= d(&s) * (1.0 + 1e-9) + 1e-18);
    }
}
