//! The temple on its terrace: a hall on a raised wooden deck (on stilts on a stone podium)
//! with a veranda, red pillars, 12 cm plaster walls with three doors, a furnished interior
//! (altar, gilded statue, lanterns) and a big gable roof; and the bell tower in the courtyard
//! with a polished bronze bell whose lip is a brushed (anisotropic) band.
//!
//! Temple frame: origin on the courtyard ground at the middle of the podium, front (stairs,
//! doors) facing -Z.

use glam::{Mat4, Vec2, Vec3};

use super::Footprint;
use super::builder::{Builder, placed};
use super::house::{WALL_THICKNESS, outdoor_ends, wall_frames};
use super::lanterns::Lantern;
use super::materials::{Palette, warm_white};
use super::roof::gable_roof;
use crate::shapes::{Opening, append, cuboid, frustum, gable, lathe, rod, wall};
use crate::{Light, Mesh};

/// Top of the deck (the hall's floor level) above the courtyard, metres.
pub const DECK_TOP: f32 = 1.45;
const HALL: Vec2 = Vec2::new(13.0, 9.0);
const HALL_WALL_HEIGHT: f32 = 4.0;
/// Outer pillars stand on this rectangle (half sizes), and carry the roof's tie beams.
const PILLARS: Vec2 = Vec2::new(8.2, 6.2);
const BEAM_TOP: f32 = DECK_TOP + 4.3;
const ROOF_PITCH_DEG: f32 = 30.0;

fn fixed<T, E: std::fmt::Debug>(r: Result<T, E>) -> T {
    r.expect("fixed temple dimensions are valid")
}

fn add(m: &mut Mesh, part: &Mesh) {
    append(m, part, Mat4::IDENTITY);
}

/// The bell's surfaces of revolution, lip at y = 0, hook top at 1.55 m: the polished body
/// (outside and inside) and the lip band, which closes the surface between them.
fn bell() -> (Mesh, Mesh) {
    let v = |r: f32, y: f32| Vec2::new(r, y);
    // Outside, from the lip band up to the hook (outwards faces on the right of travel).
    let outer = [
        v(0.48, 0.12),
        v(0.455, 0.3),
        v(0.43, 0.55),
        v(0.415, 0.85),
        v(0.40, 1.1),
        v(0.37, 1.25),
        v(0.30, 1.31),
        v(0.30, 1.31),
        v(0.07, 1.33),
        v(0.07, 1.33),
        v(0.07, 1.55),
        v(0.07, 1.55),
        v(0.0, 1.55),
    ];
    // Inside, from the crown down to the lip band.
    let inner = [
        v(0.0, 1.2),
        v(0.33, 1.18),
        v(0.37, 0.85),
        v(0.40, 0.45),
        v(0.42, 0.12),
    ];
    let band = [
        v(0.42, 0.12),
        v(0.43, 0.0),
        v(0.43, 0.0),
        v(0.49, 0.0),
        v(0.49, 0.0),
        v(0.48, 0.12),
    ];
    let segments = 48;
    let mut body = fixed(lathe(&outer, segments));
    add(&mut body, &fixed(lathe(&inner, segments)));
    (body, fixed(lathe(&band, segments)))
}

/// A seated figure as a surface of revolution, 1.47 m high.
fn statue() -> Mesh {
    let v = |r: f32, y: f32| Vec2::new(r, y);
    let profile = [
        v(0.0, 0.0),
        v(0.55, 0.0),
        v(0.55, 0.0),
        v(0.55, 0.12),
        v(0.42, 0.22),
        v(0.42, 0.22),
        v(0.45, 0.30),
        v(0.44, 0.5),
        v(0.36, 0.75),
        v(0.24, 0.92),
        v(0.10, 1.0),
        v(0.10, 1.02),
        v(0.16, 1.08),
        v(0.19, 1.18),
        v(0.17, 1.3),
        v(0.10, 1.38),
        v(0.05, 1.45),
        v(0.0, 1.47),
    ];
    fixed(lathe(&profile, 32))
}

