//! MIP levels made from the spectra, as the rows of level 0 stream by.
//!
//! Level k + 1 is level k filtered, value by value (every band, and alpha): reflectance and
//! premultiplied alpha are linear, so averaging spectra is the physical average, where
//! uplifting an averaged RGB is not. The filters are maketx's (OpenImageIO 2.4,
//! `maketexture.cpp`). Its default, box, is `resize_block`: each pixel of the smaller level is
//! the source level sampled bilinearly at that pixel's centre, edges clamped; when a size
//! halves exactly, that is the 2×2 box average, an odd size gives the bilinear sample maketx
//! gives. Every other filter is OpenImageIO's `resize` with that [`Filter`] (module `filter`):
//! each pixel the normalised weighted sum of the source pixels under the filter centred on it,
//! edges clamped. Level sizes round down, as OpenEXR's MIP maps with rounding mode DOWN and
//! maketx's do.
//!
//! `--resize` makes level 0 itself the same way from the spectra at the input's size: maketx
//! enlarges with `resize_block` for box and triangle, else with `resize` and the filter
//! widened by the enlargement.
//!
//! Nothing holds a whole level: each level keeps the rows it is still summing (a separable
//! filter's, summed across then down) or the window of source rows its filter reaches (the
//! radial ones), and the rows of its current strip of blocks.

use crate::choices::Filter;
use crate::filter::Kernel as _;
use rayon::prelude::*;
use std::collections::VecDeque;

/// Along one axis, for each pixel of the smaller image: the source pixels it reads (edges
/// clamped, in order) and their weights.
type Taps = Vec<Vec<(usize, f32)>>;

/// What a level is made from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Step {
    /// The level above it.
    Mip,
    /// The input's spectra, at the input's size (`--resize`).
    Resize,
}

/// maketx's `resize_block` along one axis: the two source pixels the bilinear sample at each
/// pixel's centre reads.
fn bilinear(src: usize, dst: usize) -> Taps {
    (0..dst)
        .map(|x| {
            // The centre of pixel x, in the source's pixel coordinates (maketx computes it in
            // NDC: s = (x + 0.5) / dst, then s · src − 0.5).
            let p = ((x as f64 + 0.5) * src as f64 / dst as f64 - 0.5).max(0.0);
            let first = (p.floor() as usize).min(src - 1);
            let second = (first + 1).min(src - 1);
            let t = (p - first as f64) as f32;
            vec![(first, 1.0 - t), (second, t)]
        })
        .collect()
}

/// OpenImageIO's `resize` along one axis, in its `f32` arithmetic.
#[derive(Debug, Clone, Copy)]
struct Axis {
    src: usize,
    dst: usize,
    /// dst / src.
    ratio: f32,
    /// The filter's width, in pixels of the smaller image (maketx's `setup_filter`).
    width: f32,
    /// Source pixels read either side of the centre.
    radius: i64,
}

impl Axis {
    fn new(filter: Filter, src: usize, dst: usize) -> Axis {
        let ratio = dst as f32 / src as f32;
        let width = ratio.max(1.0) * filter.width();
        Axis {
            src,
            dst,
            ratio,
            width,
            radius: ((width / 2.0) / ratio).ceil() as i64,
        }
    }

    /// Pixel `x`'s centre in the source: the source pixel it falls in, and where in it.
    fn centre(&self, x: usize) -> (i64, f32) {
        let s = (x as f32 + 0.5) * (1.0 / self.dst as f32);
        let at = s * self.src as f32;
        let floor = at.floor();
        (floor as i64, at - floor)
    }

    /// The distance, in pixels of the smaller image, of the source pixel `offset` from the
    /// one the centre falls in (`frac` into it).
    fn distance(&self, offset: i64, frac: f32) -> f32 {
        self.ratio * (offset as f32 - (frac - 0.5))
    }

    fn clamped(&self, i: i64) -> usize {
        i.clamp(0, self.src as i64 - 1) as usize
    }

