//! The interior mask from a glTF file (docs/irradiance-probes.md, *The interior mask*): a
//! material's `extras` `{"hikari": {"interior": w}}` ([`Material::interior`](crate::Material)),
//! and a per-vertex attribute `_HIKARI_INTERIOR` ([`Mesh::interior`](crate::Mesh)), both in
//! [0, 1] (0 outdoors, 1 indoors). glTF's custom attributes start with an underscore; the
//! `gltf` crate hands them over without it.

/// The vertex attribute's name as the `gltf` crate's `Semantic::Extras` holds it (the file
/// spells it `_HIKARI_INTERIOR`).
pub const ATTRIBUTE: &str = "HIKARI_INTERIOR";

/// The material `extras` value `hikari.interior`; `None` when absent. Other extras are
/// ignored; a value that is not a finite number in [0, 1] is an error.
pub fn material_interior(extras: &gltf::json::Extras) -> Result<Option<f32>, String> {
    let Some(raw) = extras else {
        return Ok(None);
    };
    let value: gltf::json::Value = gltf::json::deserialize::from_str(raw.get())
        .map_err(|e| format!("extras are not JSON: {e}"))?;
    match value.get("hikari").and_then(|h| h.get("interior")) {
        None => Ok(None),
        Some(v) => match v.as_f64() {
            Some(w) if (0.0..=1.0).contains(&w) => Ok(Some(w as f32)),
            _ => Err(format!(
                "extras hikari.interior must be a number from 0 (outdoors) to 1 (indoors), not {v}"
            )),
        },
    }
}

/// Checks the per-vertex values of `_HIKARI_INTERIOR`: each finite and in [0, 1].
pub fn check_vertices(values: &[f32]) -> Result<(), String> {
    match values.iter().position(|w| !(0.0..=1.0).contains(w)) {
        None => Ok(()),
        Some(i) => Err(format!(
            "_HIKARI_INTERIOR {i} is {}, outside [0, 1] (0 outdoors, 1 indoors)",
            values[i]
        )),
    }
}
