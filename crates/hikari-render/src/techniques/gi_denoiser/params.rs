//! The constants a denoiser pass reads (`GiDenoiserParams`, mirrored in `common.wgsl`), built
//! from the settings, the view and the frame index, and the Poisson disks they carry.

use bytemuck::{Pod, Zeroable};
use glam::{Mat4, Vec2, Vec4};

use super::settings::GiDenoiserSettings;
use crate::error::{RenderError, Result};
use crate::view::View;

/// Most Poisson-disk points a pass can hold (the AO denoiser's 64).
pub const MAX_DISK_POINTS: usize = 64;
/// Most samples a GI pass takes (the talk: up to 32).
pub const GI_DISK_POINTS: usize = 32;
/// Largest step between the Poisson samples a GI pass takes: at least 4 of 32 are kept.
pub const MAX_STEP: u32 = 8;
/// `GiDenoiserParams::flags[2]`: the history is last frame's denoised output (the radius
/// caps then fall as 1 / history rather than 1 / sqrt(history)); bit 0 is the step falloff.
pub const FLAG_RECURRENT: u32 = 2;

/// Which GI pass a set of constants is for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GiPass {
    /// No normal weight, the wide radius.
    First,
    /// Normal weight on top of the geometry weight, the narrower radius.
    Second,
}

#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GiDenoiserParams {
    /// x: base radius in metres; y, z: smallest and largest radius in pixels; w: distance to
    /// the tangent plane where the geometry weight reaches 0, as a fraction of view depth.
    pub radius: [f32; 4],
    /// x, y: cos and sin of this frame's disk rotation; z: metres a pixel spans per metre of
    /// view depth; w: view depth in metres at which F(viewZ) = 1/2.
    pub rotation: [f32; 4],
    /// x: coefficient of variation at which F(variance) reaches 1; y: floor of F(variance) and
    /// F(AO); z: largest accumulation speed; w: unused.
    pub scales: [f32; 4],
    /// x: samples at most; y: 1 = normal weight; z: 1 = step geometry falloff; w: largest step.
    pub flags: [u32; 4],
    /// Poisson-disk points in the unit disk, two an entry (xy, zw).
    pub disk: [[f32; 4]; 32],
}

/// `count` Poisson-disk points in the unit disk, as widely spaced as dart throwing manages:
/// the spacing starts near the densest packing it can reach and shrinks until all fit.
pub fn poisson_points(count: usize, seed: u64) -> Result<Vec<Vec2>> {
    let mut min_dist = 1.5 / (count as f32).sqrt();
    while min_dist > 0.01 {
        let pts = hikari_math::sampling::poisson::poisson_disk(count, min_dist, seed)
            .map_err(|e| RenderError::Graph(format!("gi_denoiser: Poisson disk: {e}")))?;
        if pts.len() == count {
            return Ok(pts);
        }
        min_dist *= 0.95;
    }
    Err(RenderError::Graph(format!(
        "gi_denoiser: no Poisson disk of {count} points"
    )))
}

/// Metres one pixel spans at 1 m of view depth, at the image centre: the distance between two
/// vertically adjacent pixel centres on the near plane (reverse-Z depth 1), over the near
/// distance.
pub fn metres_per_pixel(view: &View) -> f32 {
    let inv = Mat4::from_cols_array_2d(&view.inv_view_proj);
    let unproject = |ndc_y: f32| {
        let p = inv * Vec4::new(0.0, ndc_y, 1.0, 1.0);
        p.truncate() / p.w
    };
    let step = 2.0 * view.viewport[3];
    (unproject(step) - unproject(0.0)).length() / view.forward_near[3]
}

/// This frame's disk rotation, one angle for every pixel: the golden-ratio sequence over
/// frames, so that consecutive frames' kernels interleave and the temporal accumulation sees
/// every direction.
pub fn rotation(frame_index: u64) -> Vec2 {
    let golden = 0.618_033_988_749_894_9_f64;
    let angle = (frame_index as f64 * golden).fract() * std::f64::consts::TAU;
    Vec2::new(angle.cos() as f32, angle.sin() as f32)
}

