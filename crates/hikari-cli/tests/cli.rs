//! The `hikari` binary as a user runs it: outputs, and clean errors on bad input.

use std::path::PathBuf;
use std::process::{Command, Output};

mod common;

use common::{hikari, text, tmp};

/// Every preset runs within WebGPU's default limits, which the CPU driver has too: `ultra`'s
/// 4 x 4096^2 shadow cascades (256 MiB in one storage binding) are reduced to fit, with a
/// warning naming the setting, instead of failing.
#[test]
fn the_ultra_preset_renders_within_the_cpu_drivers_limits() {
    let dir = tmp("ultra");
    let png = dir.join("ultra.png");
    let o = hikari(&[
        "render",
        "--preset",
        "ultra",
        "--scene",
        "boxes",
        "--width",
        "32",
        "--height",
        "18",
        "--frames",
        "1",
        "--no-exr",
        "-o",
        png.to_str().unwrap(),
    ]);
    let t = text(&o);
    assert!(o.status.success(), "{t}");
    assert!(
        t.contains("sun_shadows.resolution 4096") && t.contains("using 2048"),
        "{t}"
    );
    assert!(png.exists());
}

#[test]
fn render_writes_png_exr_and_dumps() {
    let dir = tmp("render");
    let png = dir.join("out.png");
    let o = hikari(&[
        "render",
        "--width",
        "64",
        "--height",
        "40",
        "-o",
        png.to_str().unwrap(),
        "--dump",
        "gbuffer.normal",
        "--timings",
        "--frames",
        "2",
    ]);
    assert!(o.status.success(), "{}", text(&o));
    let img = image::open(&png).unwrap().to_rgba8();
    assert_eq!(img.dimensions(), (64, 40));
    // Not a blank image: sky and lit boxes differ.
    let px: Vec<_> = img.pixels().map(|p| p.0).collect();
    assert!(px.iter().any(|p| *p != px[0]));
    let exr = exr::prelude::read_first_rgba_layer_from_file(
        dir.join("out.exr"),
        |res, _| vec![[0f32; 4]; res.width() * res.height()],
        |v, pos, (r, g, b, a): (f32, f32, f32, f32)| v[pos.y() * 64 + pos.x()] = [r, g, b, a],
    )
    .unwrap();
    let hdr = exr.layer_data.channel_data.pixels;
    assert!(hdr.iter().flatten().all(|v| v.is_finite() && *v >= 0.0));
    assert!(
        hdr.iter().any(|p| p[0] > 100.0),
        "radiance in nits, not display values"
    );
    assert!(dir.join("gbuffer.normal.exr").exists());
    assert!(
        // The last of two frames: the still view's shadow maps are cached, TAA blends; on the
        // CPU driver, at the low preset's render scale, upsampling to the image's size.
        text(&o).contains("gbuffer.resolve") && text(&o).contains("taa.upsample"),
        "timing table: {}",
        text(&o)
    );
    assert!(
        text(&o).contains("CPU adapter") && text(&o).contains("preset low, render scale 0.5"),
        "the CPU adapter's default is said: {}",
        text(&o)
    );
    // Atomic writes leave no temporary files behind.
    let leftovers: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .filter(|e| {
            e.as_ref()
                .unwrap()
                .file_name()
                .to_string_lossy()
                .contains(".tmp")
        })
        .collect();
    assert!(leftovers.is_empty());
}

/// `--dolly` moves the camera over the frames and arrives at the view: the written frame
/// differs from a still camera's (the history saw other views) and stays close to it (it is
/// the same view).
#[test]
fn render_dolly_arrives_at_the_view_in_motion() {
    let dir = tmp("dolly");
    let run = |name: &str, dolly: &str, progress: Option<&str>| {
        let png = dir.join(name);
        let mut command = Command::new(env!("CARGO_BIN_EXE_hikari"));
        match progress {
            Some(p) => command.env("HIKARI_PROGRESS", p),
            None => command.env_remove("HIKARI_PROGRESS"),
        };
        let o = command
            .args([
                "render",
                "--scene",
                "boxes",
                "--width",
                "48",
                "--height",
                "32",
                "--frames",
                "4",
                "--dolly",
                dolly,
                "--no-exr",
                "-o",
                png.to_str().unwrap(),
            ])
            .output()
            .expect("run hikari");
        assert!(o.status.success(), "{}", text(&o));
        (image::open(&png).unwrap().to_rgb8(), o)
    };
    // A script's run (stderr a pipe): no progress. With HIKARI_PROGRESS=always, as on a
    // terminal: each step, the frames of N, the writing.
    let (still, quiet) = run("still.png", "0", None);
    let said = String::from_utf8_lossy(&quiet.stderr);
    assert!(
        !said.contains("frames") && !said.contains("GPU"),
        "progress on a pipe: {said}"
    );
    let (moving, shown) = run("moving.png", "1.5", Some("always"));
    let said = String::from_utf8_lossy(&shown.stderr);
    for step in [
        "scene boxes (built-in)",
        "starting the GPU",
        "✓ GPU: ",
        "renderer ready",
        "the first frame compiles the shaders",
        "rendered the view: 4 frames",
        "writing ",
    ] {
        assert!(said.contains(step), "`{step}` not in the progress: {said}");
    }
    assert!(
        String::from_utf8_lossy(&shown.stdout).contains("wrote "),
        "{}",
        text(&shown)
    );
    let diffs: Vec<i32> = still
        .pixels()
        .zip(moving.pixels())
        .flat_map(|(a, b)| (0..3).map(move |c| (a[c] as i32 - b[c] as i32).abs()))
        .collect();
    let mean = diffs.iter().sum::<i32>() as f64 / diffs.len() as f64;
    assert!(diffs.iter().any(|&d| d > 0), "the move left no trace");
    assert!(
        mean < 20.0,
        "mean difference {mean} levels: not the same view"
    );
}

