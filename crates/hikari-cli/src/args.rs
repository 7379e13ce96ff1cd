//! Command-line argument groups shared by several commands. Each flag is defined once, here,
//! and flattened (`#[command(flatten)]`) into every command that takes it, so that its name,
//! help and parsing cannot drift between commands.

use std::path::PathBuf;

use clap::Args;

/// `--scene`: what to load.
#[derive(Args, Debug, Clone, Default)]
pub struct SceneArgs {
    #[arg(long, value_name = "NAME|PATH", help = scene_help())]
    pub scene: Option<String>,
}

/// `--scene`'s help, naming every built-in scene there is.
pub fn scene_help() -> String {
    format!(
        "Built-in scene ({}) or a .gltf/.glb file [default: {}]",
        hikari_scene::builtin::NAMES.join(", "),
        crate::scene_source::DEFAULT_SCENE
    )
}

/// `--camera`: which of the scene's cameras looks.
#[derive(Args, Debug, Clone, Default)]
pub struct CameraArgs {
    /// Camera name in the scene; the scene's first camera if omitted.
    #[arg(long)]
    pub camera: Option<String>,
}

/// `--date`, `--time`, `--utc-offset`, `--lat`, `--lon`, `--weather`: when and where the sky
/// is, and its weather. Each wins over the settings file's `[sky]` table (and `time`).
#[derive(Args, Debug, Clone, Default)]
pub struct SkyArgs {
    /// Local date, YYYY-MM-DD, 1900 to 2100 [default: 2024-07-21].
    #[arg(long)]
    pub date: Option<String>,
    /// Local time, HH:MM or HH:MM:SS, 00:00 to 23:59:59: places the sun and the moon
    /// [default: 12:00; scenes with their own sun keep it unless --date or --time is given].
    #[arg(long)]
    pub time: Option<String>,
    /// Hours east of Greenwich of the local time, -14 to 14 [default: 9].
    #[arg(long, allow_negative_numbers = true)]
    pub utc_offset: Option<f64>,
    /// Latitude in degrees, -90 to 90, north positive [default: 34.4, Tsushima].
    #[arg(long, allow_negative_numbers = true)]
    pub lat: Option<f64>,
    /// Longitude in degrees, -180 to 180, east positive [default: 129.3].
    #[arg(long, allow_negative_numbers = true)]
    pub lon: Option<f64>,
    /// Weather: clear, hazy or overcast [default: clear].
    #[arg(long)]
    pub weather: Option<String>,
}

/// `--no-sun`, `--no-sky`: the sky's lights off, for scenes lit by their own lamps. Each wins
/// over the settings file's `[sky]` table.
#[derive(Args, Debug, Clone, Default)]
pub struct LightArgs {
    /// No directional light (sun or moon).
    #[arg(long)]
    pub no_sun: bool,
    /// No sky light: a black sky and no sky ambient light.
    #[arg(long)]
    pub no_sky: bool,
}

impl LightArgs {
    /// Turns off in `s` what the flags turn off.
    pub fn apply(&self, s: &mut hikari_render::settings::SkySettings) {
        if self.no_sun {
            s.sun = false;
        }
        if self.no_sky {
            s.sky = false;
        }
    }
}

impl SkyArgs {
    /// Whether a date or time was asked for (which overrides a scene's own sun).
    pub fn sets_time(&self) -> bool {
        self.date.is_some() || self.time.is_some()
    }

    /// Copies the given flags into `s`, checking each: the error names the flag and its
    /// allowed range.
    pub fn apply(&self, s: &mut hikari_render::settings::SkySettings) -> anyhow::Result<()> {
        use anyhow::Context;
        let check = |s: &hikari_render::settings::SkySettings, flag: &str, value: String| {
            hikari_render::settings::TechniqueSettings::validate(s, "sky")
                .map_err(|e| anyhow::anyhow!("{e}"))
                .with_context(|| format!("{flag} {value}"))
        };
        if let Some(d) = &self.date {
            s.date = d.clone();
            check(s, "--date", d.clone())?;
        }
        if let Some(t) = &self.time {
            s.time = t.clone();
            check(s, "--time", t.clone())?;
        }
        if let Some(v) = self.utc_offset {
            s.utc_offset_h = v;
            check(s, "--utc-offset", v.to_string())?;
        }
        if let Some(v) = self.lat {
            s.latitude_deg = v;
            check(s, "--lat", v.to_string())?;
        }
        if let Some(v) = self.lon {
            s.longitude_deg = v;
            check(s, "--lon", v.to_string())?;
        }
        if let Some(w) = &self.weather {
            s.weather = w.clone();
            check(s, "--weather", w.clone())?;
        }
        Ok(())
    }
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
    /// Renders at this fraction of the image's width and height, 0.5 to 1, and upsamples
    /// temporally to it (`taa.render_scale`; docs/scaling.md) [default: the preset's: low
    /// 0.5, medium 0.67, high and ultra 1]
    #[arg(long, value_name = "S")]
    pub render_scale: Option<f32>,
}

impl ConfigArgs {
    /// `--set` overrides with `--render-scale` last, so that the flag wins.
    pub fn all_overrides(&self) -> Vec<(String, String)> {
        let mut o = self.overrides.clone();
        if let Some(s) = self.render_scale {
            o.push(("taa.render_scale".into(), format!("{s:?}")));
        }
        o
    }
}

