//! CIELAB and the CIEDE2000 colour difference, for round-trip errors and the Jakob 2019 fit.

/// CIE 1976 L*a*b* of `xyz` relative to the reference white `white` (CIE 15:2018, Eq. 8.1–8.3).
pub fn xyz_to_lab(xyz: [f64; 3], white: [f64; 3]) -> [f64; 3] {
    lab_of_f([0, 1, 2].map(|k| f(xyz[k] / white[k])))
}

/// L*, a*, b* from CIE's f of X/Xn, Y/Yn and Z/Zn.
fn lab_of_f([fx, fy, fz]: [f64; 3]) -> [f64; 3] {
    [116.0 * fy - 16.0, 500.0 * (fx - fy), 200.0 * (fy - fz)]
}

/// CIELAB of `xyz` and its Jacobian ∂(L*, a*, b*)/∂(X, Y, Z) (rows L*, a*, b*). The formula
/// is continuous with a continuous derivative for every XYZ, negative and above white too.
/// One cube root a component serves f and its derivative (the outside search evaluates this
/// at every step; the values are those of [`xyz_to_lab`] bit for bit).
pub fn xyz_to_lab_jacobian(xyz: [f64; 3], white: [f64; 3]) -> ([f64; 3], [[f64; 3]; 3]) {
    let (mut fv, mut dv) = ([0.0; 3], [0.0; 3]);
    for k in 0..3 {
        let t = xyz[k] / white[k];
        let d = if t > 216.0 / 24389.0 {
            let q = t.cbrt();
            fv[k] = q;
            1.0 / (3.0 * q.powi(2))
        } else {
            fv[k] = f(t);
            841.0 / 108.0
        };
        dv[k] = d / white[k];
    }
    let [dx, dy, dz] = dv;
    let j = [
        [0.0, 116.0 * dy, 0.0],
        [500.0 * dx, -500.0 * dy, 0.0],
        [0.0, 200.0 * dy, -200.0 * dz],
    ];
    (lab_of_f(fv), j)
}

/// CIE 1976 L* of a luminance `y` relative to the white's `white_y`: [`xyz_to_lab`]'s L* alone.
pub fn lightness(y: f64, white_y: f64) -> f64 {
    116.0 * f(y / white_y) - 16.0
}

/// A lower bound of [`ciede2000`] from the two colours' L* alone: |ΔL|/S_L. The chroma and hue
/// terms, rotation included, add a square that is never negative (|R_T| ≤ 2), so a colour whose
/// bound is no nearer than a distance found need not be measured.
pub fn ciede2000_lightness_bound(l1: f64, l2: f64) -> f64 {
    (l2 - l1).abs() / s_l(0.5 * (l1 + l2))
}

/// A lower bound of [`ciede2000`] without its angles, at most its value as computed: the
/// lightness term, and the chroma and hue terms together, which are no less than
/// (1 − R_C/2)·(Δa² + Δb²)/S_C² (|R_T| ≤ R_C; ΔC′² + ΔH′² = Δa′² + Δb² ≥ Δa² + Δb²; S_H ≤
/// S_C, T being below 3), with C̄′ ≤ 1.5·C̄ (G ≤ 1/2) putting R_C and S_C at their largest.
/// Shrunk by 1e-9 of itself and 1e-12, more than ciede2000's rounding, so that a colour it
/// puts beyond a distance found is beyond it as ciede2000 computes too.
pub fn ciede2000_lower_bound(lab1: [f64; 3], lab2: [f64; 3]) -> f64 {
    let [l1, a1, b1] = lab1;
    let [l2, a2, b2] = lab2;
    let cbar = 0.75 * ((a1 * a1 + b1 * b1).sqrt() + (a2 * a2 + b2 * b2).sqrt());
    let c7 = cbar.powi(7);
    let rc = 2.0 * (c7 / (c7 + 25f64.powi(7))).sqrt();
    let sc = 1.0 + 0.045 * cbar;
    let (da, db) = (a2 - a1, b2 - b1);
    let l = (l2 - l1) / s_l(0.5 * (l1 + l2));
    let ab = (1.0 - 0.5 * rc).max(0.0) * (da * da + db * db) / (sc * sc);
    (l * l + ab).sqrt() * (1.0 - 1e-9) - 1e-12
}

/// CIEDE2000's lightness weight S_L at the mean L*.
fn s_l(lbar: f64) -> f64 {
    let l50 = (lbar - 50.0).powi(2);
    1.0 + 0.015 * l50 / (20.0 + l50).sqrt()
}

/// CIE's f(t): the cube root above (6/29)³, and its linear segment below.
fn f(t: f64) -> f64 {
    if t > 216.0 / 24389.0 {
        t.cbrt()
    } else {
        t * (841.0 / 108.0) + 4.0 / 29.0
    }
}

