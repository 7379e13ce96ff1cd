//! Ray-traced GI (issue 18): the GPU passes against their CPU twins
//! (`techniques::ray_traced_gi::reference`) and against analytic results, on 64 x 64 images.

use crate::common;

use glam::{Mat4, Vec2, Vec3};
use hikari_math::sh::basis::{C0, C1};
use hikari_math::sh::ycocg::{ShL1YCoCg, rgb_to_ycocg, ycocg_to_rgb};
use hikari_render::graph::{GraphRuntime, ImageRgba32};
use hikari_render::shader;
use hikari_render::techniques::ray_traced_gi::reference::{
    self, AccumulateInput, Accumulated, FireflyClamp, HitWord, accumulate_pixel, pack_hit,
    unpack_hit,
};
use hikari_render::techniques::ray_traced_gi::{
    FLAG_ACCUMULATE, FLAG_RESET, RayTracedGi, RayTracedGiSettings, RtGiParams, SkySource,
};
use hikari_render::techniques::sky::{PLACEHOLDER_SKY_HORIZON, PLACEHOLDER_SKY_ZENITH};
use hikari_render::view::View;
use hikari_render::{FrameSettings, Renderer};
use hikari_scene::{Camera, Instance, Material, Scene, Sun, shapes};
use rand::rngs::SmallRng;
use rand::{Rng, SeedableRng};
use wgpu::util::DeviceExt;

mod accumulate;
mod hits;
mod lights;
mod rays;
mod resolve;
mod trace;

fn random_unit(rng: &mut SmallRng) -> Vec3 {
    loop {
        let v = Vec3::new(
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
        );
        let l = v.length();
        if l > 0.1 && l <= 1.0 {
            return v / l;
        }
    }
}

fn f16(x: f32) -> f32 {
    half::f16::from_f32(x).to_f32()
}

fn texture(
    ctx: &hikari_render::GpuContext,
    format: wgpu::TextureFormat,
    w: u32,
    h: u32,
    data: &[u8],
) -> wgpu::Texture {
    common::texture_with_data(ctx, format, w, h, data)
}

fn halves(v: &[[f32; 4]]) -> Vec<u8> {
    v.iter()
        .flat_map(|p| p.map(half::f16::from_f32))
        .flat_map(|h| h.to_le_bytes())
        .collect()
}

fn rgba(img: &ImageRgba32) -> &[[f32; 4]] {
    &img.rgba
}

fn floor_scene() -> Scene {
    Scene {
        meshes: vec![shapes::plane(400.0)],
        materials: vec![Material::diffuse("floor", Vec3::splat(0.5))],
        instances: vec![Instance {
            mesh: 0,
            material: 0,
            transform: Mat4::IDENTITY,
        }],
        cameras: vec![Camera {
            name: "down".into(),
            position: Vec3::new(0.0, 10.0, 0.0),
            target: Vec3::ZERO,
            up: Vec3::Z,
            ..Camera::default()
        }],
        sun: Some(Sun::default()),
        ..Default::default()
    }
}

fn rtgi_settings(scene: &Scene, w: u32, h: u32) -> FrameSettings {
    let mut s = common::small_frame_settings(scene, w, h);
    s.settings.ray_traced_gi.enabled = true;
    s
}

/// One frame of the GI without a sun, accumulation, the shadow rays' roulette or the radiance
/// cap, so that each pixel's raw sample is the twin's exactly (the roulette and the cap have
/// tests of their own).
fn twin_settings(scene: &Scene, w: u32, h: u32) -> FrameSettings {
    let mut s = rtgi_settings(scene, w, h);
    s.sun = hikari_render::SunSource::Off;
    s.settings.ray_traced_gi.accumulate = false;
    s.settings.ray_traced_gi.hit_shadow_roulette = 0.0;
    s.settings.ray_traced_gi.hit_radiance_cap = 0.0;
    s
}

struct Read {
    y: ImageRgba32,
    cocg: ImageRgba32,
    ao: ImageRgba32,
    length: ImageRgba32,
    distance: ImageRgba32,
    hits: Vec<u32>,
    instances: Vec<u32>,
    normals: Vec<u32>,
    queue: Vec<u32>,
    /// The G-buffer's depth and normal texels.
    depth: Vec<[f32; 4]>,
    normal: Vec<[f32; 4]>,
    /// `exposure.value` after the frame.
    exposure: Vec<f32>,
}

