//! The built-in model's spectra stay bounded on whole gamuts, far from its training colours.

use specconv_colour::rgb::{REC2020, SRGB};
use specconv_evaluation::extrapolation::{rgb_cube, training_gains, uplift_gains, worst};
use specconv_spectral::otsu2018::hard_inputs::DARK;
use specconv_spectral::{Model, Uplifter};
use specconv_testkit::*;

/// Per leaf, a bound on gain∞ = ‖r‖∞ / (X+Y+Z) for every colour with X, Y, Z ≥ 0 (s = X+Y+Z):
/// r = T·c + w·o with w = min(1, s/DARK) (the dark policy), so each band has
/// |r_b| ≤ Σ_j |T_bj|·c_j + |o_b|·w ≤ max|T|·s + ‖o‖∞·s/DARK, read from the leaf's map.
fn analytic_bounds(model: &Model, up: &Uplifter) -> Vec<f64> {
    let n = up.bands();
    let max_abs = |v: &[f64]| v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    (0..model.leaves.len())
        .map(|k| {
            let t = up.affine(k);
            max_abs(&t[..3 * n]) + max_abs(&t[3 * n..]) / DARK
        })
        .collect()
}

#[test]
fn builtin_gains_stay_within_the_bound_of_each_leaf() {
    let model = Model::builtin();
    let a = model.colorimetry().unwrap();
    let up = Uplifter::new(model).unwrap();
    let bounds = analytic_bounds(model, &up);
    // sRGB's matrix has no negative entry: its cube's XYZ are all ≥ 0, as the bound needs.
    let gains = uplift_gains(&up, &rgb_cube(&SRGB, a.white_xyz(), 65));
    assert_eq!(gains.len(), model.leaves.len(), "every leaf serves sRGB");
    for (k, (g, b)) in gains.iter().zip(&bounds).enumerate() {
        eprintln!("leaf {k}: gain∞ {:.3}, bound {b:.3}", g.linf);
        assert!(g.count > 0 && g.linf <= *b, "leaf {k}: {g:?} above {b}");
        // The RMS norm is at most the largest value.
        assert!(g.l2 <= g.linf);
    }
}

#[test]
fn bright_in_gamut_colours_are_no_wilder_than_measured_spectra() {
    // Measured reflectances show how large a physical spectrum of a colour gets; the darkest
    // Munsell chips reach gain∞ ≈ 3.2. Colours at least as bright as the dark Munsell chips
    // (X+Y+Z ≥ 0.1) uplift within 2.5× that on the sRGB and Rec.2020 cubes (measured with
    // `extended` 1.55× and 1.82×; with `open`, the default since issue 43, 1.78× and 2.47×, at
    // a saturated red-orange on Rec.2020's edge, X+Y+Z = 0.11, whose largest band is 0.89);
    // below, the offset o of the dark policy dominates, and the analytic bound of the test
    // above holds.
    let model = Model::builtin();
    let a = model.colorimetry().unwrap();
    let up = Uplifter::new(model).unwrap();
    let measured = worst(&training_gains(&a, &up, &set(MUNSELL, &a.grid).spectra));
    assert_eq!(measured.count, 1269);
    for space in [SRGB, REC2020] {
        let bright: Vec<[f64; 3]> = rgb_cube(&space, a.white_xyz(), 65)
            .into_iter()
            .filter(|c| c.iter().sum::<f64>() >= 0.1)
            .collect();
        let g = worst(&uplift_gains(&up, &bright));
        eprintln!(
            "{}: gain∞ {:.3} vs Munsell {:.3}",
            space.name, g.linf, measured.linf
        );
        assert!(g.linf <= 2.5 * measured.linf, "{}: {g:?}", space.name);
    }
}
