//! A uniform world-space grid of light lists for lighting the GI rays' hits: each cell lists
//! the area lights and, apart, the point and spot lights whose reach can touch the cell, so a
//! hit visits only those instead of every light in the scene (the village at night has
//! hundreds of lanterns and lit windows).
//!
//! A light's reach is the distance beyond which the shade pass gives it no light: for an area
//! light `r + sqrt(luminance(radiance) · area / cutoff)` about its centroid (and none below
//! the minimum flux unless forced), for a point or spot light `light_range` (its range, or
//! where it falls to the cut-off). A light not in a cell cannot reach any point of it, so the
//! shade pass's running choice, visiting a cell's lights in ascending index order, picks
//! exactly as a loop over all lights would.
//!
//! The grid is built for a cut-off rounded down to a power of two ([`grid_cutoff`]): a lower
//! cut-off only lengthens the reaches, so the lists stay complete while the metered exposure
//! (and with it the frame's cut-off) drifts, and the grid is rebuilt only when it crosses a
//! power of two. Reaches and cells are inflated a little ([`INFLATE`]) so that f32 rounding on
//! the GPU, at a reach's boundary or a cell's face, can never leave a reaching light out.
//!
//! GPU layout (`ray_traced_gi/shade.wgsl`): `cells: array<vec4<u32>>` = record 0: the grid's
//! origin (xyz, metres, f32 bits) and cell size (w, metres, f32 bits); record 1: cells along
//! x, y, z; then one record a cell, x-fastest: first index, area-light count, punctual count,
//! 0. `indices: array<u32>`: per cell its area lights then its punctual lights.

use glam::{DVec3, Vec3};

use super::polygon::{AREA_LIGHT_FORCED, AreaLightGpu};
use crate::scene::upload::LightGpu;

/// Most cells along an axis.
pub const MAX_CELLS_PER_AXIS: u32 = 64;
/// Relative growth of every reach and cell box in the overlap test (f32 rounding margin).
pub const INFLATE: f64 = 1e-3;
/// Records before the first cell in the cells buffer.
pub const HEADER_RECORDS: usize = 2;

/// The cut-off (lux) the grid is built for: the frame's rounded down to a power of two.
pub fn grid_cutoff(cutoff_lux: f32) -> f32 {
    if cutoff_lux.is_nan() || cutoff_lux <= 0.0 || cutoff_lux.is_infinite() {
        return cutoff_lux;
    }
    2f32.powi(cutoff_lux.log2().floor() as i32)
        .min(cutoff_lux)
        .max(f32::MIN_POSITIVE)
}

fn luminance(c: Vec3) -> f32 {
    hikari_math::color::luminance(c)
}

/// Reach (m) of area light `l` about its centroid at `cutoff_lux`, as the shade pass computes
/// it (f32); `None` for a light the pass skips (below `min_flux_lm`, not forced).
pub fn area_reach(l: &AreaLightGpu, min_flux_lm: f32, cutoff_lux: f32) -> Option<f32> {
    let forced = l.range[2] & AREA_LIGHT_FORCED != 0;
    if l.radiance_flux[3] < min_flux_lm && !forced {
        return None;
    }
    let radiance = Vec3::from_slice(&l.radiance_flux[..3]);
    let peak = (luminance(radiance) * l.normal_area[3]).max(0.0);
    Some(l.centroid_radius[3] + (peak / cutoff_lux).sqrt())
}

/// Reach (m) of a point or spot light at `cutoff_lux`: `light_range` of `hikari::scene_gpu`.
pub fn punctual_reach(l: &LightGpu, cutoff_lux: f32) -> f32 {
    let peak = Vec3::from_slice(&l.intensity[..3]).max_element();
    l.position_range[3]
        .min((peak / cutoff_lux).sqrt())
        .max(1e-3)
}

/// A light's sphere of influence, inflated.
#[derive(Clone, Copy, Debug)]
struct Sphere {
    c: DVec3,
    r: f64,
}

/// The grid's cache key: what it was built from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightGridKey {
    /// [`grid_cutoff`] bits.
    pub cutoff_bits: u32,
    pub min_flux_bits: u32,
    /// A hash of the area and punctual light tables.
    pub lights_hash: u64,
}

