//! The one way to build the method a command uplifts with: a [`StackSpec`] (what the
//! options select) becomes a [`Stack`],
//!
//!   clustered or baseline → resampled onto the output grid → bounded (counted) → emissive
//!
//! (On the model's own grid the clustered methods fold the resampling's colour correction into
//! their affine maps instead: the same spectra, without a pass over them.)
//!
//! with the counters of its adapters. `convert`, `eval`, `report` and `simulate` all build
//! here, so the same options give the same spectra in every command.

use crate::baselines::jakob_cache::TableCache;
use crate::baselines::{Jakob2019, Meng2015, Smits1999};
use crate::bounded::Bounded;
use crate::emission::{EmissionSetting, Emissive};
use crate::error::Error;
use crate::method::MethodName;
use crate::resample::Resampled;
use crate::{Method, Model, Uplifter};
use specconv_colour::{Colorimetry, EmissionUnits, Grid, Illuminant, Integration, Observer};

/// What to uplift with: everything a command's options select about the method.
#[derive(Debug, Clone, PartialEq)]
pub struct StackSpec {
    /// The method to build (`pca` needs a model of one cluster).
    pub method: MethodName,
    /// Blend width of the clustered methods in xy ([`crate::otsu2018::blend`]); 0 is the
    /// paper's hard switch. The baselines have no clusters and ignore it.
    pub blend: f64,
    /// The setting the baselines are built in, each part the model's when `None`. The clustered
    /// methods always take their model's.
    pub baseline: Setting,
    /// Cells per axis of the Jakob 2019 table.
    pub jakob_resolution: usize,
    /// The output grid; `None`: the method's own.
    pub grid: Option<Grid>,
    /// The integration under which the output has the input's colour exactly.
    pub exact_under: ExactUnder,
    /// Spectra kept in [0, 1] with their XYZ ([`crate::bounded`]).
    pub bounded: bool,
    /// Emission spectra of any brightness instead of reflectances ([`crate::emission`]), in
    /// these units (used with [`ExactUnder::Readers`]; the band sums have their own).
    pub emissive: Option<EmissionUnits>,
}

/// Grid, observer and illuminant, each `None` for the model's.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Setting {
    /// The baselines' grid; the model's when `None`.
    pub grid: Option<Grid>,
    /// The baselines' observer; the model's when `None`.
    pub observer: Option<Observer>,
    /// The baselines' illuminant (its white has Y = 1); the model's when `None`.
    pub illuminant: Option<Illuminant>,
}

/// Whose integration the spectra's colour is exact under.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ExactUnder {
    /// The method's own band sums (the paper's Σ r·I·x̄ / Σ I·ȳ on its grid): evaluations and
    /// reports, which compare against the paper.
    BandSums,
    /// Every reader's integration of a spectral EXR (the layout's reference, on the output
    /// grid): what `convert` writes. The method's spectra are always resampled onto it.
    Readers,
}

impl StackSpec {
    /// `method` as `eval`, `report` and the study measure it, as the paper does: exact under
    /// its own band sums (the round trip of Eq. 9), on its own grid, not emissive.
    pub fn measured(
        method: MethodName,
        blend: f64,
        baseline: Setting,
        jakob_resolution: usize,
        bounded: bool,
    ) -> StackSpec {
        StackSpec {
            method,
            blend,
            baseline,
            jakob_resolution,
            grid: None,
            exact_under: ExactUnder::BandSums,
            bounded,
            emissive: None,
        }
    }

    /// The method with every option at `convert`'s default: the built-in model, blended at
    /// [`crate::otsu2018::blend::DEFAULT_WIDTH`], bounded, reflectance as readers see it.
    pub fn convert_default(method: MethodName) -> StackSpec {
        StackSpec {
            method,
            blend: crate::otsu2018::blend::DEFAULT_WIDTH,
            baseline: Setting::default(),
            jakob_resolution: crate::baselines::jakob::DEFAULT_RESOLUTION,
            grid: None,
            exact_under: ExactUnder::Readers,
            bounded: true,
            emissive: None,
        }
    }

    /// The setting the method is built in: its model's for the clustered methods, else
    /// [`StackSpec::baseline`] completed by the model's.
    fn setting(&self, model: &Model) -> Result<Colorimetry, Error> {
        if self.method.is_clustered() {
            return model.colorimetry();
        }
        let s = &self.baseline;
        Ok(Colorimetry::new(
            s.grid.unwrap_or(model.grid),
            s.observer.unwrap_or(model.observer),
            s.illuminant.unwrap_or(model.illuminant),
        )?)
    }

