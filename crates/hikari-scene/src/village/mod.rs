//! The `village` built-in scene: a Japanese mountain village in autumn, generated in code
//! from a seed (no assets), to exercise everything the renderer does at once.
//!
//! # Contents
//!
//! - Terrain ([`terrain`]): 400 m x 400 m on a 1 m grid, gentle seeded hills rising around a
//!   flat valley floor, a level terrace for the temple courtyard, a bowl for the pond; vertex
//!   colours for grass, the earth street and path, courtyard gravel and mud.
//! - Ten houses ([`house`]) along both sides of an east-west street: 12 cm walls with a door
//!   and windows cut through them, a gable roof, a ceiling, and a furnished room (boards and
//!   tatami, low table, cushions, chest of drawers, shelves, bedding, a paper floor lamp).
//! - The temple ([`temple`]) on the courtyard terrace north of the street: a hall on a raised
//!   deck with red pillars, a veranda, three doors, an altar with a gilded statue, lanterns, a
//!   big gable roof; two spot lights over its doors and a point light inside. In the
//!   courtyard, a bell tower with a polished bronze bell (metal, roughness 0.2) whose lip is
//!   brushed bronze (anisotropic, along the mesh's tangents, which run around the bell).
//! - Golden ginkgo trees ringing the courtyard, fallen ginkgo leaves on its gravel, more
//!   trees in the village and cedars on the hills ([`trees`]); all sway in the wind
//!   ([`crate::Deformation::Sway`]).
//! - The pond ([`water`]): flat water, dark base colour, roughness 0.05; a water wheel turning
//!   in it ([`crate::Deformation::Spin`]).
//! - Paper lanterns on posts along the street and the temple path ([`lanterns`]), emissive at
//!   [`materials::LANTERN_NITS`], with point lights in every other street lantern.
//! - Cameras ([`cameras::NAMES`]): `exterior_wide`, `courtyard`, `house_interior`,
//!   `temple_interior`, `night_street`, `pond`, `bell`. The sun is [`Sun::default`]; a renderer places the
//!   sun or moon for other times (hikari-render's sky settings, e.g. 21:00 for `night_street`).
//!
//! # Conventions
//!
//! Metres, Y up, north along +z, +x west (as `hikari_math::astro` gives directions). The street
//! runs along x at z = 0; the temple courtyard is north of its +x end, the pond south of it.
//!
//! Interior mask: 1 on everything inside a building (floors, ceilings, furniture, the
//! temple hall's contents, materials with `interior: Some(1.0)`), 0 on everything outdoors
//! (terrain, roofs, water, trees, lanterns, posts, gables, the temple's deck and veranda),
//! and per-vertex on the walls: 1 on their inside faces, 0 on their outside faces and on the
//! ends that form a building's outside corners, 0.5 on the other edges (top, bottom, the
//! hidden ends of side walls) and on the reveals of doors and windows, which are seen from
//! both sides ([`crate::shapes::wall`]).
//!
//! Instancing: the houses of a kind share their wall, roof, floor and ceiling meshes, all
//! houses share the furniture, the tree variants are shared by every tree of their species,
//! the lanterns share one set of meshes.
//!
//! Determinism: everything random comes from SplitMix64 streams derived from the seed, one
//! per part of the village, so the same seed gives a bit-identical scene.

use glam::{Mat4, Vec2, Vec3};

use crate::{Scene, Sun};

mod builder;
pub mod cameras;
mod furniture;
pub mod house;
pub mod lanterns;
pub mod materials;
mod rng;
mod roof;
pub mod temple;
pub mod terrain;
pub mod trees;
pub mod water;

/// The seed of [`crate::builtin::village`].
pub const DEFAULT_SEED: u64 = 0x7111_a6e5_eed5;

/// How many fallen leaves lie on the courtyard.
pub const FALLEN_LEAVES: usize = 8000;

/// A rectangular building on the ground: where it is and how big, for placing cameras and
/// checking them.
#[derive(Clone, Debug, PartialEq)]
pub struct Footprint {
    pub name: String,
    /// World position of the middle of the floor.
    pub centre: Vec3,
    /// Rotation about +Y, radians (the building's front faces its own -z).
    pub yaw: f32,
    /// Half the outer size along the building's own x and z, metres.
    pub half_size: Vec2,
    /// Height of the ceiling above the floor.
    pub ceiling_height: f32,
}

impl Footprint {
    /// Building frame (floor centre, front towards -z) to world.
    pub fn transform(&self) -> Mat4 {
        builder::placed(self.centre, self.yaw)
    }

    /// Whether `p` (world) is inside the building's outer walls, between floor and ceiling.
    pub fn contains(&self, p: Vec3) -> bool {
        let l = self.transform().inverse().transform_point3(p);
        l.x.abs() < self.half_size.x
            && l.z.abs() < self.half_size.y
            && l.y > 0.0
            && l.y < self.ceiling_height
    }
}

