//! Every kind of bad bake file gives its own error naming the file; edits behind the checksum
//! are re-sealed with a valid CRC so that the structural checks themselves are exercised.

mod common;
use common::*;
use hikari_probes::{Problem, SceneKey, decode};

fn fixture() -> Vec<u8> {
    std::fs::read(FIXTURE).unwrap()
}

fn problem(bytes: &[u8]) -> Problem {
    decode(bytes, &formula_key()).unwrap_err()
}

/// Edits the fixture, re-seals it and returns the decoder's complaint.
fn sealed(edit: impl FnOnce(&mut Vec<u8>)) -> Problem {
    let mut bytes = fixture();
    edit(&mut bytes);
    fix_crc(&mut bytes);
    problem(&bytes)
}

#[test]
fn missing_file_names_the_file() {
    let path = std::path::Path::new("/nonexistent/dir/scene.hkprobe");
    let err = hikari_probes::read_bake(path, &formula_key()).unwrap_err();
    assert_eq!(err.problem, Problem::Missing);
    let message = err.to_string();
    assert!(
        message.contains("/nonexistent/dir/scene.hkprobe") && message.contains("does not exist"),
        "{message}"
    );
}

#[test]
fn truncated_and_trailing_bytes() {
    let bytes = fixture();
    let n = bytes.len() as u64;
    assert_eq!(
        problem(&bytes[..10]),
        Problem::Truncated {
            expected: 84,
            actual: 10
        }
    );
    assert_eq!(
        problem(&bytes[..5000]),
        Problem::Truncated {
            expected: n,
            actual: 5000
        }
    );
    let mut longer = bytes.clone();
    longer.push(0);
    assert_eq!(
        problem(&longer),
        Problem::TrailingBytes {
            expected: n,
            actual: n + 1
        }
    );
}

#[test]
fn bad_magic_and_wrong_version() {
    let mut bytes = fixture();
    bytes[0] = b'X';
    assert!(matches!(problem(&bytes), Problem::BadMagic { found } if &found == b"XIKPROBE"));
    assert!(matches!(problem(b"GIF89a..."), Problem::BadMagic { .. }));
    let p = sealed(|b| put_u32(b, 8, 2));
    assert_eq!(
        p,
        Problem::UnsupportedVersion {
            found: 2,
            supported: 1
        }
    );
}

#[test]
fn checksum_mismatch_on_a_flipped_bit() {
    let mut bytes = fixture();
    bytes[TILE_PROBES + 1001] ^= 0x08;
    assert!(matches!(problem(&bytes), Problem::ChecksumMismatch { .. }));
}

#[test]
fn other_scene() {
    let bytes = fixture();
    let other = SceneKey::from_u64(42);
    let p = decode(&bytes, &other).unwrap_err();
    assert_eq!(
        p,
        Problem::OtherScene {
            expected: other,
            found: formula_key()
        }
    );
    assert!(p.to_string().contains("000102030405"), "{p}");
}

#[test]
fn unknown_flags_and_bad_settings() {
    assert_eq!(sealed(|b| put_u32(b, 12, 3)), Problem::UnknownFlags(2));
    assert!(matches!(
        sealed(|b| put_u32(b, 56, 0)),
        Problem::InvalidSettings(_)
    ));
    assert!(matches!(
        sealed(|b| put_f32(b, 60, -12.5)),
        Problem::InvalidSettings(_)
    ));
    assert!(matches!(
        sealed(|b| put_f32(b, 68, f32::NAN)),
        Problem::InvalidSettings(_)
    ));
}

#[test]
fn inconsistent_counts() {
    // The mesh's probe count in the table no longer matches its length.
    let p = sealed(|b| put_u32(b, TABLE + 24 + 4, MESH_N as u32 + 1));
    assert!(
        matches!(p, Problem::InconsistentCounts { section: 1, .. }),
        "{p:?}"
    );
    // The mesh's tetrahedron count.
    let p = sealed(|b| put_u32(b, MESH + 4, 3));
    assert!(
        matches!(p, Problem::InconsistentCounts { section: 1, .. }),
        "{p:?}"
    );
    // A tile that claims 767 probes.
    let p = sealed(|b| put_u32(b, TABLE + 4, 767));
    assert!(
        matches!(p, Problem::InconsistentCounts { section: 0, .. }),
        "{p:?}"
    );
    // More sections than the file can hold.
    let p = sealed(|b| put_u32(b, 76, u32::MAX));
    assert!(matches!(p, Problem::InconsistentCounts { .. }), "{p:?}");
    // A section that starts elsewhere than right after the previous one.
    let p = sealed(|b| put_u32(b, TABLE + 24 + 8, MESH as u32 + 1));
    assert!(
        matches!(p, Problem::SectionTable { section: 1, .. }),
        "{p:?}"
    );
    let p = sealed(|b| put_u32(b, TABLE, 9));
    assert!(
        matches!(p, Problem::SectionTable { section: 0, .. }),
        "{p:?}"
    );
}

