//! Simple meshes with normals, UVs (one unit per metre unless said otherwise) and tangents,
//! and [`append`] to merge them into bigger meshes.
//!
//! Every closed shape here is watertight by construction: neighbouring faces share whole
//! edges (no T-junctions), so ray tracers do not see cracks between them.

use glam::{Mat3, Mat4, Vec2, Vec3, Vec4};
use thiserror::Error;

use crate::{DEFAULT_INTERIOR, Mesh};

/// Why a shape could not be built from the parameters given.
#[derive(Debug, Error, PartialEq)]
pub enum ShapeError {
    #[error("{shape}: {what}")]
    Parameter { shape: &'static str, what: String },
    #[error("wall opening {index} {opening:?}: {what}")]
    Opening {
        index: usize,
        opening: Opening,
        what: String,
    },
}

/// Unit cube centred at the origin (sides 1 m), 24 vertices so each face has its own normal.
pub fn cube() -> Mesh {
    let mut m = Mesh {
        name: "cube".into(),
        ..Default::default()
    };
    for axis in 0..3 {
        for sign in [-1.0f32, 1.0] {
            let mut n = Vec3::ZERO;
            n[axis] = sign;
            // Two tangents that, with n, form a right-handed frame, so the winding is CCW
            // seen from outside.
            let u = Vec3::from_array(std::array::from_fn(|i| {
                if i == (axis + 1) % 3 { 1.0 } else { 0.0 }
            }));
            let v = n.cross(u);
            let base = m.positions.len() as u32;
            for c in [
                Vec2::new(-1.0, -1.0),
                Vec2::new(1.0, -1.0),
                Vec2::new(1.0, 1.0),
                Vec2::new(-1.0, 1.0),
            ] {
                m.positions.push(0.5 * (n + c.x * u + c.y * v));
                m.normals.push(n);
                // glTF's v runs down the image, so +v is along -v here and w = -1.
                m.uvs.push(Vec2::new(0.5 + 0.5 * c.x, 0.5 - 0.5 * c.y));
                m.tangents.push(u.extend(-1.0));
            }
            m.indices
                .extend([base, base + 1, base + 2, base, base + 2, base + 3]);
        }
    }
    m
}

/// Square in the XZ plane centred at the origin, facing +Y, `size` metres on a side.
pub fn plane(size: f32) -> Mesh {
    let h = size * 0.5;
    Mesh {
        name: "plane".into(),
        positions: vec![
            Vec3::new(-h, 0.0, -h),
            Vec3::new(-h, 0.0, h),
            Vec3::new(h, 0.0, h),
            Vec3::new(h, 0.0, -h),
        ],
        normals: vec![Vec3::Y; 4],
        indices: vec![0, 1, 2, 0, 2, 3],
        // One texture repeat per metre.
        uvs: vec![
            Vec2::new(0.0, 0.0),
            Vec2::new(0.0, size),
            Vec2::new(size, size),
            Vec2::new(size, 0.0),
        ],
        // u along +X, v along +Z: bitangent +Z = w * cross(+Y, +X) = w * -Z, so w = -1.
        tangents: vec![glam::Vec4::new(1.0, 0.0, 0.0, -1.0); 4],
        ..Default::default()
    }
}

/// Appends the parallelogram with corners `c[0], c[1], c[2], c[3]` (in that order around it),
/// its flat normal along `(c[1] - c[0]) x (c[3] - c[0])` (so it is counter-clockwise seen from
/// that side). The corners are used as given, so neighbouring faces built from the same
/// corner values share bit-identical vertices. UVs in metres: u along `c[1] - c[0]` from 0,
/// v against `c[3] - c[0]` from 0 (glTF's v runs down the image). Leaves the interior and
/// colour streams alone.
pub fn push_quad(m: &mut Mesh, c: [Vec3; 4]) {
    let (eu, ev) = (c[1] - c[0], c[3] - c[0]);
    let n = eu.cross(ev).normalize_or(Vec3::Y);
    let t = eu.normalize_or(n.any_orthonormal_vector());
    let (lu, lv) = (eu.length(), ev.length());
    let base = m.positions.len() as u32;
    for (p, uv) in c.into_iter().zip([
        Vec2::ZERO,
        Vec2::new(lu, 0.0),
        Vec2::new(lu, -lv),
        Vec2::new(0.0, -lv),
    ]) {
        m.positions.push(p);
        m.normals.push(n);
        m.uvs.push(uv);
        // +v is along -ev and cross(n, eu) is along +ev, hence w = -1.
        m.tangents.push(t.extend(-1.0));
    }
    m.indices
        .extend([base, base + 1, base + 2, base, base + 2, base + 3]);
}

/// Appends the triangle `a, b, c` (counter-clockwise seen from its front) with its flat normal;
/// UVs in metres in the plane of the triangle, u along `b - a`.
pub fn push_triangle(m: &mut Mesh, a: Vec3, b: Vec3, c: Vec3) {
    let n = (b - a).cross(c - a).normalize_or(Vec3::Y);
    let t = (b - a).normalize_or(n.any_orthonormal_vector());
    let up = n.cross(t);
    let base = m.positions.len() as u32;
    for p in [a, b, c] {
        m.positions.push(p);
        m.normals.push(n);
        m.uvs.push(Vec2::new((p - a).dot(t), -(p - a).dot(up)));
        m.tangents.push(t.extend(-1.0));
    }
    m.indices.extend([base, base + 1, base + 2]);
}

/// Axis-aligned box from corner `lo` to corner `hi`, faces outwards, UVs in metres.
pub fn cuboid(lo: Vec3, hi: Vec3) -> Mesh {
    let mut m = Mesh {
        name: "cuboid".into(),
        ..Default::default()
    };
    let c = |i: usize, j: usize, k: usize| {
        Vec3::new(
            if i == 0 { lo.x } else { hi.x },
            if j == 0 { lo.y } else { hi.y },
            if k == 0 { lo.z } else { hi.z },
        )
    };
    // Each face's corners counter-clockwise seen from outside.
    push_quad(&mut m, [c(0, 0, 0), c(0, 0, 1), c(0, 1, 1), c(0, 1, 0)]); // -x
    push_quad(&mut m, [c(1, 0, 1), c(1, 0, 0), c(1, 1, 0), c(1, 1, 1)]); // +x
    push_quad(&mut m, [c(0, 0, 0), c(1, 0, 0), c(1, 0, 1), c(0, 0, 1)]); // -y
    push_quad(&mut m, [c(0, 1, 1), c(1, 1, 1), c(1, 1, 0), c(0, 1, 0)]); // +y
    push_quad(&mut m, [c(1, 0, 0), c(0, 0, 0), c(0, 1, 0), c(1, 1, 0)]); // -z
    push_quad(&mut m, [c(0, 0, 1), c(1, 0, 1), c(1, 1, 1), c(0, 1, 1)]); // +z
    m
}

/// Closed box with the corners `origin + a ex + b ey + c ez` for a, b, c in {0, 1} (the
/// edges need not be orthogonal, nor right-handed); faces outwards, UVs 0 to 1 per face.
pub fn parallelepiped(origin: Vec3, ex: Vec3, ey: Vec3, ez: Vec3) -> Mesh {
    let mut m = Mesh::default();
    let to = Mat4::from_cols(
        ex.extend(0.0),
        ey.extend(0.0),
        ez.extend(0.0),
        origin.extend(1.0),
    );
    append(&mut m, &cuboid(Vec3::ZERO, Vec3::ONE), to);
    m.name = "parallelepiped".into();
    m
}

/// A [`frustum`] from point `a` (radius `r_a`) to point `b` (radius `r_b`), for posts, ropes
/// and branches.
pub fn rod(a: Vec3, b: Vec3, r_a: f32, r_b: f32, segments: u32) -> Result<Mesh, ShapeError> {
    let d = b - a;
    let f = frustum(r_a, r_b, d.length(), segments)?;
    let mut m = Mesh::default();
    let q = glam::Quat::from_rotation_arc(Vec3::Y, d.normalize());
    append(&mut m, &f, Mat4::from_rotation_translation(q, a));
    m.name = "rod".into();
    Ok(m)
}

/// Surface of revolution about +Y of the profile `(radius, height)` points, from the first
/// to the last, with `segments` steps around. Normals are smooth along the profile except
/// where a point is repeated (a crease); the outside is on the right of the profile's
/// direction of travel seen with the radius pointing right and height up (so a profile going
/// up at positive radius faces outwards, and one going out at the bottom faces down). Points
/// on the axis (radius 0) close the surface. u runs once around (0 to 1), v along the profile
/// (1 at the first point, 0 at the last); tangents follow u, around the axis.
pub fn lathe(profile: &[Vec2], segments: u32) -> Result<Mesh, ShapeError> {
    let err = |what: String| ShapeError::Parameter {
        shape: "lathe",
        what,
    };
    if profile.len() < 2 || segments < 3 {
        return Err(err(format!(
            "needs at least 2 profile points and 3 segments, has {} and {segments}",
            profile.len()
        )));
    }
    if let Some(p) = profile.iter().find(|p| !p.is_finite() || p.x < 0.0) {
        return Err(err(format!(
            "profile point {p} must be finite with radius >= 0"
        )));
    }
    let seg_normal = |k: usize| -> Option<Vec2> {
        let d = profile[k + 1] - profile[k];
        (d.length_squared() > 0.0).then(|| Vec2::new(d.y, -d.x).normalize())
    };
    let mut lengths = vec![0.0f32];
    for k in 1..profile.len() {
        lengths.push(lengths[k - 1] + profile[k].distance(profile[k - 1]));
    }
    let total = lengths[profile.len() - 1].max(f32::MIN_POSITIVE);
    let mut m = Mesh {
        name: "lathe".into(),
        ..Default::default()
    };
    let ring = segments + 1;
    for (k, p) in profile.iter().enumerate() {
        let before = k.checked_sub(1).and_then(seg_normal);
        let after = (k + 1 < profile.len()).then(|| seg_normal(k)).flatten();
        let n2 = match (before, after) {
            (Some(a), Some(b)) => (a + b).normalize_or(b),
            (Some(a), None) => a,
            (None, Some(b)) => b,
            (None, None) => Vec2::Y,
        };
        for s in 0..ring {
            let phi = std::f32::consts::TAU * s as f32 / segments as f32;
            let (sin, cos) = if s == segments {
                (0.0, 1.0)
            } else {
                phi.sin_cos()
            };
            // z = -r sin(phi) makes increasing phi, then up, counter-clockwise from outside.
            // Points on the axis are written as exact zeros (not -0.0), so the triangles
            // meeting there share bit-identical corners.
            m.positions.push(if p.x == 0.0 {
                Vec3::new(0.0, p.y, 0.0)
            } else {
                Vec3::new(p.x * cos, p.y, -p.x * sin)
            });
            m.normals.push(Vec3::new(n2.x * cos, n2.y, -n2.x * sin));
            m.uvs.push(Vec2::new(
                s as f32 / segments as f32,
                1.0 - lengths[k] / total,
            ));
            // +v runs back along the profile; cross(n, t) runs forward along it: w = -1.
            m.tangents.push(Vec4::new(-sin, 0.0, -cos, -1.0));
        }
    }
    for k in 0..profile.len() - 1 {
        if seg_normal(k).is_none() {
            continue;
        }
        for s in 0..segments {
            let a = k as u32 * ring + s;
            let (b, c, d) = (a + 1, a + 1 + ring, a + ring);
            // Skip the triangle that would collapse onto the axis.
            if profile[k].x > 0.0 {
                m.indices.extend([a, b, c]);
            }
            if profile[k + 1].x > 0.0 {
                m.indices.extend([a, c, d]);
            }
        }
    }
    Ok(m)
}

/// Closed cylinder (or cone, or truncated cone) about +Y from y = 0 to `height`, radius
/// `r_bottom` at the bottom and `r_top` at the top, smooth sides and flat caps.
pub fn frustum(r_bottom: f32, r_top: f32, height: f32, segments: u32) -> Result<Mesh, ShapeError> {
    if !(height > 0.0 && r_bottom.max(r_top) > 0.0) {
        return Err(ShapeError::Parameter {
            shape: "frustum",
            what: format!("height {height} and the larger radius must be positive"),
        });
    }
    let (b, t) = (Vec2::new(r_bottom, 0.0), Vec2::new(r_top, height));
    let mut profile = vec![Vec2::ZERO];
    if r_bottom > 0.0 {
        profile.extend([b, b]);
    }
    if r_top > 0.0 {
        profile.extend([t, t]);
    }
    profile.push(Vec2::new(0.0, height));
    let mut m = lathe(&profile, segments)?;
    m.name = "frustum".into();
    Ok(m)
}

/// Flat disc of `radius` in the XZ plane facing +Y, UVs in metres from the centre.
pub fn disc(radius: f32, segments: u32) -> Mesh {
    let segments = segments.max(3);
    let mut m = Mesh {
        name: "disc".into(),
        ..Default::default()
    };
    let mut push = |p: Vec3| {
        m.positions.push(p);
        m.normals.push(Vec3::Y);
        m.uvs.push(Vec2::new(p.x, p.z));
        // u along +x, v along +z = -cross(+y, +x): w = -1.
        m.tangents.push(Vec4::new(1.0, 0.0, 0.0, -1.0));
    };
    push(Vec3::ZERO);
    for s in 0..segments {
        let (sin, cos) = (std::f32::consts::TAU * s as f32 / segments as f32).sin_cos();
        push(Vec3::new(radius * cos, 0.0, -radius * sin));
    }
    for s in 0..segments {
        m.indices.extend([0, 1 + s, 1 + (s + 1) % segments]);
    }
    m
}

/// A rectangular hole in a [`wall`], in the wall's own frame: `x0..x1` along the wall,
/// `y0..y1` up from its bottom.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Opening {
    pub x0: f32,
    pub x1: f32,
    pub y0: f32,
    pub y1: f32,
}

