//! Malformed glTF files: each must give a clean error that names the file and says what is
//! wrong, never a panic. Two corpora: the hand-made files in `fixtures/malformed/` (see the
//! README there) and the cases generated below from one valid triangle, each breaking one
//! thing. Both are loaded with `load_unguarded`, which lacks `load`'s `catch_unwind`, so a
//! panic in the loader fails these tests instead of turning into an error.

use std::path::{Path, PathBuf};

use hikari_scene::gltf::{GltfError, GltfOptions, Loaded, load_unguarded};
use serde_json::{Value, json};

fn load(path: &Path) -> Result<Loaded, GltfError> {
    load_unguarded(path, &GltfOptions::default())
}

fn fixture(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures/malformed")
        .join(name)
}

/// (file, substrings the message must contain, case-insensitive).
const CORPUS: &[(&str, &[&str])] = &[
    (
        "truncated.glb",
        &["truncated .glb", "header says 564 bytes", "282"],
    ),
    ("glb_version_1.glb", &["version 1"]),
    (
        "glb_header_too_short.glb",
        &["malformed .glb", "total length of 4"],
    ),
    (
        "glb_bad_chunk_length.glb",
        &["malformed .glb", "chunklength"],
    ),
    ("bad_json.gltf", &["bad json", "eof"]),
    ("empty.gltf", &["bad json"]),
    (
        "accessor_out_of_range.gltf",
        &[
            "mesh `tri`",
            "position",
            "accessor 0",
            "out of range",
            "10 elements",
        ],
    ),
    (
        "buffer_view_out_of_range.gltf",
        &["buffer view 0", "0..400", "buffer 0", "44"],
    ),
    (
        "missing_buffer_file.gltf",
        &["buffer 0", "cannot read", "does_not_exist.bin"],
    ),
    ("short_buffer.gltf", &["buffer 0", "byteLength 400"]),
    ("bad_base64.gltf", &["buffer 0", "base64"]),
    (
        "bad_uri_encoding.gltf",
        &["buffer 0", "%FF%FE.bin", "UTF-8"],
    ),
    (
        "nan_positions.gltf",
        &["mesh `tri/0`", "position 1 is not finite", "NaN"],
    ),
    (
        "index_out_of_range.gltf",
        &["mesh `tri` primitive 0", "index 2 is 5", "3 vertices"],
    ),
    (
        "wrong_attribute_type.gltf",
        &[
            "mesh `tri` primitive 0",
            "NORMAL",
            "accessor 1 is Scalar U16",
            "expected [Vec3] of float",
        ],
    ),
    (
        "missing_position_accessor.gltf",
        &[
            "meshes[0].primitives[0].attributes[\"POSITION\"]",
            "accessor 7",
            "has 2",
        ],
    ),
    (
        "missing_material.gltf",
        &[
            "invalid gltf",
            "meshes[0].primitives[0].material",
            "index out of bounds",
        ],
    ),
    (
        "unsupported_required_extension.gltf",
        &[
            "extensionsRequired",
            "KHR_draco_mesh_compression",
            "unsupported extension",
        ],
    ),
    ("node_cycle.gltf", &["cycle"]),
];

#[test]
fn every_malformed_file_gives_an_error_naming_the_file_and_the_problem() {
    let mut failures = Vec::new();
    for (name, wanted) in CORPUS {
        let path = fixture(name);
        match load(&path) {
            Ok(_) => failures.push(format!("{name}: loaded without error")),
            Err(e) => {
                let msg = e.to_string();
                assert_eq!(e.path, path);
                if !msg.contains(&path.display().to_string()) {
                    failures.push(format!("{name}: message does not name the file: {msg}"));
                }
                for w in *wanted {
                    if !msg.to_lowercase().contains(&w.to_lowercase()) {
                        failures.push(format!("{name}: message lacks `{w}`: {msg}"));
                    }
                }
            }
        }
    }
    assert!(failures.is_empty(), "\n{}", failures.join("\n"));
}

#[test]
fn the_corpus_covers_every_fixture() {
    let dir = fixture("");
    let mut on_disk: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .filter(|n| n.ends_with(".gltf") || n.ends_with(".glb"))
        .collect();
    on_disk.sort();
    let mut listed: Vec<String> = CORPUS.iter().map(|(n, _)| n.to_string()).collect();
    listed.sort();
    assert_eq!(on_disk, listed);
}

#[test]
fn a_missing_file_is_an_error_too() {
    let e = load(&fixture("no_such_file.gltf")).unwrap_err();
    assert!(
        e.to_string()
            .contains("no_such_file.gltf: cannot read the file"),
        "{e}"
    );
}

