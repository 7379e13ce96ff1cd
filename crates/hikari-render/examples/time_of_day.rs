//! The village at four times of day from one renderer, as a library user drives it.
//!
//! ```sh
//! cargo run --release -p hikari-render --example time_of_day -- -o DIR [--width W --height H]
//! ```
//!
//! writes `DIR/0600.png`, `DIR/1200.png`, `DIR/1900.png` and `DIR/2300.png`. One renderer is
//! made; between the pictures only its clock is set (`Renderer::set_clock`), and the frames
//! rendered after each change let the temporal passes (TAA, the GI's accumulation, the
//! exposure) follow the light, as a viewer's would.

use std::path::PathBuf;

use hikari_render::{ContextOptions, FrameSettings, GpuContext, Renderer, Settings, SunSource};

struct Args {
    out: PathBuf,
    width: u32,
    height: u32,
}

fn args() -> Result<Args, String> {
    let mut a = Args {
        out: PathBuf::new(),
        width: 640,
        height: 360,
    };
    let mut it = std::env::args().skip(1);
    let mut out = None;
    while let Some(flag) = it.next() {
        let mut value = || it.next().ok_or(format!("{flag} needs a value"));
        match flag.as_str() {
            "-o" | "--output" => out = Some(PathBuf::from(value()?)),
            "--width" => a.width = value()?.parse().map_err(|e| format!("--width: {e}"))?,
            "--height" => a.height = value()?.parse().map_err(|e| format!("--height: {e}"))?,
            other => return Err(format!("unknown argument {other}")),
        }
    }
    a.out = out.ok_or("usage: time_of_day -o DIR [--width W --height H]")?;
    Ok(a)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let a = args()?;
    std::fs::create_dir_all(&a.out)?;

    // The scene and a renderer on the GPU the environment picks (WGPU_BACKEND, ...).
    let scene = hikari_scene::builtin::village();
    let ctx = GpuContext::new(&ContextOptions::from_env())?;
    println!("adapter: {}", ctx.describe());
    let mut renderer = Renderer::new(ctx, &scene)?;

    // The village's probe data: its irradiance probes baked on all CPU cores (a minute or so
    // on a laptop; the `hikari` CLI caches its bake and traces it on the GPU), and its
    // reflection probes' placements.
    let options = hikari_bake::SceneBakeOptions {
        volumes: hikari_bake::volumes::builtin_volumes("village"),
        ..Default::default()
    };
    println!("baking the irradiance probes ...");
    let bake = hikari_bake::bake_scene(&scene, &options, &|_| {})?;
    renderer.set_probe_bake(Some(&bake))?;
    renderer.set_reflection_probes(&hikari_bake::reflection_probes::builtin_reflection_probes(
        "village",
    ))?;

    // The live frame: size, camera, settings; the sun and moon come from the sky's clock.
    renderer.set_frame(FrameSettings {
        width: a.width,
        height: a.height,
        camera: scene.cameras[0].clone(),
        prev_camera: None,
        sun: SunSource::Sky,
        settings: Settings::default(),
    })?;
    let settle = 16;
    for time in ["06:00", "12:00", "19:00", "23:00"] {
        renderer.set_clock("2024-07-21", time)?;
        for _ in 1..settle {
            renderer.frame(false)?;
        }
        let frame = renderer.frame(true)?;
        let path = a.out.join(format!("{}.png", time.replace(':', "")));
        hikari_render::output::write_png(&path, frame.ldr.as_ref().ok_or("no image")?)?;
        println!("wrote {}", path.display());
    }
    Ok(())
}
