//! The village houses: timber-and-plaster rooms with 12 cm walls with a door and windows cut
//! through them, a gable roof, a ceiling, and a furnished room (tatami, table, chest of
//! drawers, shelves, bedding, a paper lamp).
//!
//! House frame: origin at the centre of the footprint on the floor level (top of the stone
//! foundation), the front (with the door) facing -Z, the ridge along X. Two kinds (sizes)
//! share their meshes among all houses of the kind; the furniture is shared by all houses.

use glam::{Mat4, Vec2, Vec3};

use super::Footprint;
use super::builder::{Builder, placed};
use super::furniture;
use super::materials::{ANDON_NITS, Palette, warm_white};
use super::rng::Rng;
use super::roof::gable_roof;
use super::terrain::Terrain;
use crate::shapes::{Opening, append, cuboid, gable, wall};
use crate::{Light, Mesh};

/// Thickness of every wall, metres (the issue asks for no more than 0.15 m).
pub const WALL_THICKNESS: f32 = 0.12;

/// Height of the boards and tatami on the floor: where furniture stands.
const TATAMI_TOP: f32 = 0.085;
const ROOF_PITCH_DEG: f32 = 27.0;

#[derive(Clone, Copy, Debug)]
pub struct Kind {
    pub name: &'static str,
    /// Outer size along x (the front), metres.
    pub width: f32,
    /// Outer size along z, metres.
    pub depth: f32,
    pub wall_height: f32,
}

pub const KINDS: [Kind; 2] = [
    Kind {
        name: "small house",
        width: 7.2,
        depth: 5.4,
        wall_height: 2.5,
    },
    Kind {
        name: "large house",
        width: 8.8,
        depth: 6.4,
        wall_height: 2.7,
    },
];

impl Kind {
    fn door(&self) -> Opening {
        let x0 = 0.18 * self.width;
        Opening {
            x0,
            x1: x0 + 1.7,
            y0: 0.0,
            y1: 1.9,
        }
    }

    /// Centre of the door in the house frame (the front wall runs from +x to -x).
    pub fn door_x(&self) -> f32 {
        let d = self.door();
        0.5 * self.width - 0.5 * (d.x0 + d.x1)
    }

    fn front_window(&self) -> Opening {
        let x0 = 0.6 * self.width;
        Opening {
            x0,
            x1: x0 + 1.6,
            y0: 0.9,
            y1: 1.75,
        }
    }

    fn back_windows(&self) -> [Opening; 2] {
        let w = |x0: f32| Opening {
            x0,
            x1: x0 + 1.4,
            y0: 1.0,
            y1: 1.7,
        };
        [w(0.15 * self.width), w(0.62 * self.width)]
    }

    fn side_length(&self) -> f32 {
        self.depth - 2.0 * WALL_THICKNESS
    }

    fn side_window(&self) -> Opening {
        let c = 0.5 * self.side_length();
        Opening {
            x0: c - 0.6,
            x1: c + 0.6,
            y0: 0.9,
            y1: 1.6,
        }
    }

    fn roof_rise(&self) -> f32 {
        0.5 * self.depth * ROOF_PITCH_DEG.to_radians().tan()
    }
}

/// Marks the end faces of a wall (at x = 0 and x = `length` in its frame) as outdoors: the
/// front and back walls run past the side walls, so their ends are the building's outside
/// corners.
pub fn outdoor_ends(mut m: Mesh, length: f32) -> Mesh {
    for ((p, n), mask) in m
        .positions
        .iter()
        .zip(&m.normals)
        .zip(m.interior.iter_mut())
    {
        if n.x.abs() > 0.99 && (p.x == 0.0 || p.x == length) {
            *mask = 0.0;
        }
    }
    m
}

/// Placement of the four walls of a `width` x `depth` room centred on the origin (front at
/// -z): front and back walls run the full width, side walls fit between them; a wall's own
/// +z (outside) faces away from the room. `[front, back, right (+x), left (-x)]`.
pub fn wall_frames(width: f32, depth: f32) -> [Mat4; 4] {
    let (hw, hd, t) = (0.5 * width, 0.5 * depth, WALL_THICKNESS);
    [
        placed(Vec3::new(hw, 0.0, -hd + 0.5 * t), std::f32::consts::PI),
        placed(Vec3::new(-hw, 0.0, hd - 0.5 * t), 0.0),
        placed(
            Vec3::new(hw - 0.5 * t, 0.0, hd - t),
            std::f32::consts::FRAC_PI_2,
        ),
        placed(
            Vec3::new(-hw + 0.5 * t, 0.0, -hd + t),
            -std::f32::consts::FRAC_PI_2,
        ),
    ]
}

