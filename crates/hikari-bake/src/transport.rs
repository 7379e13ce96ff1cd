//! One probe's baked light transport under a uniform white sky of radiance 1: its sky
//! visibility (mono L2 SH) and its bounced sky visibility (RGB L2 SH), from one set of
//! closest-hit rays.
//!
//! For probe ray direction `ω_k` (Fibonacci sphere, `4π/n` sr each):
//! - the ray escapes: the probe sees the sky, `V += 4π/n · Y(ω_k)`;
//! - it hits a surface at `x` with albedo `ρ(x)`, facing the probe: that surface, Lambertian
//!   and lit by the unit sky through its own visibility, sends radiance
//!   `L(x) = ρ/π · ∫ V_x(ω') cos θ' dω' = ρ · f(x)`, where `f(x)` is the cosine-weighted
//!   fraction of its hemisphere that sees the sky, estimated by `m` cosine-distributed any-hit
//!   rays: `f ≈ escaped / m`. Then `B += 4π/n · Y(ω_k) · ρ · f`.
//!
//! That is one bounce: the light the hit point receives from other surfaces is left out (it
//! would add about `ρ²` of the first bounce; the talk bakes the first bounce only).
//! Secondary directions are stratified in the cosine-warped unit square and rotated per hit by
//! a hash of (probe seed, ray), so neighbouring hits do not share their sampling pattern.

use glam::{Vec2, Vec3};
use hikari_bvh::TraversalStacks;
use hikari_math::sampling::rng::mix;
use hikari_math::sampling::sphere::cosine_hemisphere;
use rayon::prelude::*;

use crate::error::BakeError;
use crate::scene_rays::SceneRays;
use crate::sky_visibility::{RAY_T_MIN, SphereRays};
use crate::surfaces::SurfaceAlbedo;

/// Metres a secondary ray starts off its surface (along the normal), clear of the surface it
/// leaves at the village's scale (1 m terrain cells, 12 cm walls); plus
/// [`SURFACE_OFFSET_PER_METRE`] times the hit triangle's largest coordinate, because the
/// traversal's f32 intersection loses about that much near large triangles (a 100 km test
/// plane needs 4 cm).
pub const SURFACE_OFFSET: f32 = 2e-3;
pub const SURFACE_OFFSET_PER_METRE: f32 = 4e-7;

/// A probe's baked transport and what it cost.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ProbeTransport {
    /// Mono L2 SH of the sky visibility.
    pub sky_visibility: [f32; 9],
    /// RGB L2 SH of the bounced sky visibility (radiance relative to the sky's).
    pub bounced: [[f32; 3]; 9],
    /// Fraction of probe rays that met a surface closer than the `enclosure_radius` given.
    pub enclosed_fraction: f32,
    /// Rays traced: probe rays plus secondary rays.
    pub rays: u64,
}

/// The rotation of the secondary-ray pattern at probe ray `k` of the probe with `seed`: a
/// point of the unit square (each coordinate a multiple of 2^-24, so exact in f32).
pub fn bounce_shift(seed: u64, k: usize) -> Vec2 {
    let h = mix(seed ^ mix(k as u64));
    Vec2::new(
        (h >> 40) as f32 / (1u64 << 24) as f32,
        (h & 0xff_ffff) as f32 / (1u64 << 24) as f32,
    )
}

/// [`bounce_shift`] of every ray of every probe, probe-major (`n` rays a probe), on all
/// cores: what a GPU twin uploads, having no 64-bit integers to hash with.
pub fn bounce_shifts(probes: &[ProbeRequest], n: usize) -> Vec<[f32; 2]> {
    probes
        .par_iter()
        .flat_map_iter(|r| (0..n).map(move |k| bounce_shift(r.seed, k).to_array()))
        .collect()
}

/// Secondary sample `j` of `m` in the unit square, rotated by `shift`: a Cranley–Patterson
/// rotation of a stratified pattern, strata along the disk's radius (cosine-weighted
/// elevation), a golden-ratio sequence in azimuth. The GPU twin (hikari-render's
/// `probe_bake_gpu/bounce_rays.wgsl`) repeats these f32 operations in this order.
pub fn bounce_sample(j: u32, m: u32, shift: Vec2) -> Vec2 {
    let u = Vec2::new((j as f32 + 0.5) / m as f32, (j as f32 * 0.618_034) % 1.0) + shift;
    Vec2::new(u.x.fract(), u.y.fract())
}

/// Where a probe is and what decorrelates its secondary rays from other probes'.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ProbeRequest {
    /// World position, metres.
    pub position: Vec3,
    pub seed: u64,
}

/// What every transport tracer is given besides the scene: the probe rays, the secondary rays
/// per hit and the enclosure radius (metres).
#[derive(Clone, Debug)]
pub struct TransportSettings {
    pub sphere: SphereRays,
    pub bounce_rays: u32,
    pub enclosure_radius: f32,
}

