//! `hikari compare`: one view rendered twice, A and B, differing by settings (`--toggle`,
//! `--a`, `--b`), each on its own renderer with the same frame count; one PNG of A | B | the
//! FLIP error map, and the numbers: the settings that differ, mean and 95th-percentile FLIP,
//! both EV100s and the ratio of B's mean luminance to A's.
//!
//! Exposure. The renderer's exposure feeds back into its lighting (the GI caps each sample
//! relative to last frame's exposure; a fixed EV100 also sets the illuminance the lights'
//! cut-off and the GI's clamp are scaled by, and skips the local tonemap's highlight fit), so
//! "B at A's exposure" is made symmetric: A is first rendered metered to find its EV100, then
//! A and B are both rendered with `exposure.ev100` fixed at it, as `hikari render --ev100`
//! would. Identical settings then give identical images. `--own-exposure` renders each
//! metered instead.

use std::path::PathBuf;

use anyhow::Context;
use clap::Args;
use serde_json::json;

use hikari_render::graph::ImageRgba32;
use hikari_render::{FrameSettings, RenderedFrame, output};

use crate::args::{FrameArgs, JsonArgs};
use crate::progress::{self, ProgressArgs, Step};
use crate::scene_source::{self, ResolvedFrame};
use crate::still::{self, ImageFile};

#[derive(Args, Debug)]
pub struct CompareArgs {
    #[command(flatten)]
    pub frame: FrameArgs,
    /// B has this technique's `enabled` flipped relative to A (e.g. `ray_traced_gi`);
    /// repeatable.
    #[arg(long, value_name = "TECHNIQUE")]
    pub toggle: Vec<String>,
    /// A setting of A only, on top of the shared ones (`--set`, `--config`, preset);
    /// repeatable.
    #[arg(long = "a", value_name = "TABLE.KEY=VALUE", value_parser = crate::config::parse_override)]
    pub a: Vec<(String, String)>,
    /// A setting of B only, on top of the shared ones; repeatable.
    #[arg(long = "b", value_name = "TABLE.KEY=VALUE", value_parser = crate::config::parse_override)]
    pub b: Vec<(String, String)>,
    /// A's preset instead of the shared one (`--preset`): `--preset-a ultra --preset-b low`
    /// shows what a preset gives up.
    #[arg(long, value_name = "PRESET")]
    pub preset_a: Option<hikari_render::Preset>,
    /// B's preset instead of the shared one.
    #[arg(long, value_name = "PRESET")]
    pub preset_b: Option<hikari_render::Preset>,
    /// Meter each image on its own instead of showing both at A's EV100.
    #[arg(long)]
    pub own_exposure: bool,
    /// Frames rendered of each, the last shown [default: the larger of what A and B need,
    /// as `hikari render` counts them].
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=10_000))]
    pub frames: Option<u32>,
    /// The comparison PNG: A | B | FLIP error map (magma: black none, yellow most).
    #[arg(short, long, default_value = "compare.png")]
    pub output: PathBuf,
    /// Also write A's linear image (nits) as this EXR.
    #[arg(long)]
    pub exr_a: Option<PathBuf>,
    /// Also write B's linear image (nits) as this EXR.
    #[arg(long)]
    pub exr_b: Option<PathBuf>,
    /// Irradiance-probe bake file [default: the cache, baked on a miss].
    #[arg(long)]
    pub bake: Option<PathBuf>,
    #[command(flatten)]
    pub json: JsonArgs,
    #[command(flatten)]
    pub progress: ProgressArgs,
}

/// The settings tables as TOML.
fn tables(s: &hikari_render::Settings) -> toml::Table {
    match toml::Value::try_from(s) {
        Ok(toml::Value::Table(t)) => t,
        _ => toml::Table::new(),
    }
}

/// The techniques that have an `enabled` switch, the names `--toggle` takes.
pub fn toggles() -> Vec<String> {
    tables(&hikari_render::Settings::default())
        .into_iter()
        .filter(|(_, t)| t.get("enabled").is_some_and(|v| v.is_bool()))
        .map(|(name, _)| name)
        .collect()
}

