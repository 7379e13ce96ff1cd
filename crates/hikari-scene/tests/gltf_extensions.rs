//! KHR_mesh_quantization and KHR_texture_transform (docs/gltf.md). Each file is written here
//! from integers and numbers chosen by hand; every expected value is worked out by hand in
//! the comments from the extensions' formulas (normalized byte `max(c / 127, -1)`, unsigned
//! byte `c / 255`, short `max(c / 32767, -1)`, unsigned short `c / 65535`; the UV transform
//! `uv' = T * R * S * uv` with R's rows `[cos r, sin r]`, `[-sin r, cos r]`), never taken from
//! a run of the loader.

mod common;
use common::base64;

use std::f32::consts::{FRAC_1_SQRT_2, FRAC_PI_2};
use std::path::PathBuf;

use glam::{Mat4, Vec2, Vec3, Vec4};
use hikari_scene::gltf::{GltfError, GltfOptions, Loaded, load_unguarded};
use serde_json::{Value, json};

const BYTE: u32 = 5120;
const UNSIGNED_BYTE: u32 = 5121;
const SHORT: u32 = 5122;
const UNSIGNED_SHORT: u32 = 5123;
const UNSIGNED_INT: u32 = 5125;
const FLOAT: u32 = 5126;

fn png_1x1() -> Vec<u8> {
    let mut out = Vec::new();
    image::RgbaImage::from_raw(1, 1, vec![200, 100, 50, 255])
        .unwrap()
        .write_to(&mut std::io::Cursor::new(&mut out), image::ImageFormat::Png)
        .unwrap();
    out
}

/// Size in bytes of one component of `component_type`.
fn component_size(component_type: u32) -> usize {
    match component_type {
        BYTE | UNSIGNED_BYTE => 1,
        SHORT | UNSIGNED_SHORT => 2,
        _ => 4,
    }
}

/// One buffer of vertex data with its views and accessors, and the glTF document around it.
#[derive(Default)]
struct File {
    data: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
}

impl File {
    /// An accessor of `values` (`comps` per element) stored as `component_type`, each element
    /// padded to a multiple of 4 bytes as glTF asks of vertex attributes. Integer types take
    /// the values as they are (they must fit); FLOAT writes them as f32.
    fn accessor(
        &mut self,
        values: &[f64],
        comps: usize,
        component_type: u32,
        normalized: bool,
    ) -> usize {
        let size = component_size(component_type);
        let stride = (comps * size).next_multiple_of(4);
        while !self.data.len().is_multiple_of(4) {
            self.data.push(0);
        }
        let start = self.data.len();
        for element in values.chunks(comps) {
            let mut bytes = Vec::new();
            for &v in element {
                match component_type {
                    BYTE => bytes.extend((v as i8).to_le_bytes()),
                    UNSIGNED_BYTE => bytes.extend((v as u8).to_le_bytes()),
                    SHORT => bytes.extend((v as i16).to_le_bytes()),
                    UNSIGNED_SHORT => bytes.extend((v as u16).to_le_bytes()),
                    UNSIGNED_INT => bytes.extend((v as u32).to_le_bytes()),
                    _ => bytes.extend((v as f32).to_le_bytes()),
                }
            }
            bytes.resize(stride, 0);
            self.data.extend(bytes);
        }
        self.views.push(json!({
            "buffer": 0,
            "byteOffset": start,
            "byteLength": self.data.len() - start,
            "byteStride": stride,
            "target": 34962
        }));
        let ty = ["SCALAR", "VEC2", "VEC3", "VEC4"][comps - 1];
        let mut acc = json!({
            "bufferView": self.views.len() - 1,
            "componentType": component_type,
            "count": values.len() / comps,
            "type": ty
        });
        if normalized {
            acc["normalized"] = json!(true);
        }
        if comps == 3 {
            // min and max, which POSITION must have (in the stored, quantized units).
            let (mut lo, mut hi) = (vec![f64::MAX; 3], vec![f64::MIN; 3]);
            for e in values.chunks(3) {
                for c in 0..3 {
                    lo[c] = lo[c].min(e[c]);
                    hi[c] = hi[c].max(e[c]);
                }
            }
            acc["min"] = json!(lo);
            acc["max"] = json!(hi);
        }
        self.accessors.push(acc);
        self.accessors.len() - 1
    }

