//! The full bake of a scene into a [`hikari_probes::Bake`]: grid tiles and tetrahedral meshes,
//! each probe with sky visibility, bounced sky visibility and an interior flag, with progress
//! reports and resumption from a checkpoint.
//!
//! Work goes section by section (a grid tile, then a mesh): after each, `checkpoint` sees the
//! bake so far (the caller saves it every few seconds with `hikari_probes::save_checkpoint`)
//! and may stop the bake ([`std::ops::ControlFlow::Break`] gives [`BakeError::Cancelled`]);
//! [`bake_scene_resume`] skips the tiles and meshes a resumed bake already holds.
//!
//! **Interior** (the talk's interior/exterior classification): a probe is interior when at
//! least `interior_enclosed_fraction` (0.85) of its rays meet a surface within
//! `enclosure_radius` (12 m): walls, floor and ceiling all round. Under trees or in a street
//! the sky and the distance leave too many rays free. Probes inside geometry (see
//! [`crate::placement::inside_geometry`]) are lifted (grid) or moved out along an axis by up
//! to 40 % of the spacing (meshes), else dropped: a grid probe keeps its slot with zero
//! transport, a mesh probe is left out of the mesh.

use std::ops::ControlFlow;
use std::path::Path;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::time::{Duration, Instant};

use glam::{Vec2, Vec3};
use hikari_bvh::TraversalStacks;
use hikari_probes::{Bake, BakeSettings, GridTile, ProbeSh, SceneKey, TILE_COLUMNS, TetMesh};
use hikari_scene::Scene;
use rayon::prelude::*;

use crate::delaunay::tetrahedralize;
use crate::error::BakeError;
use crate::scene_rays::SceneRays;
use crate::sky_visibility::SphereRays;
use crate::surfaces::SurfaceAlbedo;
use crate::transport::{
    CpuTransport, ProbeRequest, ProbeTransport, TransportSettings, TransportTracer,
};
use crate::volumes::ProbeVolume;
use crate::{GridBakeOptions, GridLayout, LAYERS, place_probe, placement};

/// Secondary rays per probe-ray hit, by default (see [`crate::transport`]); the error this
/// leaves is measured by `examples/bake_village.rs`.
pub const DEFAULT_BOUNCE_RAYS: u32 = 2;

#[derive(Clone, Debug, PartialEq)]
pub struct SceneBakeOptions {
    /// The grid, and the probe rays and placement tests of every probe (grid and mesh).
    pub grid: GridBakeOptions,
    /// Secondary rays from each surface a probe ray hits (0: no bounced visibility).
    pub bounce_rays: u32,
    /// Boxes that get tetrahedral meshes ([`crate::volumes`]).
    pub volumes: Vec<ProbeVolume>,
    /// A ray meeting a surface closer than this (metres) counts as enclosed.
    pub enclosure_radius: f32,
    /// Fraction of enclosed rays from which a probe is interior.
    pub interior_enclosed_fraction: f32,
    /// Random offset of volume lattice points, as a fraction of their spacing (keeps the
    /// Delaunay input out of degenerate, cospherical configurations).
    pub volume_jitter: f32,
    /// Recorded in the bake; the caller's hash of the scene's content and of these options.
    pub scene_key: SceneKey,
}

impl Default for SceneBakeOptions {
    fn default() -> Self {
        Self {
            grid: GridBakeOptions::default(),
            bounce_rays: DEFAULT_BOUNCE_RAYS,
            volumes: Vec::new(),
            enclosure_radius: 12.0,
            interior_enclosed_fraction: 0.85,
            volume_jitter: 0.02,
            scene_key: SceneKey::default(),
        }
    }
}

/// How far a bake has come.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BakeProgress {
    /// Probes done (including those a resumed bake already had).
    pub probes_done: usize,
    /// Probes in all (mesh probes counted before placement drops any).
    pub probes_total: usize,
    /// Sections (tiles, then meshes) done and in all.
    pub sections_done: usize,
    pub sections_total: usize,
    /// Since the bake started.
    pub elapsed: Duration,
    /// Probes done in this run (not resumed), for the rate.
    pub probes_this_run: usize,
    /// Rays traced in this run so far: probe rays, bounce rays, ground and inside tests.
    pub rays_traced: u64,
}

impl BakeProgress {
    /// Time left at this run's rate so far; `None` before the first probe.
    pub fn eta(&self) -> Option<Duration> {
        if self.probes_this_run == 0 {
            return None;
        }
        let left = self.probes_total.saturating_sub(self.probes_done) as f64;
        Some(self.elapsed.mul_f64(left / self.probes_this_run as f64))
    }
}

