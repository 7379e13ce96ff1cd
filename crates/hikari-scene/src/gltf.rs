//! glTF 2.0 loading (`.gltf` with external or data-URI buffers and images, and `.glb`).
//!
//! See the crate documentation for what is read, what is ignored and the unit conventions.
//! Every problem with the file is an [`GltfError`] naming the file; nothing in here panics on
//! bad input: byte ranges are checked before they are sliced, and the parts of the `gltf`
//! crate that would slice unchecked (its accessor readers) are not used.

use std::path::{Path, PathBuf};

use glam::{Mat4, Vec2, Vec3, Vec4};
use gltf::accessor::{DataType, Dimensions};
use thiserror::Error;

mod interior_mask;
mod quantization;
mod texture_transform;

use quantization::Storage;
pub use texture_transform::UvTransform;

use crate::{
    AlphaMode, Camera, Instance, Light, LightKind, Material, Mesh, Scene, Sun, Texture, TextureRef,
    Wrap,
};

/// Extensions whose content is read. Others in `extensionsUsed` give a warning; others in
/// `extensionsRequired` are an error.
pub const SUPPORTED_EXTENSIONS: &[&str] = &[
    "KHR_lights_punctual",
    "KHR_materials_emissive_strength",
    SPECULAR_EXTENSION,
    quantization::EXTENSION,
    texture_transform::EXTENSION,
];

/// The material extension whose `specularFactor` becomes [`Material::specular`].
const SPECULAR_EXTENSION: &str = "KHR_materials_specular";

/// A glTF file that cannot be loaded: the file and what is wrong with it.
#[derive(Debug, Error)]
#[error("{}: {what}", path.display())]
pub struct GltfError {
    pub path: PathBuf,
    pub what: String,
}

/// Loader settings.
#[derive(Clone, Debug)]
pub struct GltfOptions {
    /// Nits per unit of `emissiveFactor x emissiveStrength x emissiveTexture`. The default 1
    /// follows KHR_materials_emissive_strength, which says that where a physical unit is
    /// needed the product is in cd/m².
    pub emissive_nits_per_unit: f32,
}

impl Default for GltfOptions {
    fn default() -> Self {
        Self {
            emissive_nits_per_unit: 1.0,
        }
    }
}

/// A loaded file: the scene and what was skipped or approximated on the way.
#[derive(Clone, Debug)]
pub struct Loaded {
    pub scene: Scene,
    /// One line per ignored feature; also logged with `log::warn!`.
    pub warnings: Vec<String>,
}

/// Loads `path` (`.gltf` or `.glb`) with the default [`GltfOptions`].
pub fn load(path: impl AsRef<Path>) -> Result<Loaded, GltfError> {
    load_with(path, &GltfOptions::default())
}

pub fn load_with(path: impl AsRef<Path>, options: &GltfOptions) -> Result<Loaded, GltfError> {
    let path = path.as_ref();
    guarded(path, || load_unguarded(path, options))
}

/// Loads a `.gltf` or `.glb` held in memory. Relative URIs (external buffers and images) are
/// resolved against `base_dir`; with `None` they are an error, so only self-contained files
/// (`.glb`, data URIs) load. Errors name the file as `<memory>`, or `base_dir/<memory>`.
pub fn load_slice(
    bytes: &[u8],
    base_dir: Option<&Path>,
    options: &GltfOptions,
) -> Result<Loaded, GltfError> {
    guarded(&memory_name(base_dir), || {
        load_slice_unguarded(bytes, base_dir, options)
    })
}

/// [`load_slice`] without its `catch_unwind`, for tests and fuzzing that must see a panic.
#[doc(hidden)]
pub fn load_slice_unguarded(
    bytes: &[u8],
    base_dir: Option<&Path>,
    options: &GltfOptions,
) -> Result<Loaded, GltfError> {
    let name = memory_name(base_dir);
    finish(
        &name,
        Loader::from_bytes(bytes, base_dir.map(Path::to_path_buf), options).and_then(Loader::run),
    )
}

fn memory_name(base_dir: Option<&Path>) -> PathBuf {
    base_dir.map_or_else(|| PathBuf::from("<memory>"), |b| b.join("<memory>"))
}

/// Runs a load, turning a panic into an error naming `path`.
fn guarded(
    path: &Path,
    load: impl FnOnce() -> Result<Loaded, GltfError>,
) -> Result<Loaded, GltfError> {
    // A last line of defence: the checks in `load_unguarded` should leave nothing for a
    // dependency to panic on, but a malformed file must never take the process down. Tests call
    // `load_unguarded` directly so that a panic there fails them instead of hiding here.
    let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(load));
    result.unwrap_or_else(|panic| {
        let msg = panic
            .downcast_ref::<String>()
            .map(String::as_str)
            .or_else(|| panic.downcast_ref::<&str>().copied())
            .unwrap_or("unknown");
        Err(GltfError {
            path: path.to_path_buf(),
            what: format!("malformed file (the reader failed: {msg})"),
        })
    })
}

/// [`load_with`] without its `catch_unwind`: a panic propagates. For tests that must see one;
/// use [`load`] or [`load_with`] otherwise.
#[doc(hidden)]
pub fn load_unguarded(path: &Path, options: &GltfOptions) -> Result<Loaded, GltfError> {
    finish(path, Loader::new(path, options).and_then(Loader::run))
}

/// Logs the warnings of a load, or names the file in its error.
fn finish(path: &Path, result: Res<Loaded>) -> Result<Loaded, GltfError> {
    match result {
        Ok(loaded) => {
            for w in &loaded.warnings {
                log::warn!("{}: {w}", path.display());
            }
            Ok(loaded)
        }
        Err(what) => Err(GltfError {
            path: path.to_path_buf(),
            what,
        }),
    }
}

type Res<T> = Result<T, String>;

/// Largest element count accepted for an accessor without a buffer view.
const MAX_VIEWLESS_ELEMENTS: usize = 1 << 24;

/// Most pixels of one image (16384 x 16384): its RGBA8 copy is then at most 1 GiB.
pub const MAX_IMAGE_PIXELS: u64 = 1 << 28;

/// Most bytes of RGBA8 texture data a file may decode to, over all its textures.
pub const MAX_TEXTURE_BYTES: u64 = 4 << 30;

/// Most nodes the flattened hierarchy may hold. A node listed as a child by several parents is
/// repeated under each, so a few dozen nodes that each list the next twice would otherwise
/// expand to billions of instances.
pub const MAX_NODE_VISITS: usize = 1 << 22;

/// A perspective camera's numbers as glTF constrains them: `yfov` in (0, pi), `znear` > 0,
/// `zfar` > `znear` when given, `aspectRatio` > 0 when given, all finite.
fn check_perspective(p: &gltf::camera::Perspective) -> Res<()> {
    let yfov = p.yfov();
    if !(yfov > 0.0 && yfov < std::f32::consts::PI) {
        return Err(format!("yfov {yfov} rad is outside (0, pi)"));
    }
    let znear = p.znear();
    if !(znear > 0.0 && znear.is_finite()) {
        return Err(format!("znear {znear} must be positive and finite"));
    }
    if let Some(zfar) = p.zfar()
        && !(zfar > znear && zfar.is_finite())
    {
        return Err(format!(
            "zfar {zfar} must be finite and greater than znear {znear}"
        ));
    }
    if let Some(aspect) = p.aspect_ratio()
        && !(aspect > 0.0 && aspect.is_finite())
    {
        return Err(format!("aspectRatio {aspect} must be positive and finite"));
    }
    Ok(())
}

