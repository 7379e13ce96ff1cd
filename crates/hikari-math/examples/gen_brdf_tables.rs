//! Writes `crates/hikari-render/shaders/common/brdf_tables.wgsl` (`hikari::brdf_tables`) from
//! hikari-math's directional albedo tables ([`hikari_math::brdf::albedo`]), atomically (temp
//! file + rename). `crates/hikari-render/tests/brdf_tables.rs` fails when the committed file
//! differs from what this writes.
//!
//! Run: `cargo run -p hikari-math --example gen_brdf_tables`

use hikari_math::brdf::albedo::AlbedoTables;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../hikari-render/shaders/common/brdf_tables.wgsl"
    );
    let text = AlbedoTables::compute().to_wgsl();
    let tmp = format!("{path}.tmp");
    std::fs::write(&tmp, text)?;
    std::fs::rename(&tmp, path)?;
    println!("wrote {path}");
    Ok(())
}