/// Interior mask of a [`wall`]'s inside face (its -z side).
pub const WALL_INSIDE: f32 = 1.0;
/// Interior mask of a [`wall`]'s outside face (its +z side).
pub const WALL_OUTSIDE: f32 = 0.0;
/// Interior mask of a [`wall`]'s edges: its ends, top, bottom and the reveals of its openings,
/// which are seen from both sides.
pub const WALL_EDGE: f32 = DEFAULT_INTERIOR;

/// A closed wall slab with rectangular holes through it (doors, windows).
///
/// Frame: x along the wall from 0 to `length`, y up from 0 to `height`, z through it from
/// `-thickness / 2` (inside) to `thickness / 2` (outside). Per-vertex interior mask:
/// [`WALL_INSIDE`] on the inside face, [`WALL_OUTSIDE`] on the outside face, [`WALL_EDGE`]
/// elsewhere. Openings must lie within the wall (a door may reach the bottom, y0 = 0) and
/// may touch or overlap each other.
///
/// The faces are cut along one grid through every opening edge, so neighbouring faces share
/// whole edges: the slab is watertight.
pub fn wall(
    length: f32,
    height: f32,
    thickness: f32,
    openings: &[Opening],
) -> Result<Mesh, ShapeError> {
    if !(length > 0.0
        && height > 0.0
        && thickness > 0.0
        && (length * height * thickness).is_finite())
    {
        return Err(ShapeError::Parameter {
            shape: "wall",
            what: format!(
                "length {length}, height {height} and thickness {thickness} must be positive"
            ),
        });
    }
    for (index, o) in openings.iter().enumerate() {
        let bad = |what: &str| ShapeError::Opening {
            index,
            opening: *o,
            what: what.into(),
        };
        if !(o.x0.is_finite() && o.x1.is_finite() && o.y0.is_finite() && o.y1.is_finite()) {
            return Err(bad("has a non-finite edge"));
        }
        if !(0.0 < o.x0 && o.x0 < o.x1 && o.x1 < length) {
            return Err(bad(&format!(
                "needs 0 < x0 < x1 < {length} (the wall's length)"
            )));
        }
        if !(0.0 <= o.y0 && o.y0 < o.y1 && o.y1 < height) {
            return Err(bad(&format!(
                "needs 0 <= y0 < y1 < {height} (the wall's height)"
            )));
        }
    }
    let grid = |edges: &mut Vec<f32>| {
        edges.sort_by(f32::total_cmp);
        edges.dedup();
    };
    let mut xs = vec![0.0, length];
    let mut ys = vec![0.0, height];
    for o in openings {
        xs.extend([o.x0, o.x1]);
        ys.extend([o.y0, o.y1]);
    }
    grid(&mut xs);
    grid(&mut ys);
    let (nx, ny) = (xs.len() - 1, ys.len() - 1);
    // Cell (i, j) spans xs[i]..xs[i+1], ys[j]..ys[j+1]; outside the grid counts as empty.
    let solid = |i: isize, j: isize| -> bool {
        if i < 0 || j < 0 || i >= nx as isize || j >= ny as isize {
            return false;
        }
        let (i, j) = (i as usize, j as usize);
        let (cx, cy) = (0.5 * (xs[i] + xs[i + 1]), 0.5 * (ys[j] + ys[j + 1]));
        !openings
            .iter()
            .any(|o| o.x0 < cx && cx < o.x1 && o.y0 < cy && cy < o.y1)
    };
    let mut m = Mesh {
        name: "wall".into(),
        ..Default::default()
    };
    let (zi, zo) = (-0.5 * thickness, 0.5 * thickness);
    let quad = |m: &mut Mesh, c: [Vec3; 4], mask: f32| {
        push_quad(m, c);
        m.interior.extend([mask; 4]);
    };
    for i in 0..nx {
        for j in 0..ny {
            if !solid(i as isize, j as isize) {
                continue;
            }
            let (x0, x1, y0, y1) = (xs[i], xs[i + 1], ys[j], ys[j + 1]);
            let p = |x: f32, y: f32, z: f32| Vec3::new(x, y, z);
            quad(
                &mut m,
                [p(x0, y0, zo), p(x1, y0, zo), p(x1, y1, zo), p(x0, y1, zo)],
                WALL_OUTSIDE,
            );
            quad(
                &mut m,
                [p(x1, y0, zi), p(x0, y0, zi), p(x0, y1, zi), p(x1, y1, zi)],
                WALL_INSIDE,
            );
            let (ii, jj) = (i as isize, j as isize);
            if !solid(ii - 1, jj) {
                let c = [p(x0, y0, zi), p(x0, y0, zo), p(x0, y1, zo), p(x0, y1, zi)];
                quad(&mut m, c, WALL_EDGE);
            }
            if !solid(ii + 1, jj) {
                let c = [p(x1, y0, zo), p(x1, y0, zi), p(x1, y1, zi), p(x1, y1, zo)];
                quad(&mut m, c, WALL_EDGE);
            }
            if !solid(ii, jj - 1) {
                let c = [p(x0, y0, zi), p(x1, y0, zi), p(x1, y0, zo), p(x0, y0, zo)];
                quad(&mut m, c, WALL_EDGE);
            }
            if !solid(ii, jj + 1) {
                let c = [p(x0, y1, zo), p(x1, y1, zo), p(x1, y1, zi), p(x0, y1, zi)];
                quad(&mut m, c, WALL_EDGE);
            }
        }
    }
    Ok(m)
}

