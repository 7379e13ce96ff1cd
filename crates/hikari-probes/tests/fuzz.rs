//! Arbitrary damage to a valid file: every truncation and many byte flips must give an error,
//! never a panic. With the checksum re-sealed, damage reaches the structural checks, which
//! must not panic either (a float flipped to another finite float may still read back).

mod common;
use common::*;
use hikari_probes::decode;

/// The formula bake without its 112 kB tile, so every byte can be visited quickly.
fn small_file() -> Vec<u8> {
    let mut bake = formula_bake();
    bake.tiles.clear();
    hikari_probes::encode(&bake).unwrap()
}

fn positions(len: usize) -> impl Iterator<Item = usize> {
    // Every byte of the header, table, tile edges and mesh; a stride through the tile's middle.
    (0..len).filter(|&i| !(TILE + 64..MESH - 64).contains(&i) || i % 61 == 0)
}

#[test]
fn every_truncation_is_an_error() {
    for bytes in [small_file(), std::fs::read(FIXTURE).unwrap()] {
        let step = if bytes.len() > 10_000 { 97 } else { 1 };
        for len in (0..bytes.len())
            .step_by(step)
            .chain(bytes.len().saturating_sub(300)..bytes.len())
        {
            assert!(
                decode(&bytes[..len], &formula_key()).is_err(),
                "truncated to {len} bytes was accepted"
            );
        }
    }
}

#[test]
fn every_flip_is_an_error() {
    for bytes in [small_file(), std::fs::read(FIXTURE).unwrap()] {
        let all: Vec<usize> = if bytes.len() < 10_000 {
            (0..bytes.len()).collect()
        } else {
            positions(bytes.len()).collect()
        };
        let mut tried = 0;
        for i in all {
            for mask in [0x01u8, 0x80, 0xff] {
                let mut damaged = bytes.clone();
                damaged[i] ^= mask;
                assert!(
                    decode(&damaged, &formula_key()).is_err(),
                    "byte {i} ^ {mask:#04x} was accepted"
                );
                tried += 1;
            }
        }
        assert!(tried > 2500, "only {tried} flips tried");
    }
}

#[test]
fn resealed_damage_never_panics() {
    let bytes = small_file();
    let mut accepted = 0;
    let mut rejected = 0;
    for i in 0..bytes.len() - 4 {
        for value in [0x00u8, 0x01, 0x7f, 0x80, 0xff] {
            let mut damaged = bytes.clone();
            damaged[i] = value;
            fix_crc(&mut damaged);
            match decode(&damaged, &formula_key()) {
                Ok(bake) => {
                    accepted += 1;
                    hikari_probes::validate(&bake).unwrap();
                }
                Err(_) => rejected += 1,
            }
        }
    }
    // Sanity: both outcomes occur (finite float edits pass, header and index edits do not).
    assert!(
        accepted > 0 && rejected > 0,
        "{accepted} accepted, {rejected} rejected"
    );
}
