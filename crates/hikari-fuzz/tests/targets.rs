//! Keeps the fuzz targets alive in `./x test`: each runs over its seed corpus
//! (fuzz/corpus/<target>/), the regression inputs (tests/regressions/<target>/), and a few
//! hundred seeded mutations of them. A panic in a target fails its test; the message names the
//! seed and the mutation, which `mutated_input` rebuilds.

use std::path::{Path, PathBuf};
use std::time::Instant;

use hikari_fuzz::TARGETS;
use hikari_fuzz::mutate::{Rng, mutate};

/// Mutations per target; the whole file runs in a few seconds in the dev profile.
const MUTATIONS: usize = 1500;

/// A file's name and bytes.
type Named = (String, Vec<u8>);

fn files(dir: &Path) -> Vec<Named> {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return Vec::new();
    };
    let mut out: Vec<Named> = entries
        .filter_map(|e| e.ok())
        .map(|e| e.path())
        .filter(|p| p.is_file())
        .map(|p| {
            let name = p.file_name().unwrap().to_string_lossy().into_owned();
            (name, std::fs::read(&p).unwrap())
        })
        .collect();
    out.sort();
    out
}

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// The seeds of `target` (mutated below) and its regression inputs (run as they are: some
/// are large, and mutations of them could ask for what they were refused).
fn inputs(target: &str) -> (Vec<Named>, Vec<Named>) {
    let seeds = files(&root().join("fuzz/corpus").join(target));
    let regressions = files(
        &Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("tests/regressions")
            .join(target),
    );
    (seeds, regressions)
}

fn seed_of(target: &str) -> u64 {
    target.bytes().fold(0xcbf2_9ce4_8422_2325u64, |h, b| {
        (h ^ b as u64).wrapping_mul(0x100_0000_01b3)
    })
}

/// Runs `target` on every input and `MUTATIONS` mutations, reporting the input of a panic.
fn exercise(name: &str) {
    let target = TARGETS.iter().find(|(n, _)| *n == name).unwrap().1;
    let (inputs, regressions) = inputs(name);
    assert!(!inputs.is_empty(), "fuzz/corpus/{name} has no seeds");
    let start = Instant::now();
    for (file, data) in inputs.iter().chain(&regressions) {
        if std::panic::catch_unwind(|| target(data)).is_err() {
            panic!("target {name} panicked on {file}");
        }
    }
    let datas: Vec<Vec<u8>> = inputs.iter().map(|(_, d)| d.clone()).collect();
    let mut rng = Rng::new(seed_of(name));
    for i in 0..MUTATIONS {
        let pick = rng.below(datas.len());
        let input = mutate(&mut rng, &datas[pick], &datas);
        if std::panic::catch_unwind(|| target(&input)).is_err() {
            let path = std::env::temp_dir().join(format!("hikari-fuzz-{name}-{i}.bin"));
            let _ = std::fs::write(&path, &input);
            panic!(
                "target {name} panicked on mutation {i} of {} (input written to {})",
                inputs[pick].0,
                path.display()
            );
        }
    }
    eprintln!(
        "{name}: {} inputs and {MUTATIONS} mutations in {:.2} s",
        inputs.len() + regressions.len(),
        start.elapsed().as_secs_f64()
    );
}

#[test]
fn gltf() {
    exercise("gltf");
}

#[test]
fn glb() {
    exercise("glb");
}

#[test]
fn gltf_extras() {
    exercise("gltf_extras");
}

#[test]
fn settings_toml() {
    exercise("settings_toml");
}

#[test]
fn cube() {
    exercise("cube");
}

#[test]
fn lut_strip_png() {
    exercise("lut_strip_png");
}

#[test]
fn probe_bake() {
    exercise("probe_bake");
}

#[test]
fn every_target_has_a_test_and_a_cargo_fuzz_target() {
    let tests = include_str!("targets.rs");
    for (name, _) in TARGETS {
        assert!(
            tests.contains(&format!("exercise(\"{name}\")")),
            "no test runs target {name}"
        );
        let path = root().join("fuzz/fuzz_targets").join(format!("{name}.rs"));
        let text =
            std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        assert!(
            text.contains(&format!("hikari_fuzz::{name}(")),
            "{} does not call hikari_fuzz::{name}",
            path.display()
        );
    }
}

