//! RGB colour spaces defined by primary and white chromaticities, and their exact RGB ↔ XYZ
//! matrices (the normalised primary matrix of SMPTE RP 177).

use super::{Mat3Rows, inv3, mul3};
use crate::MathError;

/// CIE 1931 xy chromaticity.
pub type Xy = [f64; 2];

/// D65 white as specified by Rec.709 / sRGB / Rec.2020 / Display P3: x 0.3127, y 0.3290.
pub const D65: Xy = [0.3127, 0.3290];
/// The ACES white (≈ D60) of SMPTE ST 2065-1 and ACEScg: x 0.32168, y 0.33767.
pub const ACES_WHITE: Xy = [0.32168, 0.33767];

/// An additive RGB space: red, green, blue primaries and white point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RgbSpace {
    /// Short name.
    pub name: &'static str,
    /// Red, green, blue primaries (xy).
    pub primaries: [Xy; 3],
    /// White point (xy): the chromaticity of RGB (1, 1, 1), which has luminance Y = 1.
    pub white: Xy,
}

/// ITU-R BT.709 / sRGB.
pub const REC709: RgbSpace = RgbSpace {
    name: "Rec.709",
    primaries: [[0.64, 0.33], [0.30, 0.60], [0.15, 0.06]],
    white: D65,
};
/// ACEScg (AP1 primaries, ACES white), S-2014-004.
pub const ACESCG: RgbSpace = RgbSpace {
    name: "ACEScg",
    primaries: [[0.713, 0.293], [0.165, 0.830], [0.128, 0.044]],
    white: ACES_WHITE,
};
/// ACES2065-1 (AP0 primaries, ACES white), SMPTE ST 2065-1.
pub const ACES2065_1: RgbSpace = RgbSpace {
    name: "ACES2065-1",
    primaries: [[0.7347, 0.2653], [0.0, 1.0], [0.0001, -0.0770]],
    white: ACES_WHITE,
};
/// ITU-R BT.2020.
pub const REC2020: RgbSpace = RgbSpace {
    name: "Rec.2020",
    primaries: [[0.708, 0.292], [0.170, 0.797], [0.131, 0.046]],
    white: D65,
};
/// Display P3 (DCI-P3 primaries, D65 white).
pub const DISPLAY_P3: RgbSpace = RgbSpace {
    name: "Display P3",
    primaries: [[0.680, 0.320], [0.265, 0.690], [0.150, 0.060]],
    white: D65,
};
/// The tonemapping space of Ghost of Tsushima (Patry 2021): ACEScg with the red primary's x
/// moved from 0.713 to 0.75, so per-channel tonemapping bends reds less toward yellow.
pub const TONEMAP: RgbSpace = RgbSpace {
    name: "Tonemap",
    primaries: [[0.75, 0.293], [0.165, 0.830], [0.128, 0.044]],
    white: ACES_WHITE,
};
/// The LMS Rayleigh space of Ghost of Tsushima (Patry 2021): spectral primaries chosen to make
/// Rayleigh transmittance match spectral rendering, with the D65 white of Rec.709.
pub const LMS_RAYLEIGH: RgbSpace = RgbSpace {
    name: "LMS Rayleigh",
    primaries: [[0.6501, 0.3495], [0.1711, 0.7959], [0.1520, 0.0218]],
    white: D65,
};

/// xy → XYZ with Y = 1.
pub fn xy_to_xyz(c: Xy) -> [f64; 3] {
    [c[0] / c[1], 1.0, (1.0 - c[0] - c[1]) / c[1]]
}

impl RgbSpace {
    /// Linear RGB → CIE XYZ (Y of white = 1). Columns are the primaries' XYZ scaled so that
    /// their sum is the white's XYZ.
    pub fn try_rgb_to_xyz(&self) -> Result<Mat3Rows, MathError> {
        for p in self.primaries.iter().chain([&self.white]) {
            if !(p[1] != 0.0 && p[0].is_finite() && p[1].is_finite()) {
                return Err(MathError::Singular {
                    context: "RGB to XYZ (primary or white with y = 0)",
                });
            }
        }
        let p = self.primaries.map(xy_to_xyz);
        let prim: Mat3Rows = [
            [p[0][0], p[1][0], p[2][0]],
            [p[0][1], p[1][1], p[2][1]],
            [p[0][2], p[1][2], p[2][2]],
        ];
        let inv = inv3(&prim).ok_or(MathError::Singular {
            context: "RGB to XYZ (collinear primaries)",
        })?;
        let s = super::mul3v(&inv, xy_to_xyz(self.white));
        Ok(mul3(
            &prim,
            &[[s[0], 0.0, 0.0], [0.0, s[1], 0.0], [0.0, 0.0, s[2]]],
        ))
    }

    /// Linear RGB → XYZ for the built-in spaces (which are never degenerate).
    pub fn rgb_to_xyz(&self) -> Mat3Rows {
        self.try_rgb_to_xyz().unwrap_or([[f64::NAN; 3]; 3])
    }

    /// XYZ → linear RGB.
    pub fn xyz_to_rgb(&self) -> Mat3Rows {
        inv3(&self.rgb_to_xyz()).unwrap_or([[f64::NAN; 3]; 3])
    }

    /// The white's XYZ (Y = 1).
    pub fn white_xyz(&self) -> [f64; 3] {
        xy_to_xyz(self.white)
    }
}

/// RGB in `src` → RGB in `dst`, via XYZ with Bradford adaptation from `src.white` to
/// `dst.white` when they differ, so RGB (1, 1, 1) maps to (1, 1, 1).
pub fn rgb_to_rgb(src: &RgbSpace, dst: &RgbSpace) -> Mat3Rows {
    let cat = super::adaptation::bradford_cat(src.white_xyz(), dst.white_xyz());
    mul3(&dst.xyz_to_rgb(), &mul3(&cat, &src.rgb_to_xyz()))
}
