//! The grading workflow as a user runs it (`render --lut-screenshot`, `lut extract`,
//! `lut apply`), and the final image's flags refusing bad input before anything is written.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn hikari(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_hikari"))
        .args(args)
        .output()
        .expect("run hikari")
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("hikari-tonemap-cli-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn text(o: &Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// A grade no one would confuse with the identity, on display values in [0, 1].
fn grade(c: [f32; 3]) -> [f32; 3] {
    [
        (0.9 * c[0] + 0.1 * c[2]).powf(0.8),
        c[1] * c[1],
        0.1 + 0.8 * c[2],
    ]
}

fn grade_png(src: &Path, dst: &Path) {
    let mut img = image::open(src).unwrap().to_rgba8();
    for p in img.pixels_mut() {
        let c = grade([p[0], p[1], p[2]].map(|v| v as f32 / 255.0));
        for (channel, v) in p.0.iter_mut().zip(c) {
            *channel = (v * 255.0).round() as u8;
        }
    }
    img.save(dst).unwrap();
}

/// Entry `(r, g, b)` of a `.cube` file's table (red fastest), parsed here on its own.
fn cube_entries(path: &Path) -> (usize, Vec<[f32; 3]>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut size = 0;
    let mut rows = Vec::new();
    for line in text.lines() {
        if let Some(n) = line.strip_prefix("LUT_3D_SIZE ") {
            size = n.trim().parse().unwrap();
        } else if line.starts_with(|c: char| c.is_ascii_digit()) {
            let v: Vec<f32> = line
                .split_whitespace()
                .map(|x| x.parse().unwrap())
                .collect();
            rows.push([v[0], v[1], v[2]]);
        }
    }
    (size, rows)
}

#[test]
fn a_graded_screenshot_gives_back_its_grade_and_lut_apply_grades_like_the_editor() {
    let dir = tmp("workflow");
    let shot = dir.join("shot.png");
    let o = hikari(&[
        "render",
        "--scene",
        "boxes",
        "--width",
        "64",
        "--height",
        "40",
        "--no-exr",
        "-o",
        s(&shot),
        "--lut-screenshot",
    ]);
    assert!(o.status.success(), "{}", text(&o));
    let img = image::open(&shot).unwrap();
    // 64 px wide: two 32x32 tiles of the strip a row, 64 tiles in 32 rows below the image.
    assert_eq!((img.width(), img.height()), (64, 40 + 32 * 32));

    let graded = dir.join("graded.png");
    grade_png(&shot, &graded);
    let cube = dir.join("grade.cube");
    let o = hikari(&["lut", "extract", s(&graded), "-o", s(&cube)]);
    assert!(o.status.success(), "{}", text(&o));
    let (size, rows) = cube_entries(&cube);
    assert_eq!((size, rows.len()), (32, 32 * 32 * 32));
    let mut worst = 0f32;
    for (i, got) in rows.iter().enumerate() {
        let lattice = [i % 32, (i / 32) % 32, i / 1024].map(|v| v as f32 / 31.0);
        let want = grade(lattice);
        for k in 0..3 {
            worst = worst.max((got[k] - want[k]).abs());
        }
    }
    // The identity strip's 8-bit inputs are within half a step of the lattice, the grade's
    // slope is at most 2, and its 8-bit output adds half a step.
    assert!(worst <= 1.5 / 255.0 + 1e-5, "{} steps", worst * 255.0);

    // The LUT applied to the ungraded screenshot gives the editor's result: trilinear
    // interpolation of a smooth grade between lattice points 1/31 apart.
    let applied = dir.join("applied.png");
    let o = hikari(&["lut", "apply", s(&cube), s(&shot), "-o", s(&applied)]);
    assert!(o.status.success(), "{}", text(&o));
    let a = image::open(&applied).unwrap().to_rgba8();
    let b = image::open(&graded).unwrap().to_rgba8();
    let worst = a
        .pixels()
        .zip(b.pixels())
        .flat_map(|(p, q)| (0..3).map(move |k| (p[k] as i32 - q[k] as i32).abs()))
        .max()
        .unwrap();
    assert!(
        worst <= 3,
        "lut apply differs from the grade by {worst} steps"
    );

    // And the LUT renders: a frame graded by it.
    let o = hikari(&[
        "render",
        "--scene",
        "boxes",
        "--width",
        "64",
        "--height",
        "40",
        "--no-exr",
        "-o",
        s(&dir.join("graded_render.png")),
        "--lut",
        s(&cube),
        "--white",
        "1,0.9,0.8",
    ]);
    assert!(o.status.success(), "{}", text(&o));
}

#[test]
fn bad_white_lut_or_strip_is_an_error_naming_it_and_nothing_is_written() {
    let dir = tmp("bad");
    let png = dir.join("out.png");
    for white in ["0,1,1", "-1,1,1", "nan,1,1", "1,1", "a,b,c"] {
        let o = hikari(&[
            "render",
            "--width",
            "64",
            "--height",
            "40",
            "-o",
            s(&png),
            "--white",
            white,
        ]);
        assert!(!o.status.success());
        assert!(text(&o).contains("--white"), "{white}: {}", text(&o));
    }
    let bad = dir.join("bad.cube");
    std::fs::write(&bad, "LUT_3D_SIZE 2\n0 0 0\n1 0 0\n").unwrap();
    let o = hikari(&[
        "render",
        "--width",
        "64",
        "--height",
        "40",
        "-o",
        s(&png),
        "--lut",
        s(&bad),
    ]);
    assert!(!o.status.success());
    let t = text(&o);
    assert!(
        t.contains("--lut") && t.contains("bad.cube:3") && t.contains("truncated"),
        "{t}"
    );
    let o = hikari(&[
        "render",
        "--width",
        "64",
        "--height",
        "40",
        "-o",
        s(&png),
        "--set",
        &format!("tonemap.lut=\"{}\"", s(&bad)),
    ]);
    assert!(!o.status.success());
    assert!(text(&o).contains("tonemap.lut"), "{}", text(&o));
    let o = hikari(&[
        "render",
        "--width",
        "16",
        "--height",
        "40",
        "-o",
        s(&png),
        "--lut-screenshot",
    ]);
    assert!(!o.status.success());
    assert!(text(&o).contains("--lut-screenshot"), "{}", text(&o));
    assert!(!png.exists(), "nothing is written on bad input");

    // A PNG without a strip, and a missing file.
    let plain = dir.join("plain.png");
    image::RgbaImage::from_fn(200, 900, |x, y| {
        image::Rgba([(x % 256) as u8, (y % 256) as u8, 7, 255])
    })
    .save(&plain)
    .unwrap();
    let cube = dir.join("out.cube");
    let o = hikari(&["lut", "extract", s(&plain), "-o", s(&cube)]);
    assert!(!o.status.success());
    assert!(
        text(&o).contains("plain.png") && text(&o).contains("no LUT strip"),
        "{}",
        text(&o)
    );
    let o = hikari(&["lut", "extract", s(&dir.join("none.png")), "-o", s(&cube)]);
    assert!(!o.status.success());
    assert!(text(&o).contains("none.png"), "{}", text(&o));
    let o = hikari(&[
        "lut",
        "apply",
        s(&bad),
        s(&plain),
        "-o",
        s(&dir.join("x.png")),
    ]);
    assert!(!o.status.success());
    assert!(text(&o).contains("bad.cube:3"), "{}", text(&o));
    assert!(!cube.exists() && !dir.join("x.png").exists());
}
