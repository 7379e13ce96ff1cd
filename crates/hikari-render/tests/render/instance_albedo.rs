//! The per-instance albedo of GI hits (`ray_traced_gi::instance_albedo`), on the CPU, against
//! analytic values: a single colour comes back exactly; vertex colours on known faces give their
//! area-weighted mean, without the faces no view can see; metals follow `albedo (1 - F0) + F0`;
//! a textured quad gives its texture's mean; cut-out texels are seen through; a material's
//! override wins and is what `reference::instance_table` uploads.

use glam::{Mat4, Vec2, Vec3};
use hikari_render::techniques::ray_traced_gi::instance_albedo::{InstanceAlbedo, VIEW_RESOLUTION};
use hikari_render::techniques::ray_traced_gi::reference::instance_table;
use hikari_scene::{AlphaMode, Instance, Material, Mesh, Scene, Texture, TextureRef, Wrap};

/// One axis-aligned face: four corners, counter-clockwise seen from outside (`normal`).
struct Quad {
    corners: [Vec3; 4],
    normal: Vec3,
    color: Vec3,
    uvs: [Vec2; 4],
}

fn mesh_of(name: &str, quads: &[Quad]) -> Mesh {
    let mut m = Mesh {
        name: name.into(),
        colors: Some(Vec::new()),
        ..Default::default()
    };
    for q in quads {
        let base = m.positions.len() as u32;
        m.positions.extend(q.corners);
        m.normals.extend([q.normal; 4]);
        m.uvs.extend(q.uvs);
        m.colors.as_mut().unwrap().extend([q.color.extend(1.0); 4]);
        m.indices
            .extend([base, base + 1, base + 2, base, base + 2, base + 3]);
    }
    m
}

const UNIT_UVS: [Vec2; 4] = [
    Vec2::new(0.0, 1.0),
    Vec2::new(1.0, 1.0),
    Vec2::new(1.0, 0.0),
    Vec2::new(0.0, 0.0),
];

/// The six faces of the box `[0, size]`, coloured by `color(axis, sign)`.
fn box_faces(size: Vec3, color: impl Fn(usize, f32) -> Vec3) -> Vec<Quad> {
    let mut quads = Vec::new();
    for axis in 0..3 {
        let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
        for sign in [1.0f32, -1.0] {
            let corner = |a: f32, b: f32| {
                let mut p = Vec3::ZERO;
                p[axis] = if sign > 0.0 { size[axis] } else { 0.0 };
                p[u] = a * size[u];
                p[v] = b * size[v];
                p
            };
            let mut corners = [
                corner(0.0, 0.0),
                corner(1.0, 0.0),
                corner(1.0, 1.0),
                corner(0.0, 1.0),
            ];
            if sign < 0.0 {
                corners.reverse();
            }
            let mut normal = Vec3::ZERO;
            normal[axis] = sign;
            quads.push(Quad {
                corners,
                normal,
                color: color(axis, sign),
                uvs: UNIT_UVS,
            });
        }
    }
    quads
}

fn scene_of(meshes: Vec<Mesh>, materials: Vec<Material>, pairs: &[(usize, usize)]) -> Scene {
    let scene = Scene {
        meshes,
        materials,
        instances: pairs
            .iter()
            .map(|&(mesh, material)| Instance {
                mesh,
                material,
                transform: Mat4::IDENTITY,
            })
            .collect(),
        ..Default::default()
    };
    scene.validate().unwrap();
    scene
}

fn close(got: Vec3, want: Vec3, tol: f32) {
    assert!(
        (got - want).abs().max_element() <= tol,
        "got {got}, want {want} (tolerance {tol})"
    );
}

