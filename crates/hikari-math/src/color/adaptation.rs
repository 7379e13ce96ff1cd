//! Von Kries chromatic adaptation in Bradford LMS space, and the white balance of
//! Ghost of Tsushima: the artist picks the colour that white should become.

use super::primaries::REC709;
use super::{Mat3Rows, inv3, mul3, mul3v};
use crate::MathError;

/// The Bradford XYZ → sharpened-LMS matrix (Lam 1985; its defining constants, not a derived
/// quantity).
pub const BRADFORD: Mat3Rows = [
    [0.8951, 0.2664, -0.1614],
    [-0.7502, 1.7135, 0.0367],
    [0.0389, -0.0685, 1.0296],
];

/// XYZ → XYZ von Kries adaptation in Bradford space taking `src_white` to `dst_white`
/// (both XYZ): `B⁻¹ · diag(B w_dst / B w_src) · B`. Identity if a cone response of
/// `src_white` is zero.
pub fn bradford_cat(src_white: [f64; 3], dst_white: [f64; 3]) -> Mat3Rows {
    let b_inv = inv3(&BRADFORD).unwrap_or([[f64::NAN; 3]; 3]);
    let s = mul3v(&BRADFORD, src_white);
    let d = mul3v(&BRADFORD, dst_white);
    if s.contains(&0.0) {
        return [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    }
    let g = [
        [d[0] / s[0], 0.0, 0.0],
        [0.0, d[1] / s[1], 0.0],
        [0.0, 0.0, d[2] / s[2]],
    ];
    mul3(&b_inv, &mul3(&g, &BRADFORD))
}

/// White balance as one linear Rec.709 matrix: Bradford adaptation from D65 to the white whose
/// linear Rec.709 colour is `target` (so `M · (1, 1, 1) = target` exactly, including its
/// brightness). Every component must be finite and > 0.
pub fn white_balance_rec709(target: [f64; 3]) -> Result<Mat3Rows, MathError> {
    for (index, &value) in target.iter().enumerate() {
        if !(value.is_finite() && value > 0.0) {
            return Err(MathError::InvalidWhite { index, value });
        }
    }
    let m = REC709.rgb_to_xyz();
    let m_inv = REC709.xyz_to_rgb();
    let src = mul3v(&m, [1.0, 1.0, 1.0]);
    let dst = mul3v(&m, target);
    Ok(mul3(&m_inv, &mul3(&bradford_cat(src, dst), &m)))
}
