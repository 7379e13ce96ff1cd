//! Built-in scenes, generated in code, without assets. Deterministic: `village` draws from a
//! seeded generator (a fixed default seed, or [`village_with_seed`]), the others use no
//! randomness.
//!
//! Units as everywhere in the crate: metres, lux, candela, nits.

use glam::{Mat4, Quat, Vec2, Vec3};

use crate::{AlphaMode, Camera, Instance, Material, Mesh, Scene, Sun, Texture, Wrap, shapes};

/// Names of the built-in scenes, for the CLI.
pub const NAMES: &[&str] = &["village", "boxes", "cornell", "terrain", "cutout"];

pub fn by_name(name: &str) -> Option<Scene> {
    match name {
        "village" => Some(village()),
        "boxes" => Some(boxes()),
        "cornell" => Some(cornell()),
        "terrain" => Some(terrain()),
        "cutout" => Some(cutout()),
        _ => None,
    }
}

/// The village scene ([`crate::village`]) with its default seed
/// ([`crate::village::DEFAULT_SEED`]).
pub fn village() -> Scene {
    village_with_seed(crate::village::DEFAULT_SEED)
}

/// The village scene generated from `seed`: the same seed gives a bit-identical scene.
pub fn village_with_seed(seed: u64) -> Scene {
    crate::village::build(seed).scene
}

/// A few boxes on a plane under the sun: the engine skeleton's first lit scene.
pub fn boxes() -> Scene {
    let materials = vec![
        Material::diffuse("ground", Vec3::new(0.30, 0.28, 0.25)),
        Material::diffuse("red", Vec3::new(0.60, 0.08, 0.06)),
        Material::diffuse("green", Vec3::new(0.10, 0.45, 0.12)),
        Material::diffuse("white", Vec3::new(0.80, 0.80, 0.78)),
        Material::diffuse("gold leaves", Vec3::new(0.75, 0.55, 0.08)),
    ];
    let meshes = vec![shapes::plane(40.0), shapes::cube()];
    let mut instances = vec![Instance {
        mesh: 0,
        material: 0,
        transform: Mat4::IDENTITY,
    }];
    let boxes = [
        (
            Vec3::new(-3.0, 1.0, 0.0),
            Vec3::new(2.0, 2.0, 2.0),
            20.0f32,
            1,
        ),
        (
            Vec3::new(1.5, 0.75, -1.5),
            Vec3::new(1.5, 1.5, 1.5),
            -35.0,
            2,
        ),
        (Vec3::new(2.5, 2.0, 2.5), Vec3::new(1.0, 4.0, 1.0), 10.0, 3),
        (Vec3::new(-0.5, 0.4, 3.0), Vec3::new(0.8, 0.8, 0.8), 45.0, 4),
    ];
    for (pos, size, yaw, material) in boxes {
        instances.push(Instance {
            mesh: 1,
            material,
            transform: Mat4::from_scale_rotation_translation(
                size,
                Quat::from_rotation_y(yaw.to_radians()),
                pos,
            ),
        });
    }
    Scene {
        meshes,
        materials,
        instances,
        cameras: vec![
            Camera {
                name: "main".into(),
                position: Vec3::new(7.0, 5.0, 11.0),
                target: Vec3::new(0.0, 1.0, 0.0),
                vfov_deg: 45.0,
                near: 0.1,
                up: Vec3::Y,
            },
            Camera {
                name: "top".into(),
                position: Vec3::new(0.5, 18.0, 0.6),
                target: Vec3::ZERO,
                vfov_deg: 50.0,
                near: 0.1,
                up: Vec3::Y,
            },
        ],
        sun: Some(Sun::default()),
        ..Default::default()
    }
}

