//! `specconv.convert`'s inputs and outputs, handed to the library's plan
//! ([`specconv_conversion::plan`]): UDIM patterns, output names and every check of the plan are
//! its, as for the command line. Here only the keywords' shapes: `outputs` as a file, a list
//! (one per input) or an existing directory, or `output_template`.

use crate::errors::{conversion, Kind};
use pyo3::prelude::*;
use specconv_conversion::plan::{Outputs, Pair, Plan};
use std::path::PathBuf;

/// Each input (UDIM patterns expanded to their tiles) with its output, once the plan's files
/// allow them. Existing outputs are the batch's to refuse, as it starts.
pub fn pairs(
    py: Python<'_>,
    inputs: Vec<PathBuf>,
    outputs: Option<Vec<PathBuf>>,
    template: Option<&str>,
) -> PyResult<Vec<Pair>> {
    if inputs.is_empty() {
        return Err(Kind::Option.err("no inputs"));
    }
    let outputs = match (outputs, template) {
        (Some(_), Some(_)) => {
            return Err(Kind::Option.err(
                "give outputs or output_template, not both",
            ))
        }
        (None, None) => {
            return Err(Kind::Option.err(
                "give outputs (a file, one file per input, or a directory that exists) or output_template",
            ))
        }
        (None, Some(t)) => Outputs::template(t).map_err(|e| conversion(e.into()))?,
        (Some(files), None) => match &files[..] {
            [dir] if dir.is_dir() => Outputs::Directory(dir.clone()),
            _ => Outputs::Files(files),
        },
    };
    // Planning looks at every file (UDIM tiles, identities): without the GIL.
    let plan = py.detach(|| Plan::new(inputs, &outputs));
    Ok(plan.map_err(|e| conversion(e.into()))?.into_pairs())
}