/// The valid seeds are accepted, so the targets reach past the first checks: a reader that
/// began refusing everything would pass every other test here.
#[test]
fn valid_seeds_load() {
    use hikari_scene::gltf::{GltfOptions, load_slice};
    for file in ["cube_data_uri.gltf", "cube.glb", "quantized_sparse.gltf"] {
        let data = std::fs::read(root().join("fuzz/corpus/gltf").join(file)).unwrap();
        let loaded = load_slice(&data, None, &GltfOptions::default())
            .unwrap_or_else(|e| panic!("{file}: {e}"));
        assert!(!loaded.scene.meshes.is_empty(), "{file}");
    }
    let data = std::fs::read(root().join("fuzz/corpus/gltf_extras/marked_nodes.gltf")).unwrap();
    assert!(
        !hikari_bake::volumes::gltf_volumes_from_bytes(&data)
            .unwrap()
            .is_empty()
    );
    assert!(
        !hikari_bake::reflection_probes::gltf_reflection_probes_from_bytes(&data)
            .unwrap()
            .is_empty()
    );
    for p in ["identity_strip_2048.png", "warm_strip_1024.png"] {
        use hikari_render::techniques::tonemap::lut_strip;
        let data = std::fs::read(root().join("fuzz/corpus/lut_strip_png").join(p)).unwrap();
        let img = lut_strip::decode_png(&data, p).unwrap();
        lut_strip::extract(&img, p).unwrap_or_else(|e| panic!("{e}"));
    }
    for c in ["identity_2.cube", "size_3_domain.cube"] {
        let text = std::fs::read_to_string(root().join("fuzz/corpus/cube").join(c)).unwrap();
        hikari_render::techniques::tonemap::cube::CubeLut::parse(&text, c).unwrap();
    }
    for b in [
        "empty.hkprobe",
        "mesh_only.hkprobe",
        "mesh_checkpoint.hkprobe",
    ] {
        let data = std::fs::read(root().join("fuzz/corpus/probe_bake").join(b)).unwrap();
        let key = hikari_probes::SceneKey(std::array::from_fn(|i| i as u8));
        hikari_probes::decode(&data, &key).unwrap_or_else(|e| panic!("{b}: {e}"));
    }
    for t in ["config.example.toml", "overrides.toml", "preset_low.toml"] {
        let text =
            std::fs::read_to_string(root().join("fuzz/corpus/settings_toml").join(t)).unwrap();
        let (file, _) = text.split_once('\0').unwrap_or((&text, ""));
        let mut table: toml::Table = file.parse().unwrap();
        for k in ["scene", "camera", "time", "width", "height"] {
            table.remove(k);
        }
        hikari_render::Settings::from_toml(None, table, &[]).unwrap_or_else(|e| panic!("{t}: {e}"));
    }
}

/// A 16000x16000 greyscale PNG header in 60 bytes: the image crate's own limit (512 MiB)
/// admits its 256 MB, but the 8-bit RGBA copy would be 1 GB. Refused from the header.
#[test]
fn a_png_claiming_too_many_pixels_is_refused_before_decoding() {
    use hikari_render::techniques::tonemap::lut_strip;
    let name = "grey_16000x16000_header.png";
    let data = std::fs::read(
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("tests/regressions/lut_strip_png")
            .join(name),
    )
    .unwrap();
    let Err(e) = lut_strip::decode_png(&data, name) else {
        panic!("accepted")
    };
    assert!(e.to_string().contains("16000x16000"), "{e}");
}

/// One 1024x1024 image (4 MB as RGBA8) named by 1100 textures, in 16 kB: each texture copies
/// its image, so this asked for 4.6 GB. Refused before any copy.
#[test]
fn textures_multiplying_one_image_are_refused_before_copying() {
    let name = "one_image_1100_textures.gltf";
    let data = std::fs::read(
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("tests/regressions/gltf")
            .join(name),
    )
    .unwrap();
    let options = hikari_scene::gltf::GltfOptions::default();
    let Err(e) = hikari_scene::gltf::load_slice_unguarded(&data, None, &options) else {
        panic!("accepted")
    };
    assert!(e.to_string().contains("1100 textures"), "{e}");
}

/// Found by the `glb` fuzzer: an image in a buffer view without `mimeType` made the `gltf`
/// crate's `Image::source` unwrap `None`. Now an error naming the image.
#[test]
fn an_image_view_without_a_mime_type_is_an_error() {
    let data = std::fs::read(
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("tests/regressions/glb/image_view_without_mime_type.glb"),
    )
    .unwrap();
    let options = hikari_scene::gltf::GltfOptions::default();
    let Err(e) =
        hikari_scene::gltf::load_slice_unguarded(&hikari_fuzz_glb_fixup(&data), None, &options)
    else {
        panic!("accepted")
    };
    assert!(
        e.to_string()
            .contains("images[0] has a bufferView but no mimeType"),
        "{e}"
    );
}

/// The header fix-up of the `glb` target.
fn hikari_fuzz_glb_fixup(data: &[u8]) -> Vec<u8> {
    let mut b = data.to_vec();
    b[0..4].copy_from_slice(b"glTF");
    b[4..8].copy_from_slice(&2u32.to_le_bytes());
    let len = b.len() as u32;
    b[8..12].copy_from_slice(&len.to_le_bytes());
    b
}

/// Found by `lut_strip_png` on the H200's 16 cores (session 21): a palette PNG with two PLTE
/// chunks whose lengths are not whole RGB entries made `png` 0.18.1 panic
/// (`decoder/transform/palette.rs:74`, a slice out of range). Now an error naming the chunk.
#[test]
fn a_png_with_two_partial_palettes_is_an_error() {
    let data = std::fs::read(
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("tests/regressions/lut_strip_png/two_palettes_of_partial_entries.png"),
    )
    .unwrap();
    let Err(e) = hikari_render::techniques::tonemap::lut_strip::decode_png(&data, "x.png") else {
        panic!("accepted")
    };
    assert!(e.to_string().contains("PLTE (palette) chunk"), "{e}");
}
