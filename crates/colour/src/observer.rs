//! Standard observers (colour-matching functions) and illuminants.

use crate::error::Error;

use crate::{Grid, SpectralTable};
use serde::{Deserialize, Serialize};
use std::sync::OnceLock;

/// A standard observer: the colour-matching functions x̄, ȳ, z̄.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum Observer {
    /// CIE 1931 2°, tabulated at 1 nm (the default).
    #[serde(rename = "cie1931")]
    Cie1931,
    /// CIE 1964 10°, tabulated at 1 nm.
    #[serde(rename = "cie1964")]
    Cie1964,
    /// The multi-lobe analytic fit of CIE 1931 by Wyman, Sloan and Shirley 2013, used by the paper.
    #[serde(rename = "wyman2013")]
    Wyman2013,
}

impl Observer {
    /// Every observer, the default (CIE 1931) first.
    pub const ALL: [Observer; 3] = [Observer::Cie1931, Observer::Cie1964, Observer::Wyman2013];

    /// The name in options, messages and serialised settings (`cie1931`, `cie1964`, `wyman2013`,
    /// as serde writes it); `FromStr` reads it back, ignoring case.
    pub fn name(self) -> &'static str {
        match self {
            Observer::Cie1931 => "cie1931",
            Observer::Cie1964 => "cie1964",
            Observer::Wyman2013 => "wyman2013",
        }
    }

    /// x̄, ȳ, z̄ sampled on `grid`.
    pub fn cmfs(self, grid: &Grid) -> Result<[Vec<f64>; 3], Error> {
        let table = match self {
            Observer::Cie1931 => cie_table(
                &CIE1931,
                "cie1931_2deg_xyz_cmf_360-830_1nm.csv",
                include_str!("../data/cie1931_2deg_xyz_cmf_360-830_1nm.csv"),
            ),
            Observer::Cie1964 => cie_table(
                &CIE1964,
                "cie1964_10deg_xyz_cmf_360-830_1nm.csv",
                include_str!("../data/cie1964_10deg_xyz_cmf_360-830_1nm.csv"),
            ),
            Observer::Wyman2013 => {
                let w = grid.wavelengths();
                return Ok([
                    w.iter().map(|&l| wyman2013(l)[0]).collect(),
                    w.iter().map(|&l| wyman2013(l)[1]).collect(),
                    w.iter().map(|&l| wyman2013(l)[2]).collect(),
                ]);
            }
        };
        let what = format!("the {} observer", self.name());
        let col = |k: usize| grid.resample(&what, &table.wavelengths, &table.columns[k]);
        Ok([col(0)?, col(1)?, col(2)?])
    }
}

impl std::fmt::Display for Observer {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for Observer {
    type Err = Error;
    fn from_str(s: &str) -> Result<Observer, Error> {
        Observer::ALL
            .into_iter()
            .find(|o| o.name().eq_ignore_ascii_case(s))
            .ok_or_else(|| {
                Error::Unknown(format!(
                    "observer '{s}': choose one of cie1931, cie1964, wyman2013"
                ))
            })
    }
}

/// Wyman, Sloan and Shirley 2013, "Simple Analytic Approximations to the CIE XYZ Color Matching
/// Functions", JCGT 2(2), Eq. 2 (the multi-lobe fit): sums of piecewise Gaussians whose width
/// differs left and right of the peak. Coefficients as published there.
pub fn wyman2013(lambda: f64) -> [f64; 3] {
    let g = |mu: f64, s1: f64, s2: f64| {
        let t = (lambda - mu) / if lambda < mu { s1 } else { s2 };
        (-0.5 * t * t).exp()
    };
    [
        1.056 * g(599.8, 37.9, 31.0) + 0.362 * g(442.0, 16.0, 26.7) - 0.065 * g(501.1, 20.4, 26.2),
        0.821 * g(568.8, 46.9, 40.5) + 0.286 * g(530.9, 16.3, 31.1),
        1.217 * g(437.0, 11.8, 36.0) + 0.681 * g(459.0, 26.0, 13.8),
    ]
}

/// A light source's relative spectral power distribution.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(into = "String", try_from = "String")]
pub enum Illuminant {
    /// Equal energy: with it, XYZ is the paper's plain Σ r·x̄ up to a constant factor.
    E,
    /// CIE standard illuminant D65 (average daylight, about 6504 K), tabulated 300–780 nm at 5 nm.
    D65,
    /// CIE illuminant D50 (daylight, about 5003 K), tabulated 300–780 nm at 5 nm.
    D50,
    /// CIE standard illuminant A (incandescent tungsten, 2856 K), tabulated 300–780 nm at 5 nm.
    A,
    /// CIE fluorescent illuminant F2 (cool white), tabulated 380–780 nm at 5 nm; `FL2` or `F2`.
    FL2,
    /// CIE fluorescent illuminant F11 (narrow-band, three phosphors), tabulated 380–780 nm at 5 nm;
    /// `FL11` or `F11`.
    FL11,
    /// Planck's law at a temperature in kelvin.
    Blackbody(f64),
}

static CIE1931: OnceLock<SpectralTable> = OnceLock::new();
static CIE1964: OnceLock<SpectralTable> = OnceLock::new();
static D65: OnceLock<SpectralTable> = OnceLock::new();
static D50: OnceLock<SpectralTable> = OnceLock::new();
static ILL_A: OnceLock<SpectralTable> = OnceLock::new();
static FL2: OnceLock<SpectralTable> = OnceLock::new();
static FL11: OnceLock<SpectralTable> = OnceLock::new();

fn cie_table(
    cell: &'static OnceLock<SpectralTable>,
    name: &str,
    text: &str,
) -> &'static SpectralTable {
    // The tables are part of the binary and tested: a parse failure is a build defect.
    cell.get_or_init(|| SpectralTable::parse(name, text).expect("embedded CIE table parses"))
}

