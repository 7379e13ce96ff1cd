//! # hikari-atmosphere
//!
//! The CPU atmosphere of hikari (issue 16): Rayleigh, Mie and an ozone layer over a spherical
//! Earth, with precomputed single and multiple scattering tables as Ghost of Tsushima describes
//! them (Patry 2021, "Atmospheric Lighting"): transmittance; Rayleigh and Mie inscattering divided
//! by their phase functions, indexed by altitude, sun angle and view angle, without azimuth; the
//! parallel "irradiance" tables for clouds, haze and particles; all computed in the talk's LMS
//! Rayleigh colour space (or Rec.709 with Bruneton's coefficients, to compare), converted to
//! linear Rec.709 on the way out. No GPU code: the GPU twin mirrors [`Atmosphere`]'s lookups.
//!
//! ```
//! use glam::Vec3;
//! use hikari_atmosphere::{Atmosphere, AtmosphereParams, TableSizes};
//!
//! let small = TableSizes { scattering: [32, 16, 8], density: [16, 16, 8], sphere: [8, 8],
//!                          ray_steps: 20, ..TableSizes::default() };
//! let atmosphere = Atmosphere::with_sizes(AtmosphereParams::default(), small)?;
//! let sun = Vec3::new(0.0, 0.5, 0.866); // 60 degrees from the zenith (+Y up)
//! let nits = atmosphere.sky_radiance(0.0, Vec3::Y, sun, atmosphere.solar_illuminance());
//! assert!(nits.z > nits.x); // blue sky
//! # Ok::<(), hikari_atmosphere::AtmosphereError>(())
//! ```
//!
//! See `docs/atmosphere.md` for the model, the parameterisations and the tables' layout.

// Table code reads best with explicit channel indices.
#![allow(clippy::needless_range_loop)]

pub mod atmosphere;
pub mod build;
pub mod error;
pub mod geometry;
pub(crate) mod parallel;
pub mod params;
pub mod phase;
pub mod table;

pub use atmosphere::Atmosphere;
pub use build::{BuildReport, TableSizes, Tables, transmittance_to_top};
pub use error::AtmosphereError;
pub use params::{AtmosphereParams, ColorSpace};
