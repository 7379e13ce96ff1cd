//! # hikari-bake: offline probe bake on the CPU
//!
//! Issue 17's irradiance probes, traced with hikari-bvh's CPU traversal on all cores (rayon's
//! global pool; `RAYON_NUM_THREADS` sets its size). [`bake_scene`] (and [`bake_scene_resume`],
//! [`bake_to_file`]) bakes the grid and the tetrahedral meshes of [`volumes`] into a
//! `hikari_probes::Bake`: sky visibility, bounced sky visibility ([`transport`]) and interior
//! flags ([`scene_bake`]); docs/irradiance-probes.md describes it all. The transport's rays go
//! through a [`TransportTracer`]: [`CpuTransport`] here, or hikari-render's GPU twin
//! (`probe_bake_gpu`), given to [`bake_scene_resume_with`] or [`bake_to_file_with`]. Below, the grid and
//! [`bake_grid_sky_visibility`], the first, grid-only entry point (kept).
//!
//! ```
//! use hikari_bake::{GridBakeOptions, bake_grid_sky_visibility};
//! let scene = hikari_scene::builtin::boxes();
//! let options = GridBakeOptions { rays_per_probe: 64, ..Default::default() };
//! let bake = bake_grid_sky_visibility(&scene, &options, |_done, _total| {})?;
//! for tile in &bake.tiles {
//!     for probe in &tile.probes {
//!         assert!(probe.sky_visibility.iter().all(|c| c.is_finite()));
//!     }
//! }
//! # Ok::<(), hikari_bake::BakeError>(())
//! ```
//!
//! ## The grid
//!
//! Probes stand `spacing` metres apart (12.5 m) along x and z from the scene bounds' minimum
//! corner, in three layers `heights` above the ground (1.5 m, 10 m, 30 m), grouped in tiles of
//! `probes_per_tile` x `probes_per_tile` x 3 (16 x 16 x 3, a 200 m square). Along each axis,
//! the fewest tiles whose probes span the scene's bounds less one spacing, centred on the
//! bounds (the outermost probes are at most half a spacing inside the bounds). Probe `(ix, iz, layer)` of a tile is
//! `probes[layer * n * n + iz * n + ix]`. The ground is the lowest upward-facing surface under
//! the column ([`placement::ground_height`]).
//!
//! A probe inside geometry ([`placement::inside_geometry`]) is **lifted** in steps of
//! `lift_step` up to `max_lift` metres until it is free, else **dropped**: it keeps its slot
//! (the grid stays regular for trilinear lookups), [`Placement::Dropped`], and zero sky
//! visibility, which is what a probe buried in a solid sees.
//!
//! ## Sky visibility
//!
//! See [`sky_visibility`]: `rays_per_probe` Fibonacci-sphere directions, weight `4π / n` each.

pub mod delaunay;
pub mod error;
pub mod placement;
pub mod scene_bake;
pub mod scene_rays;
pub mod sky_visibility;
pub mod surfaces;
pub mod transport;
pub mod transport_tables;
pub mod volumes;

use std::time::Instant;

use glam::{Vec2, Vec3};
use hikari_bvh::TraversalStacks;
use hikari_scene::Scene;
use rayon::prelude::*;

pub use error::BakeError;
pub use scene_bake::{
    BakeProgress, BakedFile, DEFAULT_BOUNCE_RAYS, SceneBakeOptions, bake_scene, bake_scene_resume,
    bake_scene_resume_with, bake_to_file, bake_to_file_with, transport_settings,
};
pub use scene_rays::SceneRays;
pub use sky_visibility::SphereRays;
pub use transport::{CpuTransport, ProbeRequest, TransportSettings, TransportTracer};
pub use volumes::ProbeVolume;

/// Layers of a grid tile (1.5 m, 10 m, 30 m above the ground by default).
pub const LAYERS: usize = 3;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GridBakeOptions {
    /// Metres between neighbouring probes along x and z.
    pub spacing: f32,
    /// Probes along each horizontal side of a tile.
    pub probes_per_tile: u32,
    /// Metres above the ground of each layer, lowest first.
    pub heights: [f32; LAYERS],
    /// Sky-visibility rays per probe.
    pub rays_per_probe: u32,
    /// Rays of the inside-geometry test per probe (closest hits).
    pub inside_test_rays: u32,
    /// A probe is inside geometry when more than this fraction of its test rays meet a back face.
    pub inside_back_face_fraction: f32,
    /// Metres a probe inside geometry is lifted per try.
    pub lift_step: f32,
    /// Most metres a probe is lifted before it is dropped.
    pub max_lift: f32,
    /// Probes per progress report (and per parallel batch).
    pub progress_batch: usize,
}