impl LightGridKey {
    pub fn new(
        area: &[AreaLightGpu],
        punctual: &[LightGpu],
        min_flux_lm: f32,
        cutoff_lux: f32,
    ) -> Self {
        // FNV-1a over the tables' words: cheap next to a frame, and any change rebuilds.
        let mut h = 0xcbf2_9ce4_8422_2325u64;
        let mut eat = |words: &[u32]| {
            for &w in words {
                h = (h ^ w as u64).wrapping_mul(0x100_0000_01b3);
            }
        };
        eat(&[area.len() as u32]);
        eat(bytemuck::cast_slice(area));
        eat(&[punctual.len() as u32]);
        eat(bytemuck::cast_slice(punctual));
        Self {
            cutoff_bits: grid_cutoff(cutoff_lux).to_bits(),
            min_flux_bits: min_flux_lm.to_bits(),
            lights_hash: h,
        }
    }
}

/// The grid on the CPU, as uploaded.
#[derive(Clone, Debug, PartialEq)]
pub struct LightGrid {
    /// Header records, then one a cell (module docs).
    pub cells: Vec<[u32; 4]>,
    /// Light indices, per cell its area lights then its punctual lights, ascending.
    pub indices: Vec<u32>,
}

impl LightGrid {
    /// The grid of `area` (lights of at least `min_flux_lm` or forced) and `punctual` lights
    /// at a cut-off of `cutoff_lux` (use [`grid_cutoff`] of the frame's).
    pub fn build(
        area: &[AreaLightGpu],
        punctual: &[LightGpu],
        min_flux_lm: f32,
        cutoff_lux: f32,
    ) -> Self {
        let grow = |r: f32| r as f64 * (1.0 + INFLATE) + 1e-4;
        let area_spheres: Vec<Option<Sphere>> = area
            .iter()
            .map(|l| {
                area_reach(l, min_flux_lm, cutoff_lux).map(|r| Sphere {
                    c: Vec3::from_slice(&l.centroid_radius[..3]).as_dvec3(),
                    r: grow(r),
                })
            })
            .collect();
        let punctual_spheres: Vec<Option<Sphere>> = punctual
            .iter()
            .map(|l| {
                Some(Sphere {
                    c: Vec3::from_slice(&l.position_range[..3]).as_dvec3(),
                    r: grow(punctual_reach(l, cutoff_lux)),
                })
            })
            .collect();
        let all = || area_spheres.iter().chain(&punctual_spheres).flatten();
        if all().next().is_none() {
            return Self {
                cells: vec![[0; 4], [0; 4], [0; 4]],
                indices: vec![0],
            };
        }
        let finite = all().all(|s| s.c.is_finite() && s.r.is_finite() && s.r < 1e9);
        let (origin, cell, dims) = if finite {
            let lo = all().fold(DVec3::INFINITY, |a, s| a.min(s.c - s.r));
            let hi = all().fold(DVec3::NEG_INFINITY, |a, s| a.max(s.c + s.r));
            let extent = (hi - lo).max(DVec3::splat(1e-3));
            // Cells about as large as the median reach, so that a light touches a few cells
            // along each axis; at most 64 along the longest axis.
            let mut reaches: Vec<f64> = all().map(|s| s.r).collect();
            reaches.sort_by(f64::total_cmp);
            let median = reaches[reaches.len() / 2];
            let cell = median
                .max(extent.max_element() / (MAX_CELLS_PER_AXIS as f64 - 0.01))
                .max(1e-3);
            let dims = (extent / cell)
                .ceil()
                .clamp(DVec3::ONE, DVec3::splat(MAX_CELLS_PER_AXIS as f64));
            let pad = cell * INFLATE;
            let origin = (lo - pad).as_vec3();
            (origin, cell as f32, dims.as_uvec3())
        } else {
            // A reach too large to grid: one cell around everything, listing every light.
            (Vec3::splat(-1e30), 2e30, glam::UVec3::ONE)
        };
        let count = (dims.x * dims.y * dims.z) as usize;
        let mut area_lists: Vec<Vec<u32>> = vec![Vec::new(); count];
        let mut punctual_lists: Vec<Vec<u32>> = vec![Vec::new(); count];
        let o = origin.as_dvec3();
        let s = cell as f64;
        let margin = s * INFLATE;
        let place = |lists: &mut Vec<Vec<u32>>, spheres: &[Option<Sphere>]| {
            for (i, sp) in spheres.iter().enumerate() {
                let Some(sp) = sp else { continue };
                if !finite {
                    lists[0].push(i as u32);
                    continue;
                }
                let first = ((sp.c - sp.r - margin - o) / s).floor().max(DVec3::ZERO);
                let last = ((sp.c + sp.r + margin - o) / s)
                    .floor()
                    .min(dims.as_dvec3() - 1.0);
                for z in first.z as u32..=last.z as u32 {
                    for y in first.y as u32..=last.y as u32 {
                        for x in first.x as u32..=last.x as u32 {
                            let lo = o + DVec3::new(x as f64, y as f64, z as f64) * s - margin;
                            let hi = lo + s + 2.0 * margin;
                            let d = sp.c.clamp(lo, hi) - sp.c;
                            if d.length_squared() <= sp.r * sp.r {
                                lists[((z * dims.y + y) * dims.x + x) as usize].push(i as u32);
                            }
                        }
                    }
                }
            }
        };
        place(&mut area_lists, &area_spheres);
        place(&mut punctual_lists, &punctual_spheres);
        let mut cells = Vec::with_capacity(HEADER_RECORDS + count);
        cells.push([
            origin.x.to_bits(),
            origin.y.to_bits(),
            origin.z.to_bits(),
            cell.to_bits(),
        ]);
        cells.push([dims.x, dims.y, dims.z, 0]);
        let mut indices = Vec::new();
        for (a, p) in area_lists.iter().zip(&punctual_lists) {
            cells.push([indices.len() as u32, a.len() as u32, p.len() as u32, 0]);
            indices.extend_from_slice(a);
            indices.extend_from_slice(p);
        }
        if indices.is_empty() {
            indices.push(0);
        }
        Self { cells, indices }
    }

