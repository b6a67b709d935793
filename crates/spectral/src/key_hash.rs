//! The hasher of the keys that number pixels and texels: the compact encoder's remembered
//! texels ([`crate::compact`]) and the pipeline's numbering of distinct pixels and texels
//! (`specconv_pipeline::in_memory`, `specconv_pipeline::palette`).

/// Hashes a pixel's or texel's key: one multiply (Fibonacci hashing) of keys that are already
/// well spread in their low bits; std's SipHash guards against keys chosen to collide, which
/// costs 3× here and buys nothing (a hostile image only slows its own load).
pub type KeyHash = std::hash::BuildHasherDefault<KeyHasher>;

/// [`KeyHash`]'s hasher.
#[derive(Default)]
pub struct KeyHasher(u64);

impl std::hash::Hasher for KeyHasher {
    fn finish(&self) -> u64 {
        self.0
    }

    fn write(&mut self, bytes: &[u8]) {
        for b in bytes {
            self.write_u64(u64::from(*b));
        }
    }

    fn write_u32(&mut self, v: u32) {
        self.write_u64(u64::from(v));
    }

    fn write_u64(&mut self, v: u64) {
        self.0 = (self.0 ^ v)
            .wrapping_mul(0x9e37_79b9_7f4a_7c15)
            .rotate_left(26);
    }
}