impl Illuminant {
    /// Relative power sampled on `grid`. Blackbodies are normalised to 1 at 560 nm.
    pub fn spd(&self, grid: &Grid) -> Result<Vec<f64>, Error> {
        let Some(table) = self.table() else {
            if let Illuminant::Blackbody(t) = self {
                let at = |l: f64| planck(l, *t);
                let norm = at(560.0);
                return Ok(grid.wavelengths().iter().map(|&l| at(l) / norm).collect());
            }
            return Ok(vec![1.0; grid.len()]);
        };
        grid.resample(
            &format!("illuminant {self}"),
            &table.wavelengths,
            &table.columns[0],
        )
    }

    /// The wavelengths (nm) a tabulated illuminant covers; `None` for E and blackbodies.
    pub fn range(&self) -> Option<(f64, f64)> {
        let t = self.table()?;
        Some((*t.wavelengths.first()?, *t.wavelengths.last()?))
    }

    fn table(&self) -> Option<&'static SpectralTable> {
        Some(match self {
            Illuminant::E | Illuminant::Blackbody(_) => return None,
            Illuminant::D65 => cie_table(
                &D65,
                "cie_illuminant_d65_300-780_5nm.csv",
                include_str!("../data/cie_illuminant_d65_300-780_5nm.csv"),
            ),
            Illuminant::D50 => cie_table(
                &D50,
                "cie_illuminant_d50_300-780_5nm.csv",
                include_str!("../data/cie_illuminant_d50_300-780_5nm.csv"),
            ),
            Illuminant::A => cie_table(
                &ILL_A,
                "cie_illuminant_a_300-780_5nm.csv",
                include_str!("../data/cie_illuminant_a_300-780_5nm.csv"),
            ),
            Illuminant::FL2 => cie_table(
                &FL2,
                "cie_illuminant_f2_380-780_5nm.csv",
                include_str!("../data/cie_illuminant_f2_380-780_5nm.csv"),
            ),
            Illuminant::FL11 => cie_table(
                &FL11,
                "cie_illuminant_f11_380-780_5nm.csv",
                include_str!("../data/cie_illuminant_f11_380-780_5nm.csv"),
            ),
        })
    }
}

/// Planck's law, spectral radiant exitance up to a constant, with the CIE's second radiation
/// constant c2 = 1.4388e-2 m·K (CIE 15:2018).
fn planck(lambda_nm: f64, kelvin: f64) -> f64 {
    const C2: f64 = 1.4388e-2;
    let l = lambda_nm * 1e-9;
    1.0 / (l.powi(5) * ((C2 / (l * kelvin)).exp_m1()))
}

impl std::fmt::Display for Illuminant {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Illuminant::E => f.write_str("E"),
            Illuminant::D65 => f.write_str("D65"),
            Illuminant::D50 => f.write_str("D50"),
            Illuminant::A => f.write_str("A"),
            Illuminant::FL2 => f.write_str("FL2"),
            Illuminant::FL11 => f.write_str("FL11"),
            Illuminant::Blackbody(t) => write!(f, "blackbody:{t}"),
        }
    }
}

