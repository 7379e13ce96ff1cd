//! Sampling: low-discrepancy sequences, sphere and hemisphere mappings, GGX visible-normal
//! sampling, void-and-cluster blue noise and Poisson disk sets.

pub mod blue_noise;
pub mod ggx;
pub mod lowdiscrepancy;
pub mod poisson;
#[rustfmt::skip]
pub mod sobol_data;
pub mod sphere;

/// A small, fast, deterministic generator (SplitMix64) so that every generated table is
/// reproducible from its seed on every platform.
#[derive(Clone, Debug)]
pub struct SplitMix64(pub u64);

impl SplitMix64 {
    /// Next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1).
    pub fn next_f64(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }
}
