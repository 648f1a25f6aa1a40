//! [`Random`]: a module's reproducible random source, derived from the run seed and
//! the module's path.
//!
//! A run has one seed (`--seed N` on `ferroc run` and on a bundle's programs, printed
//! at start when chosen from the OS). Every module instance that asks for randomness
//! ([`Setup::random`](crate::Setup::random)) gets its own stream: ChaCha8 keyed by the
//! run seed and the module's element path. So a module's numbers depend only on the
//! seed and where the module sits in the model: adding, removing or reordering other
//! modules does not change them, two noise modules never draw the same numbers, and
//! a lockstep run with the same seed is the same on every run and every machine.
//!
//! ChaCha8 (`rand_chacha`, the rand project's) is a counter-mode stream cipher: its
//! output is a pure function of the 256-bit key and the 64-bit stream number, the
//! same on every platform, and streams of different keys are independent. It costs a
//! few nanoseconds a number, far below a module step.

use rand_chacha::rand_core::{RngCore, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::hash::{BuildHasher, Hasher};

/// A module's random source: reproducible, from the run seed and the module's path
/// ([`Setup::random`](crate::Setup::random)), or from a seed the module was given
/// ([`Random::from_seed`]).
#[derive(Clone, Debug)]
pub struct Random {
    rng: ChaCha8Rng,
}

impl Random {
    /// The stream `stream` of the module at `path` in a run with `seed`. The ChaCha key
    /// is the seed and two 64-bit FNV-1a hashes of the path (of different offset
    /// bases), little-endian, then eight zero bytes; the stream number is ChaCha's.
    pub(crate) fn for_module(seed: u64, path: &str, stream: u64) -> Self {
        let mut key = [0u8; 32];
        key[..8].copy_from_slice(&seed.to_le_bytes());
        key[8..16].copy_from_slice(&fnv1a(path, FNV_OFFSET).to_le_bytes());
        key[16..24].copy_from_slice(&fnv1a(path, FNV_OFFSET_2).to_le_bytes());
        let mut rng = ChaCha8Rng::from_seed(key);
        rng.set_stream(stream);
        Random { rng }
    }

    /// A stream from a seed of the module's own (a `seed` parameter the model sets):
    /// the same numbers for the same seed, whatever the run seed and the module's
    /// path. The key is the seed, then 24 bytes of `0xff` (no module path hashes to
    /// that, so it is never the stream of a module).
    pub fn from_seed(seed: u64) -> Self {
        let mut key = [0xffu8; 32];
        key[..8].copy_from_slice(&seed.to_le_bytes());
        Random {
            rng: ChaCha8Rng::from_seed(key),
        }
    }

    /// 64 random bits.
    #[inline]
    pub fn next_u64(&mut self) -> u64 {
        self.rng.next_u64()
    }

    /// A number in [0, 1), from the upper 53 bits (every value a multiple of 2⁻⁵³).
    #[inline]
    pub fn next_f64(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    /// A number in [`low`, `high`) (`low` when the range is empty).
    #[inline]
    pub fn uniform(&mut self, low: f64, high: f64) -> f64 {
        if high > low {
            low + (high - low) * self.next_f64()
        } else {
            low
        }
    }

    /// An integer in [0, `n`), without modulo bias (Lemire's method); 0 when `n` is 0.
    pub fn below(&mut self, n: u64) -> u64 {
        if n == 0 {
            return 0;
        }
        let threshold = n.wrapping_neg() % n;
        loop {
            let m = u128::from(self.next_u64()) * u128::from(n);
            if (m as u64) >= threshold {
                return (m >> 64) as u64;
            }
        }
    }

    /// A draw of the standard normal distribution (mean 0, standard deviation 1), by
    /// the Box–Muller transform: two uniform numbers per draw.
    pub fn gaussian(&mut self) -> f64 {
        // 1 - u is in (0, 1]: its logarithm is finite.
        let u1 = 1.0 - self.next_f64();
        let u2 = self.next_f64();
        (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
    }

    /// Fills `bytes` with random bytes.
    pub fn fill(&mut self, bytes: &mut [u8]) {
        self.rng.fill_bytes(bytes);
    }
}

const FNV_OFFSET: u64 = 0xcbf2_9ce4_8422_2325;
const FNV_OFFSET_2: u64 = 0x6c62_272e_07bb_0142;

/// FNV-1a, 64 bits, from `offset`: a stable hash of the path (std's hashers may change
/// between Rust versions, and the streams must not).
fn fnv1a(text: &str, offset: u64) -> u64 {
    text.bytes().fold(offset, |h, b| {
        (h ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3)
    })
}

/// 64 bits from the operating system's randomness: the run seed when none is given.
/// std's `RandomState` keys its hashers from the OS's entropy source (getrandom on
/// Linux); hashing nothing under such a key gives a uniformly random value without a
/// dependency of our own. Modules do not call this: they take
/// [`Setup::random`](crate::Setup::random) (reproducible) or
/// [`Setup::os_random`](crate::Setup::os_random) (reported in lockstep).
#[doc(hidden)]
pub fn seed_from_os() -> u64 {
    let mut h = std::collections::hash_map::RandomState::new().build_hasher();
    h.write_u64(0x5eed);
    h.finish()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn draws(mut r: Random) -> Vec<u64> {
        (0..4).map(|_| r.next_u64()).collect()
    }

    #[test]
    fn a_stream_depends_on_seed_path_and_stream_number_only() {
        let a = draws(Random::for_module(7, "robot/noise", 0));
        assert_eq!(a, draws(Random::for_module(7, "robot/noise", 0)));
        assert_ne!(a, draws(Random::for_module(8, "robot/noise", 0)));
        assert_ne!(a, draws(Random::for_module(7, "robot/noise2", 0)));
        assert_ne!(a, draws(Random::for_module(7, "robot/noise", 1)));
        assert_ne!(a, draws(Random::from_seed(7)));
        assert_eq!(draws(Random::from_seed(3)), draws(Random::from_seed(3)));
    }

    /// The streams are part of the promise that a recording made today replays the
    /// same tomorrow: these numbers must never change.
    #[test]
    fn streams_are_stable_across_versions() {
        let mut r = Random::for_module(1, "sensors/noise", 0);
        assert_eq!(r.next_u64(), STABLE_FIRST);
    }
    const STABLE_FIRST: u64 = 14_123_434_555_778_064_449;

    #[test]
    fn numbers_fall_in_their_ranges() {
        let mut r = Random::from_seed(1);
        let mut sum = 0.0;
        for _ in 0..10_000 {
            let u = r.next_f64();
            assert!((0.0..1.0).contains(&u));
            assert!(r.below(6) < 6);
            let x = r.uniform(-2.0, 3.0);
            assert!((-2.0..3.0).contains(&x));
            let g = r.gaussian();
            assert!(g.is_finite());
            sum += g;
        }
        // The mean of 10,000 standard normal draws is within 0.05 of 0 (5 sigma).
        assert!((sum / 10_000.0).abs() < 0.05, "{}", sum / 10_000.0);
        assert_eq!(r.below(0), 0);
        assert_eq!(r.uniform(1.0, 1.0), 1.0);
    }

    #[test]
    fn the_os_gives_different_seeds() {
        assert_ne!(seed_from_os(), seed_from_os());
    }
}
