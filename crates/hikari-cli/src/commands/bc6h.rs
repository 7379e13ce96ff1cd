//! `hikari bc6h IN.exr -o OUT.dds`: an HDR image compressed to BC6H_UF16 with the encoder the
//! reflection probes use (on the GPU; `--cpu` runs its twin), written as a DDS file with the
//! DX10 header, and its error against the input printed (docs/bc6h.md).

use std::path::PathBuf;
use std::time::Instant;

use anyhow::Context;
use clap::Args;
use serde_json::json;

use hikari_render::bc6h::{self, Bc6hEncoder, Quality, reference};

use crate::args::JsonArgs;

#[derive(Args, Debug)]
pub struct Bc6hArgs {
    /// The HDR image: an OpenEXR file (its first RGBA layer; alpha is dropped).
    pub input: PathBuf,
    /// The DDS file to write (BC6H_UF16, DX10 header, one mip level).
    #[arg(short, long)]
    pub output: PathBuf,
    /// `fast`: the block's bounding box; `high`: also two insets of it, the best kept.
    #[arg(long, default_value = "fast")]
    pub quality: Quality,
    /// Encode on the CPU (the GPU encoder's twin, same blocks) instead of the GPU.
    #[arg(long)]
    pub cpu: bool,
    #[command(flatten)]
    pub json: JsonArgs,
}

pub fn run(a: Bc6hArgs) -> anyhow::Result<()> {
    anyhow::ensure!(
        a.output
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("dds")),
        "{}: the output must be a .dds file",
        a.output.display()
    );
    let (w, h, rgb) = hikari_render::output::read_exr_rgb(&a.input)?;
    anyhow::ensure!(w > 0 && h > 0, "{}: an empty image", a.input.display());
    let t0 = Instant::now();
    let (blocks, encoder) = if a.cpu {
        (
            reference::encode_image(&rgb, w, h, a.quality),
            "CPU".to_string(),
        )
    } else {
        let ctx = crate::still::gpu()?;
        let enc = Bc6hEncoder::new(&ctx)?;
        let blocks = enc.encode_rgb(&ctx, &rgb, w, h, a.quality)?;
        (blocks, format!("GPU, {}", ctx.describe()))
    };
    let seconds = t0.elapsed().as_secs_f64();
    let decoded = bc6h::decode_image(&blocks, w, h).context("reading the blocks back")?;
    let err = bc6h::error(&rgb, &decoded);
    bc6h::dds::write(&a.output, &blocks, w, h)?;
    let (before, after) = ((w * h) as u64 * 8, blocks.len() as u64);
    if a.json.json {
        let out = json!({
            "input": a.input.display().to_string(),
            "output": a.output.display().to_string(),
            "width": w, "height": h,
            "quality": format!("{:?}", a.quality).to_lowercase(),
            "encoder": encoder,
            "seconds": seconds,
            "bytes_rgba16f": before, "bytes_bc6h": after,
            "rms_log2": err.rms_log2, "mean_relative": err.mean_relative, "max_abs": err.max_abs,
        });
        println!("{}", serde_json::to_string_pretty(&out)?);
    } else {
        println!(
            "{}: {w}x{h}, {} as RGBA16F -> {} BC6H_UF16 ({}x smaller), {} quality on the \
             {encoder} in {:.3} s (with start-up)",
            a.output.display(),
            size(before),
            size(after),
            before / after.max(1),
            format!("{:?}", a.quality).to_lowercase(),
            seconds
        );
        println!(
            "error against the input: RMS of log2 {:.4}, mean relative {:.2} %, largest {:.4}",
            err.rms_log2,
            err.mean_relative * 100.0,
            err.max_abs
        );
    }
    Ok(())
}

fn size(bytes: u64) -> String {
    if bytes >= 1_000_000 {
        format!("{:.1} MB", bytes as f64 / 1e6)
    } else {
        format!("{:.1} kB", bytes as f64 / 1e3)
    }
}
