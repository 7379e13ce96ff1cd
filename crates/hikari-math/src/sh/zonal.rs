//! Convolution with zonal (rotationally symmetric) kernels, and irradiance.

use super::{Sh, ShCoeff};
use std::f32::consts::PI;

/// Per-band factors `Â_l` of the clamped cosine `max(0, cos θ)`: `π, 2π/3, π/4`.
/// Irradiance coefficients are `E_lm = Â_l L_lm` (Ramamoorthi & Hanrahan 2001).
pub const CLAMPED_COSINE_BANDS: [f32; 3] = [PI, 2.0 * PI / 3.0, PI / 4.0];

/// Convolves with a zonal kernel `h(cos θ)` given by its own zonal SH coefficients
/// `h_l = ∫ h Y_l0 dω` (l = 0, 1, 2): `(h * f)_lm = √(4π / (2l + 1)) h_l f_lm` (Funk-Hecke).
pub fn convolve_zonal<T: ShCoeff, const N: usize>(
    sh: &Sh<T, N>,
    kernel_zonal: [f32; 3],
) -> Sh<T, N> {
    let mut f = [0.0f32; 3];
    for (l, fl) in f.iter_mut().enumerate() {
        *fl = (4.0 * PI / (2 * l + 1) as f32).sqrt() * kernel_zonal[l];
    }
    sh.scale_bands(f)
}

/// Irradiance `E(n) = ∫ L(ω) max(0, n·ω) dω` as SH, from radiance SH (W m⁻² sr⁻¹ in,
/// W m⁻² out, or any consistent photometric units).
pub fn irradiance<T: ShCoeff, const N: usize>(radiance: &Sh<T, N>) -> Sh<T, N> {
    radiance.scale_bands(CLAMPED_COSINE_BANDS)
}

/// Irradiance at unit normal `n` from radiance SH.
pub fn irradiance_at<T: ShCoeff, const N: usize>(radiance: &Sh<T, N>, n: glam::Vec3) -> T {
    irradiance(radiance).eval(n)
}
