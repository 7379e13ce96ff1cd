//! KHR_texture_transform: an `offset`, `rotation` and `scale` (and an optional `texCoord`
//! override) on a material's textureInfo, applied here to the primitive's UVs at load
//! (docs/gltf.md).
//!
//! The extension object is read from the raw JSON that the `gltf` crate keeps for extensions
//! it does not parse (its `extensions` feature), not through the crate's own
//! `KHR_texture_transform` feature: with that feature a malformed value fails the whole file in
//! the JSON parser, with no material, slot or field in the message, and normal and occlusion
//! textures have no typed transform at all. So that feature must stay off for this crate.

use glam::{Mat2, Vec2, Vec3, Vec4};

/// The extension's name, as a key of a textureInfo's `extensions`.
pub const EXTENSION: &str = "KHR_texture_transform";

/// `uv' = T * R * S * uv`, the extension's affine transform of texture coordinates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UvTransform {
    pub offset: Vec2,
    /// Radians, "counter-clockwise in UV space" as the extension means it (see [`Self::apply`]).
    pub rotation: f32,
    pub scale: Vec2,
}

impl Default for UvTransform {
    fn default() -> Self {
        Self::IDENTITY
    }
}

impl UvTransform {
    pub const IDENTITY: Self = Self {
        offset: Vec2::ZERO,
        rotation: 0.0,
        scale: Vec2::ONE,
    };

    pub fn is_identity(&self) -> bool {
        *self == Self::IDENTITY
    }

    /// The linear part `R * S`. R is the extension's rotation as its implementations and its
    /// example (offset [0, 1], rotation pi/2, scale 0.5 shows the lower left quadrant of the
    /// image) apply it: rows `[cos r, sin r]` and `[-sin r, cos r]`, i.e.
    /// `u' = cos(r) u + sin(r) v`, `v' = -sin(r) u + cos(r) v`; counter-clockwise with V
    /// pointing down the image, as glTF's UVs do. (The GLSL listing in the extension text,
    /// read column-major, gives the transpose; KhronosGroup/glTF issue #1563.)
    pub fn linear(&self) -> Mat2 {
        let (s, c) = self.rotation.sin_cos();
        // Columns of R: (c, -s) and (s, c).
        let r = Mat2::from_cols(Vec2::new(c, -s), Vec2::new(s, c));
        r * Mat2::from_diagonal(self.scale)
    }

    pub fn apply(&self, uv: Vec2) -> Vec2 {
        self.linear() * uv + self.offset
    }

    /// Whether `self` and `other` map UVs the same way, to within what writing the numbers with
    /// a few digits changes.
    pub fn approx_eq(&self, other: &Self) -> bool {
        let close = |a: f32, b: f32| (a - b).abs() <= 1e-6 * (1.0 + a.abs().max(b.abs()));
        close(self.offset.x, other.offset.x)
            && close(self.offset.y, other.offset.y)
            && close(self.rotation, other.rotation)
            && close(self.scale.x, other.scale.x)
            && close(self.scale.y, other.scale.y)
    }

    /// Re-expresses tangents given for the untransformed UVs for the transformed ones. A
    /// tangent is dP/du and its bitangent `cross(normal, tangent.xyz) * w` is dP/dv (glTF's
    /// definition); with `uv' = A uv + t`, `dP/du'` and `dP/dv'` are the columns of
    /// `[dP/du dP/dv] * A^-1`. Unit tangent and bitangent stand in for the true derivatives,
    /// which is exact where the texture mapping does not stretch one direction more than the
    /// other (and for any rotation and uniform scale). The adjugate replaces the inverse: its
    /// positive multiple gives the same directions, and a singular `A` divides by nothing.
    pub fn transform_tangents(&self, normals: &[Vec3], tangents: &mut [Vec4]) {
        let a = self.linear();
        let det = a.determinant();
        // adj(A) = det * A^-1; multiplied by sign(det), a positive multiple of A^-1.
        let adj = Mat2::from_cols(
            Vec2::new(a.y_axis.y, -a.x_axis.y),
            Vec2::new(-a.y_axis.x, a.x_axis.x),
        ) * if det < 0.0 { -1.0 } else { 1.0 };
        for (t, &n) in tangents.iter_mut().zip(normals) {
            let tan = t.truncate();
            let sign = if t.w < 0.0 { -1.0 } else { 1.0 };
            let bit = n.cross(tan) * sign;
            // Column j of [T B] * M is T * M[0][j] + B * M[1][j] (row, column).
            let du = tan * adj.x_axis.x + bit * adj.x_axis.y;
            let dv = tan * adj.y_axis.x + bit * adj.y_axis.y;
            let du = (du - n * n.dot(du)).normalize_or(tan);
            let w = if n.cross(du).dot(dv) < 0.0 { -1.0 } else { 1.0 };
            *t = du.extend(w);
        }
    }
}

/// The extension object of one textureInfo (`None`: the textureInfo has none), checked
/// against the extension's schema: the transform, identity where a member is absent, and the
/// `texCoord` override if present. An error names the member and what is wrong with it.
pub fn parse(value: Option<&gltf::json::Value>) -> Result<(UvTransform, Option<u32>), String> {
    use gltf::json::Value;
    let Some(value) = value else {
        return Ok((UvTransform::IDENTITY, None));
    };
    let Value::Object(obj) = value else {
        return Err(format!("{EXTENSION} must be a JSON object, not {value}"));
    };
    let number = |field: &str, v: &Value| -> Result<f32, String> {
        match v.as_f64().map(|x| x as f32) {
            Some(x) if x.is_finite() => Ok(x),
            _ => Err(format!(
                "{EXTENSION}.{field} must be a finite number, not {v}"
            )),
        }
    };
    let pair = |field: &str| -> Result<Option<Vec2>, String> {
        let Some(v) = obj.get(field) else {
            return Ok(None);
        };
        let bad = || format!("{EXTENSION}.{field} must be an array of 2 finite numbers, not {v}");
        let items = v.as_array().filter(|a| a.len() == 2).ok_or_else(bad)?;
        let x = number(field, &items[0]).map_err(|_| bad())?;
        let y = number(field, &items[1]).map_err(|_| bad())?;
        Ok(Some(Vec2::new(x, y)))
    };
    let mut t = UvTransform::IDENTITY;
    if let Some(offset) = pair("offset")? {
        t.offset = offset;
    }
    if let Some(scale) = pair("scale")? {
        t.scale = scale;
    }
    if let Some(v) = obj.get("rotation") {
        t.rotation = number("rotation", v)?;
    }
    let tex_coord = match obj.get("texCoord") {
        None => None,
        Some(v) => Some(
            v.as_u64()
                .and_then(|x| u32::try_from(x).ok())
                .ok_or_else(|| format!("{EXTENSION}.texCoord must be an integer >= 0, not {v}"))?,
        ),
    };
    Ok((t, tex_coord))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn identity_leaves_uvs_alone_and_the_parts_compose_in_the_extensions_order() {
        let uv = Vec2::new(0.25, 0.75);
        assert_eq!(UvTransform::IDENTITY.apply(uv), uv);
        // Scale first, then rotate, then offset: (1, 0) scaled by 2 is (2, 0), rotated by
        // pi/2 is (0, -2), offset by (0.5, 0) is (0.5, -2).
        let t = UvTransform {
            offset: Vec2::new(0.5, 0.0),
            rotation: std::f32::consts::FRAC_PI_2,
            scale: Vec2::splat(2.0),
        };
        assert!((t.apply(Vec2::X) - Vec2::new(0.5, -2.0)).length() < 1e-6);
    }
}
