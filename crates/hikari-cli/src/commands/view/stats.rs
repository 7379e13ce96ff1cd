//! The viewer's numbers: per-pass GPU times (median over the last second), grouped by
//! technique and sorted by cost; frame times for the graph; frames per second; GI rays.

use std::collections::{BTreeMap, VecDeque};
use std::time::{Duration, Instant};

/// How far back the medians and the frame rate look.
pub const WINDOW: Duration = Duration::from_secs(1);
/// Frames the graph shows.
pub const GRAPH_FRAMES: usize = 240;

/// One frame's times.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrameTime {
    /// Wall time since the previous frame began.
    pub frame_ms: f64,
    /// CPU time of the frame: the renderer's encoding and the viewer's own work.
    pub cpu_ms: f64,
    /// The GPU's span of the frame, on the frames that were timed.
    pub gpu_ms: Option<f64>,
}

/// A technique's passes in the table.
#[derive(Clone, Debug, PartialEq)]
pub struct Group {
    pub technique: String,
    pub total_ms: f64,
    /// (pass, median ms), most expensive first.
    pub passes: Vec<(String, f64)>,
}

/// The GI's rays, from a frame that read them back.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RayStats {
    pub rays_per_pixel: f64,
    /// The share of the traced rays the screen-space pre-trace resolved (not sent to the BVH).
    pub pretrace_share: f64,
}

#[derive(Default)]
pub struct Stats {
    /// Per pass: (when, GPU ms) samples within the window.
    passes: BTreeMap<String, VecDeque<(Instant, f64)>>,
    frames: VecDeque<(Instant, FrameTime)>,
    pub rays: Option<RayStats>,
    /// The viewer's own CPU time a frame (egui layout, tessellation, paint recording), µs.
    ui_cpu_us: VecDeque<(Instant, f64)>,
    /// Every frame's viewer CPU time summed, and the frames.
    ui_cpu_sum: (f64, u64),
}

/// The median of `v` (sorted in place); `None` when empty.
pub fn median(v: &mut [f64]) -> Option<f64> {
    if v.is_empty() {
        return None;
    }
    v.sort_by(f64::total_cmp);
    let n = v.len();
    Some(if n % 2 == 1 {
        v[n / 2]
    } else {
        (v[n / 2 - 1] + v[n / 2]) / 2.0
    })
}

fn trim<T>(q: &mut VecDeque<(Instant, T)>, now: Instant, keep: Duration) {
    while q
        .front()
        .is_some_and(|(t, _)| now.duration_since(*t) > keep)
    {
        q.pop_front();
    }
}

impl Stats {
    /// A frame's per-pass GPU times (passes without a time are left out).
    pub fn add_passes<'a>(
        &mut self,
        now: Instant,
        timings: impl IntoIterator<Item = (&'a str, f64)>,
    ) {
        for (name, ms) in timings {
            self.passes
                .entry(name.to_string())
                .or_default()
                .push_back((now, ms));
        }
    }

    pub fn add_frame(&mut self, now: Instant, t: FrameTime) {
        self.frames.push_back((now, t));
        while self.frames.len() > GRAPH_FRAMES.max(1) {
            self.frames.pop_front();
        }
    }

    pub fn add_ui_cpu(&mut self, now: Instant, us: f64) {
        self.ui_cpu_sum.0 += us;
        self.ui_cpu_sum.1 += 1;
        self.ui_cpu_us.push_back((now, us));
        trim(&mut self.ui_cpu_us, now, WINDOW);
    }

    /// The viewer's median CPU time a frame over the last second, µs.
    pub fn ui_cpu_us(&self) -> Option<f64> {
        median(&mut self.ui_cpu_us.iter().map(|(_, v)| *v).collect::<Vec<_>>())
    }

    /// The viewer's mean CPU time a frame since it started, µs, and over how many frames.
    pub fn ui_cpu_mean_us(&self) -> Option<(f64, u64)> {
        let (sum, n) = self.ui_cpu_sum;
        (n > 0).then(|| (sum / n as f64, n))
    }

    /// Frames that began within the last second.
    pub fn fps(&self, now: Instant) -> f64 {
        let recent: Vec<_> = self
            .frames
            .iter()
            .filter(|(t, _)| now.duration_since(*t) <= WINDOW)
            .collect();
        match recent.len() {
            // Slower than one a second (a CPU driver): from the last frame's time.
            0 => self
                .frames
                .back()
                .map_or(0.0, |(_, f)| 1000.0 / f.frame_ms.max(1e-3)),
            1 => 1000.0 / recent[0].1.frame_ms.max(1e-3),
            n => {
                let span = now.duration_since(recent[0].0).as_secs_f64().max(1e-6);
                (n as f64 / span).min(n as f64 * 1000.0 / recent[0].1.frame_ms.max(1e-3))
            }
        }
    }

