//! Where the reflection probes go: the village's rooms, pond, courtyard and whole; the Cornell
//! box; glTF nodes marked in their `extras`; one probe over any other scene.

use glam::{Mat4, Quat, Vec3};
use hikari_bake::reflection_probes::{
    ReflectionProbeBox, builtin_reflection_probes, default_reflection_probe,
    gltf_reflection_probes, village_reflection_probes,
};
use hikari_scene::{Instance, Material, Scene, shapes};

fn inside(p: &ReflectionProbeBox, x: Vec3) -> bool {
    p.transform
        .inverse()
        .transform_point3(x)
        .abs()
        .max_element()
        <= 1.0 + 1e-4
}

#[test]
fn the_village_has_a_probe_in_every_room_and_round_the_pond() {
    let village = hikari_scene::village::build(hikari_scene::village::DEFAULT_SEED);
    let layout = &village.layout;
    let probes = village_reflection_probes(layout);
    assert_eq!(probes.len(), layout.houses.len() + 4);
    for p in &probes {
        p.validate().unwrap();
        assert!(inside(p, p.capture), "{}", p.name);
    }
    for (house, p) in layout
        .houses
        .iter()
        .chain(std::iter::once(&layout.temple_hall))
        .zip(&probes)
    {
        // The capture point is in the room, and the room's corners at mid-height are inside
        // the outer walls.
        assert!(house.contains(p.capture), "{}", p.name);
        for c in [[-1.0, -1.0], [1.0, -1.0], [-1.0, 1.0], [1.0, 1.0]] {
            let corner = p.transform.transform_point3(Vec3::new(c[0], 0.0, c[1]));
            assert!(house.contains(corner), "{} corner {c:?}", p.name);
        }
    }
    let pond = probes.iter().find(|p| p.name == "pond").unwrap();
    assert!(inside(pond, layout.pond_centre));
    // The village's box holds every other probe's capture point.
    let all = probes.iter().find(|p| p.name == "village").unwrap();
    assert!(probes.iter().all(|p| inside(all, p.capture)));
    assert!(probes.iter().all(|p| p.volume() <= all.volume()));
    assert_eq!(builtin_reflection_probes("village"), probes);
}

#[test]
fn the_cornell_probe_holds_the_whole_box() {
    let probes = builtin_reflection_probes("cornell");
    assert_eq!(probes.len(), 1);
    let scene = hikari_scene::builtin::cornell();
    for inst in &scene.instances {
        for v in &scene.meshes[inst.mesh].positions {
            assert!(inside(&probes[0], inst.transform.transform_point3(*v)));
        }
    }
    assert!(builtin_reflection_probes("boxes").is_empty());
}

#[test]
fn the_default_probe_bounds_every_instance() {
    let scene = Scene {
        meshes: vec![shapes::cube()],
        materials: vec![Material::default()],
        instances: vec![
            Instance {
                mesh: 0,
                material: 0,
                transform: Mat4::from_translation(Vec3::new(-5.0, 0.5, 0.0)),
            },
            Instance {
                mesh: 0,
                material: 0,
                transform: Mat4::from_scale_rotation_translation(
                    Vec3::splat(2.0),
                    Quat::IDENTITY,
                    Vec3::new(4.0, 1.0, 3.0),
                ),
            },
        ],
        ..Default::default()
    };
    let p = default_reflection_probe(&scene).unwrap();
    p.validate().unwrap();
    // The unit cube spans [-0.5, 0.5]: the first at x -5.5..-4.5, the second (doubled) at
    // 3..5 in x, 0..2 in y, 2..4 in z.
    let (lo, hi) = (Vec3::new(-5.5, 0.0, -0.5), Vec3::new(5.0, 2.0, 4.0));
    assert!(
        (p.transform.transform_point3(-Vec3::ONE) - lo)
            .abs()
            .max_element()
            < 1e-5
    );
    assert!(
        (p.transform.transform_point3(Vec3::ONE) - hi)
            .abs()
            .max_element()
            < 1e-5
    );
    // Distances to the box: 0 inside, straight up 3 m over the top is 3, past a corner the
    // diagonal.
    assert!(p.distance_to(Vec3::new(0.0, 1.0, 1.0)) < 1e-5);
    assert!((p.distance_to(Vec3::new(0.0, 5.0, 1.0)) - 3.0).abs() < 1e-5);
    assert!((p.distance_to(Vec3::new(8.0, 2.0, 8.0)) - 5.0).abs() < 1e-5);
    assert!(default_reflection_probe(&Scene::default()).is_none());
}

