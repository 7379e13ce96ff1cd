//! CPU twin of `hikari::view`'s reprojection (`shaders/common/view.wgsl`): the bilinear taps
//! of last frame's texels about a reprojected position, which every temporal pass shares.

use glam::Vec2;

/// The smallest summed weight of the valid bilinear taps that a reprojected history needs
/// (`REPROJECTION_MIN_WEIGHT` of `hikari::view`).
pub const REPROJECTION_MIN_WEIGHT: f32 = 0.01;
/// A bilinear fraction within this of 0 or 1 snaps to it (`REPROJECTION_SNAP`): a still
/// camera's motion vectors carry rounding.
pub const REPROJECTION_SNAP: f32 = 1.0 / 64.0;

/// The bilinear taps about `prev`, a position in last frame's pixels (`hikari::view`'s
/// `reprojection` and `bilinear_weight`): texel and weight of each of the 2x2, fractions within
/// [`REPROJECTION_SNAP`] of 0 or 1 snapped. Taps may lie off the image; the caller skips them.
pub fn bilinear_taps(prev: Vec2) -> [([i64; 2], f32); 4] {
    let base = (prev - 0.5).floor();
    let snap = |f: f32| {
        if (f - f.round()).abs() < REPROJECTION_SNAP {
            f.round()
        } else {
            f
        }
    };
    let f = prev - 0.5 - base;
    let frac = Vec2::new(snap(f.x), snap(f.y));
    std::array::from_fn(|k| {
        let wx = if k & 1 != 0 { frac.x } else { 1.0 - frac.x };
        let wy = if k & 2 != 0 { frac.y } else { 1.0 - frac.y };
        let t = [
            base.x as i64 + (k & 1) as i64,
            base.y as i64 + (k >> 1) as i64,
        ];
        (t, wx * wy)
    })
}
