//! Integration tests of the `specconv` binary: one test crate, modules per command.

mod runner;
mod train_eval;
