//! Integration tests of the `specconv` binary: one test crate, modules per command.

mod baselines;
mod colour;
mod compact;
mod compression;
mod convert;
mod emission;
mod farm;
mod front;
mod info;
mod layout;
mod libraries;
mod library;
mod options;
mod pictures;
mod pipes;
mod plans;
mod runner;
mod safety;
mod simulate;
mod spectral_layout;
mod studio;
mod studio_batch;
mod surface;
mod texture;
mod texture_prep;
mod train_eval;