pub struct Temple {
    pub hall: Footprint,
    /// World position of the centre of the bell.
    pub bell_centre: Vec3,
    /// World centre of the bell tower's base.
    pub bell_tower: Vec3,
    /// Obstacles on the ground for placing trees: (centre xz, radius).
    pub keep_out: Vec<(Vec2, f32)>,
    pub lantern_centres: Vec<Vec3>,
}

pub fn build(
    b: &mut Builder,
    pal: &Palette,
    lantern: &Lantern,
    origin: Vec3,
    bell_tower: Vec3,
) -> Temple {
    let to_world = placed(origin, 0.0);
    let put = |b: &mut Builder, mesh: usize, material: usize, local: Mat4| {
        b.instance(mesh, material, to_world * local);
    };
    let f = DECK_TOP;
    let t = WALL_THICKNESS;
    let mesh = |b: &mut Builder, name: &str, m: Mesh| b.mesh(name, m);

    // Base: podium, stilts, deck, stairs.
    let podium = mesh(
        b,
        "temple podium",
        cuboid(Vec3::new(-9.0, -1.0, -7.0), Vec3::new(9.0, 0.5, 7.0)),
    );
    put(b, podium, pal.stone, Mat4::IDENTITY);
    let stilt = mesh(b, "temple stilt", fixed(frustum(0.14, 0.14, 0.8, 10)));
    for i in 0..7 {
        for z in [-6.2, -2.07, 2.07, 6.2] {
            let x = -8.2 + i as f32 * (16.4 / 6.0);
            put(
                b,
                stilt,
                pal.timber_out,
                Mat4::from_translation(Vec3::new(x, 0.5, z)),
            );
        }
    }
    let deck = mesh(
        b,
        "temple deck",
        cuboid(Vec3::new(-8.5, 1.3, -6.5), Vec3::new(8.5, f, 6.5)),
    );
    put(b, deck, pal.timber_out, Mat4::IDENTITY);
    let mut stairs = Mesh::default();
    for k in 0..4 {
        let depth = (4 - k) as f32 * 0.32;
        add(
            &mut stairs,
            &cuboid(
                Vec3::new(-2.2, -0.3, -6.5 - depth),
                Vec3::new(2.2, (k + 1) as f32 * f / 5.0, -6.5),
            ),
        );
    }
    let stairs = mesh(b, "temple stairs", stairs);
    put(b, stairs, pal.timber_out, Mat4::IDENTITY);

    // The hall: walls with three doors in front, two high windows at the back and two
    // windows on each side; floor and ceiling inside.
    let door = |x0: f32| Opening {
        x0,
        x1: x0 + 2.2,
        y0: 0.0,
        y1: 2.9,
    };
    let window = |x0: f32, y0: f32, y1: f32| Opening {
        x0,
        x1: x0 + 1.5,
        y0,
        y1,
    };
    let side_len = HALL.y - 2.0 * t;
    let walls = [
        (
            "temple front wall",
            HALL.x,
            vec![door(1.6), door(5.4), door(9.2)],
        ),
        (
            "temple back wall",
            HALL.x,
            vec![window(2.0, 2.6, 3.4), window(9.5, 2.6, 3.4)],
        ),
        (
            "temple side wall",
            side_len,
            vec![window(1.2, 1.2, 2.4), window(side_len - 2.7, 1.2, 2.4)],
        ),
    ]
    .map(|(name, len, openings)| {
        let w = fixed(wall(len, HALL_WALL_HEIGHT, t, &openings));
        mesh(b, name, outdoor_ends(w, len))
    });
    let frames = wall_frames(HALL.x, HALL.y);
    let lift = Mat4::from_translation(Vec3::Y * f);
    for (w, frame) in [walls[0], walls[1], walls[2], walls[2]]
        .into_iter()
        .zip(frames)
    {
        put(b, w, pal.plaster, lift * frame);
    }
    let (ihx, ihz) = (0.5 * HALL.x - t, 0.5 * HALL.y - t);
    let floor = mesh(
        b,
        "temple floor",
        cuboid(Vec3::new(-ihx, f, -ihz), Vec3::new(ihx, f + 0.03, ihz)),
    );
    put(b, floor, pal.floor_boards, Mat4::IDENTITY);
    let top = f + HALL_WALL_HEIGHT;
    let ceiling = mesh(
        b,
        "temple ceiling",
        cuboid(Vec3::new(-ihx, top - 0.06, -ihz), Vec3::new(ihx, top, ihz)),
    );
    put(b, ceiling, pal.ceiling, Mat4::IDENTITY);
    let inner_pillar = mesh(
        b,
        "temple inner pillar",
        fixed(frustum(0.2, 0.2, HALL_WALL_HEIGHT - 0.09, 16)),
    );
    for (x, z) in [(3.5, 1.6), (-3.5, 1.6), (3.5, -1.6), (-3.5, -1.6)] {
        put(
            b,
            inner_pillar,
            pal.lacquer_in,
            Mat4::from_translation(Vec3::new(x, f + 0.03, z)),
        );
    }

    // Interior: a stepped altar with a gilded statue, two candle stands, two lanterns.
    let mut altar = Mesh::default();
    add(
        &mut altar,
        &cuboid(Vec3::new(-1.8, f, 2.6), Vec3::new(1.8, f + 0.5, 4.2)),
    );
    add(
        &mut altar,
        &cuboid(Vec3::new(-1.2, f + 0.5, 3.0), Vec3::new(1.2, f + 0.9, 4.0)),
    );
    let altar = mesh(b, "altar", altar);
    put(b, altar, pal.lacquer_in, Mat4::IDENTITY);
    let statue = mesh(b, "statue", statue());
    put(
        b,
        statue,
        pal.gold,
        Mat4::from_translation(Vec3::new(0.0, f + 0.9, 3.5)),
    );
    let candle = mesh(
        b,
        "candle stand",
        fixed(rod(Vec3::ZERO, Vec3::Y, 0.05, 0.03, 10)),
    );
    for x in [-2.3, 2.3] {
        put(
            b,
            candle,
            pal.gold,
            Mat4::from_translation(Vec3::new(x, f + 0.03, 3.0)),
        );
    }
    let mut lantern_centres = Vec::new();
    for x in [-2.0, 2.0] {
        // Hung from the ceiling by its cord (0.55 m above the lantern's bottom).
        let at = Mat4::from_translation(Vec3::new(x, top - 0.06 - 0.55, 0.8));
        let centre = lantern.hang(b, pal.andon_paper, pal.timber_in, to_world * at);
        b.scene.lights.push(Light::point_lumens(
            &format!("temple hall lantern light {}", if x < 0.0 { 1 } else { 2 }),
            centre,
            lantern.flux_lm(super::materials::ANDON_NITS, 1.0),
            warm_white(),
        ));
        lantern_centres.push(centre);
    }
    b.scene.lights.push(Light::point_lumens(
        "temple hall light",
        to_world.transform_point3(Vec3::new(0.0, f + 3.3, 0.5)),
        800.0,
        warm_white(),
    ));

    // Veranda: outer pillars (between the doors in front) carrying tie beams, an offering
    // box, two big lanterns and two spot lights over the doors and stairs.
    let pillar = mesh(
        b,
        "temple pillar",
        fixed(frustum(0.17, 0.17, BEAM_TOP - f, 16)),
    );
    let mut spots: Vec<Vec2> = Vec::new();
    for x in [-8.2, -5.7, -1.9, 1.9, 5.7, 8.2] {
        spots.extend([Vec2::new(x, -PILLARS.y), Vec2::new(x, PILLARS.y)]);
    }
    for z in [-2.07, 2.07] {
        spots.extend([Vec2::new(-PILLARS.x, z), Vec2::new(PILLARS.x, z)]);
    }
    for p in spots {
        put(
            b,
            pillar,
            pal.lacquer_out,
            Mat4::from_translation(Vec3::new(p.x, f, p.y)),
        );
    }
    let mut beams = Mesh::default();
    let (bx, bz, by0) = (PILLARS.x, PILLARS.y, BEAM_TOP - 0.3);
    for z in [-bz, bz] {
        add(
            &mut beams,
            &cuboid(
                Vec3::new(-bx - 0.2, by0, z - 0.13),
                Vec3::new(bx + 0.2, BEAM_TOP, z + 0.13),
            ),
        );
    }
    for x in [-bx, bx] {
        add(
            &mut beams,
            &cuboid(
                Vec3::new(x - 0.13, by0, -bz + 0.13),
                Vec3::new(x + 0.13, BEAM_TOP, bz - 0.13),
            ),
        );
    }
    let beams = mesh(b, "temple tie beams", beams);
    put(b, beams, pal.lacquer_out, Mat4::IDENTITY);
    let offering = mesh(
        b,
        "offering box",
        cuboid(Vec3::new(-0.6, f, -5.9), Vec3::new(0.6, f + 0.6, -5.3)),
    );
    put(b, offering, pal.timber_out, Mat4::IDENTITY);
    let scale = 1.6;
    for x in [-3.8, 3.8] {
        let at = Mat4::from_scale_rotation_translation(
            Vec3::splat(scale),
            glam::Quat::IDENTITY,
            Vec3::new(x, by0 - 0.55 * scale, -bz),
        );
        let centre = lantern.hang(b, pal.lantern_paper, pal.lantern_cap, to_world * at);
        // The glowing paper's light, as in the street's lit lanterns.
        b.scene.lights.push(Light::point_lumens(
            &format!("temple lantern light {}", if x < 0.0 { 1 } else { 2 }),
            centre,
            lantern.flux_lm(super::materials::LANTERN_NITS, scale),
            warm_white(),
        ));
        lantern_centres.push(centre);
    }
    for x in [-1.2f32, 1.2] {
        b.scene.lights.push(Light::spot_lumens(
            &format!("temple door spot {}", if x < 0.0 { 1 } else { 2 }),
            to_world.transform_point3(Vec3::new(x, by0 - 0.05, -bz)),
            Vec3::new(0.0, -1.0, -0.5).normalize(),
            1500.0,
            0.35,
            0.6,
            warm_white(),
        ));
    }

    // Roof over the pillar rectangle, gables at the short ends.
    let (roof, ridge_y) = gable_roof(PILLARS, BEAM_TOP, ROOF_PITCH_DEG, 2.0, 1.6, 0.25);
    let roof = mesh(b, "temple roof", roof);
    put(b, roof, pal.roof, Mat4::IDENTITY);
    let mut g = gable(2.0 * PILLARS.y, ridge_y - BEAM_TOP, t);
    g.interior = vec![0.0; g.positions.len()];
    let g = mesh(b, "temple gable wall", g);
    put(
        b,
        g,
        pal.gable,
        placed(
            Vec3::new(PILLARS.x, BEAM_TOP, PILLARS.y),
            std::f32::consts::FRAC_PI_2,
        ),
    );
    put(
        b,
        g,
        pal.gable,
        placed(
            Vec3::new(-PILLARS.x, BEAM_TOP, -PILLARS.y),
            -std::f32::consts::FRAC_PI_2,
        ),
    );

    let hall = Footprint {
        name: "temple hall".into(),
        centre: to_world.transform_point3(Vec3::Y * f),
        yaw: 0.0,
        half_size: 0.5 * HALL,
        ceiling_height: HALL_WALL_HEIGHT,
    };
    let bell_centre = bell_tower_build(b, pal, bell_tower);
    Temple {
        hall,
        bell_centre,
        bell_tower,
        keep_out: vec![
            (Vec2::new(origin.x, origin.z), 11.0),
            (Vec2::new(bell_tower.x, bell_tower.z), 3.5),
        ],
        lantern_centres,
    }
}

