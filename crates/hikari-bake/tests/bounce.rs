//! Bounced sky visibility against closed forms.
//!
//! Above an infinite Lambertian plane `y = 0` of albedo `a`, under a uniform sky of radiance 1:
//! every point of the plane sees the whole upper hemisphere, so it receives irradiance
//! `∫ 1 · cos θ dω = π` and sends radiance `a/π · π = a` in every direction. A probe above it
//! sees radiance `a` in every direction below the horizon and nothing bounced above, so its
//! bounced visibility is `a` times the SH of the lower hemisphere: `c_0 = a√π`,
//! `c_1 = −a√(3π)/2` (the `y` term changes sign with the hemisphere), the rest 0 (the same
//! integrals as the upper hemisphere's in known_answers.rs). The secondary rays from the plane
//! all escape, so the only error is the probe rays' edge error at the horizon
//! (`edge_tolerance`), scaled by `a`.

mod common;

use common::{assert_close, edge_tolerance, ground, scene_with};
use glam::Vec3;
use hikari_bake::scene_rays::SceneRays;
use hikari_bake::sky_visibility::SphereRays;
use hikari_bake::surfaces::SurfaceAlbedo;
use hikari_bake::transport::{ProbeTransport, probe_transport};
use hikari_bvh::TraversalStacks;
use hikari_scene::{Material, Scene, Texture, TextureRef};
use std::f32::consts::PI;

const N: u32 = 4096;

fn transport(scene: &Scene, p: Vec3, n: u32, bounce: u32) -> ProbeTransport {
    let rays = SceneRays::build(scene).expect("scene builds");
    probe_transport(
        &rays,
        &SurfaceAlbedo::new(scene),
        &SphereRays::fibonacci(n),
        bounce,
        p,
        7,
        12.0,
        &mut TraversalStacks::default(),
    )
}

fn lower_hemisphere(a: f32) -> [f32; 9] {
    let mut c = [0.0; 9];
    c[0] = a * PI.sqrt();
    c[1] = -a * (3.0 * PI).sqrt() / 2.0;
    c
}

fn channel(b: &[[f32; 3]; 9], k: usize) -> [f32; 9] {
    b.map(|c| c[k])
}

fn albedo_plane(albedo: Vec3) -> Scene {
    scene_with(vec![ground(1e5, 0.0)], Material::diffuse("plane", albedo))
}

#[test]
fn bounced_visibility_above_a_diffuse_plane_is_its_albedo_below_the_horizon() {
    let a = Vec3::new(0.2, 0.5, 0.8);
    for (h, bounce) in [(1.5, 4), (20.0, 1), (0.3, 16)] {
        let t = transport(&albedo_plane(a), Vec3::new(3.0, h, -2.0), N, bounce);
        for k in 0..3 {
            let tol = edge_tolerance(N).map(|e| e * a[k]);
            assert_close(
                channel(&t.bounced, k),
                lower_hemisphere(a[k]),
                tol,
                &format!("channel {k} at height {h} with {bounce} bounce rays"),
            );
        }
        // Probe rays plus `bounce` rays per hit: half the sphere hits.
        let hits = t.rays - u64::from(N);
        assert_eq!(hits % u64::from(bounce), 0);
        let hit_rays = hits / u64::from(bounce);
        assert!((hit_rays as f64 - f64::from(N) / 2.0).abs() < 0.01 * f64::from(N));
    }
}

#[test]
fn no_bounce_rays_means_no_bounce_and_sky_visibility_is_unchanged() {
    let t = transport(&albedo_plane(Vec3::ONE), Vec3::new(0.0, 2.0, 0.0), N, 0);
    assert!(t.bounced.iter().flatten().all(|&c| c == 0.0));
    let mut upper = [0.0; 9];
    upper[0] = PI.sqrt();
    upper[1] = (3.0 * PI).sqrt() / 2.0;
    assert_close(t.sky_visibility, upper, edge_tolerance(N), "sky visibility");
}

#[test]
fn a_single_sided_surface_seen_from_behind_reflects_nothing_a_double_sided_one_does() {
    let a = Vec3::splat(0.6);
    // Probe below the plane: it sees the plane's back over its upper hemisphere. The back of
    // a double-sided plane sees the lower hemisphere's sky (everything below escapes).
    let below = Vec3::new(0.0, -2.0, 0.0);
    let single = transport(&albedo_plane(a), below, N, 4);
    assert!(single.bounced.iter().flatten().all(|&c| c == 0.0));
    let mut m = Material::diffuse("plane", a);
    m.double_sided = true;
    let double = transport(&scene_with(vec![ground(1e5, 0.0)], m), below, N, 4);
    let mut want = [0.0; 9];
    want[0] = a.x * PI.sqrt();
    want[1] = a.x * (3.0 * PI).sqrt() / 2.0;
    assert_close(
        channel(&double.bounced, 0),
        want,
        edge_tolerance(N),
        "double-sided",
    );
}

#[test]
fn albedo_is_base_colour_times_texture_mean_times_vertex_colour_times_one_minus_metal() {
    // Texture: two sRGB texels, 0 and 188 (red), 255 and 255 (green), 64 and 64 (blue).
    let decode = |e: f32| {
        let c = e / 255.0;
        if c <= 0.04045 {
            c / 12.92
        } else {
            ((c + 0.055) / 1.055).powf(2.4)
        }
    };
    let tex_mean = Vec3::new(0.5 * (decode(0.0) + decode(188.0)), 1.0, decode(64.0));
    let base = Vec3::new(0.9, 0.5, 0.7);
    let vertex = Vec3::new(0.5, 0.8, 1.0);
    let metal = 0.25;
    let mut plane = ground(1e5, 0.0);
    plane.colors = Some(vec![vertex.extend(1.0); plane.positions.len()]);
    let mut m = Material::diffuse("textured", base);
    m.metalness = metal;
    m.base_color_texture = Some(TextureRef::new(0));
    let mut scene = scene_with(vec![plane], m);
    scene.textures = vec![Texture {
        name: "t".into(),
        width: 2,
        height: 1,
        data: vec![0, 255, 64, 255, 188, 255, 64, 255],
        ..Default::default()
    }];
    let a = base * tex_mean * vertex * (1.0 - metal);
    let t = transport(&scene, Vec3::new(0.0, 1.0, 0.0), N, 2);
    for k in 0..3 {
        let tol = edge_tolerance(N).map(|e| e * a[k] + 1e-6);
        assert_close(
            channel(&t.bounced, k),
            lower_hemisphere(a[k]),
            tol,
            "textured plane",
        );
    }
}

/// Inside a closed box every surface the probe sees is itself closed off from the sky: no
/// bounce, exactly, even when the walls' insides reflect (double-sided, albedo 1).
#[test]
fn a_closed_double_sided_box_bounces_nothing() {
    let mut m = Material::diffuse("white", Vec3::ONE);
    m.double_sided = true;
    let scene = scene_with(
        vec![hikari_scene::shapes::cuboid(
            Vec3::splat(-2.0),
            Vec3::splat(2.0),
        )],
        m,
    );
    let t = transport(&scene, Vec3::new(0.3, -0.5, 0.2), 1024, 8);
    assert!(t.sky_visibility.iter().all(|&c| c == 0.0));
    assert!(t.bounced.iter().flatten().all(|&c| c == 0.0));
    assert_eq!(t.enclosed_fraction, 1.0);
    assert_eq!(t.rays, 1024 * 9);
}
