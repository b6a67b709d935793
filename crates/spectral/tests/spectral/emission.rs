//! Emission spectra: XYZ under the observer alone equals the input, the shape does not depend
//! on brightness, bounded emission is non-negative, hard inputs have their documented outcome.

use specconv_colour::mat3::mul_vec as apply;
use specconv_colour::rgb::SRGB;
use specconv_colour::{Colorimetry, Illuminant};
use specconv_spectral::bounded::Bounded;
use specconv_spectral::emission::{emission_colorimetry, Emissive};
use specconv_spectral::{Method, Model, Uplifter};

type Stack = Emissive<Bounded<Uplifter>>;

fn setup() -> &'static (Colorimetry, Colorimetry, Stack) {
    static S: std::sync::OnceLock<(Colorimetry, Colorimetry, Stack)> = std::sync::OnceLock::new();
    S.get_or_init(|| {
        let model = Model::builtin();
        let a = model.colorimetry().unwrap();
        let e = emission_colorimetry(model.grid, model.observer).unwrap();
        let up = Uplifter::new(model).unwrap();
        let stack = Emissive::new(Bounded::new(up, a.clone()).unwrap(), a.clone()).unwrap();
        (a, e, stack)
    })
}

/// Linear sRGB colours of a 5³ cube (black left out), as XYZ.
fn srgb_cube() -> Vec<[f64; 3]> {
    let m = SRGB.to_xyz(setup().0.white_xyz());
    let mut out = vec![];
    for r in 0..5 {
        for g in 0..5 {
            for b in 0..5 {
                if r + g + b > 0 {
                    out.push(apply(&m, [r, g, b].map(|v| v as f64 / 4.0)));
                }
            }
        }
    }
    out
}

fn uplift(c: [f64; 3]) -> Vec<f64> {
    let (a, _, stack) = setup();
    let mut l = vec![0.0; a.bands()];
    assert_eq!(stack.uplift_f64_counted(&c, &mut l), 0, "{c:?} is matched");
    l
}

fn rel_err(got: [f64; 3], want: [f64; 3]) -> f64 {
    let size = want.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    (0..3).fold(0.0, |m, k| m.max((got[k] - want[k]).abs() / size))
}

#[test]
fn emission_has_the_input_colour_under_the_observer_alone_and_is_non_negative() {
    let (_, e, _) = setup();
    for c in srgb_cube() {
        for t in [1e-3, 1.0, 40.0, 65504.0] {
            let c = c.map(|v| v * t);
            let l = uplift(c);
            let err = rel_err(e.xyz(&l), c);
            assert!(err < 1e-9, "{c:?}: XYZₑ off by {err}");
            assert!(
                l.iter().all(|v| *v >= 0.0),
                "{c:?}: negative emission {l:?}"
            );
        }
    }
}

#[test]
fn a_flat_spectrum_has_unit_luminance_and_a_grey_emits_the_illuminant() {
    let (a, e, stack) = setup();
    let flat = e.xyz(&vec![1.0; e.bands()]);
    assert!((flat[1] - 1.0).abs() < 1e-12, "{flat:?}");
    // The white of the input space at Y = 5: L ∝ D65 × the reflectance of a mid grey.
    let c = a.white_xyz().map(|v| v * 5.0);
    let l = uplift(c);
    let d65 = Illuminant::D65.spd(&a.grid).unwrap();
    let mut grey = vec![0.0; a.bands()];
    stack
        .inner()
        .uplift_f64(&a.white_xyz().map(|v| v * 0.5), &mut grey);
    let k = l[17] / (d65[17] * grey[17]);
    for ((v, i), g) in l.iter().zip(&d65).zip(&grey) {
        assert!(
            (v - k * i * g).abs() <= 1e-9 * v.abs(),
            "{v} vs {}",
            k * i * g
        );
    }
    // k: the emission of Y = 5 from a reflectance of Y = 1/2 under D65 normalised to Y = 1.
    // m = 2·5 and Σ ȳ / Σ I·ȳ.
    let seen: f64 = d65.iter().zip(&e.weights[1]).map(|(i, y)| i * y).sum();
    assert!((k - 10.0 / seen).abs() < 1e-9 * k, "{k}");
}