    /// The whole document: one mesh `m` of one primitive with `attributes` and material 0
    /// (`material`, which may use texture 0), drawn by one node with `node`'s members, and
    /// `extensions` listed as used and required.
    fn doc(&self, attributes: Value, material: Value, node: Value, extensions: &[&str]) -> Value {
        let mut node = node;
        node["mesh"] = json!(0);
        let mut doc = json!({
            "asset": {"version": "2.0", "generator": "hikari-scene tests"},
            "scene": 0,
            "scenes": [{"nodes": [0]}],
            "nodes": [node],
            "meshes": [{"name": "m", "primitives": [{"attributes": attributes, "material": 0}]}],
            "materials": [material],
            "textures": [{"source": 0}],
            "images": [{"uri": format!("data:image/png;base64,{}", base64(&png_1x1()))}],
            "buffers": [{
                "uri": format!("data:application/octet-stream;base64,{}", base64(&self.data)),
                "byteLength": self.data.len()
            }],
            "bufferViews": self.views,
            "accessors": self.accessors,
        });
        if !extensions.is_empty() {
            doc["extensionsUsed"] = json!(extensions);
            doc["extensionsRequired"] = json!(extensions);
        }
        doc
    }
}

fn write(test: &str, doc: &Value) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("gltf_extensions");
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(format!("{test}.gltf"));
    std::fs::write(&path, serde_json::to_vec_pretty(doc).unwrap()).unwrap();
    path
}

fn load(test: &str, doc: &Value) -> Result<Loaded, GltfError> {
    load_unguarded(&write(test, doc), &GltfOptions::default())
}

fn load_ok(test: &str, doc: &Value) -> Loaded {
    load(test, doc).unwrap_or_else(|e| panic!("{test}: {e}"))
}

/// The error loading `doc` gives; it must name the file and contain each of `wanted`.
fn load_err(test: &str, doc: &Value, wanted: &[&str]) -> String {
    let path = write(test, doc);
    let e = match load_unguarded(&path, &GltfOptions::default()) {
        Ok(_) => panic!("{test}: loaded without error"),
        Err(e) => e,
    };
    assert_eq!(e.path, path);
    let msg = e.to_string();
    assert!(
        msg.contains(&path.display().to_string()),
        "{test}: the message does not name the file: {msg}"
    );
    for w in wanted {
        assert!(msg.contains(w), "{test}: the message lacks `{w}`: {msg}");
    }
    msg
}

fn close2(a: Vec2, b: Vec2) -> bool {
    (a - b).abs().max_element() < 1e-5
}

fn close3(a: Vec3, b: Vec3) -> bool {
    (a - b).abs().max_element() < 1e-5
}

const Q: &str = "KHR_mesh_quantization";
const TT: &str = "KHR_texture_transform";

/// A triangle of float positions, for tests about other attributes.
fn float_triangle(f: &mut File) -> usize {
    f.accessor(
        &[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0],
        3,
        FLOAT,
        false,
    )
}

fn plain_material() -> Value {
    json!({"name": "plain"})
}

#[test]
fn quantized_positions_of_every_allowed_type_dequantize_by_the_spec() {
    // (component type, normalized, stored integers of three vertices, expected floats).
    #[rustfmt::skip]
    let cases: &[(u32, bool, [f64; 9], [f32; 9])] = &[
        // Not normalized: the integer's value.
        (BYTE, false, [-100.0, 0.0, 7.0, 127.0, -128.0, 0.0, 0.0, 5.0, -1.0],
                      [-100.0, 0.0, 7.0, 127.0, -128.0, 0.0, 0.0, 5.0, -1.0]),
        (UNSIGNED_BYTE, false, [0.0, 0.0, 0.0, 255.0, 0.0, 3.0, 0.0, 200.0, 0.0],
                               [0.0, 0.0, 0.0, 255.0, 0.0, 3.0, 0.0, 200.0, 0.0]),
        (SHORT, false, [-32768.0, 0.0, 0.0, 32767.0, 100.0, 0.0, 0.0, -2.0, 1000.0],
                       [-32768.0, 0.0, 0.0, 32767.0, 100.0, 0.0, 0.0, -2.0, 1000.0]),
        (UNSIGNED_SHORT, false, [0.0, 0.0, 0.0, 65535.0, 0.0, 0.0, 0.0, 40000.0, 1.0],
                                [0.0, 0.0, 0.0, 65535.0, 0.0, 0.0, 0.0, 40000.0, 1.0]),
        // Normalized byte: c / 127, and -128 clamps to -1.
        (BYTE, true, [127.0, 0.0, 0.0, -127.0, 0.0, 0.0, 0.0, -128.0, 0.0],
                     [1.0, 0.0, 0.0, -1.0, 0.0, 0.0, 0.0, -1.0, 0.0]),
        // Normalized unsigned byte: c / 255; 51 / 255 = 0.2, 255 / 255 = 1.
        (UNSIGNED_BYTE, true, [0.0, 0.0, 0.0, 255.0, 51.0, 0.0, 0.0, 0.0, 255.0],
                              [0.0, 0.0, 0.0, 1.0, 0.2, 0.0, 0.0, 0.0, 1.0]),
        // Normalized short: c / 32767, and -32768 clamps to -1.
        (SHORT, true, [32767.0, 0.0, 0.0, -32768.0, 0.0, 0.0, 0.0, -32767.0, 0.0],
                      [1.0, 0.0, 0.0, -1.0, 0.0, 0.0, 0.0, -1.0, 0.0]),
        // Normalized unsigned short: c / 65535; 13107 / 65535 = 0.2.
        (UNSIGNED_SHORT, true, [0.0, 0.0, 0.0, 65535.0, 13107.0, 0.0, 0.0, 0.0, 65535.0],
                               [0.0, 0.0, 0.0, 1.0, 0.2, 0.0, 0.0, 0.0, 1.0]),
    ];
    for (i, &(ty, norm, ints, want)) in cases.iter().enumerate() {
        let mut f = File::default();
        let pos = f.accessor(&ints, 3, ty, norm);
        let doc = f.doc(json!({"POSITION": pos}), plain_material(), json!({}), &[Q]);
        let loaded = load_ok(&format!("position_{i}"), &doc);
        let got = &loaded.scene.meshes[0].positions;
        // Without normals the loader unwelds for flat normals; the order is kept.
        for v in 0..3 {
            let w = Vec3::from_slice(&want[3 * v..]);
            assert!(
                close3(got[v], w),
                "type {ty} normalized {norm}: vertex {v} is {} not {w}",
                got[v]
            );
        }
    }
}

