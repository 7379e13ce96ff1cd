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

#[test]
fn square_light_irradiance_on_a_parallel_plane_matches_the_closed_form() {
    let n = DVec3::Y;
    let r = rectangle(-1.0, 1.0, -1.0, 1.0, 1.0, DVec3::ZERO);
    assert!(
        (r[1] - r[0]).cross(r[2] - r[0]).y < 0.0,
        "the test rectangle faces down"
    );
    let mut worst = 0f64;
    for &(side, h) in &[(0.1, 1.0), (1.0, 1.0), (2.0, 0.5), (0.5, 3.0)] {
        for &(px, pz) in &[(0.0, 0.0), (0.3, -0.2), (1.5, 0.7), (-2.0, 3.0)] {
            let s = side * 0.5;
            let want = rectangle_closed_form(-s - px, s - px, -s - pz, s - pz, h);
            let q = rectangle(-s, s, -s, s, h, DVec3::new(px, 0.0, pz));
            let got = polygon_vector_irradiance(&q, n).dot(n);
            let err = (got - want).abs() / want;
            worst = worst.max(err);
            assert!(
                err < 1e-9,
                "side {side} height {h} at ({px}, {pz}): {got} sr, closed form {want} sr"
            );
        }
    }
    // Far away the square is a point: E = A / d^2 per unit radiance.
    let q = rectangle(-0.01, 0.01, -0.01, 0.01, 10.0, DVec3::ZERO);
    let got = polygon_vector_irradiance(&q, n).dot(n);
    assert!((got - 4e-4 / 100.0).abs() < 1e-9, "{got}");
    // A light below the horizon gives nothing; one straddling it only its upper part.
    let below = rectangle(-1.0, 1.0, -1.0, 1.0, -1.0, DVec3::ZERO);
    assert_eq!(polygon_vector_irradiance(&below, n).dot(n), 0.0);
    println!("worst relative error against the closed form: {worst:e}");
}

