//! What a long command is doing, on stderr, for a person at a terminal: `render`, `compare`
//! and `timelapse` show their steps (start-up, the probe bake, frames rendered of N, writing)
//! as indicatif spinners and bars, each step left as one line with its time when done. In
//! scripts they stay quiet: nothing is drawn when stderr is not a terminal, or with
//! `--quiet`. `HIKARI_PROGRESS=always` draws even to a pipe (a log file, a test),
//! `HIKARI_PROGRESS=never` never draws.
//!
//! Every bar lives in one [`MultiProgress`] for the process; log lines (warnings) are written
//! through it ([`LogWriter`]) so that they do not tear a bar in half.

use std::io::{IsTerminal, Write};
use std::sync::OnceLock;
use std::time::{Duration, Instant};

use clap::Args;
use indicatif::{MultiProgress, ProgressBar, ProgressDrawTarget, ProgressStyle, TermLike};

/// `--quiet`.
#[derive(Args, Debug, Clone, Default)]
pub struct ProgressArgs {
    /// No progress on stderr (there is none either when stderr is not a terminal): for
    /// scripts. Errors and warnings are still printed.
    #[arg(short, long)]
    pub quiet: bool,
}

/// When progress is drawn: `HIKARI_PROGRESS` (auto, always or never; default auto).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Mode {
    /// On a terminal only.
    Auto,
    Always,
    Never,
}

fn mode() -> Mode {
    match std::env::var("HIKARI_PROGRESS").as_deref() {
        Ok("always") => Mode::Always,
        Ok("never") => Mode::Never,
        Ok(other) if !other.is_empty() && other != "auto" => {
            log::warn!("HIKARI_PROGRESS={other}: expected auto, always or never; using auto");
            Mode::Auto
        }
        _ => Mode::Auto,
    }
}

/// stderr as indicatif's terminal, whatever it is connected to (`HIKARI_PROGRESS=always`).
#[derive(Debug)]
struct Stderr;

impl TermLike for Stderr {
    fn width(&self) -> u16 {
        100
    }
    fn move_cursor_up(&self, n: usize) -> std::io::Result<()> {
        self.write_str(&format!("\x1b[{n}A"))
    }
    fn move_cursor_down(&self, n: usize) -> std::io::Result<()> {
        self.write_str(&format!("\x1b[{n}B"))
    }
    fn move_cursor_right(&self, n: usize) -> std::io::Result<()> {
        self.write_str(&format!("\x1b[{n}C"))
    }
    fn move_cursor_left(&self, n: usize) -> std::io::Result<()> {
        self.write_str(&format!("\x1b[{n}D"))
    }
    fn write_line(&self, s: &str) -> std::io::Result<()> {
        self.write_str(&format!("{s}\n"))
    }
    fn write_str(&self, s: &str) -> std::io::Result<()> {
        std::io::stderr().write_all(s.as_bytes())
    }
    fn clear_line(&self) -> std::io::Result<()> {
        self.write_str("\r\x1b[2K")
    }
    fn flush(&self) -> std::io::Result<()> {
        std::io::stderr().flush()
    }
}

fn target(quiet: bool) -> ProgressDrawTarget {
    match (quiet, mode()) {
        (true, _) | (_, Mode::Never) => ProgressDrawTarget::hidden(),
        (false, Mode::Always) => ProgressDrawTarget::term_like(Box::new(Stderr)),
        (false, Mode::Auto) if std::io::stderr().is_terminal() => ProgressDrawTarget::stderr(),
        (false, Mode::Auto) => ProgressDrawTarget::hidden(),
    }
}

static MULTI: OnceLock<MultiProgress> = OnceLock::new();

/// The process's bars: drawn per `HIKARI_PROGRESS` and the terminal until [`set_quiet`].
fn multi() -> &'static MultiProgress {
    MULTI.get_or_init(|| MultiProgress::with_draw_target(target(false)))
}

/// `--quiet`: nothing is drawn from now on.
pub fn set_quiet(quiet: bool) {
    if quiet {
        multi().set_draw_target(target(true));
    }
}

/// A choice the command made for the user that changes what it draws (the CPU adapter's
/// preset): printed on stderr above the bars, even with `--quiet` or without a terminal.
pub fn note(message: &str) {
    let line = format!("note: {message}\n");
    let _ = multi().suspend(|| std::io::stderr().write_all(line.as_bytes()));
}

/// What `env_logger` writes through: each record printed above the bars.
pub struct LogWriter;

impl Write for LogWriter {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        match MULTI.get() {
            Some(m) => m.suspend(|| std::io::stderr().write_all(buf))?,
            None => std::io::stderr().write_all(buf)?,
        }
        Ok(buf.len())
    }
    fn flush(&mut self) -> std::io::Result<()> {
        std::io::stderr().flush()
    }
}

