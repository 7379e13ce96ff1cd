//! Per-pass timing reports: one frame's table (`render --timings`), and the median, min and
//! max over many frames (`bench frame`) as a table or as JSON.

use std::collections::BTreeMap;

use serde_json::json;

use hikari_render::graph::FrameResult;

/// Median, mean, minimum and maximum of a set of samples (in whatever unit they were taken).
#[derive(Default, Clone, Copy, Debug, PartialEq)]
pub struct Stats {
    pub median: f64,
    /// What work done every few frames costs on average, which the median hides.
    pub mean: f64,
    pub min: f64,
    pub max: f64,
}

impl Stats {
    /// `None` for no samples. The median of an even count is the upper of the middle two.
    pub fn of(mut v: Vec<f64>) -> Option<Self> {
        if v.is_empty() {
            return None;
        }
        v.sort_by(|a, b| a.total_cmp(b));
        Some(Self {
            median: v[v.len() / 2],
            mean: v.iter().sum::<f64>() / v.len() as f64,
            min: v[0],
            max: v[v.len() - 1],
        })
    }

    pub fn json(&self) -> serde_json::Value {
        json!({ "median": self.median, "mean": self.mean, "min": self.min, "max": self.max })
    }
}

/// Milliseconds of `d`.
pub fn ms(d: std::time::Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

/// The `--timings` table of a single frame.
pub fn print_single_frame(r: &FrameResult) {
    println!("{:<32} {:>10} {:>10}", "pass", "GPU ms", "CPU us");
    for t in &r.timings {
        let gpu = t.gpu_ms.map_or("n/a".to_string(), |v| format!("{v:.4}"));
        println!("{:<32} {:>10} {:>10.1}", t.name, gpu, t.cpu_us);
    }
    if let Some(s) = r.gpu_span_ms {
        println!("{:<32} {:>10.4}", "frame (first to last pass)", s);
    }
}

/// One pass over many frames.
#[derive(Debug, Clone, PartialEq)]
pub struct PassRow {
    pub name: String,
    /// Milliseconds; `None` without timestamps.
    pub gpu_ms: Option<Stats>,
    /// Microseconds to record and encode it.
    pub cpu_us: Stats,
    /// Bytes it binds to read and write (the last frame's): its memory floor's numerator.
    pub bytes: u64,
}

/// Timings gathered frame after frame.
#[derive(Default)]
pub struct FrameTimings {
    /// Per pass name: the index it first appeared at, GPU ms and CPU us samples.
    per_pass: BTreeMap<String, (usize, Vec<f64>, Vec<f64>, u64)>,
    spans: Vec<f64>,
    encode: Vec<f64>,
}

/// The summary of [`FrameTimings`].
pub struct FrameSummary {
    /// In the order the passes ran.
    pub passes: Vec<PassRow>,
    /// First to last pass on the GPU, ms; `None` without timestamps.
    pub span_ms: Option<Stats>,
    /// CPU encode of the whole frame, us.
    pub encode_us: Stats,
    /// The adapter's copy bandwidth, GB/s (read plus write), when measured: the table then
    /// shows each pass's bytes and memory floor.
    pub bandwidth_gbs: Option<f64>,
}

impl FrameTimings {
    pub fn add(&mut self, r: &FrameResult) {
        for (i, t) in r.timings.iter().enumerate() {
            let e = self
                .per_pass
                .entry(t.name.clone())
                .or_insert((i, vec![], vec![], 0));
            e.1.extend(t.gpu_ms);
            e.2.push(t.cpu_us);
            e.3 = t.traffic.total();
        }
        self.spans.extend(r.gpu_span_ms);
        self.encode.push(r.cpu_encode_us);
    }

    pub fn summary(self) -> FrameSummary {
        let mut rows: Vec<_> = self.per_pass.into_iter().collect();
        rows.sort_by_key(|(_, (i, _, _, _))| *i);
        FrameSummary {
            passes: rows
                .into_iter()
                .map(|(name, (_, gpu, cpu, bytes))| PassRow {
                    name,
                    gpu_ms: Stats::of(gpu),
                    cpu_us: Stats::of(cpu).unwrap_or_default(),
                    bytes,
                })
                .collect(),
            span_ms: Stats::of(self.spans),
            encode_us: Stats::of(self.encode).unwrap_or_default(),
            bandwidth_gbs: None,
        }
    }
}

impl FrameSummary {
    /// Per technique (the pass name before its first dot), the sum of its passes' GPU
    /// medians in ms, in the order the techniques first ran; passes without a time add 0.
    pub fn technique_sums(&self) -> Vec<(String, f64)> {
        let mut techniques: Vec<(String, f64)> = Vec::new();
        for p in &self.passes {
            let t = p.name.split('.').next().unwrap_or(&p.name);
            let ms = p.gpu_ms.map_or(0.0, |g| g.median);
            match techniques.iter_mut().find(|(n, _)| n == t) {
                Some(e) => e.1 += ms,
                None => techniques.push((t.to_string(), ms)),
            }
        }
        techniques
    }

    /// `passes` for the JSON report.
    pub fn passes_json(&self) -> serde_json::Value {
        self.passes
            .iter()
            .map(|p| {
                json!({
                    "name": p.name,
                    "gpu_ms": p.gpu_ms.map(|s| s.json()),
                    "cpu_us": p.cpu_us.json(),
                    "bytes": p.bytes,
                    "floor_ms": self.floor_ms(p),
                })
            })
            .collect()
    }

    /// A pass's memory floor, ms: its bytes at the measured bandwidth.
    pub fn floor_ms(&self, p: &PassRow) -> Option<f64> {
        self.bandwidth_gbs
            .filter(|_| p.bytes > 0)
            .map(|gbs| p.bytes as f64 / (gbs * 1e6))
    }

    /// The per-pass table, the sums per technique and the whole frame; with a measured
    /// bandwidth, each pass's bytes, memory floor and how many floors its median is.
    pub fn print_table(&self) {
        let floors = self.bandwidth_gbs.is_some();
        let extra = if floors {
            format!(" {:>9} {:>9} {:>7}", "MB", "floor ms", "x floor")
        } else {
            String::new()
        };
        println!(
            "{:<32} {:>10} {:>10} {:>10} {:>12}{extra}",
            "pass", "GPU med ms", "min", "max", "CPU med us"
        );
        for p in &self.passes {
            let extra = match self.floor_ms(p) {
                Some(f) => format!(
                    " {:>9.2} {:>9.4} {:>7}",
                    p.bytes as f64 / 1e6,
                    f,
                    p.gpu_ms
                        .map_or(String::new(), |g| format!("{:.1}", g.median / f.max(1e-9)))
                ),
                None => String::new(),
            };
            match p.gpu_ms {
                Some(g) => println!(
                    "{:<32} {:>10.4} {:>10.4} {:>10.4} {:>12.1}{extra}",
                    p.name, g.median, g.min, g.max, p.cpu_us.median
                ),
                None => println!(
                    "{:<32} {:>10} {:>10} {:>10} {:>12.1}{extra}",
                    p.name, "n/a", "", "", p.cpu_us.median
                ),
            }
        }
        if let Some(gbs) = self.bandwidth_gbs {
            println!(
                "memory floor: bytes bound to read and write at {gbs:.0} GB/s (a buffer copy's \
                 read plus write rate)"
            );
        }
        for (t, ms) in self.technique_sums() {
            println!("{:<32} {:>10.4}", format!("{t} (sum of medians)"), ms);
        }
        match self.span_ms {
            Some(s) => {
                println!(
                    "{:<32} {:>10.4} {:>10.4} {:>10.4} {:>12.1}",
                    "frame (first to last pass)", s.median, s.min, s.max, self.encode_us.median
                );
                println!("{:<32} {:>10.4}", "frame mean", s.mean);
            }
            None => println!(
                "no GPU timestamps on this adapter; CPU encode median {:.1} us",
                self.encode_us.median
            ),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stats_are_the_middle_smallest_and_largest_sample() {
        assert_eq!(Stats::of(vec![]), None);
        let s = Stats::of(vec![5.0, 1.0, 3.0]).unwrap();
        assert_eq!((s.median, s.min, s.max), (3.0, 1.0, 5.0));
        assert_eq!(s.mean, 3.0);
        assert_eq!(Stats::of(vec![1.0, 1.0, 10.0]).unwrap().mean, 4.0);
        let s = Stats::of(vec![4.0, 1.0, 2.0, 3.0]).unwrap();
        assert_eq!(s.median, 3.0);
    }

    #[test]
    fn technique_sums_add_the_medians_of_passes_sharing_the_prefix() {
        let row = |name: &str, ms: Option<f64>| PassRow {
            name: name.into(),
            gpu_ms: ms.map(|m| Stats {
                median: m,
                mean: m,
                min: m,
                max: m,
            }),
            cpu_us: Stats::default(),
            bytes: 0,
        };
        let s = FrameSummary {
            passes: vec![
                row("gbuffer.raster", Some(1.0)),
                row("shadows.a", Some(0.25)),
                row("gbuffer.resolve", Some(0.5)),
                row("shadows.b", None),
                row("tonemap", Some(2.0)),
            ],
            span_ms: None,
            encode_us: Stats::default(),
            bandwidth_gbs: None,
        };
        assert_eq!(
            s.technique_sums(),
            vec![
                ("gbuffer".to_string(), 1.5),
                ("shadows".to_string(), 0.25),
                ("tonemap".to_string(), 2.0)
            ]
        );
    }
}

/// The scene BVH's per-frame update (`Renderer::scene_rt_stats`) over many frames.
#[derive(Default)]
pub struct BvhUpdates {
    frames: Vec<hikari_render::scene::rt::FrameBvhStats>,
}

impl BvhUpdates {
    pub fn add(&mut self, s: Option<hikari_render::scene::rt::FrameBvhStats>) {
        self.frames.extend(s);
    }

    fn stats(&self, f: impl Fn(&hikari_render::scene::rt::FrameBvhStats) -> f64) -> Stats {
        Stats::of(self.frames.iter().map(f).collect()).unwrap_or_default()
    }

    /// Median, min and max of each quantity; `null` when no frame reported one.
    pub fn json(&self) -> serde_json::Value {
        if self.frames.is_empty() {
            return serde_json::Value::Null;
        }
        json!({
            "tlas_cpu_ms": self.stats(|s| s.tlas_ms).json(),
            "refit_cpu_ms": self.stats(|s| s.refit_ms).json(),
            "raster_vertices_cpu_ms": self.stats(|s| s.raster_ms).json(),
            "upload_bytes": self.stats(|s| s.upload_bytes as f64).json(),
            "instances_kept": self.stats(|s| s.instances_kept as f64).json(),
            "instances_culled": self.stats(|s| s.instances_culled as f64).json(),
            "refits_done": self.stats(|s| s.refits_done as f64).json(),
            "refit_vertices": self.stats(|s| s.refit_vertices as f64).json(),
            "refits_pending": self.stats(|s| s.refits_pending as f64).json(),
        })
    }

    /// Lines under the pass table: each quantity's median (min to max).
    pub fn print(&self) {
        if self.frames.is_empty() {
            return;
        }
        println!("scene BVH update (CPU, per frame: median, min to max)");
        let row = |name: &str, s: Stats, digits: usize| {
            println!(
                "  {name:<28} {:>12.digits$} ({:.digits$} to {:.digits$})",
                s.median, s.min, s.max
            );
        };
        row("TLAS build + culling ms", self.stats(|s| s.tlas_ms), 3);
        row("deform + refit ms", self.stats(|s| s.refit_ms), 3);
        row("raster vertices ms", self.stats(|s| s.raster_ms), 3);
        row("upload bytes", self.stats(|s| s.upload_bytes as f64), 0);
        row("instances kept", self.stats(|s| s.instances_kept as f64), 0);
        row(
            "instances culled",
            self.stats(|s| s.instances_culled as f64),
            0,
        );
        row("refits done", self.stats(|s| s.refits_done as f64), 0);
        row("refits pending", self.stats(|s| s.refits_pending as f64), 0);
    }
}