    /// Cells along x, y, z.
    pub fn dims(&self) -> [u32; 3] {
        let d = self.cells[1];
        [d[0], d[1], d[2]]
    }

    /// Light indices listed over all cells.
    pub fn entries(&self) -> usize {
        self.cells[HEADER_RECORDS..]
            .iter()
            .map(|c| (c[1] + c[2]) as usize)
            .sum()
    }

    /// Bytes on the GPU.
    pub fn bytes(&self) -> usize {
        self.cells.len() * 16 + self.indices.len() * 4
    }

    /// The cell holding `x`, as the shade pass finds it (f32); `None` outside the grid.
    pub fn cell_of(&self, x: Vec3) -> Option<usize> {
        let h = self.cells[0];
        let origin = Vec3::new(
            f32::from_bits(h[0]),
            f32::from_bits(h[1]),
            f32::from_bits(h[2]),
        );
        let cell = f32::from_bits(h[3]);
        let [dx, dy, dz] = self.dims();
        let g = ((x - origin) / cell).floor();
        let dims = Vec3::new(dx as f32, dy as f32, dz as f32);
        // NaN fails both tests: no cell.
        if !(g.cmpge(Vec3::ZERO).all() && g.cmplt(dims).all()) {
            return None;
        }
        Some(((g.z as u32 * dy + g.y as u32) * dx + g.x as u32) as usize)
    }

    /// The area lights and the punctual lights listed where `x` is (empty outside the grid).
    pub fn lights_at(&self, x: Vec3) -> (&[u32], &[u32]) {
        let Some(c) = self.cell_of(x) else {
            return (&[], &[]);
        };
        let [first, na, np, _] = self.cells[HEADER_RECORDS + c];
        let (first, na, np) = (first as usize, na as usize, np as usize);
        (
            &self.indices[first..first + na],
            &self.indices[first + na..first + na + np],
        )
    }

    /// The box (min, max corners, metres) of cell `c`, not inflated.
    pub fn cell_box(&self, c: usize) -> (Vec3, Vec3) {
        let h = self.cells[0];
        let origin = Vec3::new(
            f32::from_bits(h[0]),
            f32::from_bits(h[1]),
            f32::from_bits(h[2]),
        );
        let cell = f32::from_bits(h[3]);
        let [dx, dy, _] = self.dims();
        let c = c as u32;
        let g = Vec3::new(
            (c % dx) as f32,
            ((c / dx) % dy) as f32,
            (c / (dx * dy)) as f32,
        );
        (origin + g * cell, origin + (g + 1.0) * cell)
    }
}

/// The point and spot lights of `scene` as the shade pass reads their reach (`scene_gpu`'s
/// records: position and range, intensity; the rest zeroed, which the reach does not read).
pub fn punctual_records(scene: &hikari_scene::Scene) -> Vec<LightGpu> {
    scene
        .lights
        .iter()
        .map(|l| LightGpu {
            position_range: l.position.extend(l.range.unwrap_or(f32::MAX)).to_array(),
            intensity: (l.color * l.intensity_cd).extend(0.0).to_array(),
            ..bytemuck::Zeroable::zeroed()
        })
        .collect()
}
