//! Area lights and ray-traced shadows of point and spot lights (`techniques/area_lights`):
//! the polygon integration against the closed form of a rectangle's irradiance, the GPU pass
//! against its CPU twin, and a blocker's penumbra against its exact width.

use crate::common;

use glam::{DVec3, Mat4, Vec3, Vec4};
use hikari_bvh::{BuildOptions, Tlas};
use hikari_render::lights::reference::{
    area_light_reach, light_vector_irradiance, polygon_vector_irradiance,
};
use hikari_render::scene::bvh::{self, SceneAlphaFilter};
use hikari_render::techniques::area_lights::reference::{self, TwinScene};
use hikari_render::techniques::area_lights::{self, AreaLightParams, PolygonLights};
use hikari_render::techniques::{direct_lighting, gbuffer};
use hikari_render::{FrameSettings, Renderer};
use hikari_scene::{Camera, Instance, Material, Scene, shapes};

mod analytic;
mod denoise;
mod shade;

/// Form factor from a differential area to a parallel rectangle of sides `a`, `b` with one
/// corner straight above it at height `h` (the classic closed form, e.g. Howell's catalogue
/// of configuration factors, case B-3); the irradiance is `π L F`.
fn corner_form_factor(a: f64, b: f64, h: f64) -> f64 {
    let (x, y) = (a / h, b / h);
    let (sx, sy) = ((1.0 + x * x).sqrt(), (1.0 + y * y).sqrt());
    (x / sx * (y / sx).atan() + y / sy * (x / sy).atan()) / (2.0 * std::f64::consts::PI)
}

/// Irradiance per unit radiance (sr) at the origin (normal +y) from the rectangle
/// [x0, x1] x [z0, z1] at height h facing down, by superposing corner rectangles.
fn rectangle_closed_form(x0: f64, x1: f64, z0: f64, z1: f64, h: f64) -> f64 {
    let f = |x: f64, z: f64| x.signum() * z.signum() * corner_form_factor(x.abs(), z.abs(), h);
    std::f64::consts::PI * (f(x1, z1) - f(x0, z1) - f(x1, z0) + f(x0, z0))
}

/// The rectangle as a polygon relative to the receiving point at `p`, wound with its front
/// (facing -y) towards the point.
fn rectangle(x0: f64, x1: f64, z0: f64, z1: f64, h: f64, p: DVec3) -> [DVec3; 4] {
    // (p1 - p0) x (p2 - p0) must point down: along x first, then z.
    [
        DVec3::new(x0, h, z0),
        DVec3::new(x1, h, z0),
        DVec3::new(x1, h, z1),
        DVec3::new(x0, h, z1),
    ]
    .map(|q| q - p)
}

/// What a frame's area-light pass saw and wrote.
struct Frame {
    settings: FrameSettings,
    depth: hikari_render::graph::ImageRgba32,
    normal: hikari_render::graph::ImageRgba32,
    albedo: hikari_render::graph::ImageRgba32,
    material: hikari_render::graph::ImageRgba32,
    /// Emission and, in alpha, the specular weight the BRDF reads.
    emissive: hikari_render::graph::ImageRgba32,
    radiance: hikari_render::graph::ImageRgba32,
    unshadowed: hikari_render::graph::ImageRgba32,
    params: AreaLightParams,
}

fn render(scene: &Scene, settings: FrameSettings) -> (Renderer, Frame) {
    let ctx = common::gpu_context();
    let mut renderer = Renderer::new(ctx, scene).unwrap();
    let mut sky_lux = 0.0;
    let mut r = renderer
        .render_reading(&settings, |o| {
            sky_lux = o.sky.sky_lux;
            let g = &o.gbuffer;
            vec![
                g.depth.into(),
                g.normal.into(),
                g.albedo.into(),
                g.material.into(),
                g.emissive.into(),
                o.area_lights.into(),
                o.area_lights_unshadowed.into(),
            ]
        })
        .unwrap();
    let mut img = |n: &str| r.take_image(n).unwrap();
    // The frame took its cut-off from the frame context, whose sky is the frame's.
    let cx = settings.context().unwrap();
    assert_eq!(cx.sky_lux, sky_lux);
    let params = AreaLightParams::new(
        &settings.settings.area_lights,
        renderer.area_lights().light_count(),
        renderer.scene().light_count,
        cx.light_cutoff_lux,
        0,
    );
    let frame = Frame {
        depth: img("gbuffer.depth"),
        normal: img("gbuffer.normal"),
        albedo: img("gbuffer.albedo"),
        material: img("gbuffer.material"),
        emissive: img("gbuffer.emissive"),
        radiance: img("area_lights.radiance"),
        unshadowed: img("area_lights.unshadowed"),
        settings,
        params,
    };
    (renderer, frame)
}