/// What the grid's settings are recorded as in the file.
pub fn bake_settings(options: &SceneBakeOptions) -> BakeSettings {
    BakeSettings {
        rays_per_probe: options.grid.rays_per_probe,
        grid_spacing_m: options.grid.spacing,
        layer_heights_m: options.grid.heights,
    }
}

/// Bakes `scene` from scratch. `progress` is called on the calling thread after every batch
/// of probes.
pub fn bake_scene(
    scene: &Scene,
    options: &SceneBakeOptions,
    progress: &dyn Fn(BakeProgress),
) -> Result<Bake, BakeError> {
    let fresh = Bake::new(options.scene_key, bake_settings(options));
    bake_scene_resume(scene, options, fresh, progress, &mut |_| {
        ControlFlow::Continue(())
    })
}

fn check(options: &SceneBakeOptions) -> Result<(), BakeError> {
    crate::check(&options.grid)?;
    let bad = |option, value: String, why| Err(BakeError::BadOption { option, value, why });
    if options.grid.probes_per_tile as usize != hikari_probes::model::TILE_PROBES_X {
        return bad(
            "probes_per_tile",
            options.grid.probes_per_tile.to_string(),
            "the bake file's tiles hold 16 x 16 columns",
        );
    }
    if !(options.enclosure_radius.is_finite() && options.enclosure_radius > 0.0) {
        return bad(
            "enclosure_radius",
            options.enclosure_radius.to_string(),
            "must be a positive number of metres",
        );
    }
    if !(0.0..=1.0).contains(&options.interior_enclosed_fraction) {
        return bad(
            "interior_enclosed_fraction",
            options.interior_enclosed_fraction.to_string(),
            "must be in 0..=1",
        );
    }
    if !(0.0..0.25).contains(&options.volume_jitter) {
        return bad(
            "volume_jitter",
            options.volume_jitter.to_string(),
            "must be in 0..0.25 of the spacing",
        );
    }
    Ok(())
}

/// What the transport tracers are given: the probe rays, bounce rays and enclosure radius of
/// `options`.
pub fn transport_settings(options: &SceneBakeOptions) -> TransportSettings {
    TransportSettings {
        sphere: SphereRays::fibonacci(options.grid.rays_per_probe),
        bounce_rays: options.bounce_rays,
        enclosure_radius: options.enclosure_radius,
    }
}

struct Tracer<'a> {
    rays: &'a SceneRays,
    inside: &'a SphereRays,
    options: &'a SceneBakeOptions,
    /// Rays traced so far, by all threads.
    traced: AtomicU64,
}

/// Traces the probes of `placed` that have a position (in order, `seed(i)` for the `i`-th of
/// `placed`) through `transport`; those without one get zero transport and stay exterior.
fn trace_batch(
    tracer: &Tracer<'_>,
    transport: &dyn TransportTracer,
    placed: &[Option<Vec3>],
    seed: impl Fn(usize) -> u64,
) -> Result<Vec<(ProbeSh, bool)>, BakeError> {
    let requests: Vec<ProbeRequest> = placed
        .iter()
        .enumerate()
        .filter_map(|(i, p)| {
            p.map(|position| ProbeRequest {
                position,
                seed: seed(i),
            })
        })
        .collect();
    let traced = transport.trace(&requests)?;
    if traced.len() != requests.len() {
        return Err(BakeError::Tracer {
            tracer: transport.name().into(),
            message: format!(
                "{} probes asked for, {} transports returned",
                requests.len(),
                traced.len()
            ),
        });
    }
    let mut traced = traced.into_iter();
    Ok(placed
        .iter()
        .map(|p| match p.and_then(|_| traced.next()) {
            Some(t) => {
                tracer.count(t.rays);
                tracer.probe(&t)
            }
            None => (ProbeSh::default(), false),
        })
        .collect())
}