/// The bell tower (shōrō) at `at` (ground centre): stone base, four posts, tie beams, a small
/// gable roof; the bell hangs from a cross beam, a striker log beside it. Returns the bell's
/// world centre.
fn bell_tower_build(b: &mut Builder, pal: &Palette, at: Vec3) -> Vec3 {
    let to_world = placed(at, 0.3);
    let put = |b: &mut Builder, mesh: usize, material: usize, local: Mat4| {
        b.instance(mesh, material, to_world * local);
    };
    let base = b.mesh(
        "bell tower base",
        cuboid(Vec3::new(-2.2, -0.8, -2.2), Vec3::new(2.2, 0.4, 2.2)),
    );
    put(b, base, pal.stone, Mat4::IDENTITY);
    let post = b.mesh("bell tower post", fixed(frustum(0.15, 0.15, 4.0, 12)));
    for (x, z) in [(1.5, 1.5), (-1.5, 1.5), (1.5, -1.5), (-1.5, -1.5)] {
        put(
            b,
            post,
            pal.timber_out,
            Mat4::from_translation(Vec3::new(x, 0.4, z)),
        );
    }
    let mut beams = Mesh::default();
    for z in [-1.5, 1.5] {
        add(
            &mut beams,
            &cuboid(
                Vec3::new(-1.7, 4.1, z - 0.12),
                Vec3::new(1.7, 4.4, z + 0.12),
            ),
        );
    }
    for x in [-1.5, 1.5] {
        add(
            &mut beams,
            &cuboid(
                Vec3::new(x - 0.12, 4.1, -1.38),
                Vec3::new(x + 0.12, 4.4, 1.38),
            ),
        );
    }
    add(
        &mut beams,
        &cuboid(Vec3::new(-1.38, 4.1, -0.12), Vec3::new(1.38, 4.4, 0.12)),
    );
    let beams = b.mesh("bell tower beams", beams);
    put(b, beams, pal.timber_out, Mat4::IDENTITY);
    let (roof, ridge_y) = gable_roof(Vec2::new(1.5, 1.5), 4.4, ROOF_PITCH_DEG, 1.0, 0.9, 0.15);
    let roof = b.mesh("bell tower roof", roof);
    put(b, roof, pal.roof, Mat4::IDENTITY);
    let mut g = gable(3.0, ridge_y - 4.4, WALL_THICKNESS);
    g.interior = vec![0.0; g.positions.len()];
    let g = b.mesh("bell tower gable wall", g);
    put(
        b,
        g,
        pal.gable,
        placed(Vec3::new(1.5, 4.4, 1.5), std::f32::consts::FRAC_PI_2),
    );
    put(
        b,
        g,
        pal.gable,
        placed(Vec3::new(-1.5, 4.4, -1.5), -std::f32::consts::FRAC_PI_2),
    );

    let (body, band) = bell();
    let lip = Mat4::from_translation(Vec3::Y * (4.1 - 1.55));
    let body = b.mesh("temple bell", body);
    put(b, body, pal.bronze, lip);
    let band = b.mesh("temple bell rim", band);
    put(b, band, pal.brushed_bronze, lip);
    let mut striker = fixed(rod(
        Vec3::new(0.62, 3.0, 0.0),
        Vec3::new(2.2, 3.0, 0.0),
        0.11,
        0.11,
        12,
    ));
    for x in [0.9, 1.35] {
        add(
            &mut striker,
            &fixed(rod(
                Vec3::new(x, 3.08, 0.0),
                Vec3::new(x, 4.1, 0.0),
                0.012,
                0.012,
                6,
            )),
        );
    }
    let striker = b.mesh("bell striker", striker);
    put(b, striker, pal.rope, Mat4::IDENTITY);
    to_world.transform_point3(Vec3::Y * (4.1 - 1.55 + 0.7))
}