/// CIEDE2000 ΔE₀₀ with k_L = k_C = k_H = 1, as written out by Sharma, Wu and Dalal, "The
/// CIEDE2000 Color-Difference Formula: Implementation Notes, Supplementary Test Data, and
/// Mathematical Observations" (Color Res. Appl. 30(1), 2005), Eq. 1–16.
pub fn ciede2000(lab1: [f64; 3], lab2: [f64; 3]) -> f64 {
    use std::f64::consts::PI;
    let deg = PI / 180.0;
    let [l1, a1, b1] = lab1;
    let [l2, a2, b2] = lab2;
    let c1 = a1.hypot(b1);
    let c2 = a2.hypot(b2);
    let cbar = 0.5 * (c1 + c2);
    let c7 = cbar.powi(7);
    let g = 0.5 * (1.0 - (c7 / (c7 + 25f64.powi(7))).sqrt());
    let a1p = (1.0 + g) * a1;
    let a2p = (1.0 + g) * a2;
    let c1p = a1p.hypot(b1);
    let c2p = a2p.hypot(b2);
    let hue = |b: f64, a: f64| {
        if a == 0.0 && b == 0.0 {
            0.0
        } else {
            let h = b.atan2(a);
            if h < 0.0 {
                h + 2.0 * PI
            } else {
                h
            }
        }
    };
    let h1p = hue(b1, a1p);
    let h2p = hue(b2, a2p);
    let dlp = l2 - l1;
    let dcp = c2p - c1p;
    let dhp = if c1p * c2p == 0.0 {
        0.0
    } else {
        let d = h2p - h1p;
        if d > PI {
            d - 2.0 * PI
        } else if d < -PI {
            d + 2.0 * PI
        } else {
            d
        }
    };
    let dhp_big = 2.0 * (c1p * c2p).sqrt() * (0.5 * dhp).sin();
    let lbarp = 0.5 * (l1 + l2);
    let cbarp = 0.5 * (c1p + c2p);
    let hbarp = if c1p * c2p == 0.0 {
        h1p + h2p
    } else if (h1p - h2p).abs() <= PI {
        0.5 * (h1p + h2p)
    } else if h1p + h2p < 2.0 * PI {
        0.5 * (h1p + h2p + 2.0 * PI)
    } else {
        0.5 * (h1p + h2p - 2.0 * PI)
    };
    let t = 1.0 - 0.17 * (hbarp - 30.0 * deg).cos()
        + 0.24 * (2.0 * hbarp).cos()
        + 0.32 * (3.0 * hbarp + 6.0 * deg).cos()
        - 0.20 * (4.0 * hbarp - 63.0 * deg).cos();
    let dtheta = 30.0 * deg * (-((hbarp / deg - 275.0) / 25.0).powi(2)).exp();
    let cbarp7 = cbarp.powi(7);
    let rc = 2.0 * (cbarp7 / (cbarp7 + 25f64.powi(7))).sqrt();
    let sl = s_l(lbarp);
    let sc = 1.0 + 0.045 * cbarp;
    let sh = 1.0 + 0.015 * cbarp * t;
    let rt = -(2.0 * dtheta).sin() * rc;
    let (x, y, z) = (dlp / sl, dcp / sc, dhp_big / sh);
    (x * x + y * y + z * z + rt * y * z).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The lightness bound is never above ΔE₀₀ (pairs of every kind, near and far, greys,
    /// saturated, rotated blues where R_T acts), is reached where only L* differs, and
    /// `lightness` is `xyz_to_lab`'s L*.
    #[test]
    fn the_lightness_bound_is_below_ciede2000() {
        let mut seed = 0x2545_f491_4f6c_dd1du64;
        let mut next = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        for i in 0..200_000 {
            let scale = [0.01, 1.0, 100.0][i % 3];
            let a = [
                100.0 * next(),
                200.0 * next() - 100.0,
                200.0 * next() - 100.0,
            ];
            let b = [0, 1, 2].map(|k| a[k] + scale * (2.0 * next() - 1.0));
            let bound = ciede2000_lightness_bound(a[0], b[0]);
            assert!(bound <= ciede2000(a, b) * (1.0 + 1e-12), "{a:?} {b:?}");
        }
        let (a, b) = ([40.0, 10.0, -30.0], [41.0, 10.0, -30.0]);
        assert!((ciede2000_lightness_bound(a[0], b[0]) - ciede2000(a, b)).abs() < 1e-12);
        let white = [0.95047, 1.0, 1.08883];
        for y in [0.0, 0.001, 0.2, 1.0, 3.0] {
            let l = xyz_to_lab([0.3, y, 0.2], white)[0];
            assert_eq!(lightness(y, white[1]), l);
        }
    }

    /// The angle-free bound is never above ΔE₀₀ as computed (no tolerance: the search relies on
    /// it bit for bit), over pairs near and far, greys, saturated colours and blues where R_T
    /// turns the chroma and hue terms; and it is close for near-greys, where the half-colour
    /// search needs it (a bound of 0 would pass the first part).
    #[test]
    fn the_lower_bound_is_below_ciede2000_and_close_for_greys() {
        let mut rng = specconv_testkit_free_rng(0x9e37_79b9_7f4a_7c15);
        let mut closest = f64::INFINITY;
        for i in 0..400_000 {
            let scale = [1e-5, 0.01, 1.0, 100.0][i % 4];
            let chroma = [0.5, 5.0, 40.0, 120.0][i / 4 % 4];
            let a = [
                100.0 * rng(),
                chroma * (2.0 * rng() - 1.0),
                chroma * (2.0 * rng() - 1.0),
            ];
            let b = [0, 1, 2].map(|k| a[k] + scale * (2.0 * rng() - 1.0));
            let (bound, d) = (ciede2000_lower_bound(a, b), ciede2000(a, b));
            assert!(bound <= d, "{a:?} {b:?}: {bound} > {d}");
            if chroma == 0.5 && scale == 0.01 {
                closest = closest.min(bound / d);
            }
        }
        // Blues (h near 275°) of high chroma, where R_T is largest.
        for k in 0..20_000 {
            let h = (250.0 + 50.0 * f64::from(k % 100) / 100.0).to_radians();
            let (c, l) = (
                20.0 + f64::from(k % 7) * 15.0,
                20.0 + f64::from(k % 11) * 6.0,
            );
            let a = [l, c * h.cos(), c * h.sin()];
            let b = [l + 0.01 * rng(), a[1] + rng() - 0.5, a[2] + rng() - 0.5];
            assert!(
                ciede2000_lower_bound(a, b) <= ciede2000(a, b),
                "{a:?} {b:?}"
            );
        }
        assert!(closest > 0.5, "{closest}");
    }

    fn specconv_testkit_free_rng(mut seed: u64) -> impl FnMut() -> f64 {
        move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    /// Pairs from Sharma, Wu and Dalal 2005, Table 1 (pairs 1, 7, 13, 17, 25, 34), with their
    /// published ΔE₀₀ to four decimals.
    #[test]
    fn ciede2000_matches_sharmas_test_data() {
        let pairs = [
            ([50.0, 2.6772, -79.7751], [50.0, 0.0, -82.7485], 2.0425),
            ([50.0, 0.0, 0.0], [50.0, -1.0, 2.0], 2.3669),
            ([50.0, 2.49, -0.001], [50.0, -2.49, 0.0011], 7.2195),
            ([50.0, 2.5, 0.0], [73.0, 25.0, -18.0], 27.1492),
            (
                [60.2574, -34.0099, 36.2677],
                [60.4626, -34.1751, 39.4387],
                1.2644,
            ),
            ([2.0776, 0.0795, -1.135], [0.9033, -0.0636, -0.5514], 0.9082),
        ];
        for (a, b, de) in pairs {
            let got = ciede2000(a, b);
            assert!((got - de).abs() < 5e-5, "{a:?} {b:?}: {got} vs {de}");
            assert!((ciede2000(b, a) - de).abs() < 5e-5);
        }
        assert_eq!(ciede2000([40.0, 10.0, -3.0], [40.0, 10.0, -3.0]), 0.0);
    }

    #[test]
    fn lab_of_white_and_black() {
        let w = [0.95, 1.0, 1.09];
        let lab = xyz_to_lab(w, w);
        assert!((lab[0] - 100.0).abs() < 1e-12 && lab[1].abs() < 1e-12 && lab[2].abs() < 1e-12);
        assert!(xyz_to_lab([0.0; 3], w)[0].abs() < 1e-12);
    }

    /// The Jacobian against central differences, on both segments of f and above white.
    #[test]
    fn lab_jacobian_matches_finite_differences() {
        let w = [0.95, 1.0, 1.09];
        for xyz in [
            [0.3, 0.2, 0.5],
            [1e-4, 2e-3, 5e-4],
            [-0.01, 0.4, 2.5],
            [40.0, 3.0, 0.2],
        ] {
            let (lab, j) = xyz_to_lab_jacobian(xyz, w);
            assert_eq!(lab, xyz_to_lab(xyz, w));
            for k in 0..3 {
                let h = 1e-6 * xyz[k].abs().max(1e-3);
                let (mut p, mut m) = (xyz, xyz);
                p[k] += h;
                m[k] -= h;
                let (lp, lm) = (xyz_to_lab(p, w), xyz_to_lab(m, w));
                for row in 0..3 {
                    let fd = (lp[row] - lm[row]) / (2.0 * h);
                    assert!(
                        (fd - j[row][k]).abs() <= 1e-5 * fd.abs().max(1.0),
                        "{xyz:?} {row} {k}"
                    );
                }
            }
        }
    }
}
