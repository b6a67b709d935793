//! specconv's own developer tools, run in a checkout by its developers and by CI, never shipped
//! with the program.

#![deny(missing_docs)]

pub mod generate;
