//! glTF files written here (JSON plus buffers in the three containers: data URIs, external
//! files, .glb), loaded, and compared with what was written: node transforms, materials and
//! textures, cameras, punctual lights, emissive strength, automatic framing and default sun.

mod common;
use common::base64;

use std::path::{Path, PathBuf};

use glam::{Mat4, Quat, Vec3, Vec4};
use hikari_scene::gltf::{GltfOptions, load, load_with};
use hikari_scene::{LightKind, Sun, Wrap};
use serde_json::{Value, json};

fn dir(test: &str) -> PathBuf {
    let d = PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join("gltf_roundtrip")
        .join(test);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// One binary buffer being filled with views and accessors.
#[derive(Default)]
struct Bin {
    data: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
}

impl Bin {
    fn view(&mut self, bytes: &[u8]) -> usize {
        while !self.data.len().is_multiple_of(4) {
            self.data.push(0);
        }
        self.views
            .push(json!({"buffer": 0, "byteOffset": self.data.len(), "byteLength": bytes.len()}));
        self.data.extend_from_slice(bytes);
        self.views.len() - 1
    }

    fn floats(&mut self, v: &[f32], ty: &str, comps: usize) -> usize {
        let bytes: Vec<u8> = v.iter().flat_map(|x| x.to_le_bytes()).collect();
        let view = self.view(&bytes);
        let mut acc = json!({"bufferView": view, "componentType": 5126, "count": v.len() / comps, "type": ty});
        if ty == "VEC3" {
            let (mut lo, mut hi) = (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN));
            for p in v.chunks(3) {
                lo = lo.min(Vec3::from_slice(p));
                hi = hi.max(Vec3::from_slice(p));
            }
            acc["min"] = json!(lo.to_array());
            acc["max"] = json!(hi.to_array());
        }
        self.accessors.push(acc);
        self.accessors.len() - 1
    }

    fn indices(&mut self, v: &[u16]) -> usize {
        let bytes: Vec<u8> = v.iter().flat_map(|x| x.to_le_bytes()).collect();
        let view = self.view(&bytes);
        self.accessors.push(
            json!({"bufferView": view, "componentType": 5123, "count": v.len(), "type": "SCALAR"}),
        );
        self.accessors.len() - 1
    }
}

fn png(width: u32, height: u32, rgba: &[u8]) -> Vec<u8> {
    let mut out = Vec::new();
    image::RgbaImage::from_raw(width, height, rgba.to_vec())
        .unwrap()
        .write_to(&mut std::io::Cursor::new(&mut out), image::ImageFormat::Png)
        .unwrap();
    out
}

fn gray_png() -> Vec<u8> {
    let mut out = Vec::new();
    image::GrayImage::from_raw(1, 1, vec![77])
        .unwrap()
        .write_to(&mut std::io::Cursor::new(&mut out), image::ImageFormat::Png)
        .unwrap();
    out
}

const TEX_RGBA: [u8; 16] = [
    255, 0, 0, 255, 0, 255, 0, 255, 0, 0, 255, 255, 10, 20, 30, 40,
];

#[derive(Clone, Copy, PartialEq)]
enum Container {
    DataUri,
    External,
    Glb,
}