/// `--ev100`: a fixed exposure.
#[derive(Args, Debug, Clone, Default)]
pub struct ExposureArgs {
    /// A fixed exposure: EV at ISO 100 (sunny day about 15, overcast 12, interior 7); wins
    /// over the meter, the adaptation and `--exposure-compensation` [default: metered on the
    /// illuminance of what the camera sees].
    #[arg(long, allow_negative_numbers = true)]
    pub ev100: Option<f32>,
}

/// The final image's flags, each a settings override (flags win over `--set` and the file):
/// `--white`, `--lut`, `--exposure-compensation` and the on/off switches.
#[derive(Args, Debug, Clone, Default)]
pub struct TonemapArgs {
    /// The colour white becomes, linear Rec.709 `R,G,B`, each > 0: `1,0.9,0.75` warms the
    /// image, `0.8,0.9,1` cools it (`tonemap.white`).
    #[arg(long, value_name = "R,G,B", allow_hyphen_values = true)]
    pub white: Option<String>,
    /// Grades the image with a 3D LUT in Adobe's `.cube` format (`tonemap.lut`).
    #[arg(long, value_name = "FILE.cube")]
    pub lut: Option<PathBuf>,
    /// Exposure compensation in EV, added to the metered exposure
    /// (`exposure.compensation_ev`).
    #[arg(long, value_name = "EV", allow_negative_numbers = true)]
    pub exposure_compensation: Option<f64>,
    /// No local tonemapping (`local_tonemap.enabled = false`).
    #[arg(long)]
    pub no_tonemap_local: bool,
    /// No Purkinje shift (`tonemap.purkinje = false`).
    #[arg(long)]
    pub no_purkinje: bool,
    /// No white balance (`tonemap.white_balance = false`).
    #[arg(long)]
    pub no_white_balance: bool,
    /// No tone curve: the tonemapping space is clipped at 1 (`tonemap.curve = false`).
    #[arg(long)]
    pub no_tone_curve: bool,
    /// No LUT grade, even if the settings name one (`tonemap.grade = false`).
    #[arg(long)]
    pub no_grade: bool,
    /// No dither before the 8-bit PNG (`tonemap.dither = false`).
    #[arg(long)]
    pub no_dither: bool,
}

impl TonemapArgs {
    /// The flags as `table.key = value` settings overrides (TOML values). A bad `--white` or
    /// `--lut` is an error naming the flag.
    pub fn overrides(&self) -> anyhow::Result<Vec<(String, String)>> {
        let mut out = Vec::new();
        let mut set = |k: &str, v: String| out.push((k.to_string(), v));
        if let Some(w) = &self.white {
            let rgb = parse_white(w)?;
            set(
                "tonemap.white",
                format!("[{}, {}, {}]", rgb[0], rgb[1], rgb[2]),
            );
        }
        if let Some(p) = &self.lut {
            hikari_render::techniques::tonemap::cube::CubeLut::read(p)
                .map_err(|e| anyhow::anyhow!("--lut: {e}"))?;
            set(
                "tonemap.lut",
                toml::Value::String(p.display().to_string()).to_string(),
            );
        }
        if let Some(ev) = self.exposure_compensation {
            if !ev.is_finite() {
                anyhow::bail!("--exposure-compensation {ev} is not a finite number of EV");
            }
            set("exposure.compensation_ev", format!("{ev:?}"));
        }
        for (on, key) in [
            (self.no_tonemap_local, "local_tonemap.enabled"),
            (self.no_purkinje, "tonemap.purkinje"),
            (self.no_white_balance, "tonemap.white_balance"),
            (self.no_tone_curve, "tonemap.curve"),
            (self.no_grade, "tonemap.grade"),
            (self.no_dither, "tonemap.dither"),
        ] {
            if on {
                set(key, "false".into());
            }
        }
        Ok(out)
    }
}

/// `R,G,B`: three finite numbers > 0 (a white that is black, negative or NaN balances
/// nothing).
pub fn parse_white(s: &str) -> anyhow::Result<[f32; 3]> {
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    if parts.len() != 3 {
        anyhow::bail!(
            "--white {s:?}: expected three numbers R,G,B (linear Rec.709), e.g. 1,0.9,0.8"
        );
    }
    let mut rgb = [0f32; 3];
    for (k, p) in parts.iter().enumerate() {
        let v: f32 = p
            .parse()
            .map_err(|_| anyhow::anyhow!("--white {s:?}: `{p}` is not a number"))?;
        if !(v.is_finite() && v > 0.0) {
            anyhow::bail!(
                "--white {s:?}: {} is {v}; each component must be a finite number > 0 \
                 (white cannot become black, negative or NaN)",
                ["red", "green", "blue"][k]
            );
        }
        rgb[k] = v;
    }
    Ok(rgb)
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
    pub sky: SkyArgs,
    #[command(flatten)]
    pub lights: LightArgs,
    #[command(flatten)]
    pub size: SizeArgs,
    #[command(flatten)]
    pub config: ConfigArgs,
    #[command(flatten)]
    pub exposure: ExposureArgs,
    #[command(flatten)]
    pub tonemap: TonemapArgs,
}