/// Closed triangular prism for a gable end: the triangle (0, 0), (`base`, 0),
/// (`base` / 2, `height`) in the XY plane, `thickness` deep in z centred on 0.
pub fn gable(base: f32, height: f32, thickness: f32) -> Mesh {
    let mut m = Mesh {
        name: "gable".into(),
        ..Default::default()
    };
    let (zi, zo) = (-0.5 * thickness, 0.5 * thickness);
    let (a, b, c) = (
        Vec3::new(0.0, 0.0, zo),
        Vec3::new(base, 0.0, zo),
        Vec3::new(0.5 * base, height, zo),
    );
    let (ab, bb, cb) = (a.with_z(zi), b.with_z(zi), c.with_z(zi));
    push_triangle(&mut m, a, b, c);
    push_triangle(&mut m, bb, ab, cb);
    push_quad(&mut m, [ab, bb, b, a]); // bottom
    push_quad(&mut m, [b, bb, cb, c]); // right slope
    push_quad(&mut m, [c, cb, ab, a]); // left slope
    m
}

/// Appends `src` to `dst`, transformed by `transform` (positions by the matrix, normals by
/// its inverse transpose, tangents re-orthogonalised; a mirroring transform flips windings
/// and tangent signs). A per-vertex stream present in only one of the two is filled in the
/// other with the value that means the same as its absence: UV (0, 0), any tangent, white,
/// [`DEFAULT_INTERIOR`].
pub fn append(dst: &mut Mesh, src: &Mesh, transform: Mat4) {
    let (nd, ns) = (dst.positions.len(), src.positions.len());
    let linear = Mat3::from_mat4(transform);
    let normal_matrix = linear.inverse().transpose();
    let mirror = linear.determinant() < 0.0;
    let base = nd as u32;
    let normals: Vec<Vec3> = src
        .normals
        .iter()
        .map(|n| (normal_matrix * *n).normalize_or(*n))
        .collect();
    let any_tangent = |n: &Vec3| n.any_orthonormal_vector().extend(1.0);

    let tangents: Vec<Vec4> = if src.tangents.is_empty() {
        normals.iter().map(any_tangent).collect()
    } else {
        src.tangents
            .iter()
            .zip(&normals)
            .map(|(t, n)| {
                let v = linear * t.truncate();
                let v = v - n * n.dot(v);
                let w = if mirror { -t.w } else { t.w };
                v.try_normalize().map_or(any_tangent(n), |v| v.extend(w))
            })
            .collect()
    };
    let dst_has = |len: usize| nd > 0 && len > 0;
    if dst_has(dst.tangents.len()) || !src.tangents.is_empty() {
        if !dst_has(dst.tangents.len()) {
            dst.tangents = dst.normals.iter().map(any_tangent).collect();
        }
        dst.tangents.extend(tangents);
    }
    if dst_has(dst.uvs.len()) || !src.uvs.is_empty() {
        dst.uvs.resize(nd, Vec2::ZERO);
        if src.uvs.is_empty() {
            dst.uvs.resize(nd + ns, Vec2::ZERO);
        } else {
            dst.uvs.extend(&src.uvs);
        }
    }
    if dst_has(dst.interior.len()) || !src.interior.is_empty() {
        dst.interior.resize(nd, DEFAULT_INTERIOR);
        if src.interior.is_empty() {
            dst.interior.resize(nd + ns, DEFAULT_INTERIOR);
        } else {
            dst.interior.extend(&src.interior);
        }
    }
    if (nd > 0 && dst.colors.is_some()) || src.colors.is_some() {
        let c = dst.colors.get_or_insert_with(Vec::new);
        c.resize(nd, Vec4::ONE);
        match &src.colors {
            Some(s) => c.extend(s),
            None => c.resize(nd + ns, Vec4::ONE),
        }
    }
    dst.positions
        .extend(src.positions.iter().map(|p| transform.transform_point3(*p)));
    dst.normals.extend(normals);
    for t in src.indices.chunks_exact(3) {
        let [a, b, c] = [t[0], t[1], t[2]].map(|i| i + base);
        dst.indices
            .extend(if mirror { [a, c, b] } else { [a, b, c] });
    }
}
#[cfg(test)]
mod tests {
    use super::*;

