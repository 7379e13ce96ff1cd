//! `hikari sky`: the sky of a date, time, place and weather as an equirectangular EXR in nits,
//! its deringed L2 SH, and the sun and moon (`--json`). Drawn on the CPU with the sky's twin
//! (`hikari_render::techniques::sky::reference`), so it needs no GPU.
//!
//! Image: 2:1; row `y` looks at elevation 90° − (y + ½)·180°/h (zenith at the top, nadir at the
//! bottom), column `x` at azimuth (x + ½)·360°/w clockwise from north (north at the left edge,
//! east a quarter of the way across). Below the horizon: the ground (its albedo lit by the sun
//! and the sky). The sun's and moon's disks are left out (they are the directional light,
//! given in `--json`; half a degree is under a pixel at these sizes).
//!
//! SH: real orthonormal L2 (∫ Y_i Y_j dω = δ_ij), no Condon-Shortley phase, flat index
//! i = l(l+1)+m: Y0 = 0.282095, Y1..3 = 0.488603·(y, z, x), Y4 = 1.092548·xy, Y5 = 1.092548·yz,
//! Y6 = 0.315392·(3z²−1), Y7 = 1.092548·xz, Y8 = 0.546274·(x²−y²), in hikari's world axes:
//! +Y up, +Z north, +X west. Coefficients of radiance, nits (c_i = ∫ L Y_i dω); the cosine-
//! convolved irradiance is c_i times π, 2π/3, π/4 for bands 0, 1, 2.

use std::path::PathBuf;

use anyhow::Context;
use clap::Args;
use glam::Vec3;
use serde_json::json;

use hikari_atmosphere::{Tables, table::Table};
use hikari_render::graph::ImageRgba32;
use hikari_render::output;
use hikari_render::settings::SkySettings;
use hikari_render::techniques::sky::{self, SkyParams, lights::SkyLights, reference::SkyTwin};

use crate::args::{JsonArgs, SkyArgs};

#[derive(Args, Debug)]
pub struct SkyCommandArgs {
    #[command(flatten)]
    pub sky: SkyArgs,
    /// EXR output: linear Rec.709 radiance in nits.
    #[arg(short, long, default_value = "sky.exr")]
    pub output: PathBuf,
    /// Image width in pixels, 8 to 8192 (the height is half of it).
    #[arg(long, default_value_t = 512)]
    pub width: u32,
    /// Atmosphere table resolution, 0 to 2 (2: the full tables).
    #[arg(long, default_value_t = 2)]
    pub table_quality: u32,
    /// The atmosphere's colour space: lms_rayleigh (the talk's) or rec709 (Bruneton's
    /// coefficients, to compare) [default: lms_rayleigh].
    #[arg(long)]
    pub color_space: Option<String>,
    /// Also write this atmosphere table as `atmosphere.NAME.exr` (repeatable): one of
    /// transmittance, rayleigh, rayleigh_single, mie, scattering_distance, irradiance_rayleigh,
    /// irradiance_mie, ground_irradiance. Raw texels in the working colour space, per unit
    /// solar illuminance; a 3D table's z slices are stacked top to bottom.
    #[arg(long = "dump-table", value_name = "NAME")]
    pub dump_tables: Vec<String>,
    /// Folder for `--dump-table` files; defaults to the EXR's folder.
    #[arg(long)]
    pub dump_dir: Option<PathBuf>,
    #[command(flatten)]
    pub json: JsonArgs,
}

/// A table as an image: x across, y down, z slices stacked below one another.
fn table_image(name: &str, t: &Table) -> ImageRgba32 {
    let [nx, ny, nz] = t.size;
    ImageRgba32 {
        name: format!("atmosphere.{name}"),
        texture: None,
        width: nx as u32,
        height: (ny * nz) as u32,
        format: hikari_render::wgpu::TextureFormat::Rgba32Float,
        rgba: t.data.iter().map(|c| [c[0], c[1], c[2], 1.0]).collect(),
    }
}

const SH_NAMES: [&str; 9] = [
    "L00", "L1-1", "L10", "L11", "L2-2", "L2-1", "L20", "L21", "L22",
];