/// A KHR_lights_punctual light's numbers as the extension constrains them, and a node
/// transform that gives directional and spot lights a direction.
fn check_light(light: &gltf::khr_lights_punctual::Light, direction: Vec3) -> Res<()> {
    use gltf::khr_lights_punctual::Kind;
    let intensity = light.intensity();
    if !(intensity >= 0.0 && intensity.is_finite()) {
        return Err(format!(
            "intensity {intensity} must be finite and non-negative"
        ));
    }
    let color = Vec3::from(light.color());
    if !(color.is_finite() && color.min_element() >= 0.0) {
        return Err(format!("color {color} must be finite and non-negative"));
    }
    if let Some(range) = light.range()
        && !(range > 0.0 && range.is_finite())
    {
        return Err(format!("range {range} must be positive and finite"));
    }
    let kind = light.kind();
    if let Kind::Spot {
        inner_cone_angle: inner,
        outer_cone_angle: outer,
    } = kind
        && !(0.0 <= inner && inner < outer && outer <= std::f32::consts::FRAC_PI_2)
    {
        return Err(format!(
            "innerConeAngle {inner} and outerConeAngle {outer} rad must satisfy 0 <= inner < outer <= pi/2"
        ));
    }
    if !matches!(kind, Kind::Point) && direction == Vec3::ZERO {
        return Err("the node's transform is degenerate: it gives the light no direction".into());
    }
    Ok(())
}

struct Loader<'o> {
    /// Where relative URIs point; `None` for a file loaded from memory without a directory.
    base: Option<PathBuf>,
    options: &'o GltfOptions,
    doc: gltf::Document,
    buffers: Vec<gltf::buffer::Data>,
    warnings: std::cell::RefCell<Vec<String>>,
    /// Whether the file lists KHR_mesh_quantization (used or required), which the attribute
    /// types it adds need.
    quantization_declared: bool,
}

/// Checks a .glb header before `gltf` reads it: its length arithmetic underflows on a
/// header claiming fewer than 12 bytes.
fn check_glb_header(bytes: &[u8]) -> Res<()> {
    if bytes.len() < 12 {
        return Err(format!(
            "truncated .glb: {} bytes, but the header alone is 12",
            bytes.len()
        ));
    }
    let word = |i: usize| u32::from_le_bytes([bytes[i], bytes[i + 1], bytes[i + 2], bytes[i + 3]]);
    let (version, length) = (word(4), word(8) as usize);
    if version != 2 {
        return Err(format!(
            ".glb container version {version}; only glTF 2.0 is supported"
        ));
    }
    if length < 20 {
        return Err(format!(
            "malformed .glb: header gives a total length of {length} bytes"
        ));
    }
    if length > bytes.len() {
        return Err(format!(
            "truncated .glb: the header says {length} bytes but the file has {}",
            bytes.len()
        ));
    }
    Ok(())
}

/// `%XX` decoding of a relative URI, as glTF asks; an error if the result is not UTF-8.
fn percent_decode(uri: &str) -> Res<String> {
    let b = uri.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        let hex = |c: u8| (c as char).to_digit(16);
        if b[i] == b'%'
            && let (Some(h), Some(l)) = (
                b.get(i + 1).and_then(|&c| hex(c)),
                b.get(i + 2).and_then(|&c| hex(c)),
            )
        {
            out.push((h * 16 + l) as u8);
            i += 3;
        } else {
            out.push(b[i]);
            i += 1;
        }
    }
    String::from_utf8(out).map_err(|_| format!("URI `{uri}` does not decode to UTF-8"))
}

/// Checks a URI so that `gltf`'s importer only sees ones it handles without panicking; returns
/// the local file it names, if any, for messages.
fn check_uri(base: Option<&Path>, uri: &str) -> Res<Option<PathBuf>> {
    if uri.starts_with("data:") {
        return Ok(None);
    }
    let Some(base) = base else {
        return Err(format!(
            "URI `{uri}` names a file, but the glTF was read from memory with no directory to find it in"
        ));
    };
    if let Some(rest) = uri
        .strip_prefix("file://")
        .or_else(|| uri.strip_prefix("file:"))
    {
        return Ok(Some(PathBuf::from(rest)));
    }
    if uri.contains(':') {
        return Err(format!(
            "URI `{uri}` has an unsupported scheme (only data: and relative paths)"
        ));
    }
    Ok(Some(base.join(percent_decode(uri)?)))
}

/// What the `gltf` crate's validation misses and its accessors would later `unwrap`: it
/// indexes attribute accessors before checking they exist, accepts a camera whose `type`
/// names a projection the camera does not have, and an image without the members its source
/// needs.
fn check_before_validation(root: &gltf::json::Root) -> Res<()> {
    use gltf::json::camera::Type;
    use gltf::json::validation::Checked;
    for (c, cam) in root.cameras.iter().enumerate() {
        let missing = match cam.type_ {
            Checked::Valid(Type::Perspective) => cam.perspective.is_none().then_some("perspective"),
            Checked::Valid(Type::Orthographic) => {
                cam.orthographic.is_none().then_some("orthographic")
            }
            Checked::Invalid => None, // reported by validation
        };
        if let Some(member) = missing {
            return Err(format!(
                "invalid glTF: cameras[{c}] has type \"{member}\" but no `{member}` member"
            ));
        }
    }
    // `gltf`'s `Image::source` unwraps both: the mime type of an image in a buffer view (which
    // glTF requires but `gltf`'s validation does not check) and the URI of one without a view.
    for (i, image) in root.images.iter().enumerate() {
        match (&image.buffer_view, &image.mime_type, &image.uri) {
            (Some(_), None, _) => {
                return Err(format!(
                    "invalid glTF: images[{i}] has a bufferView but no mimeType (required with a bufferView)"
                ));
            }
            (None, _, None) => {
                return Err(format!(
                    "invalid glTF: images[{i}] has neither a uri nor a bufferView"
                ));
            }
            _ => {}
        }
    }
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, prim) in mesh.primitives.iter().enumerate() {
            for (semantic, index) in &prim.attributes {
                if index.value() >= root.accessors.len() {
                    return Err(format!(
                        "invalid glTF: meshes[{m}].primitives[{p}].attributes[\"{}\"] is accessor {} but the file has {}",
                        semantic.to_string(),
                        index.value(),
                        root.accessors.len()
                    ));
                }
            }
        }
    }
    Ok(())
}

/// Refuses an `extensionsRequired` entry that hikari does not read, and takes out of the list
/// those that hikari reads itself but the `gltf` crate's validation would refuse (it only knows
/// the extensions it parses). Returns whether the file declares KHR_mesh_quantization.
fn check_required_extensions(root: &mut gltf::json::Root) -> Res<bool> {
    for (i, ext) in root.extensions_required.iter().enumerate() {
        if !SUPPORTED_EXTENSIONS.contains(&ext.as_str()) {
            return Err(format!(
                "invalid glTF: extensionsRequired[{i}] = \"{ext}\": Unsupported extension (hikari reads {})",
                SUPPORTED_EXTENSIONS.join(", ")
            ));
        }
    }
    let declared = root
        .extensions_required
        .iter()
        .chain(&root.extensions_used)
        .any(|e| e == quantization::EXTENSION);
    root.extensions_required.retain(|e| {
        e != quantization::EXTENSION && e != texture_transform::EXTENSION && e != SPECULAR_EXTENSION
    });
    Ok(declared)
}

fn describe(e: &gltf::Error) -> String {
    match e {
        gltf::Error::Deserialize(e) => format!("bad JSON: {e}"),
        gltf::Error::Validation(list) => {
            let items: Vec<String> = list
                .iter()
                .map(|(path, e)| format!("{path}: {e}"))
                .collect();
            format!("invalid glTF: {}", items.join("; "))
        }
        gltf::Error::Binary(e) => format!("malformed .glb: {e:?}"),
        other => other.to_string(),
    }
}

