//! # hikari-fuzz: one function per parser of outside input
//!
//! Each `pub fn` here takes arbitrary bytes and feeds them to one of hikari's readers, the way
//! hikari reads that kind of file. Errors are the expected outcome and are dropped; a panic, a
//! hang or a huge allocation is a bug in the reader. Where a reader accepts the input, the
//! function also checks what the rest of hikari relies on (a glTF that loads gets its BVH
//! built; a settings table that validates reads back from its own TOML; a bake that decodes
//! re-encodes to the same bytes), with `assert!`s, so a wrong "yes" is a finding too.
//!
//! The same functions are driven two ways:
//! - by libFuzzer through cargo-fuzz, one target per function in `fuzz/` (docs/reliability.md
//!   says how to run them);
//! - by this crate's tests, over the seed corpora in `fuzz/corpus/` plus a few thousand
//!   mutations from a seeded generator ([`mutate`]), so `./x test` keeps every target alive.

use std::path::Path;

use glam::{Affine3A, Vec3};
use hikari_bvh::{Blas, BuildOptions, BvhError, Instance, Ray, Tlas};
use hikari_render::Preset;
use hikari_render::settings::Settings;
use hikari_render::techniques::tonemap::{cube::CubeLut, lut_strip};

pub mod mutate;

/// A fuzz target: never panics on any input.
pub type Target = fn(&[u8]);

/// Every target, by the name its cargo-fuzz target and corpus folder have.
pub const TARGETS: &[(&str, Target)] = &[
    ("gltf", gltf),
    ("glb", glb),
    ("gltf_extras", gltf_extras),
    ("settings_toml", settings_toml),
    ("cube", cube),
    ("lut_strip_png", lut_strip_png),
    ("probe_bake", probe_bake),
];

/// A `.gltf` or `.glb` file's bytes, as `hikari render --scene FILE` loads them (without a
/// directory: external URIs are an error), then the BVH over what it yields.
pub fn gltf(data: &[u8]) {
    let Ok(loaded) = hikari_scene::gltf::load_slice_unguarded(
        data,
        None,
        &hikari_scene::gltf::GltfOptions::default(),
    ) else {
        return;
    };
    build_bvh(&loaded.scene);
}

/// A `.glb` whose 12-byte header is made consistent first (magic `glTF`, version 2, total
/// length = the input's), so that mutations reach the chunk reader instead of stopping at the
/// header checks (which [`gltf`] covers).
pub fn glb(data: &[u8]) {
    if data.len() < 12 {
        return gltf(data);
    }
    let mut bytes = data.to_vec();
    bytes[0..4].copy_from_slice(b"glTF");
    bytes[4..8].copy_from_slice(&2u32.to_le_bytes());
    let len = u32::try_from(bytes.len()).unwrap_or(u32::MAX);
    bytes[8..12].copy_from_slice(&len.to_le_bytes());
    gltf(&bytes)
}

/// The probe volumes and reflection probes hikari-bake reads from a glTF's node `extras`.
pub fn gltf_extras(data: &[u8]) {
    let _ = hikari_bake::volumes::gltf_volumes_from_bytes(data);
    let _ = hikari_bake::reflection_probes::gltf_reflection_probes_from_bytes(data);
}

/// The BVH hikari builds over a loaded scene (as hikari-bake's `SceneRays` and the renderer
/// do): a BLAS per mesh with triangles, a TLAS over the instances, and one ray through it.
pub fn build_bvh(scene: &hikari_scene::Scene) {
    let options = BuildOptions::default();
    let mut blas_of_mesh = vec![None; scene.meshes.len()];
    let mut blases = Vec::new();
    for (i, m) in scene.meshes.iter().enumerate() {
        let tris: Vec<[u32; 3]> = m
            .indices
            .chunks_exact(3)
            .map(|t| [t[0], t[1], t[2]])
            .collect();
        if tris.is_empty() {
            continue;
        }
        match Blas::build(&m.name, &m.positions, &tris, &options) {
            Ok(b) => {
                blas_of_mesh[i] = Some(blases.len() as u32);
                blases.push(b);
            }
            Err(BvhError::NoValidTriangles { .. }) => {}
            // The scene validated, so its meshes must build.
            Err(e) => panic!("a scene that validated has a mesh the BVH refuses: {e}"),
        }
    }
    let instances: Vec<Instance> = scene
        .instances
        .iter()
        .filter_map(|inst| {
            let b = blas_of_mesh.get(inst.mesh).copied().flatten()?;
            Some(Instance::new(Affine3A::from_mat4(inst.transform), b))
        })
        .collect();
    let selected: Vec<u32> = (0..instances.len() as u32).collect();
    let tlas = match Tlas::build(&instances, &selected, &blases) {
        Ok(t) => t,
        Err(BvhError::TooManyInstances { .. }) => return,
        Err(e) => panic!("a scene that validated has instances the TLAS refuses: {e}"),
    };
    if let Some((lo, hi)) = scene.bounds() {
        let mid = 0.5 * (lo + hi);
        let origin = Vec3::new(mid.x, hi.y + 1.0, mid.z);
        let ray = Ray::new(origin, Vec3::NEG_Y, 0.0, f32::INFINITY);
        let _ = tlas.closest_hit(&blases, &ray);
    }
}