    /// The reflectance colorimetry of the output (and the emission setting of an emissive one
    /// exact under the readers' integration), known before the method is built: its grid, and
    /// the observer and illuminant of the method's setting.
    pub fn output(&self, model: &Model) -> Result<(Colorimetry, Option<EmissionSetting>), Error> {
        let base = self.setting(model)?;
        let grid = self.grid.unwrap_or(base.grid);
        let (observer, illuminant) = (base.observer, base.illuminant);
        if self.exact_under == ExactUnder::BandSums {
            return Ok((Colorimetry::new(grid, observer, illuminant)?, None));
        }
        // Every band of an output needs the observer and the illuminant (the readers'
        // integration alone would leave bands outside them without colour).
        Colorimetry::new(grid, observer, illuminant)?;
        Ok(match self.emissive {
            Some(units) => {
                let e = EmissionSetting::new(grid, observer, illuminant, units)?;
                (e.reflectance.clone(), Some(e))
            }
            None => {
                let i = Integration::reflectance(&grid.wavelengths(), observer, illuminant)?;
                (i.colorimetry(grid, observer, illuminant), None)
            }
        })
    }

    /// The blend width that applies: 0 for the baselines, which have no clusters.
    pub fn blend_width(&self) -> f64 {
        if self.method.is_clustered() {
            self.blend
        } else {
            0.0
        }
    }
}

/// The top of the stack: reflectances, or emission kept by type for its count of colours no
/// spectrum matched.
enum Top {
    Reflective(Box<dyn Method>),
    Emissive(Emissive<Box<dyn Method>>),
}

/// A built method and what its adapters are. It holds no counter: what a call's adapters count
/// goes into the caller's [`crate::method::Tally`] ([`Method::uplift_f32_tallied`]).
pub struct Stack {
    top: Top,
    colorimetry: Colorimetry,
    emission: Option<EmissionSetting>,
    bounded: bool,
    blend: f64,
}

impl Stack {
    /// Builds `d`; `model` is the clustered methods' model (and the baselines' setting where
    /// `d.baseline` leaves it open), `tables` gives the Jakob 2019 table.
    pub fn build(d: &StackSpec, model: &Model, tables: &TableCache) -> Result<Stack, Error> {
        let (colorimetry, emission) = d.output(model)?;
        let (mut m, corrected) = method(d, model, tables, &colorimetry)?;
        // The readers' integration differs from the method's band sums by ≈0.1 %, which
        // Resampled corrects even on the method's own grid (unless the method did).
        if (d.exact_under == ExactUnder::Readers && !corrected) || colorimetry.grid != m.grid() {
            m = Box::new(Resampled::new(m, colorimetry.clone())?);
        }
        if d.bounded {
            m = Box::new(Bounded::new(m, colorimetry.clone())?);
        }
        let top = match (d.emissive, &emission) {
            (None, _) => Top::Reflective(m),
            (Some(_), Some(e)) => Top::Emissive(Emissive::in_setting(m, e)?),
            (Some(_), None) => Top::Emissive(Emissive::new(m, colorimetry.clone())?),
        };
        Ok(Stack {
            top,
            colorimetry,
            emission,
            bounded: d.bounded,
            blend: d.blend_width(),
        })
    }

    /// The method to uplift with.
    pub fn method(&self) -> &dyn Method {
        match &self.top {
            Top::Reflective(m) => m,
            Top::Emissive(e) => e,
        }
    }

    /// The reflectance colorimetry of the output: its grid, observer, illuminant and the
    /// weights its spectra are exact under (in emission: of the reflectances lit by the light).
    pub fn colorimetry(&self) -> &Colorimetry {
        &self.colorimetry
    }

    /// The emission setting of an emissive stack exact under the readers' integration.
    pub fn emission(&self) -> Option<&EmissionSetting> {
        self.emission.as_ref()
    }

    /// The emission adapter, when the stack is emissive.
    pub fn emissive(&self) -> Option<&Emissive<Box<dyn Method>>> {
        match &self.top {
            Top::Emissive(e) => Some(e),
            Top::Reflective(_) => None,
        }
    }

    /// The blend width in use (0 for the baselines).
    pub fn blend(&self) -> f64 {
        self.blend
    }

    /// Whether the bounded outcomes of a [`crate::method::Tally`] mean something: the stack is
    /// bounded and reflective (in emission the bounded method sees scaled trial colours).
    pub fn counts_bounded(&self) -> bool {
        self.bounded && self.emissive().is_none()
    }

    /// Whether every spectrum stays in [0, 1]: bounded, or a method bounded by its own design
    /// (meng2015-bounded).
    pub fn keeps_range(&self, method: MethodName) -> bool {
        self.bounded || method == MethodName::Meng2015Bounded
    }
}