/// The ray work of the bake: the transport of a batch of probes. The bake calls it once per
/// batch (a few hundred probes) from one thread; placement stays on the CPU.
/// [`CpuTransport`] is the reference; hikari-render's `probe_bake_gpu` traces the same rays on
/// the GPU, and agrees with it within f32 summation order (its tests say how closely).
pub trait TransportTracer {
    /// "cpu" or "gpu", for reports.
    fn name(&self) -> &str;
    /// The rays it traces; the bake refuses a tracer built for other options.
    fn settings(&self) -> &TransportSettings;
    /// The scene's BVH, when the tracer built one the bake may reuse for probe placement.
    fn scene_rays(&self) -> Option<&SceneRays> {
        None
    }
    /// Probes per call the tracer works best with; the bake takes the smaller of this and
    /// its progress batch. 256 keeps the CPU's progress reports frequent.
    fn batch_size(&self) -> usize {
        256
    }
    /// Each probe's transport, in the order of `probes`.
    fn trace(&self, probes: &[ProbeRequest]) -> Result<Vec<ProbeTransport>, BakeError>;
}

/// [`probe_transport`] on all cores (rayon), probe by probe.
pub struct CpuTransport<'a> {
    pub scene: &'a SceneRays,
    pub albedo: &'a SurfaceAlbedo,
    pub settings: &'a TransportSettings,
}

impl TransportTracer for CpuTransport<'_> {
    fn name(&self) -> &str {
        "cpu"
    }

    fn settings(&self) -> &TransportSettings {
        self.settings
    }

    fn scene_rays(&self) -> Option<&SceneRays> {
        Some(self.scene)
    }

    fn trace(&self, probes: &[ProbeRequest]) -> Result<Vec<ProbeTransport>, BakeError> {
        Ok(probes
            .par_iter()
            .map_init(TraversalStacks::default, |stacks, p| {
                probe_transport(
                    self.scene,
                    self.albedo,
                    &self.settings.sphere,
                    self.settings.bounce_rays,
                    p.position,
                    p.seed,
                    self.settings.enclosure_radius,
                    stacks,
                )
            })
            .collect())
    }
}

/// Traces `rays` from `position`, and `bounce_rays` secondary rays from each surface they hit.
/// `seed` decorrelates the secondary rays between probes. `enclosure_radius` (metres) sets
/// what counts as a near hit for [`ProbeTransport::enclosed_fraction`].
#[allow(clippy::too_many_arguments)]
pub fn probe_transport(
    scene: &SceneRays,
    albedo: &SurfaceAlbedo,
    rays: &SphereRays,
    bounce_rays: u32,
    position: Vec3,
    seed: u64,
    enclosure_radius: f32,
    stacks: &mut TraversalStacks,
) -> ProbeTransport {
    let mut sky = [0.0f64; 9];
    let mut bounced = [[0.0f64; 3]; 9];
    let mut traced = 0u64;
    let mut near = 0usize;
    for (k, (d, w)) in rays.directions.iter().zip(&rays.weights).enumerate() {
        traced += 1;
        let Some(hit) = scene.closest(position, *d, RAY_T_MIN, stacks) else {
            for (s, w) in sky.iter_mut().zip(w) {
                *s += w;
            }
            continue;
        };
        if hit.t < enclosure_radius {
            near += 1;
        }
        if bounce_rays == 0 {
            continue;
        }
        let normal = if hit.back_face {
            if !albedo.double_sided(&hit) {
                continue;
            }
            -hit.normal
        } else {
            hit.normal
        };
        let rho = albedo.albedo(&hit);
        if rho == Vec3::ZERO {
            continue;
        }
        let Some((on_surface, scale)) = scene.hit_point(&hit) else {
            continue;
        };
        let x = on_surface + normal * (SURFACE_OFFSET + SURFACE_OFFSET_PER_METRE * scale);
        let (t1, t2) = normal.any_orthonormal_pair();
        let shift = bounce_shift(seed, k);
        let mut escaped = 0u32;
        for j in 0..bounce_rays {
            let local = cosine_hemisphere(bounce_sample(j, bounce_rays, shift));
            let dir = (t1 * local.x + t2 * local.y + normal * local.z).normalize();
            traced += 1;
            if !scene.occluded(x, dir, RAY_T_MIN, stacks) {
                escaped += 1;
            }
        }
        let radiance = rho * (escaped as f32 / bounce_rays as f32);
        for (b, w) in bounced.iter_mut().zip(w) {
            for c in 0..3 {
                b[c] += w * f64::from(radiance[c]);
            }
        }
    }
    ProbeTransport {
        sky_visibility: sky.map(|c| c as f32),
        bounced: bounced.map(|b| b.map(|c| c as f32)),
        enclosed_fraction: near as f32 / rays.len().max(1) as f32,
        rays: traced,
    }
}
