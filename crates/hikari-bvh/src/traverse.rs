//! CPU traversal of the compressed wide layout: the twin of the WGSL kernel, bit for bit in its
//! decisions (same node decoding, same visiting order, same triangle test). The child-box test
//! runs four slots per SIMD operation, with exactly the per-slot arithmetic of the kernel
//! ([`intersect_node_scalar`] is the literal per-slot form, tested equal).
//!
//! The loop follows Ylitie et al. 2017: the traversal state is a *node group* — a base index
//! plus a mask of children still to visit — rather than a single node. Visiting a node yields a
//! new node group (its hit internal children) and a *triangle group* (its hit leaf triangles);
//! triangles are tested at once, the rest of the current group goes on the stack. Each stack
//! entry is two u32: `[child_base, hits << 24 | imask]`.

use crate::layout::{Hit, INTERNAL_BIT_BASE, InstanceRecord, Ray, TriangleRecord, WideNode};
use crate::triangle::{PreparedRay, intersect_record};
use glam::Vec4;

/// The far distance of a child box is scaled up by this before the overlap test, which absorbs
/// the rounding of the reassociated slab formula `q * (step * inv_dir) + (origin - o) * inv_dir`.
pub const BOX_FAR_SCALE: f32 = 1.0 + 1.0 / (1 << 20) as f32;

const NODE_BITS: u32 = 0xFF00_0000;

/// Tests the ray against the 8 quantized child boxes. Returns the internal-child hit bits at
/// position `slot ^ octant` (0..8) and the triangle bits (0..24, relative to `prim_base`).
///
/// Four slots per SIMD lane group; each lane performs exactly the scalar operations of
/// [`intersect_node_scalar`] (a multiply, then an add; `max`/`min` are exact), so the decisions
/// are the same for every finite ray.
#[inline]
pub fn intersect_node(node: &WideNode, r: &PreparedRay, t_max: f32) -> (u32, u32) {
    let s = node.scale();
    let adj_scale = [
        s[0] * r.inv_dir[0],
        s[1] * r.inv_dir[1],
        s[2] * r.inv_dir[2],
    ];
    let adj_origin = [
        (node.origin[0] - r.origin[0]) * r.inv_dir[0],
        (node.origin[1] - r.origin[1]) * r.inv_dir[1],
        (node.origin[2] - r.origin[2]) * r.inv_dir[2],
    ];
    let lo = [planes(node.lo_x), planes(node.lo_y), planes(node.lo_z)];
    let hi = [planes(node.hi_x), planes(node.hi_y), planes(node.hi_z)];
    let mut near = [Vec4::splat(r.t_min); 2];
    let mut far = [Vec4::splat(t_max); 2];
    for a in 0..3 {
        // A negative direction meets the upper plane first.
        let (qn, qf) = if r.octant & (1 << a) != 0 {
            (hi[a], lo[a])
        } else {
            (lo[a], hi[a])
        };
        let sc = Vec4::splat(adj_scale[a]);
        let or = Vec4::splat(adj_origin[a]);
        for h in 0..2 {
            near[h] = near[h].max(qn[h] * sc + or);
            far[h] = far[h].min(qf[h] * sc + or);
        }
    }
    let scale = Vec4::splat(BOX_FAR_SCALE);
    let overlap =
        near[0].cmple(far[0] * scale).bitmask() | (near[1].cmple(far[1] * scale).bitmask() << 4);
    let mut occupied = 0u32;
    for slot in 0..8 {
        occupied |= ((node.meta(slot) != 0) as u32) << slot;
    }
    let imask = node.imask() as u32;
    let mut hits = overlap & occupied;
    let mut node_hits = 0u32;
    let mut tri_hits = 0u32;
    while hits != 0 {
        let slot = hits.trailing_zeros();
        hits &= hits - 1;
        if imask & (1 << slot) != 0 {
            node_hits |= 1 << (slot ^ r.octant);
        } else {
            let meta = node.meta(slot as usize) as u32;
            let count = (meta >> 5).count_ones();
            tri_hits |= ((1u32 << count) - 1) << (meta & 0x1F);
        }
    }
    (node_hits, tri_hits)
}

