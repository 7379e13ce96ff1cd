//! Command-line argument groups shared by several commands. Each flag is defined once, here,
//! and flattened (`#[command(flatten)]`) into every command that takes it, so that its name,
//! help and parsing cannot drift between commands.

use std::path::PathBuf;

use clap::Args;

/// `--scene`: what to load.
#[derive(Args, Debug, Clone, Default)]
pub struct SceneArgs {
    /// Built-in scene (village, cornell, terrain, boxes) or a .gltf/.glb file [default: village].
    #[arg(long)]
    pub scene: Option<String>,
}

/// `--camera`: which of the scene's cameras looks.
#[derive(Args, Debug, Clone, Default)]
pub struct CameraArgs {
    /// Camera name in the scene; the scene's first camera if omitted.
    #[arg(long)]
    pub camera: Option<String>,
}

/// `--time`: the time of day.
#[derive(Args, Debug, Clone, Default)]
pub struct TimeArgs {
    /// Time of day, HH:MM: sets the sun (or moon) by a simple model until the atmosphere
    /// issue [default: the scene's own sun].
    #[arg(long)]
    pub time: Option<String>,
}

/// `--width` and `--height`: the image size in pixels.
#[derive(Args, Debug, Clone, Default)]
pub struct SizeArgs {
    /// Image width in pixels [default: 1280].
    #[arg(long)]
    pub width: Option<u32>,
    /// Image height in pixels [default: 720].
    #[arg(long)]
    pub height: Option<u32>,
}

/// `--config`: a TOML settings file.
#[derive(Args, Debug, Clone, Default)]
pub struct ConfigArgs {
    /// TOML settings file (docs/config.example.toml); flags win over it.
    #[arg(long)]
    pub config: Option<PathBuf>,
    /// Quality preset: low, medium, high or ultra; sets every technique's resolutions, ray
    /// and sample counts and budgets [default: the file's `preset`, else high].
    #[arg(long)]
    pub preset: Option<hikari_render::Preset>,
    /// Overrides one setting, in TOML syntax: `--set sun_shadows.resolution=4096`; repeatable.
    /// Wins over the preset and the file.
    #[arg(long = "set", value_name = "TABLE.KEY=VALUE", value_parser = crate::config::parse_override)]
    pub overrides: Vec<(String, String)>,
}

/// `--ev100`: a fixed exposure.
#[derive(Args, Debug, Clone, Default)]
pub struct ExposureArgs {
    /// Placeholder exposure: EV at ISO 100 (sunny day about 15, overcast 12, interior 7)
    /// [default: metered from the sun].
    #[arg(long, allow_negative_numbers = true)]
    pub ev100: Option<f32>,
}

/// `--json`: machine-readable output.
#[derive(Args, Debug, Clone, Default)]
pub struct JsonArgs {
    /// Print one JSON object instead of a table.
    #[arg(long)]
    pub json: bool,
}

/// Everything that picks one frame of a scene: shared by `render` and `bench frame`;
/// [`crate::scene_source::resolve`] turns it into a scene and its frame settings.
#[derive(Args, Debug, Clone, Default)]
pub struct FrameArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
    #[command(flatten)]
    pub camera: CameraArgs,
    #[command(flatten)]
    pub time: TimeArgs,
    #[command(flatten)]
    pub size: SizeArgs,
    #[command(flatten)]
    pub config: ConfigArgs,
    #[command(flatten)]
    pub exposure: ExposureArgs,
}