#[test]
fn shape_does_not_depend_on_brightness() {
    let (a, _, stack) = setup();
    let n = a.bands();
    let mut tally = specconv_spectral::method::Tally::default();
    for c in srgb_cube() {
        let base = uplift(c);
        // Powers of two scale the spectrum bit for bit, other factors to rounding.
        for t in [2f64.powi(-10), 0.5, 4.0, 65536.0] {
            let l = uplift(c.map(|v| v * t));
            let want: Vec<f64> = base.iter().map(|v| v * t).collect();
            assert_eq!(l, want, "{c:?} × {t}");
        }
        for t in [1e-3, 0.37, 3.3, 100.0, 4097.0, 65504.0] {
            let l = uplift(c.map(|v| v * t));
            for (got, v) in l.iter().zip(&base) {
                assert!(
                    (got - v * t).abs() <= 1e-9 * t,
                    "{c:?} × {t}: {got} vs {}",
                    v * t
                );
            }
        }
        // In f32 too, to its rounding.
        let c32 = c.map(|v| v as f32);
        let mut base32 = vec![0.0f32; n];
        stack.uplift_f32(&c32, &mut base32);
        for t in [1e-3f32, 3.3, 65504.0] {
            let mut l = vec![0.0f32; n];
            stack.uplift_f32_tallied(&c32.map(|v| v * t), &mut l, &mut tally);
            let size = base32.iter().fold(0.0f32, |m, v| m.max(v.abs())) * t;
            for (got, v) in l.iter().zip(&base32) {
                assert!(
                    (got - v * t).abs() <= 1e-5 * size,
                    "{c:?} × {t}: {got} vs {}",
                    v * t
                );
            }
        }
    }
    assert_eq!(tally.unmatched, 0);
}

#[test]
fn saturated_bright_colours_are_halved_into_the_solid_and_still_match() {
    let (a, e, stack) = setup();
    // Linear sRGB red at the top of the box is outside the object-colour solid: the bounded
    // method cannot give it its colour; the emission still has it exactly.
    let c = apply(&SRGB.to_xyz(a.white_xyz()), [30.0, 0.0, 0.0]);
    let m = 2.0 * c[0] / a.white_xyz()[0];
    let mut r = vec![0.0; a.bands()];
    stack.inner().uplift_f64(&c.map(|v| v / m), &mut r);
    assert!(
        rel_err(a.xyz(&r), c.map(|v| v / m)) > 1e-3,
        "the top of the box is outside"
    );
    let l = uplift(c);
    assert!(rel_err(e.xyz(&l), c) < 1e-9);
}

