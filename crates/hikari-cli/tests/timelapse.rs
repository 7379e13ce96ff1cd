//! `hikari timelapse`: numbered PNG + EXR frames from `--from` to `--to`, the sun moving
//! between them, through midnight into the next date; bad arguments name their flag.

mod common;

use std::path::Path;
use std::process::{Command, Output};

use common::{hikari, text, tmp};

/// `hikari timelapse` of the boxes (which get the sky's sun once a time is given) at 64x36,
/// with the bake cache in `dir`, its progress drawn on stderr as on a terminal.
fn timelapse(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_hikari"))
        .env("XDG_CACHE_HOME", dir.join("cache"))
        .env("HIKARI_PROGRESS", "always")
        .args([
            "timelapse",
            "--scene",
            "boxes",
            "--width",
            "64",
            "--height",
            "36",
        ])
        .args(args)
        .output()
        .expect("run hikari")
}

/// Median Rec.709 luminance (nits) of an EXR, and its size.
fn exr_median_luminance(path: &Path) -> (f64, (usize, usize)) {
    let img = exr::prelude::read_first_rgba_layer_from_file(
        path,
        |res, _| (res.width(), vec![[0f32; 3]; res.width() * res.height()]),
        |(w, v), pos, (r, g, b, _a): (f32, f32, f32, f32)| v[pos.y() * *w + pos.x()] = [r, g, b],
    )
    .unwrap();
    let size = img.layer_data.size;
    let px = &img.layer_data.channel_data.pixels.1;
    assert!(px.iter().flatten().all(|c| c.is_finite() && *c >= 0.0));
    let mut lum: Vec<f64> = px
        .iter()
        .map(|p| 0.2126 * p[0] as f64 + 0.7152 * p[1] as f64 + 0.0722 * p[2] as f64)
        .collect();
    lum.sort_by(f64::total_cmp);
    (lum[lum.len() / 2], (size.width(), size.height()))
}

#[test]
fn frames_are_written_numbered_and_the_sun_moves_between_them() {
    let dir = tmp("timelapse");
    let out = dir.join("frames/nested");
    let o = timelapse(
        &dir,
        &[
            "--from",
            "05:00",
            "--to",
            "12:00",
            "--count",
            "3",
            "--settle",
            "2",
            "-o",
            out.to_str().unwrap(),
        ],
    );
    let said = text(&o);
    assert!(o.status.success(), "{said}");
    assert!(
        said.contains("wrote 3 frames")
            && said.contains("2024-07-21 05:00:00 to 2024-07-21 12:00:00")
            && said.contains("6 frames rendered"),
        "{said}"
    );
    assert!(
        said.contains("rendered the time-lapse: 6 frames") && said.contains("3 of 3 written"),
        "progress: {said}"
    );
    let mut lum = Vec::new();
    for k in 0..3 {
        let png = out.join(format!("frame_{k:04}.png"));
        let img = image::open(&png).unwrap().to_rgba8();
        assert_eq!(img.dimensions(), (64, 36), "{}", png.display());
        let (l, size) = exr_median_luminance(&png.with_extension("exr"));
        assert_eq!(size, (64, 36));
        lum.push(l);
    }
    // 05:00 is before sunrise in Tsushima's July (about 05:20), 08:30 morning, 12:00 midday.
    // Most of the view is the ground (albedo 0.3): in the noon sun, about 100 klux, it is
    // near 0.3 x 100000 / pi = 9500 nits; lit by the sky alone (a sun that did not move
    // from dawn) a few hundred.
    assert!(
        lum[0] < 100.0 && lum[1] > 10.0 * lum[0] && lum[2] > lum[1] && lum[2] > 4000.0,
        "median luminance (nits) at dawn, morning, noon: {lum:?}"
    );
    let names: Vec<String> = std::fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(
        names.len(),
        6,
        "only the frames, no temporary files: {names:?}"
    );
}

#[test]
fn a_to_before_from_runs_through_midnight_into_the_next_date() {
    let dir = tmp("timelapse-midnight");
    let out = dir.join("night");
    let o = timelapse(
        &dir,
        &[
            "--date",
            "2023-12-31",
            "--from",
            "23:30",
            "--to",
            "00:30",
            "--count",
            "2",
            "--settle",
            "1",
            "--steps-between",
            "0",
            "--no-exr",
            "--set",
            "irradiance_probes.enabled=false",
            "-o",
            out.to_str().unwrap(),
        ],
    );
    let said = text(&o);
    assert!(o.status.success(), "{said}");
    assert!(
        said.contains("2023-12-31 23:30:00 to 2024-01-01 00:30:00") && said.contains("(PNG)"),
        "{said}"
    );
    assert!(out.join("frame_0001.png").exists());
    assert!(
        !out.join("frame_0000.exr").exists(),
        "--no-exr wrote an EXR"
    );
}

fn assert_clean_failure(args: &[&str], needle: &str) {
    let mut all = vec!["timelapse", "--scene", "boxes"];
    all.extend_from_slice(args);
    let o = hikari(&all);
    let t = text(&o);
    assert!(!o.status.success(), "{args:?} should fail: {t}");
    assert!(!t.contains("panicked"), "{args:?} panicked: {t}");
    assert!(t.contains(needle), "{args:?}: expected `{needle}` in: {t}");
}

#[test]
fn bad_arguments_name_their_flag_and_render_nothing() {
    let dir = tmp("timelapse-bad");
    let file = dir.join("taken.png");
    std::fs::write(&file, "not a folder").unwrap();
    let times = ["--from", "06:00", "--to", "18:00"];
    let with = |extra: &[&'static str]| -> Vec<&'static str> {
        let mut v = times.to_vec();
        v.extend_from_slice(extra);
        v
    };
    assert_clean_failure(&with(&["--count", "1"]), "--count");
    assert_clean_failure(&with(&[]), "--count");
    assert_clean_failure(
        &["--from", "25:00", "--to", "18:00", "--count", "3"],
        "--from 25:00",
    );
    assert_clean_failure(
        &["--from", "06:00", "--to", "6pm", "--count", "3"],
        "--to 6pm",
    );
    assert_clean_failure(&with(&["--count", "3", "--time", "07:00"]), "--time 07:00");
    assert_clean_failure(&with(&["--count", "3", "--settle", "0"]), "--settle");
    assert_clean_failure(
        &with(&[
            "--count",
            "3",
            "--date",
            "2100-12-31",
            "--from",
            "23:00",
            "--to",
            "01:00",
        ])[4..],
        "--to 01:00",
    );
    let taken = file.to_str().unwrap();
    let o = hikari(&[
        "timelapse",
        "--scene",
        "boxes",
        "--from",
        "06:00",
        "--to",
        "18:00",
        "--count",
        "3",
        "-o",
        taken,
    ]);
    let t = text(&o);
    assert!(
        !o.status.success() && t.contains("-o") && t.contains("not a folder"),
        "{t}"
    );
    assert_eq!(std::fs::read_to_string(&file).unwrap(), "not a folder");
}
