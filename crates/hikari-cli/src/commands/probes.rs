//! `hikari probes`: the scene's baked probes as JSON (from the cache, baking on a miss, or
//! `--bake FILE`): every probe's position, interior flag, sky visibility (9 floats, L2 SH in
//! hikari-math's order: l=0; l=1 m=-1,0,1; l=2 m=-2..2, real orthonormal basis) and bounced
//! sky visibility (9 RGB triples), and the grid tile or tetrahedral mesh holding it. With
//! `--at X,Y,Z` the values interpolated there instead (as the renderer looks them up, with the
//! interior mask at 0.5); with `--date`, `--time` or `--weather` also the relit irradiance
//! there (the sky's SH and the sun or moon of that moment, on the CPU twins).

use std::path::PathBuf;

use anyhow::{Context, bail};
use clap::Args;
use glam::Vec3;
use serde_json::{Value, json};

use hikari_math::sh::{Sh, ShL2, ShL2Rgb};
use hikari_render::techniques::irradiance_probes::gpu_data::ProbeGpuData;
use hikari_render::techniques::irradiance_probes::{RelightParams, reference};
use hikari_render::techniques::sky::{self, SkyParams, reference::SkyTwin};

use crate::args::{ConfigArgs, FrameArgs, JsonArgs, SceneArgs, SkyArgs};
use crate::probe_bake;
use crate::progress::{self, ProgressArgs};
use crate::scene_source;

/// Only the flags that change what `probes` prints: the scene, its bake, the settings (the
/// probes' relight) and the sky's instant for the relit irradiance.
#[derive(Args, Debug)]
pub struct ProbesArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
    #[command(flatten)]
    pub sky: SkyArgs,
    #[command(flatten)]
    pub config: ConfigArgs,
    /// Bake file to read [default: the cache; baked on a miss].
    #[arg(long)]
    pub bake: Option<PathBuf>,
    /// A point X,Y,Z in metres to interpolate the probes at; repeatable.
    #[arg(long = "at", value_name = "X,Y,Z", allow_hyphen_values = true)]
    pub at: Vec<String>,
    #[command(flatten)]
    pub json: JsonArgs,
    #[command(flatten)]
    pub progress: ProgressArgs,
}

fn parse_point(s: &str) -> anyhow::Result<Vec3> {
    let v: Vec<f32> = s
        .split(',')
        .map(|x| x.trim().parse::<f32>())
        .collect::<Result<_, _>>()
        .with_context(|| format!("--at {s}: not three numbers X,Y,Z"))?;
    if v.len() != 3 || v.iter().any(|x| !x.is_finite()) {
        bail!("--at {s}: not three finite numbers X,Y,Z (metres)");
    }
    Ok(Vec3::new(v[0], v[1], v[2]))
}

fn sh9(c: &[f32; 9]) -> Value {
    json!(c.to_vec())
}

fn rgb9(c: &[[f32; 3]; 9]) -> Value {
    json!(c.iter().map(|x| x.to_vec()).collect::<Vec<_>>())
}

fn list(bake: &hikari_probes::Bake) -> Vec<Value> {
    let mut out = Vec::new();
    for t in &bake.tiles {
        for layer in 0..hikari_probes::TILE_LAYERS {
            for j in 0..16 {
                for i in 0..16 {
                    let k = hikari_probes::GridTile::probe_index(i, j, layer);
                    let p = t
                        .probe_position(&bake.settings, i, j, layer)
                        .unwrap_or_default();
                    out.push(json!({
                        "position": p,
                        "interior": t.interior[k],
                        "sky_visibility": sh9(&t.probes[k].sky_visibility),
                        "bounced_sky_visibility": rgb9(&t.probes[k].bounced_sky_visibility),
                        "grid_tile": t.tile,
                        "index": [i, j, layer],
                    }));
                }
            }
        }
    }
    for m in &bake.meshes {
        for (k, p) in m.probes.iter().enumerate() {
            out.push(json!({
                "position": m.positions[k],
                "interior": m.interior[k],
                "sky_visibility": sh9(&p.sky_visibility),
                "bounced_sky_visibility": rgb9(&p.bounced_sky_visibility),
                "mesh": m.id,
                "index": k,
            }));
        }
    }
    out
}

/// Where a global probe of `data` comes from: `("grid_tile", [x, z])` or `("mesh", id)`.
fn holder(data: &ProbeGpuData, bake: &hikari_probes::Bake, probe: u32) -> Value {
    for (t, slot) in data.tiles.iter().enumerate() {
        let n = hikari_probes::TILE_PROBE_COUNT as u32;
        if probe >= slot.first_probe && probe < slot.first_probe + n {
            return json!({"grid_tile": bake.tiles[t].tile});
        }
    }
    for (m, slot) in data.meshes.iter().enumerate() {
        if probe >= slot.first_probe && probe < slot.first_probe + slot.probes {
            return json!({"mesh": bake.meshes[m].id});
        }
    }
    Value::Null
}

