//! `gbuffer.resolve` against its CPU twin (`gbuffer::reference::resolve`): interpolated
//! normals, vertex colours, per-vertex interior mask, sampled textures, material factors,
//! motion vectors under camera motion, view depth and instance ids.

use crate::common;

use glam::{Mat4, Vec2, Vec3, Vec4};
use hikari_render::techniques::gbuffer;
use hikari_render::techniques::gbuffer::reference::ResolvedTexel;
use hikari_render::{FrameSettings, Renderer, Settings};
use hikari_scene::{Material, Mesh, Scene, Texture, TextureRef, Wrap};

/// 64x64 RGBA8 with R = G = u and B = v, linear ramps: every mip level of a linear ramp is the
/// same ramp, so trilinear filtering at any level returns the bilinear value.
fn ramp_texture(name: &str) -> Texture {
    let n = 64u32;
    let mut data = Vec::new();
    for y in 0..n {
        for x in 0..n {
            let u = ((x as f32 + 0.5) / n as f32 * 255.0).round() as u8;
            let v = ((y as f32 + 0.5) / n as f32 * 255.0).round() as u8;
            data.extend([u, u, v, 255]);
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

fn solid_texture(rgba: [u8; 4]) -> Texture {
    Texture {
        name: "solid".into(),
        width: 4,
        height: 4,
        data: rgba.repeat(16),
        wrap_s: Wrap::Repeat,
        wrap_t: Wrap::Repeat,
    }
}

fn textured_scene() -> Scene {
    let mut scene = hikari_scene::builtin::boxes();
    let quad = Mesh {
        name: "quad".into(),
        positions: vec![
            Vec3::new(-3.0, 0.01, -3.0),
            Vec3::new(3.0, 0.01, -3.0),
            Vec3::new(3.0, 0.01, 3.0),
            Vec3::new(-3.0, 0.01, 3.0),
        ],
        normals: vec![
            Vec3::Y,
            Vec3::new(0.2, 1.0, 0.0).normalize(),
            Vec3::new(0.0, 1.0, 0.3).normalize(),
            Vec3::Y,
        ],
        indices: vec![0, 2, 1, 0, 3, 2],
        // Away from the ramp's ends, where coarser mips stop being the same ramp.
        uvs: vec![
            Vec2::new(0.25, 0.25),
            Vec2::new(0.75, 0.25),
            Vec2::new(0.75, 0.75),
            Vec2::new(0.25, 0.75),
        ],
        colors: Some(vec![
            Vec4::new(1.0, 1.0, 1.0, 1.0),
            Vec4::new(0.5, 1.0, 0.8, 1.0),
            Vec4::new(1.0, 0.3, 0.6, 1.0),
            Vec4::new(0.7, 0.7, 1.0, 1.0),
        ]),
        interior: vec![0.0, 1.0, 0.5, 0.25],
        ..Default::default()
    };
    scene.meshes.push(quad);
    scene.textures.push(ramp_texture("ramp"));
    scene.textures.push(solid_texture([200, 150, 100, 255]));
    scene.materials.push(Material {
        name: "textured".into(),
        base_color: Vec3::new(0.9, 0.8, 1.0),
        roughness: 0.9,
        metalness: 0.7,
        base_color_texture: Some(TextureRef::new(1)),
        metallic_roughness_texture: Some(TextureRef::new(0)),
        occlusion_texture: Some(TextureRef::new(0)),
        occlusion_strength: 0.5,
        emissive_nits: Vec3::new(10.0, 20.0, 30.0),
        specular: 0.375,
        // Under the quad's own per-vertex mask, which wins (`Mesh::interior_at`).
        interior: Some(0.9),
        ..Material::default()
    });
    // The boxes' meshes have no mask of their own: their material's value is theirs.
    scene.materials[0].interior = Some(0.8);
    scene.instances.push(hikari_scene::Instance {
        mesh: scene.meshes.len() - 1,
        material: scene.materials.len() - 1,
        transform: Mat4::from_rotation_y(0.3),
    });
    scene
}

/// 8x8 ramps (as [`ramp_texture`]) with the given wrap modes: few texels over many pixels, so
/// the resolve samples level 0 (magnified) and the twin's bilinear sample is exact even at
/// wrap seams, where coarser mips of a ramp stop being the ramp.
fn small_ramp(name: &str, wrap_s: Wrap, wrap_t: Wrap) -> Texture {
    let n = 8u32;
    let mut data = Vec::new();
    for y in 0..n {
        for x in 0..n {
            let u = ((x as f32 + 0.5) / n as f32 * 255.0).round() as u8;
            let v = ((y as f32 + 0.5) / n as f32 * 255.0).round() as u8;
            data.extend([u, u, v, 255]);
        }
    }
    Texture {
        name: name.into(),
        width: n,
        height: n,
        data,
        wrap_s,
        wrap_t,
    }
}

/// Two quads facing the camera, with a normal map, tangents (one quad's bitangent sign
/// positive, the other's negative), anisotropy, and a texture in every slot whose wrap modes
/// together cover repeat, mirrored repeat and clamp on both axes, all with UVs from -1 to 2.
fn mapped_scene() -> Scene {
    let mut scene = Scene::default();
    let textures = [
        ("normal", Wrap::Repeat, Wrap::Repeat),
        ("base", Wrap::MirroredRepeat, Wrap::Repeat),
        ("metal_rough", Wrap::ClampToEdge, Wrap::ClampToEdge),
        ("occlusion", Wrap::ClampToEdge, Wrap::MirroredRepeat),
        ("emissive", Wrap::Repeat, Wrap::ClampToEdge),
    ];
    for (name, s, t) in textures {
        scene.textures.push(small_ramp(name, s, t));
    }
    // The normal map as tents (0.875 down to 0.125 and back up) in u (R) and v (G): equal
    // across the repeat seam, where a ramp's jump would tilt the normals of a pixel column by
    // degrees for a sub-texel difference of position.
    let tent = |i: u32| ((((2 * i + 1) as f32 / 8.0 - 1.0).abs()) * 255.0).round() as u8;
    scene.textures[0].data = (0..64)
        .flat_map(|k| [tent(k % 8), tent(k / 8), 255, 255])
        .collect();
    scene.materials.push(Material {
        name: "mapped".into(),
        base_color: Vec3::new(0.9, 0.8, 1.0),
        roughness: 0.8,
        metalness: 0.6,
        base_color_texture: Some(TextureRef::new(1)),
        metallic_roughness_texture: Some(TextureRef::new(2)),
        normal_texture: Some(TextureRef::new(0)),
        normal_scale: 0.8,
        occlusion_texture: Some(TextureRef::new(3)),
        occlusion_strength: 0.7,
        emissive_texture: Some(TextureRef::new(4)),
        emissive_nits: Vec3::new(3.0, 2.0, 1.0),
        anisotropy: Some(hikari_scene::Anisotropy {
            strength: 0.6,
            rotation: 0.7,
        }),
        ..Material::default()
    });
    for (k, sign) in [(0, 1.0), (1, -1.0)] {
        let x0 = if k == 0 { -2.1 } else { 0.1 };
        scene.meshes.push(Mesh {
            name: format!("mapped quad {k}"),
            positions: vec![
                Vec3::new(x0, -1.0, 0.0),
                Vec3::new(x0 + 2.0, -1.0, 0.0),
                Vec3::new(x0 + 2.0, 1.0, 0.0),
                Vec3::new(x0, 1.0, 0.0),
            ],
            normals: vec![
                Vec3::Z,
                Vec3::new(0.2, 0.0, 1.0).normalize(),
                Vec3::new(0.0, 0.3, 1.0).normalize(),
                Vec3::new(-0.1, 0.1, 1.0).normalize(),
            ],
            // Not along the UV axes, and varying: the resolve interpolates and
            // re-orthogonalises them.
            tangents: vec![
                Vec4::new(1.0, 0.2, 0.0, sign),
                Vec4::new(0.9, -0.3, 0.1, sign),
                Vec4::new(1.0, 0.4, -0.2, sign),
                Vec4::new(0.8, 0.0, 0.0, sign),
            ],
            indices: vec![0, 1, 2, 0, 2, 3],
            uvs: vec![
                Vec2::new(-1.0, 2.0),
                Vec2::new(2.0, 2.0),
                Vec2::new(2.0, -1.0),
                Vec2::new(-1.0, -1.0),
            ],
            ..Default::default()
        });
        scene.instances.push(hikari_scene::Instance {
            mesh: k,
            material: 0,
            transform: Mat4::from_rotation_y(if k == 0 { 0.3 } else { -0.2 }),
        });
    }
    scene.cameras.push(hikari_scene::Camera {
        name: "front".into(),
        position: Vec3::new(0.0, 0.0, 3.5),
        target: Vec3::ZERO,
        vfov_deg: 40.0,
        near: 0.1,
        up: Vec3::Y,
    });
    scene
}

/// CPU twin of the resolve's shading frame for normal-mapped materials (which
/// `gbuffer::reference::resolve` leaves out): the normal after the normal map and the
/// anisotropy direction, from the scene's own (unquantised) vertex data, in f64.
fn mapped_frame(
    scene: &Scene,
    view: &hikari_render::view::View,
    pixel: [u32; 2],
    instance: usize,
    triangle: usize,
) -> (Vec3, Vec3) {
    use glam::{DMat3, DMat4, DVec2, DVec3, DVec4};
    let inst = &scene.instances[instance];
    let mesh = &scene.meshes[inst.mesh];
    let material = &scene.materials[inst.material];
    let idx = [0, 1, 2].map(|k| mesh.indices[triangle * 3 + k] as usize);
    let model = inst.transform.as_dmat4();
    let world = idx.map(|i| model.transform_point3(mesh.positions[i].as_dvec3()));
    let inv = DMat4::from_cols_array_2d(&view.inv_view_proj.map(|c| c.map(|x| x as f64)));
    let size = DVec2::new(view.viewport[0] as f64, view.viewport[1] as f64);
    let uv = (DVec2::new(pixel[0] as f64, pixel[1] as f64) + 0.5) / size;
    let near = inv * DVec4::new(uv.x * 2.0 - 1.0, 1.0 - uv.y * 2.0, 1.0, 1.0);
    let eye = DVec3::from_array(view.position.map(|x| x as f64)[..3].try_into().unwrap());
    let dir = near.truncate() / near.w - eye;
    let ng = (world[1] - world[0]).cross(world[2] - world[0]);
    let p = eye + dir * ((world[0] - eye).dot(ng) / dir.dot(ng));
    let area = |a: DVec3, b: DVec3, c: DVec3| (b - a).cross(c - a).dot(ng) / ng.dot(ng);
    let w = [
        area(p, world[1], world[2]),
        area(world[0], p, world[2]),
        area(world[0], world[1], p),
    ];
    let lerp = |f: &dyn Fn(usize) -> DVec3| (0..3).map(|k| f(idx[k]) * w[k]).sum::<DVec3>();
    let model3 = DMat3::from_mat4(model);
    let mut n = (model3.inverse().transpose() * lerp(&|i| mesh.normals[i].normalize().as_dvec3()))
        .normalize();
    let t = model3 * lerp(&|i| mesh.tangents[i].truncate().normalize().as_dvec3());
    let mut t = (t - n * n.dot(t)).normalize();
    // The sign of the triangle's first vertex, as glTF gives one per vertex.
    let handedness = mesh.tangents[idx[0]].w.signum() as f64;
    let mut bt = n.cross(t) * handedness;
    let uv = lerp(&|i| mesh.uvs[i].as_dvec2().extend(0.0)).truncate();
    let twin = gbuffer::reference::TwinTextures { scene };
    let tex = material.normal_texture.unwrap().texture;
    let xy = (twin.sample(tex, uv, false).truncate().truncate() * 2.0 - 1.0)
        * material.normal_scale as f64;
    let tn = xy.extend((1.0 - xy.length_squared()).max(0.0).sqrt());
    n = (t * tn.x + bt * tn.y + n * tn.z).normalize();
    t = (t - n * n.dot(t)).normalize();
    bt = n.cross(t) * handedness;
    let rot = material.anisotropy.map_or(0.0, |a| a.rotation) as f64;
    let aniso = (t * rot.cos() + bt * rot.sin()).normalize();
    (n.as_vec3(), aniso.as_vec3())
}

/// Angle in degrees a normal-mapped normal or anisotropy direction may be off: the filtered
/// 8-bit map is good to about 1/255, which (times 2 to reach [-1, 1], times the normal scale
/// 0.8) tilts the normal by up to 0.36 degrees an axis.
const MAPPED_TOLERANCE_DEG: f32 = 1.0;

/// Pixels the resolve wrote against its CPU twin, by instance; panics listing the failures.
fn resolve_against_twin(scene: &Scene, w: u32, h: u32) -> Vec<usize> {
    let ctx = common::gpu_context();
    let camera = scene.cameras[0].clone();
    let mut prev = camera.clone();
    prev.position += Vec3::new(0.3, -0.1, 0.2);
    prev.target += Vec3::new(0.1, 0.05, 0.0);
    let s = FrameSettings {
        width: w,
        height: h,
        camera,
        prev_camera: Some(prev.clone()),
        sun: scene.sun.clone().into(),
        settings: Settings {
            // The G-buffer does not depend on the sky: skip the atmosphere's table build.
            sky: hikari_render::settings::SkySettings {
                enabled: false,
                ..Default::default()
            },
            ..Settings::default()
        },
    };
    let mut renderer = Renderer::new(ctx, scene).unwrap();
    // The second frame, whose TAA jitter moves the image by a sub-pixel offset and which the
    // motion vectors must leave out.
    renderer.render(&s, false).unwrap();
    let mut r = renderer
        .render_reading(&s, |o| {
            let g = &o.gbuffer;
            vec![
                g.visibility.into(),
                g.normal.into(),
                g.albedo.into(),
                g.material.into(),
                g.motion.into(),
                g.emissive.into(),
                g.instance.into(),
                g.vertex_normal.into(),
            ]
        })
        .unwrap();
    let vis: Vec<u32> = bytemuck::cast_slice(r.buffer("gbuffer.visibility").unwrap()).to_vec();
    let mut img = |n: &str| r.take_image(n).unwrap();
    let vertex_normal = img("gbuffer.vertex_normal");
    let (normal, albedo, material, motion, emissive, instance) = (
        img("gbuffer.normal"),
        img("gbuffer.albedo"),
        img("gbuffer.material"),
        img("gbuffer.motion"),
        img("gbuffer.emissive"),
        img("gbuffer.instance"),
    );
    let jitter =
        hikari_render::techniques::taa::reference::jitter(1, s.settings.taa.jitter_samples);
    assert!(jitter != [0.0; 2]);
    let view = hikari_render::view::View::with_previous(&s.camera, &prev, w, h).jittered(jitter);
    let cpu = &renderer.scene().cpu;
    // The twin leaves normal maps out: it resolves everything else from the scene without
    // them, and `mapped_frame` gives the normal and anisotropy direction.
    let mut unmapped = scene.clone();
    for m in &mut unmapped.materials {
        m.normal_texture = None;
    }
    let firsts: Vec<u32> = scene
        .meshes
        .iter()
        .scan(0, |first, m| {
            let f = *first;
            *first += m.indices.len() as u32 / 3;
            Some(f)
        })
        .collect();
    let (mut seen, mut failures) = (vec![0; scene.instances.len()], Vec::new());
    for y in 0..h {
        for x in 0..w {
            let i = (y * w + x) as usize;
            if vis[2 * i + 1] == 0 {
                assert_eq!(
                    instance.pixel(x, y)[0],
                    u32::MAX as f32,
                    "sky has no instance"
                );
                continue;
            }
            let mut want: ResolvedTexel =
                gbuffer::reference::resolve(&unmapped, cpu, &view, [x, y], vis[2 * i]).unwrap();
            seen[want.instance as usize] += 1;
            let inst = &scene.instances[want.instance as usize];
            let mapped = scene.materials[inst.material].normal_texture.is_some();
            // The twin's normal before any normal map is the vertex normal (8-bit snorm).
            let vn = Vec3::from_slice(&vertex_normal.pixel(x, y)[..3]).normalize();
            let vertex_normal_ok = vn.dot(want.normal) > 1f32.to_radians().cos();
            let nv = normal.pixel(x, y);
            let decode =
                |a: f32, b: f32| hikari_render::reference::octahedral::decode(Vec2::new(a, b));
            let (n, aniso) = (decode(nv[0], nv[1]), decode(nv[2], nv[3]));
            let mut aniso_ok = true;
            let normal_tolerance = if mapped { MAPPED_TOLERANCE_DEG } else { 0.5 };
            if mapped {
                let id = vis[2 * i];
                let chunk = &cpu.chunks[(id / 64) as usize];
                let mesh = scene.instances[chunk.instance as usize].mesh;
                let (inst, tri) = gbuffer::reference::decode_id(cpu, id, firsts[mesh]).unwrap();
                let (wn, wa) = mapped_frame(scene, &view, [x, y], inst as usize, tri as usize);
                want.normal = wn;
                aniso_ok = aniso.dot(wa) > MAPPED_TOLERANCE_DEG.to_radians().cos();
            }
            let material_of = &scene.materials[inst.material];
            let emissive_tol = if material_of.emissive_texture.is_some() {
                material_of.emissive_nits * (2.5 / 255.0)
            } else {
                Vec3::ZERO
            };
            let a = albedo.pixel(x, y);
            let m = material.pixel(x, y);
            let mv = motion.pixel(x, y);
            let e = emissive.pixel(x, y);
            let close = |got: f32, want: f32, abs: f32, rel: f32| {
                (got - want).abs() <= abs + rel * want.abs()
            };
            let checks = [
                (
                    "normal",
                    n.dot(want.normal) > normal_tolerance.to_radians().cos(),
                ),
                ("anisotropy direction", aniso_ok),
                ("vertex normal", vertex_normal_ok),
                ("albedo r", close(a[0], want.base_color.x, 2.5 / 255.0, 0.0)),
                ("albedo g", close(a[1], want.base_color.y, 2.5 / 255.0, 0.0)),
                ("albedo b", close(a[2], want.base_color.z, 2.5 / 255.0, 0.0)),
                ("interior", close(a[3], want.interior, 1.0 / 255.0, 0.0)),
                // Ramp texels are quantised to 1/255 before filtering.
                ("roughness", close(m[0], want.roughness, 3.0 / 255.0, 0.0)),
                ("metalness", close(m[1], want.metalness, 3.0 / 255.0, 0.0)),
                ("anisotropy", close(m[2], want.anisotropy, 1.0 / 255.0, 0.0)),
                ("occlusion", close(m[3], want.occlusion, 3.0 / 255.0, 0.0)),
                ("motion x", close(mv[0], want.motion.x, 0.02, 2e-3)),
                ("motion y", close(mv[1], want.motion.y, 0.02, 2e-3)),
                ("view depth", close(mv[2], want.view_depth, 0.0, 2e-3)),
                // A texture's sRGB texels filter to within 2.5/255 as the albedo's do, times
                // the factor.
                (
                    "emissive r",
                    close(e[0], want.emissive.x, emissive_tol.x, 2e-3),
                ),
                (
                    "emissive b",
                    close(e[2], want.emissive.z, emissive_tol.z, 2e-3),
                ),
                ("specular", close(e[3], want.specular, 0.0, 1e-3)),
                ("instance", instance.pixel(x, y)[0] == want.instance as f32),
            ];
            for (what, ok) in checks {
                if !ok {
                    failures.push(format!(
                        "({x}, {y}) {what}: got {nv:?} {a:?} {m:?} {mv:?} {e:?}, want {want:?}"
                    ));
                }
            }
        }
    }
    let mut kinds: Vec<&str> = failures
        .iter()
        .map(|f| {
            f.split(") ")
                .nth(1)
                .unwrap_or("")
                .split(':')
                .next()
                .unwrap_or("")
        })
        .collect();
    kinds.sort();
    let mut counts: Vec<(&str, usize)> = Vec::new();
    for k in kinds {
        match counts.last_mut() {
            Some((last, n)) if *last == k => *n += 1,
            _ => counts.push((k, 1)),
        }
    }
    assert!(
        failures.is_empty(),
        "{} failures ({counts:?}), first: {}",
        failures.len(),
        failures[..failures.len().min(4)].join("\n")
    );
    seen
}

#[test]
fn resolve_matches_its_cpu_twin() {
    let scene = textured_scene();
    let seen = resolve_against_twin(&scene, 128, 96);
    let textured = *seen.last().unwrap();
    let checked: usize = seen.iter().sum();
    assert!(
        checked > 4000 && textured > 300,
        "{checked} surface pixels, {textured} textured"
    );
}

#[test]
fn normal_maps_tangents_anisotropy_and_wrap_modes_match_the_twin() {
    let scene = mapped_scene();
    let seen = resolve_against_twin(&scene, 128, 64);
    // Both quads, each over many texels of every wrap region.
    assert!(
        seen.iter().all(|&n| n > 1500),
        "pixels seen by instance: {seen:?}"
    );
}
