//! specconv-oiio's integration tests, one binary: pixels against oiiotool, errors, parallel
//! reads.

mod dumpdata;
mod errors;
mod parallel;
