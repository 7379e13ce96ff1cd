//! A bake flattened into the buffers the GPU reads (and the CPU twins read the same arrays):
//!
//! * `probe_data`: 9 `vec4` per probe, coefficient k = (bounced sky visibility rgb_k, sky
//!   visibility_k); grid tiles first (768 probes each, in the bake's tile order), then meshes.
//! * `positions`: one `vec4` per probe, (position in metres, 1 for interior probes else 0).
//! * `topology`: `u32` words: the dense tile map (first probe of each tile of the bake's
//!   bounding rectangle of tiles, or [`NO_TILE`]), then 4 global probe indices per
//!   tetrahedron, then 4 global neighbour tetrahedra (or [`hikari_probes::HULL`]), then
//!   [`MESH_WORDS`] per mesh: bounds min xyz, max xyz (f32 bits), first tetrahedron,
//!   tetrahedra, first probe, probes, offset in `topology` of its start grid, 0; then each
//!   mesh's start grid: [`START_CELLS`]³ tetrahedra (x fastest), for each cell of the mesh's
//!   bounds the tetrahedron whose centroid is nearest the cell's centre, where the lookup's
//!   walk starts (a few steps instead of crossing the mesh from its first tetrahedron).
//!
//! Non-finite numbers in a bake become 0 here (a bake file with them is refused when read,
//! but a bake made in memory is not checked), so NaN never reaches the frame.

use bytemuck::{Pod, Zeroable};
use hikari_probes::{Bake, HULL, TILE_COLUMNS, TILE_LAYERS, TILE_PROBE_COUNT};

/// A tile-map entry with no tile.
pub const NO_TILE: u32 = u32::MAX;
/// Words per mesh record in `topology`.
pub const MESH_WORDS: usize = 12;
/// Cells of a mesh's start grid along each axis.
pub const START_CELLS: usize = 4;
/// Probes along x (and z) of a tile.
pub const TILE_SIDE: usize = hikari_probes::model::TILE_PROBES_X;

/// `ProbeLookupParams::grid_size.w` flags.
pub const PROBES_PRESENT: u32 = 1;
pub const PROBES_GRID: u32 = 2;
pub const PROBES_INTERIOR_MASK: u32 = 4;

/// The uniform of the `irradiance_probes` binding set (`lookup.wgsl`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, PartialEq)]
pub struct ProbeLookupParams {
    /// World x, z of grid column (0, 0), metres; the grid's spacing, metres; the ambient
    /// diffuse scale (the weather's balance).
    pub grid: [f32; 4],
    /// Grid columns along x and z, tiles along x, `PROBES_*` flags.
    pub grid_size: [u32; 4],
    /// Meshes; offsets in `topology` (words) of the tetrahedra, the adjacency, the meshes.
    pub topology: [u32; 4],
}

/// Where a grid tile's probes are.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TileSlot {
    /// The bake's tile coordinates.
    pub tile: [i32; 2],
    pub first_probe: u32,
    /// World x, z of the tile's centre, metres (for the camera's 3x3 tiles).
    pub centre_xz: [f32; 2],
}

/// Where a mesh's probes and tetrahedra are.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MeshSlot {
    pub first_probe: u32,
    pub probes: u32,
    pub first_tet: u32,
    pub tets: u32,
    pub lo: [f32; 3],
    pub hi: [f32; 3],
    /// Offset in `topology` (words) of the mesh's start grid.
    pub start_grid: u32,
}

#[derive(Clone, Debug, PartialEq)]
pub struct ProbeGpuData {
    pub probe_data: Vec<[f32; 4]>,
    pub positions: Vec<[f32; 4]>,
    pub topology: Vec<u32>,
    /// Flags `PROBES_PRESENT` and `PROBES_GRID` set as the bake has them; the frame adds the
    /// interior-mask flag and the diffuse scale.
    pub params: ProbeLookupParams,
    pub tiles: Vec<TileSlot>,
    pub meshes: Vec<MeshSlot>,
    /// Side of a tile, metres.
    pub tile_size_m: f32,
    /// Non-finite numbers replaced with 0.
    pub replaced_non_finite: usize,
}

fn finite(v: f32, replaced: &mut usize) -> f32 {
    if v.is_finite() {
        v
    } else {
        *replaced += 1;
        0.0
    }
}