impl Tracer<'_> {
    fn count(&self, rays: u64) {
        self.traced.fetch_add(rays, Ordering::Relaxed);
    }

    fn probe(&self, t: &ProbeTransport) -> (ProbeSh, bool) {
        (
            ProbeSh {
                sky_visibility: t.sky_visibility,
                bounced_sky_visibility: t.bounced,
            },
            t.enclosed_fraction >= self.options.interior_enclosed_fraction,
        )
    }

    /// A mesh probe out of geometry: where it is, or moved along ±x, ±y, ±z by up to 40 % of
    /// the spacing; `None` to drop it.
    fn free_position(&self, at: Vec3, spacing: f32, stacks: &mut TraversalStacks) -> Option<Vec3> {
        let inside = |p: Vec3, stacks: &mut TraversalStacks| {
            self.count(self.inside.len() as u64);
            placement::inside_geometry(
                self.rays,
                self.inside,
                p,
                self.options.grid.inside_back_face_fraction,
                stacks,
            )
        };
        if !inside(at, stacks) {
            return Some(at);
        }
        let dirs = [
            Vec3::Y,
            Vec3::X,
            Vec3::NEG_X,
            Vec3::Z,
            Vec3::NEG_Z,
            Vec3::NEG_Y,
        ];
        for step in 1..=4 {
            for d in dirs {
                let p = at + d * (0.1 * step as f32 * spacing);
                if !inside(p, stacks) {
                    return Some(p);
                }
            }
        }
        None
    }
}

/// Bakes what `bake` (a fresh or resumed bake of the same scene key and settings) lacks,
/// tracing the transport on the CPU. `checkpoint` is called after every finished section with
/// the bake so far.
pub fn bake_scene_resume(
    scene: &Scene,
    options: &SceneBakeOptions,
    bake: Bake,
    progress: &dyn Fn(BakeProgress),
    checkpoint: &mut dyn FnMut(&Bake) -> ControlFlow<()>,
) -> Result<Bake, BakeError> {
    bake_scene_resume_with(scene, options, bake, None, progress, checkpoint)
}