#[test]
fn indices_out_of_range() {
    let p = sealed(|b| put_u32(b, MESH_TETS + 16 + 12, 5));
    assert_eq!(
        p,
        Problem::IndexOutOfRange {
            section: 1,
            what: "vertex of tetrahedron",
            element: 1,
            index: 5,
            limit: 5
        }
    );
    let p = sealed(|b| put_u32(b, MESH_ADJACENCY + 4, 2));
    assert_eq!(
        p,
        Problem::IndexOutOfRange {
            section: 1,
            what: "neighbour of tetrahedron",
            element: 0,
            index: 2,
            limit: 2
        }
    );
    // Tet 1 no longer lists tet 0 back.
    let p = sealed(|b| put_u32(b, MESH_ADJACENCY + 16 + 12, u32::MAX));
    assert_eq!(
        p,
        Problem::AdjacencyNotMutual {
            section: 1,
            tet: 0,
            neighbour: 1
        }
    );
    // A tet that is its own neighbour.
    let p = sealed(|b| put_u32(b, MESH_ADJACENCY + 4, 0));
    assert_eq!(
        p,
        Problem::AdjacencyNotMutual {
            section: 1,
            tet: 0,
            neighbour: 0
        }
    );
    let p = sealed(|b| put_u32(b, MESH_TETS + 4, 0));
    assert_eq!(
        p,
        Problem::DegenerateTet {
            section: 1,
            tet: 0,
            vertices: [0, 0, 2, 3]
        }
    );
}

#[test]
fn nan_and_infinity_anywhere() {
    // Sky visibility coefficient 4 of tile probe 10.
    let p = sealed(|b| put_f32(b, TILE_PROBES + 10 * 144 + 16, f32::NAN));
    assert_eq!(
        p,
        Problem::NonFinite {
            section: 0,
            what: "sky visibility of probe",
            element: 10
        }
    );
    // Bounced visibility (blue of coefficient 8) of mesh probe 4.
    let p = sealed(|b| put_f32(b, MESH_PROBES + 4 * 144 + 36 + 26 * 4, f32::INFINITY));
    assert_eq!(
        p,
        Problem::NonFinite {
            section: 1,
            what: "bounced sky visibility of probe",
            element: 4
        }
    );
    let p = sealed(|b| put_f32(b, MESH_POSITIONS + 3 * 12 + 8, f32::NEG_INFINITY));
    assert_eq!(
        p,
        Problem::NonFinite {
            section: 1,
            what: "position of probe",
            element: 3
        }
    );
    let p = sealed(|b| put_f32(b, TILE + 16 + 4 * 200, f32::NAN));
    assert_eq!(
        p,
        Problem::NonFinite {
            section: 0,
            what: "ground height of column",
            element: 200
        }
    );
    let p = sealed(|b| put_f32(b, TILE + 8, f32::NAN));
    assert_eq!(
        p,
        Problem::NonFinite {
            section: 0,
            what: "tile origin",
            element: 0
        }
    );
}

#[test]
fn interior_flags_are_0_or_1() {
    let p = sealed(|b| b[TILE_INTERIOR + 5] = 2);
    assert_eq!(
        p,
        Problem::BadInteriorFlag {
            section: 0,
            probe: 5,
            value: 2
        }
    );
    let p = sealed(|b| b[MESH_INTERIOR + 4] = 0xff);
    assert_eq!(
        p,
        Problem::BadInteriorFlag {
            section: 1,
            probe: 4,
            value: 0xff
        }
    );
}

#[test]
fn duplicates_and_order() {
    let mut bake = formula_bake();
    bake.tiles.push(bake.tiles[0].clone());
    assert!(matches!(
        hikari_probes::encode(&bake),
        Err(Problem::DuplicateTile {
            section: 1,
            tile: [2, -1]
        })
    ));
    let mut bake = formula_bake();
    bake.meshes.push(bake.meshes[0].clone());
    assert!(matches!(
        hikari_probes::encode(&bake),
        Err(Problem::DuplicateMesh { section: 2, id: 7 })
    ));
}

#[test]
fn incomplete_bake_is_refused_for_rendering() {
    let mut bytes = fixture();
    put_u32(&mut bytes, 12, 0);
    fix_crc(&mut bytes);
    let dir = std::env::temp_dir().join(format!("hikari-probes-incomplete-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("x.hkprobe");
    std::fs::write(&path, &bytes).unwrap();
    let err = hikari_probes::read_bake(&path, &formula_key()).unwrap_err();
    assert_eq!(
        err.problem,
        Problem::Incomplete {
            tiles: 1,
            meshes: 1
        }
    );
    assert!(
        !hikari_probes::read_any(&path, &formula_key())
            .unwrap()
            .complete
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn the_writer_refuses_what_the_reader_would_refuse() {
    let path = std::env::temp_dir().join(format!(
        "hikari-probes-never-{}.hkprobe",
        std::process::id()
    ));
    let mut bake = formula_bake();
    bake.meshes[0].probes[2].sky_visibility[0] = f32::NAN;
    let err = hikari_probes::write_bake(&path, &bake).unwrap_err();
    assert!(matches!(
        err.problem,
        Problem::NonFinite {
            section: 1,
            element: 2,
            ..
        }
    ));
    assert!(err.to_string().contains("hikari-probes-never"), "{err}");
    assert!(!path.exists());

    let mut bake = formula_bake();
    bake.tiles[0].probes.pop();
    assert!(matches!(
        hikari_probes::encode(&bake),
        Err(Problem::InconsistentCounts { section: 0, .. })
    ));
    let mut bake = formula_bake();
    bake.meshes[0].adjacency.pop();
    assert!(matches!(
        hikari_probes::encode(&bake),
        Err(Problem::InconsistentCounts { section: 1, .. })
    ));
}