/// Every prefix of a valid .glb, and every single-byte corruption of its header and JSON,
/// fails cleanly or loads: never a panic.
#[test]
fn truncations_and_corruptions_never_panic() {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("scene_fuzz");
    std::fs::create_dir_all(&dir).unwrap();
    let glb = std::fs::read(fixture("truncated.glb")).unwrap();
    let json = std::fs::read(fixture("nan_positions.gltf")).unwrap();
    let path = dir.join("case.glb");
    for len in 0..glb.len() {
        std::fs::write(&path, &glb[..len]).unwrap();
        assert!(load(&path).is_err());
    }
    let path = dir.join("case.gltf");
    for i in (0..json.len()).step_by(7) {
        for b in [b'0', b'}', b'"', b'-', b'9'] {
            let mut bytes = json.clone();
            bytes[i] = b;
            std::fs::write(&path, &bytes).unwrap();
            let _ = load(&path);
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Generated corpus.

/// Byte layout of `tri.bin`: three positions, three normals, three UVs, three u16 indices.
const POS: usize = 0;
const NRM: usize = 36;
const UV: usize = 72;
const IDX: usize = 96;
const BIN_LEN: usize = 104;

fn tri_bin() -> Vec<u8> {
    let mut b = Vec::new();
    let f = |b: &mut Vec<u8>, v: &[f32]| b.extend(v.iter().flat_map(|x| x.to_le_bytes()));
    f(&mut b, &[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0]);
    f(&mut b, &[0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0]);
    f(&mut b, &[0.0, 0.0, 1.0, 0.0, 0.0, 1.0]);
    b.extend([0u16, 1, 2].iter().flat_map(|x| x.to_le_bytes()));
    b.resize(BIN_LEN, 0);
    b
}

/// The valid triangle every case breaks: mesh `tri` on node `n`, material `m`, buffer `tri.bin`.
fn tri_doc() -> Value {
    let view =
        |offset: usize, len: usize| json!({"buffer": 0, "byteOffset": offset, "byteLength": len});
    json!({
        "asset": {"version": "2.0"},
        "buffers": [{"uri": "tri.bin", "byteLength": BIN_LEN}],
        "bufferViews": [view(POS, 36), view(NRM, 36), view(UV, 24), view(IDX, 6)],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
             "min": [0.0, 0.0, 0.0], "max": [1.0, 1.0, 0.0]},
            {"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC3"},
            {"bufferView": 2, "componentType": 5126, "count": 3, "type": "VEC2"},
            {"bufferView": 3, "componentType": 5123, "count": 3, "type": "SCALAR"}
        ],
        "materials": [{"name": "m"}],
        "meshes": [{"name": "tri", "primitives": [{
            "attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2},
            "indices": 3, "material": 0
        }]}],
        "nodes": [{"name": "n", "mesh": 0}],
        "scenes": [{"nodes": [0]}],
        "scene": 0
    })
}

/// Adds a camera named `cam` with `perspective` on a new root node; returns the node's index.
fn add_camera(doc: &mut Value, camera: Value) -> usize {
    doc["cameras"] = json!([camera]);
    add_node(
        doc,
        json!({"name": "cam node", "camera": 0, "translation": [0.0, 0.0, 3.0]}),
    )
}

fn perspective(p: Value) -> Value {
    json!({"name": "cam", "type": "perspective", "perspective": p})
}

/// Adds the KHR_lights_punctual light `light` on a new root node with the extra node members
/// of `node`; returns the node's index.
fn add_light(doc: &mut Value, light: Value, node: Value) -> usize {
    doc["extensionsUsed"] = json!(["KHR_lights_punctual"]);
    doc["extensions"] = json!({"KHR_lights_punctual": {"lights": [light]}});
    let mut n = json!({"name": "lamp node", "extensions": {"KHR_lights_punctual": {"light": 0}}});
    for (k, v) in node.as_object().unwrap() {
        n[k] = v.clone();
    }
    add_node(doc, n)
}

fn add_node(doc: &mut Value, node: Value) -> usize {
    let nodes = doc["nodes"].as_array_mut().unwrap();
    nodes.push(node);
    let i = nodes.len() - 1;
    doc["scenes"][0]["nodes"]
        .as_array_mut()
        .unwrap()
        .push(json!(i));
    i
}

/// A .glb: header, JSON chunk (space-padded), BIN chunk if given (zero-padded).
fn glb(json: &[u8], bin: Option<&[u8]>) -> Vec<u8> {
    let pad = |v: &[u8], with: u8| {
        let mut v = v.to_vec();
        while !v.len().is_multiple_of(4) {
            v.push(with);
        }
        v
    };
    let json = pad(json, b' ');
    let bin = bin.map(|b| pad(b, 0));
    let total = 12 + 8 + json.len() + bin.as_ref().map_or(0, |b| 8 + b.len());
    let mut out = Vec::new();
    out.extend(b"glTF");
    out.extend(2u32.to_le_bytes());
    out.extend((total as u32).to_le_bytes());
    out.extend((json.len() as u32).to_le_bytes());
    out.extend(b"JSON");
    out.extend(&json);
    if let Some(bin) = bin {
        out.extend((bin.len() as u32).to_le_bytes());
        out.extend(b"BIN\0");
        out.extend(&bin);
    }
    out
}

/// How a case is written to disk.
enum Container {
    /// `<name>.gltf` with the buffer in `tri.bin` beside it.
    Gltf,
    /// `<name>.gltf` holding exactly these bytes (for text JSON cannot express), `tri.bin`
    /// beside it.
    GltfText(String),
    /// `<name>.glb` with the document's buffer 0 as its BIN chunk (`None`: no BIN chunk).
    Glb(Option<Vec<u8>>),
}

struct Case {
    name: &'static str,
    doc: Value,
    bin: Vec<u8>,
    container: Container,
    /// Other files beside the document: (name, bytes).
    extra: Vec<(&'static str, Vec<u8>)>,
    /// Substrings the message must contain (case-insensitive), besides the file's path.
    wanted: &'static [&'static str],
}

fn case(
    name: &'static str,
    wanted: &'static [&'static str],
    edit: impl FnOnce(&mut Value, &mut Vec<u8>),
) -> Case {
    let (mut doc, mut bin) = (tri_doc(), tri_bin());
    edit(&mut doc, &mut bin);
    Case {
        name,
        doc,
        bin,
        container: Container::Gltf,
        extra: Vec::new(),
        wanted,
    }
}