/// The Cornell box's published geometry ("Cornell Box Data", Cornell University Program of
/// Computer Graphics, <https://www.graphics.cornell.edu/online/box/data.html>), in millimetres:
/// x from the right (green) wall at 0 to the left (red) wall at about 556, y up, z from the
/// open front at 0 to the back wall at 559.2. Quads are listed as published.
mod cornell_data {
    pub const FLOOR: [[f32; 3]; 4] = [
        [552.8, 0.0, 0.0],
        [0.0, 0.0, 0.0],
        [0.0, 0.0, 559.2],
        [549.6, 0.0, 559.2],
    ];
    pub const CEILING: [[f32; 3]; 4] = [
        [556.0, 548.8, 0.0],
        [556.0, 548.8, 559.2],
        [0.0, 548.8, 559.2],
        [0.0, 548.8, 0.0],
    ];
    pub const BACK: [[f32; 3]; 4] = [
        [549.6, 0.0, 559.2],
        [0.0, 0.0, 559.2],
        [0.0, 548.8, 559.2],
        [556.0, 548.8, 559.2],
    ];
    pub const RIGHT_GREEN: [[f32; 3]; 4] = [
        [0.0, 0.0, 559.2],
        [0.0, 0.0, 0.0],
        [0.0, 548.8, 0.0],
        [0.0, 548.8, 559.2],
    ];
    pub const LEFT_RED: [[f32; 3]; 4] = [
        [552.8, 0.0, 0.0],
        [549.6, 0.0, 559.2],
        [556.0, 548.8, 559.2],
        [556.0, 548.8, 0.0],
    ];
    pub const LIGHT: [[f32; 3]; 4] = [
        [343.0, 548.8, 227.0],
        [343.0, 548.8, 332.0],
        [213.0, 548.8, 332.0],
        [213.0, 548.8, 227.0],
    ];
    /// Top face then the four sides of each block (the published lists omit the bottoms).
    pub const SHORT_BLOCK: [[[f32; 3]; 4]; 5] = [
        [
            [130.0, 165.0, 65.0],
            [82.0, 165.0, 225.0],
            [240.0, 165.0, 272.0],
            [290.0, 165.0, 114.0],
        ],
        [
            [290.0, 0.0, 114.0],
            [290.0, 165.0, 114.0],
            [240.0, 165.0, 272.0],
            [240.0, 0.0, 272.0],
        ],
        [
            [130.0, 0.0, 65.0],
            [130.0, 165.0, 65.0],
            [290.0, 165.0, 114.0],
            [290.0, 0.0, 114.0],
        ],
        [
            [82.0, 0.0, 225.0],
            [82.0, 165.0, 225.0],
            [130.0, 165.0, 65.0],
            [130.0, 0.0, 65.0],
        ],
        [
            [240.0, 0.0, 272.0],
            [240.0, 165.0, 272.0],
            [82.0, 165.0, 225.0],
            [82.0, 0.0, 225.0],
        ],
    ];
    pub const TALL_BLOCK: [[[f32; 3]; 4]; 5] = [
        [
            [423.0, 330.0, 247.0],
            [265.0, 330.0, 296.0],
            [314.0, 330.0, 456.0],
            [472.0, 330.0, 406.0],
        ],
        [
            [423.0, 0.0, 247.0],
            [423.0, 330.0, 247.0],
            [472.0, 330.0, 406.0],
            [472.0, 0.0, 406.0],
        ],
        [
            [472.0, 0.0, 406.0],
            [472.0, 330.0, 406.0],
            [314.0, 330.0, 456.0],
            [314.0, 0.0, 456.0],
        ],
        [
            [314.0, 0.0, 456.0],
            [314.0, 330.0, 456.0],
            [265.0, 330.0, 296.0],
            [265.0, 0.0, 296.0],
        ],
        [
            [265.0, 0.0, 296.0],
            [265.0, 330.0, 296.0],
            [423.0, 330.0, 247.0],
            [423.0, 0.0, 247.0],
        ],
    ];
    /// Camera: position (278, 273, -800), looking along +z, up +y; focal length 35 mm onto a
    /// 25 mm x 25 mm film.
    pub const CAMERA_POSITION: [f32; 3] = [278.0, 273.0, -800.0];
    pub const FOCAL_LENGTH: f32 = 35.0;
    pub const FILM_SIZE: f32 = 25.0;
}