/// Meshes of one kind of house, indices into the scene.
struct KindMeshes {
    front: usize,
    back: usize,
    side: usize,
    gable: usize,
    lattice: usize,
    roof: usize,
    ceiling: usize,
    boards: usize,
    tatami: usize,
    foundation: usize,
}

/// The shared furniture meshes.
struct FurnitureMeshes {
    table: usize,
    tansu: usize,
    shelves: usize,
    futon: usize,
    cushion: usize,
    andon_frame: usize,
    andon_paper: usize,
    /// The glowing paper's flux (Φ = π L A, lm) and centre (lamp frame), for its light.
    andon_lumens: f32,
    andon_centre: Vec3,
    step: usize,
}

fn kind_meshes(b: &mut Builder, k: &Kind) -> KindMeshes {
    let (hw, hd, t, h) = (0.5 * k.width, 0.5 * k.depth, WALL_THICKNESS, k.wall_height);
    let name = |part: &str| format!("{} {part}", k.name);
    let walls = [
        ("front wall", k.width, vec![k.door(), k.front_window()]),
        ("back wall", k.width, k.back_windows().to_vec()),
        ("side wall", k.side_length(), vec![k.side_window()]),
    ]
    .map(|(part, length, openings)| {
        let m = wall(length, h, t, &openings).expect("house openings lie inside their walls");
        b.mesh(&name(part), outdoor_ends(m, length))
    });
    let rise = k.roof_rise();
    let mut g = gable(k.depth, rise, t);
    // The gables close the attic above the ceiling: outdoors on both faces.
    g.interior = vec![0.0; g.positions.len()];
    let gable = b.mesh(&name("gable wall"), g);

    // Vertical bars across the front window, in the front wall's own frame.
    let mut lattice = Mesh::default();
    let win = k.front_window();
    let mut x = win.x0 + 0.1;
    while x < win.x1 - 0.05 {
        append(
            &mut lattice,
            &cuboid(
                Vec3::new(x - 0.015, win.y0, -0.015),
                Vec3::new(x + 0.015, win.y1, 0.015),
            ),
            Mat4::IDENTITY,
        );
        x += 0.12;
    }
    let lattice = b.mesh(&name("window lattice"), lattice);

    // Roof resting on the outer top edges of the front and back walls, overhanging 0.7 m at
    // the eaves and 0.45 m at the gables.
    let (roof, _) = gable_roof(Vec2::new(hw, hd), h, ROOF_PITCH_DEG, 0.7, 0.45, 0.14);
    let roof = b.mesh(&name("roof"), roof);

    let inner = |y0: f32, y1: f32, z0: f32| {
        cuboid(Vec3::new(-hw + t, y0, z0), Vec3::new(hw - t, y1, hd - t))
    };
    let ceiling = b.mesh(&name("ceiling"), inner(h - 0.04, h, -hd + t));
    let boards = b.mesh(&name("floor boards"), inner(0.0, 0.03, -hd + t));

    // Tatami: 1.8 m x 0.9 m mats with 1 cm joints, filling the room behind a 1 m strip of
    // boards inside the door.
    let (area_w, area_d) = (k.width - 2.0 * t, k.depth - 2.0 * t - 1.0);
    let (cols, rows) = ((area_w / 1.8).floor() as i32, (area_d / 0.9).floor() as i32);
    let z_start = -hd + t + 1.0 + 0.5 * (area_d - rows as f32 * 0.9);
    let x_start = -0.5 * cols as f32 * 1.8;
    let mut tatami = Mesh::default();
    for r in 0..rows {
        for c in 0..cols {
            let lo = Vec3::new(
                x_start + c as f32 * 1.8 + 0.005,
                0.03,
                z_start + r as f32 * 0.9 + 0.005,
            );
            append(
                &mut tatami,
                &cuboid(lo, lo + Vec3::new(1.79, TATAMI_TOP - 0.03, 0.89)),
                Mat4::IDENTITY,
            );
        }
    }
    let tatami = b.mesh(&name("tatami"), tatami);
    let foundation = b.mesh(
        &name("foundation"),
        cuboid(
            Vec3::new(-hw - 0.2, -1.6, -hd - 0.2),
            Vec3::new(hw + 0.2, 0.0, hd + 0.2),
        ),
    );
    KindMeshes {
        front: walls[0],
        back: walls[1],
        side: walls[2],
        gable,
        lattice,
        roof,
        ceiling,
        boards,
        tatami,
        foundation,
    }
}

