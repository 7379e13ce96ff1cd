//! The grading workflow as a user runs it (`render --lut-screenshot`, `lut extract`,
//! `lut apply`), and the final image's flags refusing bad input before anything is written.

use std::path::Path;
use std::process::Output;

mod common;

use common::{hikari, text, tmp};

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

/// A `--dump`ed EXR as (width, rgba texels).
fn read_exr(path: &Path) -> (usize, Vec<[f32; 4]>) {
    let img = exr::prelude::read_first_rgba_layer_from_file(
        path,
        |res, _| (res.width(), vec![[0f32; 4]; res.width() * res.height()]),
        |(w, v), pos, (r, g, b, a): (f32, f32, f32, f32)| v[pos.y() * *w + pos.x()] = [r, g, b, a],
    )
    .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    img.layer_data.channel_data.pixels
}

/// A `--dump`ed buffer as little-endian words.
fn read_words(path: &Path) -> Vec<[u8; 4]> {
    let bytes = std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    assert_eq!(bytes.len() % 4, 0, "{}", path.display());
    bytes.chunks(4).map(|c| c.try_into().unwrap()).collect()
}

fn ev100(dir: &Path) -> f32 {
    f32::from_le_bytes(read_words(&dir.join("exposure.value.bin"))[1])
}

fn mean_png(path: &Path) -> f64 {
    let img = image::open(path).unwrap().to_rgb8();
    img.pixels()
        .flat_map(|p| p.0)
        .map(|v| v as f64)
        .sum::<f64>()
        / (3 * img.width() * img.height()) as f64
}

/// One frame of the boxes at 64x40 into `dir`, dumping the exposure's value.
fn render_into(dir: &Path, extra: &[&str]) -> Output {
    std::fs::create_dir_all(dir).unwrap();
    let png = dir.join("out.png");
    // The `high` preset, as on a GPU: the CPU driver's default (`low`) renders at half the
    // size, and these tests count the output's pixels.
    let mut args = vec![
        "render",
        "--preset",
        "high",
        "--width",
        "64",
        "--height",
        "40",
        "--frames",
        "1",
        "-o",
        s(&png),
        "--dump",
        "exposure.value",
    ];
    args.extend_from_slice(extra);
    hikari(&args)
}

/// The exposure's and the local tonemap's flags end to end, through `hikari render`:
/// `--exposure-compensation EV` lowers the metered EV100 by exactly EV (its definition: +1 is
/// twice as bright), brightens the PNG and leaves the EXR (linear radiance) alone; `--ev100`
/// wins over it; `--no-tonemap-local` gives the image of `--set local_tonemap.enabled=false`
/// and not the default one; out-of-range or non-finite values are refused naming the flag or
/// field, with nothing written.
#[test]
fn exposure_compensation_and_no_tonemap_local_act_end_to_end() {
    let dir = tmp("flags");
    let base = dir.join("base");
    let o = render_into(&base, &[]);
    assert!(o.status.success(), "{}", text(&o));
    let brighter = dir.join("brighter");
    let o = render_into(&brighter, &["--exposure-compensation", "1.5"]);
    assert!(o.status.success(), "{}", text(&o));
    let (a, b) = (ev100(&base), ev100(&brighter));
    assert!(
        a.is_finite() && (a - b - 1.5).abs() < 1e-4,
        "EV100 {a} -> {b}"
    );
    assert!(
        mean_png(&brighter.join("out.png")) > mean_png(&base.join("out.png")) + 5.0,
        "the PNG brightens"
    );
    let (_, hdr_a) = read_exr(&base.join("out.exr"));
    let (_, hdr_b) = read_exr(&brighter.join("out.exr"));
    assert_eq!(hdr_a, hdr_b, "the EXR is radiance, before exposure");
    let fixed = dir.join("fixed");
    let o = render_into(&fixed, &["--ev100", "9.25", "--exposure-compensation", "3"]);
    assert!(o.status.success(), "{}", text(&o));
    assert_eq!(ev100(&fixed), 9.25, "a fixed EV100 wins over everything");

    let flag = dir.join("flag");
    let o = render_into(&flag, &["--no-tonemap-local"]);
    assert!(o.status.success(), "{}", text(&o));
    let set = dir.join("set");
    let o = render_into(&set, &["--set", "local_tonemap.enabled=false"]);
    assert!(o.status.success(), "{}", text(&o));
    let png = |d: &Path| {
        image::open(d.join("out.png"))
            .unwrap()
            .to_rgba8()
            .into_raw()
    };
    assert_eq!(png(&flag), png(&set), "the flag is the setting");
    assert_ne!(
        png(&flag),
        png(&base),
        "the local tonemap changes the boxes"
    );

    let bad = dir.join("bad");
    for (args, names) in [
        (
            &["--exposure-compensation", "nan"][..],
            "--exposure-compensation",
        ),
        (
            &["--exposure-compensation", "inf"][..],
            "--exposure-compensation",
        ),
        (&["--exposure-compensation", "40"][..], "compensation_ev"),
        (&["--set", "local_tonemap.contrast=-1"][..], "contrast"),
        (
            &["--set", "exposure.adapt_up_ev_per_s=nan"][..],
            "adapt_up_ev_per_s",
        ),
    ] {
        let o = render_into(&bad, args);
        assert!(!o.status.success(), "{args:?} succeeded");
        assert!(text(&o).contains(names), "{args:?}: {}", text(&o));
        assert!(!bad.join("out.png").exists(), "{args:?} wrote a PNG");
    }
}

