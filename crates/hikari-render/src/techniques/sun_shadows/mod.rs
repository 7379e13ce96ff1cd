//! Cascaded shadow maps of the sun (or moon), rasterised in compute (`raster/mod.rs`) into
//! one u32 depth a texel, looked up with 3x3 bilinear PCF by the deferred lighting
//! (`techniques/sun_shadows/lookup.wgsl`; CPU twin [`crate::techniques::sun_shadows::reference`]).
//!
//! Stability under camera motion: each cascade is the bounding sphere of its slice of the view
//! frustum, whose radius depends only on the slice distances and the field of view (not on the
//! camera's orientation), and its centre is snapped to whole texels in light space, so texels
//! keep their place in the world as the camera turns and moves.
//!
//! The maps persist across frames and scroll: a texel of a cascade is stored at its place on
//! a light-space grid fixed in the world, modulo the map size (toroidal addressing), so when
//! the camera moves and a cascade's centre moves by whole texels, only the strips it uncovers
//! are drawn ([`ShadowCache`]); every cascade is always where the camera wants it. The whole
//! cascade is drawn when it is new or when the sun or the settings change its shape
//! (`sun_shadows.cache = false`: every frame); a sun that turns by less than the cascade's
//! hold ([`hold_deg`]: 0.1° or half a texel of a 10 m caster's shadow, whichever is more)
//! keeps the cascade, so a playing clock redraws each cascade every few frames. The rasteriser's atomics need a buffer; what was
//! drawn is then copied into a layer of an R32Uint texture array, which the lookup gathers
//! 2x2 texels at a time from (a quarter of the loads, and a texture cache laid out for 2D
//! neighbourhoods), through a repeating sampler that does the wrap-around.
//!
//! Depth convention as the camera's: 1 nearest the sun, 0 farthest (the cleared value), over
//! the scene's extent along the sun direction, so every caster is inside the depth range.

pub mod reference;
pub mod settings;

use bytemuck::{Pod, Zeroable};
use glam::{IVec2, Mat4, Vec3, Vec4};

use hikari_scene::Camera;

use crate::context::GpuContext;
use crate::error::Result;
use crate::graph::{BindingSet, Buf, FrameGraph, SamplerKind, Tex, TextureDesc};
use crate::pipeline::ComputePipeline;
use crate::scene::raster::{
    MAX_VIEWS, RasterJob, RasterQueues, RasterTarget, RasterView, Rasterizer, pack_point,
};
use crate::scene::upload::SceneInFrame;
use crate::settings::SunShadowsSettings;
use crate::shader::ShaderLibrary;

/// Cascades at most.
pub const MAX_CASCADES: usize = 4;

/// What the lookup needs; `cascades` of zero means no shadows (everything lit).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct ShadowParams {
    pub light_view_proj: [[[f32; 4]; 4]; MAX_CASCADES],
    /// Per cascade: world-space size of a texel in metres.
    pub texel_world: [f32; 4],
    /// Cascades, resolution, PCF tap spacing in texels, normal bias in texels.
    pub config: [f32; 4],
    /// Per cascade: depth bias in NDC depth units.
    pub depth_bias: [f32; 4],
    /// Per cascade: where its texel (0, 0) is stored, x | y << 16 ([`Cascade::origin`]).
    pub origin: [u32; 4],
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
    /// The centre on the light-space texel grid: light-space x and y in whole texels.
    pub centre: IVec2,
}

impl Cascade {
    /// Where texel (0, 0) of a `res`-texel map of this cascade is stored: texel (x, y) lands
    /// at ((x + ox) mod res, (y + oy) mod res), which depends only on the texel's place in the
    /// world, so a cascade that moves by whole texels keeps its other texels where they are.
    pub fn origin(&self, res: u32) -> [u32; 2] {
        let (c, half, r) = (self.centre, res as i64 / 2, res as i64);
        // Texel x grows with light-space x, texel y with light-space -y.
        [
            (c.x as i64 - half).rem_euclid(r) as u32,
            (-(c.y as i64) - half).rem_euclid(r) as u32,
        ]
    }
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
    s: &SunShadowsSettings,
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
            // Whole texels (held in i32: a texel of 1 mm is 2000 km of range).
            let snap = |v: f32| (v / texel).floor().clamp(-2.0e9, 2.0e9) as i32;
            let grid = IVec2::new(snap(centre.dot(lx)), snap(centre.dot(ly)));
            let (cx, cy) = (grid.x as f32 * texel, grid.y as f32 * texel);
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
                centre: grid,
            }
        })
        .collect()
}

