//! The polygonal lights' irradiance against closed forms and Mitsuba 3, and their reach.

use super::*;

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
    let (mw, mh, mitsuba) = read_pfm(include_bytes!(
        "../../fixtures/mitsuba_cornell_direct_64.pfm"
    ));
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
