//! The bake that tools/probe_bake_fixture.py writes, rebuilt from the same formulas, and
//! helpers to edit encoded bytes.
#![allow(dead_code)]

use hikari_probes::{
    Bake, BakeSettings, GridTile, HULL, ProbeSh, SceneKey, TILE_COLUMNS, TILE_PROBE_COUNT, TetMesh,
};

pub const FIXTURE: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/tests/fixtures/formula_bake.hkprobe"
);

pub fn formula_key() -> SceneKey {
    SceneKey(std::array::from_fn(|i| i as u8))
}

/// Python computes in f64 and packs to f32 with round-to-nearest, as `as f32` does.
fn probe_sh(p: usize) -> ProbeSh {
    let p = p as f64;
    ProbeSh {
        sky_visibility: std::array::from_fn(|k| (0.001 * p + 0.5 * k as f64) as f32),
        bounced_sky_visibility: std::array::from_fn(|k| {
            std::array::from_fn(|ch| (-0.002 * p + 0.25 * k as f64 + 0.125 * ch as f64) as f32)
        }),
    }
}

pub fn formula_bake() -> Bake {
    let tile = GridTile {
        tile: [2, -1],
        origin_xz: [400.0, -200.0],
        ground_heights_m: (0..TILE_COLUMNS)
            .map(|c| (0.25 * c as f64 - 3.0) as f32)
            .collect(),
        probes: (0..TILE_PROBE_COUNT).map(probe_sh).collect(),
        interior: (0..TILE_PROBE_COUNT).map(|p| p % 3 == 0).collect(),
    };
    let mesh = TetMesh {
        id: 7,
        positions: vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
            [1.0, 1.0, 1.0],
        ],
        probes: (0..5).map(|i| probe_sh(1000 + i)).collect(),
        interior: (0..5).map(|i| i % 3 == 0).collect(),
        tets: vec![[0, 1, 2, 3], [1, 2, 3, 4]],
        adjacency: vec![[1, HULL, HULL, HULL], [HULL, HULL, HULL, 0]],
    };
    Bake {
        scene: formula_key(),
        settings: BakeSettings::with_rays(256),
        complete: true,
        tiles: vec![tile],
        meshes: vec![mesh],
    }
}

/// Byte offsets of the formula bake's parts, from the crate docs' table.
pub const TABLE: usize = 80;
pub const TILE: usize = TABLE + 2 * 24;
pub const TILE_PROBES: usize = TILE + 1040;
pub const TILE_INTERIOR: usize = TILE + 111_632;
pub const MESH: usize = TILE + 112_400;
pub const MESH_N: usize = 5;
pub const MESH_T: usize = 2;
pub const MESH_POSITIONS: usize = MESH + 8;
pub const MESH_PROBES: usize = MESH + 8 + 12 * MESH_N;
pub const MESH_TETS: usize = MESH + 8 + 156 * MESH_N;
pub const MESH_ADJACENCY: usize = MESH_TETS + 16 * MESH_T;
pub const MESH_INTERIOR: usize = MESH_ADJACENCY + 16 * MESH_T;

/// Rewrites the CRC-32 trailer so that edits reach the checks behind the checksum.
pub fn fix_crc(bytes: &mut [u8]) {
    let n = bytes.len() - 4;
    let crc = crc32fast::hash(&bytes[..n]);
    bytes[n..].copy_from_slice(&crc.to_le_bytes());
}

pub fn put_u32(bytes: &mut [u8], at: usize, v: u32) {
    bytes[at..at + 4].copy_from_slice(&v.to_le_bytes());
}

pub fn put_f32(bytes: &mut [u8], at: usize, v: f32) {
    bytes[at..at + 4].copy_from_slice(&v.to_le_bytes());
}