fn srgb_decode(e: u8) -> f64 {
    // IEC 61966-2-1.
    let c = e as f64 / 255.0;
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

#[test]
fn a_single_colour_mesh_gives_that_colour() {
    // Two boxes, one partly hiding the other: occlusion changes nothing when all is one colour.
    let mut quads = box_faces(Vec3::new(1.0, 2.0, 3.0), |_, _| Vec3::ONE);
    quads.extend(
        box_faces(Vec3::splat(0.5), |_, _| Vec3::ONE)
            .into_iter()
            .map(|mut q| {
                q.corners = q.corners.map(|c| c + Vec3::new(0.8, 0.2, 0.2));
                q
            }),
    );
    let colour = Vec3::new(0.3, 0.6, 0.2);
    let scene = scene_of(
        vec![mesh_of("boxes", &quads)],
        vec![Material::diffuse("green", colour)],
        &[(0, 0)],
    );
    let a = InstanceAlbedo::for_scene(&scene);
    close(a.per_instance[0], colour, 1e-6);
    assert_eq!(a.cost.rays, 6 * 32 * 32);
}

#[test]
fn two_colours_on_known_faces_give_their_visible_area_weighted_mean() {
    // A 1 x 2 x 3 m box, its two X faces (6 m² each) one colour, the other four (3 and 2 m²)
    // another, and a quad inside it of a third colour that no axis view can see.
    let size = Vec3::new(1.0, 2.0, 3.0);
    let (x_colour, other, hidden) = (
        Vec3::new(0.9, 0.1, 0.2),
        Vec3::new(0.1, 0.5, 0.7),
        Vec3::new(0.0, 1.0, 0.0),
    );
    let mut quads = box_faces(size, |axis, _| if axis == 0 { x_colour } else { other });
    quads.push(Quad {
        corners: [
            Vec3::new(0.2, 0.5, 1.0),
            Vec3::new(0.8, 0.5, 1.0),
            Vec3::new(0.8, 1.5, 1.0),
            Vec3::new(0.2, 1.5, 1.0),
        ],
        normal: Vec3::Z,
        color: hidden,
        uvs: UNIT_UVS,
    });
    let scene = scene_of(
        vec![mesh_of("box", &quads)],
        vec![Material::diffuse("white", Vec3::ONE)],
        &[(0, 0)],
    );
    let a = InstanceAlbedo::for_scene(&scene);
    let (ax, ay, az) = (size.y * size.z, size.x * size.z, size.x * size.y);
    let want = (x_colour * 2.0 * ax + other * 2.0 * (ay + az)) / (2.0 * (ax + ay + az));
    close(a.per_instance[0], want, 1e-6);
    // The table the GPU reads holds the same, and the emission record after it.
    let table = instance_table(&scene);
    assert_eq!(Vec3::from_slice(&table[0][..3]), a.per_instance[0]);
    assert_eq!(table[1], [0.0; 4]);
}

#[test]
fn metals_reflect_albedo_times_one_minus_f0_plus_f0() {
    let c = Vec3::new(0.8, 0.5, 0.2);
    let quads = box_faces(Vec3::ONE, |_, _| Vec3::ONE);
    let metal = |name: &str, metalness: f32| Material {
        metalness,
        ..Material::diffuse(name, c)
    };
    let scene = scene_of(
        vec![mesh_of("box", &quads)],
        vec![metal("gold", 1.0), metal("half", 0.25)],
        &[(0, 0), (0, 1)],
    );
    let a = InstanceAlbedo::for_scene(&scene);
    // Metro Exodus: albedo * (1 - F0) + F0 with F0 = base colour for metals.
    let full = c * (Vec3::ONE - c) + c;
    close(a.per_instance[0], full, 1e-6);
    close(a.per_instance[1], c * 0.75 + full * 0.25, 1e-6);
}

fn textured_quad_scene(texture: Texture, material: Material) -> Scene {
    let quad = Quad {
        corners: [
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
        ],
        normal: Vec3::Z,
        color: Vec3::ONE,
        uvs: UNIT_UVS,
    };
    let mut scene = scene_of(vec![mesh_of("quad", &[quad])], vec![material], &[(0, 0)]);
    scene.textures.push(texture);
    scene.materials[0].base_color_texture = Some(TextureRef::new(0));
    scene.validate().unwrap();
    scene
}

#[test]
fn a_textured_quad_gives_its_texture_mean() {
    // 4x4 texels under 32x32 rays a view: each texel's bilinear footprint is sampled by the
    // midpoint rule on a linear function, which is exact, so the mean is the texels' mean.
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let data: Vec<u8> = (0..64)
        .map(|_| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 56) as u8
        })
        .collect();
    let mut want = [0.0f64; 3];
    for px in data.chunks_exact(4) {
        for k in 0..3 {
            want[k] += srgb_decode(px[k]) / 16.0;
        }
    }
    let texture = Texture {
        name: "noise".into(),
        width: 4,
        height: 4,
        data,
        wrap_s: Wrap::Repeat,
        wrap_t: Wrap::Repeat,
    };
    let scene = textured_quad_scene(texture, Material::diffuse("textured", Vec3::ONE));
    let a = InstanceAlbedo::for_scene(&scene);
    let want = Vec3::new(want[0] as f32, want[1] as f32, want[2] as f32);
    close(a.per_instance[0], want, 1e-5);
}

