//! The village's named cameras: standing eye heights above the ground (or floor) they are on,
//! interior ones inside their building clear of walls and furniture.

use glam::{Vec2, Vec3};

use super::house::House;
use super::temple::Temple;
use super::terrain::Terrain;
use super::water::Pond;
use crate::Camera;

/// Names of the cameras, in the order the scene lists them.
pub const NAMES: [&str; 7] = [
    "exterior_wide",
    "courtyard",
    "house_interior",
    "temple_interior",
    "night_street",
    "pond",
    "bell",
];

fn cam(name: &str, position: Vec3, target: Vec3, vfov_deg: f32, near: f32) -> Camera {
    Camera {
        name: name.into(),
        position,
        target,
        vfov_deg,
        near,
        up: Vec3::Y,
    }
}

/// Where each outdoor camera stands (xz), so trees can keep clear of it.
pub fn outdoor_spots(terrain: &Terrain, pond: &Pond, bell_tower: Vec3) -> Vec<Vec2> {
    let s = &terrain.sites;
    vec![
        Vec2::new(-105.0, 100.0),
        s.courtyard_centre + Vec2::new(0.0, -17.0),
        Vec2::new(s.street_x.0 + 3.0, -0.8),
        Vec2::new(pond.centre.x + 10.0, pond.centre.z - 11.0),
        Vec2::new(bell_tower.x + 4.0, bell_tower.z - 3.6),
    ]
}

pub fn build(terrain: &Terrain, house: &House, temple: &Temple, pond: &Pond) -> Vec<Camera> {
    let s = &terrain.sites;
    let spots = outdoor_spots(terrain, pond, temple.bell_tower);
    let ground = |p: Vec2| terrain.max_over(p, 0.5);
    let at = |p: Vec2, height: f32| Vec3::new(p.x, ground(p) + height, p.y);

    let wide = at(spots[0], 40.0);
    let court = at(spots[1], 1.6);
    let temple_front = temple.hall.centre + Vec3::new(0.0, 2.5, 0.0);
    let (house_eye, house_target) = house.camera_spot();
    let hall = temple.hall.transform();
    let street = at(spots[2], 1.7);
    let street_target = Vec3::new(s.street_x.0 + 45.0, street.y + 0.3, 0.5);
    let pond_eye = at(spots[3], 1.6);
    let bell_eye = at(spots[4], 1.9);
    vec![
        cam(NAMES[0], wide, Vec3::new(5.0, 2.0, 8.0), 50.0, 0.5),
        cam(NAMES[1], court, temple_front, 55.0, 0.1),
        cam(NAMES[2], house_eye, house_target, 65.0, 0.05),
        cam(
            NAMES[3],
            hall.transform_point3(Vec3::new(0.8, 1.6, -3.4)),
            hall.transform_point3(Vec3::new(0.0, 1.4, 3.5)),
            65.0,
            0.05,
        ),
        cam(NAMES[4], street, street_target, 55.0, 0.1),
        cam(NAMES[5], pond_eye, pond.wheel_hub, 50.0, 0.1),
        cam(NAMES[6], bell_eye, temple.bell_centre, 40.0, 0.1),
    ]
}
