//! Spectral tables (see [`super::spectral_data`] for the sources) and integration helpers.
//!
//! All tables share one grid, 390..=780 nm every 5 nm (the range of the Stockman & Sharpe cone
//! fundamentals, so no table is extrapolated). Integrals are Riemann sums with `Δλ = 5 nm` (or
//! 10 nm on the coarse grid), normalised so that the D65 white has luminance `Y = 1`, which
//! makes the absolute `Δλ` and the arbitrary scale of D65 cancel.

use super::spectral_data::{
    CIE1931_XYZ, D65, LEN, SCOTOPIC_V, START_NM, STEP_NM, STOCKMAN_SHARPE_LMS,
};

pub use super::spectral_data::{SMITS1999, SMITS1999_NM};

/// Wavelength (nm) of fine-grid sample `i`.
pub fn wavelength_nm(i: usize) -> f64 {
    START_NM + STEP_NM * i as f64
}

/// Number of samples of the 10 nm grid (every other 5 nm sample: 390, 400, ..., 780 nm).
pub const COARSE_LEN: usize = LEN.div_ceil(2);

/// Wavelengths of the 10 nm grid, nm.
pub fn coarse_wavelengths_nm() -> [f64; COARSE_LEN] {
    std::array::from_fn(|i| wavelength_nm(2 * i))
}

/// Receptor responses used by the Purkinje shift, on the 10 nm grid: L, M, S cones (Stockman &
/// Sharpe 2°, energy, peak 1) and rods (CIE 1951 V'(λ), peak 1).
pub fn coarse_lmsr() -> [[f64; 4]; COARSE_LEN] {
    std::array::from_fn(|i| {
        let c = STOCKMAN_SHARPE_LMS[2 * i];
        [c[0], c[1], c[2], SCOTOPIC_V[2 * i]]
    })
}

/// D65 on the 10 nm grid, scaled so that `Σ ȳ D65 = 1` on that grid: a reflectance of 1 has
/// luminance 1.
pub fn coarse_d65_unit_luminance() -> [f64; COARSE_LEN] {
    let y: f64 = (0..COARSE_LEN)
        .map(|i| CIE1931_XYZ[2 * i][1] * D65[2 * i])
        .sum();
    std::array::from_fn(|i| D65[2 * i] / y)
}

/// `3 x COARSE_LEN` matrix taking a reflectance sampled on the 10 nm grid to CIE XYZ under D65
/// (white reflectance → D65 white with `Y = 1`).
pub fn coarse_reflectance_to_xyz() -> [[f64; COARSE_LEN]; 3] {
    let d = coarse_d65_unit_luminance();
    std::array::from_fn(|k| std::array::from_fn(|i| CIE1931_XYZ[2 * i][k] * d[i]))
}

/// XYZ of the D65 table itself on the fine grid, normalised to `Y = 1` (close to, but not
/// exactly, the xy 0.3127, 0.3290 of the standards: the tables are rounded and truncated).
pub fn d65_table_white_xyz() -> [f64; 3] {
    let mut xyz = [0.0; 3];
    for i in 0..LEN {
        for (k, v) in xyz.iter_mut().enumerate() {
            *v += CIE1931_XYZ[i][k] * D65[i];
        }
    }
    let y = xyz[1];
    xyz.map(|v| v / y)
}
