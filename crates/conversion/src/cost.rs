//! What uplifting costs, on threads: the timing of `report` (the science's
//! [`specconv_evaluation::cost`] times one thread; threads are the library's).

use rayon::prelude::*;
use specconv_evaluation::cost;
use specconv_spectral::Method;
use std::time::Instant;

/// Seconds to uplift `xyz` (three values a colour) tile by tile on one thread, and on `pool`'s
/// threads.
pub fn time(m: &dyn Method, xyz: &[f32], pool: &rayon::ThreadPool) -> (f64, f64) {
    let n = m.grid().len();
    let single = cost::time_one_thread(m, xyz);
    let start = Instant::now();
    pool.install(|| {
        xyz.par_chunks(3 * cost::TILE).for_each_init(
            || vec![0f32; cost::TILE * n],
            |out, tile| cost::uplift_tiles(m, tile, out),
        )
    });
    (single, start.elapsed().as_secs_f64())
}
