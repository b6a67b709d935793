//! `--shard I/N`: which shard this run is. The split itself, inputs weighted by pixel count,
//! is the library's (`specconv_conversion::Plan::shard`), the same as `farm submit`'s tasks.

use anyhow::Result;
use specconv_farm::Shard;

/// This run's shard: I of `I/N`, or `auto/N`'s from $SLURM_ARRAY_TASK_ID.
pub fn index(shard: Shard) -> Result<usize> {
    Ok(shard.index(std::env::var("SLURM_ARRAY_TASK_ID").ok().as_deref())?)
}