    /// The tangent frame agrees with the UVs: bitangent along +v.
    fn tangents_follow_uvs(m: &Mesh) {
        for t in m.indices.chunks(3) {
            let [a, b, c] = [0, 1, 2].map(|i| t[i] as usize);
            let (e1, e2) = (
                m.positions[b] - m.positions[a],
                m.positions[c] - m.positions[a],
            );
            let (d1, d2) = (m.uvs[b] - m.uvs[a], m.uvs[c] - m.uvs[a]);
            let r = 1.0 / (d1.x * d2.y - d2.x * d1.y);
            let dpdu = (e1 * d2.y - e2 * d1.y) * r;
            let dpdv = (e2 * d1.x - e1 * d2.x) * r;
            let tan = m.tangents[a];
            let bitangent = tan.w * m.normals[a].cross(tan.truncate());
            assert!(
                dpdu.normalize().dot(tan.truncate()) > 0.99,
                "{dpdu} vs {tan}"
            );
            assert!(
                dpdv.normalize().dot(bitangent) > 0.99,
                "{dpdv} vs {bitangent}"
            );
        }
    }

    fn outward_ccw(m: &Mesh) {
        for t in m.indices.chunks(3) {
            let [a, b, c] = [0, 1, 2].map(|i| m.positions[t[i] as usize]);
            let geometric = (b - a).cross(c - a).normalize();
            let shading = m.normals[t[0] as usize];
            assert!(geometric.dot(shading) > 0.99, "{geometric} vs {shading}");
        }
    }

