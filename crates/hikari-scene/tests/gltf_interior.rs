//! The interior mask from glTF (docs/irradiance-probes.md, *The interior mask*): the material
//! `extras` value `{"hikari": {"interior": w}}` and the vertex attribute `_HIKARI_INTERIOR`,
//! each validated with an error naming the material or mesh and the file; and a file with
//! nothing to draw, which loads with a camera looking at the horizon.

use std::path::PathBuf;

use hikari_scene::gltf::{GltfOptions, Loaded, load_unguarded};
use serde_json::{Value, json};

/// A triangle (positions, then the extra attribute's bytes) in `name.bin` beside `name.gltf`;
/// `attribute` is (componentType, normalized, bytes) of a SCALAR accessor `_HIKARI_INTERIOR`.
fn triangle(
    name: &str,
    materials: Value,
    attribute: Option<(u32, bool, Vec<u8>)>,
    normals: bool,
) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join("gltf_interior")
        .join(name);
    std::fs::create_dir_all(&dir).unwrap();
    let mut bin: Vec<u8> = [0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0]
        .iter()
        .flat_map(|x| x.to_le_bytes())
        .collect();
    let mut views = vec![json!({"buffer": 0, "byteOffset": 0, "byteLength": 36})];
    let mut accessors = vec![json!({"bufferView": 0, "componentType": 5126, "count": 3,
        "type": "VEC3", "min": [0.0, 0.0, 0.0], "max": [1.0, 1.0, 0.0]})];
    let mut attributes = json!({"POSITION": 0});
    if normals {
        let offset = bin.len();
        bin.extend(
            [0.0f32, 0.0, 1.0]
                .repeat(3)
                .iter()
                .flat_map(|x| x.to_le_bytes()),
        );
        views.push(json!({"buffer": 0, "byteOffset": offset, "byteLength": 36}));
        accessors.push(json!({"bufferView": views.len() - 1, "componentType": 5126,
            "count": 3, "type": "VEC3"}));
        attributes["NORMAL"] = json!(accessors.len() - 1);
    }
    if let Some((component, normalized, bytes)) = attribute {
        let offset = bin.len();
        views.push(json!({"buffer": 0, "byteOffset": offset, "byteLength": bytes.len()}));
        accessors.push(
            json!({"bufferView": views.len() - 1, "componentType": component,
            "normalized": normalized, "count": 3, "type": "SCALAR"}),
        );
        attributes["_HIKARI_INTERIOR"] = json!(accessors.len() - 1);
        bin.extend(bytes);
    }
    while !bin.len().is_multiple_of(4) {
        bin.push(0);
    }
    std::fs::write(dir.join(format!("{name}.bin")), &bin).unwrap();
    let doc = json!({
        "asset": {"version": "2.0"},
        "buffers": [{"uri": format!("{name}.bin"), "byteLength": bin.len()}],
        "bufferViews": views,
        "accessors": accessors,
        "materials": materials,
        "meshes": [{"name": "tri", "primitives": [{"attributes": attributes, "material": 0}]}],
        "nodes": [{"name": "n", "mesh": 0}],
        "scenes": [{"nodes": [0]}],
        "scene": 0
    });
    let path = dir.join(format!("{name}.gltf"));
    std::fs::write(&path, serde_json::to_vec_pretty(&doc).unwrap()).unwrap();
    path
}

fn load(path: &std::path::Path) -> Result<Loaded, String> {
    load_unguarded(path, &GltfOptions::default()).map_err(|e| e.to_string())
}

fn floats(v: &[f32]) -> Vec<u8> {
    v.iter().flat_map(|x| x.to_le_bytes()).collect()
}

#[test]
fn material_extras_set_the_interior_mask_and_other_extras_are_ignored() {
    let path = triangle(
        "material_extras",
        json!([
            {"name": "plain"},
            {"name": "outdoors", "extras": {"hikari": {"interior": 0}}},
            {"name": "indoors", "extras": {"hikari": {"interior": 1.0, "area_light": false}}},
            {"name": "porch", "extras": {"hikari": {"interior": 0.25}, "tool": "blender"}},
            {"name": "unrelated", "extras": {"hikari": {}}}
        ]),
        None,
        true,
    );
    let loaded = load(&path).unwrap();
    let masks: Vec<_> = loaded.scene.materials.iter().map(|m| m.interior).collect();
    assert_eq!(masks, [None, Some(0.0), Some(1.0), Some(0.25), None]);
    assert_eq!(loaded.scene.materials[2].area_light, Some(false));
    // No vertex attribute: the mesh carries none, so the material's value is the mask.
    let mesh = &loaded.scene.meshes[0];
    assert!(mesh.interior.is_empty());
    assert_eq!(mesh.interior_at(0, &loaded.scene.materials[3]), 0.25);
    assert_eq!(
        mesh.interior_at(0, &loaded.scene.materials[0]),
        hikari_scene::DEFAULT_INTERIOR
    );
}

