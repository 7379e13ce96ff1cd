//! The ground: a seeded height field of gentle hills around a flat valley floor where the
//! village sits, a flat terrace for the temple courtyard and a bowl for the pond, meshed on a
//! 1 m grid with vertex colours for grass, street, gravel and mud.

use glam::{Vec2, Vec3, Vec4};

use super::rng::{Rng, lattice};
use crate::Mesh;

/// Half the side of the terrain: it spans [-HALF_SIZE, HALF_SIZE] in x and z, metres.
pub const HALF_SIZE: f32 = 200.0;
/// Grid cells per side (1 m cells).
pub const CELLS: usize = 400;

/// Where the flat parts are; the generator places the village on it.
#[derive(Clone, Debug)]
pub struct Sites {
    /// The street runs along x at z = 0, from `street_x.0` to `street_x.1`.
    pub street_x: (f32, f32),
    pub street_half_width: f32,
    /// The path from the street's east end north to the courtyard: from `path.0` to `path.1`
    /// (xz).
    pub path: (Vec2, Vec2),
    pub path_half_width: f32,
    pub courtyard_centre: Vec2,
    pub courtyard_radius: f32,
    pub courtyard_y: f32,
    pub pond_centre: Vec2,
    pub pond_water_y: f32,
    /// Radius of the bowl the pond fills; the shore is where it reaches the water level.
    pub pond_bowl_radius: f32,
    pub pond_depth: f32,
}

impl Sites {
    pub fn fixed() -> Sites {
        Sites {
            street_x: (-66.0, 40.0),
            street_half_width: 3.0,
            path: (Vec2::new(40.0, 0.0), Vec2::new(40.0, 28.0)),
            path_half_width: 2.0,
            courtyard_centre: Vec2::new(40.0, 50.0),
            courtyard_radius: 24.0,
            courtyard_y: 1.2,
            pond_centre: Vec2::new(-22.0, -40.0),
            pond_water_y: -0.3,
            pond_bowl_radius: 16.0,
            pond_depth: 2.4,
        }
    }

    /// Radius at which the pond's bowl reaches the water level: the shore.
    pub fn pond_shore_radius(&self) -> f32 {
        // depth (1 - (d/R)²)² = -water_y, solved for d.
        let k = (-self.pond_water_y / self.pond_depth).sqrt();
        self.pond_bowl_radius * (1.0 - k).sqrt()
    }

    /// Normalised distance from the middle of the valley floor: below 0.85 the ground is the
    /// flat floor, above 1.15 the hills.
    pub fn plain_distance(&self, p: Vec2) -> f32 {
        (((p.x + 5.0) / 80.0).powi(2) + ((p.y - 12.0) / 62.0).powi(2)).sqrt()
    }

    pub fn distance_to_street(&self, p: Vec2) -> f32 {
        segment_distance(
            p,
            Vec2::new(self.street_x.0, 0.0),
            Vec2::new(self.street_x.1, 0.0),
        )
    }

    pub fn distance_to_path(&self, p: Vec2) -> f32 {
        segment_distance(p, self.path.0, self.path.1)
    }
}

fn segment_distance(p: Vec2, a: Vec2, b: Vec2) -> f32 {
    let ab = b - a;
    let t = ((p - a).dot(ab) / ab.length_squared()).clamp(0.0, 1.0);
    p.distance(a + ab * t)
}