#[test]
fn hard_inputs_have_their_documented_outcome() {
    let (a, e, stack) = setup();
    let n = a.bands();
    let colours: [[f32; 3]; 6] = [
        [0.0, 0.0, 0.0],
        [f32::NAN, 0.2, 0.1],
        [f32::INFINITY, 0.0, 0.0],
        [1e30, 1.1e30, 1e30],
        [f32::MAX, f32::MAX, f32::MAX],
        [0.1, -0.3, 0.2],
    ];
    let mut l = vec![0.0f32; n * colours.len()];
    let unmatched = stack.uplift_f32_counted(colours.as_flattened(), &mut l);
    let l: Vec<&[f32]> = l.chunks_exact(n).collect();
    assert!(l[0].iter().all(|v| *v == 0.0), "black: zero spectrum");
    for s in &l[1..3] {
        assert!(
            s.iter().all(|v| v.is_nan()),
            "NaN or Inf: NaN in every band"
        );
    }
    let huge = l[3].iter().map(|v| *v as f64).collect::<Vec<_>>();
    assert!(l[3].iter().all(|v| v.is_finite() && *v >= 0.0));
    let err = rel_err(e.xyz(&huge), [1e30, 1.1e30, 1e30].map(|v: f32| v as f64));
    assert!(err < 1e-5, "1e30 keeps its colour: {err}");
    assert!(
        l[4].iter().all(|v| v.is_finite()),
        "saturates at f32::MAX, never ∞"
    );
    // Negative luminance: no emission has it; bounded gives the non-negative spectrum of the
    // colour it reaches, and counts it.
    assert!(
        l[5].iter().all(|v| v.is_finite() && *v >= 0.0),
        "{:?}",
        l[5]
    );
    assert_eq!(unmatched, 1);
    // The unbounded uplift reproduces it (with negative bands).
    let plain = Emissive::new(Uplifter::new(Model::builtin()).unwrap(), a.clone()).unwrap();
    let mut r = vec![0.0; n];
    let c = [0.1, -0.3, 0.2];
    assert_eq!(plain.uplift_f64_counted(&c, &mut r), 0);
    assert!(rel_err(e.xyz(&r), c) < 1e-9);
    assert!(r.iter().any(|v| *v < 0.0));
    // Counted through the Method trait too, into the caller's tally, each call its own.
    let mut tally = specconv_spectral::method::Tally::default();
    let mut r32 = vec![0.0f32; n];
    stack.uplift_f32_tallied(&c.map(|v| v as f32), &mut r32, &mut tally);
    assert_eq!(tally.unmatched, 1);
    stack.uplift_f32_tallied(&[0.2, 0.2, 0.2], &mut r32, &mut tally);
    assert_eq!(tally.unmatched, 1);
}

#[test]
fn a_method_on_another_grid_is_refused() {
    let (a, _, _) = setup();
    let other = Colorimetry::new(
        specconv_colour::Grid::new(400.0, 700.0, 10.0).unwrap(),
        a.observer,
        a.illuminant,
    )
    .unwrap();
    let err = Emissive::new(Uplifter::new(Model::builtin()).unwrap(), other)
        .err()
        .unwrap();
    assert!(err.to_string().contains("grid"), "{err}");
}

#[test]
fn every_convention_is_exact_in_the_readers_integration() {
    use specconv_colour::EmissionUnits;
    use specconv_spectral::emission::EmissionSetting;
    use specconv_spectral::resample::Resampled;
    let model = Model::builtin();
    let mut flat_y = Vec::new();
    for units in EmissionUnits::ALL {
        let s = EmissionSetting::new(model.grid, model.observer, model.illuminant, units).unwrap();
        let corrected = Resampled::new(Uplifter::new(model).unwrap(), s.reflectance.clone());
        let bounded = Bounded::new(corrected.unwrap(), s.reflectance.clone()).unwrap();
        let stack = Emissive::in_setting(bounded, &s).unwrap();
        for c in srgb_cube() {
            let c = c.map(|v| v * 40.0);
            let mut l = vec![0.0; s.emission.wavelengths.len()];
            assert_eq!(stack.uplift_f64_counted(&c, &mut l), 0);
            let err = rel_err(s.emission.xyz(&l), c);
            assert!(err < 1e-9, "{units}: {c:?} off by {err}");
            assert!(l.iter().all(|v| *v >= 0.0), "{units}: negative emission");
        }
        flat_y.push(s.emission.xyz(&vec![1.0; model.grid.len()])[1]);
    }
    // reference: ∫ ȳ dλ over 380–730 nm; normalised: 1; photometric: 683·∫ ȳ dλ.
    assert!((flat_y[0] - 106.8).abs() < 0.1, "{flat_y:?}");
    assert!((flat_y[1] - 1.0).abs() < 1e-12, "{flat_y:?}");
    assert!((flat_y[2] / flat_y[0] - 683.0).abs() < 1e-9, "{flat_y:?}");
}
