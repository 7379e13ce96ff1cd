//! Where the relit reflection probes go (docs/reflection-probes.md): a box each, which is both
//! the region the probe lights and the proxy its reflections are parallax-corrected against,
//! and a capture point inside it.
//!
//! - The built-in village ([`village_reflection_probes`]): each house's and the temple hall's
//!   room, the pond, the courtyard, and the whole village.
//! - The Cornell box: its interior.
//! - A user's glTF scene ([`gltf_reflection_probes`]): every node whose `extras` hold
//!   `{"hikari": {"reflection_probe": true}}`, or an object with `capture` (the node's local
//!   space, default the box's centre) and `blend` (metres). The box is the node's mesh bounds
//!   under its world transform, or the cube [-1, 1]^3 for a node without a mesh, as for
//!   probe volumes.
//! - Any scene that marks none: [`default_reflection_probe`], one over its bounds.

use std::path::Path;

use glam::{Mat4, Vec3};
use hikari_scene::Scene;
use hikari_scene::village::{Footprint, VillageLayout};
use serde_json::Value;

use crate::error::BakeError;
use crate::volumes::{marked_nodes, node_box, read_gltf_json};

/// A relit reflection probe: where its cube map is captured and the box it serves.
#[derive(Clone, Debug, PartialEq)]
pub struct ReflectionProbeBox {
    pub name: String,
    /// Maps the cube [-1, 1]^3 onto the probe's box in world space (metres): both the surfaces
    /// it lights (its influence) and the proxy its reflections are parallax-corrected against.
    pub transform: Mat4,
    /// World position the cube map is captured from; inside the box.
    pub capture: Vec3,
    /// Metres inside the box's faces over which the probe fades out into the probe around it.
    pub blend_m: f32,
}

/// The smallest half-extent a probe's box may have, metres.
const MIN_HALF_M: f32 = 0.005;

impl ReflectionProbeBox {
    /// An axis-aligned box from `lo` to `hi`.
    pub fn aabb(name: &str, lo: Vec3, hi: Vec3, capture: Vec3, blend_m: f32) -> Self {
        Self {
            name: name.into(),
            transform: Mat4::from_translation(0.5 * (lo + hi)) * Mat4::from_scale(0.5 * (hi - lo)),
            capture,
            blend_m,
        }
    }

    /// Half the box's size along its three axes, metres.
    pub fn half_extents(&self) -> Vec3 {
        Vec3::new(
            self.transform.x_axis.truncate().length(),
            self.transform.y_axis.truncate().length(),
            self.transform.z_axis.truncate().length(),
        )
    }

    /// Metres from `p` to the box (0 inside).
    pub fn distance_to(&self, p: Vec3) -> f32 {
        let local = self.transform.inverse().transform_point3(p);
        let nearest = self
            .transform
            .transform_point3(local.clamp(Vec3::splat(-1.0), Vec3::ONE));
        nearest.distance(p)
    }

    /// Checks finite numbers, a box at least 1 cm along each axis whose axes are at right
    /// angles, the capture point inside it, and a blend of 0 or more metres.
    pub fn validate(&self) -> Result<(), BakeError> {
        let bad = |why: &'static str| BakeError::BadReflectionProbe {
            name: self.name.clone(),
            why,
        };
        if !self.transform.is_finite() || !self.capture.is_finite() || !self.blend_m.is_finite() {
            return Err(bad("it holds a number that is not finite"));
        }
        if self.half_extents().min_element() < MIN_HALF_M {
            return Err(bad("its box is less than 1 cm along an axis"));
        }
        let a = [
            self.transform.x_axis.truncate().normalize(),
            self.transform.y_axis.truncate().normalize(),
            self.transform.z_axis.truncate().normalize(),
        ];
        if a[0].dot(a[1]).abs() > 1e-3 || a[1].dot(a[2]).abs() > 1e-3 || a[0].dot(a[2]).abs() > 1e-3
        {
            return Err(bad("its box is sheared (its axes are not at right angles)"));
        }
        let local = self.transform.inverse().transform_point3(self.capture);
        if local.abs().max_element() > 1.0 + 1e-4 {
            return Err(bad("its capture point lies outside its box"));
        }
        if self.blend_m < 0.0 {
            return Err(bad("its blend distance is negative"));
        }
        Ok(())
    }

    /// Volume of the box, m^3 (the smaller of two overlapping boxes wins).
    pub fn volume(&self) -> f32 {
        8.0 * self.half_extents().element_product()
    }
}

