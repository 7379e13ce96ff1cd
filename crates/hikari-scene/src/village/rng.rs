//! The village's random numbers (the workspace's SplitMix64, from `hikari-math`) and a
//! lattice hash for noise. No global state: the same seed gives the same village.

use hikari_math::sampling::rng::SplitMix64;
pub use hikari_math::sampling::rng::mix;

/// The village's view of the workspace generator. Its integers come from the remainder of
/// all 64 bits, which is what the village was generated with; keeping that keeps every house
/// and tree where it was.
#[derive(Clone, Debug)]
pub struct Rng(SplitMix64);

impl Rng {
    /// An independent stream for one part of the village (`label`), so that changing how
    /// many numbers one part draws does not reshuffle the others.
    pub fn stream(seed: u64, label: &str) -> Rng {
        Rng(SplitMix64::stream(seed, label))
    }

    pub fn next_u64(&mut self) -> u64 {
        self.0.next_u64()
    }

    /// Uniform in [0, 1), 24 random bits.
    pub fn unit(&mut self) -> f32 {
        self.0.next_f32()
    }

    /// Uniform in [lo, hi).
    pub fn range(&mut self, lo: f32, hi: f32) -> f32 {
        self.0.range(lo, hi)
    }

    /// Uniform in [-r, r).
    pub fn signed(&mut self, r: f32) -> f32 {
        self.0.signed(r)
    }

    /// Uniform integer in 0..n (n > 0; 0 gives 0).
    pub fn below(&mut self, n: usize) -> usize {
        self.0.below_by_remainder(n)
    }

    pub fn chance(&mut self, p: f32) -> bool {
        self.0.chance(p)
    }
}

/// A value in [-1, 1] for the integer lattice point (i, j), fixed by `seed`.
pub fn lattice(seed: u64, i: i32, j: i32) -> f32 {
    let h = mix(seed ^ mix((i as u32 as u64) | ((j as u32 as u64) << 32)));
    (h >> 40) as f32 * (2.0 / (1u64 << 24) as f32) - 1.0
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unit_is_in_range_and_roughly_uniform() {
        let mut r = Rng::stream(7, "test");
        let n = 100_000;
        let mut sum = 0.0f64;
        for _ in 0..n {
            let u = r.unit();
            assert!((0.0..1.0).contains(&u));
            sum += u as f64;
        }
        assert!((sum / n as f64 - 0.5).abs() < 0.01);
        assert_ne!(
            Rng::stream(7, "a").next_u64(),
            Rng::stream(7, "b").next_u64()
        );
        assert_ne!(
            Rng::stream(7, "a").next_u64(),
            Rng::stream(8, "a").next_u64()
        );
    }
}
