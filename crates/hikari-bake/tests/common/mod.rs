//! Scenes and tolerances shared by the bake's tests.
#![allow(dead_code)]

use glam::{Mat4, Vec3};
use hikari_scene::{Instance, Material, Mesh, Scene, shapes};
use std::f32::consts::PI;

/// Largest |Y_i| over the sphere, per coefficient (l=0: 1/(2√π); l=1: √3/(2√π); l=2: the
/// `3z²−1` term peaks at √5/(2√π), the others at √15/(4√π)).
pub fn max_abs_y() -> [f32; 9] {
    let s = 1.0 / (2.0 * PI.sqrt());
    let l1 = 3f32.sqrt() * s;
    let l2 = 15f32.sqrt() / (4.0 * PI.sqrt());
    [s, l1, l1, l1, l2, l2, 5f32.sqrt() * s, l2, l2]
}

/// Three standard deviations of the Fibonacci set's error at a visibility edge (derived in
/// known_answers.rs's header).
pub fn edge_tolerance(n: u32) -> [f32; 9] {
    let n = n as f32;
    max_abs_y().map(|y| 3.0 * 4.0 * PI / n * y * (PI * n).powf(0.25))
}

/// The square `y = height`, |x|, |z| ≤ half, facing +Y.
pub fn ground(half: f32, height: f32) -> Mesh {
    let mut m = Mesh {
        name: "ground".into(),
        ..Default::default()
    };
    let c = |x: f32, z: f32| Vec3::new(x, height, z);
    shapes::push_triangle(&mut m, c(-half, -half), c(-half, half), c(half, half));
    shapes::push_triangle(&mut m, c(-half, -half), c(half, half), c(half, -half));
    m
}

/// One instance per mesh, all with `material`.
pub fn scene_with(meshes: Vec<Mesh>, material: Material) -> Scene {
    let instances = (0..meshes.len())
        .map(|i| Instance {
            mesh: i,
            material: 0,
            transform: Mat4::IDENTITY,
        })
        .collect();
    Scene {
        meshes,
        materials: vec![material],
        instances,
        ..Default::default()
    }
}

pub fn assert_close(got: [f32; 9], want: [f32; 9], tol: [f32; 9], what: &str) {
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
