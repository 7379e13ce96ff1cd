//! Expected traversal work of a wide BVH by the surface area heuristic, on the boxes the kernel
//! decodes: the quality figure the builders are judged by (with rays traced on the CPU).

use crate::aabb::Aabb;
use crate::layout::{SlotKind, WIDTH, WideNode};

/// SAH cost of a tree: each wide node visited and each primitive (triangle or instance) tested
/// costs 1, weighted by the chance that a random ray through the root box enters the box above
/// it, the ratio of surface areas. Boxes are the quantized child boxes as decoded.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SahCost {
    /// Wide nodes: the root (always visited, 1) plus each internal child's weight.
    pub nodes: f64,
    /// Primitives: each leaf child's weight times its primitive count.
    pub prims: f64,
}

impl SahCost {
    pub fn total(&self) -> f64 {
        self.nodes + self.prims
    }
}

/// [`SahCost`] of a tree whose root is `nodes[0]` (zero for an empty tree). When the root box
/// has no area (everything at one point), every box counts as entered.
pub fn sah_cost(nodes: &[WideNode]) -> SahCost {
    let Some(root) = nodes.first() else {
        return SahCost::default();
    };
    let mut root_box = Aabb::EMPTY;
    for slot in 0..WIDTH {
        if root.slot_kind(slot) != SlotKind::Empty {
            root_box.grow(&root.child_box(slot));
        }
    }
    let root_area = root_box.half_area() as f64;
    let weight = |node: &WideNode, slot: usize| {
        if root_area > 0.0 {
            node.child_box(slot).half_area() as f64 / root_area
        } else {
            1.0
        }
    };
    let mut cost = SahCost {
        nodes: 1.0,
        prims: 0.0,
    };
    for node in nodes {
        for slot in 0..WIDTH {
            match node.slot_kind(slot) {
                SlotKind::Internal(_) => cost.nodes += weight(node, slot),
                SlotKind::Leaf { count, .. } => cost.prims += weight(node, slot) * count as f64,
                SlotKind::Empty => {}
            }
        }
    }
    cost
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Blas, BuildOptions, Instance, Mesh, Tlas};
    use glam::{Affine3A, Vec3};

    #[test]
    fn two_unit_cubes_cost_the_root_plus_their_area_ratios() {
        // Unit cubes at x = 0..1 and x = 3..4: the root box is 4 x 1 x 1 (half area 4 + 1 + 4),
        // each cube has half area 3, and every plane lies on the quantization grid (steps of
        // 1/32 in x, 1/128 in y and z), so decoded boxes are exact.
        let cube = Mesh::new(
            vec![Vec3::ZERO, Vec3::X, Vec3::ONE, Vec3::new(0.0, 1.0, 1.0)],
            vec![[0, 1, 2], [0, 2, 3]],
        );
        let blas = vec![Blas::from_mesh("cube", &cube, &BuildOptions::default()).unwrap()];
        let instances = [
            Instance::new(Affine3A::IDENTITY, 0),
            Instance::new(Affine3A::from_translation(Vec3::new(3.0, 0.0, 0.0)), 0),
        ];
        let tlas = Tlas::build(&instances, &[0, 1], &blas).unwrap();
        let cost = sah_cost(&tlas.nodes);
        assert_eq!(cost.nodes, 1.0);
        assert!((cost.prims - 2.0 * 3.0 / 9.0).abs() < 1e-12, "{cost:?}");
        assert_eq!(sah_cost(&[]), SahCost::default());
    }
}
