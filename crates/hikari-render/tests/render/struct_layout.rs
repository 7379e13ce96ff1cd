//! Rust mirrors of WGSL structs match naga's layout: same field names, offsets and size.

use hikari_render::shader::{self, ShaderLibrary};

#[test]
fn rust_structs_match_wgsl_layouts() {
    let mut lib = ShaderLibrary::new(shader::required_capabilities()).unwrap();
    let mut failures = Vec::new();
    let layouts = hikari_render::layout::all();
    assert!(!layouts.is_empty());
    for l in layouts {
        let module = lib.module(l.shader, &[]).unwrap();
        let mut layouter = naga::proc::Layouter::default();
        layouter.update(module.to_ctx()).unwrap();
        let found = module.types.iter().find(|(_, t)| {
            t.name.as_deref().map(shader::undecorated) == Some(l.name)
                && matches!(t.inner, naga::TypeInner::Struct { .. })
        });
        let Some((handle, ty)) = found else {
            failures.push(format!("{}: no WGSL struct `{}`", l.shader, l.name));
            continue;
        };
        let naga::TypeInner::Struct { members, span } = &ty.inner else {
            unreachable!()
        };
        let wgsl: Vec<(String, usize)> = members
            .iter()
            .map(|m| (m.name.clone().unwrap_or_default(), m.offset as usize))
            .collect();
        let rust: Vec<(String, usize)> =
            l.fields.iter().map(|(n, o)| (n.to_string(), *o)).collect();
        if wgsl != rust {
            failures.push(format!(
                "{}: fields differ\n  WGSL {wgsl:?}\n  Rust {rust:?}",
                l.name
            ));
        }
        if *span as usize != l.size {
            failures.push(format!(
                "{}: WGSL size {} but Rust size {}",
                l.name, span, l.size
            ));
        }
        // A uniform's size must be a multiple of its alignment for arrays and bindings.
        let align = layouter[handle].alignment.round_up(1) as usize;
        if l.size % align != 0 {
            failures.push(format!(
                "{}: size {} not a multiple of alignment {align}",
                l.name, l.size
            ));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
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
    let src = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut found = Vec::new();
    pod_structs_in(&src, &mut found);
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
