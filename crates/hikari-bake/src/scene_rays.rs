//! The scene as the bake's ray tracer sees it: one BLAS per scene mesh with triangles, one
//! instance per scene instance, a TLAS over all of them, traced with hikari-bvh's CPU traversal
//! (the same traversal the GPU kernel twins). Static geometry only: deforming meshes are baked
//! in their rest pose. Alpha cut-outs count as opaque (the alpha test needs the textures, which
//! live with the renderer); this makes foliage a little darker than it should be.

use glam::{Affine3A, Vec3};
use hikari_bvh::{Blas, BuildOptions, Instance, Ray, Tlas, TraversalStacks, traverse};
use hikari_scene::Scene;

use crate::error::BakeError;

/// A surface hit with the side the ray arrived from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfaceHit {
    /// Distance along the (unit) ray, metres.
    pub t: f32,
    /// World-space unit geometric normal of the front face (glTF winding: counter-clockwise,
    /// reversed under a mirroring transform).
    pub normal: Vec3,
    /// The ray arrived from behind the front face.
    pub back_face: bool,
    /// Index of the scene instance hit.
    pub instance: usize,
    /// Triangle of the instance's mesh hit.
    pub primitive: usize,
    /// Barycentric weights of the triangle's second and third vertices at the hit.
    pub uv: [f32; 2],
}

pub struct SceneRays {
    blases: Vec<Blas>,
    tlas: Tlas,
    /// Per TLAS instance index: the scene instance it stands for.
    pub(crate) scene_instance: Vec<usize>,
    /// Per scene mesh: its triangles, for normals of hits.
    pub(crate) triangles: Vec<Vec<[u32; 3]>>,
    pub(crate) positions: Vec<Vec<Vec3>>,
    /// Per scene instance: its transform and mesh.
    pub(crate) transforms: Vec<Affine3A>,
    pub(crate) instance_mesh: Vec<usize>,
}

impl SceneRays {
    /// Builds the BVH of every instance of a mesh with at least one triangle. A scene with no
    /// geometry gives an empty tracer that every ray escapes.
    pub fn build(scene: &Scene) -> Result<Self, BakeError> {
        scene
            .validate()
            .map_err(|e| BakeError::Scene(e.to_string()))?;
        let triangles: Vec<Vec<[u32; 3]>> = scene
            .meshes
            .iter()
            .map(|m| {
                m.indices
                    .chunks_exact(3)
                    .map(|t| [t[0], t[1], t[2]])
                    .collect()
            })
            .collect();
        let options = BuildOptions::default();
        let mut blas_of_mesh = vec![None; scene.meshes.len()];
        let mut blases = Vec::new();
        for (i, (m, tris)) in scene.meshes.iter().zip(&triangles).enumerate() {
            if tris.is_empty() {
                continue;
            }
            match Blas::build(&m.name, &m.positions, tris, &options) {
                Ok(b) => {
                    blas_of_mesh[i] = Some(blases.len() as u32);
                    blases.push(b);
                }
                // A mesh made only of degenerate triangles cannot block a ray.
                Err(hikari_bvh::BvhError::NoValidTriangles { .. }) => {}
                Err(e) => return Err(e.into()),
            }
        }
        let mut instances = Vec::new();
        let mut scene_instance = Vec::new();
        for (i, inst) in scene.instances.iter().enumerate() {
            if let Some(b) = blas_of_mesh.get(inst.mesh).copied().flatten() {
                instances.push(Instance::new(Affine3A::from_mat4(inst.transform), b));
                scene_instance.push(i);
            }
        }
        let selected: Vec<u32> = (0..instances.len() as u32).collect();
        let tlas = Tlas::build(&instances, &selected, &blases)?;
        Ok(Self {
            blases,
            tlas,
            scene_instance,
            triangles,
            positions: scene.meshes.iter().map(|m| m.positions.clone()).collect(),
            transforms: scene
                .instances
                .iter()
                .map(|i| Affine3A::from_mat4(i.transform))
                .collect(),
            instance_mesh: scene.instances.iter().map(|i| i.mesh).collect(),
        })
    }

