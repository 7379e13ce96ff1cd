//! Synthetic probe bakes for the GPU tests of the probes and of what reads them (the haze).

use glam::Vec3;
use hikari_math::sh::{Sh, ShL2Rgb};
use hikari_probes::{
    Bake, BakeSettings, GridTile, HULL, ProbeSh, SceneKey, TILE_PROBE_COUNT, TetMesh,
};
use rand::rngs::SmallRng;
use rand::{Rng, SeedableRng};

pub fn random_probe(rng: &mut SmallRng) -> ProbeSh {
    let mut p = ProbeSh::default();
    for k in 0..9 {
        p.sky_visibility[k] = if k == 0 {
            rng.random_range(0.0..3.5)
        } else {
            rng.random_range(-0.8..0.8)
        };
        for c in 0..3 {
            p.bounced_sky_visibility[k][c] = if k == 0 {
                rng.random_range(0.0..1.2)
            } else {
                rng.random_range(-0.3..0.3)
            };
        }
    }
    p
}

pub fn tile(rng: &mut SmallRng, at: [i32; 2], spacing: f32) -> GridTile {
    let size = spacing * 16.0;
    GridTile {
        tile: at,
        origin_xz: [at[0] as f32 * size - 7.0, at[1] as f32 * size + 3.0],
        ground_heights_m: (0..256).map(|_| rng.random_range(0.0..4.0)).collect(),
        probes: (0..TILE_PROBE_COUNT).map(|_| random_probe(rng)).collect(),
        interior: (0..TILE_PROBE_COUNT)
            .map(|_| rng.random_bool(0.3))
            .collect(),
    }
}

/// `n` x `n` x `n` cubes of side `side` from `origin`, each split into the 6 tetrahedra of the
/// Kuhn triangulation (one per ordering of the axes; conforming between cubes), with
/// adjacency found by matching faces.
pub fn kuhn_mesh(rng: &mut SmallRng, origin: Vec3, side: f32, n: usize) -> TetMesh {
    let m = n + 1;
    let index = |x: usize, y: usize, z: usize| ((z * m + y) * m + x) as u32;
    let mut positions = Vec::new();
    for z in 0..m {
        for y in 0..m {
            for x in 0..m {
                positions
                    .push((origin + side * Vec3::new(x as f32, y as f32, z as f32)).to_array());
            }
        }
    }
    let orders = [
        [0, 1, 2],
        [0, 2, 1],
        [1, 0, 2],
        [1, 2, 0],
        [2, 0, 1],
        [2, 1, 0],
    ];
    let mut tets = Vec::new();
    for z in 0..n {
        for y in 0..n {
            for x in 0..n {
                for order in orders {
                    let mut c = [x, y, z];
                    let mut tet = [index(c[0], c[1], c[2]); 4];
                    for (k, axis) in order.iter().enumerate() {
                        c[*axis] += 1;
                        tet[k + 1] = index(c[0], c[1], c[2]);
                    }
                    tets.push(tet);
                }
            }
        }
    }
    let face = |tet: &[u32; 4], k: usize| {
        let mut f: Vec<u32> = (0..4).filter(|&i| i != k).map(|i| tet[i]).collect();
        f.sort_unstable();
        f
    };
    let mut adjacency = vec![[HULL; 4]; tets.len()];
    for (a, neighbours) in adjacency.iter_mut().enumerate() {
        for (ka, neighbour) in neighbours.iter_mut().enumerate() {
            let fa = face(&tets[a], ka);
            for (b, tb) in tets.iter().enumerate() {
                if b != a && (0..4).any(|kb| face(tb, kb) == fa) {
                    *neighbour = b as u32;
                }
            }
        }
    }
    let count = positions.len();
    TetMesh {
        id: 7,
        positions,
        probes: (0..count).map(|_| random_probe(rng)).collect(),
        interior: (0..count).map(|_| rng.random_bool(0.5)).collect(),
        tets,
        adjacency,
    }
}

pub fn synthetic_bake(seed: u64) -> Bake {
    let mut rng = SmallRng::seed_from_u64(seed);
    let settings = BakeSettings::with_rays(64);
    let mut bake = Bake::new(SceneKey::from_u64(seed), settings);
    bake.tiles
        .push(tile(&mut rng, [0, 0], settings.grid_spacing_m));
    bake.tiles
        .push(tile(&mut rng, [1, 0], settings.grid_spacing_m));
    bake.meshes
        .push(kuhn_mesh(&mut rng, Vec3::new(40.0, 2.0, 50.0), 5.0, 2));
    bake.complete = true;
    bake
}

/// A sky with strong linear and quadratic terms (a bright side and a darker ground), nits.
pub fn synthetic_sky(rng: &mut SmallRng) -> ShL2Rgb {
    let base = Vec3::new(6000.0, 7000.0, 9000.0);
    Sh::new(std::array::from_fn(|k| {
        let s = match k {
            0 => 1.0,
            1..=3 => rng.random_range(-0.6..0.6),
            _ => rng.random_range(-0.3..0.3),
        };
        base * s * Vec3::new(rng.random_range(0.9..1.1), 1.0, rng.random_range(0.9..1.1))
    }))
}