/// The six numbers of pixel `i`'s GI sample as the shade pass wrote them: Y SH, then Co, Cg.
fn sample_at(gy: &ImageRgba32, gc: &ImageRgba32, i: usize) -> [f32; 6] {
    [
        gy.rgba[i][0],
        gy.rgba[i][1],
        gy.rgba[i][2],
        gy.rgba[i][3],
        gc.rgba[i][0],
        gc.rgba[i][1],
    ]
}

fn render(renderer: &mut Renderer, s: &FrameSettings) -> Read {
    let mut picked = None;
    let mut r = renderer
        .render_reading(s, |o| {
            let f = o.ray_traced_gi.expect("the technique is on");
            let rays = o.ray_traced_gi_rays.unwrap();
            picked = Some(f);
            vec![
                f.gi_y.into(),
                f.gi_cocg.into(),
                f.ao.into(),
                f.history_length.into(),
                f.hit_distance.into(),
                rays.hits.into(),
                rays.hit_instances.into(),
                rays.hit_normals.into(),
                rays.queue.into(),
                o.gbuffer.depth.into(),
                o.gbuffer.normal.into(),
                o.exposure.value.into(),
            ]
        })
        .unwrap();
    let f = picked.unwrap();
    let words = |name: &str| -> Vec<u32> { bytemuck::pod_collect_to_vec(r.buffer(name).unwrap()) };
    let hits = words("ray_traced_gi.hits");
    let queue = words("ray_traced_gi.queue");
    let instances = words("ray_traced_gi.hit_instances");
    let normals = words("ray_traced_gi.hit_normals");
    let exposure = bytemuck::pod_collect_to_vec(r.buffer("exposure.value").unwrap());
    let depth = r.image("gbuffer.depth").unwrap().rgba.clone();
    let normal = r.image("gbuffer.normal").unwrap().rgba.clone();
    Read {
        y: r.take_image_of(f.gi_y).unwrap(),
        cocg: r.take_image_of(f.gi_cocg).unwrap(),
        ao: r.take_image_of(f.ao).unwrap(),
        length: r.take_image_of(f.history_length).unwrap(),
        distance: r.take_image_of(f.hit_distance).unwrap(),
        hits,
        instances,
        normals,
        queue,
        depth,
        normal,
        exposure,
    }
}

/// Scattered point and spot lights (some with a range) and one-sided, double-sided, forced and
/// dim area lights, as records: the inputs of the light grid's CPU tests.
fn scattered_lights(
    rng: &mut SmallRng,
    points: usize,
    areas: usize,
) -> (
    Vec<hikari_render::scene::upload::LightGpu>,
    hikari_render::techniques::area_lights::PolygonLights,
) {
    use hikari_render::lights::polygon::{
        AREA_LIGHT_DOUBLE_SIDED, AREA_LIGHT_FORCED, AreaLightGpu, PolygonLights,
    };
    let at = |rng: &mut SmallRng| {
        Vec3::new(
            rng.random_range(-20.0..20.0),
            rng.random_range(0.0..8.0),
            rng.random_range(-20.0..20.0),
        )
    };
    let lights = (0..points)
        .map(|k| {
            let p = at(rng);
            let spot = k % 3 == 0;
            let range = if k % 2 == 0 {
                rng.random_range(0.5..4.0)
            } else {
                f32::MAX
            };
            hikari_render::scene::upload::LightGpu {
                position_range: p.extend(range).to_array(),
                direction_kind: [0.0, -1.0, 0.0, if spot { 1.0 } else { 0.0 }],
                intensity: (Vec3::new(1.0, 0.8, 0.5) * rng.random_range(0.01..0.5))
                    .extend(0.0)
                    .to_array(),
                spot: [2.0, -1.0, 0.0, 0.0],
            }
        })
        .collect();
    let lights_area = (0..areas)
        .map(|k| {
            let c = at(rng);
            let r = rng.random_range(0.05..0.5);
            let area = r * r * 2.0;
            let radiance = Vec3::new(1.0, 0.6, 0.3) * rng.random_range(0.05..3.0);
            let flux =
                std::f32::consts::PI * radiance.dot(Vec3::new(0.2126, 0.7152, 0.0722)) * area;
            let bits = (if k % 4 == 0 {
                AREA_LIGHT_DOUBLE_SIDED
            } else {
                0
            }) | (if k % 5 == 0 { AREA_LIGHT_FORCED } else { 0 });
            AreaLightGpu {
                centroid_radius: c.extend(r).to_array(),
                normal_area: random_unit(rng).extend(area).to_array(),
                radiance_flux: radiance.extend(flux).to_array(),
                range: [0, 0, bits, 0],
            }
        })
        .collect();
    (
        lights,
        PolygonLights {
            lights: lights_area,
            ..Default::default()
        },
    )
}
