//! Write, read back, compare; atomic writes; resuming from checkpoints.

mod common;
use common::*;
use hikari_probes::{Bake, BakeSettings, GridTile, ProbeSh, Problem, SceneKey, TetMesh};

/// Deterministic varied floats (xorshift), including negatives, tiny and large magnitudes.
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }
    fn f32(&mut self) -> f32 {
        let mantissa = (self.next() % 2_000_001) as f32 / 1_000_000.0 - 1.0;
        mantissa * 10f32.powi((self.next() % 12) as i32 - 6)
    }
    fn probe(&mut self) -> ProbeSh {
        ProbeSh {
            sky_visibility: std::array::from_fn(|_| self.f32()),
            bounced_sky_visibility: std::array::from_fn(|_| std::array::from_fn(|_| self.f32())),
        }
    }
}

fn random_bake(seed: u64, tiles: usize) -> Bake {
    let mut rng = Rng(seed);
    let mut bake = Bake::new(SceneKey::from_u64(seed), BakeSettings::with_rays(1024));
    for t in 0..tiles {
        bake.tiles.push(GridTile {
            tile: [t as i32 - 1, -(t as i32)],
            origin_xz: [rng.f32(), rng.f32()],
            ground_heights_m: (0..hikari_probes::TILE_COLUMNS)
                .map(|_| rng.f32())
                .collect(),
            probes: (0..hikari_probes::TILE_PROBE_COUNT)
                .map(|_| rng.probe())
                .collect(),
            interior: (0..hikari_probes::TILE_PROBE_COUNT)
                .map(|_| rng.next().is_multiple_of(2))
                .collect(),
        });
    }
    bake.meshes.push(formula_bake().meshes[0].clone());
    bake.meshes.push(TetMesh {
        id: 9,
        positions: vec![],
        probes: vec![],
        interior: vec![],
        tets: vec![],
        adjacency: vec![],
    });
    bake.complete = true;
    bake
}

#[test]
fn round_trip_through_a_file_is_exact() {
    let dir = tempdir();
    let path = dir.join("scene.hkprobe");
    let bake = random_bake(0x9e37_79b9_7f4a_7c15, 3);
    hikari_probes::write_bake(&path, &bake).unwrap();
    let back = hikari_probes::read_bake(&path, &bake.scene).unwrap();
    assert_eq!(back, bake);
    // Bit-exact, including signed zeros, which PartialEq would not tell apart.
    let bits = |b: &Bake| -> Vec<u32> {
        b.tiles
            .iter()
            .flat_map(|t| t.probes.iter())
            .flat_map(|p| p.sky_visibility)
            .map(f32::to_bits)
            .collect()
    };
    assert_eq!(bits(&back), bits(&bake));
    // The temporary file was renamed, not left behind.
    let names: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(names, vec![std::ffi::OsString::from("scene.hkprobe")]);
}

#[test]
fn rewriting_replaces_the_old_file_and_failures_name_it() {
    let dir = tempdir();
    let path = dir.join("scene.hkprobe");
    let first = random_bake(11, 1);
    let second = random_bake(12, 2);
    hikari_probes::write_bake(&path, &first).unwrap();
    hikari_probes::write_bake(&path, &second).unwrap();
    assert_eq!(
        hikari_probes::read_bake(&path, &second.scene).unwrap(),
        second
    );

    let nowhere = dir.join("no-such-dir").join("scene.hkprobe");
    let err = hikari_probes::write_bake(&nowhere, &first).unwrap_err();
    assert!(matches!(err.problem, Problem::Io(_)));
    assert!(err.to_string().contains("no-such-dir"), "{err}");
}

#[test]
fn an_empty_bake_round_trips() {
    let bake = Bake::new(SceneKey::from_u64(1), BakeSettings::with_rays(1));
    let bytes = hikari_probes::encode(&bake).unwrap();
    assert_eq!(bytes.len(), 80 + 4);
    assert_eq!(hikari_probes::decode(&bytes, &bake.scene).unwrap(), bake);
}

#[test]
fn resume_continues_from_the_checkpoint_and_finish_removes_it() {
    let dir = tempdir();
    let path = dir.join("village.hkprobe");
    let full = random_bake(7, 3);
    let (scene, settings) = (full.scene, full.settings);

    let start = hikari_probes::resume(&path, scene, settings);
    assert!(start.discarded.is_none());
    assert!(start.bake.tiles.is_empty() && !start.bake.complete);

    // Interrupted after two tiles.
    let mut partial = start.bake;
    partial.tiles.extend(full.tiles[..2].iter().cloned());
    hikari_probes::save_checkpoint(&path, &partial).unwrap();
    assert!(hikari_probes::partial_path(&path).exists());
    let err = hikari_probes::read_bake(&hikari_probes::partial_path(&path), &scene).unwrap_err();
    assert_eq!(
        err.problem,
        Problem::Incomplete {
            tiles: 2,
            meshes: 0
        }
    );

    let resumed = hikari_probes::resume(&path, scene, settings);
    assert!(resumed.discarded.is_none());
    let mut bake = resumed.bake;
    assert!(bake.has_tile(full.tiles[1].tile) && !bake.has_tile(full.tiles[2].tile));
    for tile in &full.tiles {
        if !bake.has_tile(tile.tile) {
            bake.tiles.push(tile.clone());
        }
    }
    bake.meshes = full.meshes.clone();
    hikari_probes::finish(&path, bake).unwrap();
    assert!(!hikari_probes::partial_path(&path).exists());
    assert_eq!(hikari_probes::read_bake(&path, &scene).unwrap(), full);
}

#[test]
fn resume_drops_checkpoints_of_other_settings_scenes_or_corrupt_ones_and_says_why() {
    let dir = tempdir();
    let path = dir.join("v.hkprobe");
    let bake = random_bake(3, 1);
    hikari_probes::save_checkpoint(&path, &bake).unwrap();

    let other = BakeSettings::with_rays(64);
    let r = hikari_probes::resume(&path, bake.scene, other);
    assert!(r.bake.tiles.is_empty());
    assert!(matches!(
        r.discarded.unwrap().problem,
        Problem::OtherSettings(_)
    ));

    let r = hikari_probes::resume(&path, SceneKey::from_u64(4), bake.settings);
    assert!(r.bake.tiles.is_empty());
    assert!(matches!(
        r.discarded.unwrap().problem,
        Problem::OtherScene { .. }
    ));

    let partial = hikari_probes::partial_path(&path);
    let mut bytes = std::fs::read(&partial).unwrap();
    bytes[TABLE + 30] ^= 0x40;
    std::fs::write(&partial, &bytes).unwrap();
    let r = hikari_probes::resume(&path, bake.scene, bake.settings);
    assert!(r.bake.tiles.is_empty());
    assert!(matches!(
        r.discarded.unwrap().problem,
        Problem::ChecksumMismatch { .. }
    ));
}

fn tempdir() -> std::path::PathBuf {
    use std::sync::atomic::{AtomicU32, Ordering};
    static N: AtomicU32 = AtomicU32::new(0);
    let dir = std::env::temp_dir().join(format!(
        "hikari-probes-test-{}-{}",
        std::process::id(),
        N.fetch_add(1, Ordering::Relaxed)
    ));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}