#[test]
fn cut_out_texels_are_seen_through() {
    // A white texture 8 texels wide, its left half alpha 0, on a masked material. The front
    // quad (z = 1, red) samples u = x; the back quad (z = 0, blue) samples u = 0.9 everywhere,
    // which is opaque. From +Z the left half of the front is cut out and shows the back: half
    // red, half blue; from -Z the back hides the front: all blue. The side views see the
    // quads edge on and hit nothing. So the mean is (red + 3 blue) / 4; without the cut-out
    // it would be (red + blue) / 2.
    let (red, blue) = (Vec3::new(1.0, 0.0, 0.0), Vec3::new(0.0, 0.0, 1.0));
    let data: Vec<u8> = (0..8)
        .flat_map(|x| [255, 255, 255, if x < 4 { 0 } else { 255 }])
        .collect();
    let plane = |z: f32, colour: Vec3, uvs: [Vec2; 4]| Quad {
        corners: [
            Vec3::new(0.0, 0.0, z),
            Vec3::new(1.0, 0.0, z),
            Vec3::new(1.0, 1.0, z),
            Vec3::new(0.0, 1.0, z),
        ],
        normal: Vec3::Z,
        color: colour,
        uvs,
    };
    let front_uvs = [
        Vec2::new(0.0, 0.5),
        Vec2::new(1.0, 0.5),
        Vec2::new(1.0, 0.5),
        Vec2::new(0.0, 0.5),
    ];
    let back_uvs = [Vec2::new(0.9, 0.5); 4];
    let mut scene = scene_of(
        vec![mesh_of(
            "planes",
            &[plane(1.0, red, front_uvs), plane(0.0, blue, back_uvs)],
        )],
        vec![Material {
            alpha_mode: AlphaMode::mask(),
            ..Material::diffuse("leaf", Vec3::ONE)
        }],
        &[(0, 0)],
    );
    scene.textures.push(Texture {
        name: "half cut".into(),
        width: 8,
        height: 1,
        data,
        wrap_s: Wrap::ClampToEdge,
        wrap_t: Wrap::ClampToEdge,
    });
    scene.materials[0].base_color_texture = Some(TextureRef::new(0));
    scene.validate().unwrap();
    let a = InstanceAlbedo::for_scene(&scene);
    close(a.per_instance[0], (red + blue * 3.0) / 4.0, 1e-6);
    // The frame BVH's BLASes, marked the same way, give the same table.
    let blases =
        hikari_render::scene::bvh::blases(&scene, &hikari_bvh::BuildOptions::default()).unwrap();
    let b = InstanceAlbedo::with_blases(&scene, &blases, VIEW_RESOLUTION);
    assert_eq!(a.per_instance, b.per_instance);
}

#[test]
fn the_override_wins_and_is_not_rendered() {
    let quads = box_faces(Vec3::ONE, |axis, _| Vec3::splat(axis as f32 / 2.0));
    let over = Vec3::new(0.25, 0.5, 0.75);
    let scene = scene_of(
        vec![mesh_of("box", &quads)],
        vec![
            Material::diffuse("measured", Vec3::ONE),
            Material {
                gi_albedo: Some(over),
                metalness: 1.0,
                ..Material::diffuse("overridden", Vec3::new(0.9, 0.1, 0.1))
            },
        ],
        &[(0, 0), (0, 1), (0, 1)],
    );
    let a = InstanceAlbedo::for_scene(&scene);
    assert_eq!(a.per_instance[1], over);
    assert_eq!(a.per_instance[2], over);
    close(a.per_instance[0], Vec3::splat(0.5), 1e-6);
    assert_eq!((a.cost.pairs, a.cost.rendered), (2, 1));
    let table = instance_table(&scene);
    assert_eq!(table[2], [0.25, 0.5, 0.75, 0.0]);
    assert_eq!(table[4], [0.25, 0.5, 0.75, 0.0]);
}

#[test]
fn a_mesh_that_shows_nothing_falls_back_to_its_material() {
    // Every texel cut out: no hit, so the base colour factor (times the texture's mean, white).
    let texture = Texture {
        name: "clear".into(),
        width: 1,
        height: 1,
        data: vec![255, 255, 255, 0],
        ..Default::default()
    };
    let colour = Vec3::new(0.4, 0.3, 0.2);
    let scene = textured_quad_scene(
        texture,
        Material {
            alpha_mode: AlphaMode::mask(),
            ..Material::diffuse("glass", colour)
        },
    );
    let a = InstanceAlbedo::for_scene(&scene);
    assert_eq!(a.cost.hits, 0);
    close(a.per_instance[0], colour, 1e-6);
}

/// The village's cost, for docs/ray-traced-gi.md: `cargo test [--release] -p hikari-render
/// --test instance_albedo -- --ignored --nocapture village_cost`.
#[test]
#[ignore = "a measurement, not a check"]
fn village_cost() {
    let scene = hikari_scene::builtin::village();
    let t = std::time::Instant::now();
    let a = InstanceAlbedo::for_scene(&scene);
    let total = t.elapsed();
    let triangles: usize = scene.meshes.iter().map(|m| m.indices.len() / 3).sum();
    println!(
        "village: {} instances, {} meshes ({triangles} triangles), {:?}; total {:.0} ms",
        scene.instances.len(),
        scene.meshes.len(),
        a.cost,
        total.as_secs_f64() * 1e3
    );
    assert!(a.per_instance.iter().all(|v| v.is_finite()));
    // With the frame BVH's BLASes (what the renderer could pass): the trace alone.
    let blases =
        hikari_render::scene::bvh::blases(&scene, &hikari_bvh::BuildOptions::default()).unwrap();
    let t = std::time::Instant::now();
    let b = InstanceAlbedo::with_blases(&scene, &blases, VIEW_RESOLUTION);
    println!(
        "village through the frame's BLASes: {:.0} ms",
        t.elapsed().as_secs_f64() * 1e3
    );
    assert_eq!(a.per_instance, b.per_instance);
}