fn assert_clean_failure(args: &[&str], needle: &str) {
    let o = hikari(args);
    let t = text(&o);
    assert!(!o.status.success(), "{args:?} should fail: {t}");
    assert!(!t.contains("panicked"), "{args:?} panicked: {t}");
    assert!(t.contains(needle), "{args:?}: expected `{needle}` in: {t}");
}

#[test]
fn bad_arguments_fail_with_a_message_and_no_panic() {
    assert_clean_failure(
        &["render", "--scene", "atlantis"],
        "unknown scene `atlantis`",
    );
    assert_clean_failure(&["render", "--camera", "nope"], "no camera named `nope`");
    assert_clean_failure(&["render", "--ev100", "99"], "--ev100 99");
    assert_clean_failure(&["render", "--time", "25:00"], "25:00");
    assert_clean_failure(
        &["render", "--config", "/nonexistent/hikari.toml"],
        "cannot read config file",
    );
    assert_clean_failure(&["render", "--width", "banana"], "invalid value");
    assert_clean_failure(&["bench", "frame", "--frames", "0"], "--frames");
    assert_clean_failure(&["bench", "frame", "--time-step", "NaN"], "--time-step");
    assert_clean_failure(&["bench", "frame", "--time-step", "11"], "--time-step");
    assert_clean_failure(&["render", "--dolly", "NaN"], "--dolly");
    assert_clean_failure(&["render", "--dolly", "-101"], "--dolly");
    assert_clean_failure(
        &["render", "--set", "scene_rt.cull_margin_m=-1"],
        "scene_rt.cull_margin_m",
    );
    let dir = tmp("bad");
    let out = dir.join("x.png");
    let config = dir.join("bad.toml");
    std::fs::write(&config, "[sun_shadows]\ncascades = 9\n").unwrap();
    assert_clean_failure(
        &["render", "--config", config.to_str().unwrap()],
        "`sun_shadows.cascades` is 9; allowed: 1 to 4",
    );
    assert_clean_failure(
        &["render", "--width", "0", "-o", out.to_str().unwrap()],
        "image width",
    );
    assert_clean_failure(
        &["render", "--width", "100000", "-o", out.to_str().unwrap()],
        "exceeds this GPU's limit",
    );
    assert_clean_failure(
        &[
            "render",
            "--width",
            "16",
            "--height",
            "16",
            "--dump",
            "gbuffer.nope",
            "-o",
            out.to_str().unwrap(),
        ],
        "gbuffer.normal",
    );
    assert_clean_failure(
        &[
            "render",
            "--width",
            "16",
            "--height",
            "16",
            "-o",
            "/no/such/dir/x.png",
        ],
        "does not exist",
    );
}

/// Progress: drawn with `HIKARI_PROGRESS=always` (as on a terminal), not with `--quiet`, and
/// not on a pipe; a failure clears the step it stopped in and prints the error alone.
#[test]
fn progress_shows_the_steps_unless_quiet_or_piped() {
    let dir = tmp("progress");
    let png = dir.join("x.png");
    let run = |progress: Option<&str>, quiet: bool| {
        let mut c = Command::new(env!("CARGO_BIN_EXE_hikari"));
        c.args([
            "render",
            "--scene",
            "boxes",
            "--width",
            "100000",
            "--height",
            "8",
            "-o",
            png.to_str().unwrap(),
        ]);
        if quiet {
            c.arg("--quiet");
        }
        c.env("XDG_CACHE_HOME", dir.join("cache"));
        match progress {
            Some(p) => c.env("HIKARI_PROGRESS", p),
            None => c.env_remove("HIKARI_PROGRESS"),
        };
        let o = c.output().expect("run hikari");
        assert!(!o.status.success(), "{}", text(&o));
        let said = String::from_utf8_lossy(&o.stderr).into_owned();
        assert!(said.contains("exceeds this GPU's limit"), "{said}");
        said
    };
    let shown = run(Some("always"), false);
    assert!(
        shown.contains("starting the GPU") && shown.contains("✓ GPU: "),
        "{shown}"
    );
    for said in [
        run(Some("always"), true),
        run(None, false),
        run(Some("never"), false),
    ] {
        assert!(
            !said.contains("starting the GPU") && !said.contains('✓'),
            "progress drawn: {said}"
        );
    }
}

