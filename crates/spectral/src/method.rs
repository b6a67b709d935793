//! The [`Method`] trait that every uplift method and adapter implements, and the methods' names.

use crate::error::Error;
use specconv_colour::Grid;

/// One way of turning XYZ colours into spectra: the clustered PCA and the baselines alike, so
/// that evaluation, conversion and reports treat them the same.
pub trait Method: Send + Sync {
    /// The name used on the command line and in reports (`otsu2018`, …).
    fn name(&self) -> &str;
    /// The grid of the spectra it makes.
    fn grid(&self) -> Grid;
    /// Uplifts colours `xyz` (X, Y, Z per colour, white Y = 1) into `out` (one spectrum of
    /// `grid().len()` values per colour).
    fn uplift_f64(&self, xyz: &[f64], out: &mut [f64]);
    /// As `uplift_f64`, in single precision.
    fn uplift_f32(&self, xyz: &[f32], out: &mut [f32]);
    /// As `uplift_f32`, adding what the method's adapters counted to `tally`, which the caller
    /// owns: two conversions sharing a method never mix their counts. Adapters that count
    /// ([`crate::bounded`], [`crate::emission`]) and adapters that wrap another method
    /// override it; the default counts nothing.
    fn uplift_f32_tallied(&self, xyz: &[f32], out: &mut [f32], _tally: &mut Tally) {
        self.uplift_f32(xyz, out)
    }
    /// Bytes of the data the f32 uplift reads (tables, matrices, tree): the model's size.
    fn model_bytes(&self) -> usize;
    /// The cluster a colour is uplifted by, for methods that have clusters.
    fn cluster_of(&self, _xyz: [f64; 3]) -> Option<usize> {
        None
    }
}

/// How many colours of a call had each outcome of [`crate::bounded::Bounded`].
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Counts {
    /// The method's spectrum was already in [0, 1].
    pub in_range: usize,
    /// Projected into [0, 1] with the input's XYZ.
    pub projected: usize,
    /// Outside the object-colour solid: the nearest colour in CIELAB a reflectance can have.
    pub outside: usize,
    /// NaN or infinite colours, passed through.
    pub not_finite: usize,
}

impl std::ops::AddAssign for Counts {
    fn add_assign(&mut self, o: Counts) {
        self.in_range += o.in_range;
        self.projected += o.projected;
        self.outside += o.outside;
        self.not_finite += o.not_finite;
    }
}

/// What the adapters of a method counted over the calls of [`Method::uplift_f32_tallied`] that
/// were given it: a plain value the caller owns (per block, then summed), not a counter shared
/// on the method.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Tally {
    /// Outcomes of a bounded method uplifting the caller's colours (an emissive stack's
    /// bounded method sees scaled trial colours: not counted).
    pub bounded: Counts,
    /// Colours no emission spectrum of the method matched ([`crate::emission`]).
    pub unmatched: u64,
}

impl std::ops::AddAssign for Tally {
    fn add_assign(&mut self, o: Tally) {
        self.bounded += o.bounded;
        self.unmatched += o.unmatched;
    }
}

/// The colours of `xyz` with their spectra in `out`, `n` bands each, for the uplift loops of
/// the methods. `out` not holding `n` values per colour is the caller's bug: a panic.
pub fn per_colour<'a, T>(
    xyz: &'a [T],
    out: &'a mut [T],
    n: usize,
) -> impl Iterator<Item = (&'a [T], &'a mut [T])> {
    assert_eq!(
        xyz.len() / 3 * n,
        out.len(),
        "out must hold n values per colour"
    );
    xyz.chunks_exact(3).zip(out.chunks_exact_mut(n))
}

impl Method for Box<dyn Method> {
    fn name(&self) -> &str {
        (**self).name()
    }

    fn grid(&self) -> Grid {
        (**self).grid()
    }

    fn uplift_f64(&self, xyz: &[f64], out: &mut [f64]) {
        (**self).uplift_f64(xyz, out)
    }

    fn uplift_f32(&self, xyz: &[f32], out: &mut [f32]) {
        (**self).uplift_f32(xyz, out)
    }

    fn uplift_f32_tallied(&self, xyz: &[f32], out: &mut [f32], tally: &mut Tally) {
        (**self).uplift_f32_tallied(xyz, out, tally)
    }

    fn model_bytes(&self) -> usize {
        (**self).model_bytes()
    }

    fn cluster_of(&self, xyz: [f64; 3]) -> Option<usize> {
        (**self).cluster_of(xyz)
    }
}

/// Every method by its command-line name.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum MethodName {
    /// `smits1999`: Smits 1999, seven basis spectra mixed by the colour's RGB.
    Smits1999,
    /// `meng2015`: Meng et al. 2015, the smoothest spectrum with the colour.
    Meng2015,
    /// `meng2015-bounded`: Meng et al. 2015 with the spectrum kept in [0, 1].
    Meng2015Bounded,
    /// `jakob2019`: Jakob & Hanika 2019, a sigmoid of a quadratic per colour, from a table.
    Jakob2019,
    /// The clustered PCA with one cluster (the paper's "PCA only").
    Pca,
    /// `otsu2018`: the clustered PCA of Otsu et al. 2018 with a trained model.
    Otsu2018,
}

impl MethodName {
    /// Every method; `FromStr` accepts exactly their [`MethodName::as_str`] names.
    pub const ALL: [MethodName; 6] = [
        MethodName::Smits1999,
        MethodName::Meng2015,
        MethodName::Meng2015Bounded,
        MethodName::Jakob2019,
        MethodName::Pca,
        MethodName::Otsu2018,
    ];

    /// The command-line name (`smits1999`, `meng2015-bounded`, `otsu2018`, …); `FromStr` reads it
    /// back.
    pub fn as_str(self) -> &'static str {
        match self {
            MethodName::Smits1999 => "smits1999",
            MethodName::Meng2015 => "meng2015",
            MethodName::Meng2015Bounded => "meng2015-bounded",
            MethodName::Jakob2019 => "jakob2019",
            MethodName::Pca => "pca",
            MethodName::Otsu2018 => "otsu2018",
        }
    }

    /// Whether the method is a trained clustered-PCA model.
    pub fn is_clustered(self) -> bool {
        matches!(self, MethodName::Pca | MethodName::Otsu2018)
    }
}

impl std::fmt::Display for MethodName {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

impl std::str::FromStr for MethodName {
    type Err = Error;

    fn from_str(s: &str) -> Result<MethodName, Error> {
        MethodName::ALL
            .into_iter()
            .find(|m| m.as_str() == s)
            .ok_or_else(|| {
                let names: Vec<_> = MethodName::ALL.iter().map(|m| m.as_str()).collect();
                Error::Unknown(format!("method `{s}`; choose one of {}", names.join(", ")))
            })
    }
}
