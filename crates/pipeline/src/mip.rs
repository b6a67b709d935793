//! MIP levels made from the spectra, as the rows of level 0 stream by.
//!
//! Level k + 1 is level k filtered, value by value (every band, and alpha): reflectance and
//! premultiplied alpha are linear, so averaging spectra is the physical average, where
//! uplifting an averaged RGB is not. The filter is maketx's default (OpenImageIO 2.4,
//! `maketexture.cpp`, `resize_block`): each pixel of the smaller level is the source level
//! sampled bilinearly at that pixel's centre, edges clamped. When a size halves exactly, that
//! is the 2×2 box average; an odd size gives the bilinear sample maketx gives. Level sizes
//! round down, as OpenEXR's MIP maps with rounding mode DOWN and maketx's do.
//!
//! Nothing holds a whole level: each level keeps the (at most two) rows it is still summing
//! and the rows of its current strip of blocks.

use rayon::prelude::*;
use std::collections::VecDeque;

/// For each pixel of a level `dst` wide, the two source pixels (of a level `src` wide) that
/// the bilinear sample at its centre reads, and the weight of the second.
fn taps(src: usize, dst: usize) -> Vec<(usize, usize, f32)> {
    (0..dst)
        .map(|x| {
            // The centre of pixel x, in the source's pixel coordinates (maketx computes it in
            // NDC: s = (x + 0.5) / dst, then s · src − 0.5).
            let p = ((x as f64 + 0.5) * src as f64 / dst as f64 - 0.5).max(0.0);
            let first = (p.floor() as usize).min(src - 1);
            let second = (first + 1).min(src - 1);
            (first, second, (p - first as f64) as f32)
        })
        .collect()
}

/// One level made from the level above it.
struct Level {
    /// Width and height of this level.
    width: usize,
    height: usize,
    /// Values per pixel.
    values: usize,
    columns: Vec<(usize, usize, f32)>,
    rows: Vec<(usize, usize, f32)>,
    /// The source row expected next.
    next_source: usize,
    /// The next of this level's rows to start summing.
    next_row: usize,
    /// Rows being summed: (row, sum so far).
    open: VecDeque<(usize, Vec<f32>)>,
    /// Finished rows of the strip being gathered, and the strip's first row.
    strip: Vec<f32>,
    strip_y: usize,
}

impl Level {
    fn new(source: (usize, usize), size: (usize, usize), values: usize) -> Level {
        Level {
            width: size.0,
            height: size.1,
            values,
            columns: taps(source.0, size.0),
            rows: taps(source.1, size.1),
            next_source: 0,
            next_row: 0,
            open: VecDeque::new(),
            strip: Vec::new(),
            strip_y: 0,
        }
    }

    /// A source row filtered across, to this level's width.
    fn across(&self, source: &[f32]) -> Vec<f32> {
        let m = self.values;
        let mut out = vec![0.0f32; self.width * m];
        for (px, &(a, b, t)) in out.chunks_exact_mut(m).zip(&self.columns) {
            let (a, b) = (&source[a * m..(a + 1) * m], &source[b * m..(b + 1) * m]);
            for ((o, &a), &b) in px.iter_mut().zip(a).zip(b) {
                *o = (1.0 - t) * a + t * b;
            }
        }
        out
    }

    /// Takes the next source row, already filtered across; returns this level's rows it
    /// finished, in order.
    fn down(&mut self, across: &[f32]) -> Vec<Vec<f32>> {
        let r = self.next_source;
        self.next_source += 1;
        while self.next_row < self.height && self.rows[self.next_row].0 <= r {
            self.open
                .push_back((self.next_row, vec![0.0; self.width * self.values]));
            self.next_row += 1;
        }
        for (row, sum) in self.open.iter_mut() {
            let (a, b, t) = self.rows[*row];
            let w = if a == r { 1.0 - t } else { 0.0 } + if b == r { t } else { 0.0 };
            if w != 0.0 {
                sum.iter_mut().zip(across).for_each(|(s, &v)| *s += w * v);
            }
        }
        let mut done = Vec::new();
        while let Some((row, _)) = self.open.front() {
            if self.rows[*row].1 > r {
                break;
            }
            done.push(self.open.pop_front().expect("just seen").1);
        }
        done
    }
}

/// A strip of a made level: `height` rows of `width` pixels, `values` per pixel, from row `y`.
pub(crate) struct MadeStrip {
    pub level: usize,
    pub y: usize,
    pub width: usize,
    pub rows: Vec<f32>,
}

