//! One cluster's PCA and its uplift matrices (Eq. 5–8), and its reconstruction error computed
//! from the scatter matrix alone, so that split search never revisits the spectra.

use crate::Colorimetry;
use nalgebra::{DMatrix, Matrix3, SymmetricEigen};

/// First-and-second-moment sums of a set of spectra: what PCA and the error need.
#[derive(Debug, Clone)]
pub struct Moments {
    pub count: usize,
    /// Σ s
    pub sum: Vec<f64>,
    /// Σ s·sᵀ, row-major n×n.
    pub outer: Vec<f64>,
}

impl Moments {
    pub fn zero(n: usize) -> Moments {
        Moments {
            count: 0,
            sum: vec![0.0; n],
            outer: vec![0.0; n * n],
        }
    }

    pub fn add(&mut self, s: &[f64]) {
        let n = self.sum.len();
        self.count += 1;
        for i in 0..n {
            self.sum[i] += s[i];
            let row = &mut self.outer[i * n..(i + 1) * n];
            for (o, sj) in row.iter_mut().zip(s) {
                *o += s[i] * sj;
            }
        }
    }

    /// `self − other`, for the far side of a split.
    pub fn minus(&self, other: &Moments) -> Moments {
        Moments {
            count: self.count - other.count,
            sum: self
                .sum
                .iter()
                .zip(&other.sum)
                .map(|(a, b)| a - b)
                .collect(),
            outer: self
                .outer
                .iter()
                .zip(&other.outer)
                .map(|(a, b)| a - b)
                .collect(),
        }
    }

    pub fn mean(&self) -> Vec<f64> {
        self.sum.iter().map(|s| s / self.count as f64).collect()
    }

    /// The scatter matrix Σ (s − μ)(s − μ)ᵀ = Σ s·sᵀ − N·μ·μᵀ.
    pub fn scatter(&self) -> Vec<f64> {
        let n = self.sum.len();
        let mu = self.mean();
        let mut c = self.outer.clone();
        for i in 0..n {
            for j in 0..n {
                c[i * n + j] -= self.count as f64 * mu[i] * mu[j];
            }
        }
        c
    }
}

/// The scatter matrix of a set of spectra computed around their mean (two passes, for accuracy).
pub fn centred_scatter(spectra: &[&[f64]]) -> (Vec<f64>, Vec<f64>) {
    let n = spectra[0].len();
    let mut mu = vec![0.0; n];
    for s in spectra {
        for (m, v) in mu.iter_mut().zip(*s) {
            *m += v;
        }
    }
    mu.iter_mut().for_each(|m| *m /= spectra.len() as f64);
    let mut c = vec![0.0; n * n];
    let mut d = vec![0.0; n];
    for s in spectra {
        for i in 0..n {
            d[i] = s[i] - mu[i];
        }
        for i in 0..n {
            for j in 0..n {
                c[i * n + j] += d[i] * d[j];
            }
        }
    }
    (mu, c)
}

/// A cluster's three principal components and what the uplift needs of them.
#[derive(Debug, Clone)]
pub struct Fit {
    /// b₁, b₂, b₃: unit eigenvectors of the scatter matrix, by decreasing eigenvalue.
    pub basis: [Vec<f64>; 3],
    /// M = A·[b₁ b₂ b₃] (Eq. 6), row-major.
    pub m: [[f64; 3]; 3],
    pub m_inv: [[f64; 3]; 3],
    /// σ_max(M) / σ_min(M).
    pub condition: f64,
    /// Σ ‖s − r‖² over the cluster's spectra (Eq. 13).
    pub error: f64,
}

/// Why a cluster cannot be fitted.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Unfit {
    /// M is singular or its condition number is above the bound.
    IllConditioned(f64),
}

/// PCA of a cluster from its scatter matrix `c` (n×n, row-major), with its error.
///
/// With r = B·M⁻¹·A·(s − μ) + μ, s − r = (I − B·M⁻¹·A)(s − μ) = P·(s − μ), so the summed error
/// is tr(P·C·Pᵀ). Since C·B = B·Λ and BᵀB = I this is tr(C) − 2·tr(Λ) + tr(M⁻¹·G·M⁻ᵀ) with
/// G = A·C·Aᵀ (3×3): a few 3×3 products once the eigenvectors are known.
pub fn fit(c: &[f64], a: &Colorimetry, max_condition: f64) -> Result<Fit, Unfit> {
    let n = a.bands();
    let (values, basis) = top_three(c, n);
    let m = std::array::from_fn(|i| std::array::from_fn(|j| dot(&a.weights[i], &basis[j])));
    let mm = Matrix3::from_fn(|i, j| m[i][j]);
    let sv = mm.singular_values();
    let (smax, smin) = (sv.max(), sv.min());
    let condition = if smin > 0.0 {
        smax / smin
    } else {
        f64::INFINITY
    };
    if !(condition <= max_condition) {
        return Err(Unfit::IllConditioned(condition));
    }
    let inv = mm.try_inverse().ok_or(Unfit::IllConditioned(condition))?;
    // G = A·C·Aᵀ
    let ac: [Vec<f64>; 3] = std::array::from_fn(|i| {
        (0..n)
            .map(|j| dot(&a.weights[i], &c[j * n..(j + 1) * n]))
            .collect()
    });
    let g = Matrix3::from_fn(|i, j| dot(&ac[i], &a.weights[j]));
    let trace_c: f64 = (0..n).map(|i| c[i * n + i]).sum();
    let error = trace_c - 2.0 * values.iter().sum::<f64>() + (inv * g * inv.transpose()).trace();
    Ok(Fit {
        basis,
        m,
        m_inv: std::array::from_fn(|i| std::array::from_fn(|j| inv[(i, j)])),
        condition,
        // Rounding can leave a perfectly fitted cluster a hair below zero.
        error: error.max(0.0),
    })
}