impl<'o> Loader<'o> {
    fn new(path: &Path, options: &'o GltfOptions) -> Res<Self> {
        let bytes = std::fs::read(path).map_err(|e| format!("cannot read the file: {e}"))?;
        let base = path.parent().unwrap_or(Path::new(".")).to_path_buf();
        Self::from_bytes(&bytes, Some(base), options)
    }

    fn from_bytes(bytes: &[u8], base: Option<PathBuf>, options: &'o GltfOptions) -> Res<Self> {
        if bytes.starts_with(b"glTF") {
            check_glb_header(bytes)?;
        }
        let gltf::Gltf { document, blob } =
            gltf::Gltf::from_slice_without_validation(bytes).map_err(|e| describe(&e))?;
        let mut root = document.into_json();
        check_before_validation(&root)?;
        let quantization_declared = check_required_extensions(&mut root)?;
        let doc = gltf::Document::from_json(root).map_err(|e| describe(&e))?;
        let mut loader = Loader {
            base,
            options,
            doc,
            buffers: Vec::new(),
            warnings: Default::default(),
            quantization_declared,
        };
        loader.load_buffers(blob)?;
        Ok(loader)
    }

    /// The directory `gltf`'s importer resolves URIs against. `gltf` refuses even data URIs
    /// without one; a file read from memory has none, but `check_uri` has then refused every URI
    /// other than data:, so the directory given here is never used.
    fn uri_base(&self) -> &Path {
        self.base.as_deref().unwrap_or(Path::new("."))
    }

    fn warn(&self, w: String) {
        self.warnings.borrow_mut().push(w);
    }

    fn load_buffers(&mut self, blob: Option<Vec<u8>>) -> Res<()> {
        let mut blob = blob;
        let mut bin_user = None;
        for buffer in self.doc.buffers() {
            let i = buffer.index();
            let data = match buffer.source() {
                gltf::buffer::Source::Bin => match (blob.take(), bin_user) {
                    (Some(bin), _) => {
                        bin_user = Some(i);
                        bin
                    }
                    (None, Some(first)) => {
                        return Err(format!(
                            "buffer {i} has no uri, so it refers to the .glb BIN chunk, but buffer {first} already uses it (only the first buffer may)"
                        ));
                    }
                    (None, None) => {
                        return Err(format!(
                            "buffer {i} has no uri, so it refers to the .glb BIN chunk, which is missing"
                        ));
                    }
                },
                gltf::buffer::Source::Uri(uri) => {
                    let file = check_uri(self.base.as_deref(), uri)
                        .map_err(|e| format!("buffer {i}: {e}"))?;
                    let data =
                        gltf::buffer::Data::from_source(buffer.source(), Some(self.uri_base()));
                    match (data, file) {
                        (Ok(d), _) => d.0,
                        (Err(gltf::Error::Io(e)), Some(file)) => {
                            return Err(format!(
                                "buffer {i}: cannot read `{}`: {e}",
                                file.display()
                            ));
                        }
                        (Err(e), _) => return Err(format!("buffer {i}: {}", describe(&e))),
                    }
                }
            };
            if data.len() < buffer.length() {
                return Err(format!(
                    "buffer {i} has {} bytes but declares byteLength {}",
                    data.len(),
                    buffer.length()
                ));
            }
            self.buffers.push(gltf::buffer::Data(data));
        }
        for view in self.doc.views() {
            let b = view.buffer().index();
            let end = view.offset().checked_add(view.length());
            if end.is_none_or(|end| end > self.buffers[b].len()) {
                return Err(format!(
                    "buffer view {} spans bytes {}..{} of buffer {b}, which has {}",
                    view.index(),
                    view.offset(),
                    view.offset() as u128 + view.length() as u128,
                    self.buffers[b].len()
                ));
            }
        }
        Ok(())
    }

    fn view_bytes(&self, view: &gltf::buffer::View) -> &[u8] {
        // In range: checked in load_buffers.
        &self.buffers[view.buffer().index()][view.offset()..view.offset() + view.length()]
    }

    /// Every component of every element of `acc` as f64 (exact for all glTF component types),
    /// normalised integers mapped to [0, 1] or [-1, 1]; sparse substitution applied.
    fn read_accessor(&self, acc: &gltf::Accessor) -> Res<Vec<f64>> {
        let what = |msg: String| format!("accessor {}: {msg}", acc.index());
        let comps = acc.dimensions().multiplicity();
        let ty = acc.data_type();
        let csize = ty.size();
        let count = acc.count();
        let total = count
            .checked_mul(comps)
            .ok_or_else(|| what(format!("count {count} is too large")))?;
        let normalized = acc.normalized();
        let decode = |b: &[u8]| -> f64 {
            let v = match ty {
                DataType::I8 => b[0] as i8 as f64,
                DataType::U8 => b[0] as f64,
                DataType::I16 => i16::from_le_bytes([b[0], b[1]]) as f64,
                DataType::U16 => u16::from_le_bytes([b[0], b[1]]) as f64,
                DataType::U32 => u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
                DataType::F32 => f32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
            };
            if !normalized {
                return v;
            }
            match ty {
                DataType::I8 => (v / 127.0).max(-1.0),
                DataType::U8 => v / 255.0,
                DataType::I16 => (v / 32767.0).max(-1.0),
                DataType::U16 => v / 65535.0,
                _ => v,
            }
        };
        // Elements of `size` bytes, `stride` apart, from `offset` in `bytes`, checked.
        let gather = |bytes: &[u8],
                      offset: usize,
                      stride: usize,
                      n: usize,
                      size: usize,
                      label: &str|
         -> Res<Vec<usize>> {
            if n == 0 {
                return Ok(Vec::new());
            }
            if stride < size {
                return Err(what(format!(
                    "{label}: byte stride {stride} is smaller than the element size {size}"
                )));
            }
            let end = (n - 1)
                .checked_mul(stride)
                .and_then(|x| x.checked_add(offset))
                .and_then(|x| x.checked_add(size));
            match end {
                Some(end) if end <= bytes.len() => {
                    Ok((0..n).map(|e| offset + e * stride).collect())
                }
                _ => Err(what(format!(
                    "{label} out of range: {n} elements of {size} bytes from byte offset {offset} (stride {stride}) need {} bytes but the buffer view has {}",
                    offset as u128 + (n as u128).saturating_sub(1) * stride as u128 + size as u128,
                    bytes.len()
                ))),
            }
        };
        let elem = comps * csize;
        // Bytes behind a view were checked against the file; a view-less (all-zero or purely
        // sparse) accessor is not, so bound what it may allocate.
        if acc.view().is_none() && count > MAX_VIEWLESS_ELEMENTS {
            return Err(what(format!(
                "has no buffer view and {count} elements; at most {MAX_VIEWLESS_ELEMENTS} are supported"
            )));
        }
        // Every range is checked before `out` is allocated, so a huge count in a small file is
        // an error rather than an attempt to allocate it.
        let data = match acc.view() {
            Some(view) => {
                let bytes = self.view_bytes(&view);
                let stride = view.stride().unwrap_or(elem);
                Some((
                    bytes,
                    gather(bytes, acc.offset(), stride, count, elem, "data")?,
                ))
            }
            None => None,
        };
        let sparse = match acc.sparse() {
            Some(sparse) => {
                let n = sparse.count();
                let isize = sparse.indices().index_type().size();
                let ibytes = self.view_bytes(&sparse.indices().view());
                let idx = gather(
                    ibytes,
                    sparse.indices().offset(),
                    isize,
                    n,
                    isize,
                    "sparse indices",
                )?;
                let vbytes = self.view_bytes(&sparse.values().view());
                let vals = gather(
                    vbytes,
                    sparse.values().offset(),
                    elem,
                    n,
                    elem,
                    "sparse values",
                )?;
                Some((ibytes, idx, vbytes, vals, isize))
            }
            None => None,
        };
        let mut out = vec![0.0f64; total];
        if let Some((bytes, starts)) = data {
            for (e, start) in starts.into_iter().enumerate() {
                for c in 0..comps {
                    out[e * comps + c] = decode(&bytes[start + c * csize..]);
                }
            }
        }
        if let Some((ibytes, idx, vbytes, vals, isize)) = sparse {
            for (ipos, vpos) in idx.into_iter().zip(vals) {
                let b = &ibytes[ipos..];
                let target = match isize {
                    1 => b[0] as usize,
                    2 => u16::from_le_bytes([b[0], b[1]]) as usize,
                    _ => u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize,
                };
                if target >= count {
                    return Err(what(format!(
                        "sparse index {target} is out of range for {count} elements"
                    )));
                }
                for c in 0..comps {
                    out[target * comps + c] = decode(&vbytes[vpos + c * csize..]);
                }
            }
        }
        Ok(out)
    }

