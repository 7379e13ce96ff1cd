//! `hikari constants`: the derived colour, spectral and scattering constants, to take into
//! another engine. Matrices are arrays of rows acting on column vectors; linear Rec.709 is the
//! working space.

use anyhow::{Context, bail};
use clap::Args;
use serde_json::json;

use hikari_math::constants::DerivedConstants;

use crate::args::JsonArgs;

#[derive(Args, Debug)]
pub struct ConstantsArgs {
    /// The colour white should become under white balance, linear Rec.709 (e.g. 0.9,0.95,1.1).
    #[arg(long, default_value = "1,1,1")]
    pub white: String,
    #[command(flatten)]
    pub output: JsonArgs,
}

fn parse_white(s: &str) -> anyhow::Result<[f64; 3]> {
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    if parts.len() != 3 {
        bail!("--white `{s}`: expected three comma-separated numbers R,G,B");
    }
    let mut w = [0.0; 3];
    for (i, p) in parts.iter().enumerate() {
        w[i] = p
            .parse::<f64>()
            .with_context(|| format!("--white `{s}`: `{p}` is not a number"))?;
        if !w[i].is_finite() || w[i] <= 0.0 {
            bail!("--white `{s}`: each component must be finite and greater than 0");
        }
    }
    Ok(w)
}

pub fn run(args: ConstantsArgs) -> anyhow::Result<()> {
    let white = parse_white(&args.white)?;
    let c = DerivedConstants::new(white).with_context(|| format!("--white {}", args.white))?;
    let value = json!({
        "working_space": "linear Rec.709 (D65)",
        "matrix_convention": "arrays of rows; multiply column vectors",
        "white_rec709": c.white_rec709,
        "rec709_to_xyz": c.rec709_to_xyz,
        "acescg_to_xyz": c.acescg_to_xyz,
        "tonemap_to_xyz": c.tonemap_to_xyz,
        "lms_rayleigh_to_xyz": c.lms_rayleigh_to_xyz,
        "rec709_to_tonemap": c.rec709_to_tonemap,
        "tonemap_to_rec709": c.tonemap_to_rec709,
        "white_balance_rec709": c.white_balance_rec709,
        "rec709_to_tonemap_balanced": c.rec709_to_tonemap_balanced,
        "lmsr_from_rec709": c.lmsr_from_rec709,
        "rgb_from_lms_gain": c.rgb_from_lms_gain,
        "smits_basis": { "wavelengths_nm": c.smits_wavelengths_nm, "r": c.smits_basis[0], "g": c.smits_basis[1], "b": c.smits_basis[2] },
        "rayleigh_lms_per_km": c.rayleigh_lms_per_km,
        "rayleigh_rec709_per_km": c.rayleigh_rec709_per_km,
        "mie_per_km": c.mie_per_km,
    });
    if args.output.json {
        println!("{}", serde_json::to_string_pretty(&value)?);
        return Ok(());
    }
    println!("working space: linear Rec.709 (D65); matrices act on column vectors\n");
    let obj = value.as_object().unwrap();
    for (key, v) in obj {
        match v {
            serde_json::Value::Array(rows) if rows.iter().all(|r| r.is_array()) => {
                println!("{key}:");
                for r in rows {
                    let nums: Vec<String> = r
                        .as_array()
                        .unwrap()
                        .iter()
                        .map(|x| format!("{:>14.9}", x.as_f64().unwrap_or(f64::NAN)))
                        .collect();
                    println!("  [{}]", nums.join(", "));
                }
            }
            serde_json::Value::Array(xs) => {
                let nums: Vec<String> = xs.iter().map(|x| format!("{}", x)).collect();
                println!("{key}: [{}]", nums.join(", "));
            }
            serde_json::Value::Object(_) => println!(
                "{key}: (see --json; {} samples)",
                c.smits_wavelengths_nm.len()
            ),
            other if key != "working_space" && key != "matrix_convention" => {
                println!("{key}: {other}")
            }
            _ => {}
        }
    }
    Ok(())
}