impl Case {
    fn container(mut self, c: Container) -> Self {
        self.container = c;
        self
    }

    fn with_file(mut self, name: &'static str, bytes: Vec<u8>) -> Self {
        self.extra.push((name, bytes));
        self
    }

    /// Writes the case into its own directory; returns the document's path.
    fn write(&self) -> PathBuf {
        let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
            .join("malformed_generated")
            .join(self.name);
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join("tri.bin"), &self.bin).unwrap();
        for (name, bytes) in &self.extra {
            std::fs::write(dir.join(name), bytes).unwrap();
        }
        let json = serde_json::to_vec_pretty(&self.doc).unwrap();
        let (file, bytes) = match &self.container {
            Container::Gltf => (format!("{}.gltf", self.name), json),
            Container::GltfText(text) => (format!("{}.gltf", self.name), text.clone().into_bytes()),
            Container::Glb(bin) => (format!("{}.glb", self.name), glb(&json, bin.as_deref())),
        };
        let path = dir.join(file);
        std::fs::write(&path, bytes).unwrap();
        path
    }
}

/// The PNG signature followed by text: recognised as PNG, then undecodable.
fn broken_png() -> Vec<u8> {
    let mut v = vec![0x89, b'P', b'N', b'G', 0x0d, 0x0a, 0x1a, 0x0a];
    v.extend(b"this is not the rest of a PNG file");
    v
}

