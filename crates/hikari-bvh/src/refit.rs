//! BLAS refit for deforming meshes: same topology, boxes recomputed bottom-up, wide nodes
//! re-quantized. Quality drifts as the mesh moves far from its build pose; correctness does not.

use crate::aabb::Aabb;
use crate::blas::Blas;
use crate::error::BvhError;
use crate::layout::{SlotKind, WIDTH};
use crate::wide::encode_boxes;
use glam::{Vec3, Vec3A};

impl Blas {
    /// Moves the BLAS to new vertex positions (same count and index buffer as the build). On
    /// error the BLAS is left unchanged. Triangles the build skipped stay skipped, and a
    /// triangle that becomes degenerate simply stops being hit.
    pub fn refit(&mut self, positions: &[Vec3]) -> Result<(), BvhError> {
        if positions.len() != self.vertex_count {
            return Err(BvhError::RefitVertexCount {
                mesh: self.name.clone(),
                expected: self.vertex_count,
                got: positions.len(),
            });
        }
        for tri in &self.triangles {
            let idx = self.indices[tri.primitive as usize];
            for &i in &idx {
                let p = positions[i as usize];
                if !p.is_finite() {
                    return Err(BvhError::NonFiniteVertex {
                        mesh: self.name.clone(),
                        triangle: tri.primitive as usize,
                        vertex: i,
                        value: p.into(),
                    });
                }
            }
        }
        for tri in &mut self.triangles {
            let idx = self.indices[tri.primitive as usize];
            tri.v0 = positions[idx[0] as usize].into();
            tri.v1 = positions[idx[1] as usize].into();
            tri.v2 = positions[idx[2] as usize].into();
        }
        // Breadth-first order puts every child after its parent, so one reverse sweep sees
        // children first.
        let mut node_bounds = vec![Aabb::EMPTY; self.nodes.len()];
        for n in (0..self.nodes.len()).rev() {
            let node = self.nodes[n];
            let mut boxes = [None; WIDTH];
            let mut all = Aabb::EMPTY;
            for (slot, b) in boxes.iter_mut().enumerate() {
                let child = match node.slot_kind(slot) {
                    SlotKind::Empty => continue,
                    SlotKind::Internal(c) => node_bounds[c as usize],
                    SlotKind::Leaf { first, count } => {
                        let mut bb = Aabb::EMPTY;
                        for t in &self.triangles[first as usize..(first + count) as usize] {
                            bb.grow_point(Vec3A::from(t.v0));
                            bb.grow_point(Vec3A::from(t.v1));
                            bb.grow_point(Vec3A::from(t.v2));
                        }
                        bb
                    }
                };
                all.grow(&child);
                *b = Some(child);
            }
            encode_boxes(&mut self.nodes[n], &boxes, node.imask());
            node_bounds[n] = all;
        }
        self.bounds = node_bounds.first().copied().unwrap_or(Aabb::EMPTY);
        Ok(())
    }

    /// Vertex count the BLAS was built from (what refit expects and what the throttling
    /// budget counts).
    pub fn vertex_count(&self) -> usize {
        self.vertex_count
    }
}
