//! What `hikari render` does with little given: a glTF with nothing to draw still renders
//! (issue 17's bad input), only the sky, seen from the file's camera or, without one, from a
//! camera looking level at the horizon; without `--frames` it draws enough frames for the
//! temporal passes and says why in `--help` (issue 18).

mod common;

use std::path::Path;
use std::process::Command;

use common::{hikari, text, tmp};

#[test]
fn help_says_how_many_frames_render_draws_by_default_and_why() {
    let out = hikari(&["render", "--help"]);
    let help = text(&out);
    assert!(out.status.success(), "{help}");
    let flat = help.split_whitespace().collect::<Vec<_>>().join(" ");
    assert!(
        flat.contains("with ray-traced GI 16")
            && flat.contains("max_accumulation_speed")
            && flat.contains("jitter_samples"),
        "{flat}"
    );
}

/// Renders `gltf` (JSON text) at 32x16, one frame; returns the PNG's rows and hikari's output.
fn render(dir: &Path, name: &str, gltf: &str) -> (image::RgbImage, String) {
    let file = dir.join(format!("{name}.gltf"));
    std::fs::write(&file, gltf).unwrap();
    let png = dir.join(format!("{name}.png"));
    let out = Command::new(env!("CARGO_BIN_EXE_hikari"))
        .env("XDG_CACHE_HOME", dir.join("cache"))
        .args(["render", "--scene"])
        .arg(&file)
        .args([
            "--width",
            "32",
            "--height",
            "16",
            "--frames",
            "1",
            "--no-exr",
            // The clouds and the haze (hikari-render's tests/clouds.rs, haze.rs) would cover
            // parts of the sky that this test holds to be blue, and tint its grey ground.
            "--set",
            "clouds.enabled=false",
            "--set",
            "haze.enabled=false",
            "-o",
        ])
        .arg(&png)
        .output()
        .expect("run hikari");
    let said = text(&out);
    assert!(out.status.success(), "{name}: {said}");
    (image::open(&png).unwrap().to_rgb8(), said)
}

/// With a level view the horizon is the middle row: a blue sky above, the sky model's grey
/// ground below (neither drawn from geometry; there is none).
fn assert_horizon_in_the_middle(name: &str, img: &image::RgbImage) {
    let h = img.height();
    for (x, y, p) in img.enumerate_pixels() {
        let [r, g, b] = p.0.map(i32::from);
        if y < h / 2 {
            assert!(
                b > r + 10,
                "{name}: ({x}, {y}) above the horizon is not sky blue: {p:?}"
            );
        } else {
            assert!(
                (b - r).abs() <= 6 && (g - r).abs() <= 6 && r > 10,
                "{name}: ({x}, {y}) below the horizon is not the grey ground: {p:?}"
            );
        }
    }
}

#[test]
fn scenes_without_geometry_render_the_sky() {
    let dir = tmp("empty-scene");

    let (img, said) = render(&dir, "nothing", r#"{"asset": {"version": "2.0"}}"#);
    assert!(
        said.contains("no triangles") && said.contains("horizon"),
        "no warning: {said}"
    );
    assert_horizon_in_the_middle("nothing", &img);

    // A camera 2 m up with glTF's default orientation (looking along -z): level too.
    let (img, _) = render(
        &dir,
        "camera_only",
        r#"{"asset": {"version": "2.0"},
            "cameras": [{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.1}}],
            "nodes": [{"name": "eye", "camera": 0, "translation": [0, 2, 0]}],
            "scenes": [{"nodes": [0]}], "scene": 0}"#,
    );
    assert_horizon_in_the_middle("camera_only", &img);

    // Only a sun (KHR_lights_punctual, shining down at 60 degrees): the file's own light.
    let (img, _) = render(
        &dir,
        "sun_only",
        r#"{"asset": {"version": "2.0"}, "extensionsUsed": ["KHR_lights_punctual"],
            "extensions": {"KHR_lights_punctual": {"lights": [
                {"type": "directional", "intensity": 100000}]}},
            "nodes": [{"name": "sun", "rotation": [-0.5, 0, 0, 0.8660254],
                       "extensions": {"KHR_lights_punctual": {"light": 0}}}],
            "scenes": [{"nodes": [0]}], "scene": 0}"#,
    );
    assert_horizon_in_the_middle("sun_only", &img);
}
