//! Writes each preset's full settings TOML into the settings fuzz target's seed corpus:
//! `cargo run -p hikari-fuzz --example preset_seeds [DIR]` (default fuzz/corpus/settings_toml).

use hikari_render::{Preset, Settings};

fn main() {
    let dir = std::env::args().nth(1).unwrap_or_else(|| {
        concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../fuzz/corpus/settings_toml"
        )
        .into()
    });
    for p in Preset::ALL {
        let text = format!("preset = \"{p}\"\n{}", Settings::preset(p).to_toml());
        let path = std::path::Path::new(&dir).join(format!("preset_{p}.toml"));
        std::fs::write(&path, text).expect("write the seed");
        println!("wrote {}", path.display());
    }
}
