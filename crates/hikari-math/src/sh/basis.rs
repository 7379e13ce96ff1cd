//! Evaluation of the real orthonormal SH basis (convention in [`crate::sh`]).

use glam::{DVec3, Vec3};

/// `1 / (2√π)`, band 0.
pub const C0: f64 = 0.282_094_791_773_878_14;
/// `√3 / (2√π)`, band 1.
pub const C1: f64 = 0.488_602_511_902_919_9;
/// `√15 / (2√π)`, band 2 terms `xy`, `yz`, `xz`.
pub const C2: f64 = 1.092_548_430_592_079_2;
/// `√5 / (4√π)`, band 2 term `3z² − 1`.
pub const C3: f64 = 0.315_391_565_252_520_05;
/// `√15 / (4√π)`, band 2 term `x² − y²`.
pub const C4: f64 = 0.546_274_215_296_039_6;

/// Band `l` of flat index `i`.
pub const fn band_of(i: usize) -> usize {
    match i {
        0 => 0,
        1..=3 => 1,
        _ => 2,
    }
}

/// The 9 basis functions at unit direction `d` (f32, as the GPU evaluates them).
pub fn eval_l2(d: Vec3) -> [f32; 9] {
    eval_l2_f64(d.as_dvec3()).map(|v| v as f32)
}

/// The first 4 basis functions at unit direction `d`.
pub fn eval_l1(d: Vec3) -> [f32; 4] {
    let y = eval_l2(d);
    [y[0], y[1], y[2], y[3]]
}

/// The 9 basis functions at unit direction `d`, in f64 (for quadrature and derived tables).
pub fn eval_l2_f64(d: DVec3) -> [f64; 9] {
    let (x, y, z) = (d.x, d.y, d.z);
    [
        C0,
        C1 * y,
        C1 * z,
        C1 * x,
        C2 * x * y,
        C2 * y * z,
        C3 * (3.0 * z * z - 1.0),
        C2 * x * z,
        C4 * (x * x - y * y),
    ]
}
