//! Cascaded shadow maps of the sun (or moon), rasterised in compute (`passes/raster.rs`) into
//! one u32 depth a texel, looked up with 3x3 bilinear PCF by the deferred lighting
//! (`shaders/sun_shadows/lookup.wgsl`; CPU twin [`crate::reference::sun_shadows`]).
//!
//! Stability under camera motion: each cascade is the bounding sphere of its slice of the view
//! frustum, whose radius depends only on the slice distances and the field of view (not on the
//! camera's orientation), and its centre is snapped to whole texels in light space, so texels
//! keep their place in the world as the camera turns and moves.
//!
//! The maps persist across frames; a cascade is redrawn only when its projection changes
//! ([`ShadowCache`]; `shadows.cache = false` redraws all every frame). The rasteriser's atomics
//! need a buffer; each redrawn cascade is then copied into a layer of an R32Uint texture array,
//! which the lookup gathers 2x2 texels at a time from (a quarter of the loads, and a texture
//! cache laid out for 2D neighbourhoods).
//!
//! Depth convention as the camera's: 1 nearest the sun, 0 farthest (the cleared value), over
//! the scene's extent along the sun direction, so every caster is inside the depth range.

use bytemuck::{Pod, Zeroable};
use glam::{Mat4, Vec3, Vec4};

use hikari_scene::Camera;

use super::raster::{MAX_VIEWS, RasterJob, RasterQueues, RasterTarget, Rasterizer};
use crate::context::GpuContext;
use crate::error::Result;
use crate::graph::{Buf, FrameGraph, Tex, TextureDesc};
use crate::pipeline::ComputePipeline;
use crate::scene_gpu::SceneInFrame;
use crate::settings::ShadowSettings;
use crate::shader::ShaderLibrary;

/// What the lookup needs; `cascades` of zero means no shadows (everything lit).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct ShadowParams {
    pub light_view_proj: [[[f32; 4]; 4]; MAX_VIEWS],
    /// Per cascade: world-space size of a texel in metres.
    pub texel_world: [f32; 4],
    /// Cascades, resolution, PCF tap spacing in texels, normal bias in texels.
    pub config: [f32; 4],
    /// Per cascade: depth bias in NDC depth units.
    pub depth_bias: [f32; 4],
}

/// One cascade: its projection and the size of its texels.
#[derive(Clone, Copy, Debug)]
pub struct Cascade {
    pub view_proj: Mat4,
    pub texel_world: f32,
    /// Camera distance where the cascade's slice ends.
    pub far: f32,
    /// Radius of the cascade's bounding sphere, metres.
    pub radius: f32,
}

/// Unit light-space axes: x and y across the map, z towards the sun.
pub fn light_basis(to_sun: Vec3) -> (Vec3, Vec3, Vec3) {
    let z = to_sun.normalize();
    let helper = if z.y.abs() < 0.99 { Vec3::Y } else { Vec3::X };
    let x = helper.cross(z).normalize();
    (x, z.cross(x), z)
}

/// Camera distances of the cascade boundaries, from `near` to `far`: a blend of logarithmic
/// and uniform splits (Zhang et al. 2006, "parallel-split shadow maps").
pub fn split_distances(near: f32, far: f32, cascades: u32, lambda: f32) -> Vec<f32> {
    (0..=cascades)
        .map(|i| {
            let f = i as f32 / cascades as f32;
            let log = near * (far / near).powf(f);
            let uniform = near + (far - near) * f;
            lambda * log + (1.0 - lambda) * uniform
        })
        .collect()
}

/// Centre distance along the view axis and radius of the smallest sphere holding the frustum
/// slice between `dn` and `df`, for a frustum whose corner rays make `k = tan^2` of the half
/// diagonal angle with the axis.
pub fn slice_sphere(dn: f32, df: f32, k: f32) -> (f32, f32) {
    let z = 0.5 * (dn + df) * (1.0 + k);
    if z >= df {
        (df, df * k.sqrt())
    } else {
        (z, ((z - dn) * (z - dn) + dn * dn * k).sqrt())
    }
}

