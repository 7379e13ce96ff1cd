//! The scene's irradiance-probe bake, shared by `hikari bake`, `hikari probes` and `hikari
//! render`: the scene's content key, the cache under `$XDG_CACHE_HOME/hikari` (default
//! `~/.cache/hikari`), baking with a progress line, and reading a given file.
//!
//! Bad files: a file given with `--bake` that is missing, truncated, corrupt, of another
//! version or another scene is an error naming the file and the problem; a bad file in the
//! cache is baked again with a warning saying why.

use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use anyhow::Context;

use hikari_bake::{BakeStats, GridBake, GridBakeOptions};
use hikari_probes::{Bake, BakeSettings, GridTile, ProbeSh, Problem, SceneKey, TILE_PROBE_COUNT};
use hikari_scene::Scene;

/// Bumped when the baker's output changes for the same scene and options, so that caches made
/// by an older baker are not reused.
const BAKER_VERSION: u32 = 1;

/// The options `hikari render` and `hikari bake` bake with.
pub fn options() -> GridBakeOptions {
    GridBakeOptions::default()
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
/// instances, the materials' colours, alpha and interior values, textures, the options and
/// the baker's version).
pub fn scene_key(scene: &Scene, options: &GridBakeOptions) -> SceneKey {
    let mut h = Hasher(0xcbf2_9ce4_8422_2325);
    h.word(BAKER_VERSION);
    h.word(options.rays_per_probe);
    h.word(options.probes_per_tile);
    h.word(options.inside_test_rays);
    h.f32s([
        options.spacing,
        options.inside_back_face_fraction,
        options.lift_step,
        options.max_lift,
    ]);
    h.f32s(options.heights);
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

/// A progress line on stderr (only on a terminal): a bar, the count and the time left.
pub struct Progress {
    label: &'static str,
    start: Instant,
    last: Option<Instant>,
    tty: bool,
}

impl Progress {
    pub fn new(label: &'static str) -> Self {
        Self {
            label,
            start: Instant::now(),
            last: None,
            tty: std::io::stderr().is_terminal(),
        }
    }

    /// `done` of `total` units finished.
    pub fn update(&mut self, done: usize, total: usize) {
        if !self.tty || total == 0 {
            return;
        }
        let now = Instant::now();
        let finished = done >= total;
        if !finished
            && self
                .last
                .is_some_and(|t| now - t < Duration::from_millis(100))
        {
            return;
        }
        self.last = Some(now);
        let f = done as f64 / total as f64;
        let elapsed = self.start.elapsed().as_secs_f64();
        let eta = if done > 0 {
            format!("{:.1} s left", elapsed * (1.0 - f) / f)
        } else {
            "estimating".into()
        };
        let bar: String = (0..30)
            .map(|i| if (i as f64) < f * 30.0 { '#' } else { '.' })
            .collect();
        eprint!(
            "\r{} [{bar}] {:3.0}% {done}/{total}, {eta}   ",
            self.label,
            f * 100.0
        );
        if finished {
            eprintln!();
        }
    }
}

/// hikari-bake's grid in the bake file's model. Bounced sky visibility and interior flags are
/// not baked yet (zero and false); tetrahedral meshes neither.
pub fn to_probe_bake(grid: &GridBake, key: SceneKey) -> anyhow::Result<Bake> {
    let o = &grid.options;
    if o.probes_per_tile as usize * o.probes_per_tile as usize * hikari_bake::LAYERS
        != TILE_PROBE_COUNT
    {
        anyhow::bail!(
            "the bake file holds tiles of 16x16x3 probes, not {}x{}x3",
            o.probes_per_tile,
            o.probes_per_tile
        );
    }
    let mut bake = Bake::new(
        key,
        BakeSettings {
            rays_per_probe: o.rays_per_probe,
            grid_spacing_m: o.spacing,
            layer_heights_m: o.heights,
        },
    );
    for t in &grid.tiles {
        bake.tiles.push(GridTile {
            tile: [t.index[0] as i32, t.index[1] as i32],
            origin_xz: t.origin.to_array(),
            ground_heights_m: t.ground.clone(),
            probes: t
                .probes
                .iter()
                .map(|p| ProbeSh {
                    sky_visibility: p.sky_visibility,
                    bounced_sky_visibility: [[0.0; 3]; 9],
                })
                .collect(),
            interior: vec![false; t.probes.len()],
        });
    }
    bake.complete = true;
    Ok(bake)
}

/// Bakes `scene` on the CPU with a progress line.
///
/// The one place the baker is called: when hikari-bake gains bounced visibility, tetrahedral
/// meshes and its own progress reports, this is what changes.
pub fn bake_scene(scene: &Scene, key: SceneKey) -> anyhow::Result<(Bake, BakeStats)> {
    let mut progress = Progress::new("baking probes");
    let grid = hikari_bake::bake_grid_sky_visibility(scene, &options(), |done, total| {
        progress.update(done, total)
    })
    .context("baking the irradiance probes")?;
    Ok((to_probe_bake(&grid, key)?, grid.stats))
}

/// Writes `bake` atomically, making the folder first.
pub fn write(path: &Path, bake: &Bake) -> anyhow::Result<()> {
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir)
            .with_context(|| format!("creating the folder {}", dir.display()))?;
    }
    hikari_probes::write_bake(path, bake)?;
    Ok(())
}

/// The bake to render `scene` with: `given` (any problem with it is an error naming the file),
/// else the cache's, baked and cached on a miss; a bad cache file is baked again with a
/// warning. A cache that cannot be written is a warning too: the frame still renders.
pub fn for_render(scene: &Scene, given: Option<&Path>) -> anyhow::Result<Bake> {
    let key = scene_key(scene, &options());
    if let Some(path) = given {
        return hikari_probes::read_bake(path, &key)
            .map_err(anyhow::Error::from)
            .context("--bake");
    }
    let path = cache_path(&key);
    match hikari_probes::read_bake(&path, &key) {
        Ok(b) => {
            log::info!("probes: cached bake {}", path.display());
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
    let (bake, stats) = bake_scene(scene, key)?;
    log::info!(
        "probes: baked {} probes in {:.1} s",
        stats.probes,
        stats.total_seconds
    );
    if let Err(e) = write(&path, &bake) {
        log::warn!("probes: could not cache the bake: {e:#}");
    }
    Ok(bake)
}

/// Gives `renderer` the scene's bake ([`for_render`]) when the frame's settings use the
/// probes (they light only what the sky lights); `given` is `--bake`.
pub fn attach(
    renderer: &mut hikari_render::Renderer,
    scene: &Scene,
    settings: &hikari_render::FrameSettings,
    given: Option<&Path>,
) -> anyhow::Result<()> {
    let s = &settings.settings;
    if s.irradiance_probes.enabled && s.sky.enabled && s.sky.sky {
        let bake = for_render(scene, given)?;
        renderer.set_probe_bake(Some(&bake));
    } else if let Some(path) = given {
        log::warn!(
            "--bake {}: not used, the probes or the sky's light are off",
            path.display()
        );
    }
    Ok(())
}
