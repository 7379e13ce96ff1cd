//! The rays traced: issue 5's terrain rays, area-weighted surface rays of any scene, and
//! pinhole images; all from fixed seeds so every run traces the same rays.

use glam::Vec3;

use hikari_bvh::rng::SplitMix64;
use hikari_bvh::{Mesh, Ray};

/// Vertices per side of the issue-5 terrain (issue 3 defines it): 708 x 708 over
/// [-100, 100]^2, two triangles per cell.
pub(super) const TERRAIN_SIDE: usize = 708;
pub(super) const SEED: u64 = 0x5EED_0005;
/// Surface rays start this far off the surface.
const SURFACE_OFFSET: f32 = 0.01;

/// Where a scene's rays come from.
pub(super) enum RaySource {
    /// Issue 5's terrain: points over the height field, the camera.
    Terrain(Mesh),
    /// Area-weighted points on world-space triangles; coherent rays through `camera`.
    Surfaces {
        triangles: Vec<[Vec3; 3]>,
        /// Cumulative areas, for picking a triangle by area.
        cdf: Vec<f64>,
        camera: hikari_scene::Camera,
    },
}

impl RaySource {
    /// Workloads 1 and 2.
    pub(super) fn incoherent(&self, n: usize) -> Vec<Ray> {
        match self {
            RaySource::Terrain(mesh) => terrain_rays(mesh, n),
            RaySource::Surfaces { triangles, cdf, .. } => surface_rays(triangles, cdf, n),
        }
    }

    /// Workload 3: a `w` x `h` pinhole image.
    pub(super) fn coherent(&self, w: u32, h: u32) -> Vec<Ray> {
        match self {
            // The camera at (0, 40, -120) looking along normalize(0, -0.5, 1); the
            // image plane at distance 1 spans 0.8 horizontally and 0.4 vertically on each side.
            RaySource::Terrain(_) => pinhole_rays(
                Vec3::new(0.0, 40.0, -120.0),
                Vec3::new(0.0, -0.5, 1.0),
                Vec3::Y,
                0.4,
                w,
                h,
            ),
            RaySource::Surfaces { camera, .. } => pinhole_rays(
                camera.position,
                camera.target - camera.position,
                camera.up,
                (0.5 * camera.vfov_deg.to_radians()).tan(),
                w,
                h,
            ),
        }
    }
}

/// Height of the triangulated terrain (not the analytic formula, which the flat triangles
/// depart from by about a centimetre between vertices) at `x`, `z`.
fn mesh_height(mesh: &Mesh, x: f32, z: f32) -> f32 {
    let n = TERRAIN_SIDE;
    let cell = 200.0 / (n - 1) as f32;
    let fx = (x + 100.0) / cell;
    let fz = (z + 100.0) / cell;
    let i = (fx.floor() as usize).min(n - 2);
    let j = (fz.floor() as usize).min(n - 2);
    let (u, v) = (fx - i as f32, fz - j as f32);
    let y = |i: usize, j: usize| mesh.positions[j * n + i].y;
    // Mesh::terrain splits each cell into (a, c, b) and (b, c, d) with a = (i, j), b = (i+1, j),
    // c = (i, j+1), d = (i+1, j+1).
    if u + v <= 1.0 {
        y(i, j) + u * (y(i + 1, j) - y(i, j)) + v * (y(i, j + 1) - y(i, j))
    } else {
        y(i + 1, j + 1)
            + (1.0 - u) * (y(i, j + 1) - y(i + 1, j + 1))
            + (1.0 - v) * (y(i + 1, j) - y(i + 1, j + 1))
    }
}

/// A cosine-distributed direction around `n` (Malley's method) from two uniform numbers.
fn cosine_dir(n: Vec3, r1: f32, r2: f32) -> Vec3 {
    let r = r1.sqrt();
    let phi = std::f32::consts::TAU * r2;
    let (t, b) = n.any_orthonormal_pair();
    (t * (r * phi.cos()) + b * (r * phi.sin()) + n * (1.0 - r1).max(0.0).sqrt()).normalize()
}

/// Terrain workloads 1 and 2: uniformly random surface points with x, z in [-90, 90], 1 cm
/// above the surface, cosine-distributed directions around +y (Malley's method).
fn terrain_rays(mesh: &Mesh, n: usize) -> Vec<Ray> {
    let mut rng = SplitMix64::new(SEED);
    (0..n)
        .map(|_| {
            let x = rng.range(-90.0, 90.0);
            let z = rng.range(-90.0, 90.0);
            let y = mesh_height(mesh, x, z) + SURFACE_OFFSET;
            let r2 = rng.next_f32();
            let phi = std::f32::consts::TAU * rng.next_f32();
            let r = r2.sqrt();
            let d = Vec3::new(r * phi.cos(), (1.0 - r2).max(0.0).sqrt(), r * phi.sin()).normalize();
            Ray::new(Vec3::new(x, y, z), d, 0.0, f32::INFINITY)
        })
        .collect()
}

/// Scene workloads 1 and 2: points on world-space triangles picked by area, 1 cm off the front
/// face (counter-clockwise), cosine-distributed around its normal.
fn surface_rays(triangles: &[[Vec3; 3]], cdf: &[f64], n: usize) -> Vec<Ray> {
    let mut rng = SplitMix64::new(SEED);
    let total = *cdf.last().unwrap_or(&0.0);
    (0..n)
        .map(|_| {
            let pick = rng.next_f32() as f64 * total;
            let k = cdf.partition_point(|&c| c <= pick).min(triangles.len() - 1);
            let [a, b, c] = triangles[k];
            let (mut u, mut v) = (rng.next_f32(), rng.next_f32());
            if u + v > 1.0 {
                (u, v) = (1.0 - u, 1.0 - v);
            }
            let p = a + u * (b - a) + v * (c - a);
            let nrm = (b - a).cross(c - a).normalize();
            let d = cosine_dir(nrm, rng.next_f32(), rng.next_f32());
            Ray::new(p + nrm * SURFACE_OFFSET, d, 0.0, f32::INFINITY)
        })
        .collect()
}

/// A 2:1 image of about `n` pixels: 4096 x 2048 for the 8,388,608.
pub(super) fn coherent_size(n: usize) -> (u32, u32) {
    let h = ((n as f64 / 2.0).sqrt().floor() as u32).max(1);
    (2 * h, h)
}

/// Row-major rays of a `w` x `h` pinhole camera at `origin` looking along `forward`; the image
/// plane at distance 1 spans `half_height` above and below the axis and `half_height * w / h`
/// to each side.
fn pinhole_rays(
    origin: Vec3,
    forward: Vec3,
    up: Vec3,
    half_height: f32,
    w: u32,
    h: u32,
) -> Vec<Ray> {
    let forward = forward.normalize();
    let right = up.cross(forward).normalize();
    let up = forward.cross(right);
    let half_width = half_height * w as f32 / h as f32;
    let mut rays = Vec::with_capacity(w as usize * h as usize);
    for py in 0..h {
        let sy = (1.0 - 2.0 * (py as f32 + 0.5) / h as f32) * half_height;
        for px in 0..w {
            let sx = (2.0 * (px as f32 + 0.5) / w as f32 - 1.0) * half_width;
            let d = (forward + sx * right + sy * up).normalize();
            rays.push(Ray::new(origin, d, 0.0, f32::INFINITY));
        }
    }
    rays
}