/// [`bake_scene_resume`] with the transport's rays traced by `transport` (built for this
/// scene and [`transport_settings`] of `options`); `None` traces them on the CPU. Probe
/// placement (ground, inside tests) runs on the CPU either way, through the tracer's BVH when
/// it offers one.
pub fn bake_scene_resume_with(
    scene: &Scene,
    options: &SceneBakeOptions,
    mut bake: Bake,
    transport: Option<&dyn TransportTracer>,
    progress: &dyn Fn(BakeProgress),
    checkpoint: &mut dyn FnMut(&Bake) -> ControlFlow<()>,
) -> Result<Bake, BakeError> {
    check(options)?;
    if bake.settings != bake_settings(options) || bake.scene != options.scene_key {
        return Err(BakeError::Scene(
            "the bake to resume was made for another scene key or other settings".into(),
        ));
    }
    if let Some(t) = transport {
        let s = t.settings();
        if s.sphere.len() != options.grid.rays_per_probe.max(1) as usize
            || s.bounce_rays != options.bounce_rays
            || s.enclosure_radius != options.enclosure_radius
        {
            return Err(BakeError::Tracer {
                tracer: t.name().into(),
                message: format!(
                    "it was built for {} rays a probe, {} bounce rays and a {} m enclosure \
                     radius, but the bake asks for {}, {} and {} m",
                    s.sphere.len(),
                    s.bounce_rays,
                    s.enclosure_radius,
                    options.grid.rays_per_probe,
                    options.bounce_rays,
                    options.enclosure_radius
                ),
            });
        }
    }
    let start = Instant::now();
    let built;
    let rays = match transport.and_then(|t| t.scene_rays()) {
        Some(r) => r,
        None => {
            built = SceneRays::build(scene)?;
            &built
        }
    };
    // The CPU tracer's tables cost a pass over the textures; only built when it is used.
    let cpu_parts = transport
        .is_none()
        .then(|| (SurfaceAlbedo::new(scene), transport_settings(options)));
    let cpu = cpu_parts.as_ref().map(|(albedo, settings)| CpuTransport {
        scene: rays,
        albedo,
        settings,
    });
    let transport: &dyn TransportTracer = match (transport, &cpu) {
        (Some(t), _) => t,
        (None, Some(c)) => c,
        (None, None) => unreachable!("the CPU tracer is built when none is given"),
    };
    let inside = SphereRays::fibonacci(options.grid.inside_test_rays);
    let tracer = Tracer {
        rays,
        inside: &inside,
        options,
        traced: AtomicU64::new(0),
    };
    let grid = &options.grid;
    let n = grid.probes_per_tile as usize;
    let layout = scene
        .bounds()
        .map(|(lo, hi)| (GridLayout::plan(lo, hi, grid), lo, hi));
    let tile_count = layout.map_or(0, |(l, _, _)| (l.tiles_x * l.tiles_z) as usize);
    let probes_per_tile = n * n * LAYERS;
    let lattices: Vec<Vec<Vec3>> = options
        .volumes
        .iter()
        .map(|v| v.lattice(options.volume_jitter))
        .collect::<Result<_, _>>()?;
    let total = tile_count * probes_per_tile + lattices.iter().map(Vec::len).sum::<usize>();
    let sections_total = tile_count + lattices.len();
    let mut done = 0usize;
    let mut this_run = 0usize;
    let mut sections_done = 0usize;
    let report = |done: usize, this_run: usize, sections_done: usize| {
        progress(BakeProgress {
            probes_done: done,
            probes_total: total,
            sections_done,
            sections_total,
            elapsed: start.elapsed(),
            probes_this_run: this_run,
            rays_traced: tracer.traced.load(Ordering::Relaxed),
        })
    };
    report(0, 0, 0);

    if let Some((layout, lo, hi)) = layout {
        let tile_size = grid.spacing * n as f32;
        for t in 0..tile_count {
            let (tx, tz) = (t as u32 % layout.tiles_x, t as u32 / layout.tiles_x);
            if bake.has_tile([tx as i32, tz as i32]) {
                done += probes_per_tile;
                sections_done += 1;
                report(done, this_run, sections_done);
                continue;
            }
            let origin = layout.origin + tile_size * Vec2::new(tx as f32, tz as f32);
            let column_xz =
                |c: usize| origin + grid.spacing * Vec2::new((c % n) as f32, (c / n) as f32);
            let top = hi.y + 1.0;
            let ground: Vec<f32> = (0..n * n)
                .into_par_iter()
                .map_init(TraversalStacks::default, |stacks, c| {
                    let xz = column_xz(c);
                    let (y, traced) = placement::ground_height(rays, xz.x, xz.y, top, lo.y, stacks);
                    tracer.count(traced);
                    y
                })
                .collect();
            let mut probes = Vec::with_capacity(probes_per_tile);
            let mut interior = Vec::with_capacity(probes_per_tile);
            let batch_size = grid.progress_batch.min(transport.batch_size()).max(1);
            for batch in (0..probes_per_tile).step_by(batch_size) {
                let end = (batch + batch_size).min(probes_per_tile);
                let placed: Vec<Option<Vec3>> = (batch..end)
                    .into_par_iter()
                    .map_init(TraversalStacks::default, |stacks, k| {
                        let (layer, c) = (k / (n * n), k % (n * n));
                        let xz = column_xz(c);
                        let planned = Vec3::new(xz.x, ground[c] + grid.heights[layer], xz.y);
                        let (placed, traced) = place_probe(rays, &inside, planned, grid, stacks);
                        tracer.count(traced);
                        placed.map(|(at, _)| at)
                    })
                    .collect();
                let out = trace_batch(&tracer, transport, &placed, |i| {
                    ((t as u64) << 32) | (batch + i) as u64
                })?;
                for (p, i) in out {
                    probes.push(p);
                    interior.push(i);
                }
                done += end - batch;
                this_run += end - batch;
                report(done, this_run, sections_done);
            }
            debug_assert_eq!(ground.len(), TILE_COLUMNS);
            bake.tiles.push(GridTile {
                tile: [tx as i32, tz as i32],
                origin_xz: origin.to_array(),
                ground_heights_m: ground,
                probes,
                interior,
            });
            sections_done += 1;
            report(done, this_run, sections_done);
            if checkpoint(&bake).is_break() {
                return Err(BakeError::Cancelled);
            }
        }
    }

    for (m, (volume, lattice)) in options.volumes.iter().zip(&lattices).enumerate() {
        let id = m as u32;
        if bake.has_mesh(id) {
            done += lattice.len();
            sections_done += 1;
            report(done, this_run, sections_done);
            continue;
        }
        let placed: Vec<Option<Vec3>> = lattice
            .par_iter()
            .map_init(TraversalStacks::default, |stacks, &p| {
                tracer.free_position(p, volume.spacing, stacks)
            })
            .collect();
        let positions: Vec<Vec3> = placed.into_iter().flatten().collect();
        let dropped = lattice.len() - positions.len();
        done += dropped;
        this_run += dropped;
        let mut probes = Vec::with_capacity(positions.len());
        let mut interior = Vec::with_capacity(positions.len());
        let batch_size = grid.progress_batch.min(transport.batch_size()).max(1);
        for batch in (0..positions.len()).step_by(batch_size) {
            let end = (batch + batch_size).min(positions.len());
            let placed: Vec<Option<Vec3>> =
                positions[batch..end].iter().copied().map(Some).collect();
            let out = trace_batch(&tracer, transport, &placed, |k| {
                (u64::from(id) | 1 << 31) << 32 | (batch + k) as u64
            })?;
            for (p, i) in out {
                probes.push(p);
                interior.push(i);
            }
            done += end - batch;
            this_run += end - batch;
            report(done, this_run, sections_done);
        }
        let (tets, adjacency) = if positions.len() >= 4 {
            let points: Vec<[f64; 3]> = positions.iter().map(|p| p.as_dvec3().to_array()).collect();
            let t = tetrahedralize(&points).map_err(|e| BakeError::Tetrahedralize {
                volume: volume.name.clone(),
                source: e,
            })?;
            (t.tets, t.adjacency)
        } else {
            // Too few probes survived to make a tetrahedron: the grid covers this volume.
            (Vec::new(), Vec::new())
        };
        bake.meshes.push(TetMesh {
            id,
            positions: positions.iter().map(|p| p.to_array()).collect(),
            probes,
            interior,
            tets,
            adjacency,
        });
        sections_done += 1;
        report(done, this_run, sections_done);
        if checkpoint(&bake).is_break() {
            return Err(BakeError::Cancelled);
        }
    }
    hikari_probes::validate(&bake)
        .map_err(|p| BakeError::Scene(format!("the bake failed its own checks: {p}")))?;
    bake.complete = true;
    Ok(bake)
}

