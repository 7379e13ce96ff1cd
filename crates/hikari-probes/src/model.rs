//! The bake's data model: grid tiles and tetrahedral meshes of probes, each probe holding its
//! baked sky visibility and bounced sky visibility as L2 spherical harmonics.
//!
//! Coordinates are metres in the scene's world space, y up (the glTF convention hikari uses).

/// Probes along x in one grid tile.
pub const TILE_PROBES_X: usize = 16;
/// Probes along z in one grid tile.
pub const TILE_PROBES_Z: usize = 16;
/// Probe layers above the ground in one grid tile.
pub const TILE_LAYERS: usize = 3;
/// Ground columns (x, z positions) in one grid tile.
pub const TILE_COLUMNS: usize = TILE_PROBES_X * TILE_PROBES_Z;
/// Probes in one grid tile.
pub const TILE_PROBE_COUNT: usize = TILE_COLUMNS * TILE_LAYERS;
/// L2 spherical-harmonic coefficients per channel.
pub const SH_COEFFS: usize = 9;
/// Adjacency entry of a tetrahedron face on the mesh's hull (no neighbour across it).
pub const HULL: u32 = u32::MAX;

/// Identifies the scene content a bake belongs to: a 32-byte hash chosen by the caller (for
/// example SHA-256 or BLAKE3 of the scene's files and bake-relevant settings). A bake is only
/// accepted for the scene whose key it records.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub struct SceneKey(pub [u8; 32]);

impl SceneKey {
    /// A key from a 64-bit hash: little-endian in the first 8 bytes, the rest zero.
    pub fn from_u64(hash: u64) -> Self {
        let mut key = [0u8; 32];
        key[..8].copy_from_slice(&hash.to_le_bytes());
        Self(key)
    }
}

impl std::fmt::Display for SceneKey {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        for byte in self.0 {
            write!(f, "{byte:02x}")?;
        }
        Ok(())
    }
}

/// How the bake was made; recorded so that a bake made with other settings is not resumed or
/// mistaken for the current one.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BakeSettings {
    /// Rays traced per probe for its sky visibility (and, per hit, for the bounce).
    pub rays_per_probe: u32,
    /// Horizontal distance between neighbouring grid probes, metres (the talk: 12.5 m, so a
    /// tile of 16 probes spans 200 m).
    pub grid_spacing_m: f32,
    /// Heights of the three probe layers above the ground, metres (the talk: 1.5, 10, 30).
    pub layer_heights_m: [f32; TILE_LAYERS],
}

impl BakeSettings {
    /// The talk's grid (12.5 m spacing, layers at 1.5, 10 and 30 m) with the given ray count.
    pub fn with_rays(rays_per_probe: u32) -> Self {
        Self {
            rays_per_probe,
            grid_spacing_m: 12.5,
            layer_heights_m: [1.5, 10.0, 30.0],
        }
    }

    /// Side of one grid tile, metres.
    pub fn tile_size_m(&self) -> f32 {
        self.grid_spacing_m * TILE_PROBES_X as f32
    }
}

/// One probe's baked light transport, both as L2 SH in the order l=0; l=1 m=-1,0,1;
/// l=2 m=-2..2 in the real orthonormal basis (hikari-math's order).
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct ProbeSh {
    /// Fraction of directions that see the sky, projected to SH (dimensionless; a probe in
    /// open space has only the l=0 coefficient, 2*sqrt(pi)).
    pub sky_visibility: [f32; SH_COEFFS],
    /// Radiance reaching the probe from surfaces lit by a uniform white sky of radiance 1,
    /// through their own sky visibility and albedo; RGB per coefficient (relative to the sky).
    pub bounced_sky_visibility: [[f32; 3]; SH_COEFFS],
}