impl ShadowParams {
    pub fn disabled() -> Self {
        Self::zeroed()
    }

    pub fn new(cascades: &[Cascade], depth_range: f32, s: &SunShadowsSettings) -> Self {
        let mut p = Self::zeroed();
        for (i, c) in cascades.iter().enumerate() {
            p.light_view_proj[i] = c.view_proj.to_cols_array_2d();
            p.texel_world[i] = c.texel_world;
            p.depth_bias[i] = s.depth_bias_texels * c.texel_world / depth_range;
            let [ox, oy] = c.origin(s.resolution);
            p.origin[i] = pack_point(ox, oy);
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
    /// The binding set `sun_shadows` of `lookup.wgsl` (params, map, sampler), for the passes
    /// that look the maps up.
    pub lookup: BindingSet,
}

/// A `sun_shadows` binding set in which every point is lit (no cascades), for passes tested
/// on their own.
pub fn unshadowed_lookup(g: &mut FrameGraph<'_>) -> Result<BindingSet> {
    let map = g.texture("sun_shadows.map", map_desc(1, 1))?;
    g.pass("sun_shadows.clear")
        // Never read: no cascades means no lookup. wgpu zeroes the map.
        .uses(map, true)
        .encode(|_, _| {})?;
    Ok(lookup_set(g, &ShadowParams::disabled(), map))
}

fn lookup_set(g: &mut FrameGraph<'_>, params: &ShadowParams, map: Tex) -> BindingSet {
    g.binding_set("sun_shadows")
        .constants(params)
        .read(map)
        .sampler(SamplerKind::NearestRepeat)
        .finish()
}

pub const MAP_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Uint;

/// Bytes of the rasteriser's depth buffer: `cascades * resolution^2` u32.
fn depth_bytes(resolution: u32, cascades: u32) -> u64 {
    resolution as u64 * resolution as u64 * cascades.max(1) as u64 * 4
}

/// `s` with its resolution halved until the rasteriser's depth buffer fits in one storage
/// binding of `limit` bytes (WebGPU's default and the CPU driver's: 128 MiB, which `ultra`'s
/// 4 x 4096^2 exceeds twice over).
pub fn fit_to_binding(s: &SunShadowsSettings, limit: u64) -> SunShadowsSettings {
    let mut res = s.resolution;
    while res > 64 && depth_bytes(res, s.cascades) > limit {
        res /= 2;
    }
    SunShadowsSettings {
        resolution: res,
        ..s.clone()
    }
}

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

/// The cascades the maps hold, so that a frame draws only what changed.
#[derive(Clone, Debug, Default)]
pub struct ShadowCache {
    /// The cascade each slice of the persistent maps holds.
    drawn: Vec<Option<Cascade>>,
    /// The direction to the sun each cascade was drawn for.
    sun: Vec<Option<Vec3>>,
    /// Whether the warning that the resolution was reduced to fit the adapter was given.
    said_fitted: bool,
}

/// A sun (or moon) that turned less than this since a cascade was drawn keeps it: its shadows
/// stay where they were drawn until the sun has turned this far. A tenth of a degree is a
/// fifth of the sun's own disk (0.53°), whose penumbra is wider than the shift; a playing clock
/// turns the sun by this in 24 s of its time, so cascades are redrawn every few frames rather
/// than every frame.
pub const HELD_SUN_DEG: f32 = 0.1;

/// The caster height whose shadow a held cascade may shift by at most half a texel: coarse
/// cascades, whose texels are larger, hold the sun longer ([`hold_deg`]).
pub const HOLD_CASTER_M: f32 = 10.0;

/// How far the sun may turn before a cascade of `texel_world`-metre texels is redrawn: the
/// larger of [`HELD_SUN_DEG`] and the turn that moves the shadow of a [`HOLD_CASTER_M`] caster
/// by half a texel.
pub fn hold_deg(texel_world: f32) -> f32 {
    HELD_SUN_DEG.max((0.5 * texel_world / HOLD_CASTER_M).atan().to_degrees())
}

/// Part of a cascade to draw this frame: its texels x0..x1, y0..y1 (ends exclusive).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CascadeRegion {
    pub cascade: u32,
    pub window: [u32; 4],
}

/// Whether two cascades differ in at most their centre: same sun, size and depth range.
fn same_shape(a: &Cascade, b: &Cascade) -> bool {
    let (a, b) = (a.view_proj, b.view_proj);
    a.x_axis == b.x_axis && a.y_axis == b.y_axis && a.z_axis == b.z_axis && a.w_axis.z == b.w_axis.z
}

/// The texels of a `res` map of `want` that a map of the same shape centred `held` texels
/// away does not hold: a strip of columns and a strip of rows (they may share a corner).
fn uncovered(held: IVec2, want: IVec2, res: u32) -> Vec<[u32; 4]> {
    let d = want.as_i64vec2() - held.as_i64vec2();
    let r = res as i64;
    if d.x.abs() >= r || d.y.abs() >= r {
        return vec![[0, 0, res, res]];
    }
    let mut strips = Vec::new();
    // Texel x grows with light-space x: moving by dx uncovers the last dx columns.
    match d.x {
        0 => {}
        dx if dx > 0 => strips.push([(r - dx) as u32, 0, res, res]),
        dx => strips.push([0, 0, (-dx) as u32, res]),
    }
    // Texel y grows with light-space -y: moving by dy uncovers the first dy rows.
    match d.y {
        0 => {}
        dy if dy > 0 => strips.push([0, 0, res, dy as u32]),
        dy => strips.push([0, (r + dy) as u32, res, res]),
    }
    strips
}

impl ShadowCache {
    /// The direction to draw and look up `cascade` with this frame: the one it holds while
    /// `to_sun` is within `hold_deg` of it (with caching on), else `to_sun`.
    pub fn held_sun(
        &mut self,
        cascade: usize,
        to_sun: Vec3,
        hold_deg: f32,
        s: &SunShadowsSettings,
    ) -> Vec3 {
        if self.sun.len() <= cascade {
            self.sun.resize(cascade + 1, None);
        }
        let want = to_sun.normalize_or_zero();
        match self.sun[cascade] {
            Some(held) if s.cache && held.dot(want) >= hold_deg.to_radians().cos() => held,
            _ => {
                self.sun[cascade] = Some(want);
                want
            }
        }
    }

