//! specconv on an asset (docs/assets.md): a USD stage's (or MaterialX document's) textures,
//! each decided colour or data by the material inputs it feeds, converted as a batch, and a
//! layer that points the stage at the spectral files (a copy of the document, for MaterialX).
//!
//! - [`Reader`]: Pixar's usd-core (`pip install usd-core`) composes the stage (references,
//!   payloads, the selected variants, usdz packages) in a Python interpreter, running the
//!   reader, the Python package's `specconv._asset_reader` (built into this crate for the
//!   command line, which runs it in a child `python -I`; imported by the Python package); it
//!   reports what the stage says and decides nothing.
//!   usd-core is the reference USD implementation; the Rust `openusd` crate has no MaterialX
//!   file format and asset resolver of usd-core's (docs/assets.md has the evidence).
//!   MaterialX documents, given or referenced where usd-core has no MaterialX file format,
//!   are read by the MaterialX package (`pip install MaterialX`) in the same reader.
//! - [`decide`]: the one rule, from the inputs a texture's outputs feed: colour inputs,
//!   data inputs, `sourceColorSpace`, MaterialX `colorspace`; conflicts are never converted.
//! - [`Asset`]: every texture file once, its output under DIR, the colour space its
//!   conversion is given (the material as row 1 of docs/colour.md's precedence: the
//!   conversion's named colour space), and the layer of overrides ([`LayerPlan`]).
//!
//! Front-ends (the command line's `asset`, the Python package's `convert_asset`) read, plan,
//! convert the jobs through the conversion's batch, and write the layer.
#![forbid(unsafe_code)]
#![warn(missing_docs)]

pub mod decide;
mod error;
mod file_names;
mod interpreter;
pub mod plan;
mod reader;
pub mod record;
pub mod run;
pub mod stage;

pub use decide::{Decision, Space, Texture};
pub use error::Error;
pub use file_names::{is_document, is_stage};
pub use interpreter::{install_line, DEFAULT_TIMEOUT, PROTOCOL, PYTHON_VAR, TIMEOUT_VAR};
pub use plan::{Asset, DocumentPlan, Job, LayerPlan, Override, Planned, Retarget};
pub use reader::{check_stage, Call, Reader};
pub use run::{
    farm_layer, finish, make_folders, member, prepare, same_jobs, unknown_line, unknown_record,
    with_member, Converters, FarmFile, Outcomes, Prepared,
};
pub use stage::{MtlxReference, Node, Stage, Use};
