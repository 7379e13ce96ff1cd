//! `hikari bench soak`: many frames through the live path a viewer drives (the clock playing,
//! techniques switched off and on, the camera moving and cutting, the size changing, the scene
//! reloaded), with the process's resident memory and the GPU allocator's memory sampled once a
//! cycle at the same point of it. After the first cycle (the warm-up) both must stay within
//! `--tolerance` of what they were then; every frame's output must be finite and no GPU error
//! may be raised. Prints the curves, and exits non-zero when one of those fails.

use std::time::Instant;

use anyhow::Context;
use clap::Args;
use serde_json::json;

use hikari_render::graph::Poison;
use hikari_render::{Renderer, Settings};

use crate::args::{FrameArgs, JsonArgs};
use crate::probe_bake;
use crate::scene_source::{self, ResolvedFrame};

#[derive(Args, Debug)]
pub struct SoakArgs {
    #[command(flatten)]
    pub frame: FrameArgs,
    /// Frames in all.
    #[arg(long, default_value_t = 10_000)]
    pub frames: u32,
    /// Frames a cycle: each cycle cuts the camera away and back, switches every technique off
    /// and on again, shrinks and restores the size, and reloads the scene; memory is sampled
    /// at its end. The first cycle is the warm-up.
    #[arg(long, default_value_t = 500)]
    pub cycle: u32,
    /// Seconds the clock moves a frame (it wraps at midnight, so long soaks see the night).
    #[arg(long, default_value_t = 6.0)]
    pub clock_step: f64,
    /// Largest growth of memory after the warm-up, percent, before the soak fails.
    #[arg(long, default_value_t = 2.0)]
    pub tolerance: f64,
    /// Also write NaN and infinities into one input or history of a temporal pass each cycle
    /// (walking all of them in turn); the outputs must stay finite.
    #[arg(long)]
    pub poison: bool,
    /// Also print, at the end, how the resident set of each kind of mapping grew after the
    /// warm-up (`/proc/self/smaps`: the heap, anonymous memory, device files, libraries).
    #[arg(long)]
    pub smaps: bool,
    #[command(flatten)]
    pub output: JsonArgs,
}

/// One sample of memory, at the end of a cycle.
struct Sample {
    frame: u32,
    resident_mb: Option<f64>,
    heap_mb: Option<f64>,
    gpu_allocated_mb: Option<f64>,
    gpu_reserved_mb: Option<f64>,
    frame_ms: f64,
}

/// This process's resident set, MB (Linux; `None` elsewhere). glibc's allocator first gives
/// the heap's free pages back (`malloc_trim`): what it keeps for reuse varies from cycle to
/// cycle by tens of MB (a scene reload frees and allocates its upload copies) and would hide a
/// leak or fake one; what is left is what the process holds.
fn resident_mb() -> Option<f64> {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    // SAFETY: malloc_trim only returns free memory of the allocator's heaps to the system.
    unsafe {
        libc::malloc_trim(0);
    }
    let statm = std::fs::read_to_string("/proc/self/statm").ok()?;
    let pages: f64 = statm.split_whitespace().nth(1)?.parse().ok()?;
    Some(pages * 4096.0 / 1e6)
}

/// The resident set by kind of mapping, MB (`/proc/self/smaps`; empty elsewhere): `[heap]`,
/// anonymous memory (other threads' malloc arenas, drivers' own allocations), each device file
/// (a GPU driver's mappings), shared libraries, and the rest. `--smaps` prints how each grew,
/// to tell whose pages a growing resident set is.
fn smaps_mb() -> std::collections::BTreeMap<String, f64> {
    let mut out = std::collections::BTreeMap::new();
    let Ok(text) = std::fs::read_to_string("/proc/self/smaps") else {
        return out;
    };
    let mut kind = String::new();
    for line in text.lines() {
        let mut words = line.split_whitespace();
        let first = words.next().unwrap_or("");
        if first.contains('-') && first.chars().next().is_some_and(|c| c.is_ascii_hexdigit()) {
            let path = line.split_whitespace().nth(5).unwrap_or("");
            kind = if path.is_empty() {
                "anonymous".into()
            } else if path.starts_with("/dev/") || path.starts_with("[") {
                path.into()
            } else if path.contains(".so") {
                "libraries".into()
            } else {
                "other files".into()
            };
        } else if first == "Rss:" {
            let kb: f64 = words.next().and_then(|v| v.parse().ok()).unwrap_or(0.0);
            *out.entry(kind.clone()).or_insert(0.0) += kb / 1e3;
        }
    }
    out
}

