//! Clouds (Ghost of Tsushima, after Schneider 2015 and Hillaire 2016): a layer of
//! coverage-remapped fBm between a base and a top altitude over a spherical Earth, marched into
//! a paraboloid map of the upper hemisphere (768 x 768 by default) that stores, per texel, the
//! Mie light scattered to the eye per unit sun illuminance, the light scattered per unit sky
//! radiance, and the transmittance (the talk's red, green and blue channels). The map is
//! drawn whole when its shape or lighting changes or the clock jumps, a share of its rows per
//! frame while the sky's clock moves it (the wind and the sun: at most `time_slices` shares,
//! fewer when the clock runs fast, so that no row is older than [`STALE_FEATURE`] of a
//! feature's drift or [`STALE_SUN_DEG`] of the sun's; shares too thin to fill the GPU are
//! drawn several at a time every few frames, [`march_rows`]), and not at all while nothing
//! changes.
//!
//! * `clouds.march`: the map (`march.wgsl`);
//! * `clouds.shadow_map`: the sun's transmittance through the layer on a square of its base
//!   around the camera (`shadow_map.wgsl`), which `cloud_shadow` reads for every point whose
//!   path to the sun enters the layer there;
//! * `hikari::clouds` (binding set `clouds`): the clouds over the sky, drawn by the deferred
//!   lighting where depth is 0, and their shadow on the sun's light, in the deferred lighting
//!   and the haze.
//!
//! CPU twin: [`reference`].

pub mod reference;
pub mod settings;

use bytemuck::{Pod, Zeroable};
use glam::Vec3;
use hikari_scene::Sun;

use crate::context::GpuContext;
use crate::error::Result;
use crate::graph::{BindingSet, FrameGraph, SamplerKind, Tex, TextureDesc};
use crate::pipeline::ComputePipeline;
use crate::shader::ShaderLibrary;
use settings::CloudsSettings;

pub const CLOUDS_ON: u32 = 1;
pub const CLOUDS_SHADOWS: u32 = 2;
pub const CLOUDS_DENSITY_AA: u32 = 4;
pub const CLOUDS_MULTIPLE: u32 = 8;

/// Mean Earth radius, metres (as hikari-atmosphere's default ground radius).
pub const EARTH_RADIUS_M: f32 = 6_360_000.0;

pub const MAP_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
/// The shadow map's transmittance, read with four loads and a bilinear blend in f32 (as the
/// twin; R32Float is not filterable everywhere).
pub const SHADOW_MAP_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Float;

/// The clouds' parameters (`density.wgsl` documents each field).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, PartialEq)]
pub struct CloudParams {
    pub layer: [f32; 4],
    pub shape: [f32; 4],
    pub offset: [f32; 4],
    pub sun: [f32; 4],
    pub phase: [f32; 4],
    pub march: [u32; 4],
    pub slice: [u32; 4],
    pub shadow: [f32; 4],
}

impl CloudParams {
    /// The parameters of `s` in `weather`, lit by `sun` (none: unlit), `seconds` into the day
    /// (the wind's offset). `on` false gives parameters that draw nothing and shadow nothing.
    pub fn new(
        s: &CloudsSettings,
        weather: &str,
        sun: Option<&Sun>,
        seconds: f64,
        on: bool,
    ) -> Self {
        let flags = [
            (on && s.enabled, CLOUDS_ON),
            (s.shadows, CLOUDS_SHADOWS),
            (s.density_aa, CLOUDS_DENSITY_AA),
            (s.multiple_scattering, CLOUDS_MULTIPLE),
        ]
        .iter()
        .filter(|(b, _)| *b)
        .fold(0, |acc, (_, bit)| acc | bit);
        let (dir, lit) = match sun {
            Some(sun) if sun.illuminance_lux > 0.0 => (sun.direction.normalize_or(Vec3::Y), 1.0),
            _ => (Vec3::Y, 0.0),
        };
        Self {
            layer: [s.bottom_m, s.bottom_m + s.thickness_m, EARTH_RADIUS_M, 0.0],
            shape: [
                s.coverage_in(weather),
                s.density,
                1.0 / s.feature_m,
                s.albedo,
            ],
            offset: {
                let [x, z] = s.offset_at(seconds);
                [x, z, s.max_march_m, 0.0]
            },
            sun: dir.extend(lit).to_array(),
            phase: [s.forward_g, s.backward_g, s.backward_scale, 0.0],
            march: [s.steps, s.light_steps, s.map_size, flags],
            slice: [1, 0, 0, 0],
            shadow: [0.0; 4],
        }
    }

