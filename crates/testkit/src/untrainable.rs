//! Training sets that cannot make a model, each with the words its error must contain; shared
//! by the library's tests and those of `specconv train`. Synthetic, so nothing is copied from
//! the measured sets.

use specconv_colour::{Colorimetry, Grid};

/// A smooth spectrum in [0.1, 0.95], different for each `k`: a quadratic Bernstein curve with
/// pseudo-random weights and a small ripple, so that a set of them varies in many directions.
pub fn smooth(k: usize, n: usize) -> Vec<f64> {
    let w = [0.618, 0.414, 0.732].map(|g| (k as f64 * g + 0.1).fract());
    (0..n)
        .map(|i| {
            let t = i as f64 / (n - 1) as f64;
            let bern = w[0] * (1.0 - t).powi(2) + w[1] * 2.0 * t * (1.0 - t) + w[2] * t * t;
            0.1 + 0.8 * bern + 0.05 * (1.0 + (0.7 * (k * i) as f64).sin())
        })
        .collect()
}

/// `v` minus its least-squares part in the span of A's rows: a spectrum the observer cannot
/// see at all (XYZ = 0), a metameric black.
pub fn metameric_black(a: &Colorimetry, v: &[f64]) -> Vec<f64> {
    let w = &a.weights;
    // Normal equations (A·Aᵀ)·coef = A·v, by Cramer's rule.
    let g: [[f64; 3]; 3] = std::array::from_fn(|i| std::array::from_fn(|j| dot(&w[i], &w[j])));
    let av: [f64; 3] = std::array::from_fn(|i| dot(&w[i], v));
    let det = |m: [[f64; 3]; 3]| {
        m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
            - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
    };
    let coef: [f64; 3] = std::array::from_fn(|c| {
        let mut m = g;
        (0..3).for_each(|r| m[r][c] = av[r]);
        det(m) / det(g)
    });
    (0..v.len())
        .map(|b| v[b] - (0..3).map(|i| coef[i] * w[i][b]).sum::<f64>())
        .collect()
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

pub struct Case {
    pub name: &'static str,
    pub spectra: Vec<Vec<f64>>,
    /// Words the error must contain.
    pub error: &'static str,
}

/// Every kind of untrainable set, 30 spectra each unless too few is the point.
pub fn cases(a: &Colorimetry) -> Vec<Case> {
    let n = a.bands();
    let s = |k| smooth(k, n);
    let scaled = |v: &[f64], f: f64| v.iter().map(|x| x * f).collect::<Vec<f64>>();
    let mix = |parts: &[(f64, &[f64])]| {
        (0..n)
            .map(|b| parts.iter().map(|(w, v)| w * v[b]).sum())
            .collect::<Vec<f64>>()
    };
    let base = s(3);
    // Variation along two visible directions and a metameric black, the black the largest:
    // three real components, but M = A·B has rank 2.
    let (v1, v2) = (s(5), s(8));
    let black = metameric_black(a, &s(11));
    let metamers = (0..30)
        .map(|k| {
            let t = k as f64;
            let (c1, c2, c3) = (
                0.1 * (1.3 * t).sin(),
                0.1 * (2.9 * t).cos(),
                (0.7 * t).sin(),
            );
            mix(&[(0.6, &base), (c1, &v1), (c2, &v2), (c3, &black)])
        })
        .collect();
    let mut with_black: Vec<Vec<f64>> = (0..30).map(s).collect();
    with_black[7] = vec![0.0; n];
    vec![
        Case {
            name: "one spectrum",
            spectra: vec![base.clone()],
            error: "only 1 spectrum: three principal components need at least 4 spectra",
        },
        Case {
            name: "three spectra",
            spectra: (0..3).map(s).collect(),
            error: "only 3 spectra: three principal components need at least 4 spectra",
        },
        Case {
            name: "identical",
            spectra: vec![base.clone(); 30],
            error: "all 30 spectra are identical spectra",
        },
        Case {
            name: "identical up to rounding",
            spectra: (0..30)
                .map(|k| scaled(&base, 1.0 + 1e-15 * k as f64))
                .collect(),
            error: "all 30 spectra are identical spectra",
        },
        Case {
            name: "one spectrum scaled",
            spectra: (0..30)
                .map(|k| scaled(&base, 0.2 + 0.02 * k as f64))
                .collect(),
            error: "vary in only 1 independent direction (as copies or mixtures of 2 spectra",
        },
        Case {
            name: "mixtures of three",
            spectra: (0..30)
                .map(|k| {
                    let (u, v) = mixture_weights(k);
                    mix(&[(u, &s(0)), (v, &s(1)), (1.0 - u - v, &s(2))])
                })
                .collect(),
            error: "vary in only 2 independent directions (as copies or mixtures of 3 spectra",
        },
        Case {
            name: "metamers: singular M",
            spectra: metamers,
            error: "look almost alike to the observer",
        },
        Case {
            name: "a black spectrum",
            spectra: with_black,
            error: "reflects no light",
        },
    ]
}

/// The spectra as a CSV table on `grid`, samples named s0, s1, …
pub fn csv(grid: &Grid, spectra: &[Vec<f64>]) -> String {
    let mut out = String::from("wavelength_nm");
    (0..spectra.len()).for_each(|k| out.push_str(&format!(",s{k}")));
    out.push('\n');
    for b in 0..grid.len() {
        out.push_str(&grid.wavelength(b).to_string());
        spectra
            .iter()
            .for_each(|s| out.push_str(&format!(",{}", s[b])));
        out.push('\n');
    }
    out
}

/// The `k`th pair of weights (u, v) of a mixture of three, u, v and 1 − u − v all in [0, 1]:
/// spread over the triangle without a random generator.
pub fn mixture_weights(k: usize) -> (f64, f64) {
    let (u, v) = ((k as f64 * 0.37).fract(), (k as f64 * 0.61).fract());
    if u + v > 1.0 {
        (1.0 - u, 1.0 - v)
    } else {
        (u, v)
    }
}
