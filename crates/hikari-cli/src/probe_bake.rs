//! The scene's irradiance-probe bake, shared by `hikari bake`, `hikari probes` and `hikari
//! render`: the scene's probe volumes, its content key, the cache under `$XDG_CACHE_HOME/hikari`
//! (default `~/.cache/hikari`), baking with a progress bar (hikari-bake's `bake_to_file`:
//! grid and tetrahedral meshes, sky and bounced sky visibility, interior flags) that resumes
//! from `<file>.partial` after an interruption, and reading a given file.
//!
//! Bad files: a file given with `--bake` that is missing, truncated, corrupt, of another
//! version or another scene is an error naming the file and the problem; a bad file in the
//! cache is baked again with a warning saying why.

use std::cell::RefCell;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use anyhow::Context;

use hikari_bake::{BakeError, BakeProgress, ProbeVolume, SceneBakeOptions, TransportTracer};
use hikari_probes::{Bake, Problem, SceneKey};
use hikari_render::GpuContext;
use hikari_render::probe_bake_gpu::{GpuTransport, is_real_gpu};
use hikari_scene::Scene;

use crate::progress::{Counter, Step};
use crate::scene_source::SceneSource;

/// Bumped when the baker's output changes for the same scene and options, so that caches made
/// by an older baker are not reused. 2: bounced sky visibility, interior flags, meshes.
const BAKER_VERSION: u32 = 2;

/// Which tracer traces a bake's transport rays (probe placement is on the CPU either way).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum TracerChoice {
    /// The GPU when the adapter is a real one (not a CPU driver such as lavapipe), else the
    /// CPU on all cores.
    #[default]
    Auto,
    /// The GPU adapter wgpu picks, whatever it is (lavapipe included): an error without one.
    Gpu,
    /// hikari-bvh's CPU traversal on all cores.
    Cpu,
}

impl TracerChoice {
    /// `HIKARI_BAKE_TRACER` (auto, gpu or cpu), for the bake `hikari render` makes on a cache
    /// miss; auto when unset.
    pub fn from_env() -> anyhow::Result<Self> {
        match std::env::var("HIKARI_BAKE_TRACER") {
            Err(_) => Ok(Self::Auto),
            Ok(v) => <Self as clap::ValueEnum>::from_str(&v, true).map_err(|_| {
                anyhow::anyhow!("HIKARI_BAKE_TRACER is `{v}`; it must be auto, gpu or cpu")
            }),
        }
    }

    /// Whether to bake on `ctx`'s adapter.
    pub fn uses_gpu(self, ctx: &GpuContext) -> bool {
        match self {
            Self::Auto => is_real_gpu(ctx),
            Self::Gpu => true,
            Self::Cpu => false,
        }
    }
}

/// The GPU tracer for `scene` on `ctx` when `choice` picks the GPU there; `None` for the CPU.
pub fn gpu_tracer<'a>(
    choice: TracerChoice,
    ctx: Option<&'a GpuContext>,
    scene: &Scene,
    options: &SceneBakeOptions,
) -> anyhow::Result<Option<GpuTransport<'a>>> {
    let Some(ctx) = ctx.filter(|c| choice.uses_gpu(c)) else {
        if choice == TracerChoice::Gpu {
            anyhow::bail!(
                "the GPU tracer was asked for (--tracer gpu or HIKARI_BAKE_TRACER=gpu), but \
                 this command has no GPU adapter to bake on"
            );
        }
        return Ok(None);
    };
    let t = GpuTransport::new(ctx, scene, hikari_bake::transport_settings(options))
        .with_context(|| format!("preparing the GPU probe bake on {}", ctx.describe()))?;
    log::info!("probes: tracing the bake on {}", ctx.describe());
    Ok(Some(t))
}

/// Seconds between checkpoints (`<file>.partial`) of a running bake.
const CHECKPOINT_INTERVAL: Duration = Duration::from_secs(2);

/// The probe volumes (tetrahedral meshes) of a scene: the village's houses, temple and
/// courtyard for the built-in village, the volumes a glTF file marks in its nodes' `extras`.
pub fn volumes(source: &SceneSource) -> anyhow::Result<Vec<ProbeVolume>> {
    Ok(match source {
        SceneSource::Builtin(name) => hikari_bake::volumes::builtin_volumes(name),
        SceneSource::Gltf(path) => hikari_bake::volumes::gltf_volumes(path)?,
    })
}