/// A triangle-mesh light gives the sum of its triangles: the same as the one polygon.
#[test]
fn a_light_split_into_triangles_integrates_as_the_whole_polygon() {
    let mut scene = Scene::default();
    scene
        .materials
        .push(Material::emissive("light", Vec3::splat(1000.0)));
    let mut light = shapes::plane(1.0);
    // Facing down at 1 m.
    for p in &mut light.positions {
        *p = Vec3::new(p.x, 1.0, -p.z);
    }
    for nrm in &mut light.normals {
        *nrm = -*nrm;
    }
    scene.meshes.push(light);
    scene.instances.push(Instance {
        mesh: 0,
        material: 0,
        transform: Mat4::IDENTITY,
    });
    let lights = PolygonLights::for_scene(&scene);
    assert_eq!(lights.lights.len(), 1, "{:?}", lights.skipped);
    let got = light_vector_irradiance(
        lights.triangles_of(0),
        false,
        DVec3::new(0.2, 0.0, 0.1),
        DVec3::Y,
    )
    .y;
    let want = rectangle_closed_form(-0.7, 0.3, -0.6, 0.4, 1.0);
    assert!((got - want).abs() < 1e-6 * want, "{got} vs {want}");
    // Seen from above (its back), a one-sided light gives nothing.
    let back = light_vector_irradiance(
        lights.triangles_of(0),
        false,
        DVec3::new(0.0, 2.0, 0.0),
        -DVec3::Y,
    );
    assert_eq!(back, DVec3::ZERO);
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

/// The Cornell box at 64 x 64, lit by its light alone: every pixel of the GPU pass against the
/// CPU twin tracing the same shadow rays through hikari-bvh's CPU traversal.
///
/// Tolerance: 2 % of the pixel's value plus 1 % of the image's mean (f16 output, f32 against
/// f64 integration); a pixel may also differ where a shadow ray grazes an edge and goes the
/// other way on the CPU (one ray of 4 changes the pixel by up to a quarter): at most 3 % of
/// the lit pixels.
#[test]
fn gpu_matches_its_cpu_twin_on_the_cornell_box() {
    let scene = hikari_scene::builtin::cornell();
    let mut settings = common::small_frame_settings(&scene, 64, 64);
    settings.sun = hikari_render::SunSource::Off;
    let (renderer, f) = render(&scene, settings);
    assert!(f.params.config[1] & area_lights::AREA_POLYGONS != 0);
    let lights = &renderer.area_lights().lights;
    assert_eq!(
        lights.lights.len(),
        1,
        "the Cornell box's light is an area light"
    );
    let blases = bvh::blases(&scene, &BuildOptions::default()).unwrap();
    let tlas = Tlas::build(
        &bvh::instances(&scene),
        &area_lights::shadow_casters(&scene),
        &blases,
    )
    .unwrap();
    let filter = SceneAlphaFilter::new(&scene);
    let accept = |i, p, u, v| filter.accept(i, p, u, v);
    let twin_scene = TwinScene {
        blases: &blases,
        tlas: &tlas,
        accept: &accept,
    };
    let v4 = Vec4::from_array;
    let mut want = Vec::new();
    let mut want_unshadowed = Vec::new();
    for y in 0..64 {
        for x in 0..64 {
            let texel = direct_lighting::reference::Texel {
                depth: f.depth.pixel(x, y)[0],
                normal: v4(f.normal.pixel(x, y)),
                albedo: v4(f.albedo.pixel(x, y)),
                material: v4(f.material.pixel(x, y)),
                emissive: v4(f.emissive.pixel(x, y)),
            };
            want_unshadowed.push(reference::shade_unshadowed(
                &f.params,
                lights,
                &renderer.scene().cpu.lights,
                &texel,
                world_at(&f, x, y),
                f.settings.camera.position,
            ));
            want.push(reference::shade_with_lux(
                &f.params,
                lights,
                &renderer.scene().cpu.lights,
                &twin_scene,
                [x, y],
                &texel,
                world_at(&f, x, y),
                f.settings.camera.position,
            ));
        }
    }
    let mean = want.iter().map(|c| c.0.element_sum() / 3.0).sum::<f32>() / want.len() as f32;
    let mean_lux = want.iter().map(|c| c.1).sum::<f32>() / want.len() as f32;
    assert!(mean > 1.0, "the box is lit: mean {mean} nits");
    let (mut bad, mut lit, mut worst) = (0, 0, 0f32);
    for y in 0..64 {
        for x in 0..64 {
            let (w, w_lux) = want[(y * 64 + x) as usize];
            let g = f.radiance.pixel(x, y);
            lit += (w.max_element() > 0.0) as usize;
            // The alpha: lux the light brings, for the exposure meter.
            let mut px = (g[3] - w_lux).abs() / (0.02 * w_lux + 0.01 * mean_lux);
            for k in 0..3 {
                let tol = 0.02 * w[k].abs() + 0.01 * mean;
                px = px.max((g[k] - w[k]).abs() / tol);
            }
            worst = worst.max(px);
            bad += (px > 1.0) as usize;
        }
    }
    println!("lit {lit}, beyond tolerance {bad}, worst {worst} x tolerance");
    assert!(lit > 2000, "{lit}");
    assert!(
        bad * 100 <= lit * 3,
        "{bad} of {lit} pixels beyond tolerance"
    );
    // The unshadowed light (the shadow denoiser's denominator) has no rays: every pixel within
    // the same tolerance.
    for y in 0..64 {
        for x in 0..64 {
            let (w, w_lux) = want_unshadowed[(y * 64 + x) as usize];
            let g = f.unshadowed.pixel(x, y);
            assert!(
                (g[3] - w_lux).abs() <= 0.02 * w_lux + 0.01 * mean_lux,
                "({x}, {y}) unshadowed lux {} vs {w_lux}",
                g[3]
            );
            for k in 0..3 {
                assert!(
                    (g[k] - w[k]).abs() <= 0.02 * w[k].abs() + 0.01 * mean,
                    "({x}, {y}) unshadowed {g:?} vs {w}"
                );
            }
        }
    }
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

/// A blocker's penumbra widens with the light: the 10-90 % width of the shadow factor across
/// its edge is within 20 % (and 2 columns) of the exact width, for a light 0.2 m and 0.8 m wide,
/// and each column's shadow factor is within 0.08 of the exact one (32 rays over 16 rows).
#[test]
fn a_blocker_casts_a_penumbra_that_widens_with_the_light() {
    let mut widths = Vec::new();
    for side in [0.2f32, 0.8] {
        let (xs, gpu, exact) = penumbra_profile(side);
        let width = |v: &[f32]| (crossing(&xs, v, 0.9) - crossing(&xs, v, 0.1)).abs();
        let (g, e) = (width(&gpu), width(&exact));
        let column = (xs[1] - xs[0]).abs();
        println!("light {side} m: penumbra 10-90 % {g} m (exact {e} m), column {column} m");
        assert!(
            (g - e).abs() <= 0.2 * e + 2.0 * column,
            "light {side}: {g} vs {e}"
        );
        for (i, (a, b)) in gpu.iter().zip(&exact).enumerate() {
            assert!(
                (a - b).abs() < 0.08,
                "light {side} column {i}: {a} vs exact {b}"
            );
        }
        widths.push(g);
    }
    assert!(widths[1] > 2.5 * widths[0], "{widths:?}");
}

/// Settings reach the frame: off, the pass writes zeros and the deferred lighting keeps the
/// point and spot lights.
#[test]
fn switched_off_the_pass_writes_zero() {
    let scene = hikari_scene::builtin::cornell();
    let mut settings = common::small_frame_settings(&scene, 32, 32);
    settings.settings.area_lights.enabled = false;
    let (_, f) = render(&scene, settings);
    assert!(!f.params.shades_punctual());
    for y in 0..32 {
        for x in 0..32 {
            assert_eq!(f.radiance.pixel(x, y)[..3], [0.0; 3]);
        }
    }
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

/// hikari's Cornell box lit by its light alone (the frame's radiance: the light seen, and
/// its direct light with the area-light pass's shadows) against Mitsuba 3's direct lighting
/// (`path`, max_depth 2, 4096 spp, box filter) of the same published geometry, camera and
/// light (`tools/mitsuba_cornell.py`, fixture `mitsuba_cornell_direct_64.pfm`), at 64 x 64.
/// hikari is averaged over 8 frames (the sample pattern rotates each frame).
///
/// Metric: relative mean absolute error, sum |hikari - Mitsuba| / sum Mitsuba over every
/// channel of the lit surfaces (pixels under 1000 nits in Mitsuba: the emitter and its edge
/// pixels left out, as hikari takes one sample at each pixel's centre where Mitsuba averages
/// the pixel). Bounds, measured 0.089 and 0.998: at most 0.10 over the surfaces, and the back
/// wall (seen head-on) within 2 %. The rest is the BRDF, not the pass: hikari's at roughness 1
/// has a GGX lobe with Fresnel where Mitsuba's is Lambert, which brightens surfaces seen at
/// grazing angles (the floor by 10 %, the side walls by 6-9 %); the floor is held within 15 %.
#[test]
fn cornell_box_direct_light_matches_mitsuba() {
    let (mw, mh, mitsuba) = read_pfm(include_bytes!("../fixtures/mitsuba_cornell_direct_64.pfm"));
    assert_eq!((mw, mh), (64, 64));
    let scene = hikari_scene::builtin::cornell();
    let mut settings = common::small_frame_settings(&scene, 64, 64);
    settings.sun = hikari_render::SunSource::Off;
    let ctx = common::gpu_context();
    let mut renderer = Renderer::new(ctx, &scene).unwrap();
    let frames = 8;
    let mut sum = vec![[0f32; 3]; 64 * 64];
    for _ in 0..frames {
        let hdr = renderer.render(&settings, true).unwrap().hdr.unwrap();
        for y in 0..64 {
            for x in 0..64 {
                let p = hdr.pixel(x, y);
                for k in 0..3 {
                    sum[(y * 64 + x) as usize][k] += p[k] / frames as f32;
                }
            }
        }
    }
    let lum = |c: &[f32; 3]| 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
    let (mut diff, mut total, mut surfaces) = (0f64, 0f64, 0);
    for (h, m) in sum.iter().zip(&mitsuba) {
        if lum(m) >= 1000.0 {
            continue;
        }
        surfaces += 1;
        for k in 0..3 {
            diff += (h[k] - m[k]).abs() as f64;
            total += m[k] as f64;
        }
    }
    let error = diff / total;
    let region = |img: &[[f32; 3]], ys: std::ops::Range<usize>, xs: std::ops::Range<usize>| {
        let mut s = 0f64;
        for y in ys {
            for x in xs.clone() {
                s += img[y * 64 + x].iter().sum::<f32>() as f64;
            }
        }
        s
    };
    let ratio = |ys: std::ops::Range<usize>, xs: std::ops::Range<usize>| {
        region(&sum, ys.clone(), xs.clone()) / region(&mitsuba, ys, xs)
    };
    let back = ratio(20..32, 24..40);
    let floor = ratio(56..64, 16..32);
    println!(
        "{surfaces} surface pixels: relative mean absolute error {error:.4}; \
         back wall hikari / Mitsuba {back:.4}, floor {floor:.4}"
    );
    assert!(surfaces > 3500, "{surfaces}");
    assert!(error < 0.10, "relative mean absolute error {error}");
    assert!((back - 1.0).abs() < 0.02, "back wall ratio {back}");
    assert!((floor - 1.0).abs() < 0.15, "floor ratio {floor}");
}

/// Which emissive instances become area lights: the size rule, the material flag both ways,
/// and a point light inside an emissive shell (a lamp's paper) keeping it out, and out of the
/// shadow rays' BVH.
#[test]
fn emissive_meshes_become_area_lights_by_the_rule_and_the_flag() {
    let quad = |scene: &mut Scene, material: Material, at: Vec3| {
        scene.materials.push(material);
        scene.meshes.push(shapes::plane(0.5));
        scene.instances.push(Instance {
            mesh: scene.meshes.len() - 1,
            material: scene.materials.len() - 1,
            transform: Mat4::from_translation(at),
        });
    };
    let glow = Material::emissive("glow", Vec3::splat(1000.0));
    let mut scene = Scene::default();
    quad(
        &mut scene,
        Material::diffuse("plain", Vec3::ONE),
        Vec3::ZERO,
    );
    quad(&mut scene, glow.clone(), Vec3::X * 2.0);
    quad(
        &mut scene,
        Material {
            area_light: Some(false),
            ..glow.clone()
        },
        Vec3::X * 4.0,
    );
    // A point light in the plane of this one: inside its (flat) bounds.
    quad(&mut scene, glow.clone(), Vec3::X * 6.0);
    quad(
        &mut scene,
        Material {
            area_light: Some(true),
            ..glow.clone()
        },
        Vec3::X * 8.0,
    );
    scene.lights.push(hikari_scene::Light::point(
        "inside",
        Vec3::X * 6.0,
        10.0,
        Vec3::ONE,
    ));
    scene.lights.push(hikari_scene::Light::point(
        "inside the forced one",
        Vec3::X * 8.0,
        10.0,
        Vec3::ONE,
    ));
    let lights = PolygonLights::for_scene(&scene);
    let centres: Vec<f32> = lights.lights.iter().map(|l| l.centroid_radius[0]).collect();
    assert_eq!(centres, [2.0, 8.0], "skipped: {:?}", lights.skipped);
    assert_eq!(lights.skipped.len(), 2, "{:?}", lights.skipped);
    // Flux: pi x luminance x area.
    let flux = std::f32::consts::PI * 1000.0 * 0.25;
    assert!((lights.lights[0].radiance_flux[3] - flux).abs() < 1e-3 * flux);
    // Shadow casters: every instance but the shells around a light (instances 3 and 4).
    assert_eq!(area_lights::shadow_casters(&scene), [0, 1, 2]);
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

/// Point lights: the pass against its twin with a blocker (every pixel within 2 % and 0.01
/// nits, a few edge rays aside), the shadow there (dark behind the edge, lit before it), and
/// the deferred lighting leaving the light to the pass: the frame's radiance is the same with
/// the pass's point-light shading on or off where nothing blocks the light (no double count).
#[test]
fn point_lights_cast_ray_traced_shadows() {
    let (w, h) = (64u32, 16u32);
    let settings = |scene: &Scene, punctual_shadows: bool| {
        let mut s = common::small_frame_settings(scene, w, h);
        s.settings.area_lights.punctual_shadows = punctual_shadows;
        s.settings.area_lights.ray_budget = 8;
        s.settings.direct_lighting.placeholder_ambient = false;
        s
    };
    let scene = point_light_scene(true);
    let (renderer, f) = render(&scene, settings(&scene, true));
    assert!(f.params.shades_punctual());
    let blases = bvh::blases(&scene, &BuildOptions::default()).unwrap();
    let tlas = Tlas::build(
        &bvh::instances(&scene),
        &area_lights::shadow_casters(&scene),
        &blases,
    )
    .unwrap();
    let accept = |_, _, _, _| true;
    let twin_scene = TwinScene {
        blases: &blases,
        tlas: &tlas,
        accept: &accept,
    };
    let v4 = Vec4::from_array;
    let (mut bad, mut dark, mut lit) = (0, 0, 0);
    for y in 0..h {
        for x in 0..w {
            let texel = direct_lighting::reference::Texel {
                depth: f.depth.pixel(x, y)[0],
                normal: v4(f.normal.pixel(x, y)),
                albedo: v4(f.albedo.pixel(x, y)),
                material: v4(f.material.pixel(x, y)),
                emissive: v4(f.emissive.pixel(x, y)),
            };
            let world = world_at(&f, x, y);
            let want = reference::shade(
                &f.params,
                &renderer.area_lights().lights,
                &renderer.scene().cpu.lights,
                &twin_scene,
                [x, y],
                &texel,
                world,
                f.settings.camera.position,
            );
            let got = f.radiance.pixel(x, y);
            if (0..3).any(|k| (got[k] - want[k]).abs() > 0.02 * want[k] + 0.01) {
                bad += 1;
            }
            // Edge at x = 0 seen from the light 2 m up over a blocker at 1 m: the penumbra is
            // |x| < 0.05 m.
            if world.x < -0.1 {
                assert!(
                    got[1] < 1e-3,
                    "({x}, {y}) at {world}: {got:?} behind the edge"
                );
                dark += 1;
            } else if world.x > 0.1 {
                assert!(
                    got[1] > 1.0,
                    "({x}, {y}) at {world}: {got:?} before the edge"
                );
                lit += 1;
            }
        }
    }
    assert!(dark > 100 && lit > 100, "{dark} {lit}");
    assert!(bad <= 16, "{bad} pixels beyond the twin's tolerance");

    // No double count: unblocked, the frame is the same whichever pass shades the light.
    let open = point_light_scene(false);
    let frame = |on: bool| {
        let ctx = common::gpu_context();
        let mut r = Renderer::new(ctx, &open).unwrap();
        r.render(&settings(&open, on), true).unwrap().hdr.unwrap()
    };
    let (with_pass, without) = (frame(true), frame(false));
    for y in 0..h {
        for x in 0..w {
            let (a, b) = (with_pass.pixel(x, y), without.pixel(x, y));
            for k in 0..3 {
                assert!(
                    (a[k] - b[k]).abs() <= 4e-3 * b[k] + 1e-3,
                    "({x}, {y}): {a:?} with the pass, {b:?} without"
                );
            }
            assert!(b[1] > 1.0);
        }
    }
}

/// The GPU's unshadowed irradiance against the closed form: the pass's alpha (lux its lights
/// bring) on the open floor under the square light is luminance x E, E from the rectangle's
/// form factor at each pixel's floor point. Tolerance 0.5 %: f16 storage (2^-11) and f32
/// arithmetic.
#[test]
fn gpu_irradiance_of_a_square_light_matches_the_closed_form() {
    let side = 0.8f64;
    let scene = penumbra_scene(side as f32, false);
    let mut s = common::small_frame_settings(&scene, 64, 16);
    s.settings.area_lights.ray_budget = 1;
    let (_, f) = render(&scene, s);
    let luminance = 20000.0;
    let mut worst = 0f64;
    for y in 0..16 {
        for x in 0..64 {
            let p = world_at(&f, x, y).as_dvec3();
            assert!(p.y.abs() < 1e-3, "the floor: {p}");
            let h = 0.5 * side;
            let want = luminance * rectangle_closed_form(-h - p.x, h - p.x, -h - p.z, h - p.z, 2.0);
            let got = f.radiance.pixel(x, y)[3] as f64;
            let err = (got - want).abs() / want;
            worst = worst.max(err);
            assert!(
                err < 5e-3,
                "({x}, {y}) at {p}: {got} lux, closed form {want} lux"
            );
        }
    }
    println!("worst relative error {worst:e}");
}

/// The area lights' reach (beyond which the shader culls them per tile and the twin per pixel)
/// must be where a light's illuminance has fallen below the cut-off, in any direction, and not
/// far beyond it on the light's axis (the bound L A / (d - r)^2 tends to the far-field law).
#[test]
fn an_area_light_brings_less_than_the_cut_off_beyond_its_reach() {
    let nits = 1000.0f32;
    for &(side, cutoff) in &[(0.1f32, 0.01f32), (2.0, 0.01), (2.0, 100.0), (0.5, 5.0)] {
        let s = side as f64 * 0.5;
        let area = side * side;
        let params = AreaLightParams {
            values: [0.0, 0.0, cutoff, 0.0],
            ..Default::default()
        };
        let light = area_lights::AreaLightGpu {
            centroid_radius: [0.0, 0.0, 0.0, side * std::f32::consts::FRAC_1_SQRT_2],
            normal_area: [0.0, -1.0, 0.0, area],
            radiance_flux: [nits, nits, nits, std::f32::consts::PI * nits * area],
            range: [0; 4],
        };
        let reach = area_light_reach(&light, params.values[2]) as f64;
        // On the axis, facing the light: the closed form.
        let on_axis = nits as f64 * rectangle_closed_form(-s, s, -s, s, reach);
        assert!(
            on_axis <= cutoff as f64 && on_axis > 0.5 * cutoff as f64,
            "side {side} m, cut-off {cutoff} lux: {on_axis} lux on the axis at the reach {reach} m"
        );
        // Elsewhere below the light at the same distance, facing its centre.
        for &(x, z) in &[(0.5, 0.0), (0.7, 0.7), (-0.2, 0.9), (0.99, -0.1)] {
            let y = -(1.0f64 - x * x - z * z).max(0.0).sqrt();
            let p = DVec3::new(x, y, z).normalize() * reach;
            let q = rectangle(-s, s, -s, s, 0.0, p);
            let e = nits as f64 * polygon_vector_irradiance(&q, -p.normalize()).dot(-p.normalize());
            assert!(
                e <= cutoff as f64,
                "side {side} m, cut-off {cutoff} lux: {e} lux at {p} (reach {reach} m)"
            );
        }
    }
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

/// The village's `night_street` view with no sun or sky (the cut-off at its night floor,
/// 0.01 lux, as at 23:00), 64 x 48: every pixel of the GPU pass against the twin, which
/// picks the same lights by the same hash and traces the same rays on the CPU; and the budget
/// held (the twin counts its rays: at most `ray_budget` a pixel).
///
/// Tolerance as on the Cornell box: 2 % of the pixel plus 1 % of the image's mean, at most 3 %
/// of the lit pixels beyond it. Besides a ray grazing an edge, a pixel may differ where a pick
/// flips: f32 rounding of the pick's weight against the hash's uniform (about 1e-6 of a
/// chance per pick), or an instance the frame's BVH culls far from the camera that the
/// twin's whole-scene BVH keeps.
#[test]
fn village_at_night_gpu_matches_its_twin_within_the_ray_budget() {
    let village = hikari_scene::builtin::village();
    let (w, h) = (64u32, 48u32);
    let mut settings = common::small_frame_settings(&village, w, h);
    settings.camera = village
        .cameras
        .iter()
        .find(|c| c.name == "night_street")
        .expect("the village has a night_street camera")
        .clone();
    settings.sun = hikari_render::SunSource::Off;
    let budget = settings.settings.area_lights.ray_budget;
    let (renderer, f) = render(&village, settings);
    assert!(
        f.params.values[2] <= 0.0101,
        "night cut-off {}",
        f.params.values[2]
    );
    let lights = &renderer.area_lights().lights;
    let punctual = &renderer.scene().cpu.lights;
    let (blases, tlas) = twin_bvh(&village);
    let filter = SceneAlphaFilter::new(&village);
    let accept = |i, p, u, v| filter.accept(i, p, u, v);
    let twin_scene = TwinScene {
        blases: &blases,
        tlas: &tlas,
        accept: &accept,
    };
    let eye = f.settings.camera.position;
    let mut want = Vec::new();
    let (mut rays, mut most_rays, mut shaded, mut most_shaded) = (0u64, 0u32, 0usize, 0usize);
    let (mut most_area_in_reach, mut most_punctual) = (0usize, 0usize);
    for y in 0..h {
        for x in 0..w {
            let texel = texel_at(&f, x, y);
            let world = world_at(&f, x, y);
            let s = reference::shade_counted(
                &f.params,
                lights,
                punctual,
                &twin_scene,
                [x, y],
                &texel,
                world,
                eye,
            );
            assert!(s.rays <= budget, "({x}, {y}): {} rays", s.rays);
            rays += s.rays as u64;
            most_rays = most_rays.max(s.rays);
            if texel.depth > 0.0 {
                let shares =
                    reference::pixel_shares(&f.params, lights, punctual, &texel, world, eye);
                shaded += shares.len();
                most_shaded = most_shaded.max(shares.len());
                let np = shares
                    .iter()
                    .filter(|s| s.key & reference::PUNCTUAL_KEY != 0)
                    .count();
                most_punctual = most_punctual.max(np);
                let in_reach = lights
                    .lights
                    .iter()
                    .filter(|l| {
                        Vec3::from_slice(&l.centroid_radius[..3]).distance(world)
                            < area_light_reach(l, f.params.values[2])
                    })
                    .count();
                most_area_in_reach = most_area_in_reach.max(in_reach);
            }
            want.push(s);
        }
    }
    let pixels = (w * h) as f64;
    println!(
        "{} area lights, {} point and spot lights; shadow rays {:.2} a pixel (most {most_rays}, \
         budget {budget}); lights shaded {:.1} a pixel (most {most_shaded}); most area lights \
         in reach of a pixel {most_area_in_reach}, most point and spot lights lighting one \
         {most_punctual}",
        lights.lights.len(),
        punctual.len(),
        rays as f64 / pixels,
        shaded as f64 / pixels,
    );
    // The tile lists hold 256 lights of each kind: the whole village's fit, so no tile drops one.
    assert!(
        lights.lights.len() <= 256 && punctual.len() <= 256,
        "the tile lists of 256 could overflow"
    );
    let mean = want
        .iter()
        .map(|s| s.radiance.element_sum() / 3.0)
        .sum::<f32>()
        / want.len() as f32;
    let mean_lux = want.iter().map(|s| s.lux).sum::<f32>() / want.len() as f32;
    assert!(
        mean > 0.0 && rays > 0,
        "the street is lit at night: mean {mean} nits, {rays} rays"
    );
    let (mut bad, mut lit, mut worst) = (0, 0, 0f32);
    for y in 0..h {
        for x in 0..w {
            let s = want[(y * w + x) as usize];
            let g = f.radiance.pixel(x, y);
            lit += (s.radiance.max_element() > 0.0) as usize;
            let mut px = (g[3] - s.lux).abs() / (0.02 * s.lux + 0.01 * mean_lux);
            for (k, gk) in g.iter().take(3).enumerate() {
                let tol = 0.02 * s.radiance[k].abs() + 0.01 * mean;
                px = px.max((gk - s.radiance[k]).abs() / tol);
            }
            worst = worst.max(px);
            bad += (px > 1.0) as usize;
        }
    }
    println!("lit {lit}, beyond tolerance {bad}, worst {worst} x tolerance");
    assert!(lit * 2 > (w * h) as usize, "{lit}");
    assert!(
        bad * 100 <= lit * 3,
        "{bad} of {lit} pixels beyond tolerance"
    );
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

/// The budget's picks are unbiased: on the many-lights scene at 32 x 24 with a budget of 3 rays
/// (fewer than its 5 area and 3 point lights), the twin's mean over 256 frames (a new pick and
/// rotation each frame) against the same lights without a budget, each with its own 1024 rays.
///
/// Bound: each pixel's mean within 4 standard errors (its frames' spread / 16) plus 0.5 % of
/// its value (the unbudgeted reference's own noise and the ratio estimator's small bias with
/// few rays, small here: the lights are 5 cm wide) in at least 99 % of the lit pixels, and the
/// image's total within 4 of its standard errors plus 0.1 %. The
/// budget is held in every frame (the twin counts its rays), and the GPU's first frame is the
/// twin's (the same tolerance as on the Cornell box).
#[test]
fn budgeted_shadows_average_to_the_unbudgeted_light() {
    let scene = many_lights_scene();
    let (w, h) = (32u32, 24u32);
    let mut settings = common::small_frame_settings(&scene, w, h);
    settings.settings.area_lights.ray_budget = 3;
    settings.settings.area_lights.lights_per_pixel = 8;
    settings.settings.direct_lighting.placeholder_ambient = false;
    let (renderer, f) = render(&scene, settings);
    let lights = &renderer.area_lights().lights;
    assert_eq!(lights.lights.len(), 5, "{:?}", lights.skipped);
    let punctual = &renderer.scene().cpu.lights;
    let (blases, tlas) = twin_bvh(&scene);
    let accept = |_, _, _, _| true;
    let twin_scene = TwinScene {
        blases: &blases,
        tlas: &tlas,
        accept: &accept,
    };
    let eye = f.settings.camera.position;
    let frames = 256u64;
    let gpu_mean = (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .map(|(x, y)| f.radiance.pixel(x, y)[..3].iter().sum::<f32>() / 3.0)
        .sum::<f32>()
        / (w * h) as f32;
    let (mut bad_gpu, mut bad, mut lit, mut most_rays) = (0, 0, 0, 0);
    let (mut sum_mean, mut sum_want, mut var_sum) = (0f64, 0f64, 0f64);
    for y in 0..h {
        for x in 0..w {
            let texel = texel_at(&f, x, y);
            let world = world_at(&f, x, y);
            let (want, _) = reference::shade_unbudgeted(
                &f.params,
                lights,
                punctual,
                &twin_scene,
                [x, y],
                &texel,
                world,
                eye,
                1024,
            );
            let want = want.element_sum() as f64;
            let (mut s1, mut s2) = (0f64, 0f64);
            for frame in 0..frames {
                let p = AreaLightParams {
                    config: [
                        f.params.config[0],
                        f.params.config[1],
                        frame as u32,
                        f.params.config[3],
                    ],
                    rotation: area_lights::frame_rotation(frame),
                    ..f.params
                };
                let s = reference::shade_counted(
                    &p,
                    lights,
                    punctual,
                    &twin_scene,
                    [x, y],
                    &texel,
                    world,
                    eye,
                );
                assert!(s.rays <= 3, "({x}, {y}) frame {frame}: {} rays", s.rays);
                most_rays = most_rays.max(s.rays);
                if frame == 0 {
                    let g = f.radiance.pixel(x, y);
                    if (0..3).any(|k| {
                        (g[k] - s.radiance[k]).abs() > 0.02 * s.radiance[k] + 0.01 * gpu_mean
                    }) {
                        bad_gpu += 1;
                    }
                }
                let v = s.radiance.element_sum() as f64;
                s1 += v;
                s2 += v * v;
            }
            let mean = s1 / frames as f64;
            let var = (s2 / frames as f64 - mean * mean).max(0.0);
            let se = (var / frames as f64).sqrt();
            if want > 0.0 {
                lit += 1;
                if (mean - want).abs() > 4.0 * se + 5e-3 * want {
                    bad += 1;
                    println!("({x}, {y}): mean {mean} vs {want}, standard error {se}");
                }
            }
            sum_mean += mean;
            sum_want += want;
            var_sum += var / frames as f64;
        }
    }
    let total_error = (sum_mean - sum_want).abs() / sum_want;
    println!(
        "{lit} lit pixels, {bad} beyond 4 standard errors; image total {sum_mean:.1} vs \
         {sum_want:.1} (relative {total_error:.2e}, standard error {:.2e}); most rays {most_rays}; \
         GPU frame 0 off the twin at {bad_gpu} pixels",
        var_sum.sqrt() / sum_want
    );
    assert!(lit > 500, "{lit}");
    assert_eq!(most_rays, 3, "the budget is used");
    assert!(bad * 100 <= lit, "{bad} of {lit} pixels biased");
    assert!(
        total_error < 4.0 * var_sum.sqrt() / sum_want + 1e-3,
        "image total off by {total_error}"
    );
    assert!(
        bad_gpu * 100 <= lit * 3,
        "GPU off the twin at {bad_gpu} pixels"
    );
}

// ---- A radius per point or spot light ----

/// The exact visibility of a disc light of radius `r` (facing straight down, at 2 m) from the
/// floor at `x` behind an edge at x = 0, 1 m up: the part of the disc with X >= -x, a circular
/// segment, over the disc.
fn disc_visibility(x: f64, r: f64) -> f64 {
    let t = (x / r).clamp(-1.0, 1.0);
    ((-t).acos() + t * (1.0 - t * t).sqrt()) / std::f64::consts::PI
}

/// A point light's own radius (`Light::radius_m`) sets its penumbra, overriding the setting
/// (0.05 m here): the 10-90 % width of the shadow factor (shadowed over unshadowed light, 32
/// rays a pixel, 16 rows a column) is within 20 % and 2 columns of the exact disc's, for the
/// setting's 0.05 m and a light's own 0.25 m, and the bigger radius's is over 3 times wider.
#[test]
fn a_lights_own_radius_widens_its_penumbra() {
    let (w, h) = (64u32, 16u32);
    let mut widths = Vec::new();
    for (own, r) in [(None, 0.05f32), (Some(0.25f32), 0.25)] {
        let mut scene = point_light_scene(true);
        scene.lights[0].radius_m = own;
        let mut s = common::small_frame_settings(&scene, w, h);
        s.settings.area_lights.ray_budget = 32;
        s.settings.area_lights.punctual_radius_m = 0.05;
        s.settings.taa.enabled = false;
        let (_, f) = render(&scene, s);
        let (mut gpu, mut exact, mut xs) = (vec![0f32; w as usize], vec![0f32; w as usize], vec![]);
        for x in 0..w {
            let mut sum_x = 0.0;
            for y in 0..h {
                let p = world_at(&f, x, y);
                sum_x += p.x;
                let (a, b) = (f.radiance.pixel(x, y)[1], f.unshadowed.pixel(x, y)[1]);
                assert!(b > 0.0, "({x}, {y}) unlit");
                gpu[x as usize] += a / b / h as f32;
                exact[x as usize] += disc_visibility(p.x as f64, r as f64) as f32 / h as f32;
            }
            xs.push(sum_x / h as f32);
        }
        let width = |v: &[f32]| (crossing(&xs, v, 0.9) - crossing(&xs, v, 0.1)).abs();
        let (g, e) = (width(&gpu), width(&exact));
        let column = (xs[1] - xs[0]).abs();
        println!("radius {r} m: penumbra 10-90 % {g} m (exact {e} m), column {column} m");
        assert!(
            (g - e).abs() <= 0.2 * e + 2.0 * column,
            "radius {r}: {g} vs {e}"
        );
        widths.push(g);
    }
    assert!(widths[1] > 3.0 * widths[0], "{widths:?}");
}

// ---- The shadow denoiser ----

/// The G-buffer of the point-light penumbra scene (64 x 16, TAA off so the view has no
/// jitter), with its right quarter pushed to another depth and a band of rows given another
/// normal, so that the edge-aware weights have edges to stop at.
struct DenoiseRig {
    ctx: hikari_render::GpuContext,
    denoiser: area_lights::ShadowDenoiser,
    rt: hikari_render::graph::GraphRuntime,
    view: hikari_render::view::View,
    w: u32,
    h: u32,
    depth: Vec<f32>,
    normal: Vec<[f32; 4]>,
    motion: Vec<[f32; 4]>,
}

/// What one frame of the denoiser wrote.
struct DenoiseOut {
    raw: Vec<[f32; 4]>,
    history: reference::VisibilityHistory,
    filtered: Vec<[f32; 4]>,
    radiance: Vec<[f32; 4]>,
}

fn f16r(v: f32) -> f32 {
    half::f16::from_f32(v).to_f32()
}

fn f16r4(v: [f32; 4]) -> [f32; 4] {
    v.map(f16r)
}

impl DenoiseRig {
    fn new() -> Self {
        let (w, h) = (64u32, 16u32);
        let scene = point_light_scene(true);
        let mut s = common::small_frame_settings(&scene, w, h);
        s.settings.taa.enabled = false;
        let ctx = common::gpu_context();
        let mut renderer = Renderer::new(ctx, &scene).unwrap();
        let mut r = renderer
            .render_reading(&s, |o| {
                let g = &o.gbuffer;
                vec![g.depth.into(), g.normal.into(), g.motion.into()]
            })
            .unwrap();
        let mut depth: Vec<f32> = r
            .take_image("gbuffer.depth")
            .unwrap()
            .rgba
            .iter()
            .map(|p| p[0])
            .collect();
        let mut normal = r.take_image("gbuffer.normal").unwrap().rgba;
        let motion = r.take_image("gbuffer.motion").unwrap().rgba;
        for y in 0..h {
            for x in 0..w {
                let i = (y * w + x) as usize;
                if x >= 48 {
                    depth[i] *= 0.8;
                }
                if (6..9).contains(&y) {
                    let n = hikari_render::reference::octahedral::encode(
                        Vec3::new(0.6, 0.8, 0.0).normalize(),
                    );
                    normal[i] = f16r4([n.x, n.y, normal[i][2], normal[i][3]]);
                }
            }
        }
        let ctx = common::gpu_context();
        let mut lib =
            hikari_render::shader::library(hikari_render::shader::capabilities_for(ctx.features))
                .unwrap();
        let denoiser = area_lights::ShadowDenoiser::new(&ctx, &mut lib).unwrap();
        let mut rt = hikari_render::graph::GraphRuntime::new();
        rt.set_dumps(
            [
                "area_lights.visibility_raw",
                "area_lights.visibility_accumulated",
                "area_lights.visibility_history_length",
                "area_lights.visibility_view_depth",
                "area_lights.visibility_filtered",
                "area_lights.denoised",
            ]
            .iter()
            .map(|s| s.to_string())
            .collect(),
        );
        Self {
            ctx,
            denoiser,
            rt,
            view: hikari_render::view::View::new(&s.camera, w, h),
            w,
            h,
            depth,
            normal,
            motion,
        }
    }

    fn input<'a>(
        &'a self,
        normal_oct: &'a [[f32; 2]],
        shadowed: &'a [[f32; 4]],
        unshadowed: &'a [[f32; 4]],
    ) -> reference::DenoiseInput<'a> {
        reference::DenoiseInput {
            width: self.w,
            height: self.h,
            depth: &self.depth,
            normal_oct,
            motion: &self.motion,
            shadowed,
            unshadowed,
        }
    }

    fn oct(&self) -> Vec<[f32; 2]> {
        self.normal.iter().map(|n| [n[0], n[1]]).collect()
    }

    /// One frame of both passes on the GPU; the inputs are rounded to f16 as uploaded.
    fn frame(
        &mut self,
        params: &area_lights::ShadowDenoiseParams,
        shadowed: &[[f32; 4]],
        unshadowed: &[[f32; 4]],
    ) -> DenoiseOut {
        use wgpu::TextureFormat as F;
        let (w, h) = (self.w, self.h);
        let halves = |v: &[[f32; 4]]| -> Vec<u8> {
            let hs: Vec<half::f16> = v
                .iter()
                .flatten()
                .map(|x| half::f16::from_f32(*x))
                .collect();
            bytemuck::cast_slice(&hs).to_vec()
        };
        let tex = |f, d: &[u8]| common::texture_with_data(&self.ctx, f, w, h, d);
        let depth = tex(F::R32Float, bytemuck::cast_slice(&self.depth));
        let normal = tex(F::Rgba16Float, &halves(&self.normal));
        let motion = tex(F::Rgba16Float, &halves(&self.motion));
        let sh = tex(F::Rgba16Float, &halves(shadowed));
        let un = tex(F::Rgba16Float, &halves(unshadowed));
        let mut g = self.rt.begin_frame(&self.ctx);
        let inputs = area_lights::ShadowDenoiseInputs {
            depth: g.import_texture("test.depth", &depth),
            normal: g.import_texture("test.normal", &normal),
            motion: g.import_texture("test.motion", &motion),
            shadowed: g.import_texture("test.shadowed", &sh),
            unshadowed: g.import_texture("test.unshadowed", &un),
        };
        self.denoiser
            .record(&mut g, &self.view, params, &inputs, [w, h])
            .unwrap();
        let r = g.execute().unwrap();
        let img = |n: &str| r.image(n).unwrap().rgba.clone();
        let first = |n: &str| img(n).iter().map(|p| p[0]).collect::<Vec<f32>>();
        DenoiseOut {
            raw: img("area_lights.visibility_raw"),
            history: reference::VisibilityHistory {
                visibility: img("area_lights.visibility_accumulated"),
                length: first("area_lights.visibility_history_length"),
                view_depth: first("area_lights.visibility_view_depth"),
            },
            filtered: img("area_lights.visibility_filtered"),
            radiance: img("area_lights.denoised"),
        }
    }
}

/// A noisy penumbra: unshadowed light `u` on every surface pixel, true visibility a ramp from 0
/// (column 16) to 1 (column 40), and each frame's shadowed light u x k / 4 with k of 4 rays
/// passing (binomial), as the pass's ratio estimator gives with 4 rays.
fn true_visibility(x: u32) -> f32 {
    ((x as f32 + 0.5 - 16.0) / 24.0).clamp(0.0, 1.0)
}

const UNSHADOWED: [f32; 4] = [2.0, 1.5, 1.0, 3.0];

fn noisy_frame(rig: &DenoiseRig, rng: &mut impl rand::Rng) -> (Vec<[f32; 4]>, Vec<[f32; 4]>) {
    let (mut s, mut u) = (Vec::new(), Vec::new());
    for y in 0..rig.h {
        for x in 0..rig.w {
            let i = (y * rig.w + x) as usize;
            if rig.depth[i] <= 0.0 {
                s.push([0.0; 4]);
                u.push([0.0; 4]);
                continue;
            }
            let v = true_visibility(x);
            let k = (0..4).filter(|_| rng.random::<f32>() < v).count() as f32;
            s.push(UNSHADOWED.map(|c| c * k / 4.0));
            u.push(UNSHADOWED);
        }
    }
    (s, u)
}

fn assert_close4(what: &str, w: u32, gpu: &[[f32; 4]], cpu: &[[f32; 4]], rel: f32, abs: f32) {
    let mut bad = Vec::new();
    for (i, (g, c)) in gpu.iter().zip(cpu).enumerate() {
        for k in 0..4 {
            let tol = rel * c[k].abs() + abs;
            // Written so that NaN fails.
            let ok = (g[k] - c[k]).abs() <= tol;
            if !ok {
                bad.push((i as u32 % w, i as u32 / w, k, g[k], c[k]));
            }
        }
    }
    assert!(
        bad.is_empty(),
        "{what}: {} channels beyond tolerance, first {:?}",
        bad.len(),
        &bad[..bad.len().min(6)]
    );
}

/// Both passes against their CPU twins over 5 frames of a noisy penumbra (frame 3 a camera
/// cut), each pass fed what its GPU pass read (the temporal pass last frame's GPU history, the
/// spatial pass this frame's). Tolerance: f16 storage of the outputs (2^-11 relative) and f32
/// order of sums: 2e-3 relative + 2e-3 (visibility), 2e-3 relative + 1e-3 nits (light); the
/// history length and view depth exactly (f16 holds small integers; depth is copied).
#[test]
fn shadow_denoiser_passes_match_their_cpu_twins() {
    use rand::SeedableRng;
    let mut rig = DenoiseRig::new();
    let mut rng = rand::rngs::SmallRng::seed_from_u64(18);
    let settings = area_lights::AreaLightsSettings::default();
    let oct = rig.oct();
    let mut prev: Option<reference::VisibilityHistory> = None;
    for frame in 0..5 {
        let cut = frame == 3;
        let params = area_lights::ShadowDenoiseParams::new(&settings, cut);
        if frame == 1 {
            // From here on a block moves by a fraction of a pixel: the bilinear reprojection.
            for y in 8..16 {
                for x in 8..16 {
                    let m = &mut rig.motion[(y * rig.w + x) as usize];
                    m[0] = 0.5;
                    m[1] = -0.25;
                }
            }
        }
        // Frame 1 records a wrong view depth in a few still pixels (as if they saw another
        // surface): on frame 2 their own texel fails the depth test and the 3x3 about it
        // stands in (SVGF's fallback), so they keep their history.
        let damaged: Vec<usize> = (3..6).map(|y| (y * rig.w + 40) as usize).collect();
        for &i in &damaged {
            match frame {
                1 => rig.motion[i][2] *= 3.0,
                2 => rig.motion[i][2] /= 3.0,
                _ => {}
            }
        }
        let (s, u) = noisy_frame(&rig, &mut rng);
        let out = rig.frame(&params, &s, &u);
        let (s16, u16): (Vec<_>, Vec<_>) = (
            s.iter().map(|v| f16r4(*v)).collect(),
            u.iter().map(|v| f16r4(*v)).collect(),
        );
        let input = rig.input(&oct, &s16, &u16);
        // The graph's first frame has no valid history: the GPU resets by itself.
        let mut p = params;
        if frame == 0 {
            p.config[0] |= area_lights::denoise::SHADOW_DENOISE_RESET;
        }
        let (raw, hist) = reference::denoise_temporal(&p, &rig.view, &input, prev.as_ref());
        let w = rig.w;
        assert_close4(&format!("frame {frame} raw"), w, &out.raw, &raw, 2e-3, 2e-3);
        assert_close4(
            &format!("frame {frame} accumulated"),
            w,
            &out.history.visibility,
            &hist.visibility,
            2e-3,
            2e-3,
        );
        assert_eq!(
            out.history.length, hist.length,
            "frame {frame} history length"
        );
        assert_eq!(
            out.history.view_depth, hist.view_depth,
            "frame {frame} view depth"
        );
        // Frames since the last reset (the first frame, the cut at frame 3).
        let expected_len = if frame >= 3 {
            frame as f32 - 2.0
        } else {
            frame as f32 + 1.0
        };
        let lit = out
            .history
            .length
            .iter()
            .filter(|&&l| l == expected_len)
            .count();
        assert!(
            lit > (w * rig.h) as usize / 2,
            "frame {frame}: {lit} pixels of length {expected_len}"
        );
        if frame == 2 {
            for &i in &damaged {
                assert_eq!(
                    out.history.length[i], 3.0,
                    "damaged pixel {i} lost its history"
                );
            }
        }
        let (filtered, light) = reference::denoise_spatial(&p, &rig.view, &input, &out.history);
        assert_close4(
            &format!("frame {frame} filtered"),
            w,
            &out.filtered,
            &filtered,
            2e-3,
            2e-3,
        );
        assert_close4(
            &format!("frame {frame} light"),
            w,
            &out.radiance,
            &light,
            2e-3,
            1e-3,
        );
        prev = Some(out.history);
    }
}

/// The denoised penumbra's noise drops and its mean stays. Against the exact answer (the ramp
/// times the unshadowed light, which the noisy input averages to):
/// - frame 0 (the spatial filter alone, radius 3 px): the variance over each column's rows
///   (one true value a column), summed over the penumbra's columns, is under 0.3 of the raw
///   input's;
/// - frames 32-63 (history at its cap of 16, the spatial radius 3 / 4 px: the pixel alone): the
///   mean square error against the exact value, pooled over the penumbra's pixels and frames, is
///   under 0.1 of the raw input's (an exponential average of weight 1/16 leaves 1/31);
/// - bias: the mean over those frames and the penumbra's pixels is within 0.01 x the unshadowed
///   light of the exact mean, each column's within 0.05 (about 3 and 4 standard errors: the
///   history's frames are correlated, about one independent sample per 31 frames).
#[test]
fn denoised_penumbra_noise_drops_and_its_mean_stays() {
    use rand::SeedableRng;
    let mut rig = DenoiseRig::new();
    let mut rng = rand::rngs::SmallRng::seed_from_u64(7);
    let settings = area_lights::AreaLightsSettings::default();
    let params = area_lights::ShadowDenoiseParams::new(&settings, false);
    let (w, h) = (rig.w, rig.h);
    // Rows of the floor's own normal and depth (the band and the right quarter aside).
    let plain = |x: u32, y: u32| x < 48 && !(6..9).contains(&y);
    let light = UNSHADOWED[1] as f64;
    let frames = 64;
    let (mut mse, mut mse_raw, mut count) = (0f64, 0f64, 0f64);
    let mut columns = vec![(0f64, 0f64); w as usize];
    for frame in 0..frames {
        let (s, u) = noisy_frame(&rig, &mut rng);
        let out = rig.frame(&params, &s, &u);
        if frame == 0 {
            let (mut var_raw, mut var_out) = (0.0, 0.0);
            for x in 18..38 {
                let column = |v: &dyn Fn(u32) -> f32| {
                    let vals: Vec<f32> = (0..h).filter(|&y| plain(x, y)).map(v).collect();
                    let m = vals.iter().sum::<f32>() / vals.len() as f32;
                    vals.iter().map(|a| (a - m) * (a - m)).sum::<f32>() / vals.len() as f32
                };
                var_raw += column(&|y| s[(y * w + x) as usize][1]);
                var_out += column(&|y| out.radiance[(y * w + x) as usize][1]);
            }
            println!("frame 0: row variance {var_out} denoised, {var_raw} raw");
            assert!(var_out < 0.3 * var_raw, "{var_out} vs {var_raw}");
        }
        if frame >= frames / 2 {
            for x in 20..36 {
                let exact = true_visibility(x) as f64 * light;
                for y in (0..h).filter(|&y| plain(x, y)) {
                    let i = (y * w + x) as usize;
                    let (a, b) = (out.radiance[i][1] as f64, s[i][1] as f64);
                    mse += (a - exact).powi(2);
                    mse_raw += (b - exact).powi(2);
                    count += 1.0;
                    columns[x as usize].0 += a - exact;
                    columns[x as usize].1 += 1.0;
                }
            }
        }
    }
    let ratio = mse / mse_raw;
    let bias = columns.iter().map(|c| c.0).sum::<f64>() / count / light;
    let worst = columns
        .iter()
        .filter(|c| c.1 > 0.0)
        .map(|c| (c.0 / c.1 / light).abs())
        .fold(0.0, f64::max);
    println!("frames 32-63: error ratio {ratio}, bias {bias}, worst column {worst} of the light");
    assert!(ratio < 0.1, "mean square error {mse} vs raw {mse_raw}");
    assert!(bias.abs() < 0.01, "bias {bias}");
    assert!(worst < 0.05, "worst column bias {worst}");
}

/// NaN and infinity in any input (shadowed and unshadowed light, depth, normal, motion) never
/// reach the history or the output: every texel of every output is finite over 4 frames, and
/// pixels 4 or more pixels away from the poisoned ones (beyond the filter's reach of 3) match a
/// clean run's.
#[test]
fn nan_in_the_denoisers_inputs_never_reaches_its_outputs() {
    use rand::SeedableRng;
    let settings = area_lights::AreaLightsSettings::default();
    let params = area_lights::ShadowDenoiseParams::new(&settings, false);
    let poisoned = [(20u32, 4u32), (30, 10), (25, 13), (40, 2), (10, 8)];
    let run = |poison: bool| {
        let mut rig = DenoiseRig::new();
        let mut rng = rand::rngs::SmallRng::seed_from_u64(3);
        let w = rig.w;
        if poison {
            let idx = |(x, y): (u32, u32)| (y * w + x) as usize;
            rig.depth[idx(poisoned[2])] = f32::NAN;
            rig.normal[idx(poisoned[3])] = [f32::NAN, 0.0, 0.0, 0.0];
            rig.motion[idx(poisoned[4])] = [f32::INFINITY, 0.0, f32::NAN, 0.0];
        }
        let mut outs = Vec::new();
        for _ in 0..4 {
            let (mut s, mut u) = noisy_frame(&rig, &mut rng);
            if poison {
                s[(poisoned[0].1 * w + poisoned[0].0) as usize] =
                    [f32::NAN, f32::INFINITY, 1.0, f32::NAN];
                u[(poisoned[1].1 * w + poisoned[1].0) as usize] =
                    [f32::INFINITY, f32::NAN, 1.0, -f32::INFINITY];
            }
            outs.push(rig.frame(&params, &s, &u));
        }
        (w, outs)
    };
    let (w, bad) = run(true);
    let (_, clean) = run(false);
    for (f, (b, c)) in bad.iter().zip(&clean).enumerate() {
        let images = [
            ("accumulated", &b.history.visibility, &c.history.visibility),
            ("filtered", &b.filtered, &c.filtered),
            ("light", &b.radiance, &c.radiance),
        ];
        for (what, bi, ci) in images {
            for (i, (p, q)) in bi.iter().zip(ci.iter()).enumerate() {
                let (x, y) = (i as u32 % w, i as u32 / w);
                assert!(
                    p.iter().all(|v| v.is_finite()),
                    "frame {f} {what} ({x}, {y}): {p:?}"
                );
                let far = poisoned
                    .iter()
                    .all(|&(px, py)| px.abs_diff(x).max(py.abs_diff(y)) >= 4);
                if far {
                    assert_eq!(
                        p, q,
                        "frame {f} {what} ({x}, {y}) changed by a poisoned pixel"
                    );
                }
            }
        }
        assert!(b.history.length.iter().all(|l| l.is_finite()));
    }
}

/// The denoiser in the frame: its history grows one frame at a time on a still view, and a
/// camera cut or a resize starts it again (length 1 on every surface pixel); with `denoise` off
/// it does not run and the deferred lighting adds the raw light.
#[test]
fn the_frames_shadow_history_grows_and_resets_on_a_cut_or_a_resize() {
    let scene = point_light_scene(true);
    let ctx = common::gpu_context();
    let mut renderer = Renderer::new(ctx, &scene).unwrap();
    let mut lengths = |s: &FrameSettings| -> Vec<f32> {
        let mut r = renderer
            .render_reading(s, |o| {
                let d = o.area_lights_denoised.expect("the denoiser runs");
                vec![d.history_length.into(), o.gbuffer.depth.into()]
            })
            .unwrap();
        let depth = r.take_image("gbuffer.depth").unwrap().rgba;
        let len = r
            .take_image("area_lights.visibility_history_length")
            .unwrap()
            .rgba;
        len.iter()
            .zip(&depth)
            .filter(|(_, d)| d[0] > 0.0)
            .map(|(l, _)| l[0])
            .collect()
    };
    let all = |v: &[f32], want: f32| !v.is_empty() && v.iter().all(|&l| l == want);
    let still = common::small_frame_settings(&scene, 32, 16);
    for frame in 1..=3 {
        let l = lengths(&still);
        assert!(all(&l, frame as f32), "still frame {frame}: {l:?}");
    }
    // A cut: another camera that claims it did not move.
    let mut cut = still.clone();
    cut.camera.position += Vec3::new(0.05, 0.0, 0.0);
    cut.camera.target += Vec3::new(0.05, 0.0, 0.0);
    let l = lengths(&cut);
    assert!(all(&l, 1.0), "after a cut: {l:?}");
    assert!(all(&lengths(&cut), 2.0));
    let mut resized = cut.clone();
    resized.width = 24;
    let l = lengths(&resized);
    assert!(all(&l, 1.0), "after a resize: {l:?}");

    // Off: no denoiser, and the frame's radiance is the raw pass's.
    let mut off = still.clone();
    off.settings.area_lights.denoise = false;
    renderer
        .render_reading(&off, |o| {
            assert!(o.area_lights_denoised.is_none());
            vec![]
        })
        .unwrap();
}

/// A textured emitter lights the floor by its texture, not by its mean colour: the square light
/// of `penumbra_scene` (0.8 m, 2 m above the floor, 20 000 nits) with a 16 x 1 emissive
/// texture, white on its -x half and black on its +x half (sRGB, clamped, bilinear). The
/// closed form takes the light at its mean (10 000 nits); the shadow rays' ratio carries the
/// texture (`texture_factor`). Reference: the floor's illuminance by a 400 x 400 midpoint
/// quadrature of L T(u) cos cos / d² over the light, T the texture's bilinear luminance
/// written here. Compared per image column (16 rows, 48 frames of 8 rays: 6144 rays a
/// column) within 6 % (measured 3.5 % at 32 frames); the uniform mean's prediction is off by
/// more than 15 % somewhere (23 %), so a pass that ignored the texture fails. The twin's `texture_factor` is held to the same
/// texture function at a few points.
#[test]
fn a_textured_light_lights_by_its_texture() {
    let mut scene = penumbra_scene(0.8, false);
    let texels = 16usize;
    let value = |i: i64| if i < (texels / 2) as i64 { 1.0f64 } else { 0.0 };
    let lum = |u: f64| {
        let x = u * texels as f64 - 0.5;
        let i0 = x.floor();
        let f = x - i0;
        let at = |i: i64| value(i.clamp(0, texels as i64 - 1));
        at(i0 as i64) * (1.0 - f) + at(i0 as i64 + 1) * f
    };
    scene.textures.push(hikari_scene::Texture {
        name: "half white".into(),
        width: texels as u32,
        height: 1,
        data: (0..texels)
            .flat_map(|i| {
                let c = if value(i as i64) > 0.0 { 255 } else { 0 };
                [c, c, c, 255]
            })
            .collect(),
        wrap_s: hikari_scene::Wrap::ClampToEdge,
        wrap_t: hikari_scene::Wrap::ClampToEdge,
    });
    scene.materials[1].emissive_texture = Some(hikari_scene::TextureRef {
        texture: 0,
        uv_set: 0,
    });
    // UVs over the whole light: u = (x + 0.4) / 0.8 (mesh x is world x under the flip).
    let light_mesh = &mut scene.meshes[1];
    light_mesh.uvs = light_mesh
        .positions
        .iter()
        .map(|p| glam::Vec2::new((p.x + 0.4) / 0.8, (p.z + 0.4) / 0.8))
        .collect();
    let (w, h) = (64u32, 16u32);
    let mut s = common::small_frame_settings(&scene, w, h);
    s.settings.area_lights.ray_budget = 8;
    s.settings.area_lights.lights_per_pixel = 1;
    // Higher than the scene's camera: the floor from x = -1.6 to 1.6 m.
    s.camera.position = Vec3::new(0.0, 1.5, 0.0);
    let (_, first) = render(&scene, s.clone());
    let lights = PolygonLights::for_scene(&scene);
    assert_eq!(lights.lights.len(), 1, "{:?}", lights.skipped);
    assert_eq!(lights.lights[0].range[3], 2, "material 1, textured");
    // The twin's texture function is the one above.
    for &(b, u) in &[
        (Vec3::new(1.0, 0.0, 0.0), 0.0),
        (Vec3::new(0.0, 0.0, 1.0), 1.0),
        (Vec3::new(0.5, 0.0, 0.5), 0.5),
    ] {
        // Triangle 0 of the plane: vertices 0 (u 0), 1 (u 0), 2 (u 1).
        let got = reference::texture_factor(&lights, 0, 0, b) as f64;
        let want = lum(u) / 0.5;
        assert!(
            (got - want).abs() < 1e-4,
            "twin at u {u}: {got}, want {want}"
        );
    }
    let mut renderer = Renderer::new(common::gpu_context(), &scene).unwrap();
    let frames = 48;
    let mut sum = vec![0f64; (w * h) as usize];
    for _ in 0..frames {
        let mut r = renderer
            .render_reading(&s, |o| vec![o.area_lights.into()])
            .unwrap();
        let img = r.take_image("area_lights.radiance").unwrap();
        for (acc, p) in sum.iter_mut().zip(&img.rgba) {
            *acc += p[3] as f64 / frames as f64;
        }
    }
    let quadrature = |p: DVec3, texture: bool| {
        let n = 400;
        let da = (0.8 / n as f64) * (0.8 / n as f64);
        let mut e = 0.0;
        for i in 0..n {
            let x = -0.4 + 0.8 * (i as f64 + 0.5) / n as f64;
            let t = if texture { lum((x + 0.4) / 0.8) } else { 0.5 };
            for k in 0..n {
                let z = -0.4 + 0.8 * (k as f64 + 0.5) / n as f64;
                let d2 = (x - p.x).powi(2) + 4.0 + (z - p.z).powi(2);
                e += 20000.0 * t * 4.0 / (d2 * d2) * da;
            }
        }
        e
    };
    let (mut worst, mut uniform_off) = (0f64, 0f64);
    for x in 0..w {
        let (mut got, mut want, mut uniform) = (0.0, 0.0, 0.0);
        for y in 0..h {
            let p = world_at(&first, x, y).as_dvec3();
            got += sum[(y * w + x) as usize];
            want += quadrature(p, true);
            uniform += quadrature(p, false);
        }
        let err = (got - want).abs() / want;
        worst = worst.max(err);
        uniform_off = uniform_off.max((uniform - want).abs() / want);
        assert!(
            err < 0.06,
            "column {x}: {got} lux (sum of 16 rows), quadrature {want}"
        );
    }
    println!("worst column error {worst:.4}; the uniform mean would be off by {uniform_off:.3}");
    assert!(
        uniform_off > 0.15,
        "the texture must matter here: {uniform_off}"
    );
}
