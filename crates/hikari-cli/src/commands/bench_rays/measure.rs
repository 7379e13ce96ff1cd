//! Timing one workload on the GPU, reading its hits back and checking a sample of them
//! against the CPU twin (hikari-bvh).

use std::time::Instant;

use anyhow::{Context, ensure};

use hikari_bvh::{Blas, Hit, Ray, Tlas};
use hikari_render::GpuContext;
use hikari_render::graph::GraphRuntime;
use hikari_render::scene::bvh_trace::{
    BvhTrace, HIT_BYTES, RAY_BYTES, RayOrder, TraceConfig, TraceMode,
};
use hikari_render::wgpu;

use super::RaysArgs;
use super::rays::{RaySource, coherent_size};

/// Untimed trace passes run for at least this long (and at least two) before the timed ones.
const WARM_UP_S: f64 = 0.3;

/// One set of rays and how the kernel traces them.
pub(super) struct Workload {
    pub name: &'static str,
    pub mode: TraceMode,
    pub order: RayOrder,
    pub rays: Vec<Ray>,
    /// E.g. the coherent image size.
    pub note: String,
}

/// `t_max` of the ambient-occlusion (any hit) rays, metres.
const AO_T_MAX: f32 = 5.0;

/// The four workloads of about `n` rays each: incoherent closest and any hit, and a coherent
/// image traced as an image and in buffer order.
pub(super) fn workloads(source: &RaySource, n: usize) -> [Workload; 4] {
    let incoherent = source.incoherent(n);
    let ao: Vec<Ray> = incoherent
        .iter()
        .map(|r| Ray {
            t_max: AO_T_MAX,
            ..*r
        })
        .collect();
    let (w, h) = coherent_size(n);
    let coherent = source.coherent(w, h);
    [
        Workload {
            name: "incoherent closest hit",
            mode: TraceMode::Closest,
            order: RayOrder::Incoherent,
            rays: incoherent,
            note: "surface points, cosine directions".into(),
        },
        Workload {
            name: "incoherent any hit (AO, t_max 5)",
            mode: TraceMode::Any,
            order: RayOrder::Incoherent,
            rays: ao,
            note: "same rays".into(),
        },
        Workload {
            name: "coherent closest hit",
            mode: TraceMode::Closest,
            order: RayOrder::Image { width: w },
            rays: coherent.clone(),
            note: format!("{w}x{h} pinhole, row-major, traced as an image (8x8 tiles)"),
        },
        Workload {
            name: "coherent closest hit, buffer order",
            mode: TraceMode::Closest,
            order: RayOrder::Coherent,
            rays: coherent,
            note: "same rays, traced in buffer order (32-pixel row strips per warp)".into(),
        },
    ]
}

/// One workload traced by one kernel variant: times in milliseconds, hits and the CPU check.
pub(super) struct Measured {
    pub variant: String,
    /// The kernel configuration that traced it.
    pub kernel: TraceConfig,
    pub name: &'static str,
    pub mode: TraceMode,
    pub rays: usize,
    pub note: String,
    pub median_ms: f64,
    pub min_ms: f64,
    pub hits: usize,
    pub checked: usize,
    pub mismatches: usize,
}

impl Measured {
    pub(super) fn grays(&self, ms: f64) -> f64 {
        self.rays as f64 / (ms * 1e-3) / 1e9
    }
}

pub(super) fn median_min(v: &mut [f64]) -> (f64, f64) {
    v.sort_by(f64::total_cmp);
    (v[v.len() / 2], v[0])
}