/// The options `hikari render`, `hikari probes` and `hikari bake` bake `scene` with: the
/// default grid and bounce, `source`'s volumes, and the key of all of it
/// ([`scene_key`]).
pub fn options(scene: &Scene, source: &SceneSource) -> anyhow::Result<SceneBakeOptions> {
    let mut o = SceneBakeOptions {
        volumes: volumes(source)?,
        ..Default::default()
    };
    o.scene_key = scene_key(scene, &o);
    Ok(o)
}

/// 64-bit FNV-1a, word by word: fast enough for the village's geometry in a debug build.
struct Hasher(u64);

impl Hasher {
    fn word(&mut self, w: u32) {
        for b in w.to_le_bytes() {
            self.0 = (self.0 ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3);
        }
    }
    /// Bulk bytes (textures), eight at a time.
    fn bytes(&mut self, data: &[u8]) {
        let mut chunks = data.chunks_exact(8);
        for c in &mut chunks {
            let w = u64::from_le_bytes([c[0], c[1], c[2], c[3], c[4], c[5], c[6], c[7]]);
            self.0 = (self.0 ^ w)
                .wrapping_mul(0x0000_0100_0000_01b3)
                .rotate_left(29);
        }
        for &b in chunks.remainder() {
            self.0 = (self.0 ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3);
        }
    }
    fn f32s(&mut self, v: impl IntoIterator<Item = f32>) {
        for x in v {
            self.word(x.to_bits());
        }
    }
}

/// The key of `scene`'s bake with `options`: a hash of everything the bake reads (geometry,
/// instances, the materials' colours, alpha and interior values, textures), of every option
/// (grid, rays, bounce rays, volumes, interior classification, jitter) and of the baker's
/// version. `options.scene_key` itself is not hashed.
pub fn scene_key(scene: &Scene, options: &SceneBakeOptions) -> SceneKey {
    let mut h = Hasher(0xcbf2_9ce4_8422_2325);
    h.word(BAKER_VERSION);
    let g = &options.grid;
    h.word(g.rays_per_probe);
    h.word(g.probes_per_tile);
    h.word(g.inside_test_rays);
    h.f32s([
        g.spacing,
        g.inside_back_face_fraction,
        g.lift_step,
        g.max_lift,
    ]);
    h.f32s(g.heights);
    h.word(options.bounce_rays);
    h.f32s([
        options.enclosure_radius,
        options.interior_enclosed_fraction,
        options.volume_jitter,
    ]);
    h.word(options.volumes.len() as u32);
    for v in &options.volumes {
        h.bytes(v.name.as_bytes());
        h.word(v.name.len() as u32);
        h.f32s(v.transform.to_cols_array());
        h.f32s([v.spacing]);
    }
    for m in &scene.meshes {
        h.word(m.positions.len() as u32);
        h.f32s(m.positions.iter().flat_map(|p| p.to_array()));
        h.word(m.indices.len() as u32);
        for &i in &m.indices {
            h.word(i);
        }
    }
    for inst in &scene.instances {
        h.word(inst.mesh as u32);
        h.word(inst.material as u32);
        h.f32s(inst.transform.to_cols_array());
    }
    for mat in &scene.materials {
        h.f32s(mat.base_color.to_array());
        h.f32s([mat.alpha, mat.metalness, mat.interior.unwrap_or(-1.0)]);
        match mat.alpha_mode {
            hikari_scene::AlphaMode::Opaque => h.word(0),
            hikari_scene::AlphaMode::Mask { cutoff } => h.f32s([1.0, cutoff]),
            hikari_scene::AlphaMode::Blend => h.word(2),
        }
        h.word(mat.double_sided as u32);
        h.word(
            mat.base_color_texture
                .map_or(u32::MAX, |t| t.texture as u32),
        );
    }
    // Cut-outs and albedo come from textures too.
    for t in &scene.textures {
        h.word(t.width);
        h.word(t.height);
        h.bytes(&t.data);
    }
    SceneKey::from_u64(h.0)
}

/// Where the cache keeps bakes: `$XDG_CACHE_HOME/hikari`, else `~/.cache/hikari`.
pub fn cache_dir() -> PathBuf {
    let xdg = std::env::var_os("XDG_CACHE_HOME").map(PathBuf::from);
    match xdg.filter(|p| p.is_absolute()) {
        Some(p) => p.join("hikari"),
        None => match std::env::var_os("HOME") {
            Some(home) => PathBuf::from(home).join(".cache").join("hikari"),
            None => std::env::temp_dir().join("hikari-cache"),
        },
    }
}

