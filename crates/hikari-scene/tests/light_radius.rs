//! A point or spot light's radius (`Light::radius_m`, the softness of its ray-traced shadows):
//! validated by `Scene::validate` with errors naming the light, and read from glTF
//! `KHR_lights_punctual` light `extras` `{"hikari": {"radius": r}}`.

mod common;

use std::path::PathBuf;

use glam::Vec3;
use hikari_scene::gltf::load;
use hikari_scene::{Light, Scene};
use serde_json::{Value, json};

/// A glTF of no meshes and the given `KHR_lights_punctual` lights, one node each (at x = i m),
/// written under the test's scratch folder; returns its path.
fn write_gltf(name: &str, lights: Value) -> PathBuf {
    let n = lights.as_array().unwrap().len();
    let nodes: Vec<Value> = (0..n)
        .map(|i| {
            json!({"name": format!("node{i}"), "translation": [i as f32, 2.0, 0.0],
                   "extensions": {"KHR_lights_punctual": {"light": i}}})
        })
        .collect();
    let doc = json!({
        "asset": {"version": "2.0"},
        "extensionsUsed": ["KHR_lights_punctual"],
        "extensions": {"KHR_lights_punctual": {"lights": lights}},
        "nodes": nodes,
        "scenes": [{"nodes": (0..n).collect::<Vec<_>>()}],
        "scene": 0
    });
    common::write_gltf_doc("light_radius", name, &doc)
}

#[test]
fn gltf_light_extras_set_the_radius() {
    let path = write_gltf(
        "good",
        json!([
            {"name": "plain", "type": "point", "intensity": 10.0},
            {"name": "lantern", "type": "point", "intensity": 10.0,
             "extras": {"hikari": {"radius": 0.25}, "tool": "blender"}},
            {"name": "pin", "type": "spot", "intensity": 10.0, "spot": {"outerConeAngle": 0.5},
             "extras": {"hikari": {"radius": 0}}},
            {"name": "unrelated", "type": "point", "intensity": 10.0, "extras": {"tool": "x"}}
        ]),
    );
    let loaded = load(&path).unwrap();
    let got: Vec<_> = loaded
        .scene
        .lights
        .iter()
        .map(|l| (l.name.as_str(), l.radius_m))
        .collect();
    assert_eq!(
        got,
        [
            ("plain", None),
            ("lantern", Some(0.25)),
            ("pin", Some(0.0)),
            ("unrelated", None),
        ]
    );
    loaded.scene.validate().unwrap();
}

#[test]
fn bad_gltf_light_radii_are_errors_naming_the_light() {
    let cases = [
        ("negative", json!(-0.5)),
        ("text", json!("big")),
        ("list", json!([0.1])),
        ("huge", json!(1e300)),
        ("null", json!(null)),
    ];
    for (name, value) in cases {
        let path = write_gltf(
            name,
            json!([{"name": "street lamp", "type": "point", "intensity": 5.0,
                    "extras": {"hikari": {"radius": value}}}]),
        );
        let e = load(&path).unwrap_err().to_string();
        assert!(
            e.contains("light `street lamp`") && e.contains("hikari.radius"),
            "{name}: {e}"
        );
    }
}

#[test]
fn a_bad_radius_in_the_scene_model_is_an_error_naming_the_light() {
    for bad in [-0.01, f32::NAN, f32::INFINITY] {
        let scene = Scene {
            lights: vec![Light {
                radius_m: Some(bad),
                ..Light::point("porch light", Vec3::ONE, 10.0, Vec3::ONE)
            }],
            ..Default::default()
        };
        let e = scene.validate().unwrap_err().to_string();
        assert!(
            e.contains("porch light") && e.contains("radius_m"),
            "{bad}: {e}"
        );
    }
    for good in [0.0, 0.05, 3.0] {
        Scene {
            lights: vec![Light {
                radius_m: Some(good),
                ..Light::point("porch light", Vec3::ONE, 10.0, Vec3::ONE)
            }],
            ..Default::default()
        }
        .validate()
        .unwrap();
    }
}