    /// Reads an attribute of `dims` components as floats, stored as one of the types `storage`
    /// allows (integers dequantized); the types KHR_mesh_quantization adds only where the file
    /// declares that extension.
    fn read_floats(
        &self,
        acc: &gltf::Accessor,
        label: &str,
        dims: &[Dimensions],
        storage: Storage,
    ) -> Res<(usize, Vec<f32>)> {
        let declared = self.quantization_declared;
        let allowed = quantization::allowed(storage, acc.data_type(), acc.normalized());
        if !dims.contains(&acc.dimensions()) || allowed.is_none_or(|ext| ext && !declared) {
            return Err(format!(
                "{label}: accessor {} is {:?} {:?}{}, expected {:?} of {}{}",
                acc.index(),
                acc.dimensions(),
                acc.data_type(),
                if acc.normalized() { " normalized" } else { "" },
                dims,
                quantization::describe(storage, declared),
                if allowed == Some(true) && !declared {
                    format!(
                        " ({} allows this type, but the file does not list it in extensionsRequired)",
                        quantization::EXTENSION
                    )
                } else {
                    String::new()
                }
            ));
        }
        let v = self
            .read_accessor(acc)
            .map_err(|e| format!("{label}: {e}"))?;
        Ok((
            acc.dimensions().multiplicity(),
            v.into_iter().map(|x| x as f32).collect(),
        ))
    }

    fn run(self) -> Res<Loaded> {
        for ext in self.doc.extensions_used() {
            if !SUPPORTED_EXTENSIONS.contains(&ext) {
                self.warn(format!("extension {ext} is not supported and is ignored"));
            }
        }
        if self.doc.animations().next().is_some() {
            self.warn("animations are ignored".into());
        }
        if self.doc.skins().next().is_some() {
            self.warn("skins are ignored: skinned meshes are drawn in their bind pose".into());
        }
        let mut scene = Scene {
            textures: self.load_textures()?,
            ..Default::default()
        };
        let (materials, uv_transforms) = self.load_materials(scene.textures.len())?;
        scene.materials = materials;
        let meshes = self.load_meshes(&mut scene, &uv_transforms)?;
        self.load_nodes(&mut scene, &meshes)?;
        let bounds = scene.bounds();
        if bounds.is_none() {
            self.warn("the file has no triangles to draw: only the sky is rendered".into());
        }
        if scene.cameras.is_empty() {
            match bounds {
                Some((lo, hi)) => scene.cameras.push(Camera::framing("auto", lo, hi)),
                None => {
                    self.warn(format!(
                        "no camera and nothing to frame: camera `auto` stands {} m up, looking at the horizon (-z)",
                        Camera::HORIZON_EYE_HEIGHT_M
                    ));
                    scene.cameras.push(Camera::horizon("auto"));
                }
            }
        }
        if scene.sun.is_none() && scene.lights.is_empty() {
            scene.sun = Some(Sun::default());
        }
        scene.validate().map_err(|e| e.to_string())?;
        Ok(Loaded {
            scene,
            warnings: self.warnings.into_inner(),
        })
    }

    fn load_textures(&self) -> Res<Vec<Texture>> {
        let mut images = Vec::new();
        for image in self.doc.images() {
            let i = image.index();
            // Where the image comes from, for messages.
            let (file, source) = match image.source() {
                gltf::image::Source::Uri { uri, .. } => {
                    let file = check_uri(self.base.as_deref(), uri)
                        .map_err(|e| format!("image {i}: {e}"))?;
                    let source = file
                        .as_ref()
                        .map_or_else(|| "data URI".to_owned(), |f| format!("`{}`", f.display()));
                    (file, source)
                }
                gltf::image::Source::View { view, .. } => {
                    (None, format!("buffer view {}", view.index()))
                }
            };
            let data = gltf::image::Data::from_source(
                image.source(),
                Some(self.uri_base()),
                &self.buffers,
            )
            .map_err(|e| match (&e, &file) {
                (gltf::Error::Io(io), Some(file)) => {
                    format!("image {i}: cannot read `{}`: {io}", file.display())
                }
                _ => format!("image {i} ({source}): {}", describe(&e)),
            })?;
            let pixels = u64::from(data.width) * u64::from(data.height);
            if pixels > MAX_IMAGE_PIXELS {
                return Err(format!(
                    "image {i} ({source}) is {}x{} pixels; at most {MAX_IMAGE_PIXELS} are loaded",
                    data.width, data.height
                ));
            }
            images.push(to_rgba8(&data).ok_or_else(|| {
                format!("image {i} ({source}): decoded pixel data has the wrong size")
            })?);
        }
        // Each texture copies its image, so a few textures naming one large image would
        // otherwise multiply it without bound: the total is checked before any copy.
        let total: u64 = self
            .doc
            .textures()
            .map(|t| images[t.source().index()].2.len() as u64)
            .sum();
        if total > MAX_TEXTURE_BYTES {
            return Err(format!(
                "the {} textures decode to {total} bytes of RGBA8 (textures naming the same image each copy it); at most {MAX_TEXTURE_BYTES} are loaded",
                self.doc.textures().len()
            ));
        }
        let mut textures = Vec::new();
        for t in self.doc.textures() {
            let (width, height, data) = images[t.source().index()].clone();
            let sampler = t.sampler();
            let wrap = |w: gltf::texture::WrappingMode| match w {
                gltf::texture::WrappingMode::Repeat => Wrap::Repeat,
                gltf::texture::WrappingMode::MirroredRepeat => Wrap::MirroredRepeat,
                gltf::texture::WrappingMode::ClampToEdge => Wrap::ClampToEdge,
            };
            textures.push(Texture {
                name: t
                    .name()
                    .or(t.source().name())
                    .map_or_else(|| format!("texture{}", t.index()), str::to_owned),
                width,
                height,
                data,
                wrap_s: wrap(sampler.wrap_s()),
                wrap_t: wrap(sampler.wrap_t()),
            });
        }
        Ok(textures)
    }