/// The full-featured test file in `container`; returns its path.
fn write_full(container: Container, dir: &Path) -> PathBuf {
    let mut bin = Bin::default();
    let positions = [
        -1.0, -1.0, 0.0, 1.0, -1.0, 0.0, 1.0, 1.0, 0.0, -1.0, 1.0, 0.0,
    ];
    let pos = bin.floats(&positions, "VEC3", 3);
    let nrm = bin.floats(&[0.0, 0.0, 1.0].repeat(4), "VEC3", 3);
    let uv = bin.floats(&[0.0, 1.0, 1.0, 1.0, 1.0, 0.0, 0.0, 0.0], "VEC2", 2);
    let idx = bin.indices(&[0, 1, 2, 0, 2, 3]);
    let tex_png = png(2, 2, &TEX_RGBA);
    let image0 = match container {
        Container::External => {
            std::fs::write(dir.join("tex 0.png"), &tex_png).unwrap();
            json!({"uri": "tex%200.png"})
        }
        _ => json!({"bufferView": bin.view(&tex_png), "mimeType": "image/png"}),
    };
    let image1 = json!({"uri": format!("data:image/png;base64,{}", base64(&gray_png()))});
    let s = std::f32::consts::FRAC_1_SQRT_2;
    let (sx, cx) = (
        (-std::f32::consts::FRAC_PI_8).sin(),
        (-std::f32::consts::FRAC_PI_8).cos(),
    );
    let mut doc = json!({
        "asset": {"version": "2.0", "generator": "hikari-scene tests"},
        "extensionsUsed": ["KHR_lights_punctual", "KHR_materials_emissive_strength", "EXT_made_up_thing"],
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [
            {"name": "root", "translation": [1.0, 2.0, 3.0], "scale": [2.0, 2.0, 2.0], "children": [1, 2, 3, 4, 5]},
            {"name": "child", "rotation": [0.0, s, 0.0, s], "mesh": 0},
            {"name": "camera node", "translation": [0.0, 0.0, 10.0], "camera": 0},
            {"name": "bulb node", "translation": [0.0, 5.0, 0.0], "extensions": {"KHR_lights_punctual": {"light": 0}}},
            {"name": "spot node", "rotation": [-s, 0.0, 0.0, s], "extensions": {"KHR_lights_punctual": {"light": 1}}},
            {"name": "sun node", "rotation": [sx, 0.0, 0.0, cx], "extensions": {"KHR_lights_punctual": {"light": 2}}}
        ],
        "cameras": [{"name": "front", "type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.05, "aspectRatio": 1.5}}],
        "extensions": {"KHR_lights_punctual": {"lights": [
            {"name": "bulb", "type": "point", "intensity": 50.0, "color": [1.0, 0.5, 0.25], "range": 10.0},
            {"type": "spot", "intensity": 20.0, "spot": {"innerConeAngle": 0.2, "outerConeAngle": 0.5}},
            {"type": "directional", "intensity": 5000.0}
        ]}},
        "meshes": [{"name": "quad", "primitives": [
            {"attributes": {"POSITION": pos, "NORMAL": nrm, "TEXCOORD_0": uv}, "indices": idx, "material": 0},
            {"attributes": {"POSITION": pos}, "mode": 0, "material": 0}
        ]}],
        "materials": [{
            "name": "glow",
            "doubleSided": true,
            "pbrMetallicRoughness": {
                "baseColorFactor": [0.5, 0.25, 1.0, 0.8],
                "metallicFactor": 0.3,
                "roughnessFactor": 0.6,
                "baseColorTexture": {"index": 0},
                "metallicRoughnessTexture": {"index": 1}
            },
            "normalTexture": {"index": 0, "scale": 0.5},
            "occlusionTexture": {"index": 1, "strength": 0.7},
            "emissiveTexture": {"index": 0},
            "emissiveFactor": [1.0, 0.5, 0.25],
            "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 40.0}}
        }],
        "samplers": [{"wrapS": 33071, "wrapT": 33648}],
        "textures": [{"source": 0, "sampler": 0}, {"source": 1, "name": "gray"}],
        "images": [image0, image1],
        "bufferViews": bin.views,
        "accessors": bin.accessors,
    });
    let len = bin.data.len();
    match container {
        Container::DataUri => {
            doc["buffers"] = json!([{"uri": format!("data:application/octet-stream;base64,{}", base64(&bin.data)), "byteLength": len}]);
            let path = dir.join("full.gltf");
            std::fs::write(&path, serde_json::to_vec_pretty(&doc).unwrap()).unwrap();
            path
        }
        Container::External => {
            std::fs::write(dir.join("full.bin"), &bin.data).unwrap();
            doc["buffers"] = json!([{"uri": "full.bin", "byteLength": len}]);
            let path = dir.join("full.gltf");
            std::fs::write(&path, serde_json::to_vec_pretty(&doc).unwrap()).unwrap();
            path
        }
        Container::Glb => {
            doc["buffers"] = json!([{"byteLength": len}]);
            let path = dir.join("full.glb");
            std::fs::write(&path, glb(&serde_json::to_vec(&doc).unwrap(), &bin.data)).unwrap();
            path
        }
    }
}

fn glb(json: &[u8], bin: &[u8]) -> Vec<u8> {
    let mut json = json.to_vec();
    while !json.len().is_multiple_of(4) {
        json.push(b' ');
    }
    let mut bin = bin.to_vec();
    while !bin.len().is_multiple_of(4) {
        bin.push(0);
    }
    let total = 12 + 8 + json.len() + 8 + bin.len();
    let mut out = Vec::new();
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(json.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&json);
    out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
    out.extend_from_slice(b"BIN\0");
    out.extend_from_slice(&bin);
    out
}

fn close(a: Vec3, b: Vec3) -> bool {
    (a - b).length() < 1e-4
}

fn check_full(path: &Path) {
    let loaded = load(path).unwrap_or_else(|e| panic!("{e}"));
    let scene = &loaded.scene;
    let w = loaded.warnings.join("\n");
    assert!(w.contains("EXT_made_up_thing"), "{w}");
    assert!(w.contains("Points skipped"), "{w}");

    // Node transforms: root T(1,2,3) S(2), child R_y(90°).
    assert_eq!(scene.instances.len(), 1);
    assert_eq!(scene.meshes.len(), 1);
    let expected = Mat4::from_scale_rotation_translation(
        Vec3::splat(2.0),
        Quat::from_rotation_y(std::f32::consts::FRAC_PI_2),
        Vec3::new(1.0, 2.0, 3.0),
    );
    let t = scene.instances[0].transform;
    assert!(t.abs_diff_eq(expected, 1e-5), "{t}");
    assert!(close(t.transform_point3(Vec3::X), Vec3::new(1.0, 2.0, 1.0)));

    // Mesh: streams, and tangents generated because the material has a normal map.
    let m = &scene.meshes[0];
    assert_eq!(m.positions.len(), 4);
    assert_eq!(m.indices, vec![0, 1, 2, 0, 2, 3]);
    assert_eq!(m.normals, vec![Vec3::Z; 4]);
    assert_eq!(m.uvs[1], glam::Vec2::new(1.0, 1.0));
    for tan in &m.tangents {
        // u along +x, v down the image (-y): bitangent -y = w * cross(+z, +x) = w * +y.
        assert!(
            tan.abs_diff_eq(Vec4::new(1.0, 0.0, 0.0, -1.0), 1e-5),
            "{tan}"
        );
    }

    // Material.
    let mat = &scene.materials[scene.instances[0].material];
    assert_eq!(mat.name, "glow");
    assert!(close(mat.base_color, Vec3::new(0.5, 0.25, 1.0)));
    assert_eq!((mat.alpha, mat.metalness, mat.roughness), (0.8, 0.3, 0.6));
    assert!(
        close(mat.emissive_nits, Vec3::new(40.0, 20.0, 10.0)),
        "{}",
        mat.emissive_nits
    );
    assert!(mat.double_sided);
    assert_eq!(mat.base_color_texture.unwrap().texture, 0);
    assert_eq!(mat.metallic_roughness_texture.unwrap().texture, 1);
    assert_eq!(mat.normal_texture.unwrap().texture, 0);
    assert_eq!(mat.emissive_texture.unwrap().texture, 0);
    assert_eq!(mat.occlusion_texture.unwrap().texture, 1);
    assert_eq!((mat.normal_scale, mat.occlusion_strength), (0.5, 0.7));
    assert_eq!(mat.interior, None);

    // Textures: decoded RGBA8, samplers' wrap modes, gray expanded.
    assert_eq!(scene.textures.len(), 2);
    let t0 = &scene.textures[0];
    assert_eq!((t0.width, t0.height), (2, 2));
    assert_eq!(t0.data, TEX_RGBA.to_vec());
    assert_eq!(
        (t0.wrap_s, t0.wrap_t),
        (Wrap::ClampToEdge, Wrap::MirroredRepeat)
    );
    let t1 = &scene.textures[1];
    assert_eq!(t1.name, "gray");
    assert_eq!(t1.data, vec![77, 77, 77, 255]);
    assert_eq!((t1.wrap_s, t1.wrap_t), (Wrap::Repeat, Wrap::Repeat));

    // Camera: root scale moves it to 1,2,3 + 2 * (0,0,10).
    assert_eq!(scene.cameras.len(), 1);
    let c = &scene.cameras[0];
    assert_eq!(c.name, "front");
    assert!(
        close(c.position, Vec3::new(1.0, 2.0, 23.0)),
        "{}",
        c.position
    );
    assert!(close(c.forward(), Vec3::NEG_Z));
    assert!(close(c.up, Vec3::Y));
    assert!((c.vfov_deg - 0.8f32.to_degrees()).abs() < 1e-4);
    assert_eq!(c.near, 0.05);

    // Lights.
    assert_eq!(scene.lights.len(), 2);
    let bulb = &scene.lights[0];
    assert_eq!(bulb.name, "bulb");
    assert_eq!(bulb.kind, LightKind::Point);
    assert!(
        close(bulb.position, Vec3::new(1.0, 12.0, 3.0)),
        "{}",
        bulb.position
    );
    assert_eq!((bulb.intensity_cd, bulb.range), (50.0, Some(10.0)));
    assert!(close(bulb.color, Vec3::new(1.0, 0.5, 0.25)));
    let spot = &scene.lights[1];
    assert_eq!(spot.name, "spot node");
    assert_eq!(
        spot.kind,
        LightKind::Spot {
            inner_cone: 0.2,
            outer_cone: 0.5
        }
    );
    assert!(close(spot.direction, Vec3::NEG_Y), "{}", spot.direction);
    assert_eq!(spot.intensity_cd, 20.0);
    let sun = scene.sun.as_ref().unwrap();
    assert_eq!(sun.illuminance_lux, 5000.0);
    // The light shines along the node's -Z, turned 45° down; the sun is the other way.
    assert!(
        close(sun.direction, Vec3::new(0.0, 1.0, 1.0).normalize()),
        "{}",
        sun.direction
    );
}

#[test]
fn gltf_with_data_uris_round_trips() {
    check_full(&write_full(Container::DataUri, &dir("data_uri")));
}

#[test]
fn gltf_with_external_files_round_trips() {
    check_full(&write_full(Container::External, &dir("external")));
}

#[test]
fn glb_round_trips() {
    check_full(&write_full(Container::Glb, &dir("glb")));
}

#[test]
fn emissive_scale_is_an_option() {
    let path = write_full(Container::DataUri, &dir("emissive_option"));
    let loaded = load_with(
        &path,
        &GltfOptions {
            emissive_nits_per_unit: 100.0,
        },
    )
    .unwrap();
    let e = loaded.scene.materials[0].emissive_nits;
    assert!(close(e, Vec3::new(4000.0, 2000.0, 1000.0)), "{e}");
}

/// Two triangles far from the origin under a rotated, scaled parent; no camera, no light, no
/// normals, no material.
fn write_bare(dir: &Path) -> PathBuf {
    let mut bin = Bin::default();
    let positions = [
        0.0, 0.0, 0.0, 4.0, 0.0, 0.0, 0.0, 3.0, 0.0, 0.0, 0.0, 5.0, 4.0, 0.0, 5.0, 0.0, 3.0, 5.0,
    ];
    let pos = bin.floats(&positions, "VEC3", 3);
    let doc = json!({
        "asset": {"version": "2.0"},
        "nodes": [
            {"translation": [50.0, -20.0, 7.0], "rotation": [0.2, 0.3, 0.1, 0.927], "scale": [3.0, 1.0, 2.0], "children": [1]},
            {"mesh": 0}
        ],
        "meshes": [{"primitives": [{"attributes": {"POSITION": pos}}]}],
        "buffers": [{"uri": format!("data:application/octet-stream;base64,{}", base64(&bin.data)), "byteLength": bin.data.len()}],
        "bufferViews": bin.views,
        "accessors": bin.accessors,
    });
    let path = dir.join("bare.gltf");
    std::fs::write(&path, serde_json::to_vec(&doc).unwrap()).unwrap();
    path
}

#[test]
fn a_bare_file_gets_a_framing_camera_the_default_sun_and_flat_normals() {
    let loaded = load(write_bare(&dir("bare"))).unwrap_or_else(|e| panic!("{e}"));
    let scene = &loaded.scene;
    assert_eq!(
        scene.sun.as_ref().unwrap().illuminance_lux,
        Sun::default().illuminance_lux
    );
    assert_eq!(
        scene.sun.as_ref().unwrap().direction,
        Sun::default().direction
    );
    assert!(scene.lights.is_empty());
    assert_eq!(scene.cameras.len(), 1);
    assert_eq!(scene.cameras[0].name, "auto");
    // No scenes in the file: root nodes are used. No normals: flat ones, one per triangle.
    assert_eq!(scene.instances.len(), 1);
    let m = &scene.meshes[0];
    assert_eq!(m.positions.len(), 6);
    assert_eq!(m.normals[0], Vec3::Z);
    assert_eq!(m.normals[3], Vec3::Z);
    // No material: the glTF default (white, metallic 1, roughness 1).
    let mat = &scene.materials[scene.instances[0].material];
    assert_eq!(
        (mat.base_color, mat.metalness, mat.roughness),
        (Vec3::ONE, 1.0, 1.0)
    );

    let (lo, hi) = scene.bounds().unwrap();
    assert!(lo.x > 40.0, "bounds {lo} {hi} should be in world space");
    for aspect in [1.0, 16.0 / 9.0, 2.4] {
        assert_inside_frustum(&scene.cameras[0], aspect, lo, hi);
    }
}

fn assert_inside_frustum(c: &hikari_scene::Camera, aspect: f32, lo: Vec3, hi: Vec3) {
    let vp = c.projection(aspect) * c.view();
    for i in 0..8 {
        let p = Vec3::new(
            if i & 1 == 0 { lo.x } else { hi.x },
            if i & 2 == 0 { lo.y } else { hi.y },
            if i & 4 == 0 { lo.z } else { hi.z },
        );
        let clip = vp * p.extend(1.0);
        let ndc = clip.truncate() / clip.w;
        assert!(clip.w > 0.0, "corner {p} is behind the camera");
        assert!(
            ndc.x.abs() <= 1.0 && ndc.y.abs() <= 1.0,
            "corner {p} is outside the view at aspect {aspect}: {ndc}"
        );
        // Reverse Z: depth in (0, 1] means beyond the near plane.
        assert!(
            ndc.z > 0.0 && ndc.z <= 1.0,
            "corner {p} is in front of the near plane: {ndc}"
        );
    }
}

#[test]
fn framing_holds_for_many_boxes() {
    let boxes = [
        (Vec3::ZERO, Vec3::ONE),
        (Vec3::splat(-1000.0), Vec3::splat(1000.0)),
        (Vec3::new(-0.001, 0.0, 0.0), Vec3::new(0.001, 0.0, 0.0)),
        (Vec3::new(5.0, 5.0, 5.0), Vec3::new(5.0, 5.0, 5.0)),
        (Vec3::new(-100.0, -1.0, -3.0), Vec3::new(100.0, 1.0, 3.0)),
        (Vec3::new(0.0, -50.0, 0.0), Vec3::new(0.1, 50.0, 0.1)),
    ];
    for (lo, hi) in boxes {
        let c = hikari_scene::Camera::framing("auto", lo, hi);
        let scene = hikari_scene::Scene {
            cameras: vec![c.clone()],
            ..Default::default()
        };
        scene.validate().unwrap();
        assert_inside_frustum(&c, 1.0, lo, hi);
        assert_inside_frustum(&c, 16.0 / 9.0, lo, hi);
    }
}

#[test]
fn an_unsupported_required_extension_is_an_error_but_an_optional_one_a_warning() {
    let d = dir("extensions");
    let path = write_bare(&d);
    let mut doc: Value = serde_json::from_slice(&std::fs::read(&path).unwrap()).unwrap();
    doc["extensionsUsed"] = json!(["EXT_meshopt_compression"]);
    std::fs::write(&path, serde_json::to_vec(&doc).unwrap()).unwrap();
    let loaded = load(&path).unwrap();
    assert!(
        loaded
            .warnings
            .iter()
            .any(|w| w.contains("EXT_meshopt_compression"))
    );
    doc["extensionsRequired"] = json!(["EXT_meshopt_compression"]);
    std::fs::write(&path, serde_json::to_vec(&doc).unwrap()).unwrap();
    let e = load(&path).unwrap_err().to_string();
    assert!(
        e.contains("bare.gltf")
            && e.contains("EXT_meshopt_compression")
            && e.contains("Unsupported extension"),
        "{e}"
    );
}

#[test]
fn sparse_accessors_are_applied() {
    let d = dir("sparse");
    let path = write_bare(&d);
    let mut doc: Value = serde_json::from_slice(&std::fs::read(&path).unwrap()).unwrap();
    // Replace vertex 4 with (9, 9, 9) through a sparse substitution in a second buffer.
    let mut extra = Vec::new();
    extra.extend_from_slice(&4u16.to_le_bytes());
    extra.extend_from_slice(&[0, 0]);
    for v in [9.0f32, 9.0, 9.0] {
        extra.extend_from_slice(&v.to_le_bytes());
    }
    doc["buffers"].as_array_mut().unwrap().push(json!({"uri": format!("data:application/octet-stream;base64,{}", base64(&extra)), "byteLength": extra.len()}));
    let views = doc["bufferViews"].as_array_mut().unwrap();
    views.push(json!({"buffer": 1, "byteOffset": 0, "byteLength": 2}));
    views.push(json!({"buffer": 1, "byteOffset": 4, "byteLength": 12}));
    let n = views.len();
    doc["accessors"][0]["sparse"] = json!({"count": 1, "indices": {"bufferView": n - 2, "componentType": 5123}, "values": {"bufferView": n - 1}});
    doc["accessors"][0]["max"] = json!([9.0, 9.0, 9.0]);
    std::fs::write(&path, serde_json::to_vec(&doc).unwrap()).unwrap();
    let loaded = load(&path).unwrap_or_else(|e| panic!("{e}"));
    let m = &loaded.scene.meshes[0];
    assert_eq!(m.positions[4], Vec3::splat(9.0));
    assert_eq!(m.positions[3], Vec3::new(0.0, 0.0, 5.0));
}
