//! Sky visibility against closed forms, and grid placement on scenes whose ground and solids
//! are known.
//!
//! Closed forms, `c_i = ∫ V Y_i dω` in hikari's basis (+Y up, `Y_1 = √3/(2√π) y`):
//! - open space, `V = 1`: `c_0 = 4π · 1/(2√π) = 2√π`; every other `Y_i` integrates to 0
//!   (orthogonal to `Y_0`).
//! - above a plane `y = 0`, `V = [y > 0]`: `c_0 = 2π · 1/(2√π) = √π`;
//!   `c_1 = √3/(2√π) ∫_{y>0} y dω = √3/(2√π) · π = √(3π)/2`; the `x`, `z`, `xy`, `yz`, `xz`
//!   terms are odd in `x` or `z` over the hemisphere: 0; `3z² − 1` and `x² − y²` integrate
//!   over a hemisphere to half their (zero) full-sphere value: 0.
//! - inside a closed box, `V = 0`: all 0, exactly (every ray hits).
//!
//! Tolerance from `n`: the Fibonacci set gives every direction a cell of `4π / n` steradians;
//! only cells the visibility's edge cuts can be counted wrongly, at most `√(π n)` of them along
//! a great circle (its length `2π` over the cell width `√(4π / n)`), each off by at most its
//! weight `4π / n · max|Y_i|`: a worst case of `4π · max|Y_i| · √(π / n)` (0.098 on `c_0` at
//! n = 4096). Cut cells err both ways, so the tests use the sum of `√(π n)` errors of random
//! sign instead, three standard deviations of it: `3 · 4π / n · max|Y_i| · (π n)^(1/4)`
//! (0.026 on `c_0`, 0.045 on band 1 at n = 4096; 0.073 / 0.13 at n = 1024). Open space has no
//! edge; its error is the set's quadrature error of `Y_i` itself, a few `4π / n`.

use glam::{Mat4, Vec3};
use hikari_bake::sky_visibility::sky_visibility;
use hikari_bake::{
    BakeError, GridBakeOptions, Placement, SceneRays, SphereRays, bake_grid_sky_visibility,
};
use hikari_bvh::TraversalStacks;
use hikari_scene::{Instance, Material, Mesh, Scene, shapes};
use std::f32::consts::PI;

const N: u32 = 4096;

/// Largest |Y_i| over the sphere, per coefficient (l=0: 1/(2√π); l=1: √3/(2√π); l=2: the
/// `3z²−1` term peaks at √5/(2√π), the others at √15/(4√π)).
fn max_abs_y() -> [f32; 9] {
    let s = 1.0 / (2.0 * PI.sqrt());
    let l1 = 3f32.sqrt() * s;
    let l2 = 15f32.sqrt() / (4.0 * PI.sqrt());
    [s, l1, l1, l1, l2, l2, 5f32.sqrt() * s, l2, l2]
}

fn edge_tolerance(n: u32) -> [f32; 9] {
    let n = n as f32;
    max_abs_y().map(|y| 3.0 * 4.0 * PI / n * y * (PI * n).powf(0.25))
}

fn scene_of(meshes: Vec<Mesh>) -> Scene {
    let instances = (0..meshes.len())
        .map(|i| Instance {
            mesh: i,
            material: 0,
            transform: Mat4::IDENTITY,
        })
        .collect();
    Scene {
        meshes,
        materials: vec![Material::diffuse("grey", Vec3::splat(0.5))],
        instances,
        ..Default::default()
    }
}

/// The square `y = height`, |x|, |z| ≤ half, facing +Y.
fn ground(half: f32, height: f32) -> Mesh {
    let mut m = Mesh {
        name: "ground".into(),
        ..Default::default()
    };
    let c = |x: f32, z: f32| Vec3::new(x, height, z);
    shapes::push_triangle(&mut m, c(-half, -half), c(-half, half), c(half, half));
    shapes::push_triangle(&mut m, c(-half, -half), c(half, half), c(half, -half));
    m
}

fn visibility_at(scene: &Scene, p: Vec3, n: u32) -> [f32; 9] {
    let tracer = SceneRays::build(scene).expect("scene builds");
    sky_visibility(
        &tracer,
        &SphereRays::fibonacci(n),
        p,
        &mut TraversalStacks::default(),
    )
}

fn assert_close(got: [f32; 9], want: [f32; 9], tol: [f32; 9], what: &str) {
    for i in 0..9 {
        assert!(
            (got[i] - want[i]).abs() <= tol[i],
            "{what}: coefficient {i} is {} (want {} ± {}); all: {got:?}",
            got[i],
            want[i],
            tol[i]
        );
    }
}