pub fn run(a: ProbesArgs) -> anyhow::Result<()> {
    progress::set_quiet(a.progress.quiet);
    let points: Vec<Vec3> =
        a.at.iter()
            .map(|s| parse_point(s))
            .collect::<Result<_, _>>()?;
    let frame_args = FrameArgs {
        scene: a.scene.clone(),
        sky: a.sky.clone(),
        config: a.config.clone(),
        ..FrameArgs::default()
    };
    let frame = scene_source::resolve(&frame_args)?;
    let bake = probe_bake::for_render(
        &frame.scene,
        &frame.description.source,
        a.bake.as_deref(),
        None,
    )?;
    if points.is_empty() {
        let probes = list(&bake);
        if a.json.json {
            println!("{}", serde_json::to_string(&json!({"probes": probes}))?);
        } else {
            println!(
                "{} probes in {} grid tiles and {} tetrahedral meshes (--json lists them)",
                probes.len(),
                bake.tiles.len(),
                bake.meshes.len()
            );
        }
        return Ok(());
    }

    let data = ProbeGpuData::new(&bake);
    let relit = a.sky.sets_time() || a.sky.weather.is_some();
    let relight = if relit {
        let s = &frame.settings.settings.sky;
        let (params, sizes) = s.table_key().map_err(|e| anyhow::anyhow!("{e}"))?;
        let atmosphere = sky::atmosphere_for(&params, sizes)?;
        let cx = frame.settings.context()?;
        let lights = cx.sky.as_ref().context("--time needs the sky on")?.lights;
        let sky_params = SkyParams::new(&atmosphere, &lights, s, 0.0);
        let (raw, _) = SkyTwin::new(&atmosphere, sky_params).sh();
        let knobs = sky::frame_knobs(s, &lights);
        let params = RelightParams::new(
            cx.sun.as_ref(),
            &frame.settings.settings.irradiance_probes,
            0,
        );
        Some((raw, params, knobs.ambient_diffuse))
    } else {
        None
    };
    let mut out = Vec::new();
    for p in &points {
        let w = reference::blended_weights(&data, *p, 0.5);
        let covered = w.iter().map(|x| x.1).sum::<f32>() > 0.0;
        let mut entry = json!({"position": p.to_array(), "covered": covered});
        if covered {
            let mut vis = ShL2::zero();
            let mut bounce = ShL2Rgb::zero();
            for &(k, wk) in &w {
                let (v, b) = data.probe_sh(k as usize);
                for c in 0..9 {
                    vis.coeffs[c] += v.coeffs[c] * wk;
                    bounce.coeffs[c] += b.coeffs[c] * wk;
                }
            }
            entry["sky_visibility"] = json!(vis.coeffs.to_vec());
            entry["bounced_sky_visibility"] = json!(
                bounce
                    .coeffs
                    .iter()
                    .map(|c| c.to_array())
                    .collect::<Vec<_>>()
            );
            entry["probes"] = json!(
                w.iter()
                    .map(|&(k, wk)| json!({"weight": wk, "position": data.positions[k as usize][..3].to_vec(), "holder": holder(&data, &bake, k)}))
                    .collect::<Vec<_>>()
            );
            if let Some((sky_sh, params, scale)) = &relight {
                let mut e = ShL2Rgb::zero();
                for &(k, wk) in &w {
                    let (v, b) = data.probe_sh(k as usize);
                    let r = reference::relight_probe(sky_sh, &v, &b, params);
                    for c in 0..9 {
                        e.coeffs[c] += r.coeffs[c] * wk * *scale;
                    }
                }
                let e: ShL2Rgb = Sh::new(e.coeffs);
                entry["irradiance_sh_lux"] =
                    json!(e.coeffs.iter().map(|c| c.to_array()).collect::<Vec<_>>());
                entry["irradiance_up_lux"] = json!(e.eval(Vec3::Y).max(Vec3::ZERO).to_array());
            }
        }
        out.push(entry);
    }
    let doc = json!({
        "sh_order": "l=0; l=1 m=-1,0,1; l=2 m=-2..2 (real orthonormal, hikari-math)",
        "relit": relit,
        "points": out,
    });
    if a.json.json {
        println!("{}", serde_json::to_string_pretty(&doc)?);
    } else {
        for e in doc["points"].as_array().into_iter().flatten() {
            println!("{e}");
        }
    }
    Ok(())
}