#[test]
fn bad_material_interior_values_name_the_material_and_the_file() {
    for (i, bad) in [
        json!(1.5),
        json!(-0.01),
        json!("indoors"),
        json!(null),
        json!(true),
    ]
    .into_iter()
    .enumerate()
    {
        let name = format!("bad_material_{i}");
        let path = triangle(
            &name,
            json!([{"name": "wall", "extras": {"hikari": {"interior": bad.clone()}}}]),
            None,
            true,
        );
        let e = load(&path).expect_err(&format!("{bad} was accepted"));
        assert!(
            e.contains("material `wall`")
                && e.contains("hikari.interior")
                && e.contains(&format!("{name}.gltf")),
            "{bad}: {e}"
        );
    }
}

#[test]
fn the_vertex_attribute_sets_a_per_vertex_mask_float_or_normalized() {
    let m = json!([{"name": "m", "extras": {"hikari": {"interior": 0.75}}}]);
    let path = triangle(
        "vertex_float",
        m.clone(),
        Some((5126, false, floats(&[0.0, 0.5, 1.0]))),
        true,
    );
    let s = load(&path).unwrap().scene;
    assert_eq!(s.meshes[0].interior, [0.0, 0.5, 1.0]);
    // Vertex before material (`Mesh::interior_at`).
    assert_eq!(s.meshes[0].interior_at(1, &s.materials[0]), 0.5);

    let path = triangle(
        "vertex_u8",
        m.clone(),
        Some((5121, true, vec![0, 51, 255])),
        true,
    );
    let s = load(&path).unwrap().scene;
    assert_eq!(s.meshes[0].interior, [0.0, 0.2, 1.0]);

    // Without normals the loader unwelds the triangle for flat normals: the mask follows.
    let path = triangle(
        "vertex_flat",
        m,
        Some((5126, false, floats(&[0.25, 0.5, 0.75]))),
        false,
    );
    let s = load(&path).unwrap().scene;
    let mesh = &s.meshes[0];
    let by_position: Vec<(f32, f32)> = mesh
        .indices
        .iter()
        .map(|&i| {
            (
                mesh.positions[i as usize].x + 2.0 * mesh.positions[i as usize].y,
                mesh.interior[i as usize],
            )
        })
        .collect();
    assert_eq!(mesh.interior.len(), mesh.positions.len());
    for (key, w) in by_position {
        // Position (0,0) had 0.25, (1,0) 0.5, (0,1) 0.75.
        let want = [0.25, 0.5, 0.75][key as usize];
        assert_eq!(w, want);
    }
}

#[test]
fn bad_vertex_masks_name_the_mesh_the_attribute_and_the_file() {
    let m = json!([{"name": "m"}]);
    for (i, (values, shown)) in [
        (floats(&[0.0, 1.5, 0.0]), "1 is 1.5"),
        (floats(&[0.0, 0.0, f32::NAN]), "2 is NaN"),
        (floats(&[-1.0, 0.0, 0.0]), "0 is -1"),
    ]
    .into_iter()
    .enumerate()
    {
        let name = format!("bad_vertex_{i}");
        let path = triangle(&name, m.clone(), Some((5126, false, values)), true);
        let e = load(&path).expect_err(shown);
        assert!(
            e.contains("mesh `tri` primitive 0")
                && e.contains("_HIKARI_INTERIOR")
                && e.contains(shown)
                && e.contains(&format!("{name}.gltf")),
            "{shown}: {e}"
        );
    }
    // Integers that are not normalized are not a mask in [0, 1].
    let path = triangle(
        "bad_vertex_int",
        m,
        Some((5121, false, vec![0, 1, 0])),
        true,
    );
    let e = load(&path).unwrap_err();
    assert!(
        e.contains("_HIKARI_INTERIOR") && e.contains("accessor"),
        "{e}"
    );
}

#[test]
fn a_file_with_nothing_to_draw_loads_with_a_camera_on_the_horizon() {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("gltf_interior");
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("nothing.gltf");
    std::fs::write(
        &path,
        r#"{"asset": {"version": "2.0"}, "nodes": [{"name": "empty"}], "scenes": [{"nodes": [0]}]}"#,
    )
    .unwrap();
    let loaded = load(&path).unwrap();
    let s = &loaded.scene;
    assert!(s.bounds().is_none() && s.instances.is_empty());
    let cam = &s.cameras[..];
    assert_eq!(cam.len(), 1);
    // Level: the view direction has no vertical part, so the horizon is the image's middle row.
    let dir = cam[0].target - cam[0].position;
    assert!(dir.y == 0.0 && dir.length() > 0.0, "{:?}", cam[0]);
    assert!(cam[0].position.y > 0.0, "{:?}", cam[0]);
    assert!(
        loaded.warnings.iter().any(|w| w.contains("no triangles"))
            && loaded.warnings.iter().any(|w| w.contains("horizon")),
        "{:?}",
        loaded.warnings
    );
}