    #[test]
    fn cube_faces_wind_counter_clockwise_seen_from_outside() {
        let m = cube();
        assert_eq!(m.indices.len(), 36);
        outward_ccw(&m);
        tangents_follow_uvs(&m);
        for p in &m.positions {
            assert_eq!(p.abs().max_element(), 0.5);
        }
    }

    /// Every directed edge (by exact positions) is matched by the opposite one: closed, and
    /// with consistent winding, and free of T-junctions.
    fn watertight(m: &Mesh) {
        use std::collections::HashMap;
        let key = |p: Vec3| p.to_array().map(f32::to_bits);
        let mut edges: HashMap<([u32; 3], [u32; 3]), i32> = HashMap::new();
        for t in m.indices.chunks(3) {
            for k in 0..3 {
                let (a, b) = (
                    m.positions[t[k] as usize],
                    m.positions[t[(k + 1) % 3] as usize],
                );
                *edges.entry((key(a), key(b))).or_default() += 1;
            }
        }
        for ((a, b), n) in &edges {
            assert_eq!(
                edges.get(&(*b, *a)),
                Some(n),
                "edge {a:?} -> {b:?} unmatched in {}",
                m.name
            );
        }
    }

    /// Volume by the divergence theorem; positive when the faces point outwards.
    fn volume(m: &Mesh) -> f64 {
        m.indices
            .chunks(3)
            .map(|t| {
                let [a, b, c] = [0, 1, 2].map(|i| m.positions[t[i] as usize].as_dvec3());
                a.dot(b.cross(c)) / 6.0
            })
            .sum()
    }

