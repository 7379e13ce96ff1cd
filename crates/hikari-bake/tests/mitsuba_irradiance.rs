//! Baked sky visibility plus bounced sky visibility against Mitsuba 3.
//!
//! `tools/mitsuba_probe_irradiance.py` renders, with Mitsuba 3's `path` integrator at
//! `max_depth` 2 (the sky seen directly plus one bounce) and a `constant` environment of
//! radiance 1, the irradiance at probe positions for several normals in a scene of Lambertian
//! boxes (ground, wall, overhanging roof, pillar), into `fixtures/mitsuba_irradiance.json`.
//! Here the same boxes are baked with the default ray counts, and each probe's irradiance is
//! the SH convolved with the clamped cosine (`Â_l` = π, 2π/3, π/4) and evaluated at the
//! normal: `E(n) = Σ Â_l (V_lm + B_lm) Y_lm(n)` for a sky of radiance 1. The mean relative
//! error over all probes, normals and channels must stay under 5 % (L2 SH's truncation of
//! sharp horizons is part of what this measures).

use glam::{Mat4, Vec3};
use hikari_bake::scene_rays::SceneRays;
use hikari_bake::sky_visibility::SphereRays;
use hikari_bake::surfaces::SurfaceAlbedo;
use hikari_bake::transport::probe_transport;
use hikari_bake::{DEFAULT_BOUNCE_RAYS, DEFAULT_RAYS_PER_PROBE};
use hikari_bvh::TraversalStacks;
use hikari_math::sh::basis::eval_l2;
use hikari_scene::{Instance, Material, Scene, shapes};
use serde_json::Value;
use std::f32::consts::PI;

fn vec3(v: &Value) -> Vec3 {
    let a: Vec<f32> = v
        .as_array()
        .expect("array")
        .iter()
        .map(|x| x.as_f64().expect("number") as f32)
        .collect();
    Vec3::new(a[0], a[1], a[2])
}

fn irradiance(sh: &[f32; 9], n: Vec3) -> f32 {
    let a = [
        PI,
        2.0 * PI / 3.0,
        2.0 * PI / 3.0,
        2.0 * PI / 3.0,
        PI / 4.0,
        PI / 4.0,
        PI / 4.0,
        PI / 4.0,
        PI / 4.0,
    ];
    let y = eval_l2(n);
    (0..9).map(|i| a[i] * sh[i] * y[i]).sum()
}

#[test]
fn baked_irradiance_matches_mitsuba_within_five_percent() {
    let text = include_str!("fixtures/mitsuba_irradiance.json");
    let fixture: Value = serde_json::from_str(text).expect("fixture parses");
    let mut scene = Scene::default();
    for (i, b) in fixture["boxes"].as_array().unwrap().iter().enumerate() {
        scene
            .meshes
            .push(shapes::cuboid(vec3(&b["lo"]), vec3(&b["hi"])));
        scene.materials.push(Material::diffuse(
            b["name"].as_str().unwrap(),
            vec3(&b["albedo"]),
        ));
        scene.instances.push(Instance {
            mesh: i,
            material: i,
            transform: Mat4::IDENTITY,
        });
    }
    let rays = SceneRays::build(&scene).expect("builds");
    let albedo = SurfaceAlbedo::new(&scene);
    let sphere = SphereRays::fibonacci(DEFAULT_RAYS_PER_PROBE);
    let mut stacks = TraversalStacks::default();
    let mut sum_rel = 0.0f64;
    let mut sum_rel_sky_only = 0.0f64;
    let mut count = 0;
    let mut worst = 0.0f32;
    for (k, p) in fixture["probes"].as_array().unwrap().iter().enumerate() {
        let position = vec3(&p["position"]);
        let normal = vec3(&p["normal"]);
        let want = vec3(&p["irradiance"]);
        let t = probe_transport(
            &rays,
            &albedo,
            &sphere,
            DEFAULT_BOUNCE_RAYS,
            position,
            k as u64,
            12.0,
            &mut stacks,
        );
        let sky = irradiance(&t.sky_visibility, normal);
        let got: Vec<f32> = (0..3)
            .map(|c| sky + irradiance(&t.bounced.map(|b| b[c]), normal))
            .collect();
        for c in 0..3 {
            sum_rel_sky_only += f64::from((sky - want[c]).abs() / want[c]);
            let rel = (got[c] - want[c]).abs() / want[c];
            worst = worst.max(rel);
            sum_rel += f64::from(rel);
            count += 1;
        }
        println!(
            "probe {position} normal {normal}: baked {:.4?} mitsuba {want:.4}",
            got
        );
    }
    let mean = sum_rel / f64::from(count);
    println!(
        "mean relative error {:.2} %, worst {:.2} %",
        100.0 * mean,
        100.0 * worst
    );
    assert!(mean < 0.05, "mean relative error {:.2} %", 100.0 * mean);
    // The test tells a bake without its bounce apart: sky visibility alone misses by more.
    let sky_only = sum_rel_sky_only / f64::from(count);
    println!("without the bounce: {:.2} %", 100.0 * sky_only);
    assert!(
        sky_only > 2.0 * 0.05,
        "sky alone is off by only {:.2} %",
        100.0 * sky_only
    );
}
