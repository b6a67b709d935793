//! The one 3×3 module: the small matrices of colour (RGB ↔ XYZ, Jacobians of CIELAB and of the
//! Jakob 2019 fit, the Newton steps on the object-colour solid's dual) as row-major
//! `[[f64; 3]; 3]`. Larger linear algebra (PCA, the resampling's Gram matrix, the Bradford
//! adaptation of RGB spaces) uses nalgebra.

/// A row-major 3×3 matrix.
pub type Mat3 = [[f64; 3]; 3];

/// a·b.
#[inline]
pub fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// a × b.
#[inline]
pub fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// m·v.
#[inline]
pub fn mul_vec(m: &Mat3, v: [f64; 3]) -> [f64; 3] {
    m.map(|row| row[0] * v[0] + row[1] * v[1] + row[2] * v[2])
}

/// The inverse by cofactors. A singular matrix gives infinities or NaN, not a panic: callers
/// that can meet one check the result (or use [`solve`]).
pub fn inverse(m: &Mat3) -> Mat3 {
    let c = |r: usize, k: usize| {
        let (r1, r2) = ((r + 1) % 3, (r + 2) % 3);
        let (k1, k2) = ((k + 1) % 3, (k + 2) % 3);
        m[r1][k1] * m[r2][k2] - m[r1][k2] * m[r2][k1]
    };
    let det = m[0][0] * c(0, 0) + m[0][1] * c(0, 1) + m[0][2] * c(0, 2);
    // Transposed cofactors over the determinant.
    [0, 1, 2].map(|r| [0, 1, 2].map(|k| c(k, r) / det))
}

/// The determinant, expanded along the first row.
pub fn det(m: &Mat3) -> f64 {
    m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
        - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
        + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
}

/// x with j·x = b by Cramer's rule; `None` when j is singular or the result is not finite.
pub fn solve(j: &Mat3, b: [f64; 3]) -> Option<[f64; 3]> {
    let d = det(j);
    if !(d.abs() > 0.0 && d.is_finite()) {
        return None;
    }
    let x = [0, 1, 2].map(|k| {
        let mut m = *j;
        (0..3).for_each(|row| m[row][k] = b[row]);
        det(&m) / d
    });
    x.iter().all(|v| v.is_finite()).then_some(x)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn inverse_and_solve_agree_with_the_identity() {
        let m = [[2.0, 1.0, 0.5], [0.3, 3.0, 0.2], [0.1, 0.4, 1.5]];
        let inv = inverse(&m);
        for (r, column) in [0, 1, 2]
            .map(|c| m.map(|row| row[c]))
            .into_iter()
            .enumerate()
        {
            let row = mul_vec(&inv, column);
            for (k, v) in row.iter().enumerate() {
                let want = if k == r { 1.0 } else { 0.0 };
                assert!((v - want).abs() < 1e-14, "{inv:?}");
            }
        }
        let b = [1.0, -2.0, 0.5];
        let x = solve(&m, b).unwrap();
        let back = mul_vec(&m, x);
        assert!((0..3).all(|k| (back[k] - b[k]).abs() < 1e-14));
        assert_eq!(
            solve(&[[1.0, 2.0, 3.0], [2.0, 4.0, 6.0], [0.0, 0.0, 1.0]], b),
            None
        );
        assert_eq!(dot([1.0, 2.0, 3.0], [4.0, 5.0, 6.0]), 32.0);
    }
}