    /// `shadow` for a map of `size` texels a side over `extent_m` metres of the layer's base,
    /// centred where the path from `camera` to the sun enters the layer, snapped to whole
    /// texels (so that a moving camera samples the same texel centres). No map (w = 0) without
    /// shadows, a sun, a camera below the base, or a size.
    pub fn with_shadow_map(mut self, size: u32, extent_m: f32, camera: Vec3) -> Self {
        let both = CLOUDS_ON | CLOUDS_SHADOWS;
        self.shadow = [0.0; 4];
        if size == 0 || self.march[3] & both != both || self.sun[3] == 0.0 {
            return self;
        }
        let Some(entry) = shadow_entry(&self, camera) else {
            return self;
        };
        let texel = extent_m / size as f32;
        let corner = ((entry - glam::Vec2::splat(0.5 * extent_m)) / texel).round() * texel;
        if !corner.is_finite() || !texel.is_finite() || texel <= 0.0 {
            return self;
        }
        self.shadow = [corner.x, corner.y, texel, size as f32];
        self
    }
}

/// The most a row of the map may lag the clock while it is redrawn in slices: the wind's drift
/// as a fraction of a feature, and the sun's turn in degrees. A clock that moves more than
/// this in one frame is a jump, and the map is drawn whole.
pub const STALE_FEATURE: f32 = 0.05;
pub const STALE_SUN_DEG: f32 = 0.25;

/// What a frame redraws of the paraboloid map ([`redraw`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Redraw {
    /// Every row: the map is new, or what shapes or lights it changed, or the clock jumped.
    Whole,
    /// A row in `slices`, with this frame's parameters: only the clock moved, by so little a
    /// frame that `slices` frames of it stay within [`STALE_FEATURE`] and [`STALE_SUN_DEG`].
    Slice { slices: u32 },
    /// Nothing: the map was drawn with these very parameters.
    Nothing,
}

/// What to redraw of the map for parameters `now`, given the parameters every row was drawn
/// with (`whole`; `None`: never, or its texture is new), those of the frame before (`last`,
/// which only the clock may separate from `now` for a slice) and the most slices a frame
/// (`time_slices`). The comparison leaves out `slice` and `shadow`, which do not shape the map.
pub fn redraw(
    whole: Option<&CloudParams>,
    last: Option<&CloudParams>,
    now: &CloudParams,
    time_slices: u32,
) -> Redraw {
    let Some(whole) = whole else {
        return Redraw::Whole;
    };
    let strip = |p: &CloudParams| CloudParams {
        slice: [0; 4],
        shadow: [0.0; 4],
        ..*p
    };
    let (whole, now) = (strip(whole), strip(now));
    if whole == now {
        return Redraw::Nothing;
    }
    let last = strip(last.unwrap_or(&whole));
    // Everything but the clock's: the wind's offset (offset.xy) and the sun's direction.
    let clockless = |p: &CloudParams| CloudParams {
        offset: [0.0, 0.0, p.offset[2], p.offset[3]],
        sun: [0.0, 0.0, 0.0, p.sun[3]],
        ..*p
    };
    if clockless(&last) != clockless(&now) || clockless(&whole) != clockless(&now) {
        return Redraw::Whole;
    }
    // This frame's step of the clock: the wind's drift in features (shape[2] is 1 / feature
    // size) and the sun's turn.
    let moved = glam::Vec2::new(
        now.offset[0] - last.offset[0],
        now.offset[1] - last.offset[1],
    )
    .length()
        * now.shape[2];
    let (a, b) = (
        Vec3::from_slice(&now.sun[..3]),
        Vec3::from_slice(&last.sun[..3]),
    );
    // atan2 of the sine and cosine: exact for small angles, where acos of a dot product in f32
    // is off by hundredths of a degree.
    let turned = a.cross(b).length().atan2(a.dot(b)).to_degrees();
    if !(moved < STALE_FEATURE && turned < STALE_SUN_DEG) {
        return Redraw::Whole;
    }
    let fit = |step: f32, limit: f32| {
        if step > 0.0 {
            (limit / step).floor().min(u32::MAX as f32) as u32
        } else {
            u32::MAX
        }
    };
    let slices = time_slices
        .max(1)
        .min(fit(moved, STALE_FEATURE))
        .min(fit(turned, STALE_SUN_DEG))
        .max(1);
    Redraw::Slice { slices }
}