impl Default for GridBakeOptions {
    fn default() -> Self {
        Self {
            spacing: 12.5,
            probes_per_tile: 16,
            heights: [1.5, 10.0, 30.0],
            rays_per_probe: DEFAULT_RAYS_PER_PROBE,
            inside_test_rays: 64,
            inside_back_face_fraction: 0.5,
            lift_step: 0.5,
            max_lift: 4.0,
            progress_batch: 1024,
        }
    }
}

/// Sky-visibility rays per probe by default; the error this leaves is measured by
/// `examples/bake_village.rs` against 16 times as many (README of the crate).
pub const DEFAULT_RAYS_PER_PROBE: u32 = 2048;

/// How a probe ended up where it is.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Placement {
    /// At its layer's height above the ground.
    Planned,
    /// Lifted this many metres out of geometry.
    Lifted(f32),
    /// Inside geometry even after the largest lift; its sky visibility is zero.
    Dropped,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GridProbe {
    /// World position, metres.
    pub position: Vec3,
    pub placement: Placement,
    /// Mono L2 SH of the sky visibility (order and basis of `hikari_math::sh`).
    pub sky_visibility: [f32; 9],
}

#[derive(Clone, Debug, PartialEq)]
pub struct GridTile {
    /// Tile column and row (x, z) counted from the grid origin.
    pub index: [u32; 2],
    /// x, z of the tile's probe (0, 0), metres.
    pub origin: Vec2,
    /// Ground height (metres) under each column, `iz * n + ix`.
    pub ground: Vec<f32>,
    /// `layer * n * n + iz * n + ix`.
    pub probes: Vec<GridProbe>,
}

#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BakeStats {
    pub probes: usize,
    pub lifted: usize,
    pub dropped: usize,
    pub rays_per_probe: u32,
    /// Sky-visibility rays traced (any hit).
    pub sky_rays: u64,
    /// Ground and inside-test rays traced (closest hit).
    pub placement_rays: u64,
    pub threads: usize,
    pub bvh_seconds: f64,
    pub placement_seconds: f64,
    pub sky_seconds: f64,
    pub total_seconds: f64,
}

