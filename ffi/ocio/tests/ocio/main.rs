//! specconv-ocio's integration tests, one binary: configs and rules, the official configs,
//! XYZ against ocioconvert.

mod config;
mod official;
mod xyz;