/// Appends the quad `q` (millimetres) to `mesh` in metres, wound counter-clockwise seen from
/// the side `facing` points to, with the flat normal.
fn push_quad(mesh: &mut Mesh, q: [[f32; 3]; 4], facing: Vec3) {
    let mut p = q.map(|c| Vec3::from(c) * 1e-3);
    let n = (p[1] - p[0]).cross(p[2] - p[0]) + (p[2] - p[0]).cross(p[3] - p[0]);
    if n.dot(facing) < 0.0 {
        p.reverse();
    }
    let n = (p[1] - p[0]).cross(p[2] - p[0]).normalize();
    let u = (p[1] - p[0]).normalize();
    // +v runs from corner 3 (v = 0) to corner 0 (v = 1), per the UV table below.
    let w = if n.cross(u).dot(p[0] - p[3]) < 0.0 {
        -1.0
    } else {
        1.0
    };
    let base = mesh.positions.len() as u32;
    for (corner, uv) in p.iter().zip([
        Vec2::new(0.0, 1.0),
        Vec2::new(1.0, 1.0),
        Vec2::new(1.0, 0.0),
        Vec2::new(0.0, 0.0),
    ]) {
        mesh.positions.push(*corner);
        mesh.normals.push(n);
        mesh.uvs.push(uv);
        mesh.tangents.push(u.extend(w));
    }
    mesh.indices
        .extend([base, base + 1, base + 2, base, base + 2, base + 3]);
}

/// Luminance of the Cornell box light, nits. The published emission is a spectrum without
/// an absolute scale that matters for rendering; this value puts the floor under the light at
/// about 50 nits (E ≈ L A / d² with A = 0.0137 m², d = 0.549 m, then albedo 0.72 / π), an
/// interior exposure of about EV 7.
pub const CORNELL_LIGHT_NITS: f32 = 5000.0;

/// The Cornell box with its published dimensions, in metres (see `cornell_data`), seen from
/// the published camera. The interior mask is 1 everywhere: it is a closed room. The
/// surfaces are matte ([`Material::specular`] 0): the published reflectances are those of
/// Lambertian surfaces, which is also what reference renderers draw.
///
/// Colours: the published data give spectral reflectances (400-700 nm); these are the
/// approximate linear RGB albedos derived from them that reference renderers commonly use
/// (for example the Mitsuba and Tungsten Cornell box scenes): white (0.725, 0.71, 0.68), red
/// (0.63, 0.065, 0.05), green (0.14, 0.45, 0.091). The light is the commonly used RGB
/// emission (17, 12, 4) (the published spectrum's shape: more red than blue), scaled to a
/// luminance of [`CORNELL_LIGHT_NITS`]. It is lowered by 0.5 mm below the ceiling, which it
/// would otherwise coincide with (the published light is a patch of the ceiling).
pub fn cornell() -> Scene {
    use cornell_data::*;
    let room_center = Vec3::new(0.278, 0.274, 0.280);
    let white = Vec3::new(0.725, 0.71, 0.68);
    let emission_rgb = Vec3::new(17.0, 12.0, 4.0);
    let luminance = hikari_math::color::luminance(emission_rgb);
    let indoor = |m: Material| Material {
        interior: Some(1.0),
        roughness: 1.0,
        specular: 0.0,
        ..m
    };
    let materials = vec![
        indoor(Material::diffuse("white", white)),
        indoor(Material::diffuse("red", Vec3::new(0.63, 0.065, 0.05))),
        indoor(Material::diffuse("green", Vec3::new(0.14, 0.45, 0.091))),
        indoor(Material::emissive(
            "light",
            emission_rgb * (CORNELL_LIGHT_NITS / luminance),
        )),
    ];
    let inward = |q: [[f32; 3]; 4]| {
        let c = q.iter().map(|p| Vec3::from(*p) * 1e-3).sum::<Vec3>() / 4.0;
        room_center - c
    };
    let mut walls = Mesh {
        name: "cornell white walls".into(),
        ..Default::default()
    };
    for q in [FLOOR, CEILING, BACK] {
        push_quad(&mut walls, q, inward(q));
    }
    let mut red = Mesh {
        name: "cornell red wall".into(),
        ..Default::default()
    };
    push_quad(&mut red, LEFT_RED, inward(LEFT_RED));
    let mut green = Mesh {
        name: "cornell green wall".into(),
        ..Default::default()
    };
    push_quad(&mut green, RIGHT_GREEN, inward(RIGHT_GREEN));
    let mut blocks = Mesh {
        name: "cornell blocks".into(),
        ..Default::default()
    };
    for block in [SHORT_BLOCK, TALL_BLOCK] {
        let centre = block
            .iter()
            .flatten()
            .map(|p| Vec3::from(*p) * 1e-3)
            .sum::<Vec3>()
            / 20.0;
        let centre = Vec3::new(centre.x, 0.0, centre.z);
        for q in block {
            let c = q.iter().map(|p| Vec3::from(*p) * 1e-3).sum::<Vec3>() / 4.0;
            let out = if q.iter().all(|p| p[1] == q[0][1]) {
                Vec3::Y
            } else {
                c - centre.with_y(c.y)
            };
            push_quad(&mut blocks, q, out);
        }
    }
    let mut light = Mesh {
        name: "cornell light".into(),
        ..Default::default()
    };
    push_quad(
        &mut light,
        LIGHT.map(|[x, y, z]| [x, y - 0.5, z]),
        Vec3::NEG_Y,
    );
    let meshes = vec![walls, red, green, blocks, light];
    let instances = [(0, 0), (1, 1), (2, 2), (3, 0), (4, 3)]
        .map(|(mesh, material)| Instance {
            mesh,
            material,
            transform: Mat4::IDENTITY,
        })
        .to_vec();
    let position = Vec3::from(CAMERA_POSITION) * 1e-3;
    Scene {
        meshes,
        materials,
        instances,
        cameras: vec![Camera {
            name: "main".into(),
            position,
            target: position + Vec3::Z,
            vfov_deg: (2.0 * (0.5 * FILM_SIZE / FOCAL_LENGTH).atan()).to_degrees(),
            near: 0.01,
            up: Vec3::Y,
        }],
        sun: None,
        ..Default::default()
    }
}