impl BakeStats {
    /// Sky-visibility rays per second of the sky pass.
    pub fn sky_rays_per_second(&self) -> f64 {
        self.sky_rays as f64 / self.sky_seconds.max(1e-9)
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct GridBake {
    pub options: GridBakeOptions,
    /// x, z of probe (0, 0) of tile (0, 0), metres.
    pub origin: Vec2,
    pub tiles_x: u32,
    pub tiles_z: u32,
    /// Row-major: tile `(tx, tz)` is `tiles[tz * tiles_x + tx]`.
    pub tiles: Vec<GridTile>,
    pub stats: BakeStats,
}

/// Where the grid's tiles lie over a scene's bounds.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GridLayout {
    /// x, z of probe (0, 0) of tile (0, 0), metres.
    pub origin: Vec2,
    pub tiles_x: u32,
    pub tiles_z: u32,
}

impl GridLayout {
    /// Enough tiles that the probes span the bounds less one spacing, centred on them: at most
    /// half a spacing at each side is left to the lookup's clamping, and a scene a hair wider
    /// than whole tiles (the village's 400.2 m) does not get a row of tiles over nothing.
    pub fn plan(lo: Vec3, hi: Vec3, options: &GridBakeOptions) -> Self {
        let tile_size = options.spacing * options.probes_per_tile as f32;
        let tiles_along = |extent: f32| {
            let tiles = (((extent - options.spacing) / tile_size).ceil() as u32).max(1);
            let span = tiles as f32 * tile_size - options.spacing;
            (tiles, -0.5 * (span - extent))
        };
        let ((tiles_x, margin_x), (tiles_z, margin_z)) =
            (tiles_along(hi.x - lo.x), tiles_along(hi.z - lo.z));
        Self {
            origin: Vec2::new(lo.x + margin_x, lo.z + margin_z),
            tiles_x,
            tiles_z,
        }
    }
}

/// Lifts a probe planned at `planned` out of geometry: the first of `planned + k * lift_step`
/// (k = 0, 1, ... up to `max_lift`) outside geometry, with its lift in metres; `None` when all
/// are inside (the probe is dropped). Also returns the inside-test rays traced.
pub fn place_probe(
    rays: &SceneRays,
    inside_rays: &SphereRays,
    planned: Vec3,
    options: &GridBakeOptions,
    stacks: &mut TraversalStacks,
) -> (Option<(Vec3, f32)>, u64) {
    let lifts = (options.max_lift / options.lift_step).floor() as u32;
    let mut traced = 0u64;
    for step in 0..=lifts {
        let lift = step as f32 * options.lift_step;
        let at = planned + Vec3::Y * lift;
        traced += inside_rays.len() as u64;
        if !placement::inside_geometry(
            rays,
            inside_rays,
            at,
            options.inside_back_face_fraction,
            stacks,
        ) {
            return (Some((at, lift)), traced);
        }
    }
    (None, traced)
}

pub(crate) fn check(options: &GridBakeOptions) -> Result<(), BakeError> {
    let bad = |option, value: String, why| Err(BakeError::BadOption { option, value, why });
    let positive = |v: f32| v.is_finite() && v > 0.0;
    if !positive(options.spacing) {
        return bad(
            "spacing",
            options.spacing.to_string(),
            "must be a positive number of metres",
        );
    }
    if options.probes_per_tile == 0 || options.probes_per_tile > 1024 {
        return bad(
            "probes_per_tile",
            options.probes_per_tile.to_string(),
            "must be 1..=1024",
        );
    }
    if !options.heights.iter().all(|h| h.is_finite() && *h >= 0.0) {
        return bad(
            "heights",
            format!("{:?}", options.heights),
            "must be finite and not negative",
        );
    }
    if options.rays_per_probe == 0 {
        return bad("rays_per_probe", "0".into(), "must be at least 1");
    }
    if options.inside_test_rays == 0 {
        return bad("inside_test_rays", "0".into(), "must be at least 1");
    }
    if !(0.0..=1.0).contains(&options.inside_back_face_fraction) {
        return bad(
            "inside_back_face_fraction",
            options.inside_back_face_fraction.to_string(),
            "must be in 0..=1",
        );
    }
    if !positive(options.lift_step) {
        return bad(
            "lift_step",
            options.lift_step.to_string(),
            "must be a positive number of metres",
        );
    }
    if !(options.max_lift.is_finite() && options.max_lift >= 0.0) {
        return bad(
            "max_lift",
            options.max_lift.to_string(),
            "must be finite and not negative",
        );
    }
    if options.progress_batch == 0 {
        return bad("progress_batch", "0".into(), "must be at least 1");
    }
    Ok(())
}

/// Places the grid over `scene`'s horizontal bounds and bakes every probe's sky visibility.
/// `progress(done, total)` is called on the calling thread after each batch of probes (and once
/// with `done == total`). A scene without geometry gives a bake without tiles.
pub fn bake_grid_sky_visibility(
    scene: &Scene,
    options: &GridBakeOptions,
    mut progress: impl FnMut(usize, usize),
) -> Result<GridBake, BakeError> {
    check(options)?;
    let start = Instant::now();
    let rays = SceneRays::build(scene)?;
    let bvh_seconds = start.elapsed().as_secs_f64();
    let mut stats = BakeStats {
        rays_per_probe: options.rays_per_probe,
        threads: rayon::current_num_threads(),
        bvh_seconds,
        ..Default::default()
    };
    let Some((lo, hi)) = scene.bounds() else {
        progress(0, 0);
        stats.total_seconds = start.elapsed().as_secs_f64();
        return Ok(GridBake {
            options: *options,
            origin: Vec2::ZERO,
            tiles_x: 0,
            tiles_z: 0,
            tiles: Vec::new(),
            stats,
        });
    };
    let n = options.probes_per_tile as usize;
    let tile_size = options.spacing * n as f32;
    let layout = GridLayout::plan(lo, hi, options);
    let (origin, tiles_x, tiles_z) = (layout.origin, layout.tiles_x, layout.tiles_z);
    let tile_count = (tiles_x * tiles_z) as usize;
    let columns_per_tile = n * n;

    // Ground under every column.
    let place_start = Instant::now();
    let column_xz = |c: usize| {
        let (tile, k) = (c / columns_per_tile, c % columns_per_tile);
        let (tx, tz) = (tile as u32 % tiles_x, tile as u32 / tiles_x);
        origin
            + tile_size * Vec2::new(tx as f32, tz as f32)
            + options.spacing * Vec2::new((k % n) as f32, (k / n) as f32)
    };
    let top = hi.y + 1.0;
    let ground: Vec<(f32, u64)> = (0..tile_count * columns_per_tile)
        .into_par_iter()
        .map_init(TraversalStacks::default, |stacks, c| {
            let xz = column_xz(c);
            placement::ground_height(&rays, xz.x, xz.y, top, lo.y, stacks)
        })
        .collect();
    stats.placement_rays += ground.iter().map(|g| g.1).sum::<u64>();
    stats.placement_seconds += place_start.elapsed().as_secs_f64();

    // Probes: place (lift or drop), then trace, in batches for progress reports.
    let sphere = SphereRays::fibonacci(options.rays_per_probe);
    let inside_rays = SphereRays::fibonacci(options.inside_test_rays);
    let probes_per_tile = columns_per_tile * LAYERS;
    let total = tile_count * probes_per_tile;
    let mut probes = Vec::with_capacity(total);
    let mut probe_rays = (0u64, 0u64);
    progress(0, total);
    let sky_start = Instant::now();
    for batch_start in (0..total).step_by(options.progress_batch) {
        let batch_end = (batch_start + options.progress_batch).min(total);
        let batch: Vec<(GridProbe, u64, u64)> = (batch_start..batch_end)
            .into_par_iter()
            .map_init(TraversalStacks::default, |stacks, p| {
                let (tile, k) = (p / probes_per_tile, p % probes_per_tile);
                let (layer, col) = (k / columns_per_tile, k % columns_per_tile);
                let c = tile * columns_per_tile + col;
                let xz = column_xz(c);
                let planned = Vec3::new(xz.x, ground[c].0 + options.heights[layer], xz.y);
                let (placed, placement_rays) =
                    place_probe(&rays, &inside_rays, planned, options, stacks);
                match placed {
                    Some((at, lift)) => {
                        let sh = sky_visibility::sky_visibility(&rays, &sphere, at, stacks);
                        let placement = if lift > 0.0 {
                            Placement::Lifted(lift)
                        } else {
                            Placement::Planned
                        };
                        let probe = GridProbe {
                            position: at,
                            placement,
                            sky_visibility: sh,
                        };
                        (probe, placement_rays, sphere.len() as u64)
                    }
                    None => {
                        let probe = GridProbe {
                            position: planned,
                            placement: Placement::Dropped,
                            sky_visibility: [0.0; 9],
                        };
                        (probe, placement_rays, 0)
                    }
                }
            })
            .collect();
        for (probe, placement_rays, sky_rays) in batch {
            probe_rays.0 += placement_rays;
            probe_rays.1 += sky_rays;
            probes.push(probe);
        }
        progress(batch_end, total);
    }
    // The inside test's share of the probe pass, counted as placement by ray count.
    let probe_pass = sky_start.elapsed().as_secs_f64();
    stats.placement_rays += probe_rays.0;
    stats.sky_rays = probe_rays.1;
    let sky_share = probe_rays.1 as f64 / (probe_rays.0 + probe_rays.1).max(1) as f64;
    stats.sky_seconds = probe_pass * sky_share;
    stats.placement_seconds += probe_pass * (1.0 - sky_share);

    let mut tiles = Vec::with_capacity(tile_count);
    let mut probes = probes.into_iter();
    for t in 0..tile_count {
        let (tx, tz) = (t as u32 % tiles_x, t as u32 / tiles_x);
        let tile_probes: Vec<GridProbe> = probes.by_ref().take(probes_per_tile).collect();
        for p in &tile_probes {
            stats.probes += 1;
            match p.placement {
                Placement::Planned => {}
                Placement::Lifted(_) => stats.lifted += 1,
                Placement::Dropped => stats.dropped += 1,
            }
        }
        tiles.push(GridTile {
            index: [tx, tz],
            origin: origin + tile_size * Vec2::new(tx as f32, tz as f32),
            ground: ground[t * columns_per_tile..(t + 1) * columns_per_tile]
                .iter()
                .map(|g| g.0)
                .collect(),
            probes: tile_probes,
        });
    }
    stats.total_seconds = start.elapsed().as_secs_f64();
    Ok(GridBake {
        options: *options,
        origin,
        tiles_x,
        tiles_z,
        tiles,
        stats,
    })
}
pub mod reflection_probes;
