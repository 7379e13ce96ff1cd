//! Probe volumes: boxes that get a tetrahedral mesh of denser probes where the 12.5 m grid is
//! too coarse (inside and around buildings).
//!
//! - The built-in village: one volume per house and one for the temple hall (the building's
//!   footprint grown by a margin, from just above its floor to above its ceiling), and one over
//!   the courtyard ([`village_volumes`], from [`hikari_scene::village::VillageLayout`]).
//! - A user's glTF scene: every node whose `extras` hold `{"hikari": {"probe_volume": true}}`
//!   (or `{"hikari": {"probe_volume": {"spacing": 1.0}}}` to set the probe spacing, metres).
//!   The volume is the node's mesh's bounds (the accessors' `min`/`max` of `POSITION`) under
//!   the node's world transform; a node without a mesh (an "empty") stands for the cube
//!   [-1, 1]³ under its world transform ([`gltf_volumes`]).

use std::path::Path;

use glam::{Mat4, Quat, Vec3};
use hikari_scene::village::{Footprint, VillageLayout};
use serde_json::Value;

use crate::error::BakeError;

/// Default metres between the probes of a volume.
pub const DEFAULT_VOLUME_SPACING: f32 = 1.5;

/// Most probes along one side of a volume's lattice; a volume needing more is refused.
pub const MAX_PROBES_PER_SIDE: usize = 64;

/// A box that gets its own tetrahedral mesh.
#[derive(Clone, Debug, PartialEq)]
pub struct ProbeVolume {
    pub name: String,
    /// Maps the cube [-1, 1]³ onto the volume in world space (metres).
    pub transform: Mat4,
    /// Metres between neighbouring probes of the lattice.
    pub spacing: f32,
}

impl ProbeVolume {
    /// Lattice points of the volume (world space, metres), `spacing` apart along each of the
    /// box's axes with the box's corners included, each moved by up to ±`jitter` x spacing
    /// along each axis (a deterministic hash of its index) so that no five are cospherical for
    /// the Delaunay tetrahedralisation.
    pub fn lattice(&self, jitter: f32) -> Result<Vec<Vec3>, BakeError> {
        let axes = [
            self.transform.x_axis.truncate(),
            self.transform.y_axis.truncate(),
            self.transform.z_axis.truncate(),
        ];
        let bad = |why| BakeError::BadVolume {
            name: self.name.clone(),
            why,
        };
        if !(self.spacing.is_finite() && self.spacing > 0.0) {
            return Err(bad("its probe spacing is not a positive number of metres"));
        }
        if !self.transform.is_finite() {
            return Err(bad("its transform is not finite"));
        }
        let counts = axes.map(|a| (2.0 * a.length() / self.spacing).ceil() as usize + 1);
        if counts.iter().any(|&c| c > MAX_PROBES_PER_SIDE) {
            return Err(bad(
                "it needs more than 64 probes along a side: raise its spacing or split it",
            ));
        }
        let mut out = Vec::with_capacity(counts.iter().product());
        let mut index = 0u64;
        for k in 0..counts[2] {
            for j in 0..counts[1] {
                for i in 0..counts[0] {
                    let f = |c: usize, n: usize| {
                        if n == 1 {
                            0.0
                        } else {
                            -1.0 + 2.0 * c as f32 / (n - 1) as f32
                        }
                    };
                    let local = Vec3::new(f(i, counts[0]), f(j, counts[1]), f(k, counts[2]));
                    let h = hikari_math::sampling::rng::mix(index ^ 0x7e7a_0000);
                    let r = |s: u32| ((h >> s) & 0xffff) as f32 / 65535.0 * 2.0 - 1.0;
                    let shake = Vec3::new(r(0), r(16), r(32)) * jitter * self.spacing;
                    out.push(self.transform.transform_point3(local) + shake);
                    index += 1;
                }
            }
        }
        Ok(out)
    }
}