    /// Each triangle's winding agrees with its vertices' normals (within 60 degrees, for
    /// smooth shading on coarse curves); degenerate triangles are not allowed.
    fn winding_follows_normals(m: &Mesh) {
        for t in m.indices.chunks(3) {
            let [a, b, c] = [0, 1, 2].map(|i| m.positions[t[i] as usize]);
            let g = (b - a).cross(c - a);
            assert!(g.length() > 1e-9, "degenerate triangle {t:?} in {}", m.name);
            for i in t {
                let n = m.normals[*i as usize];
                assert!(
                    g.normalize().dot(n) > 0.5,
                    "{} vs {n} in {}",
                    g.normalize(),
                    m.name
                );
            }
        }
    }

    #[test]
    fn cuboid_is_closed_with_its_volume() {
        let m = cuboid(Vec3::new(-1.0, 0.5, 2.0), Vec3::new(2.0, 1.5, 2.5));
        watertight(&m);
        outward_ccw(&m);
        tangents_follow_uvs(&m);
        assert!((volume(&m) - 3.0 * 1.0 * 0.5).abs() < 1e-5);
    }

    #[test]
    fn wall_with_openings_is_closed_and_has_the_right_volume_and_mask() {
        let openings = [
            Opening {
                x0: 0.5,
                x1: 1.4,
                y0: 0.0,
                y1: 1.9,
            },
            Opening {
                x0: 2.0,
                x1: 3.0,
                y0: 0.9,
                y1: 1.6,
            },
            // Overlapping the previous one: the union is cut out.
            Opening {
                x0: 2.5,
                x1: 3.5,
                y0: 1.2,
                y1: 1.8,
            },
        ];
        let (l, h, t) = (5.0, 2.6, 0.12);
        let m = wall(l, h, t, &openings).unwrap();
        watertight(&m);
        outward_ccw(&m);
        tangents_follow_uvs(&m);
        // Union of the holes: 0.9 x 1.9 + 1.0 x 0.7 + 1.0 x 0.6 - overlap 0.5 x 0.4.
        let holes = 0.9 * 1.9 + 0.7 + 0.6 - 0.5 * 0.4;
        let want = (l * h - holes) * t;
        assert!(
            (volume(&m) - want as f64).abs() < 1e-4,
            "{} vs {want}",
            volume(&m)
        );
        let (lo, hi) = m.bounds().unwrap();
        assert_eq!(
            (lo, hi),
            (Vec3::new(0.0, 0.0, -0.06), Vec3::new(5.0, 2.6, 0.06))
        );
        for ((p, n), mask) in m.positions.iter().zip(&m.normals).zip(&m.interior) {
            let want = if n.z > 0.999 {
                0.0
            } else if n.z < -0.999 {
                1.0
            } else {
                0.5
            };
            assert_eq!(*mask, want, "at {p} facing {n}");
        }
        // A point in the door is not inside the slab: no face of the front crosses it.
        let in_door = |p: &Vec3| p.x > 0.5 && p.x < 1.4 && p.y < 1.9 && p.z.abs() > 0.05;
        assert!(
            m.indices
                .chunks(3)
                .all(|tri| !tri.iter().all(|i| in_door(&m.positions[*i as usize])))
        );
    }