/// A bake written to its file.
#[derive(Debug)]
pub struct BakedFile {
    pub bake: Bake,
    /// Tiles and meshes taken from a checkpoint instead of baked.
    pub resumed_sections: usize,
    /// Why a checkpoint that existed was not used (other scene, settings or version, or
    /// corrupt), for a warning.
    pub discarded_checkpoint: Option<hikari_probes::BakeFileError>,
}

/// Bakes `scene` into `path`: resumes from `<path>.partial` when that holds a checkpoint of
/// the same scene key and settings, saves a checkpoint after a finished tile or mesh when
/// `checkpoint_interval` has passed since the last one, and when `cancel` is set (checked
/// after every tile or mesh; the bake then stops with [`BakeError::Cancelled`] and the next
/// call resumes it); at the end writes `path` atomically and removes the checkpoint.
pub fn bake_to_file(
    scene: &Scene,
    options: &SceneBakeOptions,
    path: &Path,
    progress: &dyn Fn(BakeProgress),
    cancel: &AtomicBool,
    checkpoint_interval: Duration,
) -> Result<BakedFile, BakeError> {
    bake_to_file_with(
        scene,
        options,
        path,
        None,
        progress,
        cancel,
        checkpoint_interval,
    )
}

/// [`bake_to_file`] with the transport traced by `transport` (`None`: the CPU). The file does
/// not record which tracer made it: their results agree within rounding, so a checkpoint of
/// one may be finished by the other.
pub fn bake_to_file_with(
    scene: &Scene,
    options: &SceneBakeOptions,
    path: &Path,
    transport: Option<&dyn TransportTracer>,
    progress: &dyn Fn(BakeProgress),
    cancel: &AtomicBool,
    checkpoint_interval: Duration,
) -> Result<BakedFile, BakeError> {
    let resumed = hikari_probes::resume(path, options.scene_key, bake_settings(options));
    let resumed_sections = resumed.bake.tiles.len() + resumed.bake.meshes.len();
    let mut last_save = Instant::now();
    let mut save_error = None;
    let result = bake_scene_resume_with(
        scene,
        options,
        resumed.bake,
        transport,
        progress,
        &mut |bake| {
            let stop = cancel.load(Ordering::Relaxed);
            if stop || last_save.elapsed() >= checkpoint_interval {
                if let Err(e) = hikari_probes::save_checkpoint(path, bake) {
                    save_error = Some(e.to_string());
                    return ControlFlow::Break(());
                }
                last_save = Instant::now();
            }
            if stop {
                ControlFlow::Break(())
            } else {
                ControlFlow::Continue(())
            }
        },
    );
    if let Some(e) = save_error {
        return Err(BakeError::File(e));
    }
    let bake = hikari_probes::finish(path, result?).map_err(|e| BakeError::File(e.to_string()))?;
    Ok(BakedFile {
        bake,
        resumed_sections,
        discarded_checkpoint: resumed.discarded,
    })
}
