//! Which inputs each of N tasks converts. Deterministic (the same weights give the same
//! assignment on every machine and in every task) and balanced by pixel count; the split
//! itself is `specconv_atomic_file::shards`, below this crate and the conversion library, so
//! that `farm submit` and `convert --shard` split alike.

use crate::error::Error;
use std::str::FromStr;

/// Splits items of the given weights (pixels) into `n` shards of nearly equal total weight:
/// [`specconv_atomic_file::shards::split`], the one split `convert --shard` converts by too.
///
/// ```
/// use specconv_farm::{assign, Shard};
///
/// // Five inputs by pixel count over two tasks: 6 M pixels each.
/// let pixels = [4_000_000, 1_000_000, 3_000_000, 2_000_000, 2_000_000];
/// assert_eq!(assign(&pixels, 2), [vec![0, 4], vec![1, 2, 3]]);
///
/// // `convert --shard auto/2` in array task 1 converts the second shard.
/// let shard: Shard = "auto/2".parse()?;
/// assert_eq!((shard.index(Some("1"))?, shard.count), (1, 2));
/// assert!("2/2".parse::<Shard>().is_err()); // I counts from 0
/// # Ok::<(), specconv_farm::Error>(())
/// ```
pub fn assign(weights: &[u64], n: usize) -> Vec<Vec<usize>> {
    assert!(n > 0, "an assignment needs at least one task");
    specconv_atomic_file::shards::split(weights, n)
}

/// `--shard I/N`, or `auto/N` with I from `$SLURM_ARRAY_TASK_ID`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shard {
    /// `None` for `auto`.
    pub index: Option<usize>,
    /// N, the number of shards (at least 1).
    pub count: usize,
}

impl FromStr for Shard {
    type Err = Error;

    fn from_str(s: &str) -> Result<Shard, Error> {
        let bad = || Error::Shard(format!("{s:?} is not I/N or auto/N (e.g. 0/4)"));
        let (i, n) = s.split_once('/').ok_or_else(bad)?;
        let count: usize = n.trim().parse().map_err(|_| bad())?;
        if count == 0 {
            return Err(Error::Shard(format!("{s:?}: N must be at least 1")));
        }
        let index = match i.trim() {
            "auto" => None,
            i => Some(i.parse().map_err(|_| bad())?),
        };
        Shard { index, count }.checked(index)
    }
}

impl Shard {
    fn checked(self, index: Option<usize>) -> Result<Shard, Error> {
        match index {
            Some(i) if i >= self.count => Err(Error::Shard(format!(
                "shard {i} of {n} does not exist: I counts from 0 to {}",
                self.count - 1,
                n = self.count
            ))),
            _ => Ok(self),
        }
    }

    /// The shard's index: its own, or for `auto` the array task id Slurm gives the task
    /// (`$SLURM_ARRAY_TASK_ID`, passed here as `array_task`).
    pub fn index(self, array_task: Option<&str>) -> Result<usize, Error> {
        if let Some(i) = self.index {
            return Ok(i);
        }
        let id = array_task.ok_or_else(|| {
            Error::Shard(
                "a shard auto/N takes its index from $SLURM_ARRAY_TASK_ID, which is not set: \
                 give I/N, or run inside a Slurm job array"
                    .into(),
            )
        })?;
        let i = id.trim().parse().map_err(|_| {
            Error::Shard(format!("$SLURM_ARRAY_TASK_ID is {id:?}, not a task number"))
        })?;
        self.checked(Some(i))?;
        Ok(i)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shards_parse_and_auto_reads_the_array_task() {
        let s: Shard = "2/4".parse().unwrap();
        assert_eq!(s.index(None).unwrap(), 2);
        let a: Shard = "auto/4".parse().unwrap();
        assert_eq!(a.index(Some("3")).unwrap(), 3);
        assert!(a
            .index(None)
            .unwrap_err()
            .to_string()
            .contains("SLURM_ARRAY_TASK_ID"));
        assert!(a
            .index(Some("4"))
            .unwrap_err()
            .to_string()
            .contains("does not exist"));
        for bad in ["4/4", "1/0", "x/2", "2", "-1/3"] {
            assert!(bad.parse::<Shard>().is_err(), "{bad}");
        }
    }
}