    #[test]
    fn wall_rejects_bad_openings() {
        let o = |x0, x1, y0, y1| Opening { x0, x1, y0, y1 };
        let e = wall(
            3.0,
            2.5,
            0.12,
            &[o(1.0, 2.0, 0.5, 1.0), o(2.5, 3.5, 0.5, 1.0)],
        )
        .unwrap_err();
        assert!(e.to_string().contains("opening 1"), "{e}");
        assert!(wall(3.0, 2.5, 0.12, &[o(1.0, 2.0, 0.5, 2.5)]).is_err());
        assert!(wall(3.0, 2.5, 0.12, &[o(1.0, f32::NAN, 0.5, 1.0)]).is_err());
        assert!(wall(0.0, 2.5, 0.12, &[]).is_err());
    }

    #[test]
    fn lathe_and_frustum_are_closed_with_the_polygon_volume() {
        let n = 24;
        // A regular n-gon of circumradius r has area n/2 r^2 sin(2 pi / n).
        let k = 0.5 * n as f64 * (std::f64::consts::TAU / n as f64).sin();
        let cyl = frustum(0.5, 0.5, 2.0, n).unwrap();
        watertight(&cyl);
        winding_follows_normals(&cyl);
        // Tangents run around the axis; the bitangent (+v) back along the profile, which
        // on the side of a cylinder is down.
        for ((p, n), t) in cyl.positions.iter().zip(&cyl.normals).zip(&cyl.tangents) {
            assert!(
                t.truncate().dot(*n).abs() < 1e-5 && (t.truncate().length() - 1.0).abs() < 1e-5
            );
            if p.x != 0.0 || p.z != 0.0 {
                assert!(t.truncate().dot(Vec3::Y.cross(*p).normalize()) > 0.9999);
            }
            if n.y == 0.0 {
                assert!((t.w * n.cross(t.truncate())).dot(Vec3::NEG_Y) > 0.9999);
            }
        }
        assert!((volume(&cyl) - k * 0.25 * 2.0).abs() < 1e-5);
        // A cone: a third of the prism.
        let cone = frustum(0.5, 0.0, 3.0, n).unwrap();
        watertight(&cone);
        winding_follows_normals(&cone);
        assert!((volume(&cone) - k * 0.25 * 3.0 / 3.0).abs() < 1e-5);
        // Truncated: h/3 (A0 + sqrt(A0 A1) + A1).
        let f = frustum(0.6, 0.3, 1.0, n).unwrap();
        watertight(&f);
        let want = 1.0 / 3.0 * k * (0.36 + 0.18 + 0.09);
        assert!((volume(&f) - want).abs() < 1e-5);
        assert!(frustum(0.0, 0.0, 1.0, n).is_err());
        assert!(lathe(&[Vec2::ZERO], n).is_err());
        assert!(lathe(&[Vec2::ZERO, Vec2::new(-1.0, 0.0)], n).is_err());
    }