fn world_at(f: &Frame, x: u32, y: u32) -> Vec3 {
    let (w, h) = (f.settings.width, f.settings.height);
    let view = hikari_render::view::View::new(&f.settings.camera, w, h);
    let inv = Mat4::from_cols_array_2d(&view.inv_view_proj);
    gbuffer::reference::world_from_depth(inv, [x, y], [w, h], f.depth.pixel(x, y)[0])
}

/// A floor, a square light `side` metres wide facing down 2 m above it, and optionally a
/// blocker at 1 m covering x < 0; a camera at 0.5 m looking straight down.
fn penumbra_scene(side: f32, blocker: bool) -> Scene {
    let mut scene = Scene::default();
    scene.materials.push(Material {
        roughness: 1.0,
        ..Material::diffuse("floor", Vec3::splat(0.5))
    });
    scene
        .materials
        .push(Material::emissive("light", Vec3::splat(20000.0)));
    scene.meshes.push(shapes::plane(10.0));
    scene.meshes.push(shapes::plane(side));
    scene.meshes.push(shapes::plane(4.0));
    let flip = Mat4::from_rotation_x(std::f32::consts::PI);
    let mut add = |mesh, material, transform| {
        scene.instances.push(Instance {
            mesh,
            material,
            transform,
        })
    };
    add(0, 0, Mat4::IDENTITY);
    add(
        1,
        1,
        Mat4::from_translation(Vec3::new(0.0, 2.0, 0.0)) * flip,
    );
    if blocker {
        add(2, 0, Mat4::from_translation(Vec3::new(-2.0, 1.0, 0.0)));
    }
    scene.cameras.push(Camera {
        name: "down".into(),
        position: Vec3::new(0.0, 0.5, 0.0),
        target: Vec3::new(0.0, 0.0, 0.0),
        vfov_deg: 30.0,
        near: 0.01,
        up: Vec3::Z,
    });
    scene
}

/// The shadow factor of a square light behind a straight edge, per image column (averaged
/// over the rows), on the GPU and exactly: the irradiance of the part of the light the floor
/// point sees past the edge over the whole light's (the ratio estimator's expectation).
fn penumbra_profile(side: f32) -> (Vec<f32>, Vec<f32>, Vec<f32>) {
    let (w, h) = (64u32, 16u32);
    let frame = |blocker| {
        let scene = penumbra_scene(side, blocker);
        let mut s = common::small_frame_settings(&scene, w, h);
        s.settings.area_lights.ray_budget = 32;
        s.settings.area_lights.lights_per_pixel = 1;
        render(&scene, s).1
    };
    let open = frame(false);
    let shadowed = frame(true);
    let (mut gpu, mut exact, mut xs) = (vec![0f32; w as usize], vec![0f32; w as usize], vec![]);
    for x in 0..w {
        let mut sum_x = 0.0;
        for y in 0..h {
            let p = world_at(&open, x, y);
            sum_x += p.x;
            let (a, b) = (
                shadowed.radiance.pixel(x, y)[1],
                open.radiance.pixel(x, y)[1],
            );
            gpu[x as usize] += if b > 0.0 { a / b } else { 1.0 } / h as f32;
            // Light [-s, s]^2 at 2 m, edge at x = 0, 1 m: the floor point at x sees the
            // light where x_l >= -x.
            let s = side as f64 * 0.5;
            let pp = p.as_dvec3();
            let full = polygon_vector_irradiance(&rectangle(-s, s, -s, s, 2.0, pp), DVec3::Y).y;
            let x0 = (-pp.x).clamp(-s, s);
            let vis = polygon_vector_irradiance(&rectangle(x0, s, -s, s, 2.0, pp), DVec3::Y).y;
            exact[x as usize] += (vis / full) as f32 / h as f32;
        }
        xs.push(sum_x / h as f32);
    }
    (xs, gpu, exact)
}

/// Where a profile first reaches `level`, metres (linear between columns).
fn crossing(xs: &[f32], v: &[f32], level: f32) -> f32 {
    for i in 1..v.len() {
        if (v[i - 1] - level) * (v[i] - level) <= 0.0 && v[i] != v[i - 1] {
            let t = (level - v[i - 1]) / (v[i] - v[i - 1]);
            return xs[i - 1] + t * (xs[i] - xs[i - 1]);
        }
    }
    f32::NAN
}

