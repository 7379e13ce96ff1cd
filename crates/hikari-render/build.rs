//! Embeds every WGSL file so the binary needs no files at run time and a new shader cannot be
//! forgotten by the validation test. Shared modules live under `shaders/`; a technique's own
//! shaders live beside its Rust code under `src/` (`src/techniques/<name>/`, `src/raster/`).
//! A shader's key is its path under `shaders/`, or under `src/` without the `techniques/`
//! prefix: `common/brdf.wgsl`, `gbuffer/resolve.wgsl`, `raster/setup.wgsl`.

use std::{env, fs, path::Path};

fn collect(dir: &Path, root: &Path, out: &mut Vec<(String, std::path::PathBuf)>) {
    let mut entries: Vec<_> = fs::read_dir(dir)
        .expect("read shader dir")
        .map(|e| e.expect("dir entry").path())
        .collect();
    entries.sort();
    for p in entries {
        if p.is_dir() {
            collect(&p, root, out);
        } else if p.extension().is_some_and(|e| e == "wgsl") {
            let rel = p
                .strip_prefix(root)
                .unwrap()
                .to_string_lossy()
                .replace('\\', "/");
            let key = ["techniques/", "scene/"]
                .iter()
                .find_map(|p| rel.strip_prefix(p))
                .unwrap_or(&rel)
                .to_string();
            out.push((key, p));
        }
    }
}

fn main() {
    let crate_dir = Path::new(&env::var("CARGO_MANIFEST_DIR").unwrap()).to_path_buf();
    let mut files = Vec::new();
    for root in ["shaders", "src"] {
        let root = crate_dir.join(root);
        println!("cargo:rerun-if-changed={}", root.display());
        collect(&root, &root, &mut files);
    }
    files.sort();
    for pair in files.windows(2) {
        assert!(
            pair[0].0 != pair[1].0,
            "two shaders share the key {}: {} and {}",
            pair[0].0,
            pair[0].1.display(),
            pair[1].1.display()
        );
    }
    // (key, path relative to the crate, text)
    let mut src = String::from("pub static SHADER_FILES: &[(&str, &str, &str)] = &[\n");
    for (key, abs) in &files {
        println!("cargo:rerun-if-changed={}", abs.display());
        let rel = abs
            .strip_prefix(&crate_dir)
            .unwrap()
            .to_string_lossy()
            .replace('\\', "/");
        src += &format!(
            "    ({key:?}, {rel:?}, include_str!({:?})),\n",
            abs.display().to_string()
        );
    }
    src += "];\n";
    fs::write(
        Path::new(&env::var("OUT_DIR").unwrap()).join("shader_files.rs"),
        src,
    )
    .unwrap();
}