    /// What to draw this frame so that the maps hold `cascades`: all of every cascade when
    /// the maps are new or caching is off; else all of those that are new or changed shape,
    /// and of those that moved, the strips they uncovered.
    pub fn update(
        &mut self,
        cascades: &[Cascade],
        fresh: bool,
        s: &SunShadowsSettings,
    ) -> Vec<CascadeRegion> {
        if fresh || !s.cache || self.drawn.len() != cascades.len() {
            self.drawn = vec![None; cascades.len()];
        }
        let res = s.resolution;
        let mut regions = Vec::new();
        for (i, (held, want)) in self.drawn.iter_mut().zip(cascades).enumerate() {
            let windows = match held {
                Some(h) if same_shape(h, want) => uncovered(h.centre, want.centre, res),
                _ => vec![[0, 0, res, res]],
            };
            regions.extend(windows.into_iter().map(|window| CascadeRegion {
                cascade: i as u32,
                window,
            }));
            *held = Some(*want);
        }
        regions
    }
}

#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct CopyParams {
    /// Per region: layer, origin, first texel and end (exclusive) of the window, points
    /// packed as x | y << 16.
    pub regions: [[u32; 4]; MAX_VIEWS],
    /// Resolution, regions, 0, 0.
    pub config: [u32; 4],
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
        s: &SunShadowsSettings,
        queues: &mut RasterQueues,
    ) -> Result<SunShadowMaps> {
        let fitted = fit_to_binding(s, g.ctx().limits.max_storage_buffer_binding_size);
        if fitted.resolution != s.resolution && !cache.said_fitted {
            cache.said_fitted = true;
            log::warn!(
                "sun_shadows.resolution {} with {} cascades needs {} MiB in one storage binding, \
                 past this adapter's {} MiB: using {}",
                s.resolution,
                s.cascades,
                depth_bytes(s.resolution, s.cascades) >> 20,
                g.ctx().limits.max_storage_buffer_binding_size >> 20,
                fitted.resolution
            );
        }
        let s = &fitted;
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
                let params = ShadowParams::disabled();
                let lookup = lookup_set(g, &params, map);
                return Ok(SunShadowMaps {
                    texels,
                    map,
                    params,
                    lookup,
                });
            }
        };
        // Each cascade fitted for the sun it holds (the sun as it is when it has turned past
        // the cascade's hold).
        let fitted = fit_cascades(camera, aspect, to_sun, bounds, s);
        let cascades: Vec<Cascade> = fitted
            .iter()
            .enumerate()
            .map(|(i, c)| {
                let sun = cache.held_sun(i, to_sun, hold_deg(c.texel_world), s);
                if sun == to_sun.normalize_or_zero() {
                    *c
                } else {
                    fit_cascades(camera, aspect, sun, bounds, s)[i]
                }
            })
            .collect();
        let res = s.resolution as u64;
        let (texels, fresh_texels) =
            g.persistent_buffer("sun_shadows.texels", res * res * cascades.len() as u64 * 4)?;
        let (map, fresh_map) = g.persistent_texture(
            "sun_shadows.map",
            map_desc(s.resolution, cascades.len() as u32),
        )?;
        let regions = cache.update(&cascades, fresh_texels || fresh_map, s);
        // Two strips a cascade at most: every region fits in one dispatch.
        debug_assert!(regions.len() <= MAX_VIEWS);
        if !regions.is_empty() {
            let views: Vec<RasterView> = regions
                .iter()
                .map(|r| {
                    let c = &cascades[r.cascade as usize];
                    RasterView {
                        view_proj: c.view_proj,
                        slice: r.cascade,
                        window: r.window,
                        origin: c.origin(s.resolution),
                    }
                })
                .collect();
            raster.record(
                g,
                scene,
                &RasterJob {
                    technique: "sun_shadows",
                    views: &views,
                    size: [s.resolution, s.resolution],
                    // Both faces cast: thin walls are single panels in many scenes.
                    cull_back_faces: false,
                },
                RasterTarget::Depth,
                texels,
                queues,
            )?;
            let mut copy = CopyParams {
                regions: [[0; 4]; MAX_VIEWS],
                config: [s.resolution, views.len() as u32, 0, 0],
            };
            for (dst, v) in copy.regions.iter_mut().zip(&views) {
                *dst = v.packed();
            }
            // Items: a whole layer's are four texels each, a strip's one; rows of res / 4.
            let res = s.resolution;
            let items = views
                .iter()
                .map(|v| {
                    let [x0, y0, x1, y1] = v.window;
                    let texels = (x1 - x0) * (y1 - y0);
                    if v.covers([res, res]) {
                        texels / 4
                    } else {
                        texels
                    }
                })
                .max()
                .unwrap_or(0);
            let threads = [res / 4, items.div_ceil(res / 4)];
            g.pass("sun_shadows.copy")
                .constants(&copy)
                .read(texels)
                .write(map)
                .dispatch_threads(&self.copy, [threads[0], threads[1], views.len() as u32])?;
        }
        let params = ShadowParams::new(&cascades, depth_range(to_sun, bounds), s);
        let lookup = lookup_set(g, &params, map);
        Ok(SunShadowMaps {
            texels,
            map,
            params,
            lookup,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Quat;

    #[test]
    fn the_ultra_shadow_maps_fit_webgpus_default_storage_binding() {
        use crate::settings::{Preset, TechniqueSettings};
        let limit = 128 << 20;
        let ultra = SunShadowsSettings::preset(Preset::Ultra);
        assert!(ultra.resolution as u64 * ultra.resolution as u64 * 16 > limit);
        let fitted = fit_to_binding(&ultra, limit);
        assert_eq!(
            fitted.resolution, 2048,
            "halved until 4 x 2048^2 x 4 bytes fit"
        );
        assert_eq!(fit_to_binding(&ultra, u64::MAX).resolution, 4096);
        let high = SunShadowsSettings::preset(Preset::High);
        assert_eq!(fit_to_binding(&high, limit).resolution, high.resolution);
    }

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
        let s = SunShadowsSettings::default();
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

    /// Draws `regions` into per-cascade CPU maps the way the GPU does: each texel drawn is
    /// stored at (texel + origin) mod res and holds the light-space grid cell it shows.
    fn draw(
        maps: &mut [Vec<Option<IVec2>>],
        regions: &[CascadeRegion],
        want: &[Cascade],
        res: u32,
    ) {
        for r in regions {
            let c = &want[r.cascade as usize];
            let [ox, oy] = c.origin(res);
            let [x0, y0, x1, y1] = r.window;
            for y in y0..y1 {
                for x in x0..x1 {
                    let at = ((y + oy) % res * res + (x + ox) % res) as usize;
                    maps[r.cascade as usize][at] = Some(grid_cell(c, x, y, res));
                }
            }
        }
    }

    /// The light-space grid cell texel (x, y) of cascade `c` shows, from its projection alone
    /// (independent of the origin and strip logic under test).
    fn grid_cell(c: &Cascade, x: u32, y: u32, res: u32) -> IVec2 {
        let ndc = Vec3::new(
            (x as f32 + 0.5) / res as f32 * 2.0 - 1.0,
            1.0 - (y as f32 + 0.5) / res as f32 * 2.0,
            0.5,
        );
        let world = c.view_proj.inverse().project_point3(ndc);
        let (lx, ly) = (c.view_proj.row(0).truncate(), c.view_proj.row(1).truncate());
        // Rows of the projection are the light axes over the radius.
        let (u, v) = (world.dot(lx) * c.radius, world.dot(ly) * c.radius);
        IVec2::new(
            (u / c.texel_world).floor() as i32,
            (v / c.texel_world).floor() as i32,
        )
    }

    #[test]
    fn scrolled_maps_hold_every_texel_of_the_wanted_cascades() {
        let s = SunShadowsSettings {
            resolution: 64,
            ..Default::default()
        };
        let res = s.resolution;
        let bounds = (Vec3::splat(-200.0), Vec3::splat(200.0));
        let sun = Vec3::new(-0.4, 0.8, 0.3).normalize();
        let fit = |p: Vec3, yaw: f32| {
            let forward = Quat::from_rotation_y(yaw) * Vec3::Z;
            fit_cascades(&camera(p, forward), 1.78, sun, bounds, &s)
        };
        let mut cache = ShadowCache::default();
        let mut maps = vec![vec![None; (res * res) as usize]; 4];
        let first = fit(Vec3::ZERO, 0.0);
        let regions = cache.update(&first, true, &s);
        assert_eq!(regions.len(), 4, "new maps: every cascade whole");
        assert!(regions.iter().all(|r| r.window == [0, 0, res, res]));
        draw(&mut maps, &regions, &first, res);
        assert!(
            cache.update(&first, false, &s).is_empty(),
            "still: nothing drawn"
        );
        // Walk, turn, jump: after each frame every texel of every wanted cascade is held.
        let mut partial = 0;
        for frame in 1..=60 {
            let t = frame as f32;
            let jump = if frame == 40 { 300.0 } else { 0.0 };
            let p = Vec3::new(0.37 * t + jump, 0.05 * (t * 0.3).sin(), -0.81 * t);
            let want = fit(p, t * 0.11);
            let regions = cache.update(&want, false, &s);
            assert!(regions.len() <= MAX_VIEWS, "{} regions", regions.len());
            partial += regions
                .iter()
                .filter(|r| r.window != [0, 0, res, res])
                .count();
            draw(&mut maps, &regions, &want, res);
            for (i, c) in want.iter().enumerate() {
                let [ox, oy] = c.origin(res);
                for y in 0..res {
                    for x in 0..res {
                        let at = ((y + oy) % res * res + (x + ox) % res) as usize;
                        assert_eq!(
                            maps[i][at],
                            Some(grid_cell(c, x, y, res)),
                            "frame {frame}, cascade {i}, texel ({x}, {y})"
                        );
                    }
                }
            }
        }
        assert!(partial > 60, "moving views draw strips ({partial})");
        // A sun that moves changes every cascade's shape: all are drawn whole.
        let sun2 = Vec3::new(-0.41, 0.8, 0.3).normalize();
        let turned = fit_cascades(&camera(Vec3::ZERO, Vec3::Z), 1.78, sun2, bounds, &s);
        let regions = cache.update(&turned, false, &s);
        assert_eq!(regions.len(), 4);
        assert!(regions.iter().all(|r| r.window == [0, 0, res, res]));
    }

    #[test]
    fn a_cascade_moved_by_whole_texels_uncovers_one_strip_an_axis() {
        let res = 64;
        let at = |x, y| IVec2::new(x, y);
        assert!(uncovered(at(5, 5), at(5, 5), res).is_empty());
        assert_eq!(uncovered(at(0, 0), at(3, 0), res), vec![[61, 0, 64, 64]]);
        assert_eq!(uncovered(at(0, 0), at(-2, 0), res), vec![[0, 0, 2, 64]]);
        assert_eq!(uncovered(at(0, 0), at(0, 4), res), vec![[0, 0, 64, 4]]);
        assert_eq!(uncovered(at(0, 0), at(0, -1), res), vec![[0, 63, 64, 64]]);
        assert_eq!(
            uncovered(at(0, 0), at(1, -1), res),
            vec![[63, 0, 64, 64], [0, 63, 64, 64]]
        );
        assert_eq!(uncovered(at(0, 0), at(64, 0), res), vec![[0, 0, 64, 64]]);
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
