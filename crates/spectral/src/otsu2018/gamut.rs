//! Where the colours of real materials are, for bounding what an uplift does to them: the
//! chromaticities of non-negative spectra (the convex hull of the bands' chromaticities: the
//! spectral locus closed by the purple line, for observers whose locus is convex), and per
//! chromaticity the brightest colour that a reflectance in [0, 1] can have (the boundary of
//! the object-colour solid, [`crate::bounded::Solid`]).

use super::tree::Axis;
use specconv_colour::solid::Solid;
use specconv_colour::Colorimetry;

/// The locus polygon and the solid's facets of one colorimetry.
#[derive(Debug, Clone)]
pub struct Gamut {
    /// The convex hull of the bands' chromaticities, counter-clockwise. The xy of Σ rᵢ·aᵢ
    /// with rᵢ ≥ 0 is a convex combination of the aᵢ's xy, so this is every real colour's
    /// (the Wyman 2013 fit's locus folds back at long wavelengths: not its own hull).
    locus: Vec<[f64; 2]>,
    /// Facet normals u of the solid with their support h(u).
    facets: Vec<([f64; 3], f64)>,
}

impl Gamut {
    /// The locus and the solid's facets of colorimetry `a`.
    pub fn new(a: &Colorimetry) -> Gamut {
        let solid = Solid::new(&a.weights);
        let cols = solid.columns();
        let points: Vec<[f64; 2]> = cols
            .iter()
            .filter_map(|&c| specconv_colour::colorimetry::xy(c))
            .collect();
        let locus = hull(points);
        // The solid is a zonotope: its facet normals are the cross products of two generators.
        let mut facets = Vec::new();
        for (i, p) in cols.iter().enumerate() {
            for q in &cols[i + 1..] {
                let u = [
                    p[1] * q[2] - p[2] * q[1],
                    p[2] * q[0] - p[0] * q[2],
                    p[0] * q[1] - p[1] * q[0],
                ];
                for u in [u, u.map(|v| -v)] {
                    facets.push((u, solid.support(u)));
                }
            }
        }
        Gamut { locus, facets }
    }

    /// The largest t with t·c in the solid: the least h(u) / u·c over the facets with u·c > 0
    /// (∞ when none faces c).
    pub fn reach(&self, c: [f64; 3]) -> f64 {
        self.facets
            .iter()
            .filter_map(|(u, h)| {
                let uc = u[0] * c[0] + u[1] * c[1] + u[2] * c[2];
                (uc > 0.0).then(|| h / uc)
            })
            .fold(f64::INFINITY, f64::min)
    }

    /// The chord [lo, hi] (in the other coordinate) of the line `axis` = `value` inside the
    /// locus polygon: the chromaticities of real colours on it.
    pub fn chord(&self, axis: Axis, value: f64) -> Option<[f64; 2]> {
        let (k, other) = if axis == Axis::X { (0, 1) } else { (1, 0) };
        let mut range: Option<[f64; 2]> = None;
        for (i, p) in self.locus.iter().enumerate() {
            let q = self.locus[(i + 1) % self.locus.len()];
            let (lo, hi) = (p[k].min(q[k]), p[k].max(q[k]));
            if value < lo || value > hi || p[k] == q[k] {
                continue;
            }
            let t = (value - p[k]) / (q[k] - p[k]);
            let u = p[other] + t * (q[other] - p[other]);
            range = Some(range.map_or([u, u], |r| [r[0].min(u), r[1].max(u)]));
        }
        range
    }
}

/// The convex hull of `p`, counter-clockwise (Andrew's monotone chain).
fn hull(mut p: Vec<[f64; 2]>) -> Vec<[f64; 2]> {
    p.sort_by(|a, b| a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1])));
    p.dedup();
    if p.len() < 3 {
        return p;
    }
    let cross = |o: [f64; 2], a: [f64; 2], b: [f64; 2]| {
        (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
    };
    let mut h: Vec<[f64; 2]> = Vec::with_capacity(2 * p.len());
    for pass in [&p[..], &p.iter().rev().copied().collect::<Vec<_>>()[..]] {
        let start = h.len();
        for &q in pass {
            while h.len() >= start + 2 && cross(h[h.len() - 2], h[h.len() - 1], q) <= 0.0 {
                h.pop();
            }
            h.push(q);
        }
        // The last point of each chain starts the other.
        h.pop();
    }
    h
}

/// XYZ of chromaticity `xy` at luminance Y = `luminance`.
pub fn xyz(xy: [f64; 2], luminance: f64) -> [f64; 3] {
    let [x, y] = xy;
    [x / y * luminance, luminance, (1.0 - x - y) / y * luminance]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn white_reaches_the_perfect_reflector_and_chords_lie_in_the_locus() {
        let a = crate::Model::builtin().colorimetry().unwrap();
        let g = Gamut::new(&a);
        // r = 1 is the brightest reflectance of the white's chromaticity: Y = 1.
        let white = a.white_xyz();
        assert!((g.reach(white) - 1.0).abs() < 1e-9, "{}", g.reach(white));
        // A saturated green reaches less far than grey of the same luminance.
        assert!(g.reach(xyz([0.25, 0.6], 1.0)) < 0.9);
        let [lo, hi] = g.chord(Axis::X, 0.3).unwrap();
        assert!(lo < 0.1 && hi > 0.6 && lo < hi, "{lo} {hi}");
        assert!(g.chord(Axis::Y, 0.95).is_none());
    }

    #[test]
    fn the_hull_drops_inner_points_and_folds() {
        let square = [
            [0.0, 0.0],
            [1.0, 0.0],
            [0.5, 0.5],
            [1.0, 1.0],
            [0.0, 1.0],
            [0.2, 0.1],
        ];
        let h = hull(square.to_vec());
        assert_eq!(h, vec![[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]);
        // A locus that folds back on itself (as Wyman 2013's does past 650 nm) spans its hull.
        let g = Gamut {
            locus: hull(vec![[0.1, 0.0], [0.0, 0.8], [0.7, 0.3], [0.4, 0.5]]),
            facets: Vec::new(),
        };
        let [lo, hi] = g.chord(Axis::Y, 0.25).unwrap();
        // Edges (0.1, 0)–(0, 0.8) and (0.1, 0)–(0.7, 0.3); (0.4, 0.5) is inside.
        assert!(
            (lo - 0.06875).abs() < 1e-12 && (hi - 0.6).abs() < 1e-12,
            "{lo} {hi}"
        );
    }
}
