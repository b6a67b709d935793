//! Where the colours of real materials are, for bounding what an uplift does to them: the
//! spectral locus in xy, and per chromaticity the brightest colour that a reflectance in
//! [0, 1] can have (the boundary of the object-colour solid, [`crate::bounded::Solid`]).

use crate::bounded::Solid;
use crate::model::Axis;
use crate::Colorimetry;

/// The locus polygon and the solid's facets of one colorimetry.
#[derive(Debug, Clone)]
pub struct Gamut {
    /// Chromaticities of the bands' columns, in wavelength order; closed by the purple line.
    locus: Vec<[f64; 2]>,
    /// Facet normals u of the solid with their support h(u).
    facets: Vec<([f64; 3], f64)>,
}

impl Gamut {
    pub fn new(a: &Colorimetry) -> Gamut {
        let solid = Solid::new(&a.weights);
        let cols = solid.columns();
        let locus = cols
            .iter()
            .filter_map(|&c| crate::colorimetry::xy(c))
            .collect();
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
}