#[test]
fn ground_helper_faces_up() {
    let g = ground(1.0, 0.0);
    let p = &g.positions;
    let n = (p[1] - p[0]).cross(p[2] - p[0]);
    assert!(n.y > 0.0, "{n}");
}

#[test]
fn open_space_sees_the_sky_everywhere() {
    // One small triangle far away, so the BVH is not empty but no ray from the origin hits it
    // except in its tiny solid angle (1 m² at 10 km: 1e-8 sr, no Fibonacci direction).
    let mut far = Mesh {
        name: "far".into(),
        ..Default::default()
    };
    shapes::push_triangle(
        &mut far,
        Vec3::new(1e4, 0.0, 0.0),
        Vec3::new(1e4, 1.0, 0.0),
        Vec3::new(1e4, 0.0, 1.0),
    );
    let got = visibility_at(&scene_of(vec![far]), Vec3::ZERO, N);
    let mut want = [0.0; 9];
    want[0] = 2.0 * PI.sqrt();
    // c_0 is exact up to f32 rounding (every weight is 4π/n · Y_0).
    let tol = max_abs_y().map(|y| 4.0 * PI * y * 4.0 / N as f32);
    assert_close(got, want, tol, "open space");
}

#[test]
fn above_a_large_plane_sees_the_upper_hemisphere() {
    // 100 km square, probe 1.5 m up: rays escape past the edge below 1.5e-5 rad of the horizon.
    let scene = scene_of(vec![ground(5e4, 0.0)]);
    for n in [1024, N] {
        let got = visibility_at(&scene, Vec3::new(3.0, 1.5, -2.0), n);
        let mut want = [0.0; 9];
        want[0] = PI.sqrt();
        want[1] = (3.0 * PI).sqrt() / 2.0;
        assert_close(
            got,
            want,
            edge_tolerance(n),
            &format!("half space, n = {n}"),
        );
    }
}

#[test]
fn inside_a_closed_box_sees_nothing() {
    let scene = scene_of(vec![shapes::cuboid(Vec3::splat(-2.0), Vec3::splat(2.0))]);
    let got = visibility_at(&scene, Vec3::new(0.3, -0.5, 1.1), N);
    assert_eq!(got, [0.0; 9]);
}

#[test]
fn grid_follows_the_ground_and_lifts_or_drops_probes_inside_solids() {
    // Ground at y = 2 over 300 m: 300 m less one spacing needs 2 tiles along each axis, whose
    // probes span 2 * 200 - 12.5 = 387.5 m, centred: the first column is at -193.75 and every
    // column at 6.25 + 12.5 k. A low solid block on the column (6.25, 6.25) (top at 4.7 m: the
    // 1.5 m probe at 3.5 m is inside it, lifted 1.5 m) and a tall one on (106.25, 106.25) (top
    // at 40 m: all three probes are inside beyond the largest lift, dropped).
    let low = shapes::cuboid(Vec3::new(5.25, 0.0, 5.25), Vec3::new(7.25, 4.7, 7.25));
    let tall = shapes::cuboid(
        Vec3::new(105.25, 0.0, 105.25),
        Vec3::new(107.25, 40.0, 107.25),
    );
    let scene = scene_of(vec![ground(150.0, 2.0), low, tall]);
    let options = GridBakeOptions {
        rays_per_probe: 256,
        ..Default::default()
    };
    let mut reports = Vec::new();
    let bake = bake_grid_sky_visibility(&scene, &options, |d, t| reports.push((d, t)))
        .expect("bake succeeds");
    assert_eq!((bake.tiles_x, bake.tiles_z), (2, 2));
    assert_eq!(bake.stats.probes, 4 * 16 * 16 * 3);
    assert_eq!(
        reports.last(),
        Some(&(bake.stats.probes, bake.stats.probes))
    );
    assert!(reports.windows(2).all(|w| w[0].0 <= w[1].0));
    let probe_at = |x: f32, z: f32, layer: usize| {
        let (fx, fz) = ((x - bake.origin.x) / 12.5, (z - bake.origin.y) / 12.5);
        assert!(
            fx.fract() == 0.0 && fz.fract() == 0.0,
            "({x}, {z}) is not a grid column"
        );
        let (ix, iz) = (fx as usize, fz as usize);
        let tile = &bake.tiles[(iz / 16) * bake.tiles_x as usize + ix / 16];
        tile.probes[layer * 256 + (iz % 16) * 16 + ix % 16]
    };
    assert_eq!(bake.origin.x, -193.75);
    assert_eq!(bake.origin.y, -193.75);
    // Columns on the open ground: the ground is 2 m, probes at 3.5, 12 and 32 m.
    for (layer, h) in [1.5f32, 10.0, 30.0].into_iter().enumerate() {
        let p = probe_at(-93.75, -43.75, layer);
        assert_eq!(p.placement, Placement::Planned);
        assert!((p.position.y - (2.0 + h)).abs() < 1e-4, "{p:?}");
    }
    let lifted = probe_at(6.25, 6.25, 0);
    assert_eq!(lifted.placement, Placement::Lifted(1.5), "{lifted:?}");
    assert!((lifted.position.y - 5.0).abs() < 1e-4, "{lifted:?}");
    assert!(lifted.sky_visibility[0] > 0.0);
    assert_eq!(probe_at(6.25, 6.25, 1).placement, Placement::Planned);
    for layer in 0..3 {
        let p = probe_at(106.25, 106.25, layer);
        assert_eq!(p.placement, Placement::Dropped, "layer {layer}: {p:?}");
        assert_eq!(p.sky_visibility, [0.0; 9]);
    }
    assert_eq!(bake.stats.dropped, 3);
    assert_eq!(bake.stats.lifted, 1);
    assert_eq!(bake.stats.sky_rays, 256 * (bake.stats.probes as u64 - 3));
    // A probe on open ground 100 m from the plane's edges sees about the upper hemisphere (the
    // edge hides 1.5 m / 100 m of the horizon; the blocks subtend little).
    let mid = probe_at(-43.75, -43.75, 0);
    assert!((mid.sky_visibility[0] - PI.sqrt()).abs() < 0.2, "{mid:?}");
}

