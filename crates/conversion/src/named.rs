//! [`Named`]: the values of a choice, each with the one name every front-end spells it (the
//! command line, the Python package, `specconvSettings`, a farm manifest), the other spellings
//! it accepts, and the order help lists them. A front-end parses a choice only through it, so
//! that no front-end accepts a name the library does not define.

use crate::pipeline::survey::NonFinite;
use crate::pipeline::{Alpha, Filter, Mip};
use crate::{Compression, DataPolicy, Rounding};
use specconv_colour::EmissionUnits;
use specconv_exr::Sample;
use specconv_spectral::method::MethodName;

/// A choice among named values (polars' one `Wrap<T>` per enum, as a trait).
pub trait Named: Copy + PartialEq + Sized + 'static {
    /// What is chosen, for messages (`compression`).
    const WHAT: &'static str;
    /// Every value, in the order help lists them.
    const ALL: &'static [Self];

    /// Its name.
    fn name(self) -> &'static str;

    /// Other spellings of it that are accepted (`color` for `colour`), never listed in help.
    fn aliases(self) -> &'static [&'static str] {
        &[]
    }

    /// Every name, in help's order.
    fn names() -> Vec<&'static str> {
        Self::ALL.iter().map(|v| v.name()).collect()
    }

    /// The value `text` names (its name or an alias, in any case).
    fn from_name(text: &str) -> Result<Self, UnknownName> {
        Self::ALL
            .iter()
            .copied()
            .find(|v| {
                v.name().eq_ignore_ascii_case(text)
                    || v.aliases().iter().any(|a| a.eq_ignore_ascii_case(text))
            })
            .ok_or_else(|| UnknownName {
                what: Self::WHAT,
                name: text.to_string(),
                choices: Self::names(),
            })
    }
}

/// A name that is not one of a choice's.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("unknown {what} '{name}'; choose one of {}", choices.join(", "))]
pub struct UnknownName {
    /// What was named.
    pub what: &'static str,
    /// The name given.
    pub name: String,
    /// The names there are.
    pub choices: Vec<&'static str>,
}

/// `Named` for an enum: its variants with their names (and aliases after `|`).
macro_rules! named {
    ($ty:ty, $what:literal, [$($variant:path => $name:literal $(| $alias:literal)*),+ $(,)?]) => {
        impl Named for $ty {
            const WHAT: &'static str = $what;
            const ALL: &'static [Self] = &[$($variant),+];

            fn name(self) -> &'static str {
                match self {
                    $($variant => $name),+
                }
            }

            fn aliases(self) -> &'static [&'static str] {
                match self {
                    $($variant => &[$($alias),*]),+
                }
            }
        }
    };
}

named!(Alpha, "alpha", [
    Alpha::Auto => "auto",
    Alpha::Straight => "straight" | "unassociated",
    Alpha::Premultiplied => "premultiplied" | "associated",
]);
named!(Sample, "sample type", [Sample::Half => "half", Sample::Float => "float"]);
named!(Rounding, "half rounding", [
    Rounding::Nearest => "nearest",
    Rounding::Colour => "colour" | "color",
]);
named!(Compression, "compression", [
    Compression::None => "none",
    Compression::Rle => "rle",
    Compression::Zips => "zips",
    Compression::Zip => "zip",
    Compression::Piz => "piz",
    Compression::Pxr24 => "pxr24",
    Compression::B44 => "b44",
    Compression::B44a => "b44a",
    Compression::Dwaa => "dwaa",
    Compression::Dwab => "dwab",
]);
named!(Mip, "MIP levels", [Mip::All => "all", Mip::Base => "0"]);
named!(NonFinite, "NaN handling", [
    NonFinite::Refuse => "refuse" | "check",
    NonFinite::Black => "black",
    NonFinite::Box3 => "box3",
    // maketx's `--fixnan none`.
    NonFinite::Keep => "keep" | "none",
]);
named!(DataPolicy, "data policy", [
    DataPolicy::Skip => "skip",
    DataPolicy::Copy => "copy",
    DataPolicy::Fail => "fail",
]);
named!(EmissionUnits, "emission units", [
    EmissionUnits::Reference => "reference",
    EmissionUnits::Normalised => "normalised" | "normalized",
    EmissionUnits::Photometric => "photometric",
]);
named!(MethodName, "method", [
    MethodName::Otsu2018 => "otsu2018",
    MethodName::Pca => "pca",
    MethodName::Smits1999 => "smits1999",
    MethodName::Meng2015 => "meng2015",
    MethodName::Meng2015Bounded => "meng2015-bounded",
    MethodName::Jakob2019 => "jakob2019",
]);
named!(Filter, "filter", [
    Filter::Box => "box",
    Filter::Triangle => "triangle",
    Filter::Gaussian => "gaussian",
    Filter::SharpGaussian => "sharp-gaussian",
    Filter::CatmullRom => "catmull-rom",
    Filter::BlackmanHarris => "blackman-harris",
    Filter::Sinc => "sinc",
    Filter::Lanczos3 => "lanczos3",
    Filter::RadialLanczos3 => "radial-lanczos3",
    Filter::NukeLanczos6 => "nuke-lanczos6",
    Filter::Mitchell => "mitchell",
    Filter::Bspline => "bspline",
    Filter::Disk => "disk",
    Filter::Cubic => "cubic",
    Filter::Keys => "keys",
    Filter::Simon => "simon",
    Filter::Rifman => "rifman",
]);

#[cfg(test)]
mod tests {
    use super::*;

    /// Every name reads back as its value, aliases too, and no two values share a spelling;
    /// the lower crates' own names (for their messages) are the same.
    fn round_trip<T: Named + std::fmt::Debug>() {
        let mut seen = std::collections::BTreeSet::new();
        for &v in T::ALL {
            assert_eq!(T::from_name(v.name()), Ok(v));
            assert_eq!(T::from_name(&v.name().to_uppercase()), Ok(v));
            for a in v.aliases() {
                assert_eq!(T::from_name(a), Ok(v), "{a}");
            }
            for s in std::iter::once(v.name()).chain(v.aliases().iter().copied()) {
                assert!(seen.insert(s.to_ascii_lowercase()), "{s} twice");
            }
        }
        let e = T::from_name("bogus").unwrap_err();
        assert_eq!(e.choices, T::names());
        assert!(e.to_string().contains(T::WHAT), "{e}");
    }

    #[test]
    fn every_choice_reads_its_names_back() {
        round_trip::<Alpha>();
        round_trip::<Sample>();
        round_trip::<Rounding>();
        round_trip::<Compression>();
        round_trip::<Mip>();
        round_trip::<NonFinite>();
        round_trip::<DataPolicy>();
        round_trip::<EmissionUnits>();
        round_trip::<MethodName>();
        round_trip::<Filter>();
    }

    #[test]
    fn the_lower_crates_spell_their_values_alike() {
        for &m in MethodName::ALL.iter() {
            assert_eq!(m.name(), m.as_str());
            assert_eq!(m.as_str().parse::<MethodName>().unwrap(), m);
        }
        assert_eq!(<MethodName as Named>::ALL.len(), MethodName::ALL.len());
        for &u in EmissionUnits::ALL.iter() {
            assert_eq!(Named::name(u), EmissionUnits::name(u));
        }
    }
}