#[test]
fn the_node_transform_undoes_a_position_quantization() {
    // gltfpack's way: unsigned short positions on a grid, the node's scale and translation
    // map them back. Stored (0,0,0), (1000,0,0), (0,1000,500); scale 0.001, translation
    // (-0.5, 0, 2): world (-0.5, 0, 2), (0.5, 0, 2), (-0.5, 1, 2.5).
    let mut f = File::default();
    let pos = f.accessor(
        &[0.0, 0.0, 0.0, 1000.0, 0.0, 0.0, 0.0, 1000.0, 500.0],
        3,
        UNSIGNED_SHORT,
        false,
    );
    let node = json!({"scale": [0.001, 0.001, 0.001], "translation": [-0.5, 0.0, 2.0]});
    let doc = f.doc(json!({"POSITION": pos}), plain_material(), node, &[Q]);
    let loaded = load_ok("node_dequantization", &doc);
    let scene = &loaded.scene;
    let inst = &scene.instances[0];
    let mesh = &scene.meshes[inst.mesh];
    let world: Vec<Vec3> = mesh
        .positions
        .iter()
        .map(|&p| inst.transform.transform_point3(p))
        .collect();
    let want = [
        Vec3::new(-0.5, 0.0, 2.0),
        Vec3::new(0.5, 0.0, 2.0),
        Vec3::new(-0.5, 1.0, 2.5),
    ];
    for (g, w) in world.iter().zip(want) {
        assert!(close3(*g, w), "{g} != {w}");
    }
    assert_ne!(inst.transform, Mat4::IDENTITY);
}

#[test]
fn quantized_normals_and_tangents_dequantize_and_are_renormalised() {
    // Normalized byte (0, 127, 0) -> (0, 1, 0); normalized short (0, 0, -32767) -> (0, 0, -1);
    // byte (90, 90, 0) -> (0.7087, 0.7087, 0), renormalised to (1/sqrt 2, 1/sqrt 2, 0).
    // Tangents: byte (127, 0, 0, -127) -> (1, 0, 0, -1); (0, 100, 0, 127) -> xyz renormalised
    // to (0, 1, 0), w 1; short (0, 0, 20000, -32767) -> (0, 0, 1, -1).
    let want_n = [
        Vec3::Y,
        Vec3::NEG_Z,
        Vec3::new(FRAC_1_SQRT_2, FRAC_1_SQRT_2, 0.0),
    ];
    let want_t = [
        Vec4::new(1.0, 0.0, 0.0, -1.0),
        Vec4::new(0.0, 1.0, 0.0, 1.0),
        Vec4::new(0.0, 0.0, 1.0, -1.0),
    ];
    for (ty, normals, tangents) in [
        (
            BYTE,
            [0.0, 127.0, 0.0, 0.0, 0.0, -127.0, 90.0, 90.0, 0.0],
            [
                127.0, 0.0, 0.0, -127.0, 0.0, 100.0, 0.0, 127.0, 0.0, 0.0, 127.0, -127.0,
            ],
        ),
        (
            SHORT,
            [0.0, 32767.0, 0.0, 0.0, 0.0, -32767.0, 20000.0, 20000.0, 0.0],
            [
                32767.0, 0.0, 0.0, -32767.0, 0.0, 30000.0, 0.0, 32767.0, 0.0, 0.0, 20000.0,
                -32767.0,
            ],
        ),
    ] {
        let mut f = File::default();
        let pos = float_triangle(&mut f);
        let nrm = f.accessor(&normals, 3, ty, true);
        let tan = f.accessor(&tangents, 4, ty, true);
        let doc = f.doc(
            json!({"POSITION": pos, "NORMAL": nrm, "TANGENT": tan}),
            plain_material(),
            json!({}),
            &[Q],
        );
        let loaded = load_ok(&format!("normals_{ty}"), &doc);
        let m = &loaded.scene.meshes[0];
        for v in 0..3 {
            assert!(
                close3(m.normals[v], want_n[v]),
                "type {ty}: normal {v} is {} not {}",
                m.normals[v],
                want_n[v]
            );
            assert!(
                (m.tangents[v] - want_t[v]).abs().max_element() < 1e-5,
                "type {ty}: tangent {v} is {} not {}",
                m.tangents[v],
                want_t[v]
            );
        }
    }
}

