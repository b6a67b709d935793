//! The numbers include/specconv_spectrum.h shares with the library (issue 55, decision 5): the
//! text grammar's limits, the solvers' step counts and tolerances, the penalty, the white's
//! rule. They are written into the header between two marker lines from the library's own
//! constants by `cargo run -p specconv-dev -- generate`, whose `--check` (CI) fails when the
//! header is stale, as for the option tables.

use crate::{bounded, compact};
use specconv_colour::rgb::SRGB;
use specconv_colour::solid::{self, nearest};
use specconv_colour::Grid;

/// One shared number: how C names it, where the library keeps it, its value.
pub struct Shared {
    /// The macro's name in the header.
    pub c_name: &'static str,
    /// The library's constant, as the header's comment names it.
    pub library: &'static str,
    /// Its value.
    pub value: Number,
}

/// A count (written as a C integer) or a real (written as the shortest decimal that reads
/// back as the same double, which C's strtod and Rust's parse both round correctly).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Number {
    /// A step count or a limit.
    Count(i64),
    /// A tolerance, a weight, a level.
    Real(f64),
}

impl Number {
    fn c_text(self) -> String {
        match self {
            Number::Count(v) => v.to_string(),
            // Exponent form for the very large and small (1e12, not 1000000000000.0).
            Number::Real(v) if v != 0.0 && !(1e-3..1e5).contains(&v.abs()) => format!("{v:e}"),
            Number::Real(v) => format!("{v:?}"),
        }
    }
}

/// One [`Shared`], the library's name written from its path.
macro_rules! shared {
    ($c:literal, count $($p:tt)+) => {
        Shared {
            c_name: $c,
            library: stringify!($($p)+),
            value: Number::Count($($p)+ as i64),
        }
    };
    ($c:literal, real $($p:tt)+) => {
        Shared {
            c_name: $c,
            library: stringify!($($p)+),
            value: Number::Real($($p)+),
        }
    };
}

/// Every number the header shares, in the order it defines them.
pub fn shared() -> Vec<Shared> {
    vec![
        shared!("SCS_MAX_DEPTH", count compact::MAX_DEPTH),
        shared!("SCS_MAX_BANDS", count compact::MAX_BANDS),
        shared!("SCS_WHOLE_STEPS", real Grid::WHOLE_STEPS),
        shared!("SCS_DARK", real compact::DARK),
        shared!("SCS_MAX_WIDTH", real compact::MAX_WIDTH),
        shared!("SCS_DUAL_STEPS_", count solid::DUAL_STEPS),
        shared!("SCS_RESIDUAL_", real solid::RESIDUAL),
        shared!("SCS_STALLED_RESIDUAL_", real solid::STALLED_RESIDUAL),
        shared!("SCS_HESSIAN_FLOOR_", real solid::HESSIAN_FLOOR),
        shared!("SCS_STEP_FLOOR_", real solid::STEP_FLOOR),
        shared!("SCS_PSI_ROUNDING_", real solid::PSI_ROUNDING),
        shared!("SCS_ARMIJO_", real solid::ARMIJO),
        shared!("SCS_POLISH_HALVINGS_", count solid::POLISH_HALVINGS),
        shared!("SCS_STRONGER_PENALTIES_", count solid::STRONGER_PENALTIES),
        shared!("SCS_NEAREST_STEPS_", count nearest::STEPS),
        shared!("SCS_NEAREST_SUB_", count nearest::SUB_STEPS),
        shared!("SCS_NEAREST_TRIES_", count nearest::TRIES),
        shared!("SCS_NEAREST_MU_START_", real nearest::MU_START),
        shared!("SCS_NEAREST_MU_SHRINK_", real nearest::MU_SHRINK),
        shared!("SCS_NEAREST_MU_FLOOR_", real nearest::MU_FLOOR),
        shared!("SCS_NEAREST_MU_GROW_", real nearest::MU_GROW),
        shared!("SCS_NEAREST_MU_CAP_", real nearest::MU_CAP),
        shared!("SCS_NEAREST_SUB_TOLERANCE_", real nearest::SUB_TOLERANCE),
        shared!("SCS_NEAREST_SETTLED_PHI_", real nearest::SETTLED_PHI),
        shared!("SCS_NEAREST_SETTLED_MOVE_", real nearest::SETTLED_MOVE),
        shared!("SCS_REGULARISED_STEPS_", count bounded::REGULARISED_STEPS),
        shared!("SCS_REGULARISATION_", real bounded::REGULARISATION),
        shared!("SCS_WHITE_ROUNDING_", real bounded::WHITE_ROUNDING),
        shared!("SCS_SAME_WHITE_", real bounded::SAME_WHITE),
        shared!("SCS_D65_X_", real SRGB.white[0]),
        shared!("SCS_D65_Y_", real SRGB.white[1]),
    ]
}

/// The generated part: one `#define` a line, the library's name in a comment.
pub fn generated() -> String {
    let shared = shared();
    let width = shared.iter().map(|s| s.c_name.len()).max().unwrap_or(0);
    let mut out = String::new();
    for s in shared {
        let line = format!(
            "#define {:width$} {}",
            s.c_name,
            s.value.c_text(),
            width = width
        );
        out += &format!("{line:48} /* {} */\n", s.library);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every value's C text reads back as the same number (C's strtod rounds correctly, as
    /// Rust's parse does); every name once.
    #[test]
    fn each_number_is_written_exactly_and_named_once() {
        let shared = shared();
        for s in &shared {
            match s.value {
                Number::Count(v) => assert_eq!(s.value.c_text().parse::<i64>().unwrap(), v),
                Number::Real(v) => assert_eq!(
                    s.value.c_text().parse::<f64>().unwrap().to_bits(),
                    v.to_bits(),
                    "{}",
                    s.c_name
                ),
            }
            assert_eq!(
                shared.iter().filter(|t| t.c_name == s.c_name).count(),
                1,
                "{}",
                s.c_name
            );
        }
    }
}