/// Appends one probe's 9 coefficients and its position, non-finite numbers as 0.
fn push_probe(
    probe_data: &mut Vec<[f32; 4]>,
    positions: &mut Vec<[f32; 4]>,
    replaced: &mut usize,
    sh: &hikari_probes::ProbeSh,
    at: [f32; 3],
    interior: bool,
) {
    for k in 0..9 {
        let b = sh.bounced_sky_visibility[k];
        probe_data.push([
            finite(b[0], replaced),
            finite(b[1], replaced),
            finite(b[2], replaced),
            finite(sh.sky_visibility[k], replaced),
        ]);
    }
    positions.push([
        finite(at[0], replaced),
        finite(at[1], replaced),
        finite(at[2], replaced),
        if interior { 1.0 } else { 0.0 },
    ]);
}

/// The start grid of mesh `m` (see the module's documentation): per cell, x fastest, the
/// tetrahedron (global index) whose centroid is nearest the cell's centre; the mesh's first
/// one for a mesh without tetrahedra.
fn start_grid(m: &MeshSlot, tets: &[u32], positions: &[[f32; 4]]) -> Vec<u32> {
    let n = START_CELLS;
    let centroid = |t: usize| {
        let mut c = [0.0f32; 3];
        for v in &tets[4 * t..4 * t + 4] {
            for a in 0..3 {
                c[a] += 0.25 * positions[*v as usize][a];
            }
        }
        c
    };
    let range = m.first_tet as usize..(m.first_tet + m.tets) as usize;
    let centroids: Vec<(u32, [f32; 3])> = range.map(|t| (t as u32, centroid(t))).collect();
    let mut out = Vec::with_capacity(n * n * n);
    for z in 0..n {
        for y in 0..n {
            for x in 0..n {
                let centre: [f32; 3] = std::array::from_fn(|a| {
                    let i = [x, y, z][a] as f32;
                    m.lo[a] + (m.hi[a] - m.lo[a]) * (i + 0.5) / n as f32
                });
                let d2 = |c: &[f32; 3]| (0..3).map(|a| (c[a] - centre[a]).powi(2)).sum::<f32>();
                let best = centroids
                    .iter()
                    .min_by(|a, b| d2(&a.1).total_cmp(&d2(&b.1)))
                    .map_or(m.first_tet, |c| c.0);
                out.push(best);
            }
        }
    }
    out
}

impl ProbeGpuData {
    pub fn probe_count(&self) -> usize {
        self.positions.len()
    }