/// The eight 8-bit planes of one field as floats, slots 0..4 and 4..8.
#[inline]
fn planes(words: [u32; 2]) -> [Vec4; 2] {
    let b = |w: u32, k: u32| ((w >> (8 * k)) & 0xFF) as f32;
    [
        Vec4::new(
            b(words[0], 0),
            b(words[0], 1),
            b(words[0], 2),
            b(words[0], 3),
        ),
        Vec4::new(
            b(words[1], 0),
            b(words[1], 1),
            b(words[1], 2),
            b(words[1], 3),
        ),
    ]
}

/// [`intersect_node`] one slot at a time, literally as the kernel's per-slot loop reads; kept
/// as the reference the 4-wide version is tested against.
#[inline]
pub fn intersect_node_scalar(node: &WideNode, r: &PreparedRay, t_max: f32) -> (u32, u32) {
    let s = node.scale();
    let adj_scale = [
        s[0] * r.inv_dir[0],
        s[1] * r.inv_dir[1],
        s[2] * r.inv_dir[2],
    ];
    let adj_origin = [
        (node.origin[0] - r.origin[0]) * r.inv_dir[0],
        (node.origin[1] - r.origin[1]) * r.inv_dir[1],
        (node.origin[2] - r.origin[2]) * r.inv_dir[2],
    ];
    let imask = node.imask() as u32;
    let mut node_hits = 0u32;
    let mut tri_hits = 0u32;
    for slot in 0..8 {
        let meta = node.meta(slot) as u32;
        if meta == 0 {
            continue;
        }
        let (lo, hi) = node.quantized(slot);
        let mut t_near = r.t_min;
        let mut t_far = t_max;
        for a in 0..3 {
            // A negative direction meets the upper plane first.
            let (qn, qf) = if r.octant & (1 << a) != 0 {
                (hi[a], lo[a])
            } else {
                (lo[a], hi[a])
            };
            let tn = qn as f32 * adj_scale[a] + adj_origin[a];
            let tf = qf as f32 * adj_scale[a] + adj_origin[a];
            t_near = t_near.max(tn);
            t_far = t_far.min(tf);
        }
        if t_near <= t_far * BOX_FAR_SCALE {
            if imask & (1 << slot) != 0 {
                node_hits |= 1 << (slot as u32 ^ r.octant);
            } else {
                let count = (meta >> 5).count_ones();
                tri_hits |= ((1u32 << count) - 1) << (meta & 0x1F);
            }
        }
    }
    (node_hits, tri_hits)
}

/// A traversal stack plus work counters (node visits and primitive tests), kept for reuse
/// across rays.
#[derive(Clone, Debug, Default)]
pub struct Stack {
    entries: Vec<[u32; 2]>,
    /// Wide nodes visited (box tests of 8 children each) since creation.
    pub nodes_visited: u64,
    /// Leaf primitives (triangles or instances) tested since creation.
    pub prims_tested: u64,
}