/// Reads a PFM (colour, little-endian) as rows from the top.
fn read_pfm(bytes: &[u8]) -> (u32, u32, Vec<[f32; 3]>) {
    let text_end = bytes
        .iter()
        .enumerate()
        .filter(|(_, b)| **b == b'\n')
        .nth(2)
        .unwrap()
        .0;
    let header = std::str::from_utf8(&bytes[..text_end]).unwrap();
    let mut words = header.split_whitespace();
    assert_eq!(words.next(), Some("PF"));
    let w: u32 = words.next().unwrap().parse().unwrap();
    let h: u32 = words.next().unwrap().parse().unwrap();
    assert!(
        words.next().unwrap().parse::<f32>().unwrap() < 0.0,
        "little-endian"
    );
    let data: Vec<f32> = bytes[text_end + 1..]
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect();
    assert_eq!(data.len(), (w * h * 3) as usize);
    let mut rows = Vec::new();
    for y in (0..h).rev() {
        for x in 0..w {
            let i = ((y * w + x) * 3) as usize;
            rows.push([data[i], data[i + 1], data[i + 2]]);
        }
    }
    (w, h, rows)
}

/// The penumbra scene lit by a point light at the light's place instead (radius 0.05 m).
fn point_light_scene(blocker: bool) -> Scene {
    let mut scene = penumbra_scene(0.2, blocker);
    // No area light: its quad taken out (the point light would sit in its plane).
    scene.instances.remove(1);
    scene.lights.push(hikari_scene::Light::point(
        "bulb",
        Vec3::new(0.0, 2.0, 0.0),
        100.0,
        Vec3::ONE,
    ));
    scene
}

/// The G-buffer texel of a rendered frame at (x, y), as the twin reads it.
fn texel_at(f: &Frame, x: u32, y: u32) -> direct_lighting::reference::Texel {
    let v4 = Vec4::from_array;
    direct_lighting::reference::Texel {
        depth: f.depth.pixel(x, y)[0],
        normal: v4(f.normal.pixel(x, y)),
        albedo: v4(f.albedo.pixel(x, y)),
        material: v4(f.material.pixel(x, y)),
        emissive: v4(f.emissive.pixel(x, y)),
    }
}

/// The shadow rays' BVH as the twin traces it: every instance but the shells around a light.
fn twin_bvh(scene: &Scene) -> (Vec<hikari_bvh::Blas>, Tlas) {
    let blases = bvh::blases(scene, &BuildOptions::default()).unwrap();
    let tlas = Tlas::build(
        &bvh::instances(scene),
        &area_lights::shadow_casters(scene),
        &blases,
    )
    .unwrap();
    (blases, tlas)
}

/// Several coloured lights, area and point, over a floor, partly behind a blocker: lit by many
/// lights at once, each pixel's budget shared among them.
fn many_lights_scene() -> Scene {
    let mut scene = penumbra_scene(0.05, false);
    scene.cameras[0].position = Vec3::new(0.0, 2.5, 0.0);
    scene.cameras[0].vfov_deg = 60.0;
    // A 0.8 m blocker 0.8 m above the floor (mesh 2 is the 4 m plane; a new one).
    scene.meshes.push(shapes::plane(0.8));
    scene.instances.push(Instance {
        mesh: scene.meshes.len() - 1,
        material: 0,
        transform: Mat4::from_translation(Vec3::new(0.2, 0.8, 0.1)),
    });
    let flip = Mat4::from_rotation_x(std::f32::consts::PI);
    let colours = [
        Vec3::new(270000.0, 108000.0, 36000.0),
        Vec3::new(36000.0, 81000.0, 270000.0),
        Vec3::new(108000.0, 270000.0, 72000.0),
        Vec3::new(180000.0, 180000.0, 180000.0),
    ];
    for (k, (x, z, y)) in [
        (-0.9, 0.3, 1.6),
        (0.6, -0.4, 1.3),
        (1.2, 0.5, 1.8),
        (-0.3, -0.7, 1.5),
    ]
    .into_iter()
    .enumerate()
    {
        scene.materials.push(Material::emissive("lamp", colours[k]));
        scene.instances.push(Instance {
            mesh: 1,
            material: scene.materials.len() - 1,
            transform: Mat4::from_translation(Vec3::new(x, y, z)) * flip,
        });
    }
    for (k, (x, z)) in [(-1.4, -0.2), (0.2, 0.9), (1.6, -0.8)]
        .into_iter()
        .enumerate()
    {
        scene.lights.push(hikari_scene::Light::point(
            "bulb",
            Vec3::new(x, 1.4, z),
            200.0 + 100.0 * k as f32,
            colours[(k + 1) % 4] / 270000.0,
        ));
    }
    scene
}

// ---- A radius per point or spot light ----

/// The exact visibility of a disc light of radius `r` (facing straight down, at 2 m) from the
/// floor at `x` behind an edge at x = 0, 1 m up: the part of the disc with X >= -x, a circular
/// segment, over the disc.
fn disc_visibility(x: f64, r: f64) -> f64 {
    let t = (x / r).clamp(-1.0, 1.0);
    ((-t).acos() + t * (1.0 - t * t).sqrt()) / std::f64::consts::PI
}
