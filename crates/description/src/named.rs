//! [`Named`]: the values of a choice, each with the one name every front-end spells it (the
//! command line, the Python package, `specconvSettings`, a farm manifest), the other spellings
//! it accepts, and the order help lists them. A front-end parses a choice only through it, so
//! that no front-end accepts a name the library does not define.

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
pub(crate) use named;

named!(Sample, "sample type", [Sample::Half => "half", Sample::Float => "float"]);
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