/// What was placed where, for cameras, tests and tools.
#[derive(Clone, Debug)]
pub struct VillageLayout {
    pub seed: u64,
    pub houses: Vec<Footprint>,
    pub temple_hall: Footprint,
    pub courtyard_centre: Vec3,
    pub courtyard_radius: f32,
    /// Centre of the pond's water surface.
    pub pond_centre: Vec3,
    pub pond_shore_radius: f32,
    pub water_wheel_hub: Vec3,
    pub bell_centre: Vec3,
    /// Centres of all lantern papers (street, path, temple).
    pub lanterns: Vec<Vec3>,
    /// Base positions and heights of the ginkgos ringing the courtyard.
    pub courtyard_trees: Vec<(Vec2, f32)>,
}

pub struct Village {
    pub scene: Scene,
    pub layout: VillageLayout,
}

/// Generates the village for `seed`.
pub fn build(seed: u64) -> Village {
    let sites = terrain::Sites::fixed();
    let ground = terrain::Terrain::new(seed, sites);
    let s = ground.sites.clone();
    let mut b = builder::Builder::default();
    let pal = materials::Palette::new(&mut b);

    let t = b.mesh("terrain", ground.mesh(seed));
    b.instance(t, pal.terrain, Mat4::IDENTITY);

    let lantern = lanterns::Lantern::new(&mut b);
    let houses = house::build(&mut b, &pal, &ground, seed);
    let court = Vec3::new(s.courtyard_centre.x, s.courtyard_y, s.courtyard_centre.y);
    let temple = temple::build(
        &mut b,
        &pal,
        &lantern,
        court + Vec3::new(0.0, 0.0, 11.0),
        court + Vec3::new(-13.0, 0.0, -4.0),
    );
    let pond = water::build(&mut b, &pal, &ground);
    let mut lantern_centres: Vec<Vec3> = lanterns::street(&mut b, &pal, &ground, &lantern)
        .into_iter()
        .map(|l| l.centre)
        .collect();
    lantern_centres.extend(&temple.lantern_centres);

    let mut keep_out = temple.keep_out.clone();
    for h in &houses {
        let f = &h.footprint;
        keep_out.push((
            Vec2::new(f.centre.x, f.centre.z),
            f.half_size.length() + 3.0,
        ));
    }
    let hub = pond.wheel_hub;
    keep_out.push((Vec2::new(hub.x, hub.z + 3.0), 5.0));
    for spot in cameras::outdoor_spots(&ground, &pond, temple.bell_tower) {
        keep_out.push((spot, 6.0));
    }
    let courtyard_trees = trees::build(
        &mut b,
        &pal,
        &ground,
        seed,
        &trees::KeepOut {
            discs: keep_out.clone(),
        },
    );
    let leaves = trees::fallen_leaves(
        &ground,
        seed,
        FALLEN_LEAVES,
        &[
            (Vec2::new(temple.hall.centre.x, temple.hall.centre.z), 11.5),
            (Vec2::new(temple.bell_tower.x, temple.bell_tower.z), 3.3),
        ],
    );
    let leaves = b.mesh("fallen leaves", leaves);
    b.instance(leaves, pal.fallen_leaves, Mat4::IDENTITY);

    b.scene.cameras = cameras::build(&ground, &houses[0], &temple, &pond);
    b.scene.sun = Some(Sun::default());
    // Mist over the pond: haze-lit fog sprites drifting with the breeze (docs/particles.md).
    b.scene.particles.push(crate::ParticleEmitter {
        name: "pond mist".into(),
        centre: pond.centre + Vec3::new(-1.5, 0.7, 0.0),
        half_extents: Vec3::new(0.7 * pond.shore_radius, 0.35, 0.7 * pond.shore_radius),
        count: 48,
        size_m: [1.6, 2.8],
        opacity: 0.18,
        velocity_mps: Vec3::new(0.12, 0.01, 0.04),
        lifetime_s: 40.0,
        albedo: Vec3::splat(0.9),
        haze_lit: true,
        seed: 7,
        // From dusk to mid-morning, as mist over still water lies.
        hours: Some([17.5, 9.0]),
    });
    let layout = VillageLayout {
        seed,
        houses: houses.iter().map(|h| h.footprint.clone()).collect(),
        temple_hall: temple.hall.clone(),
        courtyard_centre: court,
        courtyard_radius: s.courtyard_radius,
        pond_centre: pond.centre,
        pond_shore_radius: pond.shore_radius,
        water_wheel_hub: pond.wheel_hub,
        bell_centre: temple.bell_centre,
        lanterns: lantern_centres,
        courtyard_trees,
    };
    Village {
        scene: b.scene,
        layout,
    }
}
