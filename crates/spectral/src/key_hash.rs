//! The hasher of the keys that number pixels and texels: the compact encoder's remembered
//! texels ([`crate::compact`]) and the pipeline's numbering of distinct pixels and texels
//! (`specconv_pipeline::in_memory`, `specconv_pipeline::palette`).

/// Hashes a pixel's or texel's key: one multiply (Fibonacci hashing) of keys that are already
/// well spread in their low bits; std's SipHash guards against keys chosen to collide, which
/// costs 3× here and buys nothing (a hostile image only slows its own load or conversion).
pub type KeyHash = std::hash::BuildHasherDefault<KeyHasher>;

/// [`KeyHash`]'s hasher.
#[derive(Default)]
pub struct KeyHasher(u64);

impl std::hash::Hasher for KeyHasher {
    fn finish(&self) -> u64 {
        self.0
    }

    // An array or slice key ([u32; 3]) arrives as its length, then its bytes in one piece.
    fn write(&mut self, bytes: &[u8]) {
        for chunk in bytes.chunks(8) {
            let mut word = [0u8; 8];
            word[..chunk.len()].copy_from_slice(chunk);
            self.write_u64(u64::from_le_bytes(word));
        }
    }

    fn write_u32(&mut self, v: u32) {
        self.write_u64(u64::from(v));
    }

    fn write_usize(&mut self, v: usize) {
        self.write_u64(v as u64);
    }

    fn write_u64(&mut self, v: u64) {
        self.0 = (self.0 ^ v)
            .wrapping_mul(0x9e37_79b9_7f4a_7c15)
            .rotate_left(26);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::hash::BuildHasher;

    /// The compact encoder's keys, the bits of three float32 values of a colour, take every
    /// word into the hash: 262,144 colours of a 64³ grid and their one-ulp neighbours in each
    /// value give as many distinct hashes, and a table's bucket bits (the low 16) spread them.
    #[test]
    fn colour_keys_hash_apart() {
        let build = KeyHash::default();
        let mut all = std::collections::HashSet::new();
        let mut buckets = vec![0u32; 1 << 16];
        let grid = (0..64u32).map(|i| (i as f32 / 63.0).to_bits());
        let grid: Vec<u32> = grid.collect();
        let mut count = 0;
        for &r in &grid {
            for &g in &grid {
                for &b in &grid {
                    for key in [[r, g, b], [r + 1, g, b], [r, g + 1, b], [r, g, b + 1]] {
                        let h = build.hash_one(key);
                        all.insert(h);
                        buckets[(h & 0xffff) as usize] += 1;
                        count += 1;
                    }
                }
            }
        }
        assert_eq!(all.len(), count);
        // 16 keys a bucket on average: no bucket holds more than 4 times that.
        assert!(
            buckets.iter().all(|&n| n <= 64),
            "{:?}",
            buckets.iter().max()
        );
    }
}