#[allow(clippy::too_many_arguments)]
pub(super) fn measure(
    ctx: &GpuContext,
    rt: &mut GraphRuntime,
    trace: &BvhTrace,
    blases: &[Blas],
    tlas: &Tlas,
    wl: &Workload,
    ray_buffer: &wgpu::Buffer,
    args: &RaysArgs,
    timestamps: bool,
) -> anyhow::Result<Measured> {
    let n = wl.rays.len() as u32;
    let mut frame = |readback: bool| -> anyhow::Result<(Option<f64>, Option<Vec<u8>>)> {
        let t0 = Instant::now();
        let mut g = rt.begin_frame(ctx);
        let rays = g.import_buffer("bench.rays", ray_buffer);
        let (hits, _) = g.persistent_buffer("bench.hits", n as u64 * HIT_BYTES)?;
        trace.record(&mut g, rays, hits, n, wl.mode, wl.order)?;
        if readback {
            g.readback(hits);
        }
        let r = g.execute()?;
        ctx.wait_idle()?;
        let wall = t0.elapsed().as_secs_f64() * 1e3;
        let gpu = r
            .timings
            .iter()
            .find(|t| t.name == wl.mode.pass_name())
            .and_then(|t| t.gpu_ms);
        let ms = if timestamps { gpu } else { Some(wall) };
        Ok((ms, r.buffers.into_iter().next().map(|(_, b)| b)))
    };
    // GPU clocks drop while the CPU builds kernels and checks hits: warm up for a while.
    let warm = Instant::now();
    for k in 0.. {
        if k >= 2 && warm.elapsed().as_secs_f64() > WARM_UP_S {
            break;
        }
        frame(false)?;
    }
    let mut times = Vec::new();
    for _ in 0..args.iterations {
        times.extend(frame(false)?.0);
    }
    ensure!(
        !times.is_empty(),
        "no GPU timings came back for `{}`",
        wl.mode.pass_name()
    );
    let (median_ms, min_ms) = median_min(&mut times);
    let (_, bytes) = frame(true)?;
    let bytes = bytes.context("the hit buffer was not read back")?;
    let hits = hits_from_bytes(&bytes[..n as usize * HIT_BYTES as usize]);
    let hit_count = hits.iter().filter(|h| h.is_hit()).count();

    // An even spread of rays over the whole buffer, traced again on the CPU.
    let sample = (args.check as usize).min(hits.len());
    let idx: Vec<usize> = (0..sample)
        .map(|k| k * hits.len() / sample.max(1))
        .collect();
    let sample_rays: Vec<Ray> = idx.iter().map(|&i| wl.rays[i]).collect();
    let mismatched: Vec<(usize, String)> = match wl.mode {
        TraceMode::Closest => {
            let cpu = tlas.closest_hits(blases, &sample_rays, 0);
            idx.iter()
                .zip(&cpu)
                .filter(|&(&i, c)| !same_hit(&hits[i], c, &wl.rays[i]))
                .map(|(&i, c)| (i, format!("GPU {:?}, CPU {c:?}", hits[i])))
                .collect()
        }
        TraceMode::Any => {
            let cpu = tlas.any_hits(blases, &sample_rays, 0);
            idx.iter()
                .zip(&cpu)
                .filter(|&(&i, &c)| hits[i].is_hit() != c)
                .map(|(&i, &c)| (i, format!("GPU {:?}, CPU occluded: {c}", hits[i])))
                .collect()
        }
    };
    for (i, e) in mismatched.iter().take(args.show_mismatches as usize) {
        eprintln!("{} ray {i} {:?}: {e}", wl.name, wl.rays[*i]);
    }
    let mismatches = mismatched.len();
    Ok(Measured {
        variant: String::new(),
        kernel: trace.config(wl.order),
        name: wl.name,
        mode: wl.mode,
        rays: wl.rays.len(),
        note: wl.note.clone(),
        median_ms,
        min_ms,
        hits: hit_count,
        checked: sample,
        mismatches,
    })
}

/// The GPU layout of hikari-bvh's `Ray` (32 bytes, little-endian).
pub(super) fn ray_bytes(rays: &[Ray]) -> Vec<u8> {
    let mut out = Vec::with_capacity(rays.len() * RAY_BYTES as usize);
    for r in rays {
        for v in r
            .origin
            .iter()
            .chain([&r.t_min])
            .chain(&r.dir)
            .chain([&r.t_max])
        {
            out.extend_from_slice(&v.to_le_bytes());
        }
    }
    out
}

/// hikari-bvh's `Hit` records (32 bytes, little-endian).
fn hits_from_bytes(bytes: &[u8]) -> Vec<Hit> {
    bytes
        .chunks_exact(HIT_BYTES as usize)
        .map(|c| {
            let w =
                |k: usize| u32::from_le_bytes([c[4 * k], c[4 * k + 1], c[4 * k + 2], c[4 * k + 3]]);
            Hit {
                t: f32::from_bits(w(0)),
                u: f32::from_bits(w(1)),
                v: f32::from_bits(w(2)),
                primitive: w(3),
                instance: w(4),
                _pad: [0; 3],
            }
        })
        .collect()
}

/// Whether the GPU's closest hit matches the CPU twin's: the same primitive of the same
/// instance at the same t, or a tie (another one at the same t, e.g. coincident faces of two
/// instances). "The same t" is 1e-4 relative (1e-6 for a tie) plus 1e-6 of the ray origin's
/// largest coordinate: the GPU fuses multiply-adds where the CPU rounds twice, and in the
/// instance transform that alone moves t by a few ulps of the coordinates (4e-5 m at 200 m
/// from the origin, seen in the village). Barycentrics are not compared: far away, such a
/// rounding of the hit point is a visible fraction of a small triangle (tests/bvh_trace.rs
/// compares them on small scenes).
pub(super) fn same_hit(g: &Hit, w: &Hit, ray: &Ray) -> bool {
    let coords = ray.origin.iter().fold(1.0f32, |m, c| m.max(c.abs()));
    let slack = 1e-6 * coords;
    match (g.is_hit(), w.is_hit()) {
        (false, false) => true,
        (true, true) => {
            let dt = (g.t - w.t).abs();
            if g.primitive == w.primitive && g.instance == w.instance {
                dt <= 1e-4 * w.t.abs() + slack
            } else {
                dt <= 1e-6 * w.t.abs() + slack
            }
        }
        _ => false,
    }
}