pub fn fit_cascades(
    camera: &Camera,
    aspect: f32,
    to_sun: Vec3,
    scene_bounds: (Vec3, Vec3),
    s: &ShadowSettings,
) -> Vec<Cascade> {
    let (lx, ly, lz) = light_basis(to_sun);
    let (lo, hi) = scene_bounds;
    let (mut zmin, mut zmax) = (f32::INFINITY, f32::NEG_INFINITY);
    for i in 0..8 {
        let c = Vec3::new(
            if i & 1 == 0 { lo.x } else { hi.x },
            if i & 2 == 0 { lo.y } else { hi.y },
            if i & 4 == 0 { lo.z } else { hi.z },
        );
        zmin = zmin.min(c.dot(lz));
        zmax = zmax.max(c.dot(lz));
    }
    // A margin so surfaces on the bounds do not sit exactly on depth 0 or 1.
    zmin -= 1.0;
    zmax += 1.0;
    let tan_half_v = (camera.vfov_deg.to_radians() * 0.5).tan();
    let k = tan_half_v * tan_half_v * (1.0 + aspect * aspect);
    let near = camera.near.max(0.01);
    let splits = split_distances(
        near,
        s.max_distance_m.max(near * 2.0),
        s.cascades,
        s.split_lambda,
    );
    let forward = camera.forward();
    let res = s.resolution as f32;
    splits
        .windows(2)
        .map(|w| {
            let (centre_d, radius) = slice_sphere(w[0], w[1], k);
            let centre = camera.position + forward * centre_d;
            let texel = 2.0 * radius / res;
            let snap = |v: f32| (v / texel).floor() * texel;
            let (cx, cy) = (snap(centre.dot(lx)), snap(centre.dot(ly)));
            let depth = zmax - zmin;
            // Rows: x_ndc = (p.lx - cx) / r, y_ndc = (p.ly - cy) / r, depth = (p.lz - zmin) / depth.
            let rows = [
                (lx / radius).extend(-cx / radius),
                (ly / radius).extend(-cy / radius),
                (lz / depth).extend(-zmin / depth),
                Vec4::new(0.0, 0.0, 0.0, 1.0),
            ];
            Cascade {
                view_proj: Mat4::from_cols(rows[0], rows[1], rows[2], rows[3]).transpose(),
                texel_world: texel,
                far: w[1],
                radius,
            }
        })
        .collect()
}

impl ShadowParams {
    pub fn disabled() -> Self {
        Self::zeroed()
    }

    pub fn new(cascades: &[Cascade], depth_range: f32, s: &ShadowSettings) -> Self {
        let mut p = Self::zeroed();
        for (i, c) in cascades.iter().enumerate() {
            p.light_view_proj[i] = c.view_proj.to_cols_array_2d();
            p.texel_world[i] = c.texel_world;
            p.depth_bias[i] = s.depth_bias_texels * c.texel_world / depth_range;
        }
        p.config = [
            cascades.len() as f32,
            s.resolution as f32,
            s.filter_radius_texels,
            s.normal_bias_texels,
        ];
        p
    }
}

/// The shadow maps of a frame.
#[derive(Clone, Copy, Debug)]
pub struct SunShadowMaps {
    /// `cascades * resolution^2` u32 depth bits, cascade-major: what the rasteriser draws.
    pub texels: Buf,
    /// The same depth bits as an R32Uint 2D array, a layer a cascade (at least two layers,
    /// so that its view is an array), for the lookup.
    pub map: Tex,
    pub params: ShadowParams,
}

pub const MAP_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Uint;

fn map_desc(resolution: u32, cascades: u32) -> TextureDesc {
    TextureDesc {
        size: [resolution, resolution, cascades.max(2)],
        ..TextureDesc::d2(resolution, resolution, MAP_FORMAT)
    }
}

/// Extent of the scene bounds along `to_sun` (with the fit's margin), for depth biases.
pub fn depth_range(to_sun: Vec3, (lo, hi): (Vec3, Vec3)) -> f32 {
    let z = to_sun.normalize();
    (hi - lo).abs().dot(z.abs()) + 2.0
}

/// The cascades drawn in earlier frames, so that unchanged ones are not drawn again.
#[derive(Clone, Debug, Default)]
pub struct ShadowCache {
    /// The cascade each slice of the persistent maps holds, as it was drawn.
    drawn: Vec<Option<Cascade>>,
}

