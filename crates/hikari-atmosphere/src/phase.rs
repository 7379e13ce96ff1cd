//! Phase functions, sr⁻¹, of the cosine `nu` of the scattering angle (between the light's and the
//! viewer's propagation directions; `nu = 1` is straight on). Both integrate to 1 over the sphere.

use std::f64::consts::PI;

/// Rayleigh: `3 / (16π) (1 + ν²)`.
pub fn rayleigh(nu: f64) -> f64 {
    3.0 / (16.0 * PI) * (1.0 + nu * nu)
}

/// Cornette-Shanks (1992), the Mie phase of Bruneton & Neyret 2008: Henyey-Greenstein-like, with a
/// `1 + ν²` factor that gives the Rayleigh limit at `g = 0`.
pub fn cornette_shanks(nu: f64, g: f64) -> f64 {
    let k = 3.0 / (8.0 * PI) * (1.0 - g * g) / (2.0 + g * g);
    k * (1.0 + nu * nu) / (1.0 + g * g - 2.0 * g * nu).max(1e-12).powf(1.5)
}

/// Henyey-Greenstein (1941): `(1 - g²) / (4π (1 + g² - 2gν)^1.5)`, mean cosine `g`; the haze's
/// and the clouds' phase in Ghost of Tsushima.
pub fn henyey_greenstein(nu: f64, g: f64) -> f64 {
    (1.0 - g * g) / (4.0 * PI * (1.0 + g * g - 2.0 * g * nu).max(1e-12).powf(1.5))
}