/// A setting that differs between A and B: `table.key` and the two values (`None`: absent,
/// an option not set).
#[derive(Debug, Clone, PartialEq)]
pub struct Difference {
    pub key: String,
    pub a: Option<toml::Value>,
    pub b: Option<toml::Value>,
}

/// Every `table.key` (nested keys dotted) whose value differs between `a` and `b`.
pub fn differences(a: &hikari_render::Settings, b: &hikari_render::Settings) -> Vec<Difference> {
    fn walk(
        prefix: &str,
        a: Option<&toml::Value>,
        b: Option<&toml::Value>,
        out: &mut Vec<Difference>,
    ) {
        match (a, b) {
            (Some(toml::Value::Table(ta)), Some(toml::Value::Table(tb))) => {
                let mut keys: Vec<&String> = ta.keys().chain(tb.keys()).collect();
                keys.sort();
                keys.dedup();
                for k in keys {
                    let path = if prefix.is_empty() {
                        k.clone()
                    } else {
                        format!("{prefix}.{k}")
                    };
                    walk(&path, ta.get(k), tb.get(k), out);
                }
            }
            (a, b) if a != b => out.push(Difference {
                key: prefix.to_string(),
                a: a.cloned(),
                b: b.cloned(),
            }),
            _ => {}
        }
    }
    let mut out = Vec::new();
    let (ta, tb) = (toml::Value::Table(tables(a)), toml::Value::Table(tables(b)));
    walk("", Some(&ta), Some(&tb), &mut out);
    out
}

/// FLIP of `test` against `reference`, display images of one size: the per-pixel error map.
pub fn flip(reference: &ImageRgba32, test: &ImageRgba32) -> nv_flip::FlipImageFloat {
    let image =
        |img: &ImageRgba32| nv_flip::FlipImageRgb8::with_data(img.width, img.height, &rgb8(img));
    nv_flip::flip(
        image(reference),
        image(test),
        nv_flip::DEFAULT_PIXELS_PER_DEGREE,
    )
}

/// Display values in [0, 1] as the PNG's 8-bit RGB.
fn rgb8(img: &ImageRgba32) -> Vec<u8> {
    img.rgba
        .iter()
        .flat_map(|p| [p[0], p[1], p[2]].map(|c| (c.clamp(0.0, 1.0) * 255.0).round() as u8))
        .collect()
}

/// The mean and the 95th percentile (nearest rank) of the errors.
pub fn flip_stats(errors: &[f32]) -> (f64, f64) {
    if errors.is_empty() {
        return (0.0, 0.0);
    }
    let mean = errors.iter().map(|&e| f64::from(e)).sum::<f64>() / errors.len() as f64;
    let mut sorted = errors.to_vec();
    sorted.sort_by(f32::total_cmp);
    let rank = (0.95 * sorted.len() as f64).ceil().max(1.0) as usize - 1;
    (mean, f64::from(sorted[rank]))
}

/// Mean Rec.709 luminance of a linear image (nits).
pub fn mean_luminance(img: &ImageRgba32) -> f64 {
    let sum: f64 = img
        .rgba
        .iter()
        .map(|p| {
            let y = hikari_math::color::REC709_LUMA;
            (0..3)
                .map(|c| f64::from(y[c]) * f64::from(p[c]))
                .sum::<f64>()
        })
        .sum();
    sum / img.rgba.len().max(1) as f64
}

/// A | B | error map, side by side, display values.
fn side_by_side(a: &ImageRgba32, b: &ImageRgba32, map: &nv_flip::FlipImageRgb8) -> ImageRgba32 {
    let (w, h) = (a.width as usize, a.height as usize);
    let map = map.to_vec();
    let mut rgba = Vec::with_capacity(3 * w * h);
    for y in 0..h {
        rgba.extend_from_slice(&a.rgba[y * w..(y + 1) * w]);
        rgba.extend_from_slice(&b.rgba[y * w..(y + 1) * w]);
        rgba.extend((0..w).map(|x| {
            let i = 3 * (y * w + x);
            let c = |k: usize| f32::from(map[i + k]) / 255.0;
            [c(0), c(1), c(2), 1.0]
        }));
    }
    ImageRgba32 {
        name: "compare".into(),
        texture: None,
        width: 3 * a.width,
        height: a.height,
        format: a.format,
        rgba,
    }
}