fn generated_corpus() -> Vec<Case> {
    let u32_max = u32::MAX as u64;
    vec![
        // --- Attribute counts and types.
        case(
            "normal_count_disagrees",
            &[
                "mesh `tri` primitive 0",
                "NORMAL has 2 elements but POSITION has 3",
            ],
            |d, _| d["accessors"][1]["count"] = json!(2),
        ),
        case(
            "uv_count_disagrees",
            &[
                "mesh `tri` primitive 0",
                "TEXCOORD_0 has 2 elements but POSITION has 3",
            ],
            |d, _| d["accessors"][2]["count"] = json!(2),
        ),
        case(
            "color_count_disagrees",
            &["COLOR_0 has 2 elements but POSITION has 3"],
            |d, _| {
                d["accessors"].as_array_mut().unwrap().push(
                    json!({"bufferView": 1, "componentType": 5126, "count": 2, "type": "VEC3"}),
                );
                d["meshes"][0]["primitives"][0]["attributes"]["COLOR_0"] = json!(4);
            },
        ),
        case(
            "tangent_is_vec3",
            &[
                "TANGENT",
                "accessor 1 is Vec3 F32",
                "expected [Vec4] of float",
            ],
            |d, _| d["meshes"][0]["primitives"][0]["attributes"]["TANGENT"] = json!(1),
        ),
        case(
            "position_is_u8",
            &[
                "POSITION",
                "accessor 0 is Vec3 U8",
                "expected [Vec3] of float",
            ],
            |d, _| d["accessors"][0]["componentType"] = json!(5121),
        ),
        case(
            "texcoord_u8_not_normalized",
            &[
                "TEXCOORD_0",
                "accessor 2 is Vec2 U8",
                "or normalized u8/u16",
            ],
            |d, _| d["accessors"][2]["componentType"] = json!(5121),
        ),
        case(
            "component_type_double",
            &[
                "invalid glTF",
                "accessors[1].componentType",
                "invalid value",
            ],
            |d, _| d["accessors"][1]["componentType"] = json!(5130),
        ),
        case(
            "accessor_type_unknown",
            &["invalid glTF", "accessors[1].type", "invalid value"],
            |d, _| d["accessors"][1]["type"] = json!("VEC5"),
        ),
        // --- Indices.
        case(
            "indices_are_float_vec3",
            &[
                "indices: accessor 0 is Vec3 F32",
                "expected an unsigned integer scalar",
            ],
            |d, _| d["meshes"][0]["primitives"][0]["indices"] = json!(0),
        ),
        case(
            "indices_not_whole_triangles",
            &[
                "mesh `tri` primitive 0",
                "2 indices is not a whole number of triangles",
            ],
            |d, _| d["accessors"][3]["count"] = json!(2),
        ),
        case(
            "index_u32_max",
            &[
                "mesh `tri` primitive 0",
                "index 1 is 4294967295",
                "only 3 vertices",
            ],
            |d, b| {
                d["accessors"][3]["componentType"] = json!(5125);
                d["bufferViews"][3]["byteLength"] = json!(8);
                d["accessors"][3]["count"] = json!(2);
                b[IDX..IDX + 8].copy_from_slice(&[0, 0, 0, 0, 255, 255, 255, 255]);
                // Two indices are not a triangle; a third from the padding would be out of the
                // view, so make it three by widening the buffer instead.
                b.extend([0u8; 4]);
                d["buffers"][0]["byteLength"] = json!(BIN_LEN + 4);
                d["bufferViews"][3]["byteLength"] = json!(12);
                d["accessors"][3]["count"] = json!(3);
            },
        ),
        // --- Offsets and counts out of range.
        case(
            "buffer_view_offset_past_end",
            &["buffer view 0 spans bytes 1000..1036 of buffer 0, which has 104"],
            |d, _| d["bufferViews"][0]["byteOffset"] = json!(1000),
        ),
        case(
            "buffer_view_offset_overflows",
            &[
                "buffer view 0 spans bytes 18446744073709551615..",
                "which has 104",
            ],
            |d, _| d["bufferViews"][0]["byteOffset"] = json!(u64::MAX),
        ),
        case(
            "accessor_offset_past_view",
            &[
                "POSITION: accessor 0",
                "out of range",
                "byte offset 32",
                "buffer view has 36",
            ],
            |d, _| d["accessors"][0]["byteOffset"] = json!(32),
        ),
        case(
            "stride_smaller_than_element",
            &[
                "accessor 0",
                "byte stride 4 is smaller than the element size 12",
            ],
            |d, _| d["bufferViews"][0]["byteStride"] = json!(4),
        ),
        case(
            "count_u32_max",
            &[
                "POSITION: accessor 0",
                "4294967295 elements of 12 bytes",
                "out of range",
            ],
            |d, _| d["accessors"][0]["count"] = json!(u32_max),
        ),
        case(
            "viewless_count_u32_max",
            &["accessor 1", "no buffer view and 4294967295 elements"],
            |d, _| {
                // Without a view an accessor must be sparse (zeros plus substitutions).
                d["accessors"][1] = json!({
                    "componentType": 5126, "count": u32_max, "type": "VEC3",
                    "sparse": {
                        "count": 1,
                        "indices": {"bufferView": 3, "componentType": 5123},
                        "values": {"bufferView": 1}
                    }
                });
            },
        ),
        case(
            "count_times_components_overflows",
            &["accessor 1", "is too large"],
            // 2^63 VEC3 elements: 3 x 2^63 components overflow 64 bits.
            |d, _| d["accessors"][1]["count"] = json!(1u64 << 63),
        ),
        case(
            "sparse_count_u32_max",
            &[
                "accessor 1",
                "sparse indices out of range",
                "4294967295 elements",
            ],
            |d, _| {
                d["accessors"][1]["sparse"] = json!({
                    "count": u32_max,
                    "indices": {"bufferView": 3, "componentType": 5123},
                    "values": {"bufferView": 1}
                });
            },
        ),
        case(
            "sparse_index_out_of_range",
            &[
                "accessor 1",
                "sparse index 7 is out of range for 3 elements",
            ],
            |d, b| {
                b[IDX..IDX + 2].copy_from_slice(&7u16.to_le_bytes());
                d["accessors"][1]["sparse"] = json!({
                    "count": 1,
                    "indices": {"bufferView": 3, "componentType": 5123},
                    "values": {"bufferView": 1}
                });
                // The triangle's own indices must stay valid: point them at a fresh copy.
                b.extend([0u16, 1, 2, 0].iter().flat_map(|x| x.to_le_bytes()));
                d["buffers"][0]["byteLength"] = json!(BIN_LEN + 8);
                d["bufferViews"]
                    .as_array_mut()
                    .unwrap()
                    .push(json!({"buffer": 0, "byteOffset": BIN_LEN, "byteLength": 6}));
                d["accessors"][3]["bufferView"] = json!(4);
            },
        ),
        // --- Buffers.
        case(
            "buffer_unsupported_scheme",
            &[
                "buffer 0",
                "URI `https://example.com/tri.bin`",
                "unsupported scheme",
            ],
            |d, _| d["buffers"][0]["uri"] = json!("https://example.com/tri.bin"),
        ),
        case(
            "buffer_is_a_directory",
            &["buffer 0", "cannot read"],
            |d, _| d["buffers"][0]["uri"] = json!("."),
        ),
        case(
            "glb_without_bin_chunk",
            &["buffer 0 has no uri", "BIN chunk, which is missing"],
            |d, _| d["buffers"][0] = json!({"byteLength": BIN_LEN}),
        )
        .container(Container::Glb(None)),
        case(
            "glb_two_buffers_want_bin",
            &["buffer 1 has no uri", "buffer 0 already uses it"],
            |d, _| {
                d["buffers"] = json!([{"byteLength": BIN_LEN}, {"byteLength": 4}]);
            },
        )
        .container(Container::Glb(Some(tri_bin()))),
        case(
            "glb_bin_chunk_short",
            &["buffer 0 has 8 bytes but declares byteLength 104"],
            |d, _| d["buffers"][0] = json!({"byteLength": BIN_LEN}),
        )
        .container(Container::Glb(Some(vec![0; 8]))),
        // --- Node transforms and hierarchy.
        case(
            "node_translation_overflows_f32",
            &["node 0: transform is not finite"],
            // 1e39 is beyond f32's range: it reads as infinity.
            |d, _| d["nodes"][0]["translation"] = json!([1e39, 0.0, 0.0]),
        ),
        case(
            "node_matrix_overflows_f32",
            &["node 0: transform is not finite"],
            |d, _| {
                d["nodes"][0]["matrix"] =
                    json!([1e39, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]);
            },
        ),
        case(
            "node_scales_overflow_when_composed",
            &["node 1: transform is not finite"],
            |d, _| {
                d["nodes"] = json!([
                    {"name": "parent", "scale": [1e30, 1e30, 1e30], "children": [1]},
                    {"name": "child", "scale": [1e30, 1e30, 1e30], "mesh": 0}
                ]);
            },
        ),
        case(
            "node_self_child",
            &["node 0 is its own ancestor", "cycle"],
            |d, _| {
                d["nodes"][0]["children"] = json!([0]);
            },
        ),
        case(
            "node_three_cycle",
            &["is its own ancestor", "cycle"],
            |d, _| {
                d["nodes"] = json!([
                    {"children": [1]},
                    {"children": [2]},
                    {"children": [0], "mesh": 0}
                ]);
            },
        ),
        case(
            "node_hierarchy_explodes",
            &["node hierarchy expands to more than 4194304 nodes"],
            |d, _| {
                // Each node lists the next twice: 2^40 paths to the last.
                let n = 40;
                let nodes: Vec<Value> = (0..n)
                    .map(|i| {
                        if i + 1 < n {
                            json!({"children": [i + 1, i + 1]})
                        } else {
                            json!({"mesh": 0})
                        }
                    })
                    .collect();
                d["nodes"] = json!(nodes);
            },
        ),
        case(
            "node_missing_mesh",
            &["invalid glTF", "nodes[0].mesh", "index out of bounds"],
            |d, _| d["nodes"][0]["mesh"] = json!(9),
        ),
        case(
            "scene_missing_node",
            &["invalid glTF", "scenes[0].nodes[0]", "index out of bounds"],
            |d, _| d["scenes"][0]["nodes"] = json!([5]),
        ),
        // --- Cameras.
        case(
            "camera_yfov_zero",
            &["camera `cam` (cameras[0])", "yfov 0 rad is outside (0, pi)"],
            |d, _| {
                add_camera(d, perspective(json!({"yfov": 0.0, "znear": 0.1})));
            },
        ),
        case(
            "camera_yfov_over_pi",
            &["camera `cam`", "yfov 4 rad"],
            |d, _| {
                add_camera(d, perspective(json!({"yfov": 4.0, "znear": 0.1})));
            },
        ),
        {
            // JSON has no NaN; a writer that prints one anyway makes the file unreadable.
            let mut c = case("camera_yfov_nan", &["bad json"], |d, _| {
                add_camera(d, perspective(json!({"yfov": 0.5, "znear": 0.1})));
            });
            let text = serde_json::to_string(&c.doc)
                .unwrap()
                .replace("\"yfov\":0.5", "\"yfov\":NaN");
            assert!(text.contains("NaN"));
            c.container = Container::GltfText(text);
            c
        },
        case(
            "camera_znear_zero",
            &["camera `cam`", "znear 0 must be positive"],
            |d, _| {
                add_camera(d, perspective(json!({"yfov": 0.8, "znear": 0.0})));
            },
        ),
        case(
            "camera_zfar_below_znear",
            &[
                "camera `cam`",
                "zfar 0.5 must be finite and greater than znear 1",
            ],
            |d, _| {
                add_camera(
                    d,
                    perspective(json!({"yfov": 0.8, "znear": 1.0, "zfar": 0.5})),
                );
            },
        ),
        case(
            "camera_zfar_equals_znear",
            &[
                "camera `cam`",
                "zfar 1 must be finite and greater than znear 1",
            ],
            |d, _| {
                add_camera(
                    d,
                    perspective(json!({"yfov": 0.8, "znear": 1.0, "zfar": 1.0})),
                );
            },
        ),
        case(
            "camera_aspect_zero",
            &["camera `cam`", "aspectRatio 0 must be positive"],
            |d, _| {
                add_camera(
                    d,
                    perspective(json!({"yfov": 0.8, "znear": 0.1, "aspectRatio": 0.0})),
                );
            },
        ),
        case(
            "camera_type_without_member",
            &[
                "invalid glTF",
                "cameras[0] has type \"perspective\" but no `perspective` member",
            ],
            |d, _| {
                add_camera(
                    d,
                    json!({"type": "perspective",
                           "orthographic": {"xmag": 1.0, "ymag": 1.0, "znear": 0.1, "zfar": 10.0}}),
                );
            },
        ),
        case(
            "camera_node_scaled_to_zero",
            &["camera `cam`", "transform is degenerate"],
            |d, _| {
                let n = add_camera(d, perspective(json!({"yfov": 0.8, "znear": 0.1})));
                d["nodes"][n]["scale"] = json!([0.0, 0.0, 0.0]);
            },
        ),
        // --- Images.
        case(
            "image_undecodable",
            &["image 0 (`", "broken.png`)", "png"],
            |d, _| {
                d["images"] = json!([{"uri": "broken.png"}]);
                d["textures"] = json!([{"source": 0}]);
                d["materials"][0]["pbrMetallicRoughness"] =
                    json!({"baseColorTexture": {"index": 0}});
            },
        )
        .with_file("broken.png", broken_png()),
        case(
            "image_missing_file",
            &["image 0", "cannot read", "missing.png"],
            |d, _| {
                d["images"] = json!([{"uri": "missing.png"}]);
                d["textures"] = json!([{"source": 0}]);
            },
        ),
        case(
            "image_unsupported_encoding",
            &["image 0 (buffer view 0)", "unsupported image encoding"],
            |d, _| {
                d["images"] = json!([{"bufferView": 0, "mimeType": "image/gif"}]);
                d["textures"] = json!([{"source": 0}]);
            },
        ),
        case(
            "texture_missing_image",
            &["invalid glTF", "textures[0].source", "index out of bounds"],
            |d, _| d["textures"] = json!([{"source": 3}]),
        ),
        // --- Materials.
        case(
            "alpha_cutoff_negative",
            &["material `m`", "alphaCutoff -0.5 is outside [0, 1]"],
            |d, _| {
                d["materials"][0] = json!({"name": "m", "alphaMode": "MASK", "alphaCutoff": -0.5})
            },
        ),
        case(
            "alpha_cutoff_above_one",
            &["material `m`", "alphaCutoff 2 is outside [0, 1]"],
            |d, _| {
                d["materials"][0] = json!({"name": "m", "alphaMode": "MASK", "alphaCutoff": 2.0})
            },
        ),
        case(
            "alpha_mode_unknown",
            &["invalid glTF", "materials[0].alphaMode", "invalid value"],
            |d, _| d["materials"][0]["alphaMode"] = json!("DITHER"),
        ),
        case(
            "base_color_negative",
            &[
                "material `m`",
                "base colour",
                "must be finite and non-negative",
            ],
            |d, _| {
                d["materials"][0]["pbrMetallicRoughness"] =
                    json!({"baseColorFactor": [-1.0, 0.5, 0.5, 1.0]});
            },
        ),
        // --- Lights.
        case(
            "light_negative_intensity",
            &[
                "light `lamp` (KHR_lights_punctual lights[0])",
                "intensity -5 must be finite and non-negative",
            ],
            |d, _| {
                add_light(
                    d,
                    json!({"name": "lamp", "type": "point", "intensity": -5.0}),
                    json!({}),
                );
            },
        ),
        case(
            "sun_negative_intensity",
            &["light `lamp`", "intensity -1"],
            |d, _| {
                add_light(
                    d,
                    json!({"name": "lamp", "type": "directional", "intensity": -1.0}),
                    json!({}),
                );
            },
        ),
        case(
            "light_negative_color",
            &[
                "light `lamp`",
                "color [1, -1, 1] must be finite and non-negative",
            ],
            |d, _| {
                add_light(
                    d,
                    json!({"name": "lamp", "type": "point", "color": [1.0, -1.0, 1.0]}),
                    json!({}),
                );
            },
        ),
        case(
            "light_range_zero",
            &["light `lamp`", "range 0 must be positive"],
            |d, _| {
                add_light(
                    d,
                    json!({"name": "lamp", "type": "point", "range": 0.0}),
                    json!({}),
                );
            },
        ),
        case(
            "spot_outer_beyond_right_angle",
            &[
                "light `lamp`",
                "innerConeAngle 0.1 and outerConeAngle 2 rad",
            ],
            |d, _| {
                add_light(
                    d,
                    json!({"name": "lamp", "type": "spot",
                           "spot": {"innerConeAngle": 0.1, "outerConeAngle": 2.0}}),
                    json!({}),
                );
            },
        ),
        case(
            "spot_inner_not_below_outer",
            &[
                "light `lamp`",
                "innerConeAngle 0.5 and outerConeAngle 0.5 rad",
            ],
            |d, _| {
                add_light(
                    d,
                    json!({"name": "lamp", "type": "spot",
                           "spot": {"innerConeAngle": 0.5, "outerConeAngle": 0.5}}),
                    json!({}),
                );
            },
        ),
        case(
            "spot_without_spot_member",
            &["invalid glTF", "spot", "missing"],
            |d, _| {
                add_light(d, json!({"name": "lamp", "type": "spot"}), json!({}));
            },
        ),
        case(
            "sun_node_scaled_to_zero",
            &["light `lamp`", "gives the light no direction"],
            |d, _| {
                add_light(
                    d,
                    json!({"name": "lamp", "type": "directional"}),
                    json!({"scale": [0.0, 0.0, 0.0]}),
                );
            },
        ),
        case(
            "node_light_without_lights",
            &["invalid glTF", "nodes[0]", "light"],
            |d, _| {
                d["extensionsUsed"] = json!(["KHR_lights_punctual"]);
                d["nodes"][0]["extensions"] = json!({"KHR_lights_punctual": {"light": 0}});
            },
        ),
        // --- Non-finite vertex data (through Scene::validate, naming the mesh).
        case(
            "normal_nan",
            &["mesh `tri/0`", "normal 1 is not finite"],
            |_, b| b[NRM + 12..NRM + 16].copy_from_slice(&f32::NAN.to_le_bytes()),
        ),
        case(
            "uv_infinite",
            &["mesh `tri/0`", "uv 2 is not finite"],
            |_, b| b[UV + 16..UV + 20].copy_from_slice(&f32::INFINITY.to_le_bytes()),
        ),
    ]
}