#[test]
fn scene_without_geometry_bakes_no_tiles() {
    let bake = bake_grid_sky_visibility(&Scene::default(), &GridBakeOptions::default(), |_, _| {})
        .expect("empty scene bakes");
    assert!(bake.tiles.is_empty());
    assert_eq!(bake.stats.probes, 0);
}

#[test]
fn bad_options_are_named() {
    let scene = scene_of(vec![ground(10.0, 0.0)]);
    for (options, name) in [
        (
            GridBakeOptions {
                spacing: f32::NAN,
                ..Default::default()
            },
            "spacing",
        ),
        (
            GridBakeOptions {
                rays_per_probe: 0,
                ..Default::default()
            },
            "rays_per_probe",
        ),
        (
            GridBakeOptions {
                heights: [1.5, -1.0, 30.0],
                ..Default::default()
            },
            "heights",
        ),
    ] {
        match bake_grid_sky_visibility(&scene, &options, |_, _| {}) {
            Err(BakeError::BadOption { option, .. }) => assert_eq!(option, name),
            other => panic!("{name}: {other:?}"),
        }
    }
}

#[test]
fn bad_geometry_is_an_error_not_a_panic() {
    let mut m = ground(10.0, 0.0);
    m.positions[0].x = f32::NAN;
    let err = bake_grid_sky_visibility(&scene_of(vec![m]), &GridBakeOptions::default(), |_, _| {})
        .expect_err("NaN vertex");
    assert!(err.to_string().contains("ground"), "{err}");
}

#[test]
fn inside_test_knows_solids_from_rooms_under_any_transform() {
    use hikari_bake::placement::inside_geometry;
    let solid = shapes::cuboid(Vec3::splat(-1.0), Vec3::splat(1.0));
    // The same box wound inwards: a room.
    let mut room = solid.clone();
    room.name = "room".into();
    for t in room.indices.chunks_exact_mut(3) {
        t.swap(1, 2);
    }
    let rays = SphereRays::fibonacci(64);
    let mut stacks = TraversalStacks::default();
    // glTF: a mirroring transform (negative determinant) flips the winding back, so a mirrored
    // solid is still a solid.
    for (name, transform) in [
        ("identity", Mat4::IDENTITY),
        ("mirrored", Mat4::from_scale(Vec3::new(-1.0, 1.0, 1.0))),
        (
            "rotated and scaled",
            Mat4::from_rotation_y(0.7) * Mat4::from_scale(Vec3::splat(3.0)),
        ),
    ] {
        for (mesh, inside) in [(&solid, true), (&room, false)] {
            let mut scene = scene_of(vec![mesh.clone()]);
            scene.instances[0].transform = transform;
            let tracer = SceneRays::build(&scene).expect("builds");
            assert_eq!(
                inside_geometry(&tracer, &rays, Vec3::new(0.1, 0.2, -0.3), 0.5, &mut stacks),
                inside,
                "{} under {name}",
                mesh.name
            );
            // Outside either box nothing is inside.
            assert!(!inside_geometry(
                &tracer,
                &rays,
                Vec3::new(0.0, 9.0, 0.0),
                0.5,
                &mut stacks
            ));
        }
    }
}