fn seconds(d: Duration) -> String {
    let s = d.as_secs_f64();
    if s < 60.0 {
        format!("{s:.1} s")
    } else {
        format!("{}:{:02} min", (s / 60.0) as u64, s as u64 % 60)
    }
}

/// One step of a command, a spinner while it runs: "starting the GPU". [`Step::done`] leaves
/// "✓ GPU llvmpipe (0.2 s)"; dropped without it (an error), the line is cleared.
pub struct Step {
    bar: ProgressBar,
    start: Instant,
}

impl Step {
    pub fn start(message: impl Into<String>) -> Self {
        let bar = multi().add(ProgressBar::new_spinner());
        bar.set_style(
            ProgressStyle::with_template("{spinner:.cyan} {msg} {elapsed:.dim}")
                .expect("a valid template")
                .tick_chars("⠋⠙⠹⠸⠼⠴⠦⠧⠇⠏✓"),
        );
        bar.set_message(message.into());
        bar.enable_steady_tick(Duration::from_millis(100));
        Self {
            bar,
            start: Instant::now(),
        }
    }

    /// Ends the step with `message` and the time it took.
    pub fn done(self, message: impl std::fmt::Display) {
        self.finish(format!("{message} ({})", seconds(self.start.elapsed())));
    }

    /// Ends the step leaving no line (what follows says it).
    pub fn clear(self) {
        self.bar.finish_and_clear();
    }

    fn finish(&self, line: String) {
        self.bar.set_style(
            ProgressStyle::with_template("{prefix:.green} {msg}").expect("a valid template"),
        );
        self.bar.set_prefix("✓");
        self.bar.finish_with_message(line);
    }
}

impl Drop for Step {
    fn drop(&mut self) {
        if !self.bar.is_finished() {
            self.bar.finish_and_clear();
        }
    }
}

/// A count of `total` things (frames), a bar with the time left: "rendering [####....] 5/16
/// frames". Dropped unfinished, the line is cleared.
pub struct Counter {
    bar: ProgressBar,
    start: Instant,
    unit: &'static str,
}

impl Counter {
    pub fn start(message: impl Into<String>, total: u64, unit: &'static str) -> Self {
        Self::with_template(message, total, unit, "{elapsed} ({eta} left)")
    }

    /// A count whose message says the time left itself (the bake's, from its own estimate).
    pub fn without_eta(message: impl Into<String>, total: u64, unit: &'static str) -> Self {
        Self::with_template(message, total, unit, "{elapsed}")
    }

    fn with_template(
        message: impl Into<String>,
        total: u64,
        unit: &'static str,
        time: &str,
    ) -> Self {
        let bar = multi().add(ProgressBar::new(total));
        bar.set_style(
            ProgressStyle::with_template(&format!(
                "{{spinner:.cyan}} {{msg}} [{{bar:30.cyan/blue}}] {{pos}}/{{len}} {unit}, {time}"
            ))
            .expect("a valid template")
            .progress_chars("#>."),
        );
        bar.set_message(message.into());
        bar.enable_steady_tick(Duration::from_millis(100));
        Self {
            bar,
            start: Instant::now(),
            unit,
        }
    }

    pub fn set_message(&self, message: impl Into<String>) {
        self.bar.set_message(message.into());
    }

    pub fn inc(&self) {
        self.bar.inc(1);
    }

    /// Forgets the rate so far, for the time left: after a first item that was slower than
    /// the rest (the first frame compiles the shaders).
    pub fn reset_eta(&self) {
        self.bar.reset_eta();
    }

    pub fn set_position(&self, done: u64) {
        self.bar.set_position(done);
    }

    pub fn set_total(&self, total: u64) {
        self.bar.set_length(total);
    }

    /// Ends the count with `message`, the count and the time it took.
    pub fn done(self, message: impl std::fmt::Display) {
        let n = self.bar.position();
        self.bar.set_style(
            ProgressStyle::with_template("{prefix:.green} {msg}").expect("a valid template"),
        );
        self.bar.set_prefix("✓");
        self.bar.finish_with_message(format!(
            "{message}: {n} {} ({})",
            self.unit,
            seconds(self.start.elapsed())
        ));
    }
}

impl Drop for Counter {
    fn drop(&mut self) {
        if !self.bar.is_finished() {
            self.bar.finish_and_clear();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn times_read_as_seconds_then_minutes() {
        assert_eq!(seconds(Duration::from_millis(1234)), "1.2 s");
        assert_eq!(seconds(Duration::from_secs(125)), "2:05 min");
    }
}