fn check_error(path: &Path, name: &str, wanted: &[&str], failures: &mut Vec<String>) {
    match load(path) {
        Ok(_) => failures.push(format!("{name}: loaded without error")),
        Err(e) => {
            let msg = e.to_string();
            if e.path != path || !msg.starts_with(&format!("{}: ", path.display())) {
                failures.push(format!("{name}: message does not name the file: {msg}"));
            }
            for w in wanted {
                if !msg.to_lowercase().contains(&w.to_lowercase()) {
                    failures.push(format!("{name}: message lacks `{w}`: {msg}"));
                }
            }
        }
    }
}

#[test]
fn the_unbroken_triangle_loads_with_a_camera_and_each_kind_of_light() {
    let mut doc = tri_doc();
    add_camera(
        &mut doc,
        perspective(json!({"yfov": 0.8, "znear": 0.1, "zfar": 100.0, "aspectRatio": 1.5})),
    );
    let lights = [
        json!({"name": "lamp", "type": "point", "intensity": 5.0, "range": 3.0}),
        json!({"name": "lamp", "type": "spot", "spot": {"innerConeAngle": 0.2, "outerConeAngle": 0.4}}),
        json!({"name": "lamp", "type": "directional", "intensity": 3.0}),
    ];
    for (k, light) in lights.into_iter().enumerate() {
        let mut doc = doc.clone();
        add_light(&mut doc, light, json!({}));
        let c = Case {
            name: ["valid_point", "valid_spot", "valid_sun"][k],
            doc,
            bin: tri_bin(),
            container: Container::Gltf,
            extra: Vec::new(),
            wanted: &[],
        };
        let loaded = load(&c.write()).unwrap_or_else(|e| panic!("{}: {e}", c.name));
        assert_eq!(loaded.scene.cameras[0].name, "cam");
        assert_eq!(
            loaded.scene.lights.len() + loaded.scene.sun.iter().count(),
            1
        );
    }
    let c = case("valid_glb", &[], |d, _| {
        d["buffers"][0] = json!({"byteLength": BIN_LEN})
    })
    .container(Container::Glb(Some(tri_bin())));
    load(&c.write()).unwrap();
}