fn furniture_meshes(b: &mut Builder) -> FurnitureMeshes {
    let (frame, paper) = furniture::andon();
    let andon_lumens = std::f32::consts::PI * ANDON_NITS * super::lanterns::area(&paper);
    let (lo, hi) = paper.bounds().expect("fixed andon paper");
    FurnitureMeshes {
        andon_lumens,
        andon_centre: 0.5 * (lo + hi),
        table: b.mesh("low table", furniture::low_table()),
        tansu: b.mesh("tansu", furniture::tansu()),
        shelves: b.mesh("shelves", furniture::shelves()),
        futon: b.mesh("futon", furniture::futon()),
        cushion: b.mesh("cushion", furniture::cushion()),
        andon_frame: b.mesh("andon frame", frame),
        andon_paper: b.mesh("andon paper", paper),
        step: b.mesh(
            "entrance step",
            cuboid(Vec3::new(-0.7, -0.8, -0.3), Vec3::new(0.7, -0.17, 0.3)),
        ),
    }
}

/// One placed house.
pub struct House {
    pub footprint: Footprint,
    pub kind: Kind,
    /// Furniture mirrored across x (and the camera spot with it).
    pub mirrored: bool,
}

impl House {
    /// A spot for a camera inside: near the back corner without furniture, at standing eye
    /// height, and what it looks at (the door), in world space.
    pub fn camera_spot(&self) -> (Vec3, Vec3) {
        let k = &self.kind;
        let s = if self.mirrored { -1.0 } else { 1.0 };
        let eye = Vec3::new(s * (-0.5 * k.width + 0.9), 1.45, 0.5 * k.depth - 0.8);
        let target = Vec3::new(k.door_x(), 0.9, -0.5 * k.depth);
        let to_world = self.footprint.transform();
        (
            to_world.transform_point3(eye),
            to_world.transform_point3(target),
        )
    }
}

/// The house slots: x along the street, which side (north +1, south -1). The first is the
/// house the `house_interior` camera is in.
const SLOTS: [(f32, f32); 10] = [
    (-22.0, 1.0),
    (-54.0, 1.0),
    (-38.0, 1.0),
    (-6.0, 1.0),
    (10.0, 1.0),
    (-54.0, -1.0),
    (-38.0, -1.0),
    (-22.0, -1.0),
    (-6.0, -1.0),
    (10.0, -1.0),
];

