//! `hikari view`: the renderer in a window, live (docs/viewer.md).
//!
//! * `app`: the window's event loop (winit), start-up, the frame loop;
//! * `camera`: the fly camera; `keys`: the key bindings;
//! * `panel`: the panel's state and edits; `ui`: its widgets (egui);
//! * `present`: the surface, the frame's picture and egui's paint;
//! * `stats`: the numbers; `shot`: screenshot names;
//! * `faults`: the fault switch that tests the viewer's recovery (`HIKARI_VIEW_FAULT`).

mod app;
mod camera;
mod faults;
mod keys;
mod panel;
mod present;
mod shot;
mod stats;
mod ui;

use std::path::PathBuf;

use anyhow::Context;
use clap::Args;

use crate::args::FrameArgs;
use crate::scene_source;
use crate::still;

#[derive(Args, Debug)]
pub struct ViewArgs {
    #[command(flatten)]
    pub frame: FrameArgs,
    /// Irradiance-probe bake file [default: the cache under $XDG_CACHE_HOME/hikari, baked
    /// on a miss].
    #[arg(long)]
    pub bake: Option<PathBuf>,
    /// Exit (status 0) after this many frames have been shown; for scripts and tests.
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..))]
    pub exit_after_frames: Option<u64>,
    /// Print `frame N shown` on stdout after each frame, for scripts and tests that follow
    /// the frames.
    #[arg(long, hide = true)]
    pub print_frames: bool,
    /// On exit, write the last frame shown (the picture under the panel) to this PNG.
    #[arg(long, value_name = "PATH")]
    pub screenshot: Option<PathBuf>,
}

/// Why no window can open here, before winit tries: neither display variable set.
fn check_display() -> anyhow::Result<()> {
    if !cfg!(all(
        unix,
        not(target_os = "macos"),
        not(target_os = "android")
    )) {
        return Ok(());
    }
    let set = |v: &str| std::env::var_os(v).is_some_and(|s| !s.is_empty());
    if !set("DISPLAY") && !set("WAYLAND_DISPLAY") {
        anyhow::bail!(
            "hikari view needs a display, and neither DISPLAY (X11) nor WAYLAND_DISPLAY \
             (Wayland) is set. Run it in a desktop session, or under a virtual X server: \
             install Xvfb (`apt-get install xvfb`) and run `xvfb-run -s '-screen 0 1280x720x24' \
             hikari view`. `hikari render` needs no display."
        );
    }
    Ok(())
}

pub fn run(args: ViewArgs) -> anyhow::Result<()> {
    if let Some(p) = &args.screenshot {
        still::check_image_file("--screenshot", p, still::ImageFile::Png)?;
    }
    check_display()?;
    let resolved = scene_source::resolve(&args.frame)?;
    log::info!("{}", resolved.description.line());
    let event_loop = winit::event_loop::EventLoop::new().map_err(|e| {
        let which = match (std::env::var("WAYLAND_DISPLAY"), std::env::var("DISPLAY")) {
            (Ok(w), _) if !w.is_empty() => format!("WAYLAND_DISPLAY={w}"),
            (_, Ok(d)) => format!("DISPLAY={d}"),
            _ => "the display".into(),
        };
        anyhow::anyhow!(
            "cannot open the display ({which}): {e}. Is the X server or Wayland compositor \
             running and reachable? Under no desktop, run a virtual one: `apt-get install \
             xvfb`, then `xvfb-run hikari view`."
        )
    })?;
    let mut app = app::App::new(args, resolved);
    event_loop
        .run_app(&mut app)
        .context("the window's event loop failed")?;
    app.finish()
}
