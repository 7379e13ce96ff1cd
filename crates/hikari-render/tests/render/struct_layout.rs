//! Rust mirrors of WGSL structs match naga's layout: same field names, offsets and size.

use hikari_render::shader;

#[test]
fn rust_structs_match_wgsl_layouts() {
    let mut lib = shader::library(shader::required_capabilities()).unwrap();
    let layouts = hikari_render::layout::all();
    assert!(!layouts.is_empty());
    let mut failures = Vec::new();
    for l in layouts {
        let module = lib.module(l.shader, &[]).unwrap();
        failures.extend(hikari_render::layout::struct_differences(&l, &module));
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn shared_constants_match_wgsl_values() {
    let files = shader::shader_files().unwrap();
    let constants = hikari_render::layout::constants();
    assert!(constants.len() > 50, "the registry lost its constants");
    let mut failures = Vec::new();
    for c in &constants {
        let Some(file) = files.iter().find(|f| f.path == c.shader) else {
            failures.push(format!("{}: no shader file {}", c.name, c.shader));
            continue;
        };
        failures.extend(hikari_render::layout::constant_difference(c, &file.source));
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn a_changed_constant_is_caught() {
    // The check must see a difference of value and of type, not only a missing name.
    let files = shader::shader_files().unwrap();
    let source = &files
        .iter()
        .find(|f| f.path == "direct_lighting/shade.wgsl")
        .unwrap()
        .source;
    let mut c = hikari_render::layout::constants()
        .into_iter()
        .find(|c| c.name == "LIGHTING_SUN")
        .unwrap();
    assert!(hikari_render::layout::constant_difference(&c, source).is_none());
    let hikari_render::layout::ConstValue::U32(v) = c.value else {
        panic!("LIGHTING_SUN is a u32 flag")
    };
    c.value = hikari_render::layout::ConstValue::U32(v << 1);
    assert!(hikari_render::layout::constant_difference(&c, source).is_some());
    c.value = hikari_render::layout::ConstValue::I32(v as i32);
    assert!(hikari_render::layout::constant_difference(&c, source).is_some());
}

/// `(name, file)` of every scalar constant declared in the files under `dir` whose names end
/// in `ext`, by a line scan: `const NAME: u32 =` in Rust (any visibility), `const NAME` in WGSL.
fn constants_in(dir: &std::path::Path, ext: &str, found: &mut Vec<(String, String)>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            constants_in(&path, ext, found);
            continue;
        }
        if path.extension().is_none_or(|e| e != ext) {
            continue;
        }
        for line in std::fs::read_to_string(&path).unwrap().lines() {
            let line = line.trim_start();
            let line = line
                .strip_prefix("pub(crate) ")
                .or_else(|| line.strip_prefix("pub "))
                .unwrap_or(line);
            let Some(rest) = line.strip_prefix("const ") else {
                continue;
            };
            let name: String = rest
                .chars()
                .take_while(|c| c.is_ascii_uppercase() || c.is_ascii_digit() || *c == '_')
                .collect();
            let typed = rest[name.len()..].trim_start();
            let scalar = ext == "wgsl"
                || ["u32", "i32", "f32"].iter().any(|t| {
                    typed
                        .strip_prefix(':')
                        .is_some_and(|r| r.trim_start().starts_with(t))
                });
            if !name.is_empty() && scalar {
                found.push((name, path.display().to_string()));
            }
        }
    }
}

#[test]
fn every_constant_both_languages_declare_is_registered() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let (mut rust, mut wgsl) = (Vec::new(), Vec::new());
    constants_in(&root.join("src"), "rs", &mut rust);
    constants_in(&root.join("src"), "wgsl", &mut wgsl);
    constants_in(&root.join("shaders"), "wgsl", &mut wgsl);
    assert!(
        rust.iter().any(|(n, _)| n == "LIGHTING_SUN"),
        "the Rust scan missed LIGHTING_SUN"
    );
    assert!(
        wgsl.iter().any(|(n, _)| n == "LIGHTING_SUN"),
        "the WGSL scan missed LIGHTING_SUN"
    );
    let registered: Vec<&str> = hikari_render::layout::constants()
        .iter()
        .map(|c| c.name)
        .collect();
    let mut missing: Vec<String> = rust
        .iter()
        .filter(|(n, _)| wgsl.iter().any(|(w, _)| w == n))
        .filter(|(n, _)| !registered.contains(&n.as_str()))
        .filter(|(n, _)| !hikari_render::layout::UNRELATED_SAME_NAMES.contains(&n.as_str()))
        .map(|(n, file)| format!("{n} ({file})"))
        .collect();
    missing.sort();
    missing.dedup();
    assert!(
        missing.is_empty(),
        "constants declared in Rust and WGSL without a value check; add them to \
         layout::constants() (or, if they mean different things, to UNRELATED_SAME_NAMES): {}",
        missing.join(", ")
    );
}

/// Names of the `#[repr(C)]` structs deriving `Pod` in the Rust sources under `dir`: the
/// structs the crate hands to the GPU as bytes, each of which needs a WGSL twin.
fn pod_structs_in(dir: &std::path::Path, found: &mut Vec<(String, String)>) {
    let mut entries: Vec<_> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.unwrap().path())
        .collect();
    entries.sort();
    for path in entries {
        if path.is_dir() {
            pod_structs_in(&path, found);
            continue;
        }
        if path.extension().is_none_or(|e| e != "rs") {
            continue;
        }
        let text = std::fs::read_to_string(&path).unwrap();
        let lines: Vec<&str> = text.lines().map(str::trim).collect();
        for (i, line) in lines.iter().enumerate() {
            if !line.starts_with("#[repr(C") {
                continue;
            }
            // The attributes up to the item, then the item itself.
            let mut pod = false;
            for item in &lines[i + 1..] {
                if item.starts_with("#[") || item.starts_with("///") || item.starts_with("//") {
                    pod |= item.starts_with("#[derive") && item.contains("Pod");
                    continue;
                }
                let name = item
                    .split_once("struct ")
                    .map(|(_, rest)| {
                        rest.split(|c: char| !(c.is_alphanumeric() || c == '_'))
                            .next()
                            .unwrap_or_default()
                            .to_string()
                    })
                    .filter(|n| !n.is_empty());
                if let (true, Some(name)) = (pod, name) {
                    found.push((name, path.display().to_string()));
                }
                break;
            }
        }
    }
}

#[test]
fn every_pod_struct_of_the_crate_is_registered() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut found = Vec::new();
    pod_structs_in(&root.join("src"), &mut found);
    // A Pod struct the engine gains must be registered too.
    pod_structs_in(&root.join("../hikari-gpu/src"), &mut found);
    // The scan itself must see the structs we know of, or it proves nothing.
    for known in ["View", "RasterParams", "ShadowParams", "CopyParams"] {
        assert!(
            found.iter().any(|(n, _)| n == known),
            "the source scan missed `{known}`: {found:?}"
        );
    }
    let registered: Vec<&str> = hikari_render::layout::all()
        .iter()
        .map(|l| l.name)
        .collect();
    let missing: Vec<String> = found
        .iter()
        .filter(|(n, _)| !registered.contains(&n.as_str()))
        .map(|(n, file)| format!("{n} ({file})"))
        .collect();
    assert!(
        missing.is_empty(),
        "#[repr(C)] Pod structs without a layout check; add them to layout::all(): {}",
        missing.join(", ")
    );
}