/// The map size a view `height` pixels tall with a vertical field of view of `vfov_deg` needs:
/// a texel at most a pixel at the zenith, where the paraboloid is coarsest (a quarter of the
/// map's texels a radian), capped by `s.map_size` and rounded up to 16. A small image (the
/// CPU driver's, a thumbnail) marches a small map: the map's cost follows the view's.
pub fn map_size_for(s: &CloudsSettings, height: u32, vfov_deg: f32) -> u32 {
    let vfov = vfov_deg.clamp(1.0, 179.0).to_radians();
    let needed = (4.0 * height as f32 / vfov).ceil() as u32;
    needed.next_multiple_of(16).clamp(16, s.map_size.max(16))
}

/// Threads a march dispatch should have to fill a large GPU (an H200 runs 132 × 2048 at
/// once): a thinner slice costs about what one this thick does, as the march is bound by
/// its latency, not its throughput.
pub const MIN_MARCH_THREADS: u32 = 1 << 18;

/// The rows frame `frame` draws of a `size`-texel map redrawn in `slices` slices: `Some([s,
/// i])`, every `s`-th row from row `i` (`CloudParams::slice`), or `None` on a frame that
/// draws nothing. Slices too thin to fill the GPU ([`MIN_MARCH_THREADS`]) are drawn `k` at a
/// time on every `k`-th frame, so that the same rows are drawn as often for less time:
/// every row is still drawn within any `slices` frames in a row.
pub fn march_rows(size: u32, slices: u32, frame: u64) -> Option<[u32; 2]> {
    let n = slices.max(1);
    let rows = size.max(1).div_ceil(n);
    let k = MIN_MARCH_THREADS
        .div_ceil(size.max(1))
        .div_ceil(rows)
        .clamp(1, n);
    let grouped = (n / k).max(1);
    frame.is_multiple_of(u64::from(k)).then(|| {
        [
            grouped,
            ((frame / u64::from(k)) % u64::from(grouped)) as u32,
        ]
    })
}

/// Where the path from `pos` towards the sun enters the layer's base (world x, z), as
/// `cloud_shadow_at` marches it: the sun's elevation is floored at sin 0.05 (about 3°).
/// None above the base.
pub fn shadow_entry(p: &CloudParams, pos: Vec3) -> Option<glam::Vec2> {
    let s = Vec3::from_slice(&p.sun[..3]);
    let sy = s.y.max(0.05);
    let t0 = (p.layer[0] - pos.y) / sy;
    (t0 >= 0.0).then(|| glam::Vec2::new(pos.x + s.x * t0, pos.z + s.z * t0))
}

/// The clouds of a frame.
#[derive(Clone, Copy, Debug)]
pub struct CloudsFrame {
    /// `clouds.map`: the paraboloid map (r: Mie per lux, g: per unit sky radiance,
    /// b: transmittance).
    pub map: Tex,
    /// `clouds.shadow_map`: R32Float transmittance on the layer's base (1x1 and unused where
    /// `params.shadow` has no map).
    pub shadow_map: Tex,
    pub params: CloudParams,
    /// Binding set `clouds` of `hikari::clouds`.
    pub lookup: BindingSet,
    /// Whether the clouds are on and drawn this frame (what other techniques ask, rather than
    /// reading `params`' lanes).
    pub drawn: bool,
    /// Whether every row of the map holds this frame's parameters (drawn whole, unchanged,
    /// or its last slice drawn): what is lit through it has stopped changing.
    pub settled: bool,
}

/// What the persistent map holds, kept between frames in the renderer's frame state.
#[derive(Clone, Debug, Default)]
pub struct CloudsState {
    /// The parameters every row was last drawn with.
    whole: Option<CloudParams>,
    /// The parameters of the last sliced frame, and how many sliced frames in a row had them.
    last: Option<CloudParams>,
    steady: u32,
}

pub struct Clouds {
    march: ComputePipeline,
    shadow_map: ComputePipeline,
}

fn lookup_set(
    g: &mut FrameGraph<'_>,
    params: &CloudParams,
    map: Tex,
    shadow_map: Tex,
) -> BindingSet {
    g.binding_set("clouds")
        .constants(params)
        .read(map)
        .sampler(SamplerKind::LinearClamp)
        .read(shadow_map)
        .finish()
}

