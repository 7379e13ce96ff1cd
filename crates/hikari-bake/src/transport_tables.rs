//! The bake's scene as flat tables for a GPU twin of [`crate::transport`]: per BVH instance
//! (the index hits report) its object-to-world transform, constant albedo and where its
//! triangles and vertex colours lie; per triangle its object-space vertices and, for meshes
//! with vertex colours, the colours of its corners. Everything the hit shading of
//! [`crate::transport::probe_transport`] reads, laid out as 16-byte rows for a storage buffer.

use glam::Vec3;

use crate::scene_rays::SceneRays;
use crate::surfaces::SurfaceAlbedo;

/// Rows of [`TransportTables::instances`] per instance.
pub const INSTANCE_ROWS: usize = 5;
/// [`TransportTables::instances`] row 4, `w`: no vertex colours.
pub const NO_COLORS: u32 = u32::MAX;
/// Flag bit of row 4, `z`: the material is double-sided.
pub const DOUBLE_SIDED: u32 = 1;

/// Flat tables; all rows are 4 x 32 bits.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TransportTables {
    /// Per BVH instance, [`INSTANCE_ROWS`] rows: three rows of the object-to-world affine
    /// transform (row-major 3 x 4, metres); the constant albedo (linear RGB) and the sign of
    /// the transform's determinant; then, as `u32` bits, the first row of its triangles in
    /// `triangles`, the first row of its colours in `triangles` (or [`NO_COLORS`]), flags
    /// ([`DOUBLE_SIDED`]) and 0.
    pub instances: Vec<[u32; 4]>,
    /// Three rows (object-space `a`, `b`, `c`, `w` = 0) per triangle of each mesh with a
    /// BVH instance, then three rows (RGB of `a`, `b`, `c`, `w` = 1, or all 0 for a corner
    /// without a colour) per triangle of each such mesh with vertex colours.
    pub triangles: Vec<[f32; 4]>,
}

fn bits(v: [f32; 4]) -> [u32; 4] {
    v.map(f32::to_bits)
}

impl TransportTables {
    pub fn new(rays: &SceneRays, albedo: &SurfaceAlbedo) -> Self {
        let meshes = rays.triangles.len();
        // Row of each mesh's triangles and colours, filled for meshes some instance uses.
        let mut tri_row = vec![None; meshes];
        let mut color_row = vec![None; meshes];
        let mut triangles: Vec<[f32; 4]> = Vec::new();
        let used: Vec<usize> = rays
            .scene_instance
            .iter()
            .filter_map(|&i| rays.instance_mesh.get(i).copied())
            .collect();
        for &m in &used {
            if tri_row[m].is_some() || m >= meshes {
                continue;
            }
            tri_row[m] = Some(triangles.len() as u32);
            let p = &rays.positions[m];
            for t in &rays.triangles[m] {
                for &v in t {
                    let v = p.get(v as usize).copied().unwrap_or(Vec3::ZERO);
                    triangles.push([v.x, v.y, v.z, 0.0]);
                }
            }
        }
        for &m in &used {
            if color_row[m].is_some() {
                continue;
            }
            let Some(Some((indices, colors))) = albedo.mesh_colors.get(m) else {
                continue;
            };
            color_row[m] = Some(triangles.len() as u32);
            for t in indices.chunks_exact(3) {
                for &v in t {
                    // A corner without a colour makes the CPU fall back to white for the
                    // whole triangle; w = 0 marks it so the kernel does the same.
                    triangles.push(match colors.get(v as usize) {
                        Some(c) => [c.x, c.y, c.z, 1.0],
                        None => [0.0; 4],
                    });
                }
            }
        }
        let mut instances = Vec::with_capacity(rays.scene_instance.len() * INSTANCE_ROWS);
        for &i in &rays.scene_instance {
            let xf = rays.transforms[i];
            let mesh = rays.instance_mesh[i];
            let (m3, t) = (xf.matrix3, xf.translation);
            for r in 0..3 {
                let row = m3.row(r);
                instances.push(bits([row.x, row.y, row.z, t[r]]));
            }
            let (_, material) = albedo
                .instance_parts
                .get(i)
                .copied()
                .unwrap_or((mesh, usize::MAX));
            let base = albedo
                .material_albedo
                .get(material)
                .copied()
                .unwrap_or(Vec3::ZERO);
            let sign = m3.determinant().signum();
            instances.push(bits([base.x, base.y, base.z, sign]));
            let double_sided = albedo
                .material_double_sided
                .get(material)
                .copied()
                .unwrap_or(false);
            instances.push([
                tri_row[mesh].unwrap_or(0),
                color_row[mesh].unwrap_or(NO_COLORS),
                if double_sided { DOUBLE_SIDED } else { 0 },
                0,
            ]);
        }
        Self {
            instances,
            triangles,
        }
    }
}