#[test]
fn quantized_texcoords_of_every_allowed_type_dequantize_by_the_spec() {
    #[rustfmt::skip]
    let cases: &[(u32, bool, [f64; 6], [f32; 6])] = &[
        (BYTE, false, [-3.0, 4.0, 0.0, 0.0, 127.0, -128.0], [-3.0, 4.0, 0.0, 0.0, 127.0, -128.0]),
        (UNSIGNED_BYTE, false, [0.0, 1.0, 255.0, 7.0, 2.0, 0.0], [0.0, 1.0, 255.0, 7.0, 2.0, 0.0]),
        (SHORT, false, [-1000.0, 0.0, 32767.0, 1.0, 0.0, -32768.0], [-1000.0, 0.0, 32767.0, 1.0, 0.0, -32768.0]),
        (UNSIGNED_SHORT, false, [0.0, 1023.0, 65535.0, 0.0, 512.0, 2.0], [0.0, 1023.0, 65535.0, 0.0, 512.0, 2.0]),
        // c / 127, -128 clamped to -1.
        (BYTE, true, [127.0, -127.0, 0.0, -128.0, 127.0, 0.0], [1.0, -1.0, 0.0, -1.0, 1.0, 0.0]),
        // c / 255: 51 -> 0.2, 102 -> 0.4.
        (UNSIGNED_BYTE, true, [0.0, 255.0, 51.0, 102.0, 255.0, 0.0], [0.0, 1.0, 0.2, 0.4, 1.0, 0.0]),
        // c / 32767, -32768 clamped to -1.
        (SHORT, true, [32767.0, -32768.0, 0.0, -32767.0, 32767.0, 0.0], [1.0, -1.0, 0.0, -1.0, 1.0, 0.0]),
        // c / 65535: 13107 -> 0.2, 52428 -> 0.8.
        (UNSIGNED_SHORT, true, [0.0, 65535.0, 13107.0, 52428.0, 65535.0, 0.0], [0.0, 1.0, 0.2, 0.8, 1.0, 0.0]),
    ];
    for (i, &(ty, norm, ints, want)) in cases.iter().enumerate() {
        let mut f = File::default();
        let pos = float_triangle(&mut f);
        let uv = f.accessor(&ints, 2, ty, norm);
        let doc = f.doc(
            json!({"POSITION": pos, "TEXCOORD_0": uv}),
            plain_material(),
            json!({}),
            &[Q],
        );
        let loaded = load_ok(&format!("texcoord_{i}"), &doc);
        let got = &loaded.scene.meshes[0].uvs;
        for v in 0..3 {
            let w = Vec2::from_slice(&want[2 * v..]);
            assert!(
                close2(got[v], w),
                "type {ty} normalized {norm}: uv {v} is {} not {w}",
                got[v]
            );
        }
    }
}

#[test]
fn attribute_types_the_spec_does_not_allow_are_refused_naming_mesh_primitive_and_attribute() {
    // (test, attribute, component type, normalized, components).
    let cases: &[(&str, &str, u32, bool, usize)] = &[
        ("normal_ubyte_norm", "NORMAL", UNSIGNED_BYTE, true, 3),
        ("normal_ushort_norm", "NORMAL", UNSIGNED_SHORT, true, 3),
        ("normal_byte_not_norm", "NORMAL", BYTE, false, 3),
        ("tangent_ubyte_norm", "TANGENT", UNSIGNED_BYTE, true, 4),
        ("tangent_short_not_norm", "TANGENT", SHORT, false, 4),
        ("position_uint", "POSITION", UNSIGNED_INT, false, 3),
        ("texcoord_uint", "TEXCOORD_0", UNSIGNED_INT, false, 2),
    ];
    for &(test, attribute, ty, norm, comps) in cases {
        let mut f = File::default();
        let values = vec![0.0; comps * 3];
        let mut attributes = json!({});
        if attribute != "POSITION" {
            attributes["POSITION"] = json!(float_triangle(&mut f));
        }
        attributes[attribute] = json!(f.accessor(&values, comps, ty, norm));
        let doc = f.doc(attributes, plain_material(), json!({}), &[Q]);
        load_err(test, &doc, &["mesh `m` primitive 0", attribute, "accessor"]);
    }
}

