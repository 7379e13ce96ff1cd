//! The GI albedo override of a material (`Material::gi_albedo`): validated by `Scene::validate`
//! with errors naming the material, and read from glTF material `extras`
//! `{"hikari": {"gi_albedo": [r, g, b]}}`.

mod common;
use common::base64;

use std::path::PathBuf;

use glam::Vec3;
use hikari_scene::gltf::load;
use hikari_scene::{Instance, Material, Mesh, Scene};
use serde_json::{Value, json};

fn one_triangle_scene(material: Material) -> Scene {
    Scene {
        meshes: vec![Mesh {
            name: "tri".into(),
            positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y],
            normals: vec![Vec3::Z; 3],
            indices: vec![0, 1, 2],
            ..Default::default()
        }],
        materials: vec![material],
        instances: vec![Instance {
            mesh: 0,
            material: 0,
            transform: glam::Mat4::IDENTITY,
        }],
        ..Default::default()
    }
}

#[test]
fn a_sound_override_validates() {
    for a in [Vec3::ZERO, Vec3::ONE, Vec3::new(0.2, 0.5, 0.9)] {
        let m = Material {
            gi_albedo: Some(a),
            ..Material::diffuse("wall", Vec3::splat(0.5))
        };
        one_triangle_scene(m).validate().unwrap();
    }
}

#[test]
fn a_bad_override_is_an_error_naming_the_material() {
    for bad in [
        Vec3::new(f32::NAN, 0.5, 0.5),
        Vec3::new(0.5, f32::INFINITY, 0.5),
        Vec3::new(0.5, 0.5, 1.5),
        Vec3::new(-0.1, 0.5, 0.5),
    ] {
        let m = Material {
            gi_albedo: Some(bad),
            ..Material::diffuse("plaster wall", Vec3::splat(0.5))
        };
        let e = one_triangle_scene(m).validate().unwrap_err().to_string();
        assert!(
            e.contains("material `plaster wall`") && e.contains("GI albedo"),
            "{bad}: {e}"
        );
    }
}

/// A one-triangle glTF (buffer as a data URI) drawn with material 0 of `materials`, written
/// under the test's scratch folder; returns its path.
fn write_gltf(name: &str, materials: Value) -> PathBuf {
    let mut bin: Vec<u8> = Vec::new();
    for x in [0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0] {
        bin.extend(x.to_le_bytes());
    }
    for x in [0.0f32, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0] {
        bin.extend(x.to_le_bytes());
    }
    let doc = json!({
        "asset": {"version": "2.0"},
        "buffers": [{
            "uri": format!("data:application/octet-stream;base64,{}", base64(&bin)),
            "byteLength": bin.len()
        }],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": 36},
            {"buffer": 0, "byteOffset": 36, "byteLength": 36}
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
             "min": [0.0, 0.0, 0.0], "max": [1.0, 1.0, 0.0]},
            {"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC3"}
        ],
        "materials": materials,
        "meshes": [{"name": "tri", "primitives": [{
            "attributes": {"POSITION": 0, "NORMAL": 1}, "material": 0
        }]}],
        "nodes": [{"name": "n", "mesh": 0}],
        "scenes": [{"nodes": [0]}],
        "scene": 0
    });
    common::write_gltf_doc("gi_albedo_override", name, &doc)
}

#[test]
fn gltf_material_extras_set_the_override() {
    let path = write_gltf(
        "extras",
        json!([
            {"name": "plain"},
            {"name": "tinted", "extras": {"hikari": {"gi_albedo": [0.2, 0.4, 0.6]}, "other": 1}},
            {"name": "both", "extras": {"hikari": {"area_light": false, "gi_albedo": [0, 1, 0.5]}}},
            {"name": "unrelated", "extras": {"tool": "blender"}}
        ]),
    );
    let loaded = load(&path).unwrap();
    let got: Vec<_> = loaded
        .scene
        .materials
        .iter()
        .map(|m| (m.name.as_str(), m.gi_albedo))
        .collect();
    assert_eq!(
        got,
        [
            ("plain", None),
            ("tinted", Some(Vec3::new(0.2, 0.4, 0.6))),
            ("both", Some(Vec3::new(0.0, 1.0, 0.5))),
            ("unrelated", None),
        ]
    );
    assert_eq!(loaded.scene.materials[2].area_light, Some(false));
}

#[test]
fn bad_gltf_extras_are_errors_naming_the_material() {
    let cases = [
        ("short", json!([0.2, 0.4]), "gi_albedo"),
        ("text", json!("red"), "gi_albedo"),
        ("not_numbers", json!([0.2, "x", 0.4]), "gi_albedo"),
        ("above_one", json!([1.5, 0.0, 0.0]), "GI albedo"),
        ("negative", json!([0.5, -0.5, 0.0]), "GI albedo"),
    ];
    for (name, value, says) in cases {
        let path = write_gltf(
            name,
            json!([{"name": "lamp shade", "extras": {"hikari": {"gi_albedo": value}}}]),
        );
        let e = load(&path).unwrap_err().to_string();
        assert!(
            e.contains("material `lamp shade`") && e.contains(says),
            "{name}: {e}"
        );
    }
}