/// The clustered method of `d` for an output of `colorimetry`: the model's maps, blended, and
/// (exact under the readers' integration, or on another grid) moved onto the output's grid and
/// corrected there ([`Uplifter::onto`]): the spectra [`Resampled`] would make, with the
/// correction folded into the maps. The stack and the compact texel
/// ([`crate::compact`]) both take it from here, so they decode to the same spectra.
pub fn clustered(
    d: &StackSpec,
    model: &Model,
    colorimetry: &Colorimetry,
) -> Result<Uplifter, Error> {
    let up = Uplifter::new(model)?.with_blend(d.blend)?;
    if d.exact_under == ExactUnder::Readers || colorimetry.grid != model.grid {
        return up.onto(colorimetry);
    }
    Ok(up)
}

/// The method of `d` in its setting, and whether it is already exact under the output's
/// `colorimetry`: the clustered methods fold the readers' correction into their maps when the
/// output is on the model's grid (the same spectra as [`Resampled`], whose per-pixel
/// correction was a quarter of an unbounded uplift's time in issue 22's profile).
fn method(
    d: &StackSpec,
    model: &Model,
    tables: &TableCache,
    colorimetry: &Colorimetry,
) -> Result<(Box<dyn Method>, bool), Error> {
    if d.method == MethodName::Pca && model.leaves.len() != 1 {
        return Err(Error::NeedsOneCluster {
            clusters: model.leaves.len(),
        });
    }
    let a = d.setting(model)?;
    let m: Box<dyn Method> = match d.method {
        MethodName::Pca | MethodName::Otsu2018 => {
            let up = clustered(d, model, colorimetry)?;
            let corrected = up.grid() == colorimetry.grid;
            return Ok((Box::new(up), corrected));
        }
        MethodName::Smits1999 => Box::new(Smits1999::new(&a)?),
        MethodName::Meng2015 => Box::new(Meng2015::new(&a, false)?),
        MethodName::Meng2015Bounded => Box::new(Meng2015::new(&a, true)?),
        MethodName::Jakob2019 => {
            Box::new(Jakob2019::new(&a, tables.table(&a, d.jakob_resolution)?)?)
        }
    };
    Ok((m, false))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn xyz_of(a: &Colorimetry, r: &[f64]) -> [f64; 3] {
        a.xyz(r)
    }

    #[test]
    fn the_stack_is_the_method_its_adapters_and_their_names() {
        let model = Model::builtin();
        let tables = TableCache::none();
        let s = Stack::build(
            &StackSpec::convert_default(MethodName::Otsu2018),
            model,
            &tables,
        )
        .unwrap();
        assert_eq!(s.method().name(), "otsu2018+bounded");
        assert_eq!(s.blend(), crate::otsu2018::blend::DEFAULT_WIDTH);
        let mut d = StackSpec::convert_default(MethodName::Smits1999);
        d.grid = Some(Grid::new(400.0, 700.0, 5.0).unwrap());
        d.emissive = Some(EmissionUnits::Reference);
        let s = Stack::build(&d, model, &tables).unwrap();
        assert_eq!(
            s.method().name(),
            "smits1999 on 400:700:5 nm+bounded+emissive"
        );
        assert_eq!(s.colorimetry().grid, d.grid.unwrap());
        assert_eq!(s.blend(), 0.0);
        assert!(s.emissive().is_some() && s.emission().is_some() && !s.counts_bounded());
        let mut d = StackSpec::convert_default(MethodName::Meng2015);
        d.baseline.observer = Some(Observer::Cie1964);
        d.baseline.illuminant = Some(Illuminant::A);
        d.exact_under = ExactUnder::BandSums;
        d.bounded = false;
        let s = Stack::build(&d, model, &tables).unwrap();
        assert_eq!(s.method().name(), "meng2015");
        assert_eq!(s.colorimetry().illuminant, Illuminant::A);
        assert!(!s.counts_bounded());
    }

    #[test]
    fn each_stack_reproduces_its_colours_under_its_integration() {
        let model = Model::builtin();
        let tables = TableCache::none();
        let colours = [[0.2, 0.18, 0.1], [0.5, 0.5, 0.55], [0.05, 0.1, 0.3]];
        for exact_under in [ExactUnder::BandSums, ExactUnder::Readers] {
            let mut d = StackSpec::convert_default(MethodName::Otsu2018);
            d.exact_under = exact_under;
            let s = Stack::build(&d, model, &tables).unwrap();
            let n = s.method().grid().len();
            let mut r = vec![0.0; n];
            for c in colours {
                s.method().uplift_f64(&c, &mut r);
                let got = xyz_of(s.colorimetry(), &r);
                assert!(
                    (0..3).all(|k| (got[k] - c[k]).abs() < 1e-9),
                    "{got:?} {c:?}"
                );
            }
            // Counted into the caller's tally, each call's own.
            let c32: Vec<f32> = colours.as_flattened().iter().map(|&v| v as f32).collect();
            let mut r32 = vec![0.0f32; n * colours.len()];
            let mut tally = crate::method::Tally::default();
            s.method().uplift_f32_tallied(&c32, &mut r32, &mut tally);
            assert!(s.counts_bounded());
            assert_eq!(
                tally.bounded.in_range + tally.bounded.projected,
                colours.len()
            );
            let mut again = crate::method::Tally::default();
            s.method()
                .uplift_f32_tallied(&c32[..3], &mut r32[..n], &mut again);
            assert_eq!(again.bounded.in_range + again.bounded.projected, 1);
        }
    }

    #[test]
    fn folding_the_readers_correction_gives_the_resampled_spectra() {
        // The stack folds the correction into the maps; Resampled applies it per spectrum.
        // Both must give the same spectra for every kind of input: blended, hard-switched,
        // dark (scaled offset), negative, HDR, past the overflow guard, black, NaN.
        let model = Model::builtin();
        let mut d = StackSpec::convert_default(MethodName::Otsu2018);
        d.bounded = false;
        let folded = Stack::build(&d, model, &TableCache::none()).unwrap();
        let (readers, _) = d.output(model).unwrap();
        let per_pixel = Resampled::new(
            Uplifter::new(model).unwrap().with_blend(d.blend).unwrap(),
            readers.clone(),
        )
        .unwrap();
        let white = readers.xyz(&vec![1.0; 36]);
        let mut colours = vec![[0.0; 3], [f64::NAN, 0.2, 0.3], [2e-4, 1e-4, 3e-4]];
        colours.extend([[-0.1, 0.05, 0.2], [40.0, 35.0, 20.0], [3e37, 1e37, 2e37]]);
        colours.extend((0..400).map(|i| {
            let (x, y) = (
                0.15 + (i % 20) as f64 * 0.027,
                0.08 + (i / 20) as f64 * 0.031,
            );
            [x / y * 0.3, 0.3, (1.0 - x - y) / y * 0.3]
        }));
        colours.push(white);
        let (mut a, mut b) = (vec![0.0; 36], vec![0.0; 36]);
        let (mut a32, mut b32) = (vec![0.0f32; 36], vec![0.0f32; 36]);
        for c in &colours {
            folded.method().uplift_f64(c, &mut a);
            per_pixel.uplift_f64(c, &mut b);
            let scale = a.iter().fold(1.0f64, |m, v| m.max(v.abs()));
            for (x, y) in a.iter().zip(&b) {
                let same = (x.is_nan() && y.is_nan()) || (x - y).abs() <= 1e-12 * scale;
                assert!(same, "{c:?}: {x} against {y}");
            }
            let c32 = c.map(|v| v as f32);
            folded.method().uplift_f32(&c32, &mut a32);
            per_pixel.uplift_f32(&c32, &mut b32);
            let scale = a32.iter().fold(1.0f32, |m, v| m.max(v.abs()));
            for (x, y) in a32.iter().zip(&b32) {
                let same = (x.is_nan() && y.is_nan()) || (x - y).abs() <= 2e-6 * scale;
                assert!(same, "{c:?}: {x} against {y} in f32");
            }
        }
        assert_eq!(folded.method().name(), "otsu2018");
        let other = Colorimetry::new(
            "400:700:5".parse().unwrap(),
            Observer::Cie1931,
            Illuminant::D65,
        )
        .unwrap();
        let e = Uplifter::new(model)
            .unwrap()
            .exact_under(&other)
            .err()
            .unwrap();
        assert!(e.to_string().contains("model's grid"), "{e}");
    }

    #[test]
    fn what_cannot_be_built_says_why() {
        let model = Model::builtin();
        let d = StackSpec::convert_default(MethodName::Pca);
        let e = Stack::build(&d, model, &TableCache::none()).err().unwrap();
        assert!(e.to_string().contains("one-cluster model"), "{e}");
        let mut d = StackSpec::convert_default(MethodName::Otsu2018);
        d.blend = -1.0;
        assert!(Stack::build(&d, model, &TableCache::none()).is_err());
        let mut d = StackSpec::convert_default(MethodName::Jakob2019);
        d.jakob_resolution = 1;
        let e = Stack::build(&d, model, &TableCache::none()).err().unwrap();
        assert!(e.to_string().contains("resolution"), "{e}");
    }
}
