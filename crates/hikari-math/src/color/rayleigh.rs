//! Rayleigh and Mie scattering coefficients for the two colour spaces of Ghost of Tsushima's
//! atmosphere, in km⁻¹ at sea level (multiply by `exp(−h / H)` for altitude `h`).

use super::Mat3Rows;
use super::primaries::{LMS_RAYLEIGH, REC709, rgb_to_rgb};

/// Rayleigh scattering for Rec.709 (Bruneton & Neyret 2008): β at 680, 550, 440 nm, km⁻¹.
pub const RAYLEIGH_REC709_BRUNETON: [f64; 3] = [5.8e-3, 13.5e-3, 33.1e-3];
/// Wavelengths (nm) at which Bruneton 2008 sampled the Rayleigh coefficient for R, G, B.
pub const BRUNETON_WAVELENGTHS_NM: [f64; 3] = [680.0, 550.0, 440.0];
/// Rayleigh density scale height, km (Bruneton 2008).
pub const RAYLEIGH_SCALE_HEIGHT_KM: f64 = 8.0;
/// Mie scattering, km⁻¹, grey (Bruneton 2008 reference implementation).
pub const MIE_SCATTERING_BRUNETON: f64 = 4e-3;
/// Mie extinction = scattering / 0.9 (single-scattering albedo 0.9, Bruneton 2008).
pub const MIE_EXTINCTION_BRUNETON: f64 = 4e-3 / 0.9;
/// Mie density scale height, km (Bruneton 2008).
pub const MIE_SCALE_HEIGHT_KM: f64 = 1.2;
/// Rayleigh scattering in the talk's LMS Rayleigh space, km⁻¹ (Patry 2021).
pub const RAYLEIGH_LMS_PATRY: [f64; 3] = [0.0076224, 0.012935, 0.024845];
/// Mie scattering in the LMS space: Mie is grey, so the same in every space, km⁻¹.
pub const MIE_SCATTERING_LMS: [f64; 3] = [MIE_SCATTERING_BRUNETON; 3];

/// Rayleigh β(λ) in km⁻¹ following the λ⁻⁴ law through Bruneton's value at 680 nm (which
/// reproduces his 550 and 440 nm values to 3 digits).
pub fn rayleigh_spectral_per_km(lambda_nm: f64) -> f64 {
    RAYLEIGH_REC709_BRUNETON[0] * (680.0 / lambda_nm).powi(4)
}

/// Linear Rec.709 → LMS Rayleigh RGB (both D65, so no adaptation happens).
pub fn rec709_to_lms_rayleigh() -> Mat3Rows {
    rgb_to_rgb(&REC709, &LMS_RAYLEIGH)
}

/// LMS Rayleigh RGB → linear Rec.709.
pub fn lms_rayleigh_to_rec709() -> Mat3Rows {
    rgb_to_rgb(&LMS_RAYLEIGH, &REC709)
}
