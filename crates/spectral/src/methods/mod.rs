//! The uplift methods other than the clustered PCA, behind the same [`Method`](crate::Method)
//! trait: Smits 1999, Meng et al. 2015 (unbounded and bounded) and Jakob & Hanika 2019.

pub mod jakob;
pub mod meng;
pub mod smits;
pub mod working_space;

pub use jakob::Jakob2019;
pub use meng::Meng2015;
pub use smits::Smits1999;
pub use working_space::WorkingSpace;

use crate::Error;

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