#[test]
fn quantized_attributes_need_the_extension_declared() {
    let mut f = File::default();
    let pos = f.accessor(
        &[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0],
        3,
        SHORT,
        false,
    );
    let doc = f.doc(json!({"POSITION": pos}), plain_material(), json!({}), &[]);
    load_err(
        "quantized_undeclared",
        &doc,
        &["mesh `m` primitive 0", "POSITION", "I16", Q],
    );
}

#[test]
fn a_quantized_file_listing_the_extension_in_extensions_required_loads_without_warnings() {
    let mut f = File::default();
    let pos = f.accessor(
        &[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0],
        3,
        BYTE,
        false,
    );
    let nrm = f.accessor(&[0.0, 0.0, 127.0].repeat(3), 3, BYTE, true);
    let doc = f.doc(
        json!({"POSITION": pos, "NORMAL": nrm}),
        plain_material(),
        json!({}),
        &[Q, TT],
    );
    assert_eq!(doc["extensionsRequired"], json!([Q, TT]));
    let loaded = load_ok("required", &doc);
    assert!(loaded.warnings.is_empty(), "{:?}", loaded.warnings);
    assert_eq!(loaded.scene.meshes[0].normals, vec![Vec3::Z; 3]);
}

/// A triangle with float UVs (0,0), (1,0), (0,1) and a material whose base colour texture has
/// `transform` as its KHR_texture_transform; returns the UVs loaded.
fn transformed_uvs(test: &str, transform: Value) -> Vec<Vec2> {
    let mut f = File::default();
    let pos = float_triangle(&mut f);
    let uv = f.accessor(&[0.0, 0.0, 1.0, 0.0, 0.0, 1.0], 2, FLOAT, false);
    let material = json!({
        "name": "atlas",
        "pbrMetallicRoughness": {"baseColorTexture": {"index": 0, "extensions": {TT: transform}}}
    });
    let doc = f.doc(
        json!({"POSITION": pos, "TEXCOORD_0": uv}),
        material,
        json!({}),
        &[TT],
    );
    let loaded = load_ok(test, &doc);
    assert!(loaded.warnings.is_empty(), "{:?}", loaded.warnings);
    loaded.scene.meshes[0].uvs.clone()
}

fn assert_uvs(got: &[Vec2], want: &[Vec2]) {
    assert_eq!(got.len(), want.len());
    for (g, w) in got.iter().zip(want) {
        assert!(close2(*g, *w), "uvs {got:?}, expected {want:?}");
    }
}

#[test]
fn texture_transform_offset_rotation_and_scale_each_apply_to_the_uvs() {
    // Offset (0.5, 0.25) adds to each UV.
    assert_uvs(
        &transformed_uvs("tt_offset", json!({"offset": [0.5, 0.25]})),
        &[
            Vec2::new(0.5, 0.25),
            Vec2::new(1.5, 0.25),
            Vec2::new(0.5, 1.25),
        ],
    );
    // Rotation pi/2: cos 0, sin 1, so u' = v, v' = -u: (0,0) -> (0,0), (1,0) -> (0,-1),
    // (0,1) -> (1,0).
    assert_uvs(
        &transformed_uvs("tt_rotation", json!({"rotation": FRAC_PI_2})),
        &[Vec2::ZERO, Vec2::new(0.0, -1.0), Vec2::new(1.0, 0.0)],
    );
    // Scale (2, 3) multiplies each component.
    assert_uvs(
        &transformed_uvs("tt_scale", json!({"scale": [2.0, 3.0]})),
        &[Vec2::ZERO, Vec2::new(2.0, 0.0), Vec2::new(0.0, 3.0)],
    );
    // All three, in the order T * R * S: (1,0) -> S (2,0) -> R (0,-2) -> T (0.5,-2);
    // (0,1) -> S (0,2) -> R (2,0) -> T (2.5,0); (0,0) -> T (0.5,0).
    assert_uvs(
        &transformed_uvs(
            "tt_all",
            json!({"offset": [0.5, 0.0], "rotation": FRAC_PI_2, "scale": [2.0, 2.0]}),
        ),
        &[
            Vec2::new(0.5, 0.0),
            Vec2::new(0.5, -2.0),
            Vec2::new(2.5, 0.0),
        ],
    );
    // A texCoord override of 0 changes nothing and warns of nothing.
    assert_uvs(
        &transformed_uvs("tt_texcoord0", json!({"texCoord": 0})),
        &[Vec2::ZERO, Vec2::X, Vec2::Y],
    );
}

