//! A compact texture's palette: the spectra of its distinct texels at the bands, each decoded
//! once by the rule ([`Compact::decode_f32`], what `expand` writes), and each texel's number in
//! it. A renderer's lookup then reads two band values per texel and wavelength instead of
//! summing the model's leaves for every texel of every lookup (Mitsuba's `specconv_compact`
//! and `specconv_rgb`: the room scene's render, issue 47). An 8-bit photograph's texels repeat
//! (a 2048² one has 352,000 distinct of 4.2 million), so the palette costs less memory than
//! the texels; where it would cost more (noise, float textures), there is none.

use rayon::prelude::*;
use specconv_spectral::compact::{Compact, TEXEL};
use specconv_spectral::key_hash::KeyHash;
use std::collections::HashMap;

/// Distinct texels decoded per parallel piece.
const PIECE: usize = 1024;

/// The most distinct texels of a palette: their numbers are exact as float32, the values a
/// renderer's float texture holds (2²⁴).
pub const MOST: usize = 1 << 24;

/// The palette of `texels` (six values each): each texel's number in it, written to `numbers`
/// as a float32 (exact: fewer than [`MOST`]), and the distinct texels' spectra at the bands
/// (`compact.grid().len()` values each, in the order of their first texel), bitwise distinct
/// texels decoded once each. `None` where the spectra and numbers would take more memory than
/// the texels (more than 5/n of them distinct, n the bands), or there are [`MOST`] distinct
/// texels or more, or a spectrum's numbers would pass `u32`: the texture then decodes per
/// lookup. `numbers` holds one value per texel.
pub fn palette(compact: &Compact, texels: &[f32], numbers: &mut [f32]) -> Option<Vec<f32>> {
    let count = texels.len() / TEXEL;
    assert_eq!(numbers.len(), count, "one number per texel");
    let most = most(compact, count);
    let mut seen: HashMap<(u64, u64, u64), u32, KeyHash> = HashMap::with_hasher(KeyHash::default());
    let mut distinct: Vec<f32> = Vec::new();
    let mut last: Option<(&[f32], f32)> = None;
    for (t, number) in texels.chunks_exact(TEXEL).zip(numbers.iter_mut()) {
        // Neighbours repeat: the texel before answers without a hash.
        if let Some((before, j)) = last.filter(|(before, _)| same(before, t)) {
            *number = j;
            last = Some((before, j));
            continue;
        }
        let next = (distinct.len() / TEXEL) as u32;
        let j = *seen.entry(key(t)).or_insert(next);
        if j == next {
            if next as usize >= most {
                return None;
            }
            distinct.extend_from_slice(t);
        }
        *number = j as f32;
        last = Some((t, j as f32));
    }
    drop(seen);
    Some(spectra(compact, &distinct))
}

/// The most distinct texels a palette of `count` texels may have: beyond it the spectra and
/// numbers would take more memory than the texels (5/n of them, n the bands), or a number
/// would not be exact as float32 ([`MOST`]), or a spectrum's numbers would pass `u32`.
pub(crate) fn most(compact: &Compact, count: usize) -> usize {
    let n = compact.grid().len().max(1);
    (count * (TEXEL - 1) / n)
        .min(MOST - 1)
        .min(u32::MAX as usize / n - 1)
}

/// The spectra at the bands of `distinct` texels (six values each), decoded in parallel by
/// the rule.
pub(crate) fn spectra(compact: &Compact, distinct: &[f32]) -> Vec<f32> {
    let n = compact.grid().len().max(1);
    let mut spectra = vec![0.0f32; distinct.len() / TEXEL * n];
    spectra
        .par_chunks_mut(PIECE * n)
        .zip(distinct.par_chunks(PIECE * TEXEL))
        .for_each(|(s, t)| compact.decode_f32(t, s));
    spectra
}

/// Bitwise equal: a texel's number names exactly its values (NaN payloads and signed zeros
/// apart, which only cost an entry).
fn same(a: &[f32], b: &[f32]) -> bool {
    a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits())
}

/// A texel's six values' bits, two to a number.
fn key(t: &[f32]) -> (u64, u64, u64) {
    let pair = |i: usize| u64::from(t[i].to_bits()) << 32 | u64::from(t[i + 1].to_bits());
    (pair(0), pair(2), pair(4))
}

#[cfg(test)]
mod tests {
    use super::*;
    use specconv_spectral::method::MethodName;
    use specconv_spectral::stack::StackSpec;
    use specconv_spectral::Model;

    fn compact() -> Compact {
        let d = StackSpec::convert_default(MethodName::Otsu2018);
        Compact::new(Model::builtin(), "test", &d).unwrap()
    }

    #[test]
    fn each_texel_is_numbered_to_its_own_spectrum() {
        let c = compact();
        let n = c.grid().len();
        // Repeating colours, signed zeros, NaN and a u of its own: 400 texels, 6 distinct.
        let colours: [[f32; 6]; 6] = [
            [0.2, 0.3, 0.4, 0.0, 0.0, 0.0],
            [0.5, 0.2, 0.1, 0.0, 0.0, 0.0],
            [0.5, 0.2, 0.1, 0.01, -0.02, 0.0],
            [0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
            [-0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
            [f32::NAN, 0.1, 0.1, 0.0, 0.0, 0.0],
        ];
        let order = [0, 0, 1, 2, 1, 3, 4, 5, 0, 2];
        let texels: Vec<f32> = (0..40)
            .flat_map(|_| order.iter().flat_map(|&i| colours[i]))
            .collect();
        let mut numbers = vec![-1.0; texels.len() / TEXEL];
        let spectra = palette(&c, &texels, &mut numbers).expect("6 of 400 distinct");
        assert_eq!(spectra.len(), 6 * n);
        let mut want = vec![0.0; texels.len() / TEXEL * n];
        c.decode_f32(&texels, &mut want);
        for (k, &j) in numbers.iter().enumerate() {
            assert_eq!(j.fract(), 0.0);
            let got = &spectra[j as usize * n..(j as usize + 1) * n];
            let want = &want[k * n..(k + 1) * n];
            assert!(
                got.iter()
                    .zip(want)
                    .all(|(a, b)| a.to_bits() == b.to_bits()),
                "texel {k}"
            );
        }
        let first: Vec<f32> = numbers[..10].to_vec();
        assert_eq!(first, [0.0, 0.0, 1.0, 2.0, 1.0, 3.0, 4.0, 5.0, 0.0, 2.0]);
    }

    #[test]
    fn no_palette_where_it_would_outweigh_the_texels() {
        let c = compact();
        let n = c.grid().len();
        // Distinct texels: 5/n of them is where the palette costs what the texels do.
        let texels = |count: usize, distinct: usize| -> Vec<f32> {
            (0..count)
                .flat_map(|i| {
                    let v = 0.1 + (i % distinct) as f32 * 1e-4;
                    [v, 0.2, 0.3, 0.0, 0.0, 0.0]
                })
                .collect()
        };
        let count = 100 * n;
        let mut numbers = vec![0.0; count];
        assert!(palette(&c, &texels(count, 500), &mut numbers).is_some());
        assert!(palette(&c, &texels(count, 501), &mut numbers).is_none());
        assert!(palette(&c, &texels(count, count), &mut numbers).is_none());
        assert!(palette(&c, &[], &mut []).is_some_and(|s| s.is_empty()));
    }
}
