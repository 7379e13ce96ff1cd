//! Gable roofs, shared by the houses, the temple and the bell tower.

use glam::{Mat4, Vec2, Vec3};

use crate::Mesh;
use crate::shapes::{append, cuboid, parallelepiped};

fn add(m: &mut Mesh, part: &Mesh) {
    append(m, part, Mat4::IDENTITY);
}

/// A gable roof over the rectangle ±`half` (x, z) whose underside rests on its long edges at
/// height `base_y`, pitched `pitch_deg`, overhanging `eave` beyond the long edges and `verge`
/// beyond the short ones, slabs `thick` deep, with a ridge cap. Returns the mesh and the
/// height of the underside at the ridge.
pub fn gable_roof(
    half: Vec2,
    base_y: f32,
    pitch_deg: f32,
    eave: f32,
    verge: f32,
    thick: f32,
) -> (Mesh, f32) {
    let pitch = pitch_deg.to_radians();
    let ridge_y = base_y + half.y * pitch.tan();
    let run = half.y + eave;
    let mut m = Mesh::default();
    for side in [-1.0f32, 1.0] {
        let origin = Vec3::new(-half.x - verge, ridge_y, 0.0);
        let along = Vec3::X * 2.0 * (half.x + verge);
        let down = Vec3::new(0.0, -run * pitch.tan(), side * run);
        let up = Vec3::new(0.0, pitch.cos(), side * pitch.sin()) * thick;
        add(&mut m, &parallelepiped(origin, along, down, up));
    }
    let cap = thick / pitch.cos() + 0.1;
    add(
        &mut m,
        &cuboid(
            Vec3::new(-half.x - verge - 0.1, ridge_y, -0.25),
            Vec3::new(half.x + verge + 0.1, ridge_y + cap, 0.25),
        ),
    );
    (m, ridge_y)
}