/// The intermediates dump by name: the exposure's two histograms (128 u32 counts each: every
/// pixel in the luminance one, the surface pixels in the illuminance one), the filled and
/// blurred bilateral grid (64x32x64, slices stacked vertically: each pixel adds a weight of
/// one in all, so the filled grid's weights sum to the pixel count), the cells' mean log
/// luminance and its wide blur, and the gain.
#[test]
fn the_intermediates_dump_by_name() {
    let dir = tmp("dumps");
    let names = [
        "exposure.histogram",
        "local_tonemap.grid",
        "local_tonemap.grid_blurred",
        "local_tonemap.coarse",
        "local_tonemap.wide",
        "local_tonemap.log2_gain",
    ];
    let mut args = Vec::new();
    for n in names {
        args.extend(["--dump", n]);
    }
    let o = render_into(&dir, &args);
    assert!(o.status.success(), "{}", text(&o));
    let pixels = 64 * 40;

    let counts: Vec<u32> = read_words(&dir.join("exposure.histogram.bin"))
        .into_iter()
        .map(u32::from_le_bytes)
        .collect();
    assert_eq!(counts.len(), 256);
    let (illuminance, luminance) = counts.split_at(128);
    assert_eq!(luminance.iter().sum::<u32>(), pixels);
    let surface = illuminance.iter().sum::<u32>();
    assert!(surface > 0 && surface < pixels, "{surface} surface pixels");

    let (w, grid) = read_exr(&dir.join("local_tonemap.grid.exr"));
    assert_eq!((w, grid.len()), (64, 64 * 32 * 64));
    let weight: f64 = grid.iter().map(|t| t[1] as f64).sum();
    assert!(
        (weight - pixels as f64).abs() < 1e-3,
        "grid weight {weight}"
    );
    // Σ w V over Σ w is a log luminance inside the grid's range.
    let wv: f64 = grid.iter().map(|t| t[0] as f64).sum();
    assert!((0.0..=24.0).contains(&(wv / weight)), "{}", wv / weight);
    let (_, blurred) = read_exr(&dir.join("local_tonemap.grid_blurred.exr"));
    assert_eq!(blurred.len(), grid.len());
    assert!(blurred.iter().flatten().all(|v| v.is_finite()));
    assert_ne!(blurred, grid);

    let (w, coarse) = read_exr(&dir.join("local_tonemap.coarse.exr"));
    assert_eq!((w, coarse.len()), (64, 64 * 32));
    let coarse_weight: f64 = coarse.iter().map(|t| t[1] as f64).sum();
    assert!(
        (coarse_weight - pixels as f64).abs() < 1e-3,
        "{coarse_weight}"
    );
    let (w, wide) = read_exr(&dir.join("local_tonemap.wide.exr"));
    assert_eq!((w, wide.len()), (256, 256 * 128));
    assert!(wide.iter().all(|t| t[0].is_finite()));

    let (w, gain) = read_exr(&dir.join("local_tonemap.log2_gain.exr"));
    assert_eq!((w, gain.len()), (64, pixels as usize));
    assert!(gain.iter().all(|t| t[0].is_finite()));
    assert!(gain.iter().any(|t| t[0] != 0.0), "the gain is not all zero");
}
