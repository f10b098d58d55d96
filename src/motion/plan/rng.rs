//! The planner's random numbers: ChaCha8 with explicit conversions, so a seed gives the same
//! numbers on every machine and with every version of the `rand` traits' helpers.

use rand::{RngCore, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// A seeded stream of uniform numbers.
pub(crate) struct Stream(ChaCha8Rng);

impl Stream {
    /// The stream of `seed`, for one purpose (`salt` keeps the search's and the shortcutting's
    /// numbers independent).
    pub(crate) fn new(seed: u64, salt: u64) -> Self {
        Self(ChaCha8Rng::seed_from_u64(
            seed ^ salt.wrapping_mul(0x9E37_79B9_7F4A_7C15),
        ))
    }

    /// Uniform in [0, 1): the top 53 bits of one 64-bit word.
    pub(crate) fn unit(&mut self) -> f64 {
        (self.0.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    /// Uniform in [lo, hi].
    pub(crate) fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.unit()
    }

    /// A configuration uniform in the box `bounds`.
    pub(crate) fn config(&mut self, bounds: &[(f64, f64); 6]) -> [f64; 6] {
        let mut q = [0.0; 6];
        for (j, &(lo, hi)) in bounds.iter().enumerate() {
            q[j] = self.range(lo, hi);
        }
        q
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_seed_gives_the_same_numbers_and_salts_differ() {
        let mut a = Stream::new(7, 1);
        let mut b = Stream::new(7, 1);
        let mut c = Stream::new(7, 2);
        let xa: Vec<u64> = (0..4).map(|_| a.unit().to_bits()).collect();
        let xb: Vec<u64> = (0..4).map(|_| b.unit().to_bits()).collect();
        let xc: Vec<u64> = (0..4).map(|_| c.unit().to_bits()).collect();
        assert_eq!(xa, xb);
        assert_ne!(xa, xc);
        assert!((0..1000).all(|_| (0.0..1.0).contains(&a.unit())));
    }
}