/// Side of the terrain grid in vertices.
pub const TERRAIN_GRID: usize = 708;
/// Half the side of the terrain in metres: it spans [-100, 100] in x and z.
pub const TERRAIN_HALF_SIZE: f32 = 100.0;

/// The terrain benchmark's height field, metres. Evaluated in f64: in f32 the rounding of
/// 0.7x + 0.3z (up to 100) alone moves the result by about 1e-5.
pub fn terrain_height(x: f32, z: f32) -> f32 {
    let (x, z) = (x as f64, z as f64);
    (5.0 * (0.1 * x).sin() * (0.13 * z).cos() + 2.0 * (0.7 * x + 0.3 * z).sin()) as f32
}

/// (dy/dx, dy/dz) of [`terrain_height`].
pub fn terrain_gradient(x: f32, z: f32) -> Vec2 {
    let (x, z) = (x as f64, z as f64);
    let s = 0.7 * x + 0.3 * z;
    glam::DVec2::new(
        0.5 * (0.1 * x).cos() * (0.13 * z).cos() + 1.4 * s.cos(),
        -0.65 * (0.1 * x).sin() * (0.13 * z).sin() + 0.6 * s.cos(),
    )
    .as_vec2()
}

/// The ray-tracing benchmark height field: a [`TERRAIN_GRID`]² vertex grid over x, z in
/// [-100, 100] m, y = 5 sin(0.1x) cos(0.13z) + 2 sin(0.7x + 0.3z), two triangles per cell
/// (2 x 707² = 999 698 triangles), analytic normals, UVs spanning the grid once; the camera at
/// (0, 40, -120) looking along normalize(0, -0.5, 1) with a vertical field of view of
/// 2 atan(0.4) (an image plane at distance 1 spanning ±0.4 vertically); the default sun.
pub fn terrain() -> Scene {
    let n = TERRAIN_GRID;
    let step = 2.0 * TERRAIN_HALF_SIZE / (n - 1) as f32;
    let mut m = Mesh {
        name: "terrain".into(),
        ..Default::default()
    };
    m.positions.reserve(n * n);
    for j in 0..n {
        for i in 0..n {
            // Coordinates from the index, not by accumulating `step`, so the grid edges land
            // exactly on ±100.
            let x = -TERRAIN_HALF_SIZE + i as f32 * step;
            let z = -TERRAIN_HALF_SIZE + j as f32 * step;
            let g = terrain_gradient(x, z);
            m.positions.push(Vec3::new(x, terrain_height(x, z), z));
            m.normals.push(
                glam::DVec3::new(-g.x as f64, 1.0, -g.y as f64)
                    .normalize()
                    .as_vec3(),
            );
            m.uvs.push(Vec2::new(i as f32, j as f32) / (n - 1) as f32);
            // u along +x: dp/du ∝ (1, dy/dx, 0); v along +z, which is -cross(normal, +x), so w = -1.
            m.tangents
                .push(Vec3::new(1.0, g.x, 0.0).normalize().extend(-1.0));
        }
    }
    m.indices.reserve(6 * (n - 1) * (n - 1));
    for j in 0..n - 1 {
        for i in 0..n - 1 {
            let v00 = (j * n + i) as u32;
            let (v10, v01, v11) = (v00 + 1, v00 + n as u32, v00 + n as u32 + 1);
            // Counter-clockwise seen from above (+y).
            m.indices.extend([v00, v01, v11, v00, v11, v10]);
        }
    }
    let position = Vec3::new(0.0, 40.0, -120.0);
    Scene {
        meshes: vec![m],
        materials: vec![Material {
            interior: Some(0.0),
            ..Material::diffuse("ground", Vec3::new(0.30, 0.28, 0.25))
        }],
        instances: vec![Instance {
            mesh: 0,
            material: 0,
            transform: Mat4::IDENTITY,
        }],
        cameras: vec![Camera {
            name: "main".into(),
            position,
            target: position + Vec3::new(0.0, -0.5, 1.0).normalize(),
            vfov_deg: (2.0 * 0.4f32.atan()).to_degrees(),
            near: 0.1,
            up: Vec3::Y,
        }],
        sun: Some(Sun::default()),
        ..Default::default()
    }
}

