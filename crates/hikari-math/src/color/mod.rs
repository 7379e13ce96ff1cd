//! Colour science: RGB spaces from primaries and white points, transfer functions, chromatic
//! adaptation, spectral data, the Smits reflectance basis, the Purkinje shift and the LMS
//! Rayleigh space of Ghost of Tsushima.
//!
//! Matrices are derived in `f64` from chromaticities (never typed in rounded) and returned as
//! arrays of rows, `m[row][col]`, acting on column vectors: `xyz = m · rgb`.

pub mod adaptation;
pub mod primaries;
pub mod purkinje;
pub mod rayleigh;
pub mod smits;
pub mod spectral;
#[rustfmt::skip]
pub mod spectral_data;
pub mod transfer;

/// The luminance weights of linear Rec.709 (ITU-R BT.709's Y row, as every renderer rounds it):
/// `Y = 0.2126 R + 0.7152 G + 0.0722 B`. The one place they are written; WGSL's is
/// `hikari::color::luminance`.
pub const REC709_LUMA: [f32; 3] = [0.2126, 0.7152, 0.0722];

/// The luminance of linear Rec.709 `c` ([`REC709_LUMA`]).
pub fn luminance(c: glam::Vec3) -> f32 {
    c.dot(glam::Vec3::from_array(REC709_LUMA))
}

/// A 3x3 matrix as rows, `m[row][col]`.
pub type Mat3Rows = [[f64; 3]; 3];

pub(crate) fn to_dmat3(m: &Mat3Rows) -> glam::DMat3 {
    glam::DMat3::from_cols_array_2d(m).transpose()
}

pub(crate) fn from_dmat3(m: glam::DMat3) -> Mat3Rows {
    m.transpose().to_cols_array_2d()
}

/// `a · b` for row-major 3x3 matrices.
pub fn mul3(a: &Mat3Rows, b: &Mat3Rows) -> Mat3Rows {
    from_dmat3(to_dmat3(a) * to_dmat3(b))
}

/// `m · v`.
pub fn mul3v(m: &Mat3Rows, v: [f64; 3]) -> [f64; 3] {
    (to_dmat3(m) * glam::DVec3::from_array(v)).to_array()
}

/// Inverse, or `None` when singular.
pub fn inv3(m: &Mat3Rows) -> Option<Mat3Rows> {
    let d = to_dmat3(m);
    let det = d.determinant();
    if !det.is_finite() || det.abs() < 1e-300 {
        return None;
    }
    Some(from_dmat3(d.inverse()))
}

/// `m` with every entry rounded to `f32`, for GPU uniforms.
pub fn to_f32(m: &Mat3Rows) -> [[f32; 3]; 3] {
    m.map(|r| r.map(|v| v as f32))
}