    /// The taps of a separable filter, normalised along this axis.
    fn taps(&self, filter: Filter) -> Taps {
        (0..self.dst)
            .map(|x| {
                let (base, frac) = self.centre(x);
                let mut taps: Vec<(usize, f32)> = (-self.radius..=self.radius)
                    .map(|i| {
                        let w = filter.along(self.distance(i, frac), self.width);
                        (self.clamped(base + i), w)
                    })
                    .collect();
                let total = taps.iter().fold(0.0f32, |s, t| s + t.1);
                if total != 0.0 {
                    taps.iter_mut().for_each(|t| t.1 /= total);
                }
                taps
            })
            .collect()
    }
}

/// How a level reads the level above.
enum Kernel {
    /// Across, then down: the rows being summed, as (row, sum so far).
    Separable {
        columns: Taps,
        rows: Taps,
        open: VecDeque<(usize, Vec<f32>)>,
    },
    /// A filter of the distance in both directions at once (radial-lanczos3, disk): the
    /// source rows it still reaches, as (row, values).
    Radial {
        filter: Filter,
        x: Axis,
        y: Axis,
        window: VecDeque<(usize, Vec<f32>)>,
    },
}

/// One level made from the level above it (or, resized, from the input's spectra).
struct Level {
    /// Width and height of this level.
    width: usize,
    height: usize,
    /// Values per pixel.
    values: usize,
    kernel: Kernel,
    /// The source row expected next.
    next_source: usize,
    /// The next of this level's rows to start (separable) or make (radial).
    next_row: usize,
    /// Finished rows of the strip being gathered, and the strip's first row.
    strip: Vec<f32>,
    strip_y: usize,
}

impl Level {
    fn new(
        source: (usize, usize),
        size: (usize, usize),
        values: usize,
        filter: Filter,
        step: Step,
    ) -> Level {
        let (x, y) = (
            Axis::new(filter, source.0, size.0),
            Axis::new(filter, source.1, size.1),
        );
        // maketx's `resize_block` for box, and when enlarging for triangle too.
        let kernel =
            if filter == Filter::Box || (step == Step::Resize && filter == Filter::Triangle) {
                Kernel::Separable {
                    columns: bilinear(source.0, size.0),
                    rows: bilinear(source.1, size.1),
                    open: VecDeque::new(),
                }
            } else if filter.separable() {
                Kernel::Separable {
                    columns: x.taps(filter),
                    rows: y.taps(filter),
                    open: VecDeque::new(),
                }
            } else {
                Kernel::Radial {
                    filter,
                    x,
                    y,
                    window: VecDeque::new(),
                }
            };
        Level {
            width: size.0,
            height: size.1,
            values,
            kernel,
            next_source: 0,
            next_row: 0,
            strip: Vec::new(),
            strip_y: 0,
        }
    }

    /// A source row filtered across, to this level's width (a radial filter reads it whole).
    fn across(&self, source: &[f32]) -> Vec<f32> {
        let Kernel::Separable { columns, .. } = &self.kernel else {
            return source.to_vec();
        };
        let m = self.values;
        let mut out = vec![0.0f32; self.width * m];
        for (px, taps) in out.chunks_exact_mut(m).zip(columns) {
            let (first, w) = taps[0];
            for (o, &v) in px.iter_mut().zip(&source[first * m..(first + 1) * m]) {
                *o = w * v;
            }
            for &(i, w) in &taps[1..] {
                for (o, &v) in px.iter_mut().zip(&source[i * m..(i + 1) * m]) {
                    *o += w * v;
                }
            }
        }
        out
    }