/// The cached bake file of the scene with this key.
pub fn cache_path(key: &SceneKey) -> PathBuf {
    cache_dir().join(format!("probes-{key}.hikprobe"))
}

/// Set by Ctrl-C while a bake runs: the bake saves its checkpoint and stops.
static CANCEL: AtomicBool = AtomicBool::new(false);

#[cfg(unix)]
extern "C" fn on_interrupt(_: libc::c_int) {
    CANCEL.store(true, Ordering::SeqCst);
    // A second Ctrl-C ends the process at once.
    // SAFETY: signal() is async-signal-safe; SIG_DFL is a valid disposition.
    unsafe {
        libc::signal(libc::SIGINT, libc::SIG_DFL);
    }
}

/// Ctrl-C cancels the bake (after the tile or mesh being baked, with a checkpoint) instead of
/// killing the process, while the guard lives.
struct InterruptGuard;

impl InterruptGuard {
    fn install() -> Self {
        CANCEL.store(false, Ordering::SeqCst);
        #[cfg(unix)]
        // SAFETY: the handler only stores an atomic and resets the disposition, both
        // async-signal-safe.
        unsafe {
            libc::signal(
                libc::SIGINT,
                on_interrupt as extern "C" fn(libc::c_int) as libc::sighandler_t,
            );
        }
        Self
    }
}

impl Drop for InterruptGuard {
    fn drop(&mut self) {
        #[cfg(unix)]
        // SAFETY: restoring the default disposition.
        unsafe {
            libc::signal(libc::SIGINT, libc::SIG_DFL);
        }
    }
}

/// The bake's progress bar (`crate::progress`: on a terminal, not with `--quiet`): probes
/// done of all, tiles and meshes, the time left.
pub struct Progress {
    label: &'static str,
    bar: Option<Counter>,
    /// The latest report, for the summary.
    pub latest: Option<BakeProgress>,
}

impl Progress {
    pub fn new(label: &'static str) -> Self {
        Self {
            label,
            bar: None,
            latest: None,
        }
    }

    pub fn update(&mut self, p: BakeProgress) {
        self.latest = Some(p);
        if p.probes_total == 0 {
            return;
        }
        let label = self.label;
        let bar = self
            .bar
            .get_or_insert_with(|| Counter::without_eta(label, p.probes_total as u64, "probes"));
        bar.set_total(p.probes_total as u64);
        bar.set_position(p.probes_done as u64);
        let eta = match p.eta() {
            Some(d) => format!("{:.0} s left", d.as_secs_f64()),
            None => "estimating the time left".into(),
        };
        bar.set_message(format!(
            "{label} ({}/{} tiles and meshes, {eta})",
            p.sections_done, p.sections_total
        ));
    }

    /// Leaves the bar as a line: probes baked and the time.
    pub fn finish(&mut self) {
        if let Some(bar) = self.bar.take() {
            bar.done("baked the irradiance probes");
        }
    }
}

/// What a bake run did, for `hikari bake`'s summary.
pub struct BakeRun {
    pub bake: Bake,
    /// Tiles and meshes taken from `<file>.partial`.
    pub resumed_sections: usize,
    /// Rays traced in this run (probe, bounce, ground and inside-test rays).
    pub rays: u64,
    pub seconds: f64,
    /// "gpu" or "cpu": what traced the transport.
    pub tracer: String,
}

/// Bakes `scene` into `path` with a progress bar: resumes from `<path>.partial`, checkpoints
/// every few seconds, and Ctrl-C stops it with a checkpoint (the next run resumes it).
/// `tracer` traces the transport (`None`: the CPU).
pub fn bake_into(
    scene: &Scene,
    options: &SceneBakeOptions,
    path: &Path,
    tracer: Option<&dyn TransportTracer>,
) -> anyhow::Result<BakeRun> {
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir)
            .with_context(|| format!("creating the folder {}", dir.display()))?;
    }
    let progress = RefCell::new(Progress::new("baking probes"));
    let start = Instant::now();
    let guard = InterruptGuard::install();
    let result = hikari_bake::bake_to_file_with(
        scene,
        options,
        path,
        tracer,
        &|p| progress.borrow_mut().update(p),
        &CANCEL,
        CHECKPOINT_INTERVAL,
    );
    drop(guard);
    let baked = match result {
        Ok(b) => b,
        Err(BakeError::Cancelled) => {
            anyhow::bail!(
                "the bake of {} was interrupted; its checkpoint {} resumes it on the next run",
                path.display(),
                hikari_probes::partial_path(path).display()
            )
        }
        Err(e) => {
            return Err(anyhow::Error::from(e))
                .with_context(|| format!("baking the irradiance probes into {}", path.display()));
        }
    };
    progress.borrow_mut().finish();
    if let Some(why) = &baked.discarded_checkpoint {
        log::warn!("probes: an old checkpoint was not used: {why}");
    }
    if baked.resumed_sections > 0 {
        log::info!(
            "probes: resumed {} tiles and meshes from {}",
            baked.resumed_sections,
            hikari_probes::partial_path(path).display()
        );
    }
    let rays = progress.borrow().latest.map_or(0, |p| p.rays_traced);
    Ok(BakeRun {
        bake: baked.bake,
        resumed_sections: baked.resumed_sections,
        rays,
        seconds: start.elapsed().as_secs_f64(),
        tracer: tracer.map_or("cpu", |t| t.name()).into(),
    })
}