/// Walks one tree, calling `leaf(prim_index, &mut t_max)` for every primitive of every hit leaf;
/// `leaf` returns true to stop. Returns true if stopped. The stack is left as it was found.
#[inline]
pub(crate) fn walk<F: FnMut(u32, &mut f32) -> bool>(
    nodes: &[WideNode],
    r: &PreparedRay,
    t_max: &mut f32,
    stack: &mut Stack,
    mut leaf: F,
) -> bool {
    if nodes.is_empty() {
        return false;
    }
    let Stack {
        entries: stack,
        nodes_visited,
        prims_tested,
    } = stack;
    let base = stack.len();
    // A synthetic group whose only member is the root: slot 0 with imask bit 0, announced at
    // bit position 0 ^ octant.
    let mut group = [0u32, (1 << (INTERNAL_BIT_BASE + r.octant)) | 1];
    loop {
        let mut tri_group = [0u32, 0u32];
        if group[1] & NODE_BITS != 0 {
            let pos = (group[1] >> INTERNAL_BIT_BASE).trailing_zeros();
            group[1] &= !(1 << (INTERNAL_BIT_BASE + pos));
            let slot = pos ^ r.octant;
            let below = group[1] & 0xFF & ((1u32 << slot) - 1);
            let index = group[0] + below.count_ones();
            if group[1] & NODE_BITS != 0 {
                stack.push(group);
            }
            let node = &nodes[index as usize];
            *nodes_visited += 1;
            let (node_hits, tri_hits) = intersect_node(node, r, *t_max);
            group = [
                node.child_base,
                (node_hits << INTERNAL_BIT_BASE) | node.imask() as u32,
            ];
            tri_group = [node.prim_base, tri_hits];
        }
        while tri_group[1] != 0 {
            let k = tri_group[1].trailing_zeros();
            tri_group[1] &= tri_group[1] - 1;
            *prims_tested += 1;
            if leaf(tri_group[0] + k, t_max) {
                stack.truncate(base);
                return true;
            }
        }
        if group[1] & NODE_BITS == 0 {
            if stack.len() == base {
                return false;
            }
            group = stack.pop().unwrap();
        }
    }
}

/// The filter of the unfiltered traversals: with it, the opacity test of a candidate hit folds
/// away, so scenes without cut-outs pay nothing for them.
#[inline(always)]
fn accept_all(_instance: u32, _primitive: u32, _u: f32, _v: f32) -> bool {
    true
}

/// Closest hit within one BLAS, updating `t_max` and `best`. A hit on a triangle marked
/// [`crate::layout::TRIANGLE_NON_OPAQUE`] counts only if `accept(instance, primitive, u, v)`
/// says so; a rejected one leaves `t_max` alone, so the walk goes on past it.
#[inline]
#[allow(clippy::too_many_arguments)]
pub(crate) fn closest_in_blas<F: FnMut(u32, u32, f32, f32) -> bool>(
    nodes: &[WideNode],
    tris: &[TriangleRecord],
    r: &PreparedRay,
    t_max: &mut f32,
    best: &mut Hit,
    instance: u32,
    stack: &mut Stack,
    accept: &mut F,
) {
    walk(nodes, r, t_max, stack, |i, t_max| {
        let tri = &tris[i as usize];
        if let Some((t, u, v)) = intersect_record(r, tri, *t_max)
            && (tri.is_opaque() || accept(instance, tri.primitive, u, v))
        {
            *t_max = t;
            *best = Hit {
                t,
                u,
                v,
                primitive: tri.primitive,
                instance,
                _pad: [0; 3],
            };
        }
        false
    });
}

/// Any accepted hit within one BLAS (see [`closest_in_blas`] for `accept`).
#[inline]
pub(crate) fn any_in_blas<F: FnMut(u32, u32, f32, f32) -> bool>(
    nodes: &[WideNode],
    tris: &[TriangleRecord],
    r: &PreparedRay,
    t_max: f32,
    instance: u32,
    stack: &mut Stack,
    accept: &mut F,
) -> bool {
    let mut t = t_max;
    walk(nodes, r, &mut t, stack, |i, t_max| {
        let tri = &tris[i as usize];
        match intersect_record(r, tri, *t_max) {
            Some((_, u, v)) => tri.is_opaque() || accept(instance, tri.primitive, u, v),
            None => false,
        }
    })
}

