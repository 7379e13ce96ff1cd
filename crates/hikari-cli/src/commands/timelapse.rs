//! `hikari timelapse`: one view from `--from` to `--to`, the clock moving every rendered frame
//! on one renderer, so that TAA, the GI's accumulation, the shadow denoiser and the exposure
//! follow the light as they would on screen; `--count` frames written, evenly spaced.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::Context;
use clap::Args;

use hikari_math::astro::DateTime;

use crate::args::FrameArgs;
use crate::progress::{self, Counter, ProgressArgs};
use crate::scene_source;
use crate::still;

/// `--time` is `--from` and `--to` here: hidden from the help (and refused if given).
#[derive(Args, Debug)]
#[command(mut_arg("time", |a| a.hide(true)))]
pub struct TimelapseArgs {
    #[command(flatten)]
    pub frame: FrameArgs,
    /// Local time of the first frame written, HH:MM or HH:MM:SS, on `--date`.
    #[arg(long, value_name = "HH:MM[:SS]")]
    pub from: String,
    /// Local time of the last frame written; one not later than `--from` is on the next day
    /// (the time-lapse runs through midnight).
    #[arg(long, value_name = "HH:MM[:SS]")]
    pub to: String,
    /// Frames written, evenly spaced from `--from` to `--to`, both included.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(2..=100_000))]
    pub count: u32,
    /// Frames rendered at `--from` before the first is written (that one included), for the
    /// temporal passes to converge [default: `hikari render`'s default frame count].
    #[arg(long, value_name = "K", value_parser = clap::value_parser!(u32).range(1..=10_000))]
    pub settle: Option<u32>,
    /// Frames rendered between two written frames, at times in between: the temporal passes
    /// see the light move in smaller steps. 0: from one written frame's time to the next's.
    #[arg(long, value_name = "M", default_value_t = 1, value_parser = clap::value_parser!(u32).range(0..=10_000))]
    pub steps_between: u32,
    /// Folder for the frames, `frame_0000.png` (and `.exr`) on; created if missing.
    #[arg(short, long, default_value = "timelapse")]
    pub output: PathBuf,
    /// Do not write the EXRs.
    #[arg(long)]
    pub no_exr: bool,
    /// Irradiance-probe bake file [default: the cache, baked on a miss].
    #[arg(long)]
    pub bake: Option<PathBuf>,
    #[command(flatten)]
    pub progress: ProgressArgs,
}

/// The clock of a time-lapse: the first written frame's date and time and the seconds to the
/// last.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Span {
    pub start: DateTime,
    pub seconds: i64,
}

impl Span {
    /// From `from` on `date` to the next `to`: later the same day, else (not later) the next.
    /// Errors name the flag.
    pub fn new(date: &str, from: &str, to: &str, utc_offset_h: f64) -> anyhow::Result<Self> {
        let start = DateTime::parse(date, from, utc_offset_h)
            .map_err(|e| anyhow::anyhow!("--from {from}: {e}"))?;
        let end = DateTime::parse(date, to, utc_offset_h)
            .map_err(|e| anyhow::anyhow!("--to {to}: {e}"))?;
        let (a, b) = (start.seconds_of_day(), end.seconds_of_day());
        let seconds = if b > a {
            i64::from(b - a)
        } else {
            i64::from(b) + 86_400 - i64::from(a)
        };
        // The last frame must have a date the sky knows.
        start
            .plus_seconds(seconds)
            .map_err(|e| anyhow::anyhow!("--to {to} (the day after --date {date}): {e}"))?;
        Ok(Self { start, seconds })
    }

    /// The instant `fraction` (0 to 1) of the way, to the nearest second.
    pub fn at(&self, fraction: f64) -> anyhow::Result<DateTime> {
        let dt = (self.seconds as f64 * fraction).round() as i64;
        Ok(self.start.plus_seconds(dt)?)
    }
}