/// The bake to render `scene` (from `source`) with: `given` (any problem with it is an error
/// naming the file), else the cache's, baked into the cache on a miss (resuming an interrupted
/// one) on `ctx`'s GPU when `HIKARI_BAKE_TRACER` (default auto) picks it; a bad cache file is
/// baked again with a warning.
pub fn for_render(
    scene: &Scene,
    source: &SceneSource,
    given: Option<&Path>,
    ctx: Option<&GpuContext>,
) -> anyhow::Result<Bake> {
    let options = options(scene, source)?;
    let key = options.scene_key;
    if let Some(path) = given {
        return hikari_probes::read_bake(path, &key)
            .map_err(anyhow::Error::from)
            .context("--bake");
    }
    let path = cache_path(&key);
    let step = Step::start("reading the probe bake from the cache");
    match hikari_probes::read_bake(&path, &key) {
        Ok(b) => {
            log::info!("probes: cached bake {}", path.display());
            step.done(format!("probe bake from the cache, {}", path.display()));
            return Ok(b);
        }
        Err(e) if matches!(e.problem, Problem::Missing) => {
            log::info!(
                "probes: no cached bake for this scene; baking {}",
                path.display()
            );
        }
        Err(e) => log::warn!("{e}; baking the probes again"),
    }
    step.clear();
    let gpu = gpu_tracer(TracerChoice::from_env()?, ctx, scene, &options)?;
    let run = bake_into(
        scene,
        &options,
        &path,
        gpu.as_ref().map(|t| t as &dyn TransportTracer),
    )?;
    log::info!(
        "probes: baked {} probes in {:.1} s ({})",
        run.bake.probe_count(),
        run.seconds,
        run.tracer
    );
    Ok(run.bake)
}

/// The scene's reflection probes: a built-in scene's placements, the probes a glTF file marks
/// in its nodes' `extras`, else one over the scene's bounds (docs/reflection-probes.md).
pub fn reflection_probes(
    scene: &Scene,
    source: &SceneSource,
) -> anyhow::Result<Vec<hikari_bake::reflection_probes::ReflectionProbeBox>> {
    use hikari_bake::reflection_probes as rp;
    let mut probes = match source {
        SceneSource::Builtin(name) => rp::builtin_reflection_probes(name),
        SceneSource::Gltf(path) => rp::gltf_reflection_probes(path)?,
    };
    if probes.is_empty() {
        probes.extend(rp::default_reflection_probe(scene));
    }
    Ok(probes)
}

/// Gives `renderer` the scene's probe data: its irradiance-probe bake ([`for_render`]; `given`
/// is `--bake`) when the settings use the probes (they light only what the sky lights), and
/// its reflection probes ([`reflection_probes`]) when those are on.
pub fn attach(
    renderer: &mut hikari_render::Renderer,
    scene: &Scene,
    source: &SceneSource,
    settings: &hikari_render::FrameSettings,
    given: Option<&Path>,
) -> anyhow::Result<()> {
    let s = &settings.settings;
    if s.irradiance_probes.enabled && s.sky.enabled && s.sky.sky {
        let bake = for_render(scene, source, given, Some(&renderer.ctx))?;
        renderer.set_probe_bake(Some(&bake))?;
    } else if let Some(path) = given {
        log::warn!(
            "--bake {}: not used, the probes or the sky's light are off",
            path.display()
        );
    }
    if s.reflection_probes.enabled && s.sky.enabled {
        let probes = reflection_probes(scene, source)?;
        log::info!("reflection probes: {}", probes.len());
        renderer.set_reflection_probes(&probes)?;
    }
    Ok(())
}
