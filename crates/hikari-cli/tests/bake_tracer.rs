//! `hikari bake --tracer`: the GPU tracer (forced, so it runs on lavapipe too) and the CPU one
//! bake the same probes, with the same rays, to within rounding; the summary says which ran.

mod common;

use std::f64::consts::PI;

use common::{hikari, text, tmp};

fn json_of(args: &[&str]) -> serde_json::Value {
    let o = hikari(args);
    assert!(o.status.success(), "{}", text(&o));
    serde_json::from_slice(&o.stdout).unwrap_or_else(|e| panic!("{e}: {}", text(&o)))
}

/// Largest |Y_i| of the real L2 SH basis, per coefficient.
fn max_abs_y() -> [f64; 9] {
    let s = 1.0 / (2.0 * PI.sqrt());
    let l1 = 3f64.sqrt() * s;
    let l2 = 15f64.sqrt() / (4.0 * PI.sqrt());
    [s, l1, l1, l1, l2, l2, 5f64.sqrt() * s, l2, l2]
}

#[test]
fn gpu_and_cpu_tracers_bake_the_same_probes() {
    let dir = tmp("tracer");
    let mut summaries = Vec::new();
    let mut probes = Vec::new();
    for tracer in ["cpu", "gpu"] {
        let file = dir.join(format!("{tracer}.hikprobe"));
        let f = file.to_str().unwrap();
        let s = json_of(&[
            "bake", "--scene", "boxes", "--tracer", tracer, "-o", f, "--json",
        ]);
        assert_eq!(s["tracer"], tracer, "{s}");
        assert_eq!(s["adapter"].is_string(), tracer == "gpu", "{s}");
        assert!(s["rays_per_second"].as_f64().unwrap() > 0.0);
        summaries.push(s);
        let listed = json_of(&["probes", "--scene", "boxes", "--bake", f, "--json"]);
        probes.push(listed["probes"].as_array().unwrap().clone());
    }
    assert_eq!(summaries[0]["probes"], summaries[1]["probes"]);
    let (cpu_rays, gpu_rays) = (
        summaries[0]["rays"].as_u64().unwrap(),
        summaries[1]["rays"].as_u64().unwrap(),
    );
    // Ray counts differ only where a hit flips between the tracers (2 bounce rays each).
    assert!(
        cpu_rays.abs_diff(gpu_rays) <= cpu_rays / 1000,
        "{cpu_rays} vs {gpu_rays}"
    );
    // Three rays' worth of SH weight (2048 rays a probe) per coefficient, as in
    // hikari-render's tests/probe_bake_gpu.rs.
    let tol = max_abs_y().map(|y| 3.0 * 4.0 * PI / 2048.0 * y + 1e-4);
    assert_eq!(probes[0].len(), probes[1].len());
    for (c, g) in probes[0].iter().zip(&probes[1]) {
        assert_eq!(c["position"], g["position"]);
        assert_eq!(c["interior"], g["interior"]);
        let sky = |p: &serde_json::Value| -> Vec<f64> {
            p["sky_visibility"]
                .as_array()
                .unwrap()
                .iter()
                .map(|v| v.as_f64().unwrap())
                .collect()
        };
        let bounced = |p: &serde_json::Value| -> Vec<Vec<f64>> {
            p["bounced_sky_visibility"]
                .as_array()
                .unwrap()
                .iter()
                .map(|t| {
                    t.as_array()
                        .unwrap()
                        .iter()
                        .map(|v| v.as_f64().unwrap())
                        .collect()
                })
                .collect()
        };
        let (sc, sg, bc, bg) = (sky(c), sky(g), bounced(c), bounced(g));
        for (i, t) in tol.iter().enumerate() {
            assert!((sc[i] - sg[i]).abs() <= *t, "{c}\n{g}");
            for k in 0..3 {
                assert!((bc[i][k] - bg[i][k]).abs() <= *t, "{c}\n{g}");
            }
        }
    }
}

#[test]
fn an_unknown_tracer_is_named() {
    let o = hikari(&["bake", "--scene", "boxes", "--tracer", "quantum"]);
    assert!(!o.status.success());
    let t = text(&o);
    assert!(t.contains("quantum") && t.contains("--tracer"), "{t}");
}
