//! The [`Method`] trait that every uplift method and adapter implements, and the methods' names.

use crate::Error;
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
    /// Bytes of the data the f32 uplift reads (tables, matrices, tree): the model's size.
    fn model_bytes(&self) -> usize;
    /// The cluster a colour is uplifted by, for methods that have clusters.
    fn cluster_of(&self, _xyz: [f64; 3]) -> Option<usize> {
        None
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
    Smits1999,
    Meng2015,
    Meng2015Bounded,
    Jakob2019,
    /// The clustered PCA with one cluster (the paper's "PCA only").
    Pca,
    Otsu2018,
}

impl MethodName {
    pub const ALL: [MethodName; 6] = [
        MethodName::Smits1999,
        MethodName::Meng2015,
        MethodName::Meng2015Bounded,
        MethodName::Jakob2019,
        MethodName::Pca,
        MethodName::Otsu2018,
    ];

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