#[test]
fn missing_adapter_is_a_clear_error() {
    let o = Command::new(env!("CARGO_BIN_EXE_hikari"))
        .args(["info"])
        .env("WGPU_ADAPTER_NAME", "no-such-gpu-anywhere")
        .output()
        .unwrap();
    let t = text(&o);
    assert!(!o.status.success());
    assert!(
        t.contains("no-such-gpu-anywhere") && !t.contains("panicked"),
        "{t}"
    );

    // No driver at all: Vulkan pointed at an empty ICD list.
    let o = Command::new(env!("CARGO_BIN_EXE_hikari"))
        .args(["render", "--width", "8", "--height", "8"])
        .env("WGPU_BACKEND", "vulkan")
        .env("VK_ICD_FILENAMES", "/nonexistent/icd.json")
        .env("VK_DRIVER_FILES", "/nonexistent/icd.json")
        .env_remove("WGPU_ADAPTER_NAME")
        .output()
        .unwrap();
    let t = text(&o);
    assert!(!o.status.success(), "{t}");
    assert!(
        t.contains("mesa-vulkan-drivers") && !t.contains("panicked"),
        "{t}"
    );
}

#[test]
fn constants_json_has_every_key_and_the_white_balance_maps_white() {
    let o = hikari(&["constants", "--white", "0.8,0.9,1.2", "--json"]);
    assert!(o.status.success(), "{}", text(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    for key in [
        "rec709_to_xyz",
        "acescg_to_xyz",
        "tonemap_to_xyz",
        "lms_rayleigh_to_xyz",
        "rec709_to_tonemap",
        "tonemap_to_rec709",
        "white_balance_rec709",
        "lmsr_from_rec709",
        "rgb_from_lms_gain",
        "smits_basis",
        "rayleigh_lms_per_km",
    ] {
        assert!(v.get(key).is_some(), "missing {key}");
    }
    // The talk's interface: the artist picks what white becomes, so W * (1,1,1) = white.
    let m: Vec<Vec<f64>> = serde_json::from_value(v["white_balance_rec709"].clone()).unwrap();
    let white = [0.8, 0.9, 1.2];
    for (row, want) in m.iter().zip(white) {
        assert!((row.iter().sum::<f64>() - want).abs() < 1e-9, "{m:?}");
    }
    // The talk's LMS Rayleigh coefficients, as published.
    assert_eq!(
        v["rayleigh_lms_per_km"],
        serde_json::json!([0.0076224, 0.012935, 0.024845])
    );
    assert_eq!(v["lmsr_from_rec709"].as_array().unwrap().len(), 4);

    assert_clean_failure(&["constants", "--white", "1,0,1"], "greater than 0");
    assert_clean_failure(&["constants", "--white", "1,x,1"], "not a number");
}

#[test]
fn bench_frame_names_the_scene_camera_time_and_size_that_ran() {
    // The scene and time come from a config file, not from flags: the report must name what
    // was resolved, not the default scene.
    let dir = tmp("bench-frame");
    let config = dir.join("bench.toml");
    std::fs::write(&config, "scene = \"cornell\"\ntime = \"7:30\"\n").unwrap();
    let first_camera = hikari_scene::builtin::by_name("cornell").unwrap().cameras[0]
        .name
        .clone();
    let mut args = vec![
        "bench",
        "frame",
        "--frames",
        "2",
        "--warmup",
        "0",
        "--width",
        "64",
        "--height",
        "48",
        "--config",
        config.to_str().unwrap(),
    ];
    let o = hikari(&args);
    let t = text(&o);
    assert!(o.status.success(), "{t}");
    let header = String::from_utf8_lossy(&o.stdout)
        .lines()
        .next()
        .unwrap_or_default()
        .to_string();
    for want in [
        "scene cornell (built-in)",
        &format!("camera `{first_camera}`"),
        "time 07:30",
        "64x48",
        "2 frames after 0 warm-up",
    ] {
        assert!(header.contains(want), "`{want}` not in the header: {t}");
    }
    assert!(!t.contains("village"), "{t}");

    args.push("--json");
    let o = hikari(&args);
    assert!(o.status.success(), "{}", text(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(
        v["scene"],
        serde_json::json!({
            "name": "cornell",
            "source": "built-in",
            "camera": first_camera,
            "camera_from": "the scene's first",
            "time": "07:30",
            "date": "2024-07-21",
            "width": 64,
            "height": 48,
        })
    );
    assert_eq!(v["frames"], 2);
    assert!(!v["passes"].as_array().unwrap().is_empty(), "{v}");
    // Each pass's bytes and memory floor: TAA's resolve binds this frame's radiance, the
    // motion vectors and last frame's history to read and the new history to write, four
    // 64x48 Rgba16Float images (counted by hand from its WGSL).
    let taa = v["passes"]
        .as_array()
        .unwrap()
        .iter()
        .find(|p| p["name"] == "taa.resolve")
        .unwrap_or_else(|| panic!("no taa.resolve: {v}"));
    assert_eq!(taa["bytes"], 4 * 64 * 48 * 8, "{taa}");
    assert!(taa["floor_ms"].as_f64().is_some_and(|f| f > 0.0), "{taa}");
}

#[test]
fn sky_writes_a_2_to_1_exr_and_its_json_names_sun_moon_and_sh() {
    let dir = tmp("sky");
    let out = dir.join("noon.exr");
    let o = hikari(&[
        "sky",
        "--table-quality",
        "0",
        "--width",
        "64",
        "--time",
        "12:30",
        "--json",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", text(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    // A clear summer noon at 34.4° N: the sun high in the south, near 100 klux on the ground.
    let sun = &v["sun"];
    assert!(sun["elevation_deg"].as_f64().unwrap() > 70.0, "{v}");
    let lux = sun["illuminance_lux"].as_f64().unwrap();
    assert!((80_000.0..125_000.0).contains(&lux), "{v}");
    assert!(
        v["moon"]["illuminated_fraction"].as_f64().unwrap() > 0.95,
        "{v}"
    );
    let sh = v["sh"].as_array().unwrap();
    assert_eq!(sh.len(), 9);
    assert!(sh.iter().all(|c| c.as_array().unwrap().len() == 3));
    // A blue sky: band 0 bluer than red.
    assert!(
        sh[0][2].as_f64().unwrap() > sh[0][0].as_f64().unwrap(),
        "{v}"
    );
    let img = exr::prelude::read_first_rgba_layer_from_file(
        &out,
        |r, _| vec![0f32; r.width() * r.height()],
        |_, _, (_, _, _, _): (f32, f32, f32, f32)| {},
    )
    .unwrap();
    assert_eq!(img.layer_data.size.0, 64);
    assert_eq!(img.layer_data.size.1, 32);

    let bad = dir.join("bad.exr");
    assert_clean_failure(
        &["sky", "--lat", "95", "-o", bad.to_str().unwrap()],
        "--lat 95",
    );
    assert_clean_failure(
        &["sky", "--date", "2101-01-01", "-o", bad.to_str().unwrap()],
        "--date 2101-01-01",
    );
    assert!(!bad.exists(), "nothing is written on bad input");
}

/// `hikari` with the bake cache in `cache` (never the user's own).
fn hikari_cached(cache: &std::path::Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_hikari"))
        .args(args)
        .env("XDG_CACHE_HOME", cache)
        .output()
        .expect("run hikari")
}

fn json_of(o: &Output) -> serde_json::Value {
    assert!(o.status.success(), "{}", text(o));
    serde_json::from_slice(&o.stdout).unwrap_or_else(|e| panic!("{e}: {}", text(o)))
}

/// `hikari bake` writes a bake file and sums it up; `hikari probes` lists every probe with the
/// issue's fields; a probe 30 m above the boxes sees the whole sky (sky visibility of a
/// constant 1: l=0 coefficient 2 sqrt(pi), the rest 0, within the bake's Monte Carlo error);
/// `--at` a probe's own position gives that probe's values, and with `--time` the relit
/// irradiance there.
#[test]
fn bake_and_probes_write_and_list_the_bake() {
    let dir = tmp("bake");
    let file = dir.join("boxes.hikprobe");
    let f = file.to_str().unwrap();
    let summary = json_of(&hikari_cached(
        &dir,
        &["bake", "--scene", "boxes", "-o", f, "--json"],
    ));
    assert!(file.exists());
    let tiles = summary["grid"]["tiles"].as_array().unwrap().len();
    assert!(tiles >= 1);
    assert_eq!(summary["grid"]["probes"], tiles * 768);
    assert_eq!(summary["rays_per_probe"], 2048);
    assert_eq!(summary["bounce_rays_per_hit"], 2);
    assert!(summary["rays"].as_u64().unwrap() >= 2048 * tiles as u64 * 768 / 2);
    assert!(summary["seconds"].as_f64().unwrap() > 0.0);

    let listed = json_of(&hikari_cached(
        &dir,
        &["probes", "--scene", "boxes", "--bake", f, "--json"],
    ));
    let probes = listed["probes"].as_array().unwrap();
    assert_eq!(probes.len(), tiles * 768);
    for p in probes.iter().take(50) {
        assert_eq!(p["position"].as_array().unwrap().len(), 3);
        assert!(p["interior"].is_boolean());
        assert_eq!(p["sky_visibility"].as_array().unwrap().len(), 9);
        let b = p["bounced_sky_visibility"].as_array().unwrap();
        assert_eq!(b.len(), 9);
        assert!(b.iter().all(|c| c.as_array().unwrap().len() == 3));
        assert!(p["grid_tile"].is_array());
    }
    // The bake is the full one: the ground (albedo 0.3, a 40 m square) bounces sky light to the
    // low probes above it.
    let over_ground = |p: &&serde_json::Value| {
        let at = |k: usize| p["position"][k].as_f64().unwrap().abs();
        p["index"][2] == 0 && at(0) < 18.0 && at(2) < 18.0
    };
    let bounced = |p: &serde_json::Value| p["bounced_sky_visibility"][0][0].as_f64().unwrap();
    assert!(
        probes.iter().filter(over_ground).all(|p| bounced(p) > 0.0)
            && probes.iter().filter(over_ground).count() >= 4,
        "a probe 1.5 m over the ground has no bounced sky visibility"
    );
    // The top layer stands 30 m over the ground: nothing of the boxes scene reaches that high.
    let top = probes
        .iter()
        .find(|p| p["index"][2] == 2)
        .expect("a top-layer probe");
    let open = 2.0 * std::f64::consts::PI.sqrt();
    let c: Vec<f64> = top["sky_visibility"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    assert!((c[0] - open).abs() < 0.02 * open, "{c:?}");
    assert!(c[1..].iter().all(|x| x.abs() < 0.02 * open), "{c:?}");

    // At a probe's own position the interpolation is that probe.
    let at = top["position"].as_array().unwrap();
    let at = format!(
        "{},{},{}",
        at[0].as_f64().unwrap(),
        at[1].as_f64().unwrap(),
        at[2].as_f64().unwrap()
    );
    let o = hikari_cached(
        &dir,
        &[
            "probes", "--scene", "boxes", "--bake", f, "--json", "--at", &at, "--time", "10:00",
        ],
    );
    let v = json_of(&o);
    let point = &v["points"][0];
    assert_eq!(point["covered"], true);
    let got: Vec<f64> = point["sky_visibility"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    for k in 0..9 {
        assert!((got[k] - c[k]).abs() < 1e-4, "{got:?} vs {c:?}");
    }
    assert_eq!(v["relit"], true);
    let up = point["irradiance_up_lux"].as_array().unwrap();
    assert!(up.iter().all(|x| x.as_f64().unwrap() > 100.0), "{point}");
}

/// Bad bake files: a given file that is missing, truncated or of another scene is an error
/// naming the file and the problem; a bad file in the cache is baked again with a warning,
/// and the cache then holds a good one.
#[test]
fn bad_bake_files_are_named_or_rebaked_never_a_panic() {
    let dir = tmp("badbake");
    let cache = dir.join("cache");
    let png = dir.join("out.png");
    let png = png.to_str().unwrap();
    let render = |extra: &[&str]| {
        let mut args = vec![
            "render", "--scene", "boxes", "--width", "48", "--height", "32", "-o", png, "--no-exr",
        ];
        args.extend_from_slice(extra);
        hikari_cached(&cache, &args)
    };
    let missing = dir.join("missing.hikprobe");
    let o = render(&["--bake", missing.to_str().unwrap()]);
    let t = text(&o);
    assert!(!o.status.success() && !t.contains("panicked"), "{t}");
    assert!(t.contains("missing.hikprobe"), "{t}");

    // A miss bakes and fills the cache.
    let o = render(&[]);
    assert!(o.status.success(), "{}", text(&o));
    let cached: Vec<PathBuf> = std::fs::read_dir(cache.join("hikari"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "hikprobe"))
        .collect();
    assert_eq!(cached.len(), 1, "{cached:?}");
    let good = std::fs::read(&cached[0]).unwrap();

    // Truncated, given: an error naming the file and the problem.
    let truncated = dir.join("truncated.hikprobe");
    std::fs::write(&truncated, &good[..good.len() / 2]).unwrap();
    let o = render(&["--bake", truncated.to_str().unwrap()]);
    let t = text(&o);
    assert!(!o.status.success() && !t.contains("panicked"), "{t}");
    assert!(
        t.contains("truncated.hikprobe") && t.contains("truncated"),
        "{t}"
    );

    // Another scene's bake, given.
    let other = dir.join("other.hikprobe");
    let o = hikari_cached(
        &cache,
        &["bake", "--scene", "cutout", "-o", other.to_str().unwrap()],
    );
    assert!(o.status.success(), "{}", text(&o));
    let o = render(&["--bake", other.to_str().unwrap()]);
    let t = text(&o);
    assert!(!o.status.success() && !t.contains("panicked"), "{t}");
    assert!(t.contains("other.hikprobe"), "{t}");

    // Corrupt in the cache: a warning, a rebake, and a good cache again.
    let mut bad = good.clone();
    bad[200] ^= 0xff;
    std::fs::write(&cached[0], &bad).unwrap();
    let o = render(&[]);
    let t = text(&o);
    assert!(o.status.success(), "{t}");
    assert!(t.contains("baking the probes again"), "{t}");
    assert_eq!(std::fs::read(&cached[0]).unwrap(), good);
}

/// Issue 16's bad input, each on `hikari sky` (flags) and in a settings file (`[sky]` fields):
/// the error names the flag or field and its allowed range, the exit is non-zero, and nothing
/// is written.
#[test]
fn sky_bad_input_names_the_flag_or_field_and_its_range_and_writes_nothing() {
    let dir = tmp("sky-bad");
    let out = dir.join("bad.exr");
    let o = out.to_str().unwrap();
    let flags: &[(&[&str], &[&str])] = &[
        (&["--date", "1899-12-31"], &["--date 1899-12-31", "1900"]),
        (&["--date", "2101-01-01"], &["--date 2101-01-01", "2100"]),
        (&["--date", "2024-02-30"], &["--date 2024-02-30"]),
        (&["--time", "24:00"], &["--time 24:00", "23:59:59"]),
        (&["--time", "12:60"], &["--time 12:60", "23:59:59"]),
        (&["--lat", "90.5"], &["--lat 90.5", "-90 to 90"]),
        (&["--lat", "NaN"], &["--lat NaN", "-90 to 90"]),
        (&["--lon", "-180.5"], &["--lon -180.5", "-180 to 180"]),
        (&["--lon", "181"], &["--lon 181", "-180 to 180"]),
        (&["--utc-offset", "15"], &["--utc-offset 15", "-14 to 14"]),
        (
            &["--weather", "snowy"],
            &["--weather snowy", "clear, hazy, overcast"],
        ),
        (
            &["--color-space", "srgb"],
            &["--color-space srgb", "lms_rayleigh, rec709"],
        ),
        (&["--width", "7"], &["--width 7", "8 to 8192"]),
        (&["--table-quality", "3"], &["--table-quality 3", "0 to 2"]),
        (
            &["--dump-table", "rayleigh_multiple"],
            &["--dump-table rayleigh_multiple", "ground_irradiance"],
        ),
    ];
    let png = dir.join("bad.png");
    assert_clean_failure(&["sky", "-o", png.to_str().unwrap()], "ending in .exr");
    assert!(!png.exists());
    for (flag, needles) in flags {
        let mut args = vec!["sky", "-o", o];
        args.extend_from_slice(flag);
        // Small sizes, so that a case that wrongly passes ends quickly.
        for (name, small) in [("--width", "16"), ("--table-quality", "0")] {
            if !flag.contains(&name) {
                args.extend([name, small]);
            }
        }
        for needle in *needles {
            assert_clean_failure(&args, needle);
        }
        assert!(!out.exists(), "{flag:?}: nothing is written on bad input");
    }

    // The same flags on render and bench frame.
    let p = png.to_str().unwrap();
    let frame_flags: &[(&[&str], &str)] = &[
        (&["render", "-o", p, "--lon", "181"], "--lon 181"),
        (&["render", "-o", p, "--date", "1899-12-31"], "1900"),
        (&["render", "-o", p, "--lat", "-90.01"], "-90 to 90"),
        (
            &["bench", "frame", "--weather", "snowy"],
            "clear, hazy, overcast",
        ),
        (&["bench", "frame", "--utc-offset", "-15"], "-14 to 14"),
        (&["bench", "frame", "--time", "24:00:00"], "23:59:59"),
    ];
    for (args, needle) in frame_flags {
        assert_clean_failure(args, needle);
    }
    assert!(!png.exists());

    // The same checks reach the settings file's `[sky]` table (render reads it before any GPU
    // work, so these fail fast).
    let fields: &[(&str, &[&str])] = &[
        ("date = \"1899-12-31\"", &["`sky.date`", "1900"]),
        ("date = \"2100-12-32\"", &["`sky.date`"]),
        ("time = \"24:00\"", &["`sky.time`", "23:59:59"]),
        ("latitude_deg = -91.0", &["`sky.latitude_deg`", "-90 to 90"]),
        (
            "longitude_deg = 180.5",
            &["`sky.longitude_deg`", "-180 to 180"],
        ),
        ("utc_offset_h = -14.5", &["`sky.utc_offset_h`", "-14 to 14"]),
        (
            "weather = \"foggy\"",
            &["`sky.weather`", "clear, hazy, overcast"],
        ),
        (
            "sky_brightness_scale = -1.0",
            &["`sky.sky_brightness_scale`", "0 to 16"],
        ),
        ("latitude_deg = nan", &["`sky.latitude_deg`", "-90 to 90"]),
        (
            "color_space = \"xyz\"",
            &["`sky.color_space`", "lms_rayleigh, rec709"],
        ),
    ];
    for (line, needles) in fields {
        let config = dir.join("sky.toml");
        std::fs::write(&config, format!("[sky]\n{line}\n")).unwrap();
        for needle in *needles {
            assert_clean_failure(
                &[
                    "render",
                    "--config",
                    config.to_str().unwrap(),
                    "-o",
                    png.to_str().unwrap(),
                ],
                needle,
            );
        }
        assert!(!png.exists(), "{line}: nothing is written on bad input");
    }
}

/// `--dump-table NAME` writes the atmosphere's tables by name, each the size the table quality
/// gives it (hikari-render's `table_sizes(0)`), z slices stacked; transmittances lie in (0, 1].
#[test]
fn sky_dumps_its_tables_by_name() {
    let dir = tmp("sky-tables");
    let out = dir.join("sky.exr");
    let o = hikari(&[
        "sky",
        "--table-quality",
        "0",
        "--width",
        "16",
        "--dump-table",
        "transmittance",
        "--dump-table",
        "irradiance_mie",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", text(&o));
    let read = |name: &str| {
        exr::prelude::read_first_rgba_layer_from_file(
            dir.join(format!("atmosphere.{name}.exr")),
            |r, _| (r.width(), vec![[0f32; 3]; r.width() * r.height()]),
            |(w, px), p, (r, g, b, _): (f32, f32, f32, f32)| px[p.y() * *w + p.x()] = [r, g, b],
        )
        .unwrap_or_else(|e| panic!("{name}: {e}"))
    };
    let t = read("transmittance");
    assert_eq!(
        (t.layer_data.size.0, t.layer_data.size.1),
        (64, 16),
        "[mu, r]"
    );
    let (_, px) = &t.layer_data.channel_data.pixels;
    assert!(
        px.iter().flatten().all(|c| *c > 0.0 && *c <= 1.0),
        "transmittance outside (0, 1]"
    );
    let m = read("irradiance_mie");
    assert_eq!(
        (m.layer_data.size.0, m.layer_data.size.1),
        (32, 16 * 8),
        "[mu, mu_s, r] with r stacked"
    );
    assert!(!dir.join("atmosphere.rayleigh.exr").exists());
}

/// `--no-sun --no-sky` and the settings file's `[sky] sun = false, sky = false` turn off the
/// directional light and the sky's light alike: the same image, far darker than the village's
/// sunlit noon (what is left is its own lamps).
#[test]
fn no_sun_and_no_sky_from_flags_or_the_settings_file() {
    let dir = tmp("no-sun");
    let config = dir.join("off.toml");
    std::fs::write(&config, "[sky]\nsun = false\nsky = false\n").unwrap();
    let render = |name: &str, extra: &[&str]| {
        let png = dir.join(format!("{name}.png"));
        let mut args = vec![
            "render",
            "--width",
            "48",
            "--height",
            "32",
            "--ev100",
            "14",
            "--set",
            "sky.table_quality=0",
            "-o",
            png.to_str().unwrap(),
        ];
        args.extend_from_slice(extra);
        let o = hikari(&args);
        assert!(o.status.success(), "{name}: {}", text(&o));
        exr::prelude::read_first_rgba_layer_from_file(
            dir.join(format!("{name}.exr")),
            |res, _| vec![[0f32; 3]; res.width() * res.height()],
            |v, pos, (r, g, b, _): (f32, f32, f32, f32)| v[pos.y() * 48 + pos.x()] = [r, g, b],
        )
        .unwrap()
        .layer_data
        .channel_data
        .pixels
    };
    let mean = |px: &[[f32; 3]]| {
        px.iter()
            .map(|p| 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2])
            .sum::<f32>()
            / px.len() as f32
    };
    let on = render("on", &[]);
    let flags = render("flags", &["--no-sun", "--no-sky"]);
    let file = render("file", &["--config", config.to_str().unwrap()]);
    assert!(flags == file, "the flags and the settings file differ");
    let (on, off) = (mean(&on), mean(&flags));
    assert!(on > 100.0, "a sunlit noon: mean {on} nits");
    assert!(off < 0.02 * on, "lights off: mean {off} nits against {on}");
}

/// The EXR's layout, checked against the ephemeris (`--json`, itself held to PyEphem in
/// hikari-math's tests): a low morning sun brightens the sky most in its own column (columns
/// from north clockwise), above the horizon (rows from the zenith down); below the horizon the
/// ground is its albedo (the clear weather's 0.1) lit by the sun and the sky, at least the
/// direct sun's share albedo · E / π.
#[test]
fn sky_exr_rows_columns_and_ground_follow_the_sun() {
    let dir = tmp("sky-layout");
    let (w, h) = (128usize, 64usize);
    let run = |time: &str| {
        let out = dir.join(format!("{}.exr", time.replace(':', "")));
        let o = hikari(&[
            "sky",
            "--table-quality",
            "0",
            "--width",
            "128",
            "--time",
            time,
            "--json",
            "-o",
            out.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", text(&o));
        let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        let px = exr::prelude::read_first_rgba_layer_from_file(
            &out,
            |res, _| vec![0f32; res.width() * res.height()],
            move |v, p, (r, g, b, _): (f32, f32, f32, f32)| {
                v[p.y() * w + p.x()] = 0.2126 * r + 0.7152 * g + 0.0722 * b
            },
        )
        .unwrap()
        .layer_data
        .channel_data
        .pixels;
        (v, px)
    };

    let (v, px) = run("07:00");
    let (az, el) = (
        v["sun"]["azimuth_deg"].as_f64().unwrap(),
        v["sun"]["elevation_deg"].as_f64().unwrap(),
    );
    assert!(
        (5.0..40.0).contains(&el) && (40.0..110.0).contains(&az),
        "{v}"
    );
    let best = (0..w * h / 2)
        .max_by(|a, b| px[*a].total_cmp(&px[*b]))
        .unwrap();
    let (x, y) = (best % w, best / w);
    let col_az = (x as f64 + 0.5) * 360.0 / w as f64;
    let row_el = 90.0 - (y as f64 + 0.5) * 180.0 / h as f64;
    let px_deg = 360.0 / w as f64;
    assert!(
        (col_az - az).abs() <= 1.5 * px_deg,
        "brightest sky at azimuth {col_az}, the sun at {az}"
    );
    assert!(
        (row_el - el).abs() <= 20.0,
        "brightest sky at elevation {row_el}, the sun at {el}"
    );

    let (v, px) = run("12:30");
    let sun_lux = v["sun"]["illuminance_lux"].as_f64().unwrap() as f32;
    let nadir = &px[(h - 1) * w..];
    let direct_share = 0.1 * sun_lux / std::f32::consts::PI;
    for (x, l) in nadir.iter().enumerate() {
        assert!(
            (0.95 * direct_share..1.5 * direct_share).contains(l),
            "ground at column {x}: {l} nits, the direct sun alone gives {direct_share}"
        );
    }
}

/// `--color-space rec709` runs the same sky with Bruneton's Rec.709 coefficients (the talk's
/// comparison): still a blue noon sky, another SH than the LMS Rayleigh default.
#[test]
fn sky_runs_in_either_colour_space() {
    let dir = tmp("sky-space");
    let run = |space: &str| {
        let out = dir.join(format!("{space}.exr"));
        let o = hikari(&[
            "sky",
            "--table-quality",
            "0",
            "--width",
            "16",
            "--color-space",
            space,
            "--json",
            "-o",
            out.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", text(&o));
        let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        assert_eq!(v["color_space"], space);
        let sh0: Vec<f64> = v["sh"][0]
            .as_array()
            .unwrap()
            .iter()
            .map(|c| c.as_f64().unwrap())
            .collect();
        assert!(sh0[2] > sh0[0], "{space}: a blue sky, {v}");
        sh0
    };
    assert_ne!(run("lms_rayleigh"), run("rec709"));
}

/// The soak's CI version: two cycles (the first the warm-up) through the live path, with a
/// NaN written each cycle; memory flat, outputs finite. The 10,000-frame run is in
/// docs/reliability.md.
#[test]
fn bench_soak_keeps_memory_flat_through_the_live_path() {
    let o = hikari(&[
        "bench", "soak", "--scene", "boxes", "--width", "16", "--height", "12", "--frames", "128",
        "--cycle", "64", "--poison", "--preset", "low", "--json",
    ]);
    assert!(o.status.success(), "{}", text(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["flat"], true, "{v}");
    assert_eq!(v["samples"].as_array().unwrap().len(), 2, "{v}");
    assert_eq!(v["poisoned"], 2, "{v}");
    for s in v["samples"].as_array().unwrap() {
        assert!(s["resident_mb"].as_f64().unwrap() > 10.0, "{v}");
    }
    let switches = v["switches"].as_array().unwrap();
    for t in ["taa", "ray_traced_gi", "exposure"] {
        assert!(switches.iter().any(|s| s == t), "`{t}` not switched: {v}");
    }
}

/// `hikari bc6h`: an EXR (the sky's) to a DDS file as the DDS specification lays it out (magic,
/// a DX10 extension header naming DXGI_FORMAT_BC6H_UF16 = 95, then 16 bytes a 4x4 block), the
/// GPU's blocks equal to the CPU twin's, and the error printed.
#[test]
fn bc6h_writes_a_dx10_dds_and_its_error() {
    let dir = tmp("bc6h");
    let exr = dir.join("sky.exr");
    let o = hikari(&["sky", "-o", exr.to_str().unwrap(), "--width", "64"]);
    assert!(o.status.success(), "{}", text(&o));
    let gpu = dir.join("gpu.dds");
    let o = hikari(&["bc6h", exr.to_str().unwrap(), "-o", gpu.to_str().unwrap()]);
    let t = text(&o);
    assert!(o.status.success(), "{t}");
    assert!(t.contains("error against the input: RMS of log2"), "{t}");
    let bytes = std::fs::read(&gpu).unwrap();
    let u32_at = |i: usize| u32::from_le_bytes(bytes[i..i + 4].try_into().unwrap());
    assert_eq!(&bytes[0..4], b"DDS ");
    assert_eq!((u32_at(12), u32_at(16)), (32, 64), "height, width");
    assert_eq!(&bytes[84..88], b"DX10");
    assert_eq!(u32_at(128), 95, "DXGI_FORMAT_BC6H_UF16");
    assert_eq!(bytes.len(), 148 + 16 * 16 * 8);
    let cpu = dir.join("cpu.dds");
    let o = hikari(&[
        "bc6h",
        exr.to_str().unwrap(),
        "-o",
        cpu.to_str().unwrap(),
        "--cpu",
    ]);
    assert!(o.status.success(), "{}", text(&o));
    assert_eq!(
        std::fs::read(&cpu).unwrap(),
        bytes,
        "the GPU's blocks are the twin's"
    );
    let o = hikari(&["bc6h", exr.to_str().unwrap(), "-o", "x.png"]);
    assert!(!o.status.success() && text(&o).contains("must be a .dds file"));
}
