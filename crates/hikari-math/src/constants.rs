//! Every derived constant in one plain struct, for `hikari constants [--white R,G,B] [--json]`
//! (the CLI serialises it; this crate stays serde-free) and for engineers copying numbers.
//! Matrices are arrays of rows acting on column vectors; linear Rec.709 is the working space.

use crate::MathError;
use crate::color::adaptation::white_balance_rec709;
use crate::color::primaries::{ACESCG, LMS_RAYLEIGH, REC709, TONEMAP, rgb_to_rgb};
use crate::color::purkinje::PurkinjeMatrices;
use crate::color::rayleigh::{
    MIE_SCATTERING_BRUNETON, RAYLEIGH_LMS_PATRY, RAYLEIGH_REC709_BRUNETON,
};
use crate::color::smits::smits_basis;
use crate::color::{Mat3Rows, mul3};

/// The constants of issue 4's `hikari constants --json` keys, plus a few companions.
#[derive(Clone, Debug, PartialEq)]
pub struct DerivedConstants {
    /// The white colour given (linear Rec.709) that `white_balance_rec709` maps white to.
    pub white_rec709: [f64; 3],
    /// Linear Rec.709 → CIE XYZ (D65, Y of white = 1).
    pub rec709_to_xyz: Mat3Rows,
    /// ACEScg → XYZ (ACES white).
    pub acescg_to_xyz: Mat3Rows,
    /// Tonemapping space (ACEScg, red x = 0.75) → XYZ (ACES white).
    pub tonemap_to_xyz: Mat3Rows,
    /// LMS Rayleigh space → XYZ (D65).
    pub lms_rayleigh_to_xyz: Mat3Rows,
    /// Linear Rec.709 → tonemapping space, Bradford-adapted D65 → ACES white.
    pub rec709_to_tonemap: Mat3Rows,
    /// Tonemapping space → linear Rec.709, Bradford-adapted ACES white → D65.
    pub tonemap_to_rec709: Mat3Rows,
    /// White balance (Bradford von Kries) as one linear Rec.709 matrix: (1, 1, 1) → `white_rec709`.
    pub white_balance_rec709: Mat3Rows,
    /// `rec709_to_tonemap · white_balance_rec709`: the one matrix the talk's grading applies.
    pub rec709_to_tonemap_balanced: Mat3Rows,
    /// Purkinje shift, shader matrix 1 (4 x 3): Rec.709 → gain-ready LMS and rod response R.
    pub lmsr_from_rec709: [[f64; 3]; 4],
    /// Purkinje shift, shader matrix 2 (3 x 3): LMS gain → Rec.709 change per unit rod response.
    pub rgb_from_lms_gain: Mat3Rows,
    /// Wavelengths of the Smits basis, nm.
    pub smits_wavelengths_nm: Vec<f64>,
    /// The computed Smits basis: reflectance of R, G, B at each wavelength.
    pub smits_basis: [Vec<f64>; 3],
    /// Rayleigh scattering in the LMS Rayleigh space, km⁻¹ (Patry 2021).
    pub rayleigh_lms_per_km: [f64; 3],
    /// Rayleigh scattering in Rec.709, km⁻¹ (Bruneton 2008).
    pub rayleigh_rec709_per_km: [f64; 3],
    /// Mie scattering (grey), km⁻¹ (Bruneton 2008).
    pub mie_per_km: f64,
}

impl DerivedConstants {
    /// Derives everything for white-balance target `white` (linear Rec.709, each component
    /// finite and > 0; `[1, 1, 1]` for no white balance).
    pub fn new(white: [f64; 3]) -> Result<Self, MathError> {
        let white_balance = white_balance_rec709(white)?;
        let rec709_to_tonemap = rgb_to_rgb(&REC709, &TONEMAP);
        let purkinje = PurkinjeMatrices::new();
        let smits = smits_basis();
        Ok(Self {
            white_rec709: white,
            rec709_to_xyz: REC709.rgb_to_xyz(),
            acescg_to_xyz: ACESCG.rgb_to_xyz(),
            tonemap_to_xyz: TONEMAP.rgb_to_xyz(),
            lms_rayleigh_to_xyz: LMS_RAYLEIGH.rgb_to_xyz(),
            rec709_to_tonemap,
            tonemap_to_rec709: rgb_to_rgb(&TONEMAP, &REC709),
            white_balance_rec709: white_balance,
            rec709_to_tonemap_balanced: mul3(&rec709_to_tonemap, &white_balance),
            lmsr_from_rec709: purkinje.lmsr_from_rgb,
            rgb_from_lms_gain: purkinje.rgb_from_lms_gain,
            smits_wavelengths_nm: smits.wavelengths_nm.to_vec(),
            smits_basis: smits.rgb.map(|r| r.to_vec()),
            rayleigh_lms_per_km: RAYLEIGH_LMS_PATRY,
            rayleigh_rec709_per_km: RAYLEIGH_REC709_BRUNETON,
            mie_per_km: MIE_SCATTERING_BRUNETON,
        })
    }
}