    #[test]
    fn parallelepiped_and_rod_are_closed_with_their_volumes() {
        let (ex, ey, ez) = (
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(0.5, 1.0, 0.0),
            Vec3::new(0.0, 0.3, -0.7),
        );
        // Left-handed edges on purpose: still outwards.
        let p = parallelepiped(Vec3::new(1.0, 2.0, 3.0), ex, ey, ez);
        watertight(&p);
        outward_ccw(&p);
        assert!((volume(&p) - ex.dot(ey.cross(ez)).abs() as f64).abs() < 1e-5);
        let (a, b) = (Vec3::new(1.0, 0.0, 0.0), Vec3::new(1.0, 3.0, 4.0));
        let r = rod(a, b, 0.2, 0.2, 16).unwrap();
        watertight(&r);
        winding_follows_normals(&r);
        let k = 8.0 * (std::f64::consts::TAU / 16.0).sin();
        assert!((volume(&r) - k * 0.04 * 5.0).abs() < 1e-4, "{}", volume(&r));
        // The axis runs from a to b: every vertex is within the radius of the segment.
        for v in &r.positions {
            let t = ((*v - a).dot(b - a) / 25.0).clamp(0.0, 1.0);
            assert!(v.distance(a + t * (b - a)) <= 0.2 + 1e-5);
        }
    }

    #[test]
    fn gable_is_a_closed_triangular_prism() {
        let g = gable(4.0, 1.5, 0.12);
        watertight(&g);
        outward_ccw(&g);
        assert!((volume(&g) - 0.5 * 4.0 * 1.5 * 0.12).abs() < 1e-5);
    }

    #[test]
    fn disc_faces_up() {
        let d = disc(2.0, 16);
        outward_ccw(&d);
        tangents_follow_uvs(&d);
        let n = 16.0f64;
        let area: f64 = d
            .indices
            .chunks(3)
            .map(|t| {
                let [a, b, c] = [0, 1, 2].map(|i| d.positions[t[i] as usize].as_dvec3());
                0.5 * (b - a).cross(c - a).y
            })
            .sum();
        assert!((area - 0.5 * n * 4.0 * (std::f64::consts::TAU / n).sin()).abs() < 1e-5);
    }

    #[test]
    fn append_transforms_and_fills_streams() {
        let mut dst = plane(1.0);
        let mut w = wall(2.0, 1.0, 0.1, &[]).unwrap();
        w.colors = Some(vec![Vec4::new(1.0, 0.0, 0.0, 1.0); w.positions.len()]);
        let rot = Mat4::from_rotation_translation(
            glam::Quat::from_rotation_y(0.7),
            Vec3::new(1.0, 2.0, 3.0),
        );
        append(&mut dst, &w, rot);
        assert_eq!(dst.positions.len(), 4 + w.positions.len());
        assert_eq!(dst.interior.len(), dst.positions.len());
        assert_eq!(dst.interior[..4], [DEFAULT_INTERIOR; 4]);
        assert_eq!(dst.colors.as_ref().unwrap()[0], Vec4::ONE);
        assert_eq!(
            dst.colors.as_ref().unwrap()[4],
            Vec4::new(1.0, 0.0, 0.0, 1.0)
        );
        outward_ccw(&dst);
        tangents_follow_uvs(&dst);
        // A mirror keeps faces pointing outwards and tangents agreeing with UVs.
        let mut mirrored = Mesh::default();
        append(
            &mut mirrored,
            &cuboid(Vec3::ZERO, Vec3::ONE),
            Mat4::from_scale(Vec3::new(-1.0, 2.0, 1.0)),
        );
        outward_ccw(&mirrored);
        tangents_follow_uvs(&mirrored);
        assert!((volume(&mirrored) - 2.0).abs() < 1e-5);
    }

    #[test]
    fn plane_faces_up() {
        outward_ccw(&plane(2.0));
        tangents_follow_uvs(&plane(2.0));
    }
}
