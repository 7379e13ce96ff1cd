//! The WGSL twins: they must parse and validate (naga), and the colour constants written into
//! color.wgsl must equal the exact f64 derivations rounded to f32.
#![allow(clippy::needless_range_loop)]

mod common;

use common::{validate_wgsl as validate, wgsl_module as shader};
use hikari_math::color::Mat3Rows;
use hikari_math::color::primaries::{ACESCG, LMS_RAYLEIGH, REC709, TONEMAP, rgb_to_rgb};
use hikari_math::color::purkinje::PurkinjeMatrices;

#[test]
fn wgsl_twins_validate() {
    let sh = shader("sh.wgsl");
    assert!(sh.starts_with("#define_import_path hikari::sh"));
    validate(&sh, "sh.wgsl");
    let color = shader("color.wgsl");
    assert!(color.starts_with("#define_import_path hikari::color"));
    validate(&color, "color.wgsl");
}

/// Numbers of `const NAME: ... = ...;` in declaration order (columns, as WGSL writes them).
fn const_numbers(src: &str, name: &str) -> Vec<f64> {
    let line = src
        .lines()
        .find(|l| l.starts_with(&format!("const {name}:")))
        .unwrap_or_else(|| panic!("{name} missing"));
    let mut rhs = line[line.find('=').unwrap() + 1..].to_string();
    for ty in ["mat3x3<f32>", "mat3x4<f32>", "vec3<f32>", "vec4<f32>"] {
        rhs = rhs.replace(ty, " ");
    }
    rhs.split(|c: char| !(c.is_ascii_digit() || c == '.' || c == '-' || c == 'e' || c == '+'))
        .filter(|t| !t.is_empty() && t.chars().any(|c| c.is_ascii_digit()))
        .map(|t| {
            t.parse::<f64>()
                .unwrap_or_else(|_| panic!("{name}: bad number {t}"))
        })
        .collect()
}

fn check(src: &str, name: &str, rows: &[[f64; 3]]) {
    let got = const_numbers(src, name);
    let r = rows.len();
    assert_eq!(got.len(), 3 * r, "{name}: {got:?}");
    for c in 0..3 {
        for (row, vals) in rows.iter().enumerate() {
            let want = vals[c];
            let v = got[c * r + row];
            assert!(
                (v - want).abs() <= 1e-7 * want.abs().max(1.0),
                "{name}[{row}][{c}] = {v}, derived {want}"
            );
        }
    }
}

#[test]
fn color_wgsl_constants_match_derivation() {
    let src = shader("color.wgsl");
    let m = |a: Mat3Rows| a;
    check(&src, "REC709_TO_XYZ", &m(REC709.rgb_to_xyz()));
    check(&src, "XYZ_TO_REC709", &m(REC709.xyz_to_rgb()));
    check(&src, "REC709_TO_ACESCG", &rgb_to_rgb(&REC709, &ACESCG));
    check(&src, "ACESCG_TO_REC709", &rgb_to_rgb(&ACESCG, &REC709));
    check(&src, "REC709_TO_TONEMAP", &rgb_to_rgb(&REC709, &TONEMAP));
    check(&src, "TONEMAP_TO_REC709", &rgb_to_rgb(&TONEMAP, &REC709));
    check(
        &src,
        "REC709_TO_LMS_RAYLEIGH",
        &rgb_to_rgb(&REC709, &LMS_RAYLEIGH),
    );
    check(
        &src,
        "LMS_RAYLEIGH_TO_REC709",
        &rgb_to_rgb(&LMS_RAYLEIGH, &REC709),
    );
    let p = PurkinjeMatrices::new();
    check(&src, "PURKINJE_LMSR_FROM_REC709", &p.lmsr_from_rgb);
    check(&src, "PURKINJE_RGB_FROM_LMS_GAIN", &p.rgb_from_lms_gain);
}

#[test]
fn sh_wgsl_constants_match_cpu() {
    let src = shader("sh.wgsl");
    let get = |name: &str| const_numbers(&src, name)[0];
    use hikari_math::sh::basis::*;
    for (name, v) in [
        ("SH_C0", C0),
        ("SH_C1", C1),
        ("SH_C2", C2),
        ("SH_C3", C3),
        ("SH_C4", C4),
    ] {
        assert!((get(name) - v).abs() < 1e-15, "{name}");
    }
    assert_eq!(
        get("SH_DERING_LAMBDA_SCALE") as f32,
        hikari_math::sh::dering::LAMBDA_SCALE
    );
}