#[test]
fn the_extensions_own_example_shows_the_lower_left_quadrant() {
    // The extension's example: offset [0, 1], rotation pi/2 (it writes 1.57079632679), scale
    // [0.5, 0.5] "utilizes only the lower left quadrant of the source image" (V points down,
    // so that is u in [0, 0.5], v in [0.5, 1]). A triangle whose UVs cover the unit square's corners (0,0), (1,0), (0,1)
    // must land at corners of that quadrant: (0,0) -> (0,1); (1,0) -> (0,0.5); (0,1) -> (0.5,1).
    let got = transformed_uvs(
        "tt_spec_example",
        json!({"offset": [0.0, 1.0], "rotation": FRAC_PI_2, "scale": [0.5, 0.5]}),
    );
    for uv in &got {
        assert!(
            (-1e-5..=0.5 + 1e-5).contains(&uv.x) && (0.5 - 1e-5..=1.0 + 1e-5).contains(&uv.y),
            "{uv} is outside the lower left quadrant"
        );
    }
    assert_uvs(
        &got,
        &[
            Vec2::new(0.0, 1.0),
            Vec2::new(0.0, 0.5),
            Vec2::new(0.5, 1.0),
        ],
    );
}

#[test]
fn gltfpack_style_quantized_texcoords_with_a_dequantizing_transform() {
    // Unsigned short UVs, not normalized, on a 0..1023 grid; the transform's scale 1/1023 and
    // offset (0.25, -0.5) map them back: 1023 -> 1 + offset, 0 -> offset.
    let mut f = File::default();
    let pos = float_triangle(&mut f);
    let uv = f.accessor(
        &[0.0, 0.0, 1023.0, 0.0, 0.0, 1023.0],
        2,
        UNSIGNED_SHORT,
        false,
    );
    let s = 1.0 / 1023.0;
    let material = json!({
        "name": "packed",
        "pbrMetallicRoughness": {"baseColorTexture": {"index": 0, "extensions": {TT: {"offset": [0.25, -0.5], "scale": [s, s]}}}},
        "normalTexture": {"index": 0, "extensions": {TT: {"offset": [0.25, -0.5], "scale": [s, s]}}}
    });
    let doc = f.doc(
        json!({"POSITION": pos, "TEXCOORD_0": uv}),
        material,
        json!({}),
        &[Q, TT],
    );
    let loaded = load_ok("gltfpack_uvs", &doc);
    assert!(loaded.warnings.is_empty(), "{:?}", loaded.warnings);
    assert_uvs(
        &loaded.scene.meshes[0].uvs,
        &[
            Vec2::new(0.25, -0.5),
            Vec2::new(1.25, -0.5),
            Vec2::new(0.25, 0.5),
        ],
    );
}

/// A quad in the z = 0 plane facing +z, UVs (0,0), (1,0), (1,1), (0,1) at x, y = (0,0),
/// (1,0), (1,1), (0,1), with a normal-mapped material whose normal texture has `transform`;
/// `tangents`: also give a TANGENT attribute (1, 0, 0, 1) (dP/du of these UVs). Returns the
/// tangents loaded.
fn quad_tangents(test: &str, transform: Option<Value>, tangents: bool) -> Vec<Vec4> {
    let mut f = File::default();
    let pos = f.accessor(
        &[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 1.0, 0.0],
        3,
        FLOAT,
        false,
    );
    let nrm = f.accessor(&[0.0, 0.0, 1.0].repeat(4), 3, FLOAT, false);
    let uv = f.accessor(&[0.0, 0.0, 1.0, 0.0, 1.0, 1.0, 0.0, 1.0], 2, FLOAT, false);
    let mut attributes = json!({"POSITION": pos, "NORMAL": nrm, "TEXCOORD_0": uv});
    if tangents {
        attributes["TANGENT"] = json!(f.accessor(&[1.0, 0.0, 0.0, 1.0].repeat(4), 4, FLOAT, false));
    }
    let mut normal = json!({"index": 0});
    if let Some(t) = transform {
        normal["extensions"] = json!({TT: t});
    }
    let material = json!({"name": "bumpy", "normalTexture": normal});
    let mut doc = f.doc(attributes, material, json!({}), &[TT]);
    // Two triangles of the quad.
    let idx = {
        let bytes: Vec<u8> = [0u16, 1, 2, 0, 2, 3]
            .iter()
            .flat_map(|i| i.to_le_bytes())
            .collect();
        let mut data = f.data.clone();
        let offset = data.len();
        data.extend(bytes);
        doc["buffers"][0] = json!({
            "uri": format!("data:application/octet-stream;base64,{}", base64(&data)),
            "byteLength": data.len()
        });
        doc["bufferViews"]
            .as_array_mut()
            .unwrap()
            .push(json!({"buffer": 0, "byteOffset": offset, "byteLength": 12}));
        let view = doc["bufferViews"].as_array().unwrap().len() - 1;
        doc["accessors"].as_array_mut().unwrap().push(
            json!({"bufferView": view, "componentType": UNSIGNED_SHORT, "count": 6, "type": "SCALAR"}),
        );
        doc["accessors"].as_array().unwrap().len() - 1
    };
    doc["meshes"][0]["primitives"][0]["indices"] = json!(idx);
    let loaded = load_ok(test, &doc);
    loaded.scene.meshes[0].tangents.clone()
}