    /// The materials, and for each the KHR_texture_transform its primitives' UVs get.
    fn load_materials(&self, texture_count: usize) -> Res<(Vec<Material>, Vec<UvTransform>)> {
        let mut out = Vec::new();
        let mut transforms = Vec::new();
        let docs: Vec<_> = self.doc.materials().collect();
        for m in docs {
            let name = m.name().map_or_else(
                || format!("material{}", m.index().unwrap_or(0)),
                str::to_owned,
            );
            let pbr = m.pbr_metallic_roughness();
            let [r, g, b, a] = pbr.base_color_factor();
            let strength = m.emissive_strength().unwrap_or(1.0);
            let normal = m.normal_texture();
            let occlusion = m.occlusion_texture();
            let ext = texture_transform::EXTENSION;
            // Per texture slot, in the order that picks the material's UV transform: the glTF
            // member, its name in messages, the texture, textureInfo.texCoord and the
            // KHR_texture_transform object.
            let slots = [
                pbr.base_color_texture().map(|i| {
                    let v = i.extension_value(ext).cloned();
                    (
                        "baseColorTexture",
                        "base colour",
                        i.texture(),
                        i.tex_coord(),
                        v,
                    )
                }),
                pbr.metallic_roughness_texture().map(|i| {
                    let v = i.extension_value(ext).cloned();
                    (
                        "metallicRoughnessTexture",
                        "metallic-roughness",
                        i.texture(),
                        i.tex_coord(),
                        v,
                    )
                }),
                normal.as_ref().map(|i| {
                    let v = i.extension_value(ext).cloned();
                    ("normalTexture", "normal", i.texture(), i.tex_coord(), v)
                }),
                occlusion.as_ref().map(|i| {
                    let v = i.extension_value(ext).cloned();
                    (
                        "occlusionTexture",
                        "occlusion",
                        i.texture(),
                        i.tex_coord(),
                        v,
                    )
                }),
                m.emissive_texture().map(|i| {
                    let v = i.extension_value(ext).cloned();
                    ("emissiveTexture", "emissive", i.texture(), i.tex_coord(), v)
                }),
            ];
            // hikari's meshes have one UV set, so a material has one transform: the first
            // textured slot's (the base colour's where it has one); a slot with a different one
            // is drawn with it anyway, with a warning.
            let mut chosen: Option<(&str, UvTransform)> = None;
            let mut refs = [None; 5];
            for (slot, r) in slots.iter().zip(&mut refs) {
                let Some((member, what, texture, core_set, transform)) = slot else {
                    continue;
                };
                let (transform, set_override) = texture_transform::parse(transform.as_ref())
                    .map_err(|e| format!("material `{name}`: {member}: {e}"))?;
                let set = set_override.unwrap_or(*core_set);
                if set != 0 {
                    self.warn(format!(
                        "material `{name}`: {what} texture uses TEXCOORD_{set}{}; only TEXCOORD_0 is loaded, so it is used instead",
                        if set_override.is_some() {
                            format!(" ({ext}.texCoord)")
                        } else {
                            String::new()
                        }
                    ));
                }
                match chosen {
                    None => chosen = Some((member, transform)),
                    Some((first, t)) if !t.approx_eq(&transform) => self.warn(format!(
                        "material `{name}`: {member} has a different {ext} ({transform:?}) from {first} ({t:?}); a mesh has one UV set, so {first}'s is used for every texture of the material"
                    )),
                    Some(_) => {}
                }
                *r = (texture.index() < texture_count).then(|| TextureRef::new(texture.index()));
            }
            transforms.push(chosen.map_or(UvTransform::IDENTITY, |(_, t)| t));
            let [
                base_color_texture,
                metallic_roughness_texture,
                normal_texture,
                occlusion_texture,
                emissive_texture,
            ] = refs;
            let alpha_mode = match m.alpha_mode() {
                gltf::material::AlphaMode::Opaque => AlphaMode::Opaque,
                gltf::material::AlphaMode::Mask => {
                    let cutoff = m.alpha_cutoff().unwrap_or(AlphaMode::DEFAULT_CUTOFF);
                    if !(0.0..=1.0).contains(&cutoff) {
                        return Err(format!(
                            "material `{name}`: alphaCutoff {cutoff} is outside [0, 1]"
                        ));
                    }
                    AlphaMode::Mask { cutoff }
                }
                gltf::material::AlphaMode::Blend => {
                    self.warn(format!(
                        "material `{name}`: alpha mode BLEND is drawn as a cut-out at alpha {} (transparency is not supported yet)",
                        AlphaMode::BLEND_AS_MASK_CUTOFF
                    ));
                    AlphaMode::Blend
                }
            };
            let mat = Material {
                alpha_mode,
                base_color: Vec3::new(r, g, b),
                alpha: a.clamp(0.0, 1.0),
                roughness: pbr.roughness_factor().clamp(0.0, 1.0),
                metalness: pbr.metallic_factor().clamp(0.0, 1.0),
                emissive_nits: Vec3::from(m.emissive_factor())
                    * strength
                    * self.options.emissive_nits_per_unit,
                double_sided: m.double_sided(),
                base_color_texture,
                metallic_roughness_texture,
                normal_texture,
                normal_scale: normal.as_ref().map_or(1.0, |n| n.scale()),
                emissive_texture,
                occlusion_texture,
                occlusion_strength: occlusion
                    .as_ref()
                    .map_or(1.0, |o| o.strength())
                    .clamp(0.0, 1.0),
                area_light: area_light_flag(m.extras())
                    .map_err(|e| format!("material `{name}`: {e}"))?,
                gi_albedo: gi_albedo_override(m.extras())
                    .map_err(|e| format!("material `{name}`: {e}"))?,
                interior: interior_mask::material_interior(m.extras())
                    .map_err(|e| format!("material `{name}`: {e}"))?,
                specular: self.specular_factor(&m, &name)?,
                name,
                ..Default::default()
            };
            out.push(mat);
        }
        Ok((out, transforms))
    }

    /// KHR_materials_specular's `specularFactor` (1 without the extension). Its textures and
    /// its specular colour are not read: a warning says so where they would change the
    /// look.
    fn specular_factor(&self, m: &gltf::Material, name: &str) -> Res<f32> {
        let Some(ext) = m.extension_value(SPECULAR_EXTENSION) else {
            return Ok(1.0);
        };
        let here = |what: &str| format!("material `{name}`: {SPECULAR_EXTENSION}.{what}");
        let Some(obj) = ext.as_object() else {
            return Err(format!(
                "material `{name}`: {SPECULAR_EXTENSION} must be an object"
            ));
        };
        let factor = match obj.get("specularFactor") {
            None => 1.0,
            Some(v) => match v.as_f64() {
                Some(f) if (0.0..=1.0).contains(&f) => f as f32,
                _ => {
                    return Err(format!(
                        "{} {v} must be a number in [0, 1]",
                        here("specularFactor")
                    ));
                }
            },
        };
        for key in ["specularTexture", "specularColorTexture"] {
            if obj.contains_key(key) {
                self.warn(format!(
                    "{} is not loaded; the factors alone are used",
                    here(key)
                ));
            }
        }
        if let Some(c) = obj.get("specularColorFactor") {
            let white = c
                .as_array()
                .is_some_and(|a| a.len() == 3 && a.iter().all(|x| x.as_f64() == Some(1.0)));
            if !white {
                self.warn(format!(
                    "{} {c} is not supported; the specular reflection stays uncoloured",
                    here("specularColorFactor")
                ));
            }
        }
        Ok(factor)
    }

    /// Loads every primitive; returns, per glTF mesh, its (scene mesh, scene material) pairs.
    /// `uv_transforms[m]` is material m's KHR_texture_transform (the default material has
    /// none).
    fn load_meshes(
        &self,
        scene: &mut Scene,
        uv_transforms: &[UvTransform],
    ) -> Res<Vec<Vec<(usize, usize)>>> {
        let mut default_material = None;
        let mut out = Vec::new();
        let meshes: Vec<_> = self.doc.meshes().collect();
        for mesh in meshes {
            let mut prims = Vec::new();
            let mesh_name = mesh
                .name()
                .map_or_else(|| format!("mesh{}", mesh.index()), str::to_owned);
            for prim in mesh.primitives() {
                let label = format!("mesh `{mesh_name}` primitive {}", prim.index());
                if prim.mode() != gltf::mesh::Mode::Triangles {
                    self.warn(format!(
                        "{label}: mode {:?} skipped; only triangle lists are drawn",
                        prim.mode()
                    ));
                    continue;
                }
                if prim.morph_targets().next().is_some() {
                    self.warn(format!("{label}: morph targets are ignored"));
                }
                let material = match prim.material().index() {
                    Some(i) => i,
                    None => *default_material.get_or_insert_with(|| {
                        scene.materials.push(Material {
                            name: "gltf default".into(),
                            base_color: Vec3::ONE,
                            metalness: 1.0,
                            roughness: 1.0,
                            ..Default::default()
                        });
                        scene.materials.len() - 1
                    }),
                };
                let wants_tangents = scene.materials[material].normal_texture.is_some();
                let uv_transform = uv_transforms
                    .get(material)
                    .copied()
                    .unwrap_or(UvTransform::IDENTITY);
                let Some(m) = self.load_primitive(&prim, &label, wants_tangents, &uv_transform)?
                else {
                    continue;
                };
                scene.meshes.push(m);
                prims.push((scene.meshes.len() - 1, material));
            }
            out.push(prims);
        }
        Ok(out)
    }