    /// Lays `bake` out for the GPU. Tiles are placed on the grid of the first tile (their
    /// origins are multiples of the tile size apart in a bake of hikari-bake).
    pub fn new(bake: &Bake) -> Self {
        let mut replaced = 0usize;
        let spacing = finite(bake.settings.grid_spacing_m, &mut replaced).max(1e-3);
        let tile_size = spacing * TILE_SIDE as f32;
        let mut probe_data = Vec::with_capacity(bake.probe_count() * 9);
        let mut positions = Vec::with_capacity(bake.probe_count());

        // Grid: tiles in bake order; the map covers their bounding rectangle.
        let mut tiles = Vec::new();
        let (mut lo, mut hi) = ([i32::MAX; 2], [i32::MIN; 2]);
        for t in &bake.tiles {
            for a in 0..2 {
                lo[a] = lo[a].min(t.tile[a]);
                hi[a] = hi[a].max(t.tile[a]);
            }
        }
        let mut origin = [0.0f32; 2];
        if let Some(first) = bake.tiles.first() {
            for a in 0..2 {
                origin[a] = first.origin_xz[a] - (first.tile[a] - lo[a]) as f32 * tile_size;
            }
        }
        let tiles_x = if bake.tiles.is_empty() {
            0
        } else {
            (hi[0] - lo[0] + 1) as usize
        };
        let tiles_z = if bake.tiles.is_empty() {
            0
        } else {
            (hi[1] - lo[1] + 1) as usize
        };
        let mut tile_map = vec![NO_TILE; tiles_x * tiles_z];
        for t in &bake.tiles {
            let first_probe = positions.len() as u32;
            let slot = (t.tile[1] - lo[1]) as usize * tiles_x + (t.tile[0] - lo[0]) as usize;
            tile_map[slot] = first_probe;
            let x0 = origin[0] + (t.tile[0] - lo[0]) as f32 * tile_size;
            let z0 = origin[1] + (t.tile[1] - lo[1]) as f32 * tile_size;
            for layer in 0..TILE_LAYERS {
                for j in 0..TILE_SIDE {
                    for i in 0..TILE_SIDE {
                        let k = hikari_probes::GridTile::probe_index(i, j, layer);
                        let ground = t.ground_heights_m.get(j * TILE_SIDE + i).copied();
                        let y = ground.unwrap_or(0.0) + bake.settings.layer_heights_m[layer];
                        let at = [x0 + i as f32 * spacing, y, z0 + j as f32 * spacing];
                        let sh = t.probes.get(k).copied().unwrap_or_default();
                        let interior = t.interior.get(k).copied().unwrap_or(false);
                        push_probe(
                            &mut probe_data,
                            &mut positions,
                            &mut replaced,
                            &sh,
                            at,
                            interior,
                        );
                    }
                }
            }
            debug_assert_eq!(
                positions.len() as u32 - first_probe,
                TILE_PROBE_COUNT as u32
            );
            tiles.push(TileSlot {
                tile: t.tile,
                first_probe,
                centre_xz: [x0 + 0.5 * tile_size, z0 + 0.5 * tile_size],
            });
        }

        // Meshes: probes after the grid's; tetrahedra and adjacency made global.
        let mut tets = Vec::new();
        let mut adjacency = Vec::new();
        let mut meshes = Vec::new();
        for m in &bake.meshes {
            let first_probe = positions.len() as u32;
            let first_tet = (tets.len() / 4) as u32;
            let (mut mlo, mut mhi) = ([f32::MAX; 3], [f32::MIN; 3]);
            for (k, sh) in m.probes.iter().enumerate() {
                let at = m.positions.get(k).copied().unwrap_or_default();
                push_probe(
                    &mut probe_data,
                    &mut positions,
                    &mut replaced,
                    sh,
                    at,
                    m.interior.get(k).copied().unwrap_or(false),
                );
                let at = positions[positions.len() - 1];
                for a in 0..3 {
                    mlo[a] = mlo[a].min(at[a]);
                    mhi[a] = mhi[a].max(at[a]);
                }
            }
            for (t, tet) in m.tets.iter().enumerate() {
                tets.extend(tet.map(|v| first_probe + v));
                let adj = m.adjacency.get(t).copied().unwrap_or([HULL; 4]);
                adjacency.extend(adj.map(|n| if n == HULL { HULL } else { first_tet + n }));
            }
            meshes.push(MeshSlot {
                first_probe,
                probes: m.probes.len() as u32,
                first_tet,
                tets: m.tets.len() as u32,
                lo: mlo,
                hi: mhi,
                start_grid: 0,
            });
        }

        let tet_offset = tile_map.len();
        let adj_offset = tet_offset + tets.len();
        let mesh_offset = adj_offset + adjacency.len();
        let cells = START_CELLS * START_CELLS * START_CELLS;
        let grids_offset = mesh_offset + MESH_WORDS * meshes.len();
        let mut start_grids = Vec::with_capacity(cells * meshes.len());
        for (k, m) in meshes.iter_mut().enumerate() {
            m.start_grid = (grids_offset + k * cells) as u32;
            start_grids.extend(start_grid(m, &tets, &positions));
        }
        let mut topology = tile_map;
        topology.extend(tets);
        topology.extend(adjacency);
        for m in &meshes {
            topology.extend(m.lo.map(f32::to_bits));
            topology.extend(m.hi.map(f32::to_bits));
            topology.extend([
                m.first_tet,
                m.tets,
                m.first_probe,
                m.probes,
                m.start_grid,
                0,
            ]);
        }
        topology.extend(start_grids);
        let mut flags = 0;
        if !positions.is_empty() {
            flags |= PROBES_PRESENT;
        }
        if !tiles.is_empty() {
            flags |= PROBES_GRID;
        }
        Self {
            params: ProbeLookupParams {
                grid: [origin[0], origin[1], spacing, 1.0],
                grid_size: [
                    (tiles_x * TILE_SIDE) as u32,
                    (tiles_z * TILE_SIDE) as u32,
                    tiles_x as u32,
                    flags,
                ],
                topology: [
                    meshes.len() as u32,
                    tet_offset as u32,
                    adj_offset as u32,
                    mesh_offset as u32,
                ],
            },
            probe_data,
            positions,
            topology,
            tiles,
            meshes,
            tile_size_m: tile_size,
            replaced_non_finite: replaced,
        }
    }

    /// Probe `p`'s sky visibility (mono) and bounced sky visibility (RGB) as SH.
    pub fn probe_sh(&self, p: usize) -> (hikari_math::sh::ShL2, hikari_math::sh::ShL2Rgb) {
        let c = &self.probe_data[p * 9..p * 9 + 9];
        (
            hikari_math::sh::Sh::new(std::array::from_fn(|k| c[k][3])),
            hikari_math::sh::Sh::new(std::array::from_fn(|k| {
                glam::Vec3::new(c[k][0], c[k][1], c[k][2])
            })),
        )
    }

    /// Whether probe `p` is an interior probe.
    pub fn interior(&self, p: usize) -> bool {
        self.positions[p][3] > 0.5
    }
}

/// Columns of one tile (for the lookup's layer offsets).
pub const COLUMNS: usize = TILE_COLUMNS;
