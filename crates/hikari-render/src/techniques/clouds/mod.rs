//! Clouds (Ghost of Tsushima, after Schneider 2015 and Hillaire 2016): a layer of
//! coverage-remapped fBm between a base and a top altitude over a spherical Earth, marched into
//! a paraboloid map of the upper hemisphere (768 x 768 by default) that stores, per texel, the
//! Mie light scattered to the eye per unit sun illuminance, the light scattered per unit sky
//! radiance, and the transmittance (the talk's red, green and blue channels). The map is
//! redrawn a row in `time_slices` per frame, whole when its parameters change.
//!
//! * `clouds.march`: the map (`march.wgsl`);
//! * `hikari::clouds` (binding set `clouds`): the clouds over the sky, drawn by the deferred
//!   lighting where depth is 0, and their shadow on the sun's light, in the deferred lighting
//!   and the haze.
//!
//! CPU twin: [`reference`].

pub mod reference;
pub mod settings;

use std::sync::Mutex;

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
        }
    }
}

/// The clouds of a frame.
#[derive(Clone, Copy, Debug)]
pub struct CloudsFrame {
    /// `clouds.map`: the paraboloid map (r: Mie per lux, g: per unit sky radiance,
    /// b: transmittance).
    pub map: Tex,
    pub params: CloudParams,
    /// Binding set `clouds` of `hikari::clouds`.
    pub lookup: BindingSet,
}

pub struct Clouds {
    march: ComputePipeline,
    /// The parameters the persistent map was last drawn whole with.
    drawn: Mutex<Option<CloudParams>>,
}

fn lookup_set(g: &mut FrameGraph<'_>, params: &CloudParams, map: Tex) -> BindingSet {
    g.binding_set("clouds")
        .constants(params)
        .read(map)
        .sampler(SamplerKind::LinearClamp)
        .finish()
}

/// Clouds that draw nothing and cast no shadow: a 1x1 map and `params` (flags off).
fn disabled_frame(g: &mut FrameGraph<'_>, params: CloudParams) -> Result<CloudsFrame> {
    let map = g.texture("clouds.map", TextureDesc::d2(1, 1, MAP_FORMAT))?;
    g.pass("clouds.clear")
        // Never read with the clouds off. wgpu zeroes it.
        .uses(map, true)
        .encode(|_, _| {})?;
    let lookup = lookup_set(g, &params, map);
    Ok(CloudsFrame {
        map,
        params,
        lookup,
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
            drawn: Mutex::new(None),
        })
    }

    /// Draws this frame's share of the map (all of it when `params` changed) and makes the
    /// lookup set. With the clouds off, a 1x1 map and parameters that draw nothing.
    pub fn record<'r>(
        &'r self,
        g: &mut FrameGraph<'r>,
        s: &CloudsSettings,
        params: CloudParams,
    ) -> Result<CloudsFrame> {
        if params.march[3] & CLOUDS_ON == 0 {
            return disabled_frame(g, params);
        }
        let size = s.map_size;
        let (map, fresh) =
            g.persistent_texture("clouds.map", TextureDesc::d2(size, size, MAP_FORMAT))?;
        let mut drawn = self.drawn.lock().unwrap_or_else(|e| e.into_inner());
        let mut p = params;
        if fresh || drawn.as_ref() != Some(&params) {
            *drawn = Some(params);
        } else {
            let n = s.time_slices.max(1);
            p.slice = [n, (g.frame_index() % u64::from(n)) as u32, 0, 0];
        }
        g.pass("clouds.march")
            .constants(&p)
            .write(map)
            .dispatch_threads(&self.march, [size, size.div_ceil(p.slice[0]), 1])?;
        let lookup = lookup_set(g, &params, map);
        Ok(CloudsFrame {
            map,
            params,
            lookup,
        })
    }
}
