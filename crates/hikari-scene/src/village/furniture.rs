//! Furniture for the houses' rooms, each a mesh shared by every house (instanced). Local
//! frame: standing on y = 0, centred on x and z, its front facing -Z.

use glam::{Mat4, Vec3};

use crate::Mesh;
use crate::shapes::{append, cuboid, frustum};

fn add(m: &mut Mesh, part: Mesh) {
    append(m, &part, Mat4::IDENTITY);
}

fn coloured(mut part: Mesh, c: Vec3) -> Mesh {
    part.colors = Some(vec![c.extend(1.0); part.positions.len()]);
    part
}

/// Low round table (chabudai): top 0.9 m across at 0.33 m, four legs.
pub fn low_table() -> Mesh {
    let mut m = Mesh::default();
    let top = frustum(0.45, 0.45, 0.03, 24).expect("fixed positive sizes");
    append(&mut m, &top, Mat4::from_translation(Vec3::Y * 0.30));
    for (x, z) in [(0.25, 0.25), (-0.25, 0.25), (0.25, -0.25), (-0.25, -0.25)] {
        add(
            &mut m,
            cuboid(
                Vec3::new(x - 0.02, 0.0, z - 0.02),
                Vec3::new(x + 0.02, 0.3, z + 0.02),
            ),
        );
    }
    m
}

/// Chest of drawers (tansu): 0.9 m wide, 1.1 m high, 0.45 m deep, two columns of four drawer
/// fronts with handles on its front.
pub fn tansu() -> Mesh {
    let mut m = Mesh::default();
    let (hw, hd, h) = (0.45, 0.225, 1.1);
    add(
        &mut m,
        cuboid(Vec3::new(-hw, 0.0, -hd), Vec3::new(hw, h, hd)),
    );
    for col in 0..2 {
        for row in 0..4 {
            let x0 = -hw + 0.03 + col as f32 * 0.435;
            let y0 = 0.05 + row as f32 * 0.26;
            let front = Vec3::new(x0, y0, -hd - 0.015);
            add(&mut m, cuboid(front, Vec3::new(x0 + 0.405, y0 + 0.23, -hd)));
            let c = Vec3::new(x0 + 0.2025, y0 + 0.115, -hd - 0.015);
            add(
                &mut m,
                cuboid(
                    c - Vec3::new(0.06, 0.01, 0.02),
                    c + Vec3::new(0.06, 0.01, 0.0),
                ),
            );
        }
    }
    m
}

/// Open shelves: 1.0 m wide, 1.6 m high, 0.35 m deep, five boards, with jars and boxes.
pub fn shelves() -> Mesh {
    let mut m = Mesh::default();
    let (hw, hd, h) = (0.5, 0.175, 1.6);
    add(
        &mut m,
        cuboid(Vec3::new(-hw, 0.0, -hd), Vec3::new(-hw + 0.03, h, hd)),
    );
    add(
        &mut m,
        cuboid(Vec3::new(hw - 0.03, 0.0, -hd), Vec3::new(hw, h, hd)),
    );
    add(
        &mut m,
        cuboid(
            Vec3::new(-hw + 0.03, 0.0, hd - 0.02),
            Vec3::new(hw - 0.03, h, hd),
        ),
    );
    for k in 0..5 {
        let y = 0.05 + k as f32 * 0.37;
        add(
            &mut m,
            cuboid(
                Vec3::new(-hw + 0.03, y, -hd),
                Vec3::new(hw - 0.03, y + 0.025, hd - 0.02),
            ),
        );
        if k < 4 {
            // A jar and a box on each of the lower four boards.
            let jar = frustum(0.07, 0.05, 0.18, 12).expect("fixed positive sizes");
            let x = -0.25 + 0.12 * k as f32;
            append(
                &mut m,
                &jar,
                Mat4::from_translation(Vec3::new(x, y + 0.025, 0.0)),
            );
            let bx = 0.22 - 0.05 * k as f32;
            add(
                &mut m,
                cuboid(
                    Vec3::new(bx - 0.1, y + 0.025, -0.1),
                    Vec3::new(bx + 0.1, y + 0.145, 0.08),
                ),
            );
        }
    }
    m
}

/// Bedding laid out on the floor (futon): mattress, quilt and pillow, 1.0 m x 2.0 m along z,
/// head at +z. Vertex colours give the three fabrics (the material is white).
pub fn futon() -> Mesh {
    let mut m = Mesh::default();
    add(
        &mut m,
        coloured(
            cuboid(Vec3::new(-0.5, 0.0, -1.0), Vec3::new(0.5, 0.09, 1.0)),
            Vec3::new(0.78, 0.76, 0.70),
        ),
    );
    add(
        &mut m,
        coloured(
            cuboid(Vec3::new(-0.52, 0.09, -1.02), Vec3::new(0.52, 0.15, 0.45)),
            Vec3::new(0.06, 0.09, 0.30),
        ),
    );
    add(
        &mut m,
        coloured(
            cuboid(Vec3::new(-0.25, 0.09, 0.6), Vec3::new(0.25, 0.19, 0.9)),
            Vec3::new(0.55, 0.45, 0.30),
        ),
    );
    m
}

/// Floor cushion (zabuton), 0.55 m square.
pub fn cushion() -> Mesh {
    cuboid(
        Vec3::new(-0.275, 0.0, -0.275),
        Vec3::new(0.275, 0.07, 0.275),
    )
}

/// Paper floor lamp (andon): its wooden frame, and separately its glowing paper box.
pub fn andon() -> (Mesh, Mesh) {
    let mut frame = Mesh::default();
    let (r, h) = (0.17, 0.8);
    for (x, z) in [(r, r), (-r, r), (r, -r), (-r, -r)] {
        add(
            &mut frame,
            cuboid(
                Vec3::new(x - 0.015, 0.0, z - 0.015),
                Vec3::new(x + 0.015, h, z + 0.015),
            ),
        );
    }
    add(
        &mut frame,
        cuboid(Vec3::new(-r, 0.1, -r), Vec3::new(r, 0.13, r)),
    );
    let paper = cuboid(Vec3::new(-0.15, 0.2, -0.15), Vec3::new(0.15, 0.72, 0.15));
    (frame, paper)
}