/// Adds the houses along both sides of the street, fronts towards it.
pub fn build(b: &mut Builder, pal: &Palette, terrain: &Terrain, seed: u64) -> Vec<House> {
    let mut rng = Rng::stream(seed, "houses");
    let kinds = KINDS.map(|k| kind_meshes(b, &k));
    let f = furniture_meshes(b);
    let street_edge = terrain.sites.street_half_width + 1.5;
    let mut houses = Vec::new();
    for (x, side) in SLOTS {
        let which = rng.below(KINDS.len());
        let (k, km) = (KINDS[which], &kinds[which]);
        let x = x + rng.signed(1.5);
        let z = side * (street_edge + 0.5 * k.depth + rng.range(0.0, 0.8));
        // North side faces -z (its front, -z in the house frame, already does); south side
        // is turned round.
        let yaw = if side > 0.0 {
            0.0
        } else {
            std::f32::consts::PI
        } + rng.signed(0.05);
        let radius = 0.5 * Vec2::new(k.width, k.depth).length();
        let floor_y = terrain.max_over(Vec2::new(x, z), radius) + 0.35;
        let footprint = Footprint {
            name: format!("house {}", houses.len()),
            centre: Vec3::new(x, floor_y, z),
            yaw,
            half_size: Vec2::new(0.5 * k.width, 0.5 * k.depth),
            ceiling_height: k.wall_height,
        };
        let to_world = footprint.transform();
        let put = |b: &mut Builder, mesh: usize, material: usize, local: Mat4| {
            b.instance(mesh, material, to_world * local);
        };
        let frames = wall_frames(k.width, k.depth);
        put(b, km.front, pal.plaster, frames[0]);
        put(b, km.lattice, pal.timber_out, frames[0]);
        put(b, km.back, pal.plaster, frames[1]);
        put(b, km.side, pal.plaster, frames[2]);
        put(b, km.side, pal.plaster, frames[3]);
        let (hw, hd, t, h) = (0.5 * k.width, 0.5 * k.depth, WALL_THICKNESS, k.wall_height);
        put(
            b,
            km.gable,
            pal.gable,
            placed(Vec3::new(hw - 0.5 * t, h, hd), std::f32::consts::FRAC_PI_2),
        );
        put(
            b,
            km.gable,
            pal.gable,
            placed(
                Vec3::new(-hw + 0.5 * t, h, -hd),
                -std::f32::consts::FRAC_PI_2,
            ),
        );
        put(b, km.roof, pal.roof, Mat4::IDENTITY);
        put(b, km.ceiling, pal.ceiling, Mat4::IDENTITY);
        put(b, km.boards, pal.floor_boards, Mat4::IDENTITY);
        put(b, km.tatami, pal.tatami, Mat4::IDENTITY);
        put(b, km.foundation, pal.stone, Mat4::IDENTITY);
        put(
            b,
            f.step,
            pal.stone,
            Mat4::from_translation(Vec3::new(k.door_x(), 0.0, -hd - 0.5)),
        );

        // Furniture, possibly mirrored across x. Right (+x) side: chest against the back
        // wall, shelves against the side wall near the front; left: bedding and a lamp;
        // middle: the table and cushions.
        let mirrored = rng.chance(0.5);
        let s = if mirrored { -1.0 } else { 1.0 };
        let at = |x: f32, y: f32, z: f32, yaw: f32| placed(Vec3::new(s * x, y, z), s * yaw);
        let inside_x = hw - t;
        let tatami_mid = 0.5 * (-hd + t + 1.0 + hd - t);
        let boards = 0.03;
        put(
            b,
            f.table,
            pal.furniture,
            at(0.2, TATAMI_TOP, tatami_mid, rng.signed(0.5)),
        );
        let cushions = 2 + rng.below(3);
        for c in 0..cushions {
            let a = std::f32::consts::TAU * c as f32 / cushions as f32 + rng.signed(0.2);
            let p = Vec3::new(0.2 + 0.8 * a.cos(), 0.0, tatami_mid + 0.8 * a.sin());
            put(b, f.cushion, pal.cushion, at(p.x, TATAMI_TOP, p.z, a));
        }
        // Against the walls, standing on the boards (their feet sink into the tatami's edge
        // where they overlap it, out of sight).
        put(
            b,
            f.tansu,
            pal.furniture,
            at(inside_x - 0.6, boards, hd - t - 0.24, 0.0),
        );
        put(
            b,
            f.shelves,
            pal.furniture,
            at(
                inside_x - 0.19,
                boards,
                -hd + t + 1.4,
                std::f32::consts::FRAC_PI_2,
            ),
        );
        let tatami_x = 0.9 * (k.width - 2.0 * t).div_euclid(1.8);
        put(
            b,
            f.futon,
            pal.fabric,
            at(-tatami_x + 0.55, TATAMI_TOP, tatami_mid + 0.1, 0.0),
        );
        let lamp = at(-inside_x + 0.35, boards, -hd + t + 1.3, 0.0);
        put(b, f.andon_frame, pal.furniture, lamp);
        put(b, f.andon_paper, pal.andon_paper, lamp);
        // The glowing paper's light, inside it (a glowing paper without its light would light
        // the room only through the GI's rays).
        b.scene.lights.push(Light::point_lumens(
            &format!("andon light {}", houses.len()),
            (to_world * lamp).transform_point3(f.andon_centre),
            f.andon_lumens,
            warm_white(),
        ));
        houses.push(House {
            footprint,
            kind: k,
            mirrored,
        });
    }
    houses
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn openings_fit_their_walls_and_the_door_is_on_the_front() {
        for k in KINDS {
            for (len, o) in [
                (k.width, k.door()),
                (k.width, k.front_window()),
                (k.width, k.back_windows()[0]),
                (k.width, k.back_windows()[1]),
                (k.side_length(), k.side_window()),
            ] {
                assert!(
                    wall(len, k.wall_height, WALL_THICKNESS, &[o]).is_ok(),
                    "{k:?} {o:?}"
                );
            }
            // The front wall's frame maps its door to door_x on the front face.
            let f = wall_frames(k.width, k.depth)[0];
            let d = k.door();
            let mid = f.transform_point3(Vec3::new(0.5 * (d.x0 + d.x1), 1.0, 0.0));
            assert!((mid.x - k.door_x()).abs() < 1e-5);
            assert!((mid.z + 0.5 * k.depth - 0.5 * WALL_THICKNESS).abs() < 1e-5);
            // Every wall's outside (+z) faces away from the house centre.
            for frame in wall_frames(k.width, k.depth) {
                let c = frame.transform_point3(Vec3::new(0.5, 1.0, 0.0));
                let out = frame.transform_vector3(Vec3::Z);
                assert!(out.dot(c.with_y(0.0)) > 0.0);
            }
        }
    }
}