pub fn run(args: TimelapseArgs) -> anyhow::Result<()> {
    progress::set_quiet(args.progress.quiet);
    if let Some(t) = &args.frame.sky.time {
        anyhow::bail!("--time {t}: a time-lapse runs from --from to --to; give those instead");
    }
    // The times first, on any date, so that their errors name --from and --to.
    Span::new("2000-01-01", &args.from, &args.to, 0.0)?;
    let mut frame_args = args.frame.clone();
    frame_args.sky.time = Some(args.from.clone());
    // The date, offset and place as the flags and the settings file give them.
    let resolved = scene_source::resolve(&frame_args)?;
    let sky = &resolved.settings.settings.sky;
    let span = Span::new(&sky.date, &args.from, &args.to, sky.utc_offset_h)?;
    still::output_folder("-o", &args.output)?;
    log::info!("{}", resolved.description.line());

    let mut settings = resolved.settings.clone();
    let settle = args
        .settle
        .unwrap_or_else(|| still::default_frames(&settings.settings));
    let steps = args.steps_between + 1;
    let intervals = args.count - 1;
    // Every rendered frame: (fraction of the span, index of the written frame it is).
    let mut plan: Vec<(f64, Option<u32>)> = (1..settle).map(|_| (0.0, None)).collect();
    plan.push((0.0, Some(0)));
    for i in 0..intervals {
        for j in 1..=steps {
            let f = (f64::from(i) + f64::from(j) / f64::from(steps)) / f64::from(intervals);
            plan.push((f, (j == steps).then_some(i + 1)));
        }
    }
    let digits = (args.count - 1).to_string().len().max(4);
    let started = Instant::now();
    let mut renderer = still::renderer(&resolved, args.bake.as_deref())?;
    renderer.set_frame(settings.clone())?;
    let mut last_time = String::new();
    let bar = Counter::start("rendering the time-lapse", plan.len() as u64, "frames");
    for &(fraction, written) in &plan {
        let when = span.at(fraction)?;
        let sky = &mut settings.settings.sky;
        sky.date = when.date_string();
        sky.time = when.time_string();
        let now = format!("{} {}", sky.date, sky.time);
        renderer
            .set_clock(&sky.date, &sky.time)
            .with_context(|| format!("the clock at {now}"))?;
        let frame = renderer.frame(written.is_some())?;
        if let Some(k) = written {
            let png = args.output.join(format!("frame_{k:0digits$}.png"));
            let exr = png.with_extension("exr");
            still::write_images(&png, (!args.no_exr).then_some(exr.as_path()), &frame)?;
            log::info!("wrote {} ({now})", png.display());
        }
        bar.inc();
        if let Some(k) = written {
            bar.set_message(format!(
                "rendering the time-lapse, {} of {} written, at {now}",
                k + 1,
                args.count
            ));
        }
        last_time = now;
    }
    bar.done("rendered the time-lapse");
    let first = span.start;
    println!(
        "wrote {} frames{} to {}, {} {} to {last_time}, {} frames rendered in {:.1} s",
        args.count,
        if args.no_exr {
            " (PNG)"
        } else {
            " (PNG + EXR)"
        },
        args.output.display(),
        first.date_string(),
        first.time_string(),
        plan.len(),
        started.elapsed().as_secs_f64()
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_to_not_later_than_from_crosses_midnight() {
        let s = Span::new("2023-12-31", "22:00", "02:30", 9.0).unwrap();
        assert_eq!(s.seconds, 4 * 3600 + 1800);
        let end = s.at(1.0).unwrap();
        assert_eq!(
            (end.date_string(), end.time_string()),
            ("2024-01-01".into(), "02:30:00".into())
        );
        let mid = s.at(0.5).unwrap();
        assert_eq!(mid.time_string(), "00:15:00");
        // Equal times: a whole day.
        assert_eq!(
            Span::new("2024-02-28", "12:00", "12:00", 9.0)
                .unwrap()
                .seconds,
            86_400
        );
        let same_day = Span::new("2024-02-28", "06:00", "18:00:30", 9.0).unwrap();
        assert_eq!(same_day.seconds, 12 * 3600 + 30);
    }

    #[test]
    fn bad_times_name_their_flag() {
        let e = Span::new("2024-07-21", "25:00", "12:00", 9.0)
            .unwrap_err()
            .to_string();
        assert!(e.contains("--from 25:00"), "{e}");
        let e = Span::new("2024-07-21", "06:00", "6pm", 9.0)
            .unwrap_err()
            .to_string();
        assert!(e.contains("--to 6pm"), "{e}");
        let e = Span::new("2100-12-31", "23:00", "01:00", 9.0)
            .unwrap_err()
            .to_string();
        assert!(e.contains("--to 01:00"), "{e}");
    }
}