/// Closest hit in one BLAS (object space); hits report `instance`.
///
/// Both windings count: there is no back-face culling (GI, AO and shadow rays must see both
/// sides of a leaf or a wall), so a glTF `doubleSided: false` material matters only to the
/// rasteriser; a caller that wants single-sided hits can compare the triangle's normal with
/// the ray direction itself.
pub fn closest_hit_blas(
    nodes: &[WideNode],
    tris: &[TriangleRecord],
    ray: &Ray,
    instance: u32,
    stack: &mut Stack,
) -> Option<Hit> {
    closest_hit_blas_filtered(nodes, tris, ray, instance, stack, accept_all)
}

/// [`closest_hit_blas`] where hits on non-opaque triangles count only if
/// `accept(instance, primitive, u, v)` returns true (`u`, `v` the weights of `v1` and `v2`).
/// `accept` is called for non-opaque triangles only, possibly for candidates that a closer
/// hit later replaces, and in no particular order.
pub fn closest_hit_blas_filtered(
    nodes: &[WideNode],
    tris: &[TriangleRecord],
    ray: &Ray,
    instance: u32,
    stack: &mut Stack,
    mut accept: impl FnMut(u32, u32, f32, f32) -> bool,
) -> Option<Hit> {
    let r = PreparedRay::new(ray);
    let mut t_max = ray.t_max;
    let mut best = Hit::NONE;
    closest_in_blas(
        nodes,
        tris,
        &r,
        &mut t_max,
        &mut best,
        instance,
        stack,
        &mut accept,
    );
    best.is_hit().then_some(best)
}

/// True if anything in one BLAS is hit with `t_min < t < t_max` (both windings).
pub fn any_hit_blas(
    nodes: &[WideNode],
    tris: &[TriangleRecord],
    ray: &Ray,
    stack: &mut Stack,
) -> bool {
    any_hit_blas_filtered(nodes, tris, ray, 0, stack, accept_all)
}

/// [`any_hit_blas`] where a hit on a non-opaque triangle counts only if `accept` returns true
/// (see [`closest_hit_blas_filtered`]); `instance` is what `accept` is told.
pub fn any_hit_blas_filtered(
    nodes: &[WideNode],
    tris: &[TriangleRecord],
    ray: &Ray,
    instance: u32,
    stack: &mut Stack,
    mut accept: impl FnMut(u32, u32, f32, f32) -> bool,
) -> bool {
    let r = PreparedRay::new(ray);
    any_in_blas(nodes, tris, &r, ray.t_max, instance, stack, &mut accept)
}

/// The ray in the instance's object space. Directions are not renormalized, so `t` is shared.
#[inline]
pub fn to_object_space(inst: &InstanceRecord, ray: &Ray, t_max: f32) -> Ray {
    let m = &inst.world_to_object;
    let o = ray.origin;
    let d = ray.dir;
    let row = |r: &[f32; 4], v: [f32; 3]| r[0] * v[0] + r[1] * v[1] + r[2] * v[2];
    Ray {
        origin: [
            row(&m[0], o) + m[0][3],
            row(&m[1], o) + m[1][3],
            row(&m[2], o) + m[2][3],
        ],
        t_min: ray.t_min,
        dir: [row(&m[0], d), row(&m[1], d), row(&m[2], d)],
        t_max,
    }
}

/// Reusable traversal stacks (one per tree level; the kernel uses one array with a base index).
#[derive(Clone, Debug, Default)]
pub struct TraversalStacks {
    pub tlas: Stack,
    pub blas: Stack,
}

/// Two-level closest hit: TLAS leaves are instances, entered with the ray in object space.
pub fn closest_hit(
    tlas_nodes: &[WideNode],
    instances: &[InstanceRecord],
    blases: &[crate::Blas],
    ray: &Ray,
    stacks: &mut TraversalStacks,
) -> Option<Hit> {
    closest_hit_filtered(tlas_nodes, instances, blases, ray, stacks, accept_all)
}