pub fn run(a: SkyCommandArgs) -> anyhow::Result<()> {
    if !(8..=8192).contains(&a.width) || !a.width.is_multiple_of(2) {
        anyhow::bail!("--width {} is outside the range 8 to 8192 (even)", a.width);
    }
    if !a
        .output
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("exr"))
    {
        anyhow::bail!(
            "-o {}: hikari sky writes OpenEXR; give a file name ending in .exr",
            a.output.display()
        );
    }
    if a.table_quality > 2 {
        anyhow::bail!(
            "--table-quality {} is outside the range 0 to 2",
            a.table_quality
        );
    }
    if let Some(bad) = a
        .dump_tables
        .iter()
        .find(|n| !Tables::NAMES.contains(&n.as_str()))
    {
        anyhow::bail!(
            "--dump-table {bad}: no atmosphere table of that name; there are: {}",
            Tables::NAMES.join(", ")
        );
    }
    let mut s = SkySettings {
        table_quality: a.table_quality,
        ..SkySettings::default()
    };
    a.sky.apply(&mut s)?;
    if let Some(c) = &a.color_space {
        s.color_space = c.clone();
        s.color_space()
            .map_err(|e| anyhow::anyhow!("{e}"))
            .with_context(|| format!("--color-space {c}"))?;
    }
    let params = s.atmosphere().map_err(|e| anyhow::anyhow!("{e}"))?;
    let atmosphere = sky::atmosphere_for(&params, s.table_sizes())?;
    let l = SkyLights::new(&s).map_err(|e| anyhow::anyhow!("{e}"))?;
    let params = SkyParams::new(&atmosphere, &l, &s, 0.0);
    let twin = SkyTwin::new(&atmosphere, params);

    let (w, h) = (a.width, a.width / 2);
    let mut rgba = Vec::with_capacity((w * h) as usize);
    for y in 0..h {
        let e = (90.0 - (y as f32 + 0.5) * 180.0 / h as f32).to_radians();
        for x in 0..w {
            let az = ((x as f32 + 0.5) * 360.0 / w as f32).to_radians();
            let d = Vec3::new(-az.sin() * e.cos(), e.sin(), az.cos() * e.cos());
            let c = twin.background_no_disks(d);
            let c = if c.is_finite() { c } else { Vec3::ZERO };
            rgba.push([c.x, c.y, c.z, 1.0]);
        }
    }
    let img = ImageRgba32 {
        name: "sky".into(),
        texture: None,
        width: w,
        height: h,
        format: hikari_render::wgpu::TextureFormat::Rgba32Float,
        rgba,
    };
    let (_, sh) = twin.sh();
    output::write_exr(&a.output, &img).with_context(|| format!("{}", a.output.display()))?;
    let dump_dir = a.dump_dir.clone().unwrap_or_else(|| {
        a.output
            .parent()
            .map(PathBuf::from)
            .unwrap_or_else(|| PathBuf::from("."))
    });
    for name in &a.dump_tables {
        let Some(table) = atmosphere.tables.by_name(name) else {
            anyhow::bail!("--dump-table {name}: no atmosphere table of that name");
        };
        let path = output::write_dump(&dump_dir, &table_image(name, table))
            .with_context(|| format!("--dump-table {name}"))?;
        if !a.json.json {
            println!("wrote {}", path.display());
        }
    }

    let body = |b: &sky::lights::Body, lux: f32| {
        json!({
            "azimuth_deg": b.azimuth_deg,
            "elevation_deg": b.elevation_deg,
            "illuminance_lux": lux,
        })
    };
    let sun_lux = l.sun.horizontal_lux();
    let moon_lux = l.moon.horizontal_lux();
    if a.json.json {
        let mut moon = body(&l.moon, moon_lux);
        moon["illuminated_fraction"] = json!(l.moon_illuminated_fraction);
        let v = json!({
            "output": a.output.display().to_string(),
            "date": s.date, "time": s.time, "utc_offset_h": s.utc_offset_h,
            "latitude_deg": s.latitude_deg, "longitude_deg": s.longitude_deg,
            "weather": s.weather,
            "color_space": s.color_space,
            "sun": body(&l.sun, sun_lux),
            "moon": moon,
            "sh_convention": "real orthonormal L2, no Condon-Shortley phase, index l(l+1)+m; axes +Y up, +Z north, +X west; radiance coefficients in nits",
            "sh": sh.coeffs.iter().map(|c| [c.x, c.y, c.z]).collect::<Vec<_>>(),
        });
        println!("{}", serde_json::to_string_pretty(&v)?);
    } else {
        println!("wrote {}", a.output.display());
        println!(
            "sun: azimuth {:.2}°, elevation {:.2}°, {:.1} lux on the ground; moon: azimuth {:.2}°, elevation {:.2}°, {:.4} lux, {:.1} % lit",
            l.sun.azimuth_deg,
            l.sun.elevation_deg,
            sun_lux,
            l.moon.azimuth_deg,
            l.moon.elevation_deg,
            moon_lux,
            l.moon_illuminated_fraction * 100.0
        );
        println!(
            "// L2 SH of the sky's radiance (nits), deringed; real orthonormal basis, no Condon-Shortley"
        );
        println!("// phase, index l(l+1)+m; axes +Y up, +Z north, +X west (docs/atmosphere.md)");
        for (c, name) in sh.coeffs.iter().zip(SH_NAMES) {
            println!("({:>12.6}, {:>12.6}, {:>12.6}); // {name}", c.x, c.y, c.z);
        }
    }
    Ok(())
}