fn pack_disk(points: &[Vec2]) -> [[f32; 4]; 32] {
    let mut disk = [[0.0; 4]; 32];
    for (i, p) in points.iter().take(MAX_DISK_POINTS).enumerate() {
        disk[i / 2][(i % 2) * 2] = p.x;
        disk[i / 2][(i % 2) * 2 + 1] = p.y;
    }
    disk
}

fn common(
    s: &GiDenoiserSettings,
    view: &View,
    frame_index: u64,
    radius_m: f32,
    samples: u32,
    disk: &[Vec2],
) -> GiDenoiserParams {
    let r = rotation(frame_index);
    GiDenoiserParams {
        radius: [
            radius_m,
            s.min_radius_px.min(s.max_radius_px),
            s.max_radius_px,
            s.plane_tolerance,
        ],
        rotation: [r.x, r.y, metres_per_pixel(view), s.radius_half_distance_m],
        scales: [
            s.variance_reference,
            s.min_radius_scale,
            s.max_accumulation_speed,
            0.0,
        ],
        flags: [
            // The uniform holds MAX_DISK_POINTS; the shaders index it below flags[0].
            samples.min(disk.len().min(MAX_DISK_POINTS) as u32),
            0,
            u32::from(s.step_falloff) | if s.recurrent { FLAG_RECURRENT } else { 0 },
            MAX_STEP,
        ],
        disk: pack_disk(disk),
    }
}

impl GiDenoiserParams {
    /// Constants of a GI pass; `disk` holds the 32 Poisson points.
    pub fn gi_pass(
        s: &GiDenoiserSettings,
        view: &View,
        frame_index: u64,
        pass: GiPass,
        disk: &[Vec2],
    ) -> Self {
        let (radius, normal) = match pass {
            GiPass::First => (s.pass1_radius_m, 0),
            GiPass::Second => (s.pass2_radius_m, 1),
        };
        let mut p = common(s, view, frame_index, radius, s.samples, disk);
        // spatial.wgsl holds at most this many points in workgroup memory.
        p.flags[0] = p.flags[0].min(GI_DISK_POINTS as u32);
        p.flags[1] = normal;
        p.scales[3] = s.gi_hit_distance_scale;
        p
    }

    /// Constants of the AO denoiser; `disk` holds the 64 Poisson points.
    pub fn ao(s: &GiDenoiserSettings, view: &View, frame_index: u64, disk: &[Vec2]) -> Self {
        let mut p = common(s, view, frame_index, s.ao_radius_m, s.ao_samples, disk);
        p.scales[3] = s.ao_hit_distance_scale;
        p
    }

    /// Poisson point `i`, rotated by this frame's angle.
    pub fn disk_point(&self, i: u32) -> Vec2 {
        let e = self.disk[i as usize / 2];
        let p = if i.is_multiple_of(2) {
            Vec2::new(e[0], e[1])
        } else {
            Vec2::new(e[2], e[3])
        };
        let (c, s) = (self.rotation[0], self.rotation[1]);
        Vec2::new(c * p.x - s * p.y, s * p.x + c * p.y)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn disks_hold_every_point_inside_the_unit_disk_and_apart() {
        for count in [GI_DISK_POINTS, MAX_DISK_POINTS] {
            let pts = poisson_points(count, 7).unwrap();
            assert_eq!(pts.len(), count);
            assert!(pts.iter().all(|p| p.length() <= 1.0));
            // Dart throwing at this density keeps points at least ~0.5 / sqrt(n) apart.
            let closest = pts
                .iter()
                .enumerate()
                .flat_map(|(i, a)| pts[i + 1..].iter().map(move |b| a.distance(*b)))
                .fold(f32::MAX, f32::min);
            assert!(closest >= 0.5 / (count as f32).sqrt(), "{count}: {closest}");
        }
    }

    #[test]
    fn the_rotation_is_a_unit_rotation_that_changes_every_frame() {
        let angles: Vec<Vec2> = (0..64).map(rotation).collect();
        for (i, r) in angles.iter().enumerate() {
            assert!((r.length() - 1.0).abs() < 1e-6);
            if i > 0 {
                assert!(r.distance(angles[i - 1]) > 0.1, "frame {i}");
            }
        }
    }
}