    fn load_primitive(
        &self,
        prim: &gltf::Primitive,
        label: &str,
        wants_tangents: bool,
        uv_transform: &UvTransform,
    ) -> Res<Option<Mesh>> {
        let err = |e: String| format!("{label}: {e}");
        let Some(pos) = prim.get(&gltf::Semantic::Positions) else {
            self.warn(format!("{label}: no POSITION attribute; skipped"));
            return Ok(None);
        };
        let (_, p) = self
            .read_floats(&pos, "POSITION", &[Dimensions::Vec3], Storage::Position)
            .map_err(err)?;
        let positions: Vec<Vec3> = p.chunks_exact(3).map(Vec3::from_slice).collect();
        let n = positions.len();
        let per_vertex = |what: &str, len: usize| -> Res<()> {
            if len != n {
                return Err(err(format!(
                    "{what} has {len} elements but POSITION has {n}"
                )));
            }
            Ok(())
        };
        let mut mesh = Mesh {
            name: label.replace("mesh `", "").replace("` primitive ", "/"),
            positions,
            // glTF animations and morph targets are not read: meshes are static.
            deformation: None,
            ..Default::default()
        };
        if let Some(a) = prim.get(&gltf::Semantic::Normals) {
            let (_, v) = self
                .read_floats(&a, "NORMAL", &[Dimensions::Vec3], Storage::Direction)
                .map_err(err)?;
            mesh.normals = v.chunks_exact(3).map(Vec3::from_slice).collect();
            if a.data_type() != DataType::F32 {
                // Quantized normals are not unit length; the extension asks to renormalise.
                for n in &mut mesh.normals {
                    *n = n.normalize_or_zero();
                }
            }
            per_vertex("NORMAL", mesh.normals.len())?;
        }
        if let Some(a) = prim.get(&gltf::Semantic::Tangents) {
            let (_, v) = self
                .read_floats(&a, "TANGENT", &[Dimensions::Vec4], Storage::Direction)
                .map_err(err)?;
            mesh.tangents = v.chunks_exact(4).map(Vec4::from_slice).collect();
            if a.data_type() != DataType::F32 {
                // Renormalise xyz; w is the handedness, +-1, whatever its quantized value.
                for t in &mut mesh.tangents {
                    let w = if t.w < 0.0 { -1.0 } else { 1.0 };
                    *t = t.truncate().normalize_or_zero().extend(w);
                }
            }
            per_vertex("TANGENT", mesh.tangents.len())?;
        }
        if let Some(a) = prim.get(&gltf::Semantic::TexCoords(0)) {
            let (_, v) = self
                .read_floats(&a, "TEXCOORD_0", &[Dimensions::Vec2], Storage::TexCoord)
                .map_err(err)?;
            // KHR_texture_transform, before tangents are generated from these UVs.
            mesh.uvs = v
                .chunks_exact(2)
                .map(|uv| uv_transform.apply(Vec2::from_slice(uv)))
                .collect();
            per_vertex("TEXCOORD_0", mesh.uvs.len())?;
        }
        if let Some(a) = prim.get(&gltf::Semantic::Colors(0)) {
            let (dims, v) = self
                .read_floats(
                    &a,
                    "COLOR_0",
                    &[Dimensions::Vec3, Dimensions::Vec4],
                    Storage::Unorm,
                )
                .map_err(err)?;
            let c: Vec<Vec4> = v
                .chunks_exact(dims)
                .map(|c| {
                    if dims == 3 {
                        Vec3::from_slice(c).extend(1.0)
                    } else {
                        Vec4::from_slice(c)
                    }
                })
                .collect();
            per_vertex("COLOR_0", c.len())?;
            mesh.colors = Some(c);
        }
        if let Some(a) = prim.get(&gltf::Semantic::Extras(interior_mask::ATTRIBUTE.into())) {
            let (_, v) = self
                .read_floats(
                    &a,
                    "_HIKARI_INTERIOR",
                    &[Dimensions::Scalar],
                    Storage::Unorm,
                )
                .map_err(err)?;
            per_vertex("_HIKARI_INTERIOR", v.len())?;
            interior_mask::check_vertices(&v).map_err(err)?;
            mesh.interior = v;
        }
        mesh.indices = match prim.indices() {
            Some(a) => {
                if a.dimensions() != Dimensions::Scalar
                    || !matches!(a.data_type(), DataType::U8 | DataType::U16 | DataType::U32)
                    || a.normalized()
                {
                    return Err(err(format!(
                        "indices: accessor {} is {:?} {:?}, expected an unsigned integer scalar",
                        a.index(),
                        a.dimensions(),
                        a.data_type()
                    )));
                }
                let v = self
                    .read_accessor(&a)
                    .map_err(|e| err(format!("indices: {e}")))?;
                v.into_iter().map(|x| x as u32).collect()
            }
            None => (0..n as u32).collect(),
        };
        if !mesh.indices.len().is_multiple_of(3) {
            return Err(err(format!(
                "{} indices is not a whole number of triangles",
                mesh.indices.len()
            )));
        }
        if let Some(i) = mesh.indices.iter().position(|&ix| ix as usize >= n) {
            return Err(err(format!(
                "index {i} is {} but there are only {n} vertices",
                mesh.indices[i]
            )));
        }
        if mesh.normals.is_empty() {
            // glTF asks for flat normals when none are given: unweld so each triangle has its own.
            flat_normals(&mut mesh);
        }
        if mesh.tangents.is_empty() && wants_tangents && !mesh.uvs.is_empty() {
            mesh.tangents = generate_tangents(&mesh);
        } else if !mesh.tangents.is_empty() && !uv_transform.is_identity() {
            // The file's tangents follow its UVs; re-express them for the transformed ones.
            uv_transform.transform_tangents(&mesh.normals, &mut mesh.tangents);
        }
        Ok(Some(mesh))
    }