#[test]
fn every_generated_case_gives_an_error_naming_the_file_and_the_problem() {
    let corpus = generated_corpus();
    assert!(corpus.len() + CORPUS.len() >= 30);
    let mut names: Vec<_> = corpus.iter().map(|c| c.name).collect();
    names.sort();
    names.dedup();
    assert_eq!(names.len(), corpus.len(), "case names must be unique");
    let mut failures = Vec::new();
    for c in &corpus {
        check_error(&c.write(), c.name, c.wanted, &mut failures);
    }
    assert!(failures.is_empty(), "\n{}", failures.join("\n"));
}

/// A chain of nodes thousands deep is not malformed: it loads, without recursion, and the
/// leaf's transform is the product of the chain (each link translates 1 mm along x).
#[test]
fn a_node_chain_thousands_deep_loads() {
    let depth = 5000;
    let c = case("deep_chain", &[], |d, _| {
        let nodes: Vec<Value> = (0..depth)
            .map(|i| {
                if i + 1 < depth {
                    json!({"translation": [0.001, 0.0, 0.0], "children": [i + 1]})
                } else {
                    json!({"translation": [0.001, 0.0, 0.0], "mesh": 0})
                }
            })
            .collect();
        d["nodes"] = json!(nodes);
    });
    let scene = load(&c.write()).unwrap().scene;
    assert_eq!(scene.instances.len(), 1);
    let x = scene.instances[0].transform.w_axis.x;
    assert!((x - depth as f32 * 0.001).abs() < 1e-3, "{x}");
}