/// Volume around a building: its footprint grown by `margin` metres on each side, from
/// `floor_clearance` above the floor to `above_ceiling` over the ceiling.
pub fn building_volume(
    footprint: &Footprint,
    margin: f32,
    floor_clearance: f32,
    above_ceiling: f32,
    spacing: f32,
) -> ProbeVolume {
    let bottom = floor_clearance;
    let top = footprint.ceiling_height + above_ceiling;
    let half = Vec3::new(
        footprint.half_size.x + margin,
        0.5 * (top - bottom),
        footprint.half_size.y + margin,
    );
    let local =
        Mat4::from_translation(Vec3::new(0.0, 0.5 * (top + bottom), 0.0)) * Mat4::from_scale(half);
    ProbeVolume {
        name: footprint.name.clone(),
        transform: footprint.transform() * local,
        spacing,
    }
}

/// The village's volumes: each house (3 m around it, 1.5 m probes), the temple hall (4 m
/// around, 2 m probes) and the courtyard with the ring of golden trees around it (its circle's
/// square widened by 8 m, so that the ground under the trees, 27.5 m from the centre, has probes
/// of its own to carry their yellow bounce; 1 m to 13 m up, through the crowns; 4 m probes).
pub fn village_volumes(layout: &VillageLayout) -> Vec<ProbeVolume> {
    let mut out: Vec<ProbeVolume> = layout
        .houses
        .iter()
        .map(|h| building_volume(h, 3.0, 0.4, 1.0, DEFAULT_VOLUME_SPACING))
        .collect();
    out.push(building_volume(&layout.temple_hall, 4.0, 0.4, 1.5, 2.0));
    let r = layout.courtyard_radius;
    out.push(ProbeVolume {
        name: "courtyard".into(),
        transform: Mat4::from_translation(layout.courtyard_centre + Vec3::new(0.0, 7.0, 0.0))
            * Mat4::from_scale(Vec3::new(r + 8.0, 6.0, r + 8.0)),
        spacing: 4.0,
    });
    out
}

/// Volumes of a built-in scene by name (only the village has any).
pub fn builtin_volumes(name: &str) -> Vec<ProbeVolume> {
    match name {
        "village" => village_volumes(
            &hikari_scene::village::build(hikari_scene::village::DEFAULT_SEED).layout,
        ),
        _ => Vec::new(),
    }
}

/// The probe volumes a glTF file (`.gltf` or `.glb`) marks in its nodes' `extras` (module
/// documentation). Nodes of the file's default scene (else scene 0) and their descendants.
pub fn gltf_volumes(path: &Path) -> Result<Vec<ProbeVolume>, BakeError> {
    read_gltf_json(path, volumes_of_document)
}

/// `read` of a glTF file's JSON document; its errors and the file's name the path.
pub(crate) fn read_gltf_json<T>(
    path: &Path,
    read: impl FnOnce(&Value) -> Result<T, String>,
) -> Result<T, BakeError> {
    let err = |what: String| BakeError::Gltf {
        path: path.to_path_buf(),
        what,
    };
    let bytes = std::fs::read(path).map_err(|e| err(format!("cannot read: {e}")))?;
    parse_gltf_json(&bytes, read).map_err(err)
}

/// `read` of the JSON document of a glTF file's bytes (`.gltf` or `.glb`).
pub(crate) fn parse_gltf_json<T>(
    bytes: &[u8],
    read: impl FnOnce(&Value) -> Result<T, String>,
) -> Result<T, String> {
    let json = gltf_json_bytes(bytes)?;
    let doc: Value = serde_json::from_slice(json).map_err(|e| format!("bad JSON: {e}"))?;
    read(&doc)
}

/// [`gltf_volumes`] of a file's bytes; the error says what is wrong, without a file name.
pub fn gltf_volumes_from_bytes(bytes: &[u8]) -> Result<Vec<ProbeVolume>, String> {
    parse_gltf_json(bytes, volumes_of_document)
}

