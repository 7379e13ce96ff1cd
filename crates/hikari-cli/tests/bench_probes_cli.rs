//! `hikari bench probes` on the CPU driver at a tiny size: it runs, names the passes the issue
//! asks for with their counts, as a table and as JSON, and refuses bad sizes by name.

mod common;

use std::process::{Command, Output};

use common::{text, tmp};

/// `hikari` with the bake cache in `cache` (never the user's own).
fn hikari_cached(cache: &std::path::Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_hikari"))
        .args(args)
        .env("XDG_CACHE_HOME", cache)
        .output()
        .expect("run hikari")
}

const RUN: [&str; 17] = [
    "bench",
    "probes",
    "--scene",
    "boxes",
    "--width",
    "64",
    "--height",
    "48",
    "--frames",
    "2",
    "--warmup",
    "1",
    "--grid-tiles",
    "3",
    "--mesh-probes",
    "100",
    "--set=ray_traced_gi.enabled=false",
];

#[test]
fn bench_probes_times_the_relight_and_the_lookup_on_their_own() {
    let cache = tmp("bench-probes");
    let o = hikari_cached(&cache, &RUN);
    let t = text(&o);
    assert!(o.status.success(), "{t}");
    let out = String::from_utf8_lossy(&o.stdout);
    let line = |pass: &str| {
        out.lines()
            .find(|l| l.starts_with(&format!("{pass} ")))
            .unwrap_or_else(|| panic!("no row for {pass}: {t}"))
            .to_string()
    };
    // 3 tiles of 16x16x3 probes; the mesh as asked; every pixel of 64x48.
    assert!(
        line("irradiance_probes.relight_grid").contains("2304 probes, 3 tiles"),
        "{t}"
    );
    assert!(
        line("irradiance_probes.relight_mesh").contains("100 probes, 0 tiles"),
        "{t}"
    );
    assert!(
        line("irradiance_probes.lookup").contains("3072 pixels"),
        "{t}"
    );
    line("irradiance_probes.relight");
    line("direct_lighting.shade");

    let mut args = RUN.to_vec();
    args.push("--json");
    let o = hikari_cached(&cache, &args);
    assert!(o.status.success(), "{}", text(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["benchmark"], "probes");
    assert_eq!(
        (v["width"].as_u64(), v["height"].as_u64()),
        (Some(64), Some(48))
    );
    let passes = v["passes"].as_array().unwrap();
    let pass = |name: &str| {
        passes
            .iter()
            .find(|p| p["name"] == name)
            .unwrap_or_else(|| panic!("no {name} in {passes:?}"))
    };
    let grid = pass("irradiance_probes.relight_grid");
    assert_eq!(grid["counts"]["probes"], 2304);
    assert_eq!(grid["counts"]["tiles"], 3);
    // 64 probes a workgroup.
    assert_eq!(grid["counts"]["workgroups"], 36);
    assert_eq!(
        pass("irradiance_probes.relight_mesh")["counts"]["workgroups"],
        2
    );
    assert_eq!(
        pass("irradiance_probes.lookup")["counts"]["pixels"],
        64 * 48
    );
    if v["timestamps"] == true {
        for p in passes {
            let us = &p["gpu_us"];
            let (med, min, max) = (
                us["median"].as_f64().unwrap(),
                us["min"].as_f64().unwrap(),
                us["max"].as_f64().unwrap(),
            );
            assert!(min <= med && med <= max && min >= 0.0, "{p}");
        }
    }
}

#[test]
fn bench_probes_refuses_bad_sizes_by_name() {
    for (args, want) in [
        (
            &["bench", "probes", "--grid-tiles", "0"][..],
            "--grid-tiles",
        ),
        (
            &["bench", "probes", "--grid-tiles", "5000"][..],
            "--grid-tiles",
        ),
        (
            &["bench", "probes", "--mesh-probes", "0"][..],
            "--mesh-probes",
        ),
        (&["bench", "probes", "--frames", "0"][..], "--frames"),
    ] {
        let o = common::hikari(args);
        let t = text(&o);
        assert!(!o.status.success(), "{args:?}: {t}");
        assert!(t.contains(want) && !t.contains("panicked"), "{args:?}: {t}");
    }
}
