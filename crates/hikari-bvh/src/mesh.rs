//! Indexed triangle meshes as the builder takes them, and two procedural ones used by tests,
//! examples and benchmarks.

use crate::rng::SplitMix64;
use glam::Vec3;

#[derive(Clone, Debug, Default, PartialEq)]
pub struct Mesh {
    pub positions: Vec<Vec3>,
    pub indices: Vec<[u32; 3]>,
}

impl Mesh {
    pub fn new(positions: Vec<Vec3>, indices: Vec<[u32; 3]>) -> Self {
        Self { positions, indices }
    }

    /// The issue-5 terrain: an `n x n` vertex grid over x, z in [-100, 100] with
    /// `y = 5 sin(0.1 x) cos(0.13 z) + 2 sin(0.7 x + 0.3 z)`, two triangles per cell.
    /// `n = 708` gives 1,000,000 triangles (roughly).
    pub fn terrain(n: usize) -> Mesh {
        let n = n.max(2);
        let mut positions = Vec::with_capacity(n * n);
        for j in 0..n {
            let z = -100.0 + 200.0 * j as f32 / (n - 1) as f32;
            for i in 0..n {
                let x = -100.0 + 200.0 * i as f32 / (n - 1) as f32;
                positions.push(Vec3::new(x, terrain_height(x, z), z));
            }
        }
        let mut indices = Vec::with_capacity(2 * (n - 1) * (n - 1));
        for j in 0..n - 1 {
            for i in 0..n - 1 {
                let a = (j * n + i) as u32;
                let b = a + 1;
                let c = a + n as u32;
                let d = c + 1;
                indices.push([a, c, b]);
                indices.push([b, c, d]);
            }
        }
        Mesh { positions, indices }
    }

    /// `count` random triangles in the cube `[-extent, extent]^3`, each with edges up to
    /// `size` long: overlapping, intersecting, every orientation.
    pub fn random_soup(seed: u64, count: usize, extent: f32, size: f32) -> Mesh {
        let mut rng = SplitMix64::new(seed);
        let mut positions = Vec::with_capacity(count * 3);
        let mut indices = Vec::with_capacity(count);
        for t in 0..count {
            let c = Vec3::new(
                rng.range(-extent, extent),
                rng.range(-extent, extent),
                rng.range(-extent, extent),
            );
            for _ in 0..3 {
                positions.push(
                    c + Vec3::new(
                        rng.range(-size, size),
                        rng.range(-size, size),
                        rng.range(-size, size),
                    ) * 0.5,
                );
            }
            let b = 3 * t as u32;
            indices.push([b, b + 1, b + 2]);
        }
        Mesh { positions, indices }
    }
}

pub fn terrain_height(x: f32, z: f32) -> f32 {
    5.0 * (0.1 * x).sin() * (0.13 * z).cos() + 2.0 * (0.7 * x + 0.3 * z).sin()
}