    /// Takes the next source row, already filtered across; returns this level's rows it
    /// finished, in order.
    fn down(&mut self, across: &[f32]) -> Vec<Vec<f32>> {
        let r = self.next_source;
        self.next_source += 1;
        match &mut self.kernel {
            Kernel::Separable { rows, open, .. } => {
                while self.next_row < self.height && rows[self.next_row][0].0 <= r {
                    open.push_back((self.next_row, vec![0.0; self.width * self.values]));
                    self.next_row += 1;
                }
                for (row, sum) in open.iter_mut() {
                    // A clamped edge reads a row more than once: its weights, summed.
                    let w = rows[*row]
                        .iter()
                        .filter(|t| t.0 == r)
                        .fold(0.0f32, |s, t| s + t.1);
                    if w != 0.0 {
                        sum.iter_mut().zip(across).for_each(|(s, &v)| *s += w * v);
                    }
                }
                let mut done = Vec::new();
                while let Some((row, _)) = open.front() {
                    if rows[*row].last().expect("a tap at least").0 > r {
                        break;
                    }
                    done.push(open.pop_front().expect("just seen").1);
                }
                done
            }
            Kernel::Radial { window, .. } => {
                window.push_back((r, across.to_vec()));
                let mut done = Vec::new();
                while self.next_row < self.height && self.reach(self.next_row).1 <= r {
                    done.push(self.radial_row(self.next_row));
                    self.next_row += 1;
                }
                if self.next_row < self.height {
                    let first = self.reach(self.next_row).0;
                    let Kernel::Radial { window, .. } = &mut self.kernel else {
                        unreachable!("matched above")
                    };
                    while window.front().is_some_and(|(row, _)| *row < first) {
                        window.pop_front();
                    }
                }
                done
            }
        }
    }

    /// The first and last source rows a radial filter reads for row `y`.
    fn reach(&self, y: usize) -> (usize, usize) {
        let Kernel::Radial { y: axis, .. } = &self.kernel else {
            unreachable!("radial filters only")
        };
        let (base, _) = axis.centre(y);
        (
            axis.clamped(base - axis.radius),
            axis.clamped(base + axis.radius),
        )
    }

    /// Row `y` of a radial filter, from the source rows in its window: OpenImageIO's
    /// non-separable `resize` (the weights normalised by their sum). Its rows are centred on
    /// the sample; OpenImageIO 2.4 starts them at the larger of the two radii, and aborts
    /// where the radii differ.
    fn radial_row(&self, y: usize) -> Vec<f32> {
        let Kernel::Radial {
            filter,
            x: ax,
            y: ay,
            window,
        } = &self.kernel
        else {
            unreachable!("radial filters only")
        };
        let m = self.values;
        let (base_y, frac_y) = ay.centre(y);
        let first = window.front().expect("rows arrive before they are read").0;
        let mut out = vec![0.0f32; self.width * m];
        for (x, px) in out.chunks_exact_mut(m).enumerate() {
            let (base_x, frac_x) = ax.centre(x);
            let mut total = 0.0f32;
            for j in -ay.radius..=ay.radius {
                let row = &window[ay.clamped(base_y + j) - first].1;
                for i in -ax.radius..=ax.radius {
                    let w = filter.at(
                        (ax.distance(i, frac_x), ay.distance(j, frac_y)),
                        (ax.width, ay.width),
                    );
                    if w != 0.0 {
                        total += w;
                        let at = ax.clamped(base_x + i) * m;
                        for (o, &v) in px.iter_mut().zip(&row[at..at + m]) {
                            *o += w * v;
                        }
                    }
                }
            }
            if total != 0.0 {
                px.iter_mut().for_each(|v| *v /= total);
            }
        }
        out
    }
}

/// A strip of a made level: `height` rows of `width` pixels, `values` per pixel, from row `y`.
pub struct MadeStrip {
    pub level: usize,
    pub y: usize,
    pub width: usize,
    pub rows: Vec<f32>,
}

/// Every level below 0 of a MIP map, made as level 0's rows arrive in order; or, resized,
/// every level, made as the rows of the input's spectra arrive.
pub struct Cascade {
    /// `levels[k]` makes the level after `sizes[k]`.
    levels: Vec<Level>,
    /// Rows per strip (the tile height).
    strip_height: usize,
    /// The first size is the input's, not level 0's (`--resize`).
    resized: bool,
}

