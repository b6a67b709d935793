//! Which inputs of a batch one shard converts: the plan of the farm crate weighted by each
//! input's pixel count. Shared by `convert --shard` and `farm submit`, so both split alike.

use anyhow::Result;
use specconv_farm::Shard;
use std::path::{Path, PathBuf};

/// The inputs of one shard of a `convert` batch, and their outputs.
pub(crate) fn shard_of(
    shard: Shard,
    inputs: Vec<PathBuf>,
    outputs: Vec<PathBuf>,
) -> Result<(Vec<PathBuf>, Vec<PathBuf>)> {
    let index = index(shard)?;
    let weights: Vec<u64> = inputs.iter().map(|i| pixels(i)).collect();
    let mine = &specconv_farm::plan(&weights, shard.count)[index];
    Ok(mine
        .iter()
        .map(|&k| (inputs[k].clone(), outputs[k].clone()))
        .unzip())
}

/// This run's shard: I of `I/N`, or `auto/N`'s from $SLURM_ARRAY_TASK_ID.
pub(crate) fn index(shard: Shard) -> Result<usize> {
    Ok(shard.index(std::env::var("SLURM_ARRAY_TASK_ID").ok().as_deref())?)
}

/// Pixels of every level of an input, the weight of the plan; 0 when it cannot be read (it
/// will fail fast wherever it lands).
pub(crate) fn pixels(input: &Path) -> u64 {
    specconv_conversion::images::pixel_count(input).unwrap_or(0)
}