/// How far a cascade drawn as `held` lies from where `want` puts it, in cascade radii; infinite
/// when they differ in more than their centre (sun direction, size or depth range).
fn drift(held: &Cascade, want: &Cascade) -> f32 {
    let (h, w) = (held.view_proj, want.view_proj);
    let same_shape = h.x_axis == w.x_axis
        && h.y_axis == w.y_axis
        && h.z_axis == w.z_axis
        && h.w_axis.z == w.w_axis.z;
    if !same_shape {
        return f32::INFINITY;
    }
    // x and y of NDC span the cascade's diameter: a radius is one unit.
    (h.w_axis.truncate().truncate() - w.w_axis.truncate().truncate()).length()
}

/// A cascade that has drifted this far (in radii) is redrawn whatever the per-frame limit, so
/// that the held cascades keep covering nearly all of their slices.
pub const MAX_DRIFT: f32 = 0.1;

impl ShadowCache {
    /// Slices to draw this frame. All of them when the maps are new or caching is off; else
    /// those that moved, at most `per_frame` of them (the farthest drifted first) unless they
    /// are new, changed shape or drifted beyond [`MAX_DRIFT`].
    fn update(&mut self, cascades: &[Cascade], fresh: bool, s: &ShadowSettings) -> Vec<u32> {
        if fresh || !s.cache || self.drawn.len() != cascades.len() {
            self.drawn = vec![None; cascades.len()];
        }
        let mut must = Vec::new();
        let mut may = Vec::new();
        for (i, (held, want)) in self.drawn.iter().zip(cascades).enumerate() {
            match held.as_ref().map(|h| drift(h, want)) {
                None => must.push(i),
                Some(d) if d > MAX_DRIFT => must.push(i),
                Some(d) if d > 0.0 => may.push((d, i)),
                Some(_) => {}
            }
        }
        may.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
        let room = (s.cascades_per_frame as usize).saturating_sub(must.len());
        must.extend(may.iter().take(room).map(|&(_, i)| i));
        must.sort_unstable();
        for &i in &must {
            self.drawn[i] = Some(cascades[i]);
        }
        must.into_iter().map(|i| i as u32).collect()
    }

    /// What the maps hold after this frame's update.
    fn held(&self) -> Vec<Cascade> {
        self.drawn.iter().flatten().copied().collect()
    }
}

#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
struct CopyParams {
    layers: [u32; 4],
    config: [u32; 4],
}

/// The technique's pipelines (the drawing itself is the shared rasteriser's).
pub struct SunShadows {
    copy: ComputePipeline,
}

impl SunShadows {
    pub fn new(ctx: &GpuContext, lib: &mut ShaderLibrary) -> Result<Self> {
        Ok(Self {
            copy: ComputePipeline::new(ctx, lib, "sun_shadows/copy.wgsl", "main", &[])?,
        })
    }

