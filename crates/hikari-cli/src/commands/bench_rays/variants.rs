//! `--variants`: kernel configurations to compare, and how each is described.

use anyhow::{Context, bail};

use hikari_render::scene::bvh_trace::{Refill, TraceConfig};

/// A `--variants` entry: the configurations for coherent and for incoherent rays.
pub(super) fn parse_variant(spec: &str) -> anyhow::Result<(TraceConfig, TraceConfig)> {
    let mut configs = (TraceConfig::coherent(), TraceConfig::incoherent());
    let mut parts = spec.split('+').peekable();
    match parts.peek().copied() {
        Some("auto") => {
            parts.next();
        }
        Some("coh") => {
            parts.next();
            configs.1 = configs.0;
        }
        Some("inc") => {
            parts.next();
            configs.0 = configs.1;
        }
        _ => bail!("variant `{spec}` must start with `auto`, `coh` or `inc`"),
    }
    for part in parts {
        let num = |prefix: &str| -> anyhow::Result<u32> {
            part[prefix.len()..]
                .parse()
                .with_context(|| format!("variant `{spec}`: `{part}` needs a number"))
        };
        let change: Box<dyn Fn(&mut TraceConfig)> = match part {
            "checked" => Box::new(|c| c.runtime_checks = true),
            "alpha" => Box::new(|c| c.alpha = true),
            "dyn" => Box::new(|c| c.refill = Refill::Dynamic),
            "stride" => Box::new(|c| c.refill = Refill::Stride),
            p if p.starts_with("refill") => {
                let min_free = num("refill")?;
                Box::new(move |c| c.refill = Refill::Subgroup { min_free })
            }
            p if p.starts_with("rpt") => {
                let n = num("rpt")?;
                Box::new(move |c| c.rays_per_thread = n)
            }
            p if p.starts_with("wg") => {
                let n = num("wg")?;
                Box::new(move |c| c.workgroup = n)
            }
            p if p.starts_with("tri") => {
                let n = num("tri")?;
                Box::new(move |c| c.triangles_per_step = n)
            }
            _ => bail!(
                "variant `{spec}`: unknown part `{part}` (checked, dyn, stride, refill<N>, \
                 rpt<N>, wg<N>, tri<N>)"
            ),
        };
        change(&mut configs.0);
        change(&mut configs.1);
    }
    Ok(configs)
}

/// A kernel configuration in a few words.
pub(super) fn kernel_summary(c: &TraceConfig) -> String {
    let refill = match c.refill {
        Refill::Stride => "stride".to_string(),
        Refill::Dynamic => "dynamic".to_string(),
        Refill::Subgroup { min_free } => format!("subgroup refill at {min_free}"),
    };
    let tris = match c.triangles_per_step {
        0 => "all".to_string(),
        n => n.to_string(),
    };
    format!(
        "workgroup {}, {} rays/invocation ({refill}), {tris} triangles/step{}{}",
        c.workgroup,
        c.rays_per_thread,
        if c.runtime_checks { ", checked" } else { "" },
        if c.alpha { ", cut-outs" } else { "" }
    )
}
