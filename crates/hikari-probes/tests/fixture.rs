//! The reader and writer against a file written by tools/probe_bake_fixture.py from the format
//! table alone (Python struct and zlib.crc32).

mod common;
use common::*;

#[test]
fn reads_the_python_written_file() {
    let bake = hikari_probes::read_bake(FIXTURE.as_ref(), &formula_key()).unwrap();
    assert_eq!(bake, formula_bake());
}

#[test]
fn writes_the_same_bytes_as_python() {
    let ours = hikari_probes::encode(&formula_bake()).unwrap();
    let python = std::fs::read(FIXTURE).unwrap();
    assert_eq!(ours.len(), python.len());
    let first_difference = ours.iter().zip(&python).position(|(a, b)| a != b);
    assert_eq!(first_difference, None);
}

#[test]
fn tile_positions_follow_the_documented_layout() {
    let bake = formula_bake();
    let tile = &bake.tiles[0];
    // Probe (3, 5) of layer 2: x0 + 3 * 12.5, ground[5 * 16 + 3] + 30, z0 + 5 * 12.5.
    let p = tile.probe_position(&bake.settings, 3, 5, 2).unwrap();
    assert_eq!(p, [437.5, 0.25 * 83.0 - 3.0 + 30.0, -137.5]);
    assert_eq!(
        hikari_probes::GridTile::probe_index(3, 5, 2),
        (2 * 16 + 5) * 16 + 3
    );
    assert_eq!(tile.probe_position(&bake.settings, 16, 0, 0), None);
}