#[test]
fn tangents_follow_the_transformed_uvs() {
    // Untransformed, u grows along +x: tangent (1, 0, 0); the bitangent dP/dv is +y and
    // cross(normal z, tangent x) = +y agrees, so w = +1.
    for t in quad_tangents("tangent_plain", None, false) {
        assert!(
            (t - Vec4::new(1.0, 0.0, 0.0, 1.0)).abs().max_element() < 1e-5,
            "{t}"
        );
    }
    // Rotated by pi/2: u' = v, v' = -u. u' grows along +y, so the tangent is (0, 1, 0); v'
    // grows along -x, and cross(z, y) = -x agrees, so w = +1. Generated from the UVs, and
    // re-expressed from the file's (1, 0, 0, 1), both must give this.
    let rotated = json!({"rotation": FRAC_PI_2});
    for (test, given) in [("tangent_rotated", false), ("tangent_rotated_given", true)] {
        for t in quad_tangents(test, Some(rotated.clone()), given) {
            assert!(
                (t - Vec4::new(0.0, 1.0, 0.0, 1.0)).abs().max_element() < 1e-5,
                "{test}: {t}"
            );
        }
    }
    // Mirrored in u by scale (-1, 1): u' = -u grows along -x, tangent (-1, 0, 0); v' = v
    // along +y, but cross(z, -x) = -y, so w = -1.
    let mirrored = json!({"scale": [-1.0, 1.0], "offset": [1.0, 0.0]});
    for (test, given) in [
        ("tangent_mirrored", false),
        ("tangent_mirrored_given", true),
    ] {
        for t in quad_tangents(test, Some(mirrored.clone()), given) {
            assert!(
                (t - Vec4::new(-1.0, 0.0, 0.0, -1.0)).abs().max_element() < 1e-5,
                "{test}: {t}"
            );
        }
    }
}

#[test]
fn one_transform_per_material_the_base_colours_with_a_warning_for_others() {
    let mut f = File::default();
    let pos = float_triangle(&mut f);
    let uv = f.accessor(&[0.0, 0.0, 1.0, 0.0, 0.0, 1.0], 2, FLOAT, false);
    let material = json!({
        "name": "mixed",
        "pbrMetallicRoughness": {
            "baseColorTexture": {"index": 0, "extensions": {TT: {"offset": [1.0, 2.0]}}},
            "metallicRoughnessTexture": {"index": 0, "extensions": {TT: {"offset": [1.0, 2.0]}}}
        },
        "emissiveTexture": {"index": 0, "extensions": {TT: {"scale": [4.0, 4.0]}}}
    });
    let doc = f.doc(
        json!({"POSITION": pos, "TEXCOORD_0": uv}),
        material,
        json!({}),
        &[TT],
    );
    let loaded = load_ok("per_material", &doc);
    // The base colour's offset (1, 2), not the emissive scale.
    assert_uvs(
        &loaded.scene.meshes[0].uvs,
        &[
            Vec2::new(1.0, 2.0),
            Vec2::new(2.0, 2.0),
            Vec2::new(1.0, 3.0),
        ],
    );
    // One warning, for the emissive slot only (the metallic-roughness one agrees).
    assert_eq!(loaded.warnings.len(), 1, "{:?}", loaded.warnings);
    let w = &loaded.warnings[0];
    assert!(
        w.contains("`mixed`") && w.contains("emissiveTexture") && w.contains("baseColorTexture"),
        "{w}"
    );
}

#[test]
fn a_tex_coord_override_other_than_0_warns_and_uses_texcoord_0() {
    let mut f = File::default();
    let pos = float_triangle(&mut f);
    let uv = f.accessor(&[0.0, 0.0, 1.0, 0.0, 0.0, 1.0], 2, FLOAT, false);
    let material = json!({
        "name": "second set",
        "pbrMetallicRoughness": {"baseColorTexture": {"index": 0, "extensions": {TT: {"texCoord": 1, "offset": [0.0, 1.0]}}}}
    });
    let doc = f.doc(
        json!({"POSITION": pos, "TEXCOORD_0": uv}),
        material,
        json!({}),
        &[TT],
    );
    let loaded = load_ok("texcoord_override", &doc);
    assert!(
        loaded.warnings.iter().any(|w| w.contains("`second set`")
            && w.contains("TEXCOORD_1")
            && w.contains("texCoord")),
        "{:?}",
        loaded.warnings
    );
    assert_uvs(
        &loaded.scene.meshes[0].uvs,
        &[
            Vec2::new(0.0, 1.0),
            Vec2::new(1.0, 1.0),
            Vec2::new(0.0, 2.0),
        ],
    );
}

