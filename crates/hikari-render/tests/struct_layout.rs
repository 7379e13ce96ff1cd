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