    /// The BLASes the TLAS's instance records point at (for a GPU copy of the same BVH).
    pub fn blases(&self) -> &[Blas] {
        &self.blases
    }

    /// The TLAS; hits report its instance records' `instance_index`, an index into
    /// [`SceneRays::scene_instances`].
    pub fn tlas(&self) -> &Tlas {
        &self.tlas
    }

    /// Per TLAS instance: the scene instance it stands for.
    pub fn scene_instances(&self) -> &[usize] {
        &self.scene_instance
    }

    /// Whether anything lies along `dir` from `origin` (any hit, `t` in `t_min..infinity`).
    pub fn occluded(
        &self,
        origin: Vec3,
        dir: Vec3,
        t_min: f32,
        stacks: &mut TraversalStacks,
    ) -> bool {
        if self.tlas.instances.is_empty() {
            return false;
        }
        let ray = Ray::new(origin, dir, t_min, f32::INFINITY);
        traverse::any_hit(
            &self.tlas.nodes,
            &self.tlas.instances,
            &self.blases,
            &ray,
            stacks,
        )
    }

    /// The nearest surface along unit `dir` from `origin` beyond `t_min`.
    pub fn closest(
        &self,
        origin: Vec3,
        dir: Vec3,
        t_min: f32,
        stacks: &mut TraversalStacks,
    ) -> Option<SurfaceHit> {
        if self.tlas.instances.is_empty() {
            return None;
        }
        let ray = Ray::new(origin, dir, t_min, f32::INFINITY);
        let hit = traverse::closest_hit(
            &self.tlas.nodes,
            &self.tlas.instances,
            &self.blases,
            &ray,
            stacks,
        )?;
        let inst = *self.scene_instance.get(hit.instance as usize)?;
        let normal = self.face_normal(inst, hit.primitive as usize)?;
        Some(SurfaceHit {
            t: hit.t,
            normal,
            back_face: normal.dot(dir) > 0.0,
            instance: inst,
            primitive: hit.primitive as usize,
            uv: [hit.u, hit.v],
        })
    }

    /// World position of `hit` on its triangle (from the barycentrics, not `origin + t dir`,
    /// which loses the surface on long rays) and the largest coordinate magnitude of the
    /// triangle's world vertices, metres: the scale of the traversal's rounding near it.
    pub fn hit_point(&self, hit: &SurfaceHit) -> Option<(Vec3, f32)> {
        let xf = self.transforms.get(hit.instance)?;
        let mesh = *self.instance_mesh.get(hit.instance)?;
        let [a, b, c] = *self.triangles.get(mesh)?.get(hit.primitive)?;
        let p = self.positions.get(mesh)?;
        let [a, b, c] = [a, b, c].map(|i| xf.transform_point3(p[i as usize]));
        let [u, v] = hit.uv;
        let scale = a.abs().max(b.abs()).max(c.abs()).max_element();
        Some((a + (b - a) * u + (c - a) * v, scale))
    }

    fn face_normal(&self, instance: usize, primitive: usize) -> Option<Vec3> {
        let xf = self.transforms.get(instance)?;
        let mesh = *self.instance_mesh.get(instance)?;
        let [a, b, c] = *self.triangles.get(mesh)?.get(primitive)?;
        let p = self.positions.get(mesh)?;
        let [a, b, c] = [a, b, c].map(|i| xf.transform_point3(p[i as usize]));
        // A mirroring transform reverses the winding; glTF keeps the front face by flipping.
        let sign = xf.matrix3.determinant().signum();
        let n = (b - a).cross(c - a) * sign;
        let n = n.normalize_or_zero();
        (n != Vec3::ZERO).then_some(n)
    }
}
