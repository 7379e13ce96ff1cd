//! Instance culling before the TLAS rebuild: logical visibility, an expanded frustum, and
//! contribution (projected size) culling, as in Metro Exodus' RT module.
//!
//! The frustum is expanded by `margin` metres on every side because rays leave the view: with
//! normalized planes, any point within `margin` of a point inside the frustum lies inside the
//! expanded frustum, so a ray that starts inside the view frustum and travels at most `margin`
//! can only hit instances that survive.

use crate::aabb::Aabb;
use crate::blas::Blas;
use crate::tlas::Instance;
use glam::{Mat4, Vec3, Vec3A, Vec4};

/// Six planes `n . p + d >= 0` inside, with unit normals.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frustum {
    pub planes: [Vec4; 6],
}

impl Frustum {
    /// Planes of a view-projection matrix with clip depth in `[0, w]` (wgpu, D3D, Metal).
    pub fn from_view_proj(m: &Mat4) -> Frustum {
        let r0 = m.row(0);
        let r1 = m.row(1);
        let r2 = m.row(2);
        let r3 = m.row(3);
        let raw = [r3 + r0, r3 - r0, r3 + r1, r3 - r1, r2, r3 - r2];
        Frustum {
            planes: raw.map(|p| {
                let len = p.truncate().length();
                if len > 0.0 && len.is_finite() {
                    p / len
                } else {
                    p
                }
            }),
        }
    }

    /// The same frustum with every plane pushed out by `margin`.
    pub fn expanded(&self, margin: f32) -> Frustum {
        Frustum {
            planes: self
                .planes
                .map(|p| Vec4::new(p.x, p.y, p.z, p.w + margin.max(0.0))),
        }
    }

    pub fn contains_point(&self, p: Vec3) -> bool {
        self.planes
            .iter()
            .all(|pl| pl.truncate().dot(p) + pl.w >= 0.0)
    }

    /// Conservative: false only if the box lies entirely outside one plane.
    pub fn intersects_aabb(&self, b: &Aabb) -> bool {
        self.planes.iter().all(|pl| {
            let n = Vec3A::from_vec4(*pl);
            // The corner furthest along the normal.
            let p = Vec3A::select(n.cmpge(Vec3A::ZERO), b.max, b.min);
            n.dot(p) + pl.w >= 0.0
        })
    }
}

#[derive(Clone, Copy, Debug)]
pub struct CullSettings {
    /// Metres added on every side of the view frustum; set it to the longest ray that matters
    /// (e.g. the GI ray length).
    pub margin: f32,
    /// Contribution culling: an instance whose bounding-sphere radius divided by its distance
    /// from the camera is below this is dropped (0 disables). 0.01 is about 0.6 degrees.
    pub min_angular_size: f32,
    /// Instances closer than this (box distance, metres) are never contribution-culled.
    pub contribution_min_distance: f32,
}

impl Default for CullSettings {
    fn default() -> Self {
        Self {
            margin: 10.0,
            min_angular_size: 0.0,
            contribution_min_distance: 0.0,
        }
    }
}

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct CullStats {
    pub total: usize,
    pub hidden: usize,
    pub outside_frustum: usize,
    pub too_small: usize,
    /// Instances with a bad BLAS index or non-finite bounds (left for the TLAS build to report).
    pub invalid: usize,
    pub survived: usize,
}

/// Indices of the instances that should enter this frame's TLAS.
pub fn cull_instances(
    instances: &[Instance],
    blases: &[Blas],
    camera: Vec3,
    frustum: &Frustum,
    settings: &CullSettings,
) -> (Vec<u32>, CullStats) {
    let expanded = frustum.expanded(settings.margin);
    let cam = Vec3A::from(camera);
    let mut stats = CullStats {
        total: instances.len(),
        ..Default::default()
    };
    let mut out = Vec::with_capacity(instances.len());
    for (i, inst) in instances.iter().enumerate() {
        if !inst.visible {
            stats.hidden += 1;
            continue;
        }
        let b = inst.world_bounds(blases);
        if b.is_empty() || !b.is_finite() {
            stats.invalid += 1;
            continue;
        }
        if !expanded.intersects_aabb(&b) {
            stats.outside_frustum += 1;
            continue;
        }
        if settings.min_angular_size > 0.0 {
            let radius = 0.5 * (b.max - b.min).length();
            let nearest = cam.clamp(b.min, b.max);
            let dist = (nearest - cam).length();
            if dist > settings.contribution_min_distance
                && radius < settings.min_angular_size * dist
            {
                stats.too_small += 1;
                continue;
            }
        }
        out.push(i as u32);
    }
    stats.survived = out.len();
    (out, stats)
}