/// `frames` frames of `settings` on a renderer of its own; the last one read back, and the
/// EV100 it was shown at. `what` names the run in the progress ("A", "B").
fn render_view(
    view: &ResolvedFrame,
    settings: &FrameSettings,
    frames: u32,
    bake: Option<&std::path::Path>,
    what: &str,
) -> anyhow::Result<(RenderedFrame, f32)> {
    let mut renderer = still::renderer(view, bake)?;
    still::read_exposure(&mut renderer);
    let mut settings = settings.clone();
    let frame = still::render_frames(&mut renderer, &mut settings, frames, what, |_, _| {})?;
    let ev100 = still::ev100(&frame)?;
    Ok((frame, ev100))
}

fn show(v: &Option<toml::Value>) -> String {
    v.as_ref().map_or("(not set)".into(), |v| v.to_string())
}

pub fn run(args: CompareArgs) -> anyhow::Result<()> {
    progress::set_quiet(args.progress.quiet);
    still::check_image_file("-o", &args.output, ImageFile::Png)?;
    for (flag, p) in [("--exr-a", &args.exr_a), ("--exr-b", &args.exr_b)] {
        if let Some(p) = p {
            still::check_image_file(flag, p, ImageFile::Exr)?;
        }
    }
    let valid = toggles();
    for t in &args.toggle {
        if !valid.contains(t) {
            anyhow::bail!(
                "--toggle {t}: no technique `{t}` with an `enabled` setting; valid: {}",
                valid.join(", ")
            );
        }
    }
    let with = |extra: &[(String, String)], preset: Option<hikari_render::Preset>| {
        let mut f = args.frame.clone();
        f.config.overrides.extend(extra.iter().cloned());
        if preset.is_some() {
            f.config.preset = preset;
        }
        f
    };
    let a = scene_source::resolve(&with(&args.a, args.preset_a)).context("A's settings (--a)")?;
    let a_tables = tables(&a.settings.settings);
    let mut b_extra = args.b.clone();
    for t in &args.toggle {
        let on = a_tables
            .get(t)
            .and_then(|v| v.get("enabled"))
            .and_then(toml::Value::as_bool)
            .with_context(|| format!("--toggle {t}: A has no `{t}.enabled`"))?;
        b_extra.push((format!("{t}.enabled"), (!on).to_string()));
    }
    let b = scene_source::resolve(&with(&b_extra, args.preset_b))
        .context("B's settings (--b, --toggle)")?;
    log::info!("{}", a.description.line());
    let diff = differences(&a.settings.settings, &b.settings.settings);
    let frames = args.frames.unwrap_or_else(|| {
        still::default_frames(&a.settings.settings).max(still::default_frames(&b.settings.settings))
    });
    let bake = args.bake.as_deref();

    let ((a_frame, ev_a), (b_frame, ev_b)) = if args.own_exposure {
        (
            render_view(&a, &a.settings, frames, bake, "A")?,
            render_view(&b, &b.settings, frames, bake, "B")?,
        )
    } else {
        // A's EV100: fixed by its settings, else metered on a first run of A.
        let ev100 = match a.settings.settings.exposure.ev100 {
            Some(ev) => ev,
            None => render_view(&a, &a.settings, frames, bake, "A to meter its exposure")?.1,
        };
        if b.settings
            .settings
            .exposure
            .ev100
            .is_some_and(|ev| ev != ev100)
        {
            log::warn!("B's exposure.ev100 is replaced by A's, {ev100}: --own-exposure keeps it");
        }
        let fixed = |view: &ResolvedFrame| {
            let mut s = view.settings.clone();
            s.settings.exposure.ev100 = Some(ev100);
            s
        };
        (
            render_view(&a, &fixed(&a), frames, bake, "A")?,
            render_view(&b, &fixed(&b), frames, bake, "B")?,
        )
    };
    let step = Step::start(format!("comparing, writing {}", args.output.display()));

    let ((a_hdr, a_ldr), (b_hdr, b_ldr)) = (still::images(&a_frame)?, still::images(&b_frame)?);
    let errors = flip(a_ldr, b_ldr);
    let (mean, p95) = flip_stats(&errors.to_vec());
    let map = errors.apply_color_lut(&nv_flip::magma_lut());
    output::write_png(&args.output, &side_by_side(a_ldr, b_ldr, &map))?;
    for (p, hdr) in [(&args.exr_a, a_hdr), (&args.exr_b, b_hdr)] {
        if let Some(p) = p {
            output::write_exr(p, hdr)?;
        }
    }
    let (lum_a, lum_b) = (mean_luminance(a_hdr), mean_luminance(b_hdr));
    let ratio = lum_b / lum_a;
    let exposure = if args.own_exposure { "own" } else { "A's" };
    step.clear();

    if args.json.json {
        let settings = |pick: fn(&Difference) -> &Option<toml::Value>| {
            serde_json::Value::Object(
                diff.iter()
                    .map(|d| {
                        (
                            d.key.clone(),
                            json!(pick(d).as_ref().map(|v| v.to_string())),
                        )
                    })
                    .collect(),
            )
        };
        let out = json!({
            "scene": a.description.json(),
            "frames": frames,
            "exposure": if args.own_exposure { "own" } else { "a" },
            "a": {
                "settings": settings(|d| &d.a),
                "ev100": ev_a,
                "mean_luminance_nits": lum_a,
            },
            "b": {
                "settings": settings(|d| &d.b),
                "ev100": ev_b,
                "mean_luminance_nits": lum_b,
            },
            "flip": { "mean": mean, "p95": p95 },
            "luminance_ratio_b_over_a": ratio,
            "output": args.output.display().to_string(),
            "exr_a": args.exr_a.as_ref().map(|p| p.display().to_string()),
            "exr_b": args.exr_b.as_ref().map(|p| p.display().to_string()),
        });
        println!("{}", serde_json::to_string_pretty(&out)?);
        return Ok(());
    }
    println!("compare: {}, {frames} frames each", a.description.line());
    if diff.is_empty() {
        println!("A and B: the same settings");
    }
    for d in &diff {
        println!("  {}: A {}, B {}", d.key, show(&d.a), show(&d.b));
    }
    println!(
        "EV100: A {:.3}, B {:.3} (B at {exposure} exposure)",
        ev_a, ev_b
    );
    println!("FLIP: mean {mean:.4}, 95th percentile {p95:.4}");
    println!("mean luminance B/A: {ratio:.4} (A {lum_a:.4} nits, B {lum_b:.4} nits)");
    println!("wrote {} (A | B | FLIP)", args.output.display());
    for p in [&args.exr_a, &args.exr_b].into_iter().flatten() {
        println!("wrote {}", p.display());
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn toggles_are_the_tables_with_an_enabled_switch() {
        let t = toggles();
        for name in ["ray_traced_gi", "taa", "exposure", "sky"] {
            assert!(t.iter().any(|n| n == name), "{name} in {t:?}");
        }
        assert!(!t.iter().any(|n| n == "tonemap"), "{t:?}");
    }

    #[test]
    fn differences_name_each_changed_key_with_both_values() {
        let a = hikari_render::Settings::default();
        assert!(differences(&a, &a).is_empty());
        let mut b = a.clone();
        b.taa.enabled = !a.taa.enabled;
        b.exposure.ev100 = Some(12.0);
        let d = differences(&a, &b);
        let keys: Vec<&str> = d.iter().map(|d| d.key.as_str()).collect();
        assert_eq!(keys, ["exposure.ev100", "taa.enabled"]);
        assert_eq!(d[0].a, None);
        assert_eq!(d[1].b, Some(toml::Value::Boolean(b.taa.enabled)));
    }

    #[test]
    fn flip_stats_are_the_mean_and_the_nearest_rank_percentile() {
        let e: Vec<f32> = (1..=100).map(|i| i as f32 / 100.0).collect();
        let (mean, p95) = flip_stats(&e);
        assert!((mean - 0.505).abs() < 1e-6);
        assert_eq!(p95, f64::from(0.95f32));
        assert_eq!(flip_stats(&[0.0; 7]), (0.0, 0.0));
    }
}