/// A 16x16x3 block of grid probes over one square of terrain.
///
/// Probe `(i, j, layer)` (i along x, j along z) is element `(layer * 16 + j) * 16 + i` of
/// `probes` and `interior`; it stands at
/// `(origin_xz[0] + i * spacing, ground_heights_m[j * 16 + i] + layer_heights_m[layer], origin_xz[1] + j * spacing)`.
#[derive(Clone, Debug, PartialEq)]
pub struct GridTile {
    /// Tile coordinates in the scene's grid of tiles; unique within a bake.
    pub tile: [i32; 2],
    /// World x and z of probe (0, 0), metres.
    pub origin_xz: [f32; 2],
    /// Terrain height under each probe column (`TILE_COLUMNS` of them), metres.
    pub ground_heights_m: Vec<f32>,
    /// `TILE_PROBE_COUNT` probes.
    pub probes: Vec<ProbeSh>,
    /// `TILE_PROBE_COUNT` flags: true for probes inside buildings (the interior mask's side).
    pub interior: Vec<bool>,
}

impl GridTile {
    /// Index of probe `(i, j, layer)` in `probes` and `interior`.
    pub fn probe_index(i: usize, j: usize, layer: usize) -> usize {
        (layer * TILE_PROBES_Z + j) * TILE_PROBES_X + i
    }

    /// World position of probe `(i, j, layer)`, metres; `None` outside the tile or when
    /// `ground_heights_m` is short.
    pub fn probe_position(
        &self,
        settings: &BakeSettings,
        i: usize,
        j: usize,
        layer: usize,
    ) -> Option<[f32; 3]> {
        if i >= TILE_PROBES_X || j >= TILE_PROBES_Z || layer >= TILE_LAYERS {
            return None;
        }
        let ground = *self.ground_heights_m.get(j * TILE_PROBES_X + i)?;
        Some([
            self.origin_xz[0] + i as f32 * settings.grid_spacing_m,
            ground + settings.layer_heights_m[layer],
            self.origin_xz[1] + j as f32 * settings.grid_spacing_m,
        ])
    }
}

/// Probes at free positions, tetrahedralised, for places the grid is too coarse for.
#[derive(Clone, Debug, PartialEq)]
pub struct TetMesh {
    /// The baker's identifier of the mesh (for example its index in the scene); unique within
    /// a bake.
    pub id: u32,
    /// Probe positions, metres.
    pub positions: Vec<[f32; 3]>,
    /// One per position.
    pub probes: Vec<ProbeSh>,
    /// One per position: true for probes inside buildings.
    pub interior: Vec<bool>,
    /// Four distinct probe indices per tetrahedron. hikari-bake writes them with positive
    /// volume, `(b - a) · ((c - a) × (d - a)) > 0`, as the Delaunay tetrahedralisation of the
    /// probes (so the mesh is convex and a walk that leaves through a hull face has left it);
    /// the reader does not check either.
    pub tets: Vec<[u32; 4]>,
    /// Per tetrahedron, the neighbour across the face opposite vertex k in entry k, or
    /// [`HULL`]. Neighbours are mutual.
    pub adjacency: Vec<[u32; 4]>,
}

/// A whole bake (or, while baking, the part done so far).
#[derive(Clone, Debug, PartialEq)]
pub struct Bake {
    /// The scene this bake belongs to.
    pub scene: SceneKey,
    /// How it was baked.
    pub settings: BakeSettings,
    /// False while the baker is still adding tiles or meshes (a checkpoint); the renderer only
    /// accepts complete bakes.
    pub complete: bool,
    /// Grid tiles, in any order.
    pub tiles: Vec<GridTile>,
    /// Tetrahedral meshes, in any order.
    pub meshes: Vec<TetMesh>,
}

impl Bake {
    /// An empty, incomplete bake to fill.
    pub fn new(scene: SceneKey, settings: BakeSettings) -> Self {
        Self {
            scene,
            settings,
            complete: false,
            tiles: Vec::new(),
            meshes: Vec::new(),
        }
    }

    /// Whether the tile at these tile coordinates is already baked (for resuming).
    pub fn has_tile(&self, tile: [i32; 2]) -> bool {
        self.tiles.iter().any(|t| t.tile == tile)
    }

    /// Whether the mesh with this id is already baked (for resuming).
    pub fn has_mesh(&self, id: u32) -> bool {
        self.meshes.iter().any(|m| m.id == id)
    }

    /// Number of probes over all tiles and meshes.
    pub fn probe_count(&self) -> usize {
        self.tiles.iter().map(|t| t.probes.len()).sum::<usize>()
            + self.meshes.iter().map(|m| m.probes.len()).sum::<usize>()
    }
}
