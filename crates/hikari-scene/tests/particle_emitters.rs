//! Particle emitters from glTF node `extras` `{"hikari": {"particles": {...}}}`: placed at the
//! node, their box scaled with it, bad values errors naming the node.

mod common;

use std::path::PathBuf;

use glam::Vec3;
use hikari_scene::gltf::load;
use serde_json::{Value, json};

/// A glTF of no meshes and one node with `extras`; returns its path.
fn write_gltf(name: &str, extras: Value) -> PathBuf {
    let doc = json!({
        "asset": {"version": "2.0"},
        "nodes": [{"name": "pond mist", "translation": [4.0, 1.0, -2.0], "scale": [2.0, 1.0, 2.0],
                   "extras": extras}],
        "scenes": [{"nodes": [0]}],
        "scene": 0
    });
    common::write_gltf_doc("particle_emitters", name, &doc)
}

#[test]
fn node_extras_make_an_emitter_at_the_node() {
    let path = write_gltf(
        "good",
        json!({"hikari": {"particles": {"half_extents": [1.0, 0.5, 1.5], "count": 32,
               "size_m": [0.5, 2.0], "opacity": 0.2, "velocity_mps": [0.1, 0.0, 0.0],
               "lifetime_s": 30.0, "albedo": [0.9, 0.9, 0.85], "haze_lit": false, "seed": 9,
               "hours": [17.5, 9.0]}},
               "tool": "blender"}),
    );
    let loaded = load(&path).unwrap();
    loaded.scene.validate().unwrap();
    let [e] = loaded.scene.particles.as_slice() else {
        panic!("{:?}", loaded.scene.particles)
    };
    assert_eq!(e.name, "pond mist");
    assert_eq!(e.centre, Vec3::new(4.0, 1.0, -2.0));
    assert_eq!(e.half_extents, Vec3::new(2.0, 0.5, 3.0));
    assert_eq!(
        (
            e.count,
            e.size_m,
            e.opacity,
            e.lifetime_s,
            e.haze_lit,
            e.seed
        ),
        (32, [0.5, 2.0], 0.2, 30.0, false, 9)
    );
    assert_eq!(e.velocity_mps, Vec3::new(0.1, 0.0, 0.0));
    assert_eq!(e.hours, Some([17.5, 9.0]));
    // Nothing in the extras but other tools' data: no emitter.
    let loaded = load(write_gltf("none", json!({"tool": "blender"}))).unwrap();
    assert!(loaded.scene.particles.is_empty());
}

#[test]
fn bad_emitter_extras_are_errors_naming_the_node() {
    let cases = [
        ("not_object", json!(3)),
        ("unknown_key", json!({"colour": [1, 1, 1]})),
        ("count_text", json!({"count": "many"})),
        ("count_negative", json!({"count": -4})),
        ("short_size", json!({"size_m": [1.0]})),
        ("haze_lit_number", json!({"haze_lit": 1})),
        ("hours_one", json!({"hours": [6.0]})),
        ("hours_text", json!({"hours": ["dusk", "dawn"]})),
    ];
    for (name, p) in cases {
        let e = load(write_gltf(name, json!({"hikari": {"particles": p}})))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("node `pond mist`") && e.contains("hikari.particles"),
            "{name}: {e}"
        );
    }
    // Out of range: the loader's validation refuses it with the emitter's name.
    let e = load(write_gltf(
        "zero_opacity",
        json!({"hikari": {"particles": {"opacity": 0.0}}}),
    ))
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("particles `pond mist`") && e.contains("opacity"),
        "{e}"
    );
    let e = load(write_gltf(
        "late_hours",
        json!({"hikari": {"particles": {"hours": [25.0, 3.0]}}}),
    ))
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("particles `pond mist`") && e.contains("hours"),
        "{e}"
    );
}