fn smoothstep(e0: f32, e1: f32, x: f32) -> f32 {
    let t = ((x - e0) / (e1 - e0)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// Exactly `b` at t = 1 (and `a` at t = 0), so blended regions are exactly level.
fn lerp(a: f32, b: f32, t: f32) -> f32 {
    a * (1.0 - t) + b * t
}

/// Value noise in [-1, 1] with a quintic fade (C2 between lattice points).
fn value_noise(seed: u64, p: Vec2) -> f32 {
    let (i, j) = (p.x.floor(), p.y.floor());
    let (fx, fz) = (p.x - i, p.y - j);
    let fade = |t: f32| t * t * t * (t * (t * 6.0 - 15.0) + 10.0);
    let (u, v) = (fade(fx), fade(fz));
    let (i, j) = (i as i32, j as i32);
    let a = lerp(lattice(seed, i, j), lattice(seed, i + 1, j), u);
    let b = lerp(lattice(seed, i, j + 1), lattice(seed, i + 1, j + 1), u);
    lerp(a, b, v)
}

/// Sum of `octaves` of value noise, each twice the frequency and half the amplitude of the
/// last, normalised back to about [-1, 1].
fn fbm(seed: u64, p: Vec2, octaves: u32) -> f32 {
    let (mut sum, mut amp, mut norm, mut q) = (0.0, 1.0, 0.0, p);
    for o in 0..octaves {
        sum += amp * value_noise(seed.wrapping_add(o as u64 * 0x1234_5678_9abc), q);
        norm += amp;
        amp *= 0.5;
        // Rotate between octaves so the lattices do not line up.
        q = Vec2::new(1.6 * q.x - 1.2 * q.y, 1.2 * q.x + 1.6 * q.y) + Vec2::splat(17.3);
    }
    sum / norm
}

/// The ground of one village: its height function and its grid.
pub struct Terrain {
    pub sites: Sites,
    hills_seed: u64,
    plain_seed: u64,
    /// Heights at the grid vertices, row-major: `heights[j * (CELLS + 1) + i]` at
    /// x = -HALF_SIZE + i, z = -HALF_SIZE + j.
    heights: Vec<f32>,
}

impl Terrain {
    pub fn new(seed: u64, sites: Sites) -> Terrain {
        let mut rng = Rng::stream(seed, "terrain");
        let mut t = Terrain {
            sites,
            hills_seed: rng.next_u64(),
            plain_seed: rng.next_u64(),
            heights: Vec::new(),
        };
        let n = CELLS + 1;
        t.heights = (0..n * n)
            .map(|k| {
                let (x, z) = grid_xz(k % n, k / n);
                t.height(x, z)
            })
            .collect();
        t
    }

    /// The designed height at (x, z), metres; the mesh interpolates it linearly between grid
    /// vertices ([`Terrain::surface_height`]).
    pub fn height(&self, x: f32, z: f32) -> f32 {
        let s = &self.sites;
        let p = Vec2::new(x, z);
        let r = p.length();
        // Gentle hills (±14 m over ~170 m), rising towards the edge as a valley's sides.
        let hills = 14.0 * fbm(self.hills_seed, p / 170.0, 5) + 18.0 * smoothstep(110.0, 200.0, r);
        // The valley floor: ±0.25 m undulation.
        let plain = 0.25 * fbm(self.plain_seed, p / 40.0, 3);
        // An ellipse around the village, street and pond where the floor is flat.
        let e = s.plain_distance(p);
        let mut h = lerp(hills, plain, 1.0 - smoothstep(0.85, 1.15, e));
        // A level terrace for the courtyard (cut into the hillside where it rises).
        let dc = p.distance(s.courtyard_centre);
        h = lerp(
            h,
            s.courtyard_y,
            1.0 - smoothstep(s.courtyard_radius + 2.0, s.courtyard_radius + 12.0, dc),
        );
        // The pond: level ground around it, then a bowl.
        let dp = p.distance(s.pond_centre);
        h = lerp(
            h,
            0.0,
            1.0 - smoothstep(s.pond_bowl_radius + 2.0, s.pond_bowl_radius + 10.0, dp),
        );
        if dp < s.pond_bowl_radius {
            h -= s.pond_depth * (1.0 - (dp / s.pond_bowl_radius).powi(2)).powi(2);
        }
        h
    }

    fn grid(&self, i: usize, j: usize) -> f32 {
        self.heights[j * (CELLS + 1) + i]
    }

    /// Height of the meshed surface at (x, z): the grid triangles' linear interpolation
    /// (clamped to the grid's edge outside it).
    pub fn surface_height(&self, x: f32, z: f32) -> f32 {
        let max = CELLS as f32 - 1e-3;
        let gx = (x + HALF_SIZE).clamp(0.0, max);
        let gz = (z + HALF_SIZE).clamp(0.0, max);
        let (i, j) = (gx.floor() as usize, gz.floor() as usize);
        let (fx, fz) = (gx - i as f32, gz - j as f32);
        let (h00, h10, h01, h11) = (
            self.grid(i, j),
            self.grid(i + 1, j),
            self.grid(i, j + 1),
            self.grid(i + 1, j + 1),
        );
        // The cell's diagonal runs from (i, j) to (i + 1, j + 1), as in `mesh`.
        if fz >= fx {
            h00 + fx * (h11 - h01) + fz * (h01 - h00)
        } else {
            h00 + fx * (h10 - h00) + fz * (h11 - h10)
        }
    }

    /// The highest point of the meshed surface over a disc (sampled), for standing things on
    /// slightly uneven ground.
    pub fn max_over(&self, centre: Vec2, radius: f32) -> f32 {
        let mut h = self.surface_height(centre.x, centre.y);
        for k in 0..16 {
            for r in [0.5 * radius, radius] {
                let a = std::f32::consts::TAU * k as f32 / 16.0;
                let p = centre + r * Vec2::new(a.cos(), a.sin());
                h = h.max(self.surface_height(p.x, p.y));
            }
        }
        h
    }

    /// The lowest point of the meshed surface over a disc (sampled).
    pub fn min_over(&self, centre: Vec2, radius: f32) -> f32 {
        let mut h = self.surface_height(centre.x, centre.y);
        for k in 0..16 {
            for r in [0.5 * radius, radius] {
                let a = std::f32::consts::TAU * k as f32 / 16.0;
                let p = centre + r * Vec2::new(a.cos(), a.sin());
                h = h.min(self.surface_height(p.x, p.y));
            }
        }
        h
    }

    /// Albedo of the grass, the terrain material's base colour; vertex colours scale it.
    pub const GRASS: Vec3 = Vec3::new(0.13, 0.20, 0.06);

    /// Ground colour at (x, z) with height `h` as a factor on [`Terrain::GRASS`] (above 1 for
    /// the lighter earth and gravel), so that a renderer ignoring vertex colours still shows
    /// green ground.
    fn colour(&self, x: f32, z: f32, h: f32, rng_value: f32) -> Vec4 {
        let s = &self.sites;
        let p = Vec2::new(x, z);
        let grass = Self::GRASS * (0.85 + 0.3 * rng_value);
        let dry = Vec3::new(0.30, 0.26, 0.12);
        let earth = Vec3::new(0.32, 0.25, 0.17);
        let gravel = Vec3::new(0.52, 0.50, 0.45);
        let mud = Vec3::new(0.10, 0.08, 0.06);
        // Autumn: grass turning straw-coloured on the higher ground.
        let mut c = grass.lerp(dry, smoothstep(4.0, 20.0, h) * 0.6);
        let road = 1.0
            - smoothstep(
                s.street_half_width - 0.3,
                s.street_half_width + 0.3,
                s.distance_to_street(p),
            )
            .min(smoothstep(
                s.path_half_width - 0.3,
                s.path_half_width + 0.3,
                s.distance_to_path(p),
            ));
        c = c.lerp(earth, road);
        let court = 1.0
            - smoothstep(
                s.courtyard_radius - 0.5,
                s.courtyard_radius + 0.5,
                p.distance(s.courtyard_centre),
            );
        c = c.lerp(gravel, court);
        let wet = 1.0 - smoothstep(s.pond_water_y + 0.05, s.pond_water_y + 0.3, h);
        c = c.lerp(mud, wet);
        // Vertex colours are the ground's albedo itself (within [0, 1], as glTF's COLOR_0);
        // the terrain material's base colour is white.
        c.clamp(Vec3::ZERO, Vec3::ONE).extend(1.0)
    }

    /// The terrain mesh: (CELLS + 1)² vertices on a 1 m grid, two triangles per cell
    /// (counter-clockwise from above, diagonal from (i, j) to (i + 1, j + 1)), normals from
    /// central differences of the grid heights, UVs in metres, vertex colours.
    pub fn mesh(&self, seed: u64) -> Mesh {
        let n = CELLS + 1;
        let mut rng = Rng::stream(seed, "terrain colour");
        let mut m = Mesh {
            name: "terrain".into(),
            ..Default::default()
        };
        let mut colors = Vec::with_capacity(n * n);
        for j in 0..n {
            for i in 0..n {
                let (x, z) = grid_xz(i, j);
                let h = self.grid(i, j);
                let (il, ir) = (i.saturating_sub(1), (i + 1).min(n - 1));
                let (jl, jr) = (j.saturating_sub(1), (j + 1).min(n - 1));
                let dx = (self.grid(ir, j) - self.grid(il, j)) / (ir - il) as f32;
                let dz = (self.grid(i, jr) - self.grid(i, jl)) / (jr - jl) as f32;
                m.positions.push(Vec3::new(x, h, z));
                let normal = Vec3::new(-dx, 1.0, -dz).normalize();
                m.normals.push(normal);
                m.uvs.push(Vec2::new(x, z));
                // u along +x: dp/du = (1, dx, 0); v along +z is -cross(n, +x)-ward: w = -1.
                m.tangents
                    .push(Vec3::new(1.0, dx, 0.0).normalize().extend(-1.0));
                colors.push(self.colour(x, z, h, rng.unit()));
            }
        }
        m.colors = Some(colors);
        m.indices.reserve(6 * CELLS * CELLS);
        for j in 0..CELLS {
            for i in 0..CELLS {
                let v00 = (j * n + i) as u32;
                let (v10, v01, v11) = (v00 + 1, v00 + n as u32, v00 + n as u32 + 1);
                m.indices.extend([v00, v01, v11, v00, v11, v10]);
            }
        }
        m
    }
}

fn grid_xz(i: usize, j: usize) -> (f32, f32) {
    (-HALF_SIZE + i as f32, -HALF_SIZE + j as f32)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn surface_height_interpolates_the_mesh_triangles() {
        let t = Terrain::new(3, Sites::fixed());
        let m = t.mesh(3);
        let n = CELLS + 1;
        // At vertices it is the vertex height; inside a triangle, the plane through its
        // corners (computed here by barycentric coordinates from the mesh itself).
        for (k, (x, z)) in [(10.25, -3.5), (-150.7, 99.1), (0.9, 0.1), (37.0, 12.0)]
            .into_iter()
            .enumerate()
        {
            let (i, j) = (
                (x + HALF_SIZE).floor() as usize,
                (z + HALF_SIZE).floor() as usize,
            );
            let v00 = j * n + i;
            let tris = [[v00, v00 + n, v00 + n + 1], [v00, v00 + n + 1, v00 + 1]];
            let p = Vec2::new(x, z);
            let mut found = None;
            for tri in tris {
                let [a, b, c] = tri.map(|v| m.positions[v]);
                let (a2, b2, c2) = (a.truncate_xz(), b.truncate_xz(), c.truncate_xz());
                let d = (b2 - a2).perp_dot(c2 - a2);
                let wb = (p - a2).perp_dot(c2 - a2) / d;
                let wc = (b2 - a2).perp_dot(p - a2) / d;
                let wa = 1.0 - wb - wc;
                if wa >= -1e-6 && wb >= -1e-6 && wc >= -1e-6 {
                    found = Some(wa * a.y + wb * b.y + wc * c.y);
                }
            }
            let want = found.unwrap();
            assert!((t.surface_height(x, z) - want).abs() < 1e-4, "sample {k}");
        }
    }

    trait Xz {
        fn truncate_xz(self) -> Vec2;
    }
    impl Xz for Vec3 {
        fn truncate_xz(self) -> Vec2 {
            Vec2::new(self.x, self.z)
        }
    }

    #[test]
    fn village_ground_is_flat_and_the_pond_is_a_bowl_below_the_water() {
        for seed in [1, 2, 99] {
            let t = Terrain::new(seed, Sites::fixed());
            let s = &t.sites;
            for x in (-60..35).step_by(5) {
                for z in [-10.0, 0.0, 10.0] {
                    assert!(
                        t.height(x as f32, z).abs() <= 0.3,
                        "seed {seed} at {x}, {z}"
                    );
                }
            }
            let c = s.courtyard_centre;
            assert_eq!(t.height(c.x + 10.0, c.y - 5.0), s.courtyard_y);
            let p = s.pond_centre;
            assert!(t.height(p.x, p.y) < s.pond_water_y - 2.0);
            let shore = s.pond_shore_radius();
            assert!((t.height(p.x + shore, p.y) - s.pond_water_y).abs() < 1e-4);
            assert!(t.height(p.x + shore + 1.0, p.y) > s.pond_water_y);
        }
    }
}