/// The JSON chunk of a `.glb`, or the whole of a `.gltf`.
fn gltf_json_bytes(bytes: &[u8]) -> Result<&[u8], String> {
    if !bytes.starts_with(b"glTF") {
        return Ok(bytes);
    }
    let word = |at: usize| {
        bytes
            .get(at..at + 4)
            .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize)
            .ok_or_else(|| format!("GLB shorter than its header ({} bytes)", bytes.len()))
    };
    let (len, kind) = (word(12)?, word(16)?);
    if kind != 0x4E4F_534A {
        return Err("the GLB's first chunk is not JSON".into());
    }
    bytes
        .get(20..20 + len)
        .ok_or_else(|| format!("the GLB's JSON chunk ({len} bytes) runs past the file"))
}

fn node_local(node: &Value, index: usize) -> Result<Mat4, String> {
    let floats = |key: &str, n: usize| -> Result<Option<Vec<f32>>, String> {
        let Some(v) = node.get(key) else {
            return Ok(None);
        };
        let a = v
            .as_array()
            .filter(|a| a.len() == n)
            .ok_or_else(|| format!("node {index}: `{key}` is not {n} numbers"))?;
        a.iter()
            .map(|x| {
                x.as_f64()
                    .map(|x| x as f32)
                    .ok_or_else(|| format!("node {index}: `{key}` holds a non-number"))
            })
            .collect::<Result<Vec<f32>, String>>()
            .map(Some)
    };
    if let Some(m) = floats("matrix", 16)? {
        return Ok(Mat4::from_cols_slice(&m));
    }
    let t = floats("translation", 3)?.unwrap_or(vec![0.0; 3]);
    let r = floats("rotation", 4)?.unwrap_or(vec![0.0, 0.0, 0.0, 1.0]);
    let s = floats("scale", 3)?.unwrap_or(vec![1.0; 3]);
    Ok(Mat4::from_scale_rotation_translation(
        Vec3::from_slice(&s),
        Quat::from_xyzw(r[0], r[1], r[2], r[3]).normalize(),
        Vec3::from_slice(&t),
    ))
}

/// Bounds of a glTF mesh from its primitives' POSITION accessors' `min` and `max`.
fn mesh_bounds(doc: &Value, mesh: usize) -> Option<(Vec3, Vec3)> {
    let prims = doc
        .get("meshes")?
        .get(mesh)?
        .get("primitives")?
        .as_array()?;
    let mut out: Option<(Vec3, Vec3)> = None;
    for p in prims {
        let acc = p.get("attributes")?.get("POSITION")?.as_u64()? as usize;
        let acc = doc.get("accessors")?.get(acc)?;
        let v3 = |k: &str| -> Option<Vec3> {
            let a = acc.get(k)?.as_array()?;
            Some(Vec3::new(
                a.first()?.as_f64()? as f32,
                a.get(1)?.as_f64()? as f32,
                a.get(2)?.as_f64()? as f32,
            ))
        };
        let (lo, hi) = (v3("min")?, v3("max")?);
        out = Some(match out {
            Some((a, b)) => (a.min(lo), b.max(hi)),
            None => (lo, hi),
        });
    }
    out
}

pub(crate) fn volumes_of_document(doc: &Value) -> Result<Vec<ProbeVolume>, String> {
    let mut out = Vec::new();
    for node in marked_nodes(doc, "probe_volume")? {
        let i = node.index;
        let spacing = match &node.mark {
            Value::Bool(true) => Some(DEFAULT_VOLUME_SPACING),
            Value::Bool(false) => None,
            Value::Object(o) => Some(match o.get("spacing") {
                None => DEFAULT_VOLUME_SPACING,
                Some(s) => s
                    .as_f64()
                    .map(|s| s as f32)
                    .filter(|s| s.is_finite() && *s > 0.0)
                    .ok_or_else(|| {
                        format!("node {i}: extras.hikari.probe_volume.spacing is not a positive number of metres")
                    })?,
            }),
            _ => {
                return Err(format!(
                    "node {i}: extras.hikari.probe_volume is neither true, false nor an object"
                ));
            }
        };
        if let Some(spacing) = spacing {
            out.push(ProbeVolume {
                transform: node_box(doc, &node, "probe volume")?,
                name: node.name,
                spacing,
            });
        }
    }
    Ok(out)
}