    /// The frames the graph shows, oldest first.
    pub fn frames(&self) -> impl Iterator<Item = &FrameTime> {
        self.frames.iter().map(|(_, f)| f)
    }

    /// Each technique's passes with their median GPU time over the last second (a pass last
    /// timed longer ago keeps its last second of samples), techniques most expensive first.
    pub fn table(&mut self, now: Instant) -> Vec<Group> {
        let mut groups: BTreeMap<String, Group> = BTreeMap::new();
        for (name, samples) in &mut self.passes {
            // Keep at least the latest sample: the timed frames are few on a slow GPU.
            let newest = samples.back().map(|(t, _)| *t).unwrap_or(now);
            trim(samples, newest, WINDOW);
            let Some(ms) = median(&mut samples.iter().map(|(_, v)| *v).collect::<Vec<_>>()) else {
                continue;
            };
            let technique = name.split('.').next().unwrap_or(name).to_string();
            let g = groups.entry(technique.clone()).or_insert_with(|| Group {
                technique,
                total_ms: 0.0,
                passes: Vec::new(),
            });
            g.total_ms += ms;
            g.passes.push((name.clone(), ms));
        }
        let mut out: Vec<Group> = groups.into_values().collect();
        for g in &mut out {
            g.passes.sort_by(|a, b| b.1.total_cmp(&a.1));
        }
        out.sort_by(|a, b| b.total_ms.total_cmp(&a.total_ms));
        out
    }

    /// Forgets the per-pass times (passes of a technique switched off stop being timed).
    pub fn clear_passes(&mut self) {
        self.passes.clear();
    }
}

/// This thread's CPU time, µs: what the viewer's own work costs, without the time it spends
/// blocked (a driver's queue, the window system). Wall time where the platform has no thread
/// clock.
pub fn thread_cpu_us() -> f64 {
    #[cfg(unix)]
    {
        let mut t = libc::timespec {
            tv_sec: 0,
            tv_nsec: 0,
        };
        // SAFETY: `t` is a valid timespec for the call to fill.
        if unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut t) } == 0 {
            return t.tv_sec as f64 * 1e6 + t.tv_nsec as f64 / 1e3;
        }
    }
    use std::sync::OnceLock;
    static START: OnceLock<Instant> = OnceLock::new();
    START.get_or_init(Instant::now).elapsed().as_secs_f64() * 1e6
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn medians() {
        assert_eq!(median(&mut []), None);
        assert_eq!(median(&mut [3.0, 1.0, 2.0]), Some(2.0));
        assert_eq!(median(&mut [4.0, 1.0, 3.0, 2.0]), Some(2.5));
    }

    #[test]
    fn the_table_is_grouped_by_technique_sorted_by_cost_over_the_last_second() {
        let mut s = Stats::default();
        let t0 = Instant::now();
        s.add_passes(t0, [("taa.resolve", 100.0), ("sky.lut", 9.0)]);
        let t1 = t0 + Duration::from_millis(1500);
        for (i, ms) in [1.0, 5.0, 3.0].into_iter().enumerate() {
            let t = t1 + Duration::from_millis(100 * i as u64);
            s.add_passes(
                t,
                [
                    ("taa.resolve", ms),
                    ("sky.lut", 0.5),
                    ("sky.draw", 2.0),
                    ("gbuffer", 4.0),
                ],
            );
        }
        let table = s.table(t1 + Duration::from_millis(300));
        let names: Vec<&str> = table.iter().map(|g| g.technique.as_str()).collect();
        assert_eq!(names, ["gbuffer", "taa", "sky"]);
        // The 100 ms sample is older than a second: the median is of 1, 5, 3.
        assert_eq!(table[1].passes, vec![("taa.resolve".to_string(), 3.0)]);
        assert_eq!(table[2].passes[0].0, "sky.draw");
        assert!((table[2].total_ms - 2.5).abs() < 1e-9);
    }

    #[test]
    fn frames_per_second_and_the_graphs_length() {
        let mut s = Stats::default();
        let t0 = Instant::now();
        for i in 0..300u64 {
            s.add_frame(
                t0 + Duration::from_millis(20 * i),
                FrameTime {
                    frame_ms: 20.0,
                    cpu_ms: 1.0,
                    gpu_ms: None,
                },
            );
        }
        assert_eq!(s.frames().count(), GRAPH_FRAMES);
        let fps = s.fps(t0 + Duration::from_millis(20 * 299));
        assert!((fps - 50.0).abs() < 2.0, "{fps}");
        assert_eq!(Stats::default().fps(t0), 0.0);
        let mut slow = Stats::default();
        let frame = FrameTime {
            frame_ms: 2500.0,
            cpu_ms: 1.0,
            gpu_ms: None,
        };
        slow.add_frame(t0, frame);
        assert!((slow.fps(t0 + Duration::from_secs(2)) - 0.4).abs() < 1e-9);
    }
}
