//! Reproducible "randomness": the same seed text gives the same sequence on every
//! machine, which keeps simulated runs comparable cycle for cycle.

/// A small xorshift generator: reproducible "randomness" without a dependency.
#[derive(Clone, Debug)]
pub(crate) struct Sequence(u64);

impl Sequence {
    /// Seeded from a text (FNV-1a), never zero.
    pub(crate) fn from_text(text: &str) -> Self {
        let mut h: u64 = 0xcbf2_9ce4_8422_2325;
        for b in text.bytes() {
            h = (h ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3);
        }
        Sequence(h | 1)
    }

    pub(crate) fn next(&mut self) -> u64 {
        let mut x = self.0;
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        self.0 = x;
        x
    }

    /// Uniform in [lo, hi).
    pub(crate) fn between(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn traffic_is_reproducible_per_address() {
        let mut a = Sequence::from_text("192.168.10.21");
        let mut b = Sequence::from_text("192.168.10.21");
        let mut c = Sequence::from_text("192.168.10.22");
        let (x, y, z) = (a.next(), b.next(), c.next());
        assert_eq!(x, y);
        assert_ne!(x, z);
        for _ in 0..1000 {
            let v = a.between(0.3, 1.4);
            assert!((0.3..1.4).contains(&v));
        }
    }
}