impl Cascade {
    /// The levels of a MIP map whose levels have `sizes` (level 0 first; when `resized`, the
    /// input's size first, then level 0's), made with `filter`, gathered in strips of
    /// `strip_height` rows, `values` per pixel.
    pub fn new(
        sizes: &[(usize, usize)],
        strip_height: usize,
        values: usize,
        filter: Filter,
        resized: bool,
    ) -> Cascade {
        Cascade {
            levels: sizes
                .windows(2)
                .enumerate()
                .map(|(k, w)| {
                    let step = if resized && k == 0 {
                        Step::Resize
                    } else {
                        Step::Mip
                    };
                    Level::new(w[0], w[1], values, filter, step)
                })
                .collect(),
            strip_height,
            resized,
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
                    level: k + 1 - usize::from(self.resized),
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
        filtered(w, h, image, push, Filter::Box)
    }

    /// The same, with `filter`.
    fn filtered(w: usize, h: usize, image: &[f32], push: usize, filter: Filter) -> Vec<Vec<f32>> {
        let s = sizes(w, h);
        let mut c = Cascade::new(&s, 4, 1, filter, false);
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

    /// Every level of every filter, made from rows as they arrive, equals the same filter
    /// applied to the whole level above at once (OpenImageIO's `resize`, written out plainly).
    #[test]
    fn streamed_levels_are_the_whole_level_filtered() {
        let (w, h) = (13, 11);
        let image: Vec<f32> = (0..w * h).map(|v| ((v * 7919) % 101) as f32).collect();
        for filter in specconv_description::Named::ALL
            .iter()
            .copied()
            .filter(|f: &Filter| *f != Filter::Box)
        {
            let streamed = filtered(w, h, &image, 3, filter);
            let s = sizes(w, h);
            for k in 1..s.len() {
                let whole = resize(&streamed[k - 1], s[k - 1], s[k], filter);
                for (a, b) in streamed[k].iter().zip(&whole) {
                    assert!((a - b).abs() <= 1e-3, "{filter} level {k}: {a} {b}");
                }
            }
        }
    }

    /// OpenImageIO's `resize` of a one-value image, pixel by pixel, in 2-D.
    fn resize(
        src: &[f32],
        (sw, sh): (usize, usize),
        (dw, dh): (usize, usize),
        f: Filter,
    ) -> Vec<f32> {
        let (ax, ay) = (Axis::new(f, sw, dw), Axis::new(f, sh, dh));
        let mut out = Vec::new();
        for y in 0..dh {
            let (by, fy) = ay.centre(y);
            for x in 0..dw {
                let (bx, fx) = ax.centre(x);
                let (mut sum, mut total) = (0.0f64, 0.0f64);
                for j in -ay.radius..=ay.radius {
                    for i in -ax.radius..=ax.radius {
                        let w = f64::from(f.at(
                            (ax.distance(i, fx), ay.distance(j, fy)),
                            (ax.width, ay.width),
                        ));
                        let v = src[ay.clamped(by + j) * sw + ax.clamped(bx + i)];
                        sum += w * f64::from(v);
                        total += w;
                    }
                }
                out.push((sum / total) as f32);
            }
        }
        out
    }

    #[test]
    fn resizing_makes_level_0_then_its_levels() {
        // 3×2 → 4×2 (box enlarges bilinearly, as maketx's resize_block), then 2×1 and 1×1.
        let image = [0.0, 3.0, 6.0, 0.0, 3.0, 6.0];
        let sizes = [(3, 2), (4, 2), (2, 1), (1, 1)];
        let mut c = Cascade::new(&sizes, 4, 1, Filter::Box, true);
        let made = c.push(&image, 3);
        let levels: Vec<usize> = made.iter().map(|m| m.level).collect();
        assert_eq!(levels, [0, 1, 2]);
        // Centres at 0.375·3 − 0.5 = −0.125 (clamped to 0), 0.625, 1.375, 2.125 (clamped).
        assert_eq!(made[0].rows[..4], [0.0, 1.875, 4.125, 6.0]);
    }
}
