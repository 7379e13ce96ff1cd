//! `hikari compare`: A | B | FLIP in one PNG three images wide; identical settings give FLIP
//! exactly 0 and a luminance ratio of 1; a toggled technique shows up in the numbers; bad
//! `--toggle` names list the valid ones.

mod common;

use std::path::Path;

use common::{hikari, text, tmp};

/// `hikari compare --json` of the boxes at 64x36, 2 frames each, probes off (no bake).
fn compare(dir: &Path, name: &str, args: &[&str]) -> (serde_json::Value, image::RgbaImage) {
    let png = dir.join(format!("{name}.png"));
    let mut all = vec![
        "compare",
        "--scene",
        "boxes",
        "--width",
        "64",
        "--height",
        "36",
        "--frames",
        "2",
        "--set",
        "irradiance_probes.enabled=false",
        "--json",
        "-o",
        png.to_str().unwrap(),
    ];
    all.extend_from_slice(args);
    // Progress drawn as on a terminal: on stderr, the JSON on stdout untouched.
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_hikari"))
        .args(&all)
        .env("HIKARI_PROGRESS", "always")
        .output()
        .expect("run hikari");
    assert!(o.status.success(), "{}", text(&o));
    let said = String::from_utf8_lossy(&o.stderr);
    assert!(
        said.contains("rendered A: 2 frames") && said.contains("rendered B: 2 frames"),
        "progress: {said}"
    );
    let json: serde_json::Value =
        serde_json::from_slice(&o.stdout).unwrap_or_else(|e| panic!("{e}: {}", text(&o)));
    (json, image::open(&png).unwrap().to_rgba8())
}

/// The panel `k` (0: A, 1: B, 2: FLIP) of a comparison image.
fn panel(img: &image::RgbaImage, k: u32) -> Vec<[u8; 4]> {
    let w = img.width() / 3;
    (0..img.height())
        .flat_map(|y| (0..w).map(move |x| (x + k * w, y)))
        .map(|(x, y)| img.get_pixel(x, y).0)
        .collect()
}

#[test]
fn identical_settings_give_flip_zero_and_a_luminance_ratio_of_one() {
    let dir = tmp("compare-same");
    let (exr_a, exr_b) = (dir.join("a.exr"), dir.join("b.exr"));
    let (j, img) = compare(
        &dir,
        "same",
        &[
            "--exr-a",
            exr_a.to_str().unwrap(),
            "--exr-b",
            exr_b.to_str().unwrap(),
        ],
    );
    assert_eq!(img.dimensions(), (3 * 64, 36), "A | B | FLIP: three widths");
    assert_eq!(j["flip"]["mean"], 0.0, "{j}");
    assert_eq!(j["flip"]["p95"], 0.0, "{j}");
    assert_eq!(j["luminance_ratio_b_over_a"], 1.0, "{j}");
    assert_eq!(j["a"]["ev100"], j["b"]["ev100"], "{j}");
    assert_eq!(j["a"]["settings"], serde_json::json!({}), "{j}");
    assert_eq!(j["exposure"], "a");
    let (a, b, map) = (panel(&img, 0), panel(&img, 1), panel(&img, 2));
    assert_eq!(a, b, "A and B differ");
    assert!(a.iter().any(|p| *p != a[0]), "a blank image");
    assert!(map.iter().all(|p| *p == map[0]), "an error map with errors");
    assert!(exr_a.exists() && exr_b.exists());
    assert!(j["a"]["mean_luminance_nits"].as_f64().unwrap() > 0.0);
}

#[test]
fn a_toggled_technique_is_named_and_changes_the_image_at_as_exposure() {
    let dir = tmp("compare-toggle");
    let (j, img) = compare(&dir, "gi", &["--toggle", "ray_traced_gi"]);
    assert_eq!(img.dimensions(), (3 * 64, 36));
    assert_eq!(j["a"]["settings"]["ray_traced_gi.enabled"], "true", "{j}");
    assert_eq!(j["b"]["settings"]["ray_traced_gi.enabled"], "false", "{j}");
    assert_eq!(j["a"]["ev100"], j["b"]["ev100"], "B at A's exposure: {j}");
    let mean = j["flip"]["mean"].as_f64().unwrap();
    let p95 = j["flip"]["p95"].as_f64().unwrap();
    assert!(mean > 0.0 && p95 >= mean, "{j}");
    // Another light on the same scene: near A's, not it. (With the probes off, B's ambient
    // is the sky's unoccluded SH, a little brighter than the GI's traced bounce.)
    let ratio = j["luminance_ratio_b_over_a"].as_f64().unwrap();
    assert!(ratio != 1.0 && (0.5..2.0).contains(&ratio), "{j}");
    assert_ne!(panel(&img, 0), panel(&img, 1));
}

/// `--preset-a` and `--preset-b` give each side its own preset: the settings that differ
/// include the render scale (high 1, low 0.5), and the images differ.
#[test]
fn each_side_may_have_its_own_preset() {
    let dir = tmp("compare-presets");
    let (j, img) = compare(
        &dir,
        "presets",
        &["--preset-a", "high", "--preset-b", "low"],
    );
    assert_eq!(j["a"]["settings"]["taa.render_scale"], "1.0", "{j}");
    assert_eq!(j["b"]["settings"]["taa.render_scale"], "0.5", "{j}");
    assert!(j["flip"]["mean"].as_f64().unwrap() > 0.0, "{j}");
    assert_ne!(panel(&img, 0), panel(&img, 1));
}

/// `--own-exposure` meters each image: B's exposure compensation then moves B's EV100 (it
/// would not at A's exposure, which B takes as `exposure.ev100`).
#[test]
fn own_exposure_meters_b_on_its_own() {
    let dir = tmp("compare-own");
    let (j, _) = compare(
        &dir,
        "own",
        &["--own-exposure", "--b", "exposure.compensation_ev=2"],
    );
    assert_eq!(j["exposure"], "own");
    assert_eq!(j["b"]["settings"]["exposure.compensation_ev"], "2.0", "{j}");
    let (a, b) = (
        j["a"]["ev100"].as_f64().unwrap(),
        j["b"]["ev100"].as_f64().unwrap(),
    );
    assert!((a - b - 2.0).abs() < 0.05, "EV100 A {a}, B {b}: {j}");
}

#[test]
fn bad_toggles_and_settings_are_named_with_what_is_valid() {
    let o = hikari(&["compare", "--scene", "boxes", "--toggle", "bloom"]);
    let t = text(&o);
    assert!(!o.status.success() && !t.contains("panicked"), "{t}");
    assert!(
        t.contains("--toggle bloom") && t.contains("ray_traced_gi") && t.contains("taa"),
        "{t}"
    );
    // A table without an `enabled` switch is not toggled either.
    let o = hikari(&["compare", "--scene", "boxes", "--toggle", "tonemap"]);
    assert!(!o.status.success() && text(&o).contains("--toggle tonemap"));
    let o = hikari(&["compare", "--scene", "boxes", "--b", "taa.jitter_samples=0"]);
    let t = text(&o);
    assert!(
        !o.status.success() && t.contains("taa.jitter_samples") && t.contains("--b"),
        "{t}"
    );
    let o = hikari(&["compare", "--scene", "boxes", "--a", "taa"]);
    assert!(
        !o.status.success() && text(&o).contains("--a"),
        "{}",
        text(&o)
    );
    let o = hikari(&["compare", "--scene", "boxes", "-o", "/no/such/dir/c.png"]);
    assert!(text(&o).contains("does not exist"), "{}", text(&o));
}