    #[allow(clippy::too_many_arguments)]
    pub fn record<'r>(
        &'r self,
        g: &mut FrameGraph<'r>,
        raster: &'r Rasterizer,
        scene: &SceneInFrame,
        cache: &mut ShadowCache,
        camera: &Camera,
        aspect: f32,
        to_sun: Vec3,
        s: &ShadowSettings,
        queues: &mut RasterQueues,
    ) -> Result<SunShadowMaps> {
        let bounds = match scene.bounds {
            Some(b) if s.enabled && to_sun.length_squared() > 0.0 => b,
            _ => {
                *cache = ShadowCache::default();
                let texels = g.buffer("sun_shadows.texels", 16)?;
                let map = g.texture("sun_shadows.map", map_desc(1, 2))?;
                g.pass("sun_shadows.clear")
                    .uses(texels, true)
                    // Never read: no cascades means no lookup. wgpu zeroes the map.
                    .uses(map, true)
                    .encode(move |enc, res| enc.clear_buffer(res.buffer(texels), 0, None))?;
                return Ok(SunShadowMaps {
                    texels,
                    map,
                    params: ShadowParams::disabled(),
                });
            }
        };
        let cascades = fit_cascades(camera, aspect, to_sun, bounds, s);
        let res = s.resolution as u64;
        let (texels, fresh_texels) =
            g.persistent_buffer("sun_shadows.texels", res * res * cascades.len() as u64 * 4)?;
        let (map, fresh_map) = g.persistent_texture(
            "sun_shadows.map",
            map_desc(s.resolution, cascades.len() as u32),
        )?;
        let stale = cache.update(&cascades, fresh_texels || fresh_map, s);
        if !stale.is_empty() {
            let view_proj: Vec<Mat4> = stale
                .iter()
                .map(|&i| cascades[i as usize].view_proj)
                .collect();
            raster.record(
                g,
                scene,
                &RasterJob {
                    technique: "sun_shadows",
                    view_proj: &view_proj,
                    slices: &stale,
                    size: [s.resolution, s.resolution],
                    // Both faces cast: thin walls are single panels in many scenes.
                    cull_back_faces: false,
                },
                RasterTarget::Depth,
                texels,
                queues,
            )?;
            let mut layers = [0u32; 4];
            layers[..stale.len()].copy_from_slice(&stale);
            let copy = CopyParams {
                layers,
                config: [s.resolution, stale.len() as u32, 0, 0],
            };
            g.pass("sun_shadows.copy")
                .constants(&copy)
                .read(texels)
                .write(map)
                .dispatch_threads(
                    &self.copy,
                    [s.resolution / 4, s.resolution, stale.len() as u32],
                )?;
        }
        Ok(SunShadowMaps {
            texels,
            map,
            params: ShadowParams::new(&cache.held(), depth_range(to_sun, bounds), s),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Quat;

    fn camera(position: Vec3, forward: Vec3) -> Camera {
        Camera {
            name: "c".into(),
            position,
            target: position + forward,
            vfov_deg: 60.0,
            near: 0.1,
            up: Vec3::Y,
        }
    }

    fn corners(dn: f32, df: f32, fov_deg: f32, aspect: f32) -> Vec<Vec3> {
        let t = (fov_deg.to_radians() * 0.5).tan();
        let mut v = Vec::new();
        for d in [dn, df] {
            for (sx, sy) in [(-1.0, -1.0), (1.0, -1.0), (-1.0, 1.0), (1.0, 1.0)] {
                v.push(Vec3::new(sx * d * t * aspect, sy * d * t, d));
            }
        }
        v
    }

    #[test]
    fn the_slice_sphere_holds_its_frustum_slice_and_is_minimal() {
        for (dn, df, fov, aspect) in [
            (0.1, 5.0, 60.0, 1.78),
            (5.0, 40.0, 90.0, 1.0),
            (40.0, 250.0, 30.0, 2.4),
        ] {
            let t = (f32::to_radians(fov) * 0.5).tan();
            let k = t * t * (1.0 + aspect * aspect);
            let (z, r) = slice_sphere(dn, df, k);
            let c = Vec3::new(0.0, 0.0, z);
            let far = corners(dn, df, fov, aspect)
                .iter()
                .map(|p| p.distance(c))
                .fold(0.0, f32::max);
            assert!(
                far <= r * (1.0 + 1e-5),
                "corner at {far} outside radius {r}"
            );
            // Minimal: the farthest corner is on the sphere.
            assert!(
                far >= r * (1.0 - 1e-4),
                "radius {r} larger than needed ({far})"
            );
        }
    }

    #[test]
    fn cascades_keep_their_size_when_the_camera_turns_and_their_texels_when_it_moves() {
        let s = ShadowSettings::default();
        let bounds = (Vec3::splat(-200.0), Vec3::splat(200.0));
        let sun = Vec3::new(-0.4, 0.8, 0.3).normalize();
        let base = fit_cascades(
            &camera(Vec3::new(1.0, 2.0, 3.0), Vec3::Z),
            1.78,
            sun,
            bounds,
            &s,
        );
        for i in 0..20 {
            let q = Quat::from_euler(
                glam::EulerRot::YXZ,
                i as f32 * 0.37,
                (i as f32 * 0.11).sin() * 0.6,
                0.0,
            );
            let pos = Vec3::new(
                1.0 + i as f32 * 0.731,
                2.0 + i as f32 * 0.05,
                3.0 - i as f32 * 1.37,
            );
            let moved = fit_cascades(&camera(pos, q * Vec3::Z), 1.78, sun, bounds, &s);
            for (a, b) in base.iter().zip(&moved) {
                assert!(
                    (a.radius - b.radius).abs() <= a.radius * 1e-5,
                    "radius changed"
                );
                // A fixed world point lands on the same sub-texel position in every frame:
                // the projections differ by whole texels.
                let p = Vec3::new(3.3, 0.7, -2.1);
                let (pa, pb) = (a.view_proj.project_point3(p), b.view_proj.project_point3(p));
                let texels = (pa - pb).truncate() * 0.5 * s.resolution as f32;
                let frac = (texels - texels.round()).abs();
                assert!(frac.max_element() < 2e-2, "moved by {texels} texels");
            }
        }
    }

    #[test]
    fn a_moving_view_redraws_the_most_drifted_cascades_within_the_frame_limit() {
        let s = ShadowSettings {
            cascades_per_frame: 1,
            ..Default::default()
        };
        let bounds = (Vec3::splat(-200.0), Vec3::splat(200.0));
        let sun = Vec3::new(-0.4, 0.8, 0.3).normalize();
        let fit = |z: f32| {
            fit_cascades(
                &camera(Vec3::new(0.0, 2.0, z), Vec3::Z),
                1.78,
                sun,
                bounds,
                &s,
            )
        };
        let mut cache = ShadowCache::default();
        assert_eq!(
            cache.update(&fit(0.0), true, &s),
            vec![0, 1, 2, 3],
            "new maps: all"
        );
        assert!(cache.update(&fit(0.0), false, &s).is_empty(), "still: none");
        // Walking forward: one cascade a frame, and each is drawn where it was wanted then.
        let mut drawn_at = [0.0f32; 4];
        for frame in 1..=40 {
            let z = frame as f32 * 0.05;
            let want = fit(z);
            let drawn = cache.update(&want, false, &s);
            assert!(
                drawn.len() <= 1
                    || drawn.iter().all(|&i| {
                        // Beyond the limit only for cascades drifted past MAX_DRIFT.
                        drift(&fit(drawn_at[i as usize])[i as usize], &want[i as usize]) > MAX_DRIFT
                    }),
                "frame {frame}: drew {drawn:?}"
            );
            for &i in &drawn {
                drawn_at[i as usize] = z;
            }
            for (i, held) in cache.held().iter().enumerate() {
                let d = drift(held, &want[i]);
                assert!(
                    d <= MAX_DRIFT,
                    "frame {frame}: cascade {i} drifted {d} radii"
                );
            }
        }
        // The nearest cascade, the smallest, drifts fastest and is redrawn most often.
        let mut counts = [0; 4];
        let mut cache2 = ShadowCache::default();
        cache2.update(&fit(0.0), true, &s);
        for frame in 1..=40 {
            for i in cache2.update(&fit(frame as f32 * 0.05), false, &s) {
                counts[i as usize] += 1;
            }
        }
        assert!(counts[0] > counts[3], "redraws per cascade {counts:?}");
        // Standing still again, the remaining ones catch up and then nothing is drawn.
        let end = fit(2.0);
        let mut frames = 0;
        while !cache2.update(&end, false, &s).is_empty() {
            frames += 1;
            assert!(frames <= 4, "still view keeps redrawing");
        }
        for (held, want) in cache2.held().iter().zip(&end) {
            assert_eq!(held.view_proj, want.view_proj);
        }
        // A sun that moves changes every cascade's shape: all are redrawn at once.
        let sun2 = Vec3::new(-0.41, 0.8, 0.3).normalize();
        let turned = fit_cascades(
            &camera(Vec3::new(0.0, 2.0, 2.0), Vec3::Z),
            1.78,
            sun2,
            bounds,
            &s,
        );
        assert_eq!(cache2.update(&turned, false, &s).len(), 4);
    }

    #[test]
    fn splits_run_from_near_to_far_and_blend_log_and_uniform() {
        let d = split_distances(0.1, 100.0, 4, 1.0);
        assert!(
            (d[2] - (0.1f32 * 100.0).sqrt()).abs() < 1e-3,
            "log split {d:?}"
        );
        let d = split_distances(0.1, 100.0, 4, 0.0);
        assert!((d[2] - 50.05).abs() < 1e-3, "uniform split {d:?}");
        assert!(d.windows(2).all(|w| w[0] < w[1]));
    }
}