/// Bytes the allocator has handed out and not had back, MB (glibc; `None` elsewhere): the
/// heap's own growth, which tells a leak of the process's allocations from memory a driver
/// maps beside the heap (both count in the resident set).
fn heap_mb() -> Option<f64> {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    {
        // SAFETY: mallinfo2 only reads the allocator's counters.
        let info = unsafe { libc::mallinfo2() };
        Some((info.uordblks + info.hblkhd) as f64 / 1e6)
    }
    #[cfg(not(all(target_os = "linux", target_env = "gnu")))]
    {
        None
    }
}

/// What the GPU allocator holds for this device, MB: allocated and reserved (its blocks).
/// `None` where the backend keeps no report.
fn gpu_mb(ctx: &hikari_render::GpuContext) -> (Option<f64>, Option<f64>) {
    match ctx.device.generate_allocator_report() {
        Some(r) => (
            Some(r.total_allocated_bytes as f64 / 1e6),
            Some(r.total_reserved_bytes as f64 / 1e6),
        ),
        None => (None, None),
    }
}

/// `settings` with technique `table` switched on or off.
fn with_switch(settings: &Settings, table: &str, on: bool) -> anyhow::Result<Settings> {
    let mut t = toml::Value::try_from(settings)?;
    t[table]["enabled"] = toml::Value::Boolean(on);
    Ok(t.try_into()?)
}

/// What happens at frame `p` of a cycle of `c` frames with `n` technique switches.
#[derive(Debug, PartialEq)]
enum Event {
    CutAway,
    CutBack,
    Switch { index: usize, on: bool },
    Shrink,
    Restore,
    Reload,
    Poison,
    None,
}

fn event_at(p: u32, c: u32, n: usize) -> Event {
    // The switches share the second quarter and the third; each is off for half its slot.
    let span = c / 2;
    let slot = (span / n.max(1) as u32).max(2);
    match p {
        _ if p == c / 16 => Event::CutAway,
        _ if p == c / 8 => Event::CutBack,
        _ if p >= c / 4 && p < c / 4 + slot * n as u32 => {
            let k = p - c / 4;
            match k % slot {
                0 => Event::Switch {
                    index: (k / slot) as usize,
                    on: false,
                },
                r if r == slot / 2 => Event::Switch {
                    index: (k / slot) as usize,
                    on: true,
                },
                _ => Event::None,
            }
        }
        _ if p == c * 3 / 4 + 1 => Event::Shrink,
        _ if p == c * 13 / 16 + 1 => Event::Restore,
        _ if p == c * 7 / 8 => Event::Reload,
        _ if p == c * 15 / 16 => Event::Poison,
        _ => Event::None,
    }
}