/// The room inside a building's walls, from its floor to its ceiling, captured at its middle
/// `capture_height` above the floor (below the ceiling).
fn room(f: &Footprint, wall: f32, capture_height: f32, blend_m: f32) -> ReflectionProbeBox {
    let h = f.ceiling_height;
    let half = Vec3::new(f.half_size.x - wall, 0.5 * h, f.half_size.y - wall);
    let local = Mat4::from_translation(Vec3::new(0.0, 0.5 * h, 0.0)) * Mat4::from_scale(half);
    ReflectionProbeBox {
        name: format!("{} room", f.name),
        transform: f.transform() * local,
        capture: f
            .transform()
            .transform_point3(Vec3::new(0.0, capture_height.min(h - 0.1), 0.0)),
        blend_m,
    }
}

/// The village's probes: each house's and the temple hall's room (captured 1.5 m above the
/// floor, above the low furniture; blend 0.3 m), the pond (its shore grown by 6 m, from 1 m
/// below the water to 12 m above, captured 1.5 m over the water; blend 3 m), the courtyard
/// (its circle grown by 4 m, 1 m below to 15 m above its ground, captured at 1.7 m; blend 4 m)
/// and the whole village (the terrain's square, captured 1.7 m over the courtyard; no blend:
/// it is the last resort).
pub fn village_reflection_probes(layout: &VillageLayout) -> Vec<ReflectionProbeBox> {
    use hikari_scene::village::house::WALL_THICKNESS;
    use hikari_scene::village::terrain::HALF_SIZE;
    let mut out: Vec<ReflectionProbeBox> = layout
        .houses
        .iter()
        .map(|h| room(h, WALL_THICKNESS, 1.5, 0.3))
        .collect();
    out.push(room(&layout.temple_hall, WALL_THICKNESS, 1.5, 0.3));
    let pond = layout.pond_centre;
    let r = layout.pond_shore_radius + 6.0;
    out.push(ReflectionProbeBox::aabb(
        "pond",
        pond + Vec3::new(-r, -1.0, -r),
        pond + Vec3::new(r, 12.0, r),
        pond + Vec3::new(0.0, 1.5, 0.0),
        3.0,
    ));
    let court = layout.courtyard_centre;
    let r = layout.courtyard_radius + 4.0;
    out.push(ReflectionProbeBox::aabb(
        "courtyard",
        court + Vec3::new(-r, -1.0, -r),
        court + Vec3::new(r, 15.0, r),
        court + Vec3::new(0.0, 1.7, 0.0),
        4.0,
    ));
    out.push(ReflectionProbeBox::aabb(
        "village",
        Vec3::new(-HALF_SIZE, court.y - 60.0, -HALF_SIZE),
        Vec3::new(HALF_SIZE, court.y + 200.0, HALF_SIZE),
        court + Vec3::new(0.0, 1.7, 0.0),
        0.0,
    ));
    out
}

/// The probes of a built-in scene by name: the village's, the Cornell box's interior; none for
/// the others (the caller then uses [`default_reflection_probe`]).
pub fn builtin_reflection_probes(name: &str) -> Vec<ReflectionProbeBox> {
    match name {
        "village" => village_reflection_probes(
            &hikari_scene::village::build(hikari_scene::village::DEFAULT_SEED).layout,
        ),
        "cornell" => {
            let scene = hikari_scene::builtin::cornell();
            let (lo, hi) = bounds(&scene).expect("the Cornell box has geometry");
            vec![ReflectionProbeBox::aabb(
                "cornell",
                lo,
                hi,
                0.5 * (lo + hi),
                0.0,
            )]
        }
        _ => Vec::new(),
    }
}