/// [`closest_hit`] with a filter for hits on non-opaque triangles, told the instance index (as
/// hits report it) and the primitive (see [`closest_hit_blas_filtered`]).
pub fn closest_hit_filtered(
    tlas_nodes: &[WideNode],
    instances: &[InstanceRecord],
    blases: &[crate::Blas],
    ray: &Ray,
    stacks: &mut TraversalStacks,
    mut accept: impl FnMut(u32, u32, f32, f32) -> bool,
) -> Option<Hit> {
    let r = PreparedRay::new(ray);
    let mut t_max = ray.t_max;
    let mut best = Hit::NONE;
    let TraversalStacks { tlas, blas } = stacks;
    walk(tlas_nodes, &r, &mut t_max, tlas, |i, t_max| {
        let inst = &instances[i as usize];
        // A BLAS list other than the one the TLAS was built with is a caller bug; missing
        // the instance beats a panic in the middle of a bake.
        let Some(b) = blases.get(inst.blas_index as usize) else {
            return false;
        };
        let obj = PreparedRay::new(&to_object_space(inst, ray, *t_max));
        closest_in_blas(
            &b.nodes,
            &b.triangles,
            &obj,
            t_max,
            &mut best,
            inst.instance_index,
            blas,
            &mut accept,
        );
        false
    });
    best.is_hit().then_some(best)
}

/// Two-level any hit with `t_min < t < ray.t_max`.
pub fn any_hit(
    tlas_nodes: &[WideNode],
    instances: &[InstanceRecord],
    blases: &[crate::Blas],
    ray: &Ray,
    stacks: &mut TraversalStacks,
) -> bool {
    any_hit_filtered(tlas_nodes, instances, blases, ray, stacks, accept_all)
}

/// [`any_hit`] with a filter for hits on non-opaque triangles (see [`closest_hit_filtered`]).
pub fn any_hit_filtered(
    tlas_nodes: &[WideNode],
    instances: &[InstanceRecord],
    blases: &[crate::Blas],
    ray: &Ray,
    stacks: &mut TraversalStacks,
    mut accept: impl FnMut(u32, u32, f32, f32) -> bool,
) -> bool {
    let r = PreparedRay::new(ray);
    let mut t_max = ray.t_max;
    let TraversalStacks { tlas, blas } = stacks;
    walk(tlas_nodes, &r, &mut t_max, tlas, |i, t_max| {
        let inst = &instances[i as usize];
        let Some(b) = blases.get(inst.blas_index as usize) else {
            return false;
        };
        let obj = PreparedRay::new(&to_object_space(inst, ray, *t_max));
        any_in_blas(
            &b.nodes,
            &b.triangles,
            &obj,
            *t_max,
            inst.instance_index,
            blas,
            &mut accept,
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::SplitMix64;

    #[test]
    fn simd_node_test_matches_the_scalar_one() {
        let mesh = crate::Mesh::random_soup(5, 2000, 10.0, 2.0);
        let blas = crate::Blas::from_mesh("m", &mesh, &Default::default()).unwrap();
        let mut rng = SplitMix64::new(6);
        for i in 0..3000 {
            let o = glam::Vec3::new(
                rng.range(-12.0, 12.0),
                rng.range(-12.0, 12.0),
                rng.range(-12.0, 12.0),
            );
            let mut d = glam::Vec3::new(
                rng.range(-1.0, 1.0),
                rng.range(-1.0, 1.0),
                rng.range(-1.0, 1.0),
            );
            if i % 4 == 0 {
                d.x = 0.0;
            }
            let t_max = if i % 3 == 0 {
                rng.range(0.0, 20.0)
            } else {
                f32::INFINITY
            };
            let r = PreparedRay::new(&Ray::new(o, d, rng.range(0.0, 2.0), t_max));
            for node in blas.nodes.iter().step_by(7) {
                assert_eq!(
                    intersect_node(node, &r, t_max),
                    intersect_node_scalar(node, &r, t_max)
                );
            }
        }
    }
}