pub fn run(a: SoakArgs) -> anyhow::Result<()> {
    anyhow::ensure!(a.frames > 0, "--frames must be at least 1");
    let ResolvedFrame {
        scene,
        settings,
        description,
        ..
    } = scene_source::resolve(&a.frame)?;
    let switches: Vec<&'static str> = settings
        .settings
        .switches()
        .into_iter()
        .filter(|(_, on)| *on)
        .map(|(name, _)| name)
        .collect();
    let min_cycle = 4 * switches.len() as u32 + 16;
    anyhow::ensure!(
        a.cycle >= min_cycle,
        "--cycle {} is too short for {} technique switches: at least {min_cycle} frames",
        a.cycle,
        switches.len()
    );
    anyhow::ensure!(
        a.frames >= 2 * a.cycle,
        "--frames {} is less than two cycles of {}: the first cycle is the warm-up",
        a.frames,
        a.cycle
    );
    anyhow::ensure!(
        a.clock_step.is_finite() && a.clock_step.abs() <= 3600.0,
        "--clock-step {} is outside -3600 to 3600 seconds a frame",
        a.clock_step
    );
    anyhow::ensure!(
        a.tolerance.is_finite() && a.tolerance > 0.0,
        "--tolerance {} must be a positive percentage",
        a.tolerance
    );
    if !a.output.json {
        println!(
            "bench soak: {}{}, {} frames in cycles of {}, clock {} s a frame, {} technique \
             switches{}",
            description.line(),
            if settings.settings.sky.enabled {
                " (the sky's sun or moon follows the clock)"
            } else {
                ""
            },
            a.frames,
            a.cycle,
            a.clock_step,
            switches.len(),
            if a.poison {
                ", NaN written each cycle"
            } else {
                ""
            }
        );
    }
    let ctx = crate::still::gpu()?;
    let adapter = ctx.describe();
    let mut renderer = Renderer::new(ctx.clone(), &scene)?;
    // The viewer's mode: no frame waits for the rasteriser's queue counts.
    renderer.set_interactive(true);
    probe_bake::attach(&mut renderer, &scene, &description.source, &settings, None)?;
    renderer.set_frame(settings.clone())?;
    // The clock moves the sky's sun or moon, as in the viewer, even in a scene with its own.
    if settings.settings.sky.enabled {
        renderer.set_sun_source(hikari_render::SunSource::Sky)?;
    }
    let clock0 = settings
        .settings
        .sky
        .date_time()
        .map(|t| f64::from(t.seconds_of_day()))
        .map_err(|e| anyhow::anyhow!("{e}"))?;
    let (w, h) = (settings.width, settings.height);
    let home = settings.camera.clone();
    let away = scene.cameras.get(1).cloned().unwrap_or_else(|| {
        let mut c = home.clone();
        let back = -c.forward() * 5.0;
        c.position += back;
        c.target += back;
        c
    });
    // The temporal passes' inputs, for `--poison`.
    let mut poisons: Vec<Poison> = Vec::new();
    if a.poison {
        renderer.runtime.set_record_reads(true);
        let f = renderer.frame(false)?;
        renderer.runtime.set_record_reads(false);
        for p in f.result.reads.iter().filter(|p| p.is_temporal()) {
            for t in p.textures.iter().filter(|t| t.poisonable && !t.cached) {
                poisons.push(Poison {
                    pass: p.pass.clone(),
                    texture: t.name.clone(),
                });
            }
        }
    }
    let mut samples: Vec<Sample> = Vec::new();
    // The resident set by kind of mapping after the warm-up cycle and at the last sample.
    let mut maps: Vec<std::collections::BTreeMap<String, f64>> = Vec::new();
    let mut live_settings = settings.settings.clone();
    let mut cycle_ms = 0.0;
    let mut poisoned = 0usize;
    let t_all = Instant::now();
    for i in 0..a.frames {
        let p = i % a.cycle;
        let t0 = Instant::now();
        // The camera drifts on a small circle as a flying viewer's does.
        let drift = |c: &hikari_scene::Camera| {
            let phase = f64::from(i) * std::f64::consts::TAU / 240.0;
            let mut c = c.clone();
            let d = glam::Vec3::new(phase.cos() as f32, 0.0, phase.sin() as f32) * 0.25;
            c.position += d;
            c.target += d;
            c
        };
        match event_at(p, a.cycle, switches.len()) {
            Event::CutAway => renderer.set_camera(drift(&away), true)?,
            Event::CutBack => renderer.set_camera(drift(&home), true)?,
            Event::Switch { index, on } => {
                live_settings = with_switch(&live_settings, switches[index], on)?;
                renderer.set_settings(live_settings.clone())?;
            }
            Event::Shrink => renderer.resize((w * 3 / 4).max(8), (h * 3 / 4).max(8))?,
            Event::Restore => renderer.resize(w, h)?,
            Event::Reload => {
                renderer.reload_scene(&scene)?;
                probe_bake::attach(&mut renderer, &scene, &description.source, &settings, None)?;
            }
            Event::Poison => {
                if let Some(next) = poisons.get(poisoned % poisons.len().max(1)) {
                    renderer.runtime.poison_next_frame(next.clone());
                    poisoned += 1;
                }
            }
            Event::None => {}
        }
        if !matches!(p, _ if p == a.cycle / 16 || p == a.cycle / 8) {
            let at_home = p < a.cycle / 16 || p >= a.cycle / 8;
            renderer.set_camera(drift(if at_home { &home } else { &away }), false)?;
        }
        let clock = (clock0 + a.clock_step * f64::from(i + 1)).rem_euclid(86_400.0);
        renderer.set_time_of_day(clock)?;
        let f = renderer
            .frame(true)
            .with_context(|| format!("soak frame {i}"))?;
        let hdr = f.hdr.context("the frame's image was not read back")?;
        let bad = hdr
            .rgba
            .iter()
            .filter(|px| !px.iter().all(|v| v.is_finite()))
            .count();
        anyhow::ensure!(
            bad == 0,
            "soak frame {i}: {bad} pixels of the output are not finite (NaN or infinity)"
        );
        cycle_ms += t0.elapsed().as_secs_f64() * 1e3;
        if p == a.cycle - 1 {
            let (gpu_allocated_mb, gpu_reserved_mb) = gpu_mb(&ctx);
            let s = Sample {
                frame: i + 1,
                resident_mb: resident_mb(),
                heap_mb: heap_mb(),
                gpu_allocated_mb,
                gpu_reserved_mb,
                frame_ms: cycle_ms / f64::from(a.cycle),
            };
            cycle_ms = 0.0;
            if !a.output.json {
                println!(
                    "frame {:>7}  resident {}  heap {}  GPU allocated {}  reserved {}  {:.2} ms a frame",
                    s.frame,
                    mb(s.resident_mb),
                    mb(s.heap_mb),
                    mb(s.gpu_allocated_mb),
                    mb(s.gpu_reserved_mb),
                    s.frame_ms
                );
            }
            samples.push(s);
            if a.smaps {
                let now = smaps_mb();
                if maps.len() < 2 {
                    maps.push(now);
                } else {
                    maps[1] = now;
                }
            }
        }
    }
    if let [first, last] = &maps[..] {
        println!("resident set by mapping, MB, after the warm-up and at the end:");
        for (kind, mb) in last {
            let was = first.get(kind).copied().unwrap_or(0.0);
            if mb.max(was) >= 0.5 {
                println!("  {kind:<32} {was:>9.1} {mb:>9.1}  {:+.1}", mb - was);
            }
        }
    }
    let resident = max_growth(samples.iter().map(|s| s.resident_mb));
    let gpu = max_growth(samples.iter().map(|s| s.gpu_reserved_mb));
    let heap = max_growth(samples.iter().map(|s| s.heap_mb));
    let flat = |g: Option<f64>| g.is_none_or(|g| g <= a.tolerance);
    let ok = flat(resident) && flat(gpu);
    let pct = |g: Option<f64>| g.map_or("not measured".to_string(), |g| format!("{g:+.2} %"));
    if a.output.json {
        let out = json!({
            "benchmark": "soak",
            "adapter": adapter,
            "scene": description.json(),
            "width": w, "height": h,
            "frames": a.frames, "cycle": a.cycle, "clock_step_s": a.clock_step,
            "switches": switches, "poisoned": poisoned,
            "seconds": t_all.elapsed().as_secs_f64(),
            "samples": samples.iter().map(|s| json!({
                "frame": s.frame, "resident_mb": s.resident_mb, "heap_mb": s.heap_mb,
                "gpu_allocated_mb": s.gpu_allocated_mb, "gpu_reserved_mb": s.gpu_reserved_mb,
                "frame_ms": s.frame_ms,
            })).collect::<Vec<_>>(),
            "max_growth_percent": { "resident": resident, "heap": heap, "gpu_reserved": gpu },
            "tolerance_percent": a.tolerance,
            "flat": ok,
        });
        println!("{}", serde_json::to_string_pretty(&out)?);
    } else {
        println!("adapter: {adapter}");
        println!(
            "after the warm-up cycle, largest growth: resident {}, allocator heap {}, GPU \
             reserved {} (tolerance {} %); every output finite, no GPU error; {} inputs \
             poisoned; {:.0} s",
            pct(resident),
            pct(heap),
            pct(gpu),
            a.tolerance,
            poisoned,
            t_all.elapsed().as_secs_f64()
        );
    }
    anyhow::ensure!(
        ok,
        "memory grew past {} % after the warm-up: resident {}, GPU reserved {}",
        a.tolerance,
        pct(resident),
        pct(gpu)
    );
    Ok(())
}