/// Side of the [`cutout`] scene's textures in texels.
pub const CUTOUT_TEXTURE_SIZE: u32 = 64;
/// Checker cells along each side of the [`cutout`] scene's checker texture.
pub const CUTOUT_CHECKER_CELLS: u32 = 8;
/// Alpha cut-off of the [`cutout`] scene's ramp quad (the checker uses glTF's default 0.5).
pub const CUTOUT_RAMP_CUTOFF: f32 = 0.25;

/// Whether the checker quad of [`cutout`] is covered at texture coordinate `uv` (in [0, 1]²):
/// cells where the column plus row is even are opaque (alpha 1), the others empty (alpha 0).
/// Exact away from cell edges, where texture filtering blends the two.
pub fn cutout_checker_covered(uv: Vec2) -> bool {
    let cell = (uv * CUTOUT_CHECKER_CELLS as f32).floor();
    (cell.x as i64 + cell.y as i64).rem_euclid(2) == 0
}

/// Alpha of the ramp quad of [`cutout`] at `u` in [0, 1]: the texel column's centre, so it
/// rises from 1/128 at the left edge to 127/128 at the right (constant down each column),
/// stored in 8 bits (within 1/510 of that).
pub fn cutout_ramp_alpha(u: f32) -> f32 {
    let n = CUTOUT_TEXTURE_SIZE as f32;
    let column = (u * n).floor().clamp(0.0, n - 1.0);
    (column + 0.5) / n
}

/// A `size`² RGBA8 texture with white RGB and the alpha `alpha(u, v)` at each texel centre.
fn alpha_texture(name: &str, alpha: impl Fn(Vec2) -> f32) -> Texture {
    let n = CUTOUT_TEXTURE_SIZE;
    let mut data = Vec::with_capacity((n * n * 4) as usize);
    for y in 0..n {
        for x in 0..n {
            let uv = (Vec2::new(x as f32, y as f32) + 0.5) / n as f32;
            let a = (alpha(uv).clamp(0.0, 1.0) * 255.0).round() as u8;
            data.extend_from_slice(&[255, 255, 255, a]);
        }
    }
    Texture {
        name: name.into(),
        width: n,
        height: n,
        data,
        wrap_s: Wrap::ClampToEdge,
        wrap_t: Wrap::ClampToEdge,
    }
}