/// The three largest eigenpairs of a symmetric matrix, signs fixed so that each vector's
/// largest-magnitude component is positive (PCA leaves the sign free; a model must not).
fn top_three(c: &[f64], n: usize) -> ([f64; 3], [Vec<f64>; 3]) {
    let eig = SymmetricEigen::new(DMatrix::from_row_slice(n, n, c));
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&i, &j| {
        eig.eigenvalues[j]
            .total_cmp(&eig.eigenvalues[i])
            .then(i.cmp(&j))
    });
    let values = std::array::from_fn(|k| eig.eigenvalues[order[k]]);
    let vectors = std::array::from_fn(|k| {
        let mut v: Vec<f64> = eig.eigenvectors.column(order[k]).iter().copied().collect();
        let peak = v
            .iter()
            .copied()
            .fold(0.0f64, |p, x| if x.abs() > p.abs() { x } else { p });
        if peak < 0.0 {
            v.iter_mut().for_each(|x| *x = -*x);
        }
        v
    });
    (values, vectors)
}

pub(crate) fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Grid, Illuminant, Observer};

    fn colorimetry() -> Colorimetry {
        Colorimetry::new(Grid::PAPER, Observer::Cie1931, Illuminant::D65).unwrap()
    }

    /// Smooth pseudo-random spectra, reproducible without a random-number crate.
    fn spectra(count: usize, n: usize) -> Vec<Vec<f64>> {
        (0..count)
            .map(|k| {
                let (a, b, c) = (
                    (k as f64 * 0.37).sin(),
                    (k as f64 * 1.13).cos(),
                    (k as f64 * 0.71).sin(),
                );
                (0..n)
                    .map(|i| {
                        let t = i as f64 / n as f64;
                        0.5 + 0.2 * a * t
                            + 0.15 * b * (3.0 * t).sin()
                            + 0.1 * c * (7.0 * t).cos()
                            + 0.02 * (k as f64 * i as f64).sin()
                    })
                    .collect()
            })
            .collect()
    }

    #[test]
    fn error_from_scatter_equals_error_from_the_spectra() {
        let a = colorimetry();
        let data = spectra(50, a.bands());
        let refs: Vec<&[f64]> = data.iter().map(|s| s.as_slice()).collect();
        let (mu, c) = centred_scatter(&refs);
        let f = fit(&c, &a, 1e12).unwrap();
        let c_mu = a.xyz(&mu);
        let mut direct = 0.0;
        for s in &data {
            let cs = a.xyz(s);
            let d = [cs[0] - c_mu[0], cs[1] - c_mu[1], cs[2] - c_mu[2]];
            let w: Vec<f64> = (0..3).map(|i| dot(&f.m_inv[i], &d)).collect();
            for (i, si) in s.iter().enumerate() {
                let r = mu[i] + (0..3).map(|k| w[k] * f.basis[k][i]).sum::<f64>();
                direct += (si - r).powi(2);
            }
        }
        assert!(
            direct > 1e-3,
            "the test data must not be trivially reconstructible"
        );
        assert!(
            (f.error - direct).abs() < 1e-10 * direct,
            "{} vs {direct}",
            f.error
        );
    }

    #[test]
    fn moments_give_the_same_scatter_as_two_passes() {
        let data = spectra(30, 36);
        let refs: Vec<&[f64]> = data.iter().map(|s| s.as_slice()).collect();
        let (_, c2) = centred_scatter(&refs);
        let mut m = Moments::zero(36);
        data.iter().for_each(|s| m.add(s));
        let c1 = m.scatter();
        let worst = c1
            .iter()
            .zip(&c2)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(worst < 1e-12, "{worst}");
    }

    #[test]
    fn basis_is_orthonormal_with_fixed_signs() {
        let a = colorimetry();
        let data = spectra(40, a.bands());
        let refs: Vec<&[f64]> = data.iter().map(|s| s.as_slice()).collect();
        let f = fit(&centred_scatter(&refs).1, &a, 1e12).unwrap();
        for i in 0..3 {
            for j in 0..3 {
                let d = dot(&f.basis[i], &f.basis[j]);
                assert!((d - if i == j { 1.0 } else { 0.0 }).abs() < 1e-12);
            }
            let peak =
                f.basis[i]
                    .iter()
                    .copied()
                    .fold(0.0f64, |p, x| if x.abs() > p.abs() { x } else { p });
            assert!(peak > 0.0);
        }
    }

    #[test]
    fn an_ill_conditioned_cluster_is_refused() {
        let a = colorimetry();
        let data = spectra(40, a.bands());
        let refs: Vec<&[f64]> = data.iter().map(|s| s.as_slice()).collect();
        let c = centred_scatter(&refs).1;
        let cond = fit(&c, &a, 1e12).unwrap().condition;
        assert_eq!(
            fit(&c, &a, cond * 0.5).unwrap_err(),
            Unfit::IllConditioned(cond)
        );
    }
}
