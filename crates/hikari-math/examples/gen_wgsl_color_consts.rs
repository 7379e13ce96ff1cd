//! Regenerates the constant block of `crates/hikari-render/shaders/common/color.wgsl` from the
//! exact f64 derivations (between the BEGIN/END GENERATED markers). A test in
//! `tests/wgsl_consts.rs` fails when the file and the derivation disagree.
//!
//! Run: `cargo run -p hikari-math --example gen_wgsl_color_consts`

use hikari_math::color::Mat3Rows;
use hikari_math::color::primaries::{ACESCG, LMS_RAYLEIGH, REC709, TONEMAP, rgb_to_rgb};
use hikari_math::color::purkinje::PurkinjeMatrices;

fn mat3(name: &str, m: &Mat3Rows) -> String {
    let cols: Vec<String> = (0..3)
        .map(|c| {
            format!(
                "vec3<f32>({:e}, {:e}, {:e})",
                m[0][c] as f32, m[1][c] as f32, m[2][c] as f32
            )
        })
        .collect();
    format!(
        "const {name}: mat3x3<f32> = mat3x3<f32>({});",
        cols.join(", ")
    )
}

fn mat3x4(name: &str, m: &[[f64; 3]; 4]) -> String {
    let cols: Vec<String> = (0..3)
        .map(|c| {
            format!(
                "vec4<f32>({:e}, {:e}, {:e}, {:e})",
                m[0][c] as f32, m[1][c] as f32, m[2][c] as f32, m[3][c] as f32
            )
        })
        .collect();
    format!(
        "const {name}: mat3x4<f32> = mat3x4<f32>({});",
        cols.join(", ")
    )
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let p = PurkinjeMatrices::new();
    let lines = [
        "// Linear Rec.709 (D65) <-> CIE XYZ.".to_string(),
        mat3("REC709_TO_XYZ", &REC709.rgb_to_xyz()),
        mat3("XYZ_TO_REC709", &REC709.xyz_to_rgb()),
        "// Rec.709 <-> ACEScg, Bradford D65 <-> ACES white.".to_string(),
        mat3("REC709_TO_ACESCG", &rgb_to_rgb(&REC709, &ACESCG)),
        mat3("ACESCG_TO_REC709", &rgb_to_rgb(&ACESCG, &REC709)),
        "// Rec.709 <-> the tonemapping space (ACEScg, red x 0.75), Bradford-adapted.".to_string(),
        mat3("REC709_TO_TONEMAP", &rgb_to_rgb(&REC709, &TONEMAP)),
        mat3("TONEMAP_TO_REC709", &rgb_to_rgb(&TONEMAP, &REC709)),
        "// Rec.709 <-> the LMS Rayleigh space (both D65).".to_string(),
        mat3(
            "REC709_TO_LMS_RAYLEIGH",
            &rgb_to_rgb(&REC709, &LMS_RAYLEIGH),
        ),
        mat3(
            "LMS_RAYLEIGH_TO_REC709",
            &rgb_to_rgb(&LMS_RAYLEIGH, &REC709),
        ),
        "// Purkinje shift matrices (lmsr_from_rec709 4x3, rgb_from_lms_gain 3x3).".to_string(),
        mat3x4("PURKINJE_LMSR_FROM_REC709", &p.lmsr_from_rgb),
        mat3("PURKINJE_RGB_FROM_LMS_GAIN", &p.rgb_from_lms_gain),
    ];
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../hikari-render/shaders/common/color.wgsl"
    );
    let text = std::fs::read_to_string(path)?;
    let begin = text.find("// BEGIN GENERATED").ok_or("no BEGIN marker")?;
    let begin = begin + text[begin..].find('\n').ok_or("no newline")? + 1;
    let end = text.find("// END GENERATED").ok_or("no END marker")?;
    let out = format!("{}{}\n{}", &text[..begin], lines.join("\n"), &text[end..]);
    std::fs::write(path, out)?;
    println!("updated {path}");
    Ok(())
}