#[test]
fn malformed_texture_transforms_are_errors_naming_material_slot_and_field() {
    // (test, slot, transform, field named).
    let cases: &[(&str, &str, Value, &str)] = &[
        (
            "offset_3",
            "baseColorTexture",
            json!({"offset": [0.0, 1.0, 2.0]}),
            "offset",
        ),
        (
            "offset_1",
            "emissiveTexture",
            json!({"offset": [0.0]}),
            "offset",
        ),
        (
            "offset_string",
            "normalTexture",
            json!({"offset": ["0", 1]}),
            "offset",
        ),
        (
            "scale_string",
            "occlusionTexture",
            json!({"scale": "2"}),
            "scale",
        ),
        (
            "scale_huge",
            "metallicRoughnessTexture",
            json!({"scale": [1e39, 1.0]}),
            "scale",
        ),
        (
            "rotation_string",
            "baseColorTexture",
            json!({"rotation": "pi"}),
            "rotation",
        ),
        (
            "rotation_array",
            "normalTexture",
            json!({"rotation": [1.0]}),
            "rotation",
        ),
        (
            "rotation_overflow",
            "emissiveTexture",
            json!({"rotation": -1e300}),
            "rotation",
        ),
        (
            "texcoord_negative",
            "baseColorTexture",
            json!({"texCoord": -1}),
            "texCoord",
        ),
        (
            "texcoord_fraction",
            "occlusionTexture",
            json!({"texCoord": 0.5}),
            "texCoord",
        ),
        ("not_object", "baseColorTexture", json!([1, 2]), TT),
    ];
    for (test, slot, transform, field) in cases {
        let mut f = File::default();
        let pos = float_triangle(&mut f);
        let uv = f.accessor(&[0.0, 0.0, 1.0, 0.0, 0.0, 1.0], 2, FLOAT, false);
        let info = json!({"index": 0, "extensions": {TT: transform}});
        let mut material = json!({"name": "broken", "pbrMetallicRoughness": {}});
        match *slot {
            "baseColorTexture" | "metallicRoughnessTexture" => {
                material["pbrMetallicRoughness"][slot] = info
            }
            _ => material[slot] = info,
        }
        let doc = f.doc(
            json!({"POSITION": pos, "TEXCOORD_0": uv}),
            material,
            json!({}),
            &[TT],
        );
        let qualified = format!("{TT}.{field}");
        let field = if *field == TT { TT } else { qualified.as_str() };
        load_err(
            &format!("malformed_{test}"),
            &doc,
            &["material `broken`", slot, field],
        );
    }
}

const SPEC: &str = "KHR_materials_specular";

/// A triangle drawn with `material`, declaring KHR_materials_specular.
fn specular_doc(material: Value) -> Value {
    let mut f = File::default();
    let pos = float_triangle(&mut f);
    f.doc(json!({"POSITION": pos}), material, json!({}), &[SPEC])
}

#[test]
fn khr_materials_specular_sets_the_specular_weight() {
    let cases = [
        (
            json!({"name": "matte", "extensions": {SPEC: {"specularFactor": 0.0}}}),
            0.0,
        ),
        (
            json!({"name": "half", "extensions": {SPEC: {"specularFactor": 0.5}}}),
            0.5,
        ),
        // The extension's default factor is 1, as is a material without it.
        (json!({"name": "default", "extensions": {SPEC: {}}}), 1.0),
        (plain_material(), 1.0),
    ];
    for (i, (material, want)) in cases.into_iter().enumerate() {
        let loaded = load_ok(&format!("specular_{i}"), &specular_doc(material));
        assert_eq!(loaded.scene.materials[0].specular, want, "case {i}");
        assert!(
            loaded.warnings.is_empty(),
            "case {i}: {:?}",
            loaded.warnings
        );
    }
}

#[test]
fn khr_materials_specular_textures_and_colour_warn_and_bad_factors_are_errors() {
    let material = json!({"name": "tinted", "extensions": {SPEC: {
        "specularFactor": 0.25,
        "specularColorFactor": [1.0, 0.5, 0.5],
        "specularTexture": {"index": 0}
    }}});
    let loaded = load_ok("specular_tinted", &specular_doc(material));
    assert_eq!(loaded.scene.materials[0].specular, 0.25);
    assert_eq!(loaded.warnings.len(), 2, "{:?}", loaded.warnings);
    for w in &loaded.warnings {
        assert!(w.contains("`tinted`") && w.contains(SPEC), "{w}");
    }
    // A white specular colour changes nothing and gives no warning.
    let white =
        json!({"name": "white", "extensions": {SPEC: {"specularColorFactor": [1.0, 1.0, 1.0]}}});
    assert!(
        load_ok("specular_white", &specular_doc(white))
            .warnings
            .is_empty()
    );
    for (i, bad) in [json!(1.5), json!(-0.1), json!("0.5")]
        .into_iter()
        .enumerate()
    {
        let material = json!({"name": "bad", "extensions": {SPEC: {"specularFactor": bad}}});
        load_err(
            &format!("specular_bad_{i}"),
            &specular_doc(material),
            &["`bad`", "KHR_materials_specular.specularFactor", "[0, 1]"],
        );
    }
}