/// A node of the default scene whose `extras.hikari` holds a given key.
pub(crate) struct MarkedNode {
    pub index: usize,
    /// Its `name`, else "node {index}".
    pub name: String,
    /// Its world transform.
    pub world: Mat4,
    pub mesh: Option<usize>,
    /// The key's value.
    pub mark: Value,
}

/// The box a marked node stands for, as the map of the cube [-1, 1]^3 onto it in world space:
/// its mesh's bounds (the POSITION accessors' `min`/`max`) under its world transform, or the
/// cube itself under that transform for a node without a mesh (an "empty").
pub(crate) fn node_box(doc: &Value, node: &MarkedNode, what: &str) -> Result<Mat4, String> {
    let local_box = match node.mesh {
        Some(m) => {
            let (lo, hi) = mesh_bounds(doc, m).ok_or_else(|| {
                format!(
                    "node {}: its mesh {m} has no POSITION min/max to bound the {what}",
                    node.index
                )
            })?;
            Mat4::from_translation(0.5 * (lo + hi))
                * Mat4::from_scale((0.5 * (hi - lo)).max(Vec3::splat(1e-3)))
        }
        None => Mat4::IDENTITY,
    };
    Ok(node.world * local_box)
}

/// The default scene's (else scene 0's) nodes and descendants whose `extras.hikari` holds
/// `key`, with their world transforms.
pub(crate) fn marked_nodes(doc: &Value, key: &str) -> Result<Vec<MarkedNode>, String> {
    let nodes = doc
        .get("nodes")
        .and_then(Value::as_array)
        .cloned()
        .unwrap_or_default();
    let scene = doc.get("scene").and_then(Value::as_u64).unwrap_or(0) as usize;
    let roots: Vec<usize> = doc
        .get("scenes")
        .and_then(|s| s.get(scene))
        .and_then(|s| s.get("nodes"))
        .and_then(Value::as_array)
        .map(|a| {
            a.iter()
                .filter_map(|v| v.as_u64())
                .map(|v| v as usize)
                .collect()
        })
        .unwrap_or_default();
    let mut out = Vec::new();
    let mut stack: Vec<(usize, Mat4, usize)> =
        roots.iter().map(|&r| (r, Mat4::IDENTITY, 0)).collect();
    while let Some((i, parent, depth)) = stack.pop() {
        // glTF forbids cycles; a depth cap keeps a cyclic file from looping forever.
        if depth > nodes.len() {
            return Err(format!("node {i} is part of a cycle"));
        }
        let node = nodes
            .get(i)
            .ok_or_else(|| format!("node {i} does not exist ({} nodes)", nodes.len()))?;
        let world = parent * node_local(node, i)?;
        if let Some(mark) = node
            .get("extras")
            .and_then(|e| e.get("hikari"))
            .and_then(|h| h.get(key))
        {
            out.push(MarkedNode {
                index: i,
                name: node
                    .get("name")
                    .and_then(Value::as_str)
                    .map(str::to_owned)
                    .unwrap_or_else(|| format!("node {i}")),
                world,
                mesh: node.get("mesh").and_then(Value::as_u64).map(|m| m as usize),
                mark: mark.clone(),
            });
        }
        if let Some(children) = node.get("children").and_then(Value::as_array) {
            for c in children.iter().filter_map(Value::as_u64) {
                stack.push((c as usize, world, depth + 1));
            }
        }
    }
    Ok(out)
}