/// Every level below 0 of a MIP map, made as level 0's rows arrive in order.
pub(crate) struct Cascade {
    /// `levels[k]` makes level k + 1.
    levels: Vec<Level>,
    /// Rows per strip (the tile height).
    strip_height: usize,
}

impl Cascade {
    /// The levels of a MIP map whose levels have `sizes` (level 0 first), gathered in strips
    /// of `strip_height` rows, `values` per pixel.
    pub fn new(sizes: &[(usize, usize)], strip_height: usize, values: usize) -> Cascade {
        Cascade {
            levels: sizes
                .windows(2)
                .map(|w| Level::new(w[0], w[1], values))
                .collect(),
            strip_height,
        }
    }

    /// Takes the next rows of level 0 (`width` pixels each); returns the strips of smaller
    /// levels they completed, each before any strip made from it.
    pub fn push(&mut self, rows: &[f32], width: usize) -> Vec<MadeStrip> {
        let mut made = Vec::new();
        let Some(first) = self.levels.first() else {
            return made;
        };
        let m = first.values;
        // Filtering across is most of the work: rows in parallel.
        let across: Vec<Vec<f32>> = rows
            .par_chunks_exact(width * m)
            .map(|row| first.across(row))
            .collect();
        for row in across {
            self.down(0, &row, &mut made);
        }
        made
    }

    /// Feeds one row, filtered across, to the level made by `levels[k]`.
    fn down(&mut self, k: usize, across: &[f32], made: &mut Vec<MadeStrip>) {
        let finished = self.levels[k].down(across);
        for row in finished {
            let level = &mut self.levels[k];
            level.strip.extend_from_slice(&row);
            let rows = level.strip.len() / (level.width * level.values);
            let end = level.strip_y + rows;
            if rows == self.strip_height || end == level.height {
                made.push(MadeStrip {
                    level: k + 1,
                    y: level.strip_y,
                    width: level.width,
                    rows: std::mem::take(&mut level.strip),
                });
                level.strip_y = end;
            }
            if k + 1 < self.levels.len() {
                let next = self.levels[k + 1].across(&row);
                self.down(k + 1, &next, made);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Sizes of a MIP map rounding down, as OpenEXR's.
    fn sizes(w: usize, h: usize) -> Vec<(usize, usize)> {
        let n = (usize::BITS - w.max(h).leading_zeros()) as usize;
        (0..n).map(|k| ((w >> k).max(1), (h >> k).max(1))).collect()
    }

    /// Every made level, whole, from an image pushed in strips of `push` rows.
    fn levels(w: usize, h: usize, image: &[f32], push: usize) -> Vec<Vec<f32>> {
        let s = sizes(w, h);
        let mut c = Cascade::new(&s, 4, 1);
        let mut out = vec![Vec::new(); s.len()];
        out[0] = image.to_vec();
        for rows in image.chunks(push * w) {
            for strip in c.push(rows, w) {
                assert_eq!(strip.y * s[strip.level].0, out[strip.level].len());
                out[strip.level].extend(strip.rows);
            }
        }
        for (k, (w, h)) in s.iter().enumerate() {
            assert_eq!(out[k].len(), w * h, "level {k}");
        }
        out
    }

    #[test]
    fn halving_is_the_two_by_two_average() {
        let image: Vec<f32> = (0..16).map(|v| v as f32).collect();
        let l = levels(4, 4, &image, 1);
        assert_eq!(l[1], vec![2.5, 4.5, 10.5, 12.5]);
        assert_eq!(l[2], vec![7.5]);
    }

    #[test]
    fn odd_sizes_sample_bilinearly_at_the_centre_as_maketx_does() {
        // 5 → 2: centres at 1.25 − 0.5 = 0.75 and 3.75 − 0.5 = 3.25 (maketx's NDC arithmetic).
        let image = [0.0, 10.0, 20.0, 30.0, 40.0];
        let l = levels(5, 1, &image, 1);
        assert_eq!(l[1], vec![7.5, 32.5]);
        // 2 → 1 then: the average.
        assert_eq!(l[2], vec![20.0]);
    }

    #[test]
    fn strips_and_pushes_of_any_height_give_the_same_levels() {
        let (w, h) = (13, 11);
        let image: Vec<f32> = (0..w * h).map(|v| ((v * 7919) % 101) as f32).collect();
        let whole = levels(w, h, &image, h);
        for push in [1, 2, 3, 5] {
            assert_eq!(levels(w, h, &image, push), whole, "push {push}");
        }
        // A constant stays constant at every level.
        let flat = levels(w, h, &vec![0.25; w * h], 3);
        assert!(flat.iter().flatten().all(|&v| v == 0.25));
    }
}