/// World bounds of every instance's transformed vertices, `None` for an empty scene.
fn bounds(scene: &Scene) -> Option<(Vec3, Vec3)> {
    let mut lo = Vec3::splat(f32::INFINITY);
    let mut hi = Vec3::splat(f32::NEG_INFINITY);
    for inst in &scene.instances {
        for p in &scene.meshes.get(inst.mesh)?.positions {
            let w = inst.transform.transform_point3(*p);
            lo = lo.min(w);
            hi = hi.max(w);
        }
    }
    (lo.is_finite() && hi.is_finite()).then_some((lo, hi))
}

/// One probe for a scene that marks none: the bounds of its instances (grown to at least 1 cm
/// an axis), captured at the centre in x and z, 1.7 m above the bottom (clamped inside the
/// box); blend 10 % of the smallest half-extent. `None` for an empty scene.
pub fn default_reflection_probe(scene: &Scene) -> Option<ReflectionProbeBox> {
    let (lo, hi) = bounds(scene)?;
    let mid = 0.5 * (lo + hi);
    let half = (0.5 * (hi - lo)).max(Vec3::splat(MIN_HALF_M));
    let (lo, hi) = (mid - half, mid + half);
    Some(ReflectionProbeBox::aabb(
        "scene",
        lo,
        hi,
        Vec3::new(mid.x, (lo.y + 1.7).min(mid.y + 0.9 * half.y), mid.z),
        0.1 * half.min_element(),
    ))
}

/// The reflection probes a glTF file (`.gltf` or `.glb`) marks in its nodes' `extras` (module
/// documentation), each validated.
pub fn gltf_reflection_probes(path: &Path) -> Result<Vec<ReflectionProbeBox>, BakeError> {
    read_gltf_json(path, probes_of_document)
}

/// [`gltf_reflection_probes`] of a file's bytes; the error says what is wrong, without a file
/// name.
pub fn gltf_reflection_probes_from_bytes(bytes: &[u8]) -> Result<Vec<ReflectionProbeBox>, String> {
    crate::volumes::parse_gltf_json(bytes, probes_of_document)
}

pub(crate) fn probes_of_document(doc: &Value) -> Result<Vec<ReflectionProbeBox>, String> {
    let mut out = Vec::new();
    for node in marked_nodes(doc, "reflection_probe")? {
        let i = node.index;
        let field = |f: &str| format!("node {i}: extras.hikari.reflection_probe{f}");
        let options = match &node.mark {
            Value::Bool(false) => continue,
            Value::Bool(true) => None,
            Value::Object(o) => Some(o.clone()),
            _ => {
                return Err(format!(
                    "{} is neither true, false nor an object",
                    field("")
                ));
            }
        };
        let transform = node_box(doc, &node, "reflection probe")?;
        let half = Vec3::new(
            transform.x_axis.truncate().length(),
            transform.y_axis.truncate().length(),
            transform.z_axis.truncate().length(),
        );
        let mut capture = transform.transform_point3(Vec3::ZERO);
        let mut blend_m = 0.1 * half.min_element();
        if let Some(o) = options {
            if let Some(c) = o.get("capture") {
                let v: Vec<f32> = c
                    .as_array()
                    .filter(|a| a.len() == 3)
                    .and_then(|a| a.iter().map(|x| x.as_f64().map(|x| x as f32)).collect())
                    .ok_or_else(|| format!("{} is not 3 numbers", field(".capture")))?;
                capture = node.world.transform_point3(Vec3::from_slice(&v));
            }
            if let Some(b) = o.get("blend") {
                blend_m = b
                    .as_f64()
                    .map(|b| b as f32)
                    .filter(|b| b.is_finite() && *b >= 0.0)
                    .ok_or_else(|| {
                        format!("{} is not a number of metres, 0 or more", field(".blend"))
                    })?;
            }
        }
        let probe = ReflectionProbeBox {
            name: node.name,
            transform,
            capture,
            blend_m,
        };
        probe.validate().map_err(|e| format!("node {i}: {e}"))?;
        out.push(probe);
    }
    Ok(out)
}