/// A 2 m square facing +Z, standing on the ground centred at x = `x`, with UVs 0 to 1 across it
/// ((0, 0) at its top left seen from the front, as glTF's UVs).
fn standing_quad(name: &str, x: f32) -> Mesh {
    let (lo, hi) = (Vec3::new(x - 1.0, 0.25, 0.0), Vec3::new(x + 1.0, 2.25, 0.0));
    Mesh {
        name: name.into(),
        positions: vec![
            Vec3::new(lo.x, hi.y, 0.0),
            Vec3::new(hi.x, hi.y, 0.0),
            Vec3::new(hi.x, lo.y, 0.0),
            Vec3::new(lo.x, lo.y, 0.0),
        ],
        normals: vec![Vec3::Z; 4],
        uvs: vec![
            Vec2::new(0.0, 0.0),
            Vec2::new(1.0, 0.0),
            Vec2::new(1.0, 1.0),
            Vec2::new(0.0, 1.0),
        ],
        // +u along +x; +v (down the image) along -y = w cross(+z, +x) = w (+y), so w = -1.
        tangents: vec![Vec3::X.extend(-1.0); 4],
        indices: vec![0, 2, 1, 0, 3, 2],
        ..Default::default()
    }
}

/// Alpha-tested geometry for renderer tests: two double-sided 2 m squares standing 0.25 m
/// above a 12 m ground plane, under the default sun, so their cut-outs show both in the image
/// and in their shadows on the ground.
///
/// - Mesh 1, material `checker cut-out`: [`AlphaMode::Mask`] at the default cut-off 0.5, base
///   colour texture 0 (white, alpha a checker of [`CUTOUT_CHECKER_CELLS`]² cells, see
///   [`cutout_checker_covered`]); centred at x = -1.25.
/// - Mesh 2, material `ramp cut-out`: [`AlphaMode::Mask`] at [`CUTOUT_RAMP_CUTOFF`], base
///   colour texture 1 (white, alpha [`cutout_ramp_alpha`] rising left to right); centred at
///   x = 1.25. Covered right of u ≈ 0.25, so a renderer that ignores the material's cut-off
///   and uses 0.5 shows a narrower quad.
///
/// Both quads lie in the plane z = 0 facing +Z, spanning y from 0.25 to 2.25 m. Camera `main`
/// looks at them from the front; camera `behind` from the back (the double-sided faces).
pub fn cutout() -> Scene {
    let checker = Material {
        base_color_texture: Some(crate::TextureRef::new(0)),
        alpha_mode: AlphaMode::mask(),
        double_sided: true,
        ..Material::diffuse("checker cut-out", Vec3::new(0.8, 0.45, 0.1))
    };
    let ramp = Material {
        base_color_texture: Some(crate::TextureRef::new(1)),
        alpha_mode: AlphaMode::Mask {
            cutoff: CUTOUT_RAMP_CUTOFF,
        },
        double_sided: true,
        ..Material::diffuse("ramp cut-out", Vec3::new(0.1, 0.35, 0.8))
    };
    let textures = vec![
        alpha_texture("checker alpha", |uv| {
            if cutout_checker_covered(uv) { 1.0 } else { 0.0 }
        }),
        alpha_texture("ramp alpha", |uv| cutout_ramp_alpha(uv.x)),
    ];
    let instance = |mesh, material| Instance {
        mesh,
        material,
        transform: Mat4::IDENTITY,
    };
    Scene {
        meshes: vec![
            shapes::plane(12.0),
            standing_quad("checker quad", -1.25),
            standing_quad("ramp quad", 1.25),
        ],
        materials: vec![
            Material::diffuse("ground", Vec3::new(0.5, 0.5, 0.5)),
            checker,
            ramp,
        ],
        instances: vec![instance(0, 0), instance(1, 1), instance(2, 2)],
        cameras: vec![
            Camera {
                name: "main".into(),
                position: Vec3::new(0.0, 1.8, 6.0),
                target: Vec3::new(0.0, 1.0, 0.0),
                vfov_deg: 45.0,
                near: 0.1,
                up: Vec3::Y,
            },
            Camera {
                name: "behind".into(),
                position: Vec3::new(0.0, 1.8, -6.0),
                target: Vec3::new(0.0, 1.0, 0.0),
                vfov_deg: 45.0,
                near: 0.1,
                up: Vec3::Y,
            },
        ],
        sun: Some(Sun::default()),
        textures,
        ..Default::default()
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn every_builtin_scene_validates() {
        for name in super::NAMES {
            super::by_name(name).unwrap().validate().unwrap();
        }
    }
}