/// The largest growth of the later values over the first (the warm-up's), percent; `None`
/// when the first or every later one is not measured.
fn max_growth(values: impl Iterator<Item = Option<f64>>) -> Option<f64> {
    let mut values = values;
    let base = values.next()??;
    values
        .flatten()
        .map(|v| (v - base) / base.max(1e-9) * 100.0)
        .fold(None, |m: Option<f64>, g| Some(m.map_or(g, |m| m.max(g))))
}

fn mb(v: Option<f64>) -> String {
    v.map_or("-".to_string(), |v| format!("{v:8.1} MB"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn growth_is_measured_from_the_warm_up_and_a_leak_fails_the_tolerance() {
        // 13 MB a frame over a 64-frame cycle, the CPU driver's leak, from 480 MB.
        let leak = [480.0, 480.0 + 832.0, 480.0 + 1664.0].map(Some);
        assert!(max_growth(leak.into_iter()).unwrap() > 2.0);
        let flat = [Some(480.0), Some(480.3), None, Some(479.0)];
        let g = max_growth(flat.into_iter()).unwrap();
        assert!((g - 0.0625).abs() < 1e-9, "{g}");
        assert_eq!(max_growth([None, Some(1.0)].into_iter()), None);
        assert_eq!(max_growth([Some(1.0)].into_iter()), None);
    }

    #[test]
    fn a_cycle_switches_each_technique_off_then_on_and_has_each_event_once() {
        let (c, n) = (100, 10);
        let events: Vec<Event> = (0..c).map(|p| event_at(p, c, n)).collect();
        for k in 0..n {
            let off = events.iter().position(|e| {
                *e == Event::Switch {
                    index: k,
                    on: false,
                }
            });
            let on = events
                .iter()
                .position(|e| *e == Event::Switch { index: k, on: true });
            assert!(
                matches!((off, on), (Some(a), Some(b)) if a < b),
                "switch {k}: {off:?} {on:?}"
            );
        }
        for e in [
            Event::CutAway,
            Event::CutBack,
            Event::Shrink,
            Event::Restore,
            Event::Reload,
            Event::Poison,
        ] {
            assert_eq!(events.iter().filter(|x| **x == e).count(), 1, "{e:?}");
        }
    }
}