impl std::str::FromStr for Illuminant {
    type Err = Error;
    fn from_str(s: &str) -> Result<Illuminant, Error> {
        let lower = s.trim().to_ascii_lowercase();
        if let Some(t) = lower.strip_prefix("blackbody:") {
            let t = t.trim_end_matches('k');
            return match t.parse::<f64>() {
                Ok(k) if k.is_finite() && (100.0..=1e6).contains(&k) => Ok(Illuminant::Blackbody(k)),
                _ => Err(Error::Unknown(format!(
                    "illuminant '{s}': a blackbody needs a temperature between 100 and 1000000 kelvin, e.g. blackbody:5500"
                ))),
            };
        }
        Ok(match lower.as_str() {
            "e" => Illuminant::E,
            "d65" => Illuminant::D65,
            "d50" => Illuminant::D50,
            "a" => Illuminant::A,
            "fl2" | "f2" => Illuminant::FL2,
            "fl11" | "f11" => Illuminant::FL11,
            _ => {
                return Err(Error::Unknown(format!(
                    "illuminant '{s}': choose one of D65, E, A, D50, FL2, FL11, blackbody:KELVIN"
                )))
            }
        })
    }
}

impl From<Illuminant> for String {
    fn from(i: Illuminant) -> String {
        i.to_string()
    }
}

impl TryFrom<String> for Illuminant {
    type Error = Error;
    fn try_from(s: String) -> Result<Illuminant, Error> {
        s.parse()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tabulated_observers_sample_the_cie_tables() {
        let g = Grid::new(555.0, 560.0, 5.0).unwrap();
        let [x, y, z] = Observer::Cie1931.cmfs(&g).unwrap();
        // CIE 1931 at 555 nm: x̄ = 0.5121, ȳ = 1.0, z̄ = 0.00575 (CIE 018:2019 table).
        assert!(
            (x[0] - 0.5121).abs() < 1e-3
                && (y[0] - 1.0).abs() < 1e-3
                && (z[0] - 0.00575).abs() < 1e-4
        );
        let [_, y10, _] = Observer::Cie1964.cmfs(&g).unwrap();
        assert!(y10[0] > 0.9 && y10[0] < 1.0);
    }

    #[test]
    fn wyman_fit_is_close_to_the_cie_1931_table() {
        let g = Grid::new(380.0, 730.0, 1.0).unwrap();
        let table = Observer::Cie1931.cmfs(&g).unwrap();
        let fit = Observer::Wyman2013.cmfs(&g).unwrap();
        for k in 0..3 {
            let worst = table[k]
                .iter()
                .zip(&fit[k])
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            // The fit's published error is a few percent of the peak (1.78 for z̄).
            assert!(worst < 0.06, "cmf {k}: worst difference {worst}");
        }
    }

    #[test]
    fn illuminants_parse_print_and_sample() {
        for name in ["E", "D65", "D50", "A", "FL2", "FL11", "blackbody:5500"] {
            let ill: Illuminant = name.parse().unwrap();
            assert_eq!(ill.to_string(), name);
            let spd = ill.spd(&Grid::PAPER).unwrap();
            assert_eq!(spd.len(), 36);
            assert!(spd.iter().all(|v| v.is_finite() && *v > 0.0), "{name}");
        }
        // D65 at 560 nm is 100.0 by definition of its normalisation.
        let d65 = Illuminant::D65
            .spd(&Grid::new(560.0, 560.0, 1.0).unwrap())
            .unwrap();
        assert!((d65[0] - 100.0).abs() < 1e-9);
        assert!("blackbody:-3".parse::<Illuminant>().is_err());
        assert!("D75"
            .parse::<Illuminant>()
            .unwrap_err()
            .to_string()
            .contains("choose one of"));
        assert!(Illuminant::D65.spd(&"380:800:10".parse().unwrap()).is_err());
    }

    #[test]
    fn blackbody_peaks_where_wien_says() {
        // Wien's displacement law: λmax = 2.897771955e-3 m·K / T.
        let g = Grid::new(300.0, 1000.0, 0.5).unwrap();
        let spd = Illuminant::Blackbody(5000.0).spd(&g).unwrap();
        let peak = g.wavelength(
            (0..g.len())
                .max_by(|&a, &b| spd[a].total_cmp(&spd[b]))
                .unwrap(),
        );
        assert!((peak - 579.55).abs() < 1.0, "{peak}");
    }
}
