//! The pond (a flat, dark, near-mirror water surface filling the terrain's bowl) and the
//! water wheel turning in it ([`Deformation::Spin`]) under a wooden flume.
//!
//! Wheel frame: hub at the origin, axle along X, the wheel in the YZ plane; the flume runs
//! along +Z to the shore.

use glam::{Mat4, Vec3};

use super::builder::Builder;
use super::materials::Palette;
use super::terrain::Terrain;
use crate::shapes::{append, cuboid, disc, parallelepiped, rod};
use crate::{Deformation, Mesh};

/// Outer radius of the wheel (paddle tips), metres.
pub const WHEEL_RADIUS: f32 = 2.05;
/// Turning rate, radians per second (about 7 s a turn).
pub const WHEEL_RATE: f32 = 0.9;
/// How far the wheel's hub is from the pond's centre (towards +z), metres.
const WHEEL_OFFSET: f32 = 8.5;

fn add(m: &mut Mesh, part: &Mesh) {
    append(m, part, Mat4::IDENTITY);
}

fn fixed(r: Result<Mesh, crate::shapes::ShapeError>) -> Mesh {
    r.expect("fixed wheel dimensions are valid")
}

/// The wheel: hub, two rims of straight segments, spokes and sixteen paddles.
fn wheel() -> Mesh {
    let mut m = Mesh::default();
    add(
        &mut m,
        &fixed(rod(Vec3::X * -0.5, Vec3::X * 0.5, 0.2, 0.2, 16)),
    );
    let n = 16;
    let dir = |k: usize| {
        let a = std::f32::consts::TAU * k as f32 / n as f32;
        Vec3::new(0.0, a.cos(), a.sin())
    };
    let rim = 1.7;
    for x in [-0.38, 0.38] {
        let side = Vec3::X * x;
        for k in 0..n {
            add(
                &mut m,
                &fixed(rod(
                    side + dir(k) * rim,
                    side + dir(k + 1) * rim,
                    0.05,
                    0.05,
                    8,
                )),
            );
            if k % 2 == 0 {
                add(
                    &mut m,
                    &fixed(rod(side + dir(k) * 0.2, side + dir(k) * rim, 0.04, 0.04, 6)),
                );
            }
        }
    }
    for k in 0..n {
        let d = dir(k);
        let tangent = Vec3::X.cross(d);
        let origin = Vec3::new(-0.45, 0.0, 0.0) + d * 1.45 - tangent * 0.02;
        add(
            &mut m,
            &parallelepiped(
                origin,
                Vec3::X * 0.9,
                d * (WHEEL_RADIUS - 1.45),
                tangent * 0.04,
            ),
        );
    }
    m
}

pub struct Pond {
    pub centre: Vec3,
    pub water_y: f32,
    pub shore_radius: f32,
    /// World position of the wheel's hub.
    pub wheel_hub: Vec3,
}

/// Adds the water surface, the wheel (spinning) and its static axle, posts and flume.
pub fn build(b: &mut Builder, pal: &Palette, terrain: &Terrain) -> Pond {
    let s = &terrain.sites;
    let shore = s.pond_shore_radius();
    let centre = Vec3::new(s.pond_centre.x, s.pond_water_y, s.pond_centre.y);
    // The disc reaches a little under the banks so no gap shows at the shore.
    let water = b.mesh("pond water", disc(shore + 0.5, 96));
    b.instance(water, pal.water, Mat4::from_translation(centre));

    let hub = centre + Vec3::new(0.0, 1.4, WHEEL_OFFSET);
    let mut w = wheel();
    w.deformation = Some(Deformation::Spin {
        pivot: Vec3::ZERO,
        axis: Vec3::X,
        radians_per_second: WHEEL_RATE,
    });
    let w = b.mesh("water wheel", w);
    let at_hub = Mat4::from_translation(hub);
    b.instance(w, pal.timber_out, at_hub);

    // Static frame in the hub's frame: axle and two posts down into the pond bed, the flume
    // above the wheel's top on two posts to the shore.
    let ground = |local: Vec3| terrain.surface_height(hub.x + local.x, hub.z + local.z) - hub.y;
    let mut frame = Mesh::default();
    add(
        &mut frame,
        &fixed(rod(Vec3::X * -0.75, Vec3::X * 0.75, 0.09, 0.09, 10)),
    );
    for x in [-0.62f32, 0.62] {
        let foot = ground(Vec3::new(x, 0.0, 0.0)) - 0.3;
        add(
            &mut frame,
            &cuboid(
                Vec3::new(x - 0.08, foot, -0.1),
                Vec3::new(x + 0.08, 0.15, 0.1),
            ),
        );
    }
    let (fy, z0, z1) = (WHEEL_RADIUS + 0.1, 0.3, 6.5);
    add(
        &mut frame,
        &cuboid(Vec3::new(-0.35, fy, z0), Vec3::new(0.35, fy + 0.05, z1)),
    );
    for x in [-0.4f32, 0.35] {
        add(
            &mut frame,
            &cuboid(Vec3::new(x, fy, z0), Vec3::new(x + 0.05, fy + 0.3, z1)),
        );
    }
    for z in [3.0f32, 5.5] {
        for x in [-0.45f32, 0.4] {
            let foot = ground(Vec3::new(x, 0.0, z)) - 0.3;
            add(
                &mut frame,
                &cuboid(
                    Vec3::new(x, foot, z - 0.05),
                    Vec3::new(x + 0.05, fy, z + 0.05),
                ),
            );
        }
    }
    let frame = b.mesh("water wheel frame", frame);
    b.instance(frame, pal.timber_out, at_hub);
    Pond {
        centre,
        water_y: s.pond_water_y,
        shore_radius: shore,
        wheel_hub: hub,
    }
}