/// Blend and mask materials load with their modes; blend warns that it is drawn as a cut-out.
#[test]
fn alpha_modes_load() {
    use hikari_scene::AlphaMode;
    let c = case("alpha_modes", &[], |d, _| {
        d["materials"] = json!([
            {"name": "opaque"},
            {"name": "mask default", "alphaMode": "MASK"},
            {"name": "mask 0.3", "alphaMode": "MASK", "alphaCutoff": 0.3},
            {"name": "blend", "alphaMode": "BLEND"}
        ]);
    });
    let loaded = load(&c.write()).unwrap();
    let m = &loaded.scene.materials;
    assert_eq!(m[0].alpha_mode, AlphaMode::Opaque);
    assert_eq!(m[0].alpha_cutoff(), None);
    // glTF 2.0 spec, material.alphaCutoff: "default": 0.5.
    assert_eq!(m[1].alpha_mode, AlphaMode::Mask { cutoff: 0.5 });
    assert_eq!(m[2].alpha_cutoff(), Some(0.3));
    assert_eq!(m[3].alpha_mode, AlphaMode::Blend);
    assert_eq!(m[3].alpha_cutoff(), Some(0.5));
    assert!(
        loaded
            .warnings
            .iter()
            .any(|w| w.contains("material `blend`") && w.contains("cut-out")),
        "{:?}",
        loaded.warnings
    );
    assert!(!loaded.warnings.iter().any(|w| w.contains("mask")));
}

/// A material's `extras` `{"hikari": {"area_light": ...}}` sets `Material::area_light`; other
/// extras are ignored; a flag that is not a boolean is an error naming the material.
#[test]
fn area_light_extras_load() {
    let c = case("area_light_extras", &[], |d, _| {
        d["materials"] = json!([
            {"name": "plain"},
            {"name": "on", "extras": {"hikari": {"area_light": true}, "other": 1}},
            {"name": "off", "extras": {"hikari": {"area_light": false}}},
            {"name": "unrelated", "extras": {"tool": "blender"}}
        ]);
    });
    let loaded = load(&c.write()).unwrap();
    let flags: Vec<_> = loaded
        .scene
        .materials
        .iter()
        .map(|m| m.area_light)
        .collect();
    assert_eq!(flags, [None, Some(true), Some(false), None]);
    let bad = case("area_light_extras_bad", &[], |d, _| {
        d["materials"] = json!([{"name": "lamp", "extras": {"hikari": {"area_light": "yes"}}}]);
    });
    let e = load(&bad.write()).unwrap_err().to_string();
    assert!(
        e.contains("material `lamp`") && e.contains("area_light"),
        "{e}"
    );
}
