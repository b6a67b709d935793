//! Which files of a job each of N runs converts: deterministic (the same weights give the same
//! split on every machine and in every run) and balanced by weight (pixels). Here, below both
//! the conversion library and the farm, so that `convert --shard` and `farm submit` split one
//! way: the library weighs inputs by reading them, the farm by its manifest's counts.

/// Splits items of the given weights (pixels) into `n` shards of nearly equal total weight.
///
/// Longest processing time first: items in decreasing weight (ties by position) each go to the
/// lightest shard so far (ties to the lowest shard). The heaviest shard then exceeds the mean
/// by less than the heaviest item, and is within 4/3 of the best possible (Graham 1969). Each
/// shard lists its items in input order. `n` = 0 gives no shards.
///
/// ```
/// use specconv_atomic_file::shards::split;
///
/// // Five inputs by pixel count over two runs: 6 M pixels each.
/// let pixels = [4_000_000, 1_000_000, 3_000_000, 2_000_000, 2_000_000];
/// assert_eq!(split(&pixels, 2), [vec![0, 4], vec![1, 2, 3]]);
/// ```
pub fn split(weights: &[u64], n: usize) -> Vec<Vec<usize>> {
    let mut shards = vec![Vec::new(); n];
    if n == 0 {
        return shards;
    }
    let mut order: Vec<usize> = (0..weights.len()).collect();
    order.sort_by(|&a, &b| weights[b].cmp(&weights[a]).then(a.cmp(&b)));
    // The lightest shard, ties to the lowest: a heap of (load, shard), smallest first.
    let mut lightest: std::collections::BinaryHeap<std::cmp::Reverse<(u64, usize)>> =
        (0..n).map(|s| std::cmp::Reverse((0, s))).collect();
    for i in order {
        let std::cmp::Reverse((load, s)) = lightest.pop().expect("n > 0 shards");
        shards[s].push(i);
        lightest.push(std::cmp::Reverse((load.saturating_add(weights[i]), s)));
    }
    for s in &mut shards {
        s.sort_unstable();
    }
    shards
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The split as first written (a scan for the lightest shard per item), which `farm
    /// submit` and `convert --shard` have planned with since: the heap must not move a file.
    fn scanned(weights: &[u64], n: usize) -> Vec<Vec<usize>> {
        let mut order: Vec<usize> = (0..weights.len()).collect();
        order.sort_by(|&a, &b| weights[b].cmp(&weights[a]).then(a.cmp(&b)));
        let mut load = vec![0u64; n];
        let mut shards = vec![Vec::new(); n];
        for i in order {
            let lightest = (0..n).min_by_key(|&s| (load[s], s)).unwrap();
            load[lightest] += weights[i];
            shards[lightest].push(i);
        }
        for s in &mut shards {
            s.sort_unstable();
        }
        shards
    }

    #[test]
    fn every_item_lands_in_exactly_one_shard_and_loads_stay_within_the_heaviest_item() {
        // Uneven sizes: a few large textures among many small ones, and zero-pixel (unreadable)
        // inputs.
        let weights: Vec<u64> = (0..37u64)
            .map(|i| (i * 7919 % 23) * (1 << (i % 5)) * 1000)
            .collect();
        for n in 1..=9 {
            let shards = split(&weights, n);
            assert_eq!(shards, scanned(&weights, n), "n = {n}");
            assert_eq!(shards.len(), n);
            let mut seen: Vec<usize> = shards.iter().flatten().copied().collect();
            seen.sort_unstable();
            assert_eq!(seen, (0..weights.len()).collect::<Vec<_>>(), "n = {n}");
            let loads: Vec<u64> = shards
                .iter()
                .map(|s| s.iter().map(|&i| weights[i]).sum())
                .collect();
            let heaviest = *weights.iter().max().unwrap();
            let (min, max) = (*loads.iter().min().unwrap(), *loads.iter().max().unwrap());
            assert!(max - min <= heaviest, "n = {n}: loads {loads:?}");
            assert!(shards.iter().all(|s| s.windows(2).all(|w| w[0] < w[1])));
        }
    }

    #[test]
    fn the_split_is_the_same_every_time_and_ties_go_by_position() {
        let w = [5, 5, 5, 5, 1];
        assert_eq!(split(&w, 2), vec![vec![0, 2, 4], vec![1, 3]]);
        assert_eq!(split(&w, 2), split(&w, 2));
        // More shards than items: the rest are empty.
        assert_eq!(split(&[3, 9], 3), vec![vec![1], vec![0], vec![]]);
        assert!(split(&[3, 9], 0).is_empty());
        // Weightless items (inputs that cannot be read) add no load: all to the first shard,
        // as the scan put them.
        let zeros = vec![0u64; 10];
        assert_eq!(split(&zeros, 3), scanned(&zeros, 3));
        assert_eq!(split(&zeros, 3)[0], (0..10).collect::<Vec<_>>());
    }
}