/// Keys of the `--config` file that are not settings tables (hikari-cli's `config.rs`).
const CONFIG_HEAD_KEYS: [&str; 5] = ["scene", "camera", "time", "width", "height"];

/// The settings as `hikari render --config FILE [--preset P] [--set table.key=value ...]` reads
/// them. The input is the file's text, optionally followed by a NUL byte, a preset name on the
/// first line after it (empty: none), and one `table.key=value` override a line.
pub fn settings_toml(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let (file, command_line) = text.split_once('\0').unwrap_or((text, ""));
    let mut lines = command_line.lines();
    let preset = lines.next().and_then(|p| p.parse::<Preset>().ok());
    let overrides: Vec<(String, String)> = lines
        .filter_map(|l| l.split_once('='))
        .map(|(k, v)| (k.trim().to_string(), v.trim().to_string()))
        .collect();
    let Ok(mut table) = file.parse::<toml::Table>() else {
        return;
    };
    for k in CONFIG_HEAD_KEYS {
        table.remove(k);
    }
    let Ok(settings) = Settings::from_toml(preset, table, &overrides) else {
        return;
    };
    assert_eq!(
        settings.validate(),
        Ok(()),
        "from_toml returned settings that do not validate"
    );
    // What `to_toml` writes must read back as the same settings.
    let text = settings.to_toml();
    let table: toml::Table = text
        .parse()
        .unwrap_or_else(|e| panic!("to_toml wrote TOML that does not parse: {e}\n{text}"));
    let again = Settings::from_toml(None, table, &[])
        .unwrap_or_else(|e| panic!("to_toml wrote settings that do not read back: {e}\n{text}"));
    assert_eq!(again, settings, "settings changed through to_toml\n{text}");
}

/// A `.cube` LUT file (`--lut FILE`). One that parses is sampled and must read back from
/// the text it writes.
pub fn cube(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let Ok(lut) = CubeLut::parse(text, "fuzz.cube") else {
        return;
    };
    for c in [[0.0, 0.0, 0.0], [0.5, 0.25, 1.0], [f32::NAN, -1.0, 2.0]] {
        let _ = lut.sample(c);
    }
    let written = lut.to_text();
    if let Err(e) = CubeLut::parse(&written, "written.cube") {
        panic!("a parsed LUT's own text does not parse: {e}");
    }
}

/// A graded screenshot (`hikari grade --from FILE`): the PNG decoded, then its LUT strip read.
pub fn lut_strip_png(data: &[u8]) {
    let Ok(img) = lut_strip::decode_png(data, "fuzz.png") else {
        return;
    };
    if let Ok(lut) = lut_strip::extract(&img, "fuzz.png") {
        let _ = lut.sample([0.3, 0.6, 0.9]);
    }
}

/// An irradiance-probe bake file. Decoded as is (the scene key expected is the one the file
/// names, so the key check passes), then again with its length field and CRC-32 made to match,
/// so that mutations reach the structural checks. A bake that decodes must validate and
/// re-encode to the very bytes it came from.
pub fn probe_bake(data: &[u8]) {
    decode_bake(data);
    use hikari_probes::format::{CHECKSUM_LEN, HEADER_LEN};
    if data.len() >= HEADER_LEN + CHECKSUM_LEN {
        let mut bytes = data.to_vec();
        let len = bytes.len() as u64;
        bytes[16..24].copy_from_slice(&len.to_le_bytes());
        let n = bytes.len() - CHECKSUM_LEN;
        let crc = crc32fast::hash(&bytes[..n]);
        bytes[n..].copy_from_slice(&crc.to_le_bytes());
        decode_bake(&bytes);
    }
}

fn decode_bake(data: &[u8]) {
    let mut key = [0u8; 32];
    if let Some(k) = data.get(24..56) {
        key.copy_from_slice(k);
    }
    let Ok(bake) = hikari_probes::decode(data, &hikari_probes::SceneKey(key)) else {
        return;
    };
    assert_eq!(
        hikari_probes::validate(&bake),
        Ok(()),
        "a decoded bake does not validate"
    );
    let again = hikari_probes::encode(&bake).expect("a decoded bake encodes");
    assert!(again == data, "a decoded bake re-encodes to other bytes");
}

/// Runs `target` on every file of `dir` (for tools and tests); returns how many it read.
pub fn run_dir(target: fn(&[u8]), dir: &Path) -> std::io::Result<usize> {
    let mut n = 0;
    for entry in std::fs::read_dir(dir)? {
        let path = entry?.path();
        if path.is_file() {
            target(&std::fs::read(&path)?);
            n += 1;
        }
    }
    Ok(n)
}
