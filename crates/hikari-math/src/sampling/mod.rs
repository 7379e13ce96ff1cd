//! Sampling: low-discrepancy sequences, sphere and hemisphere mappings, GGX visible-normal
//! sampling, void-and-cluster blue noise and Poisson disk sets.

pub mod blue_noise;
pub mod ggx;
pub mod lowdiscrepancy;
pub mod poisson;
pub mod rng;
#[rustfmt::skip]
pub mod sobol_data;
pub mod sphere;

/// The workspace's seeded generator, also reachable here where the generated tables use it.
pub use rng::SplitMix64;
