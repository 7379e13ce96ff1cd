//! The malformed-file corpus in `fixtures/malformed/`: each file must give a clean error that
//! names the file and says what is wrong, never a panic (see fixtures/malformed/README.md).

use std::path::PathBuf;

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
        match hikari_scene::gltf::load(&path) {
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
    let e = hikari_scene::gltf::load(fixture("no_such_file.gltf")).unwrap_err();
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
        assert!(hikari_scene::gltf::load(&path).is_err());
    }
    let path = dir.join("case.gltf");
    for i in (0..json.len()).step_by(7) {
        for b in [b'0', b'}', b'"', b'-', b'9'] {
            let mut bytes = json.clone();
            bytes[i] = b;
            std::fs::write(&path, &bytes).unwrap();
            let _ = hikari_scene::gltf::load(&path);
        }
    }
}