/// Clouds that draw nothing: a 1x1 map and shadow map, `params` without a shadow map (with the
/// clouds on and shadows, `cloud_shadow` marches the layer at each point).
fn disabled_frame(g: &mut FrameGraph<'_>, mut params: CloudParams) -> Result<CloudsFrame> {
    params.shadow = [0.0; 4];
    let map = g.texture("clouds.map", TextureDesc::d2(1, 1, MAP_FORMAT))?;
    let shadow_map = g.texture(
        "clouds.shadow_map",
        TextureDesc::d2(1, 1, SHADOW_MAP_FORMAT),
    )?;
    g.pass("clouds.clear")
        // Never read with the clouds off (or without a shadow map). wgpu zeroes them.
        .uses(map, true)
        .uses(shadow_map, true)
        .encode(|_, _| {})?;
    let lookup = lookup_set(g, &params, map, shadow_map);
    Ok(CloudsFrame {
        map,
        shadow_map,
        params,
        lookup,
        drawn: false,
        settled: true,
    })
}

/// A `clouds` binding set that draws no clouds and casts no shadow, for passes tested on
/// their own.
pub fn disabled_lookup(g: &mut FrameGraph<'_>) -> Result<BindingSet> {
    Ok(disabled_frame(g, CloudParams::zeroed())?.lookup)
}

/// A `clouds` binding set of `params` whose map is a blank 1x1: their shadow (computed from
/// the parameters alone) without drawing the map, for passes tested on their own.
pub fn shadow_lookup(g: &mut FrameGraph<'_>, params: CloudParams) -> Result<BindingSet> {
    Ok(disabled_frame(g, params)?.lookup)
}

impl Clouds {
    pub fn new(ctx: &GpuContext, lib: &mut ShaderLibrary) -> Result<Self> {
        Ok(Self {
            march: ComputePipeline::new(ctx, lib, "clouds/march.wgsl", "main", &[])?,
            shadow_map: ComputePipeline::new(ctx, lib, "clouds/shadow_map.wgsl", "main", &[])?,
        })
    }

    /// Draws this frame's share of the map (all of it when `params` changed) and the shadow
    /// map around `camera`, and makes the lookup set. With the clouds off, a 1x1 map and
    /// parameters that draw nothing. `state` says what the map holds.
    pub fn record<'r>(
        &'r self,
        g: &mut FrameGraph<'r>,
        state: &mut CloudsState,
        s: &CloudsSettings,
        params: CloudParams,
        camera: Vec3,
    ) -> Result<CloudsFrame> {
        if params.march[3] & CLOUDS_ON == 0 {
            return disabled_frame(g, params);
        }
        // The paraboloid map does not depend on the camera: it is compared without the
        // shadow map's place.
        let mut params = params;
        params.shadow = [0.0; 4];
        let size = s.map_size;
        let (map, fresh) =
            g.persistent_texture("clouds.map", TextureDesc::d2(size, size, MAP_FORMAT))?;
        let decision = if fresh {
            Redraw::Whole
        } else {
            redraw(
                state.whole.as_ref(),
                state.last.as_ref(),
                &params,
                s.time_slices,
            )
        };
        let mut p = params;
        let mut draw = decision != Redraw::Nothing;
        match decision {
            Redraw::Whole => {
                *state = CloudsState {
                    whole: Some(params),
                    last: Some(params),
                    steady: 0,
                };
            }
            Redraw::Nothing => {}
            Redraw::Slice { slices: n } => {
                match march_rows(size, n, g.frame_index()) {
                    Some([every, first]) => p.slice = [every, first, 0, 0],
                    None => draw = false,
                }
                state.steady = if state.last == Some(params) {
                    state.steady + 1
                } else {
                    1
                };
                state.last = Some(params);
                // n frames in a row with the same parameters redrew every row with them.
                if state.steady >= n {
                    state.whole = Some(params);
                }
            }
        }
        if draw {
            g.pass("clouds.march")
                .constants(&p)
                .write(map)
                .dispatch_threads(&self.march, [size, size.div_ceil(p.slice[0]), 1])?;
        }
        let settled = state.whole == Some(params);
        let params = params.with_shadow_map(s.shadow_map_size, s.shadow_map_extent_m, camera);
        let n = params.shadow[3] as u32;
        let shadow_map = g.texture(
            "clouds.shadow_map",
            TextureDesc::d2(n.max(1), n.max(1), SHADOW_MAP_FORMAT),
        )?;
        if n > 0 {
            g.pass("clouds.shadow_map")
                .constants(&params)
                .write(shadow_map)
                .dispatch_threads(&self.shadow_map, [n, n, 1])?;
        } else {
            g.pass("clouds.shadow_map_clear")
                // Never read without a shadow map. wgpu zeroes it.
                .uses(shadow_map, true)
                .encode(|_, _| {})?;
        }
        let lookup = lookup_set(g, &params, map, shadow_map);
        Ok(CloudsFrame {
            map,
            shadow_map,
            params,
            lookup,
            drawn: true,
            settled,
        })
    }
}
