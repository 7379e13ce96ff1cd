//! Every WGSL file composes and validates with naga; no GPU needed.

use hikari_render::shader;

#[test]
fn every_entry_shader_composes_and_validates() {
    // What the renderer requires of every adapter (64-bit atomics for the rasteriser).
    let caps = shader::required_capabilities();
    let mut lib = shader::library(caps).expect("modules load");
    let entries = lib.entry_shaders();
    assert!(entries.len() >= 5, "found only {entries:?}");
    let mut failures = Vec::new();
    for path in &entries {
        match lib.module(path, &[]) {
            Ok(module) => {
                if let Err(e) = shader::validate(path, &module, caps) {
                    failures.push(e.to_string());
                }
                let sets = lib.binding_sets(path);
                if let Err(e) = hikari_render::pipeline::reflect_groups(path, &module, &sets) {
                    failures.push(e.to_string());
                }
            }
            Err(e) => failures.push(e.to_string()),
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n\n"));
}

#[test]
fn the_rasteriser_variants_compose_and_validate() {
    // The raster kernels are also built with DEPTH_ONLY (shadow maps) and ALPHA_TEST
    // (cut-outs), alone and together; the alpha variants bind the scene's attributes,
    // materials, colour textures and a sampler after the rest (0 to 12, no gaps).
    use naga_oil::compose::ShaderDefValue::Bool;
    let caps = shader::required_capabilities();
    let mut lib = shader::library(caps).expect("modules load");
    let variants = [
        vec![("DEPTH_ONLY", Bool(true))],
        vec![("ALPHA_TEST", Bool(true))],
        vec![("DEPTH_ONLY", Bool(true)), ("ALPHA_TEST", Bool(true))],
    ];
    for defs in &variants {
        for path in ["raster/triangles.wgsl", "raster/tiles.wgsl"] {
            let module = lib.module(path, defs).unwrap();
            shader::validate(path, &module, caps).unwrap();
            let slots = hikari_render::pipeline::reflect_bindings(path, &module).unwrap();
            let alpha = defs.iter().any(|(k, _)| *k == "ALPHA_TEST");
            if alpha {
                assert_eq!(slots.len(), 13, "{path} {defs:?}");
            }
        }
    }
}

#[test]
fn every_wgsl_file_on_disk_is_embedded() {
    // Shared modules under shaders/, each technique's own beside its code under src/; keys
    // as build.rs gives them (src/techniques/x/y.wgsl is x/y.wgsl, src/scene/x/y.wgsl x/y.wgsl).
    let crate_dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut on_disk = Vec::new();
    for root in ["shaders", "src"] {
        let root = crate_dir.join(root);
        let mut stack = vec![root.clone()];
        while let Some(dir) = stack.pop() {
            for e in std::fs::read_dir(dir).unwrap() {
                let p = e.unwrap().path();
                if p.is_dir() {
                    stack.push(p);
                } else if p.extension().is_some_and(|x| x == "wgsl") {
                    let rel = p
                        .strip_prefix(&root)
                        .unwrap()
                        .to_string_lossy()
                        .replace('\\', "/");
                    let key = ["techniques/", "scene/"]
                        .iter()
                        .find_map(|p| rel.strip_prefix(p))
                        .unwrap_or(&rel);
                    on_disk.push(key.to_string());
                }
            }
        }
    }
    on_disk.sort();
    let mut embedded: Vec<String> = shader::shader_files()
        .unwrap()
        .into_iter()
        .map(|f| f.path)
        .collect();
    embedded.sort();
    assert_eq!(on_disk, embedded);
}

#[test]
fn a_broken_shader_is_reported_with_its_path() {
    // The composer must turn a WGSL error into an error naming the file, not a panic.
    let mut composer = naga_oil::compose::Composer::default();
    let r = composer.make_naga_module(naga_oil::compose::NagaModuleDescriptor {
        source: "fn f() -> f32 { return 1 + ; }",
        file_path: "broken.wgsl",
        ..Default::default()
    });
    let e = r.unwrap_err();
    assert!(e.emit_to_string(&composer).contains("broken.wgsl"));
}

#[test]
fn bindings_outside_group_zero_are_refused() {
    let module = naga::front::wgsl::parse_str(
        "@group(1) @binding(0) var<uniform> x: vec4<f32>;\n@compute @workgroup_size(1) fn main() { _ = x; }",
    )
    .unwrap();
    let e = hikari_render::pipeline::reflect_bindings("g1.wgsl", &module).unwrap_err();
    assert!(e.to_string().contains("@group(1)"), "{e}");
    assert!(e.to_string().contains("binding sets"), "{e}");
}

/// A shared module's bindings get a group of their own in each pipeline that imports it, so
/// the deferred lighting's own bindings and the shadow lookup's cannot collide.
#[test]
fn shared_modules_bind_in_groups_of_their_own() {
    let caps = shader::required_capabilities();
    let mut lib = shader::library(caps).unwrap();
    assert_eq!(
        lib.binding_sets("direct_lighting/shade.wgsl"),
        [
            "brdf_tables",
            "clouds",
            "irradiance_probes",
            "sky",
            "sky_ambient",
            "sun_shadows"
        ]
    );
    assert!(lib.binding_sets("taa/resolve.wgsl").is_empty());
    let module = lib.module("direct_lighting/shade.wgsl", &[]).unwrap();
    let groups = hikari_render::pipeline::reflect_groups(
        "direct_lighting/shade.wgsl",
        &module,
        &lib.binding_sets("direct_lighting/shade.wgsl"),
    )
    .unwrap();
    assert_eq!(groups.len(), 7);
    let names: Vec<&str> = groups[6]
        .iter()
        .map(|s| shader::undecorated(&s.name))
        .collect();
    assert_eq!(names, ["shadow", "shadow_map", "shadow_sampler"]);
}

#[test]
fn gaps_in_bindings_are_refused() {
    let module = naga::front::wgsl::parse_str(
        "@group(0) @binding(1) var<uniform> x: vec4<f32>;\n@compute @workgroup_size(1) fn main() { _ = x; }",
    )
    .unwrap();
    assert!(hikari_render::pipeline::reflect_bindings("gap.wgsl", &module).is_err());
}

#[test]
fn bvh_stack_size_matches_the_kernel() {
    // The Rust side refuses scenes deeper than the kernel's stack; the two must agree. naga
    // folds the constant into the array type, so read it from the module's source.
    let files = shader::shader_files().unwrap();
    let src = &files
        .iter()
        .find(|f| f.path == "bvh/traverse.wgsl")
        .unwrap()
        .source;
    let line = src
        .lines()
        .find(|l| l.starts_with("const BVH_STACK_SIZE: u32 ="))
        .expect("BVH_STACK_SIZE in hikari::bvh");
    let value: u32 = line
        .split('=')
        .nth(1)
        .unwrap()
        .trim()
        .trim_end_matches(';')
        .trim_end_matches('u')
        .parse()
        .unwrap();
    assert_eq!(value, hikari_render::scene::bvh_trace::STACK_SIZE);
}
