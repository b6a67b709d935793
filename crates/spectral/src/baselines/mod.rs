//! The uplift methods other than the clustered PCA, behind the same [`Method`](crate::Method)
//! trait: Smits 1999, Meng et al. 2015 (unbounded and bounded) and Jakob & Hanika 2019.

pub mod jakob;
pub mod jakob_cache;
pub mod meng;
pub mod smits;

pub use jakob::Jakob2019;
pub use meng::Meng2015;
pub use smits::Smits1999;