    fn load_nodes(&self, scene: &mut Scene, meshes: &[Vec<(usize, usize)>]) -> Res<()> {
        let roots: Vec<gltf::Node> = match self
            .doc
            .default_scene()
            .or_else(|| self.doc.scenes().next())
        {
            Some(s) => s.nodes().collect(),
            None => {
                // No scene: every node that is nobody's child is a root.
                let children: std::collections::HashSet<usize> = self
                    .doc
                    .nodes()
                    .flat_map(|n| n.children().map(|c| c.index()))
                    .collect();
                self.doc
                    .nodes()
                    .filter(|n| !children.contains(&n.index()))
                    .collect()
            }
        };
        if self.doc.scenes().len() > 1 {
            self.warn("the file has several scenes; only the default one is loaded".into());
        }
        let node_count = self.doc.nodes().len();
        let mut visits = vec![0usize; node_count];
        // Depth first in file order, so instances, cameras and lights keep the file's order.
        let mut stack: Vec<(gltf::Node, Mat4, usize)> = roots
            .into_iter()
            .rev()
            .map(|n| (n, Mat4::IDENTITY, 0))
            .collect();
        let mut total_visits = 0usize;
        while let Some((node, parent, depth)) = stack.pop() {
            if depth > node_count {
                return Err(format!(
                    "node {} is its own ancestor: the node hierarchy has a cycle",
                    node.index()
                ));
            }
            total_visits += 1;
            if total_visits > MAX_NODE_VISITS {
                return Err(format!(
                    "the node hierarchy expands to more than {MAX_NODE_VISITS} nodes (nodes shared by several parents are repeated for each)"
                ));
            }
            visits[node.index()] += 1;
            let world = parent * Mat4::from_cols_array_2d(&node.transform().matrix());
            if !world.is_finite() {
                return Err(format!("node {}: transform is not finite", node.index()));
            }
            if let Some(mesh) = node.mesh() {
                for &(m, material) in &meshes[mesh.index()] {
                    scene.instances.push(Instance {
                        mesh: m,
                        material,
                        transform: world,
                    });
                }
            }
            let node_name = node.name().map(str::to_owned);
            if let Some(cam) = node.camera() {
                let name = cam
                    .name()
                    .map(str::to_owned)
                    .or(node_name.clone())
                    .unwrap_or_else(|| format!("camera{}", cam.index()));
                match cam.projection() {
                    gltf::camera::Projection::Perspective(p) => {
                        check_perspective(&p).map_err(|e| {
                            format!("camera `{name}` (cameras[{}]): {e}", cam.index())
                        })?;
                        let position = world.transform_point3(Vec3::ZERO);
                        let forward = world.transform_vector3(Vec3::NEG_Z).normalize_or_zero();
                        let up = world.transform_vector3(Vec3::Y).normalize_or_zero();
                        if forward == Vec3::ZERO || up == Vec3::ZERO {
                            return Err(format!(
                                "camera `{name}`: node {} transform is degenerate",
                                node.index()
                            ));
                        }
                        scene.cameras.push(Camera {
                            name,
                            position,
                            target: position + forward,
                            vfov_deg: p.yfov().to_degrees(),
                            near: p.znear(),
                            up,
                        });
                    }
                    gltf::camera::Projection::Orthographic(_) => {
                        self.warn(format!(
                            "camera `{name}`: orthographic cameras are not supported; skipped"
                        ));
                    }
                }
            }
            if let Some(e) = particle_emitter(node.extras(), world).map_err(|e| {
                format!(
                    "node `{}` (nodes[{}]): {e}",
                    node_name.as_deref().unwrap_or("unnamed"),
                    node.index()
                )
            })? {
                let name = node_name
                    .clone()
                    .unwrap_or_else(|| format!("particles{}", node.index()));
                scene.particles.push(crate::ParticleEmitter { name, ..e });
            }
            if let Some(light) = node.light() {
                let name = light
                    .name()
                    .map(str::to_owned)
                    .or(node_name)
                    .unwrap_or_else(|| format!("light{}", light.index()));
                let color = Vec3::from(light.color());
                let direction = world.transform_vector3(Vec3::NEG_Z).normalize_or_zero();
                let position = world.transform_point3(Vec3::ZERO);
                let radius_m = check_light(&light, direction)
                    .and_then(|()| light_radius(light.extras()))
                    .map_err(|e| {
                        format!(
                            "light `{name}` (KHR_lights_punctual lights[{}]): {e}",
                            light.index()
                        )
                    })?;
                match light.kind() {
                    gltf::khr_lights_punctual::Kind::Directional => {
                        if scene.sun.is_some() {
                            self.warn(format!("light `{name}`: only the first directional light is used as the sun"));
                        } else {
                            scene.sun = Some(Sun {
                                direction: -direction,
                                illuminance_lux: light.intensity(),
                                color,
                            });
                        }
                    }
                    kind => {
                        let kind = match kind {
                            gltf::khr_lights_punctual::Kind::Spot {
                                inner_cone_angle,
                                outer_cone_angle,
                            } => LightKind::Spot {
                                inner_cone: inner_cone_angle,
                                outer_cone: outer_cone_angle,
                            },
                            _ => LightKind::Point,
                        };
                        scene.lights.push(Light {
                            name,
                            kind,
                            position,
                            direction,
                            intensity_cd: light.intensity(),
                            color,
                            range: light.range(),
                            radius_m,
                        });
                    }
                }
            }
            for child in node.children().collect::<Vec<_>>().into_iter().rev() {
                stack.push((child, world, depth + 1));
            }
        }
        // Validation of the `gltf` crate does not reject a node with two parents; it would be
        // drawn twice here, which is what such a file asks for, but say so.
        if let Some(n) = visits.iter().position(|&v| v > 1) {
            self.warn(format!(
                "node {n} is reached through more than one parent and appears {} times",
                visits[n]
            ));
        }
        Ok(())
    }
}

/// The node `extras` emitter `{"hikari": {"particles": {...}}}` ([`crate::ParticleEmitter`]):
/// centred on the node's world position, its box's half extents scaled by the node's scale;
/// every key optional (the emitter's defaults): `half_extents` [x, y, z], `count`, `size_m`
/// [birth, death], `opacity`, `velocity_mps` [x, y, z], `lifetime_s`, `albedo` [r, g, b],
/// `haze_lit`, `seed`, `hours` [from, to]. An unknown key or a value of the wrong kind is an error; ranges are
/// checked with the scene by `Scene::validate`.
fn particle_emitter(
    extras: &gltf::json::Extras,
    world: Mat4,
) -> Res<Option<crate::ParticleEmitter>> {
    let Some(raw) = extras else {
        return Ok(None);
    };
    let value: gltf::json::Value = gltf::json::deserialize::from_str(raw.get())
        .map_err(|e| format!("extras are not JSON: {e}"))?;
    let Some(p) = value.get("hikari").and_then(|h| h.get("particles")) else {
        return Ok(None);
    };
    let Some(fields) = p.as_object() else {
        return Err(format!(
            "extras hikari.particles must be an object, not {p}"
        ));
    };
    let bad = |key: &str, want: &str, v: &gltf::json::Value| {
        format!("extras hikari.particles.{key} must be {want}, not {v}")
    };
    let number = |key: &str, v: &gltf::json::Value| {
        v.as_f64()
            .map(|x| x as f32)
            .ok_or_else(|| bad(key, "a number", v))
    };
    let numbers = |key: &str, v: &gltf::json::Value, n: usize| -> Res<Vec<f32>> {
        match v.as_array() {
            Some(a) if a.len() == n => a.iter().map(|x| number(key, x)).collect(),
            _ => Err(bad(key, &format!("an array of {n} numbers"), v)),
        }
    };
    let mut e = crate::ParticleEmitter {
        centre: world.transform_point3(Vec3::ZERO),
        ..Default::default()
    };
    let (scale, _, _) = world.to_scale_rotation_translation();
    for (key, v) in fields {
        match key.as_str() {
            "half_extents" => e.half_extents = Vec3::from_slice(&numbers(key, v, 3)?) * scale.abs(),
            "count" => {
                e.count = v
                    .as_u64()
                    .and_then(|c| u32::try_from(c).ok())
                    .ok_or_else(|| bad(key, "a whole number", v))?
            }
            "size_m" => {
                let s = numbers(key, v, 2)?;
                e.size_m = [s[0], s[1]];
            }
            "opacity" => e.opacity = number(key, v)?,
            "velocity_mps" => e.velocity_mps = Vec3::from_slice(&numbers(key, v, 3)?),
            "lifetime_s" => e.lifetime_s = number(key, v)?,
            "albedo" => e.albedo = Vec3::from_slice(&numbers(key, v, 3)?),
            "haze_lit" => e.haze_lit = v.as_bool().ok_or_else(|| bad(key, "true or false", v))?,
            "hours" => {
                let h = numbers(key, v, 2)?;
                e.hours = Some([h[0], h[1]]);
            }
            "seed" => {
                e.seed = v
                    .as_u64()
                    .and_then(|c| u32::try_from(c).ok())
                    .ok_or_else(|| bad(key, "a whole number", v))?
            }
            other => return Err(format!("extras hikari.particles has no key `{other}`")),
        }
    }
    Ok(Some(e))
}