#[test]
fn bad_probes_are_refused_by_name() {
    let good = ReflectionProbeBox::aabb("good", Vec3::ZERO, Vec3::ONE, Vec3::splat(0.5), 0.1);
    good.validate().unwrap();
    let cases = [
        (
            ReflectionProbeBox {
                capture: Vec3::new(0.5, 2.0, 0.5),
                ..good.clone()
            },
            "outside",
        ),
        (
            ReflectionProbeBox {
                blend_m: f32::NAN,
                ..good.clone()
            },
            "finite",
        ),
        (
            ReflectionProbeBox {
                blend_m: -1.0,
                ..good.clone()
            },
            "negative",
        ),
        (
            ReflectionProbeBox::aabb(
                "flat",
                Vec3::ZERO,
                Vec3::new(1.0, 0.001, 1.0),
                Vec3::ZERO,
                0.0,
            ),
            "1 cm",
        ),
        (
            ReflectionProbeBox {
                transform: Mat4::from_cols_array(&[
                    1.0, 0.0, 0.0, 0.0, 0.5, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0,
                ]),
                capture: Vec3::ZERO,
                ..good.clone()
            },
            "sheared",
        ),
    ];
    for (p, why) in cases {
        let e = p.validate().unwrap_err().to_string();
        assert!(e.contains(&p.name) && e.contains(why), "{e}");
    }
}

fn write_gltf(name: &str, nodes: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("hikari-rp-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("scene.gltf");
    let json = format!(
        r#"{{"asset": {{"version": "2.0"}}, "scene": 0, "scenes": [{{"nodes": [0]}}], "nodes": {nodes}}}"#
    );
    std::fs::write(&path, json).unwrap();
    path
}

#[test]
fn gltf_nodes_marked_in_their_extras_are_probes() {
    // An empty under a parent: the cube [-1, 1]^3 scaled (2, 1, 3), turned 90 degrees about y,
    // moved to (10, 1, 0) + the parent's (0, 2, 0).
    let path = write_gltf(
        "good",
        r#"[
            {"name": "parent", "translation": [0, 2, 0], "children": [1, 2]},
            {"name": "hall", "translation": [10, 1, 0], "rotation": [0, 0.7071068, 0, 0.7071068],
             "scale": [2, 1, 3],
             "extras": {"hikari": {"reflection_probe": {"capture": [0.5, -0.5, 0], "blend": 0.25}}}},
            {"name": "not a probe", "extras": {"hikari": {"reflection_probe": false}}}
        ]"#,
    );
    let probes = gltf_reflection_probes(&path).unwrap();
    assert_eq!(probes.len(), 1);
    let p = &probes[0];
    assert_eq!(p.name, "hall");
    assert_eq!(p.blend_m, 0.25);
    // By hand: local (0.5, -0.5, 0) scaled to (1, -0.5, 0), turned +90 degrees about y (x goes
    // to -z) to (0, -0.5, -1), moved by (10, 3, 0).
    assert!(
        (p.capture - Vec3::new(10.0, 2.5, -1.0)).abs().max_element() < 1e-5,
        "{}",
        p.capture
    );
    // The box's half-extents are the scale, its x axis now along -z.
    let x_axis = p.transform.x_axis.truncate();
    assert!(
        (x_axis - Vec3::new(0.0, 0.0, -2.0)).abs().max_element() < 1e-5,
        "{x_axis}"
    );
    assert!(
        (p.half_extents() - Vec3::new(2.0, 1.0, 3.0))
            .abs()
            .max_element()
            < 1e-5
    );
}

#[test]
fn malformed_probe_extras_name_the_node_and_field() {
    let cases = [
        (r#""yes""#, "neither true, false nor an object"),
        (r#"{"capture": [0, 0]}"#, "reflection_probe.capture"),
        (r#"{"capture": [0, 5, 0]}"#, "outside its box"),
        (r#"{"blend": -2}"#, "reflection_probe.blend"),
        (r#"{"blend": "wide"}"#, "reflection_probe.blend"),
    ];
    for (k, (mark, want)) in cases.iter().enumerate() {
        let path = write_gltf(
            &format!("bad{k}"),
            &format!(r#"[{{"extras": {{"hikari": {{"reflection_probe": {mark}}}}}}}]"#),
        );
        let e = gltf_reflection_probes(&path).unwrap_err().to_string();
        assert!(e.contains("node 0") && e.contains(want), "{mark}: {e}");
    }
}
