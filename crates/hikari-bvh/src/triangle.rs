//! Watertight ray-triangle intersection (Woop, Benthin, Wald 2013) and the per-ray constants it
//! and the box test share.
//!
//! The paper re-evaluates an edge function in double precision when it rounds to exactly zero.
//! WGSL has no portable f64, and this crate's traversal is the twin of the kernel, so both skip
//! that step: a zero edge function counts as inside for both neighbouring triangles. A ray through
//! a shared edge may then report either triangle, but it can never slip between them.

use crate::layout::{Ray, TriangleRecord};

/// Ray constants computed once per ray (and once per instance, in object space).
#[derive(Clone, Copy, Debug)]
pub struct PreparedRay {
    pub origin: [f32; 3],
    pub dir: [f32; 3],
    /// Reciprocal direction with zero components replaced by a tiny signed value, so the box
    /// test never computes `0 * inf`.
    pub inv_dir: [f32; 3],
    /// Bit a set if the direction along axis a is negative.
    pub octant: u32,
    /// Axis permutation: `k[2]` is the dominant axis of the direction.
    pub k: [usize; 3],
    /// Shear constants `dir[kx]/dir[kz]`, `dir[ky]/dir[kz]`, `1/dir[kz]`.
    pub shear: [f32; 3],
    pub t_min: f32,
}

const MIN_DIR: f32 = 1e-30;

impl PreparedRay {
    pub fn new(ray: &Ray) -> Self {
        let d = ray.dir;
        let mut inv_dir = [0.0; 3];
        let mut octant = 0;
        for a in 0..3 {
            let safe = if d[a].abs() < MIN_DIR {
                MIN_DIR.copysign(d[a])
            } else {
                d[a]
            };
            inv_dir[a] = 1.0 / safe;
            if safe.is_sign_negative() {
                octant |= 1 << a;
            }
        }
        let ad = [d[0].abs(), d[1].abs(), d[2].abs()];
        let kz = if ad[0] >= ad[1] && ad[0] >= ad[2] {
            0
        } else if ad[1] >= ad[2] {
            1
        } else {
            2
        };
        let mut kx = (kz + 1) % 3;
        let mut ky = (kx + 1) % 3;
        // Swapping keeps the winding of the projected triangle when the ray looks down -kz,
        // so the sign convention of U, V, W does not depend on the ray.
        if d[kz] < 0.0 {
            std::mem::swap(&mut kx, &mut ky);
        }
        let shear = [d[kx] / d[kz], d[ky] / d[kz], 1.0 / d[kz]];
        Self {
            origin: ray.origin,
            dir: d,
            inv_dir,
            octant,
            k: [kx, ky, kz],
            shear,
            t_min: ray.t_min,
        }
    }
}

/// Intersects one triangle; returns `(t, u, v)` for a hit with `t_min < t < t_max`, where
/// `u`, `v` are the weights of `v1` and `v2`.
#[inline]
pub fn intersect(
    r: &PreparedRay,
    v0: [f32; 3],
    v1: [f32; 3],
    v2: [f32; 3],
    t_max: f32,
) -> Option<(f32, f32, f32)> {
    let [kx, ky, kz] = r.k;
    let [sx, sy, sz] = r.shear;
    let o = r.origin;
    let a = [v0[0] - o[0], v0[1] - o[1], v0[2] - o[2]];
    let b = [v1[0] - o[0], v1[1] - o[1], v1[2] - o[2]];
    let c = [v2[0] - o[0], v2[1] - o[1], v2[2] - o[2]];
    let ax = a[kx] - sx * a[kz];
    let ay = a[ky] - sy * a[kz];
    let bx = b[kx] - sx * b[kz];
    let by = b[ky] - sy * b[kz];
    let cx = c[kx] - sx * c[kz];
    let cy = c[ky] - sy * c[kz];
    let eu = cx * by - cy * bx;
    let ev = ax * cy - ay * cx;
    let ew = bx * ay - by * ax;
    if (eu < 0.0 || ev < 0.0 || ew < 0.0) && (eu > 0.0 || ev > 0.0 || ew > 0.0) {
        return None;
    }
    let det = eu + ev + ew;
    if det == 0.0 {
        return None;
    }
    let t_scaled = eu * (sz * a[kz]) + ev * (sz * b[kz]) + ew * (sz * c[kz]);
    let inv_det = 1.0 / det;
    let t = t_scaled * inv_det;
    // Written so that NaN fails the test.
    if t > r.t_min && t < t_max {
        Some((t, ev * inv_det, ew * inv_det))
    } else {
        None
    }
}

#[inline]
pub fn intersect_record(
    r: &PreparedRay,
    tri: &TriangleRecord,
    t_max: f32,
) -> Option<(f32, f32, f32)> {
    intersect(r, tri.v0, tri.v1, tri.v2, t_max)
}

/// True if the triangle has zero area, or an area f32 cannot represent: the intersection test
/// forms the same kind of products, so such a triangle could never be hit anyway.
pub fn is_degenerate(v0: glam::Vec3A, v1: glam::Vec3A, v2: glam::Vec3A) -> bool {
    // Components, not the squared length, which would underflow for triangles the
    // intersection test still handles.
    let n = (v1 - v0).cross(v2 - v0);
    n == glam::Vec3A::ZERO || !n.is_finite()
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    #[test]
    fn hit_and_barycentrics() {
        let ray = Ray::new(Vec3::new(0.25, 0.25, -1.0), Vec3::Z, 0.0, 10.0);
        let r = PreparedRay::new(&ray);
        let (t, u, v) =
            intersect(&r, [0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], 10.0).expect("hit");
        assert!((t - 1.0).abs() < 1e-6);
        assert!((u - 0.25).abs() < 1e-6 && (v - 0.25).abs() < 1e-6);
        // Both windings hit (no back-face culling).
        assert!(intersect(&r, [0.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0], 10.0).is_some());
        // t_max excludes.
        assert!(intersect(&r, [0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], 0.5).is_none());
    }

    #[test]
    fn shared_edge_is_watertight() {
        // Two triangles sharing the diagonal of a unit square; rays exactly through the diagonal
        // must hit at least one of them.
        let p = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
        ];
        for i in 0..=64 {
            let s = i as f32 / 64.0;
            for dir in [
                Vec3::Z,
                Vec3::new(0.3, -0.2, 1.0),
                Vec3::new(-0.7, 0.1, -0.4),
            ] {
                let hit_point = Vec3::new(s, s, 0.0);
                let ray = Ray::new(hit_point - dir * 3.0, dir, 0.0, 100.0);
                let r = PreparedRay::new(&ray);
                let a = intersect(&r, p[0], p[1], p[2], 100.0);
                let b = intersect(&r, p[0], p[2], p[3], 100.0);
                assert!(a.is_some() || b.is_some(), "leak at s={s} dir={dir}");
            }
        }
    }
}