/// The material `extras` flag `{"hikari": {"area_light": true|false}}` ([`Material::area_light`]);
/// `None` when absent. Other extras are ignored; a flag that is not a boolean is an error.
fn area_light_flag(extras: &gltf::json::Extras) -> Res<Option<bool>> {
    let Some(raw) = extras else {
        return Ok(None);
    };
    let value: gltf::json::Value = gltf::json::deserialize::from_str(raw.get())
        .map_err(|e| format!("extras are not JSON: {e}"))?;
    match value.get("hikari").and_then(|h| h.get("area_light")) {
        None => Ok(None),
        Some(gltf::json::Value::Bool(b)) => Ok(Some(*b)),
        Some(other) => Err(format!(
            "extras hikari.area_light must be true or false, not {other}"
        )),
    }
}

/// The light `extras` value `{"hikari": {"radius": r}}` ([`Light::radius_m`], metres); `None`
/// when absent. Other extras are ignored; anything but a finite number >= 0 is an error.
fn light_radius(extras: &gltf::json::Extras) -> Res<Option<f32>> {
    let Some(raw) = extras else {
        return Ok(None);
    };
    let value: gltf::json::Value = gltf::json::deserialize::from_str(raw.get())
        .map_err(|e| format!("extras are not JSON: {e}"))?;
    let Some(v) = value.get("hikari").and_then(|h| h.get("radius")) else {
        return Ok(None);
    };
    match v.as_f64().map(|r| r as f32) {
        Some(r) if r >= 0.0 && r.is_finite() => Ok(Some(r)),
        _ => Err(format!(
            "extras hikari.radius must be a finite number of metres >= 0, not {v}"
        )),
    }
}

/// The material `extras` override `{"hikari": {"gi_albedo": [r, g, b]}}`
/// ([`Material::gi_albedo`]); `None` when absent. Anything but three numbers is an error; the
/// range is checked with the rest of the material by `Scene::validate`.
fn gi_albedo_override(extras: &gltf::json::Extras) -> Res<Option<Vec3>> {
    let Some(raw) = extras else {
        return Ok(None);
    };
    let value: gltf::json::Value = gltf::json::deserialize::from_str(raw.get())
        .map_err(|e| format!("extras are not JSON: {e}"))?;
    let Some(v) = value.get("hikari").and_then(|h| h.get("gi_albedo")) else {
        return Ok(None);
    };
    let bad = || format!("extras hikari.gi_albedo must be three numbers [r, g, b], not {v}");
    let items = v.as_array().filter(|a| a.len() == 3).ok_or_else(bad)?;
    let mut rgb = [0.0f32; 3];
    for (c, item) in rgb.iter_mut().zip(items) {
        *c = item.as_f64().ok_or_else(bad)? as f32;
    }
    Ok(Some(Vec3::from(rgb)))
}

fn to_rgba8(d: &gltf::image::Data) -> Option<(u32, u32, Vec<u8>)> {
    use gltf::image::Format as F;
    let (channels, bytes_per) = match d.format {
        F::R8 => (1, 1),
        F::R8G8 => (2, 1),
        F::R8G8B8 => (3, 1),
        F::R8G8B8A8 => (4, 1),
        F::R16 => (1, 2),
        F::R16G16 => (2, 2),
        F::R16G16B16 => (3, 2),
        F::R16G16B16A16 => (4, 2),
        F::R32G32B32FLOAT => (3, 4),
        F::R32G32B32A32FLOAT => (4, 4),
    };
    let texels = d.width as usize * d.height as usize;
    if d.pixels.len() != texels * channels * bytes_per {
        return None;
    }
    let channel = |b: &[u8]| -> u8 {
        match bytes_per {
            1 => b[0],
            2 => (u16::from_ne_bytes([b[0], b[1]]) >> 8) as u8,
            _ => (f32::from_ne_bytes([b[0], b[1], b[2], b[3]]).clamp(0.0, 1.0) * 255.0 + 0.5) as u8,
        }
    };
    if d.format == F::R8G8B8A8 {
        return Some((d.width, d.height, d.pixels.clone()));
    }
    let mut out = Vec::with_capacity(texels * 4);
    for px in d.pixels.chunks_exact(channels * bytes_per) {
        let mut c = [0u8; 4];
        for (k, ch) in px.chunks_exact(bytes_per).enumerate() {
            c[k] = channel(ch);
        }
        out.extend_from_slice(&match channels {
            1 => [c[0], c[0], c[0], 255],
            2 => [c[0], c[1], 0, 255],
            3 => [c[0], c[1], c[2], 255],
            _ => [c[0], c[1], c[2], c[3]],
        });
    }
    Some((d.width, d.height, out))
}

/// Unwelds `mesh` so each triangle has its own three vertices with the face normal.
fn flat_normals(mesh: &mut Mesh) {
    let old = std::mem::take(mesh);
    let pick = |i: u32| old.positions[i as usize];
    mesh.name = old.name.clone();
    for t in old.indices.chunks_exact(3) {
        let [a, b, c] = [pick(t[0]), pick(t[1]), pick(t[2])];
        let n = (b - a).cross(c - a).normalize_or(Vec3::Y);
        for &i in t {
            let i = i as usize;
            mesh.indices.push(mesh.positions.len() as u32);
            mesh.positions.push(old.positions[i]);
            mesh.normals.push(n);
            if let Some(t) = old.tangents.get(i) {
                mesh.tangents.push(*t);
            }
            if let Some(uv) = old.uvs.get(i) {
                mesh.uvs.push(*uv);
            }
            if let Some(c) = old.colors.as_ref().and_then(|c| c.get(i)) {
                mesh.colors.get_or_insert_with(Vec::new).push(*c);
            }
            if let Some(w) = old.interior.get(i) {
                mesh.interior.push(*w);
            }
        }
    }
}

/// Per-vertex tangents from the UV gradients of the surrounding triangles, Gram-Schmidt
/// orthogonalised against the normal. This is not MikkTSpace (which glTF recommends), so normal
/// maps baked for MikkTSpace can show small seams where the two disagree.
pub fn generate_tangents(mesh: &Mesh) -> Vec<Vec4> {
    let n = mesh.positions.len();
    let (mut tan, mut bit) = (vec![Vec3::ZERO; n], vec![Vec3::ZERO; n]);
    for t in mesh.indices.chunks_exact(3) {
        let [a, b, c] = [t[0] as usize, t[1] as usize, t[2] as usize];
        let (e1, e2) = (
            mesh.positions[b] - mesh.positions[a],
            mesh.positions[c] - mesh.positions[a],
        );
        let (d1, d2) = (mesh.uvs[b] - mesh.uvs[a], mesh.uvs[c] - mesh.uvs[a]);
        let det = d1.x * d2.y - d2.x * d1.y;
        if det.abs() < 1e-20 {
            continue;
        }
        let dpdu = (e1 * d2.y - e2 * d1.y) / det;
        let dpdv = (e2 * d1.x - e1 * d2.x) / det;
        for v in [a, b, c] {
            tan[v] += dpdu;
            bit[v] += dpdv;
        }
    }
    (0..n)
        .map(|i| {
            let nrm = mesh.normals[i];
            let t = (tan[i] - nrm * nrm.dot(tan[i])).normalize_or(nrm.any_orthonormal_vector());
            let w = if nrm.cross(t).dot(bit[i]) < 0.0 {
                -1.0
            } else {
                1.0
            };
            t.extend(w)
        })
        .collect()
}
