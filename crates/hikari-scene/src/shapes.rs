//! Simple meshes with flat normals, UVs and tangents.

use glam::{Vec2, Vec3};

use crate::Mesh;

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

    #[test]
    fn plane_faces_up() {
        outward_ccw(&plane(2.0));
        tangents_follow_uvs(&plane(2.0));
    }
}
