//! Collapse of a binary BVH into the compressed 8-wide layout, and the child-box quantization
//! shared by build and refit.

use crate::aabb::Aabb;
use crate::build_sah::BinaryBvh;
use crate::build_sah::parallel::{collect_pieces, map_largest_first};
use crate::layout::{META_INTERNAL, WIDTH, WideNode, leaf_meta};
use glam::{Vec3A, Vec4};

/// Result of a collapse: nodes in depth-first order of their allocation (every child index is
/// larger than its parent's, which refit relies on) and, in leaf order, positions into `BinaryBvh::prims`.
pub struct WideBvh {
    pub nodes: Vec<WideNode>,
    pub leaf_prims: Vec<u32>,
    /// Number of nodes on the longest root-to-leaf path.
    pub depth: u32,
}

/// Subtrees of at most this many primitives are collapsed as independent jobs (in parallel when
/// threads are available) and appended in a fixed order, so the layout never depends on the
/// thread count.
const JOB_PRIMS: u32 = 8 * 1024;

/// A pending wide node: binary node, wide node index, depth.
type Pending = (u32, u32, u32);

pub fn collapse(bin: &BinaryBvh, max_leaf: usize, threads: usize) -> WideBvh {
    let max_leaf = max_leaf.clamp(1, crate::layout::MAX_LEAF_TRIANGLES);
    let mut nodes = vec![WideNode::default()];
    let mut leaf_prims = Vec::new();
    let mut jobs = Vec::new();
    // Small trees are not worth splitting into jobs (nor spawning threads for).
    let split_into_jobs = bin.nodes[0].prims > 2 * JOB_PRIMS;
    if !split_into_jobs {
        // Wide nodes hold 4 primitives or more on average: room enough that the arrays are
        // not regrown.
        nodes.reserve(bin.prims.len() / 3 + 1);
        leaf_prims.reserve(bin.prims.len());
    }
    let mut depth = emit(
        bin,
        max_leaf,
        vec![(0, 0, 1)],
        &mut nodes,
        &mut leaf_prims,
        split_into_jobs.then_some(&mut jobs),
    );
    if jobs.is_empty() {
        return WideBvh {
            nodes,
            leaf_prims,
            depth,
        };
    }

    // Each job collapses into its own arrays with its root at local index 0.
    let results = map_largest_first(
        threads,
        jobs.clone(),
        |job| bin.nodes[job.0 as usize].prims as usize,
        |job| {
            let prims = bin.nodes[job.0 as usize].prims as usize;
            // Wide nodes hold 5 to 6 primitives on average: room enough not to grow.
            let mut n = Vec::with_capacity(prims / 4 + 1);
            n.push(WideNode::default());
            let mut p = Vec::with_capacity(prims);
            let d = emit(bin, max_leaf, vec![(job.0, 0, job.2)], &mut n, &mut p, None);
            (n, p, d)
        },
    );

    // Appended in job order: local node i >= 1 moves to node_base + i - 1, and the local root
    // replaces the job's placeholder. The copies run in parallel into preallocated arrays.
    let mut node_ranges = Vec::with_capacity(jobs.len());
    let mut prim_ranges = Vec::with_capacity(jobs.len());
    let (mut node_end, mut prim_end) = (nodes.len(), leaf_prims.len());
    for (sub_nodes, sub_prims, sub_depth) in &results {
        depth = depth.max(*sub_depth);
        node_ranges.push(node_end..node_end + sub_nodes.len() - 1);
        prim_ranges.push(prim_end..prim_end + sub_prims.len());
        node_end += sub_nodes.len() - 1;
        prim_end += sub_prims.len();
    }
    let remap = |mut n: WideNode, node_base: usize, prim_base: usize| {
        n.child_base = node_base as u32 + n.child_base - 1;
        n.prim_base += prim_base as u32;
        n
    };
    for (i, (job, (sub_nodes, _, _))) in jobs.iter().zip(&results).enumerate() {
        nodes[job.1 as usize] = remap(sub_nodes[0], node_ranges[i].start, prim_ranges[i].start);
    }
    // Piece 0 is the top part; piece i + 1 is job i.
    node_ranges.insert(0, 0..nodes.len());
    prim_ranges.insert(0, 0..leaf_prims.len());
    let all_nodes = collect_pieces(threads, node_end, &node_ranges, |k| {
        let (src, bases) = if k == 0 {
            (&nodes[..], None)
        } else {
            let bases = (node_ranges[k].start, prim_ranges[k].start);
            (&results[k - 1].0[1..], Some(bases))
        };
        src.iter().map(move |&n| match bases {
            Some((nb, pb)) => remap(n, nb, pb),
            None => n,
        })
    });
    let all_prims = collect_pieces(threads, prim_end, &prim_ranges, |k| {
        if k == 0 {
            &leaf_prims
        } else {
            &results[k - 1].1
        }
        .iter()
        .copied()
    });
    WideBvh {
        nodes: all_nodes,
        leaf_prims: all_prims,
        depth,
    }
}

/// Emits wide nodes depth-first from `todo`; pending nodes whose subtree is small enough go to
/// `jobs` instead when given. Returns the deepest level emitted.
fn emit(
    bin: &BinaryBvh,
    max_leaf: usize,
    mut todo: Vec<Pending>,
    nodes: &mut Vec<WideNode>,
    leaf_prims: &mut Vec<u32>,
    mut jobs: Option<&mut Vec<Pending>>,
) -> u32 {
    let bn = &bin.nodes;
    // Depth-first: the binary nodes were laid out depth-first, so this order walks them almost
    // sequentially (breadth-first order made every binary node read a cache miss). Children are
    // still allocated, contiguously, when their parent is emitted, so every child index is
    // larger than its parent's.
    let mut depth = 1;
    while let Some((b, w, d)) = todo.pop() {
        if let Some(jobs) = jobs.as_mut()
            && w != 0
            && bn[b as usize].prims <= JOB_PRIMS
        {
            jobs.push((b, w, d));
            continue;
        }
        depth = depth.max(d);
        let bnode = &bn[b as usize];
        if bnode.is_leaf() && bnode.count as usize > max_leaf {
            nodes[w as usize] = leaf_bundle(bin, bnode, max_leaf, leaf_prims);
            continue;
        }
        // Open the binary subtree: repeatedly replace the internal child with the largest box
        // by its two children, which removes the most expected traversal work per slot.
        let mut open = [0u32; WIDTH];
        // Surface area of each open internal child; -1 for leaves, which are never opened.
        let mut area = [-1.0f32; WIDTH];
        let area_of = |c: u32| {
            let n = &bn[c as usize];
            if n.is_leaf() {
                -1.0
            } else {
                n.bounds.half_area()
            }
        };
        let mut n_open;
        if bn[b as usize].is_leaf() {
            open[0] = b;
            n_open = 1;
        } else {
            let f = bn[b as usize].first;
            open[0] = f;
            open[1] = f + 1;
            area[0] = area_of(f);
            area[1] = area_of(f + 1);
            n_open = 2;
        }
        while n_open < WIDTH {
            let mut best = usize::MAX;
            let mut best_area = -1.0;
            for (i, &a) in area[..n_open].iter().enumerate() {
                if a > best_area {
                    best_area = a;
                    best = i;
                }
            }
            if best == usize::MAX {
                break;
            }
            let f = bn[open[best] as usize].first;
            open[best] = f;
            open[n_open] = f + 1;
            area[best] = area_of(f);
            area[n_open] = area_of(f + 1);
            n_open += 1;
        }
        let open = &open[..n_open];

        let parent_center = bn[b as usize].bounds.center();
        let mut centers = [Vec3A::ZERO; WIDTH];
        for (c, &o) in centers.iter_mut().zip(open) {
            *c = bn[o as usize].bounds.center();
        }
        let slots = assign_slots(parent_center, &centers[..n_open]);

        let mut node = WideNode::default();
        let mut boxes = [None; WIDTH];
        let mut imask = 0u8;
        node.child_base = nodes.len() as u32;
        node.prim_base = leaf_prims.len() as u32;
        let mut leaf_offset = 0u32;
        let todo_start = todo.len();
        for slot in 0..WIDTH {
            let Some(ci) = slots[slot] else { continue };
            let ci = ci as usize;
            let c = open[ci];
            boxes[slot] = Some(bn[c as usize].bounds);
            if bn[c as usize].prims as usize > max_leaf {
                imask |= 1 << slot;
                node.set_meta(slot, META_INTERNAL | slot as u8);
                let child_w = nodes.len() as u32;
                nodes.push(WideNode::default());
                todo.push((c, child_w, d + 1));
            } else {
                let before = leaf_prims.len();
                gather_prims(bin, c, leaf_prims);
                let count = (leaf_prims.len() - before) as u32;
                node.set_meta(slot, leaf_meta(leaf_offset, count));
                leaf_offset += count;
            }
        }
        // Reversed so the lowest slot is popped, and emitted, first.
        todo[todo_start..].reverse();
        encode_boxes(&mut node, &boxes, imask);
        nodes[w as usize] = node;
    }
    depth
}

/// A node for a binary leaf holding more primitives than one leaf slot may (a binary tree built
/// with larger leaves than `max_leaf`): each slot takes a chunk of at most `max_leaf`.
fn leaf_bundle(
    bin: &BinaryBvh,
    leaf: &crate::build_sah::BinNode,
    max_leaf: usize,
    leaf_prims: &mut Vec<u32>,
) -> WideNode {
    let first = leaf.first as usize;
    let count = leaf.count as usize;
    debug_assert!(count <= WIDTH * max_leaf);
    // Chunks are runs along the leaf's widest axis, so each chunk stays compact.
    let mut order = [0u32; WIDTH * crate::layout::MAX_LEAF_TRIANGLES];
    let order = &mut order[..count];
    for (i, o) in order.iter_mut().enumerate() {
        *o = (first + i) as u32;
    }
    if max_leaf > 1 {
        let ext = leaf.bounds.extent();
        let axis = if ext.x >= ext.y && ext.x >= ext.z {
            0
        } else if ext.y >= ext.z {
            1
        } else {
            2
        };
        let key = |i: &u32| {
            let p = &bin.prims[*i as usize];
            (p.lo3() + p.hi3())[axis]
        };
        order.sort_by(|a, b| key(a).total_cmp(&key(b)));
    }
    let mut chunk_boxes = [Aabb::EMPTY; WIDTH];
    let mut centers = [Vec3A::ZERO; WIDTH];
    let chunks = count.div_ceil(max_leaf).min(WIDTH);
    for (k, b) in chunk_boxes[..chunks].iter_mut().enumerate() {
        for &i in &order[k * max_leaf..((k + 1) * max_leaf).min(count)] {
            let p = &bin.prims[i as usize];
            b.grow(&Aabb::new(p.lo3(), p.hi3()));
        }
        centers[k] = b.center();
    }
    let slots = assign_slots(leaf.bounds.center(), &centers[..chunks]);
    let mut node = WideNode {
        prim_base: leaf_prims.len() as u32,
        ..Default::default()
    };
    let mut boxes = [None; WIDTH];
    let mut offset = 0u32;
    for (slot, k) in slots.iter().enumerate() {
        let Some(k) = *k else { continue };
        let k = k as usize;
        let chunk = &order[k * max_leaf..((k + 1) * max_leaf).min(count)];
        leaf_prims.extend_from_slice(chunk);
        node.set_meta(slot, leaf_meta(offset, chunk.len() as u32));
        offset += chunk.len() as u32;
        boxes[slot] = Some(chunk_boxes[k]);
    }
    encode_boxes(&mut node, &boxes, 0);
    node
}

fn gather_prims(bin: &BinaryBvh, root: u32, out: &mut Vec<u32>) {
    // A subtree gathered here holds at most MAX_LEAF_TRIANGLES primitives, so its depth is tiny.
    let mut stack = [0u32; 2 * crate::layout::MAX_LEAF_TRIANGLES + 2];
    stack[0] = root;
    let mut sp = 1;
    while sp > 0 {
        sp -= 1;
        let i = stack[sp];
        let n = &bin.nodes[i as usize];
        if n.is_leaf() {
            out.extend(n.first..n.first + n.count);
        } else {
            stack[sp] = n.first + 1;
            stack[sp + 1] = n.first;
            sp += 2;
        }
    }
}

/// Places each child in the slot whose octant corner its centre points to, relative to the
/// parent's centre. Traversal visits slots in the order `slot ^ ray_octant`, so a ray meets
/// children roughly front to back without sorting. Children with the strongest preference (the
/// largest centre offset) choose first, each taking the free slot whose corner direction best
/// matches its offset; returns, per slot, the child index (at most 8 children).
pub(crate) fn assign_slots(parent_center: Vec3A, centers: &[Vec3A]) -> [Option<u8>; WIDTH] {
    // Eight lanes as two `Vec4`s throughout: every comparison here is a coin flip for a branch
    // predictor, and this runs for every node of every TLAS rebuild.
    let n = centers.len().min(WIDTH);
    // Unused lanes hold NaN, which compares neither greater nor equal.
    let mut strength = [f32::NAN; WIDTH];
    // Per child, its scores for the eight slots (two lane groups) and the first slot of its
    // highest score: the slot it takes if still free when its turn comes, which is usually so.
    // Computed for all children up front, where they do not wait on each other.
    let mut scores = [(Vec4::ZERO, Vec4::ZERO); WIDTH];
    let mut favourite = [0u32; WIDTH];
    // Corner direction of each slot: +1 on axes whose bit is set, -1 otherwise.
    const X: Vec4 = Vec4::new(-1.0, 1.0, -1.0, 1.0);
    const Y: Vec4 = Vec4::new(-1.0, -1.0, 1.0, 1.0);
    for c in 0..n {
        let off = centers[c] - parent_center;
        let o = if off.is_finite() { off } else { Vec3A::ZERO };
        strength[c] = o.abs().element_sum();
        // Dot products with all eight corner directions; multiplying by +-1 is exact, so each
        // score is exactly the sum of the signed offsets (x, then y, then z). Offsets are
        // finite, so no score is NaN.
        let xy = X * o.x + Y * o.y;
        let z = Vec4::splat(o.z);
        let (lo, hi) = (xy - z, xy + z);
        scores[c] = (lo, hi);
        let best = Vec4::splat(lo.max(hi).max_element());
        favourite[c] = (lo.cmpeq(best).bitmask() | hi.cmpeq(best).bitmask() << 4).trailing_zeros();
    }
    let lanes = |v: &[f32; WIDTH]| {
        (
            Vec4::new(v[0], v[1], v[2], v[3]),
            Vec4::new(v[4], v[5], v[6], v[7]),
        )
    };
    let bits = |lo: glam::BVec4A, hi: glam::BVec4A| lo.bitmask() | hi.bitmask() << 4;
    // Stable sort by decreasing strength, ties in child order (deterministic): each child's
    // rank is the number of children stronger than it, or as strong and before it.
    let (s_lo, s_hi) = lanes(&strength);
    let mut order = [0u8; WIDTH];
    for (c, &strength_c) in strength[..n].iter().enumerate() {
        let sc = Vec4::splat(strength_c);
        let stronger = bits(s_lo.cmpgt(sc), s_hi.cmpgt(sc));
        let tied_before = bits(s_lo.cmpeq(sc), s_hi.cmpeq(sc)) & ((1u32 << c) - 1);
        order[(stronger | tied_before).count_ones() as usize] = c as u8;
    }
    let mut slots = [None; WIDTH];
    let mut free = (1u32 << WIDTH) - 1;
    for &c in &order[..n] {
        let c = c as usize;
        // The favourite is the first slot of the highest score overall, hence also among the
        // free slots when it is free itself.
        let mut slot = favourite[c];
        if free & (1 << slot) == 0 {
            let (lo, hi) = scores[c];
            let ninf = Vec4::NEG_INFINITY;
            let lo = Vec4::select(FREE_LANES[(free & 0xF) as usize], lo, ninf);
            let hi = Vec4::select(FREE_LANES[(free >> 4) as usize], hi, ninf);
            // The first free slot of the highest score (any free one if all scores are -inf).
            let best = Vec4::splat(lo.max(hi).max_element());
            slot = (bits(lo.cmpeq(best), hi.cmpeq(best)) & free).trailing_zeros();
        }
        free &= !(1 << slot);
        slots[slot as usize] = Some(c as u8);
    }
    slots
}

/// Lane masks of four slots from four bits of a free-slot mask (bit `k` set: lane `k` true):
/// a table lookup instead of four scalar-to-vector moves on the slot assignment's critical path.
const FREE_LANES: [glam::BVec4A; 16] = {
    let mut t = [glam::BVec4A::FALSE; 16];
    let mut i = 0;
    while i < 16 {
        t[i] = glam::BVec4A::new(i & 1 != 0, i & 2 != 0, i & 4 != 0, i & 8 != 0);
        i += 1;
    }
    t
};

/// Smallest power-of-two step `2^(e-127)` with `255 * step >= extent`, as the biased exponent.
fn step_exponent(extent: f32) -> u32 {
    let x = extent / 255.0;
    // Also catches NaN: a zero or invalid extent gets the finest step.
    if x.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
        return 1;
    }
    let bits = x.to_bits();
    let mut e = (bits >> 23) & 0xFF;
    if bits & 0x7F_FFFF != 0 {
        e += 1;
    }
    e.clamp(1, 254)
}

/// Writes origin, exponents, imask and the quantized child planes. Every decoded child box
/// (`origin + q * step`, evaluated in f32 as the kernel does) contains the exact child box.
///
/// The eight slots are quantized together as SIMD lanes, one axis at a time (every node of
/// every TLAS rebuild comes through here); each lane computes exactly what a scalar loop per
/// slot and axis would.
pub(crate) fn encode_boxes(node: &mut WideNode, boxes: &[Option<Aabb>; WIDTH], imask: u8) {
    let mut list = [Aabb::EMPTY; WIDTH];
    let mut slots = [None; WIDTH];
    for (slot, b) in boxes.iter().enumerate() {
        if let Some(b) = b {
            list[slot] = *b;
            slots[slot] = Some(slot as u8);
        }
    }
    encode_children(node, &list, &slots, imask);
}

/// [`encode_boxes`] with slot `s` holding the child box `boxes[slots[s]]`, as
/// [`assign_slots`] places them.
pub(crate) fn encode_children(
    node: &mut WideNode,
    boxes: &[Aabb],
    slots: &[Option<u8>; WIDTH],
    imask: u8,
) {
    let mut all = Aabb::EMPTY;
    for &k in slots.iter().flatten() {
        all.grow(&boxes[k as usize]);
    }
    if all.is_empty() {
        node.origin = [0.0; 3];
        node.set_exponents_imask([127; 3], imask);
        return;
    }
    let origin = all.min;
    let ext = all.max - origin;
    // Per lane group (slots 0..4, 4..8), the slots' lower and upper bounds transposed to one
    // vector per axis.
    let o4 = as_lanes(origin);
    let mut lo = [[Vec4::ZERO; 2]; 3];
    let mut hi = [[Vec4::ZERO; 2]; 3];
    for h in 0..2 {
        // Empty slots sit at the origin, where they quantize to 0 and never force a coarser
        // step.
        let corner = |k: usize, upper: bool| match slots[4 * h + k] {
            None => o4,
            Some(c) if upper => as_lanes(boxes[c as usize].max),
            Some(c) => as_lanes(boxes[c as usize].min),
        };
        for (upper, out) in [(false, &mut lo), (true, &mut hi)] {
            let t = glam::Mat4::from_cols(
                corner(0, upper),
                corner(1, upper),
                corner(2, upper),
                corner(3, upper),
            )
            .transpose();
            out[0][h] = t.x_axis;
            out[1][h] = t.y_axis;
            out[2][h] = t.z_axis;
        }
    }
    let mut e = [0u32; 3];
    for (a, ea) in e.iter_mut().enumerate() {
        *ea = step_exponent(ext[a]);
    }
    // Quantized planes (small integers held as floats): per axis, the two lane groups of the
    // lower planes, then of the upper ones.
    let mut q = [[[Vec4::ZERO; 2]; 2]; 3];
    // Axes still to quantize: all at first, then those whose step had to grow.
    let mut todo = 0b111u32;
    while todo != 0 {
        let mut again = 0u32;
        for a in 0..3 {
            if todo & (1 << a) == 0 {
                continue;
            }
            let step = f32::from_bits(e[a] << 23);
            // 1 / step, exact (a power of two; 2^-127 is the denormal 1 << 22), so multiplying
            // by it rounds exactly as dividing by `step` would, at a fraction of the latency.
            let inv = if e[a] <= 253 {
                f32::from_bits((254 - e[a]) << 23)
            } else {
                f32::from_bits(1 << 22)
            };
            let (o, st, iv) = (Vec4::splat(origin[a]), Vec4::splat(step), Vec4::splat(inv));
            let decode = |k: Vec4| o + k * st;
            let one = Vec4::ONE;
            let top = Vec4::splat(255.0);
            let mut missed = false;
            for h in 0..2 {
                let (mn, mx) = (lo[a][h], hi[a][h]);
                // Offsets are >= 0 (the origin is the minimum), so truncation is floor; planes
                // clamp to 255. Step down while the decoded plane lies above the box.
                let mut l = truncated((mn - o) * iv, 255.0);
                let mut above = decode(l).cmpgt(mn);
                loop {
                    let down = l.cmpgt(Vec4::ZERO) & above;
                    if !down.any() {
                        break;
                    }
                    l -= Vec4::select(down, one, Vec4::ZERO);
                    above = decode(l).cmpgt(mn);
                }
                // Round up, then step up while the decoded plane lies below the box.
                let f = (mx - o) * iv;
                let mut u = truncated(f, 256.0);
                u += Vec4::select(u.cmplt(f), one, Vec4::ZERO);
                u = u.min(top);
                let mut below = decode(u).cmplt(mx);
                loop {
                    let up = u.cmplt(top) & below;
                    if !up.any() {
                        break;
                    }
                    u += Vec4::select(up, one, Vec4::ZERO);
                    below = decode(u).cmplt(mx);
                }
                missed |= (below | above).any();
                q[a][0][h] = l;
                q[a][1][h] = u;
            }
            // Rounding of the origin addition left a plane unreachable: coarser step on this
            // axis. At the largest finite step the decoded planes already reach +-inf, so stop
            // there.
            if missed && e[a] < 254 {
                e[a] += 1;
                again |= 1 << a;
            }
        }
        todo = again;
    }
    node.origin = origin.into();
    node.set_exponents_imask(e.map(|x| x as u8), imask);
    node.lo_x = plane_bytes(q[0][0]);
    node.lo_y = plane_bytes(q[1][0]);
    node.lo_z = plane_bytes(q[2][0]);
    node.hi_x = plane_bytes(q[0][1]);
    node.hi_y = plane_bytes(q[1][1]);
    node.hi_z = plane_bytes(q[2][1]);
}

/// The vector's lanes as a `Vec4` (the fourth lane is unspecified).
#[cfg(target_arch = "x86_64")]
#[inline]
fn as_lanes(v: Vec3A) -> Vec4 {
    Vec4::from(std::arch::x86_64::__m128::from(v))
}

#[cfg(not(target_arch = "x86_64"))]
#[inline]
fn as_lanes(v: Vec3A) -> Vec4 {
    v.extend(0.0)
}

/// Non-negative lanes truncated to integers (kept as floats), clamped to `max` (at most 256)
/// first, with NaN lanes taken as 0: what Rust's saturating `as u32` casts give, for the range
/// that matters.
#[inline]
fn truncated(v: Vec4, max: f32) -> Vec4 {
    let v = Vec4::select(v.cmpeq(v), v, Vec4::ZERO);
    small_trunc(v.max(Vec4::ZERO).min(Vec4::splat(max)))
}

/// Truncation of lanes in `[0, 256]`: a round trip through integers, exact in that range.
#[cfg(target_arch = "x86_64")]
#[inline]
fn small_trunc(v: Vec4) -> Vec4 {
    use std::arch::x86_64::{_mm_cvtepi32_ps, _mm_cvttps_epi32};
    // SAFETY: SSE2 is part of the x86_64 baseline; these touch no memory.
    Vec4::from(unsafe { _mm_cvtepi32_ps(_mm_cvttps_epi32(v.into())) })
}

#[cfg(not(target_arch = "x86_64"))]
#[inline]
fn small_trunc(v: Vec4) -> Vec4 {
    v.trunc()
}

/// Eight planes (integers 0..=255 held as floats, slots 0..4 and 4..8) as the bytes of a
/// node field.
#[cfg(target_arch = "x86_64")]
#[inline]
fn plane_bytes(q: [Vec4; 2]) -> [u32; 2] {
    use std::arch::x86_64::{
        _mm_cvtsi128_si64, _mm_cvttps_epi32, _mm_packs_epi32, _mm_packus_epi16,
    };
    // Convert, then narrow to 16 and to 8 bits (the values fit, so neither saturates).
    // SAFETY: SSE2 is part of the x86_64 baseline; these touch no memory.
    let bytes = unsafe {
        let words = _mm_packs_epi32(_mm_cvttps_epi32(q[0].into()), _mm_cvttps_epi32(q[1].into()));
        _mm_cvtsi128_si64(_mm_packus_epi16(words, words)) as u64
    };
    [bytes as u32, (bytes >> 32) as u32]
}

#[cfg(not(target_arch = "x86_64"))]
#[inline]
fn plane_bytes(q: [Vec4; 2]) -> [u32; 2] {
    let b = |v: Vec4| u32::from_le_bytes(v.to_array().map(|x| x as u8));
    [b(q[0]), b(q[1])]
}

#[cfg(test)]
mod tests {
    use crate::rng::SplitMix64;

    #[test]
    fn multiplying_by_the_inverse_step_rounds_like_dividing() {
        let mut rng = SplitMix64::new(4);
        for e in 1u32..=254 {
            let step = f32::from_bits(e << 23);
            let inv = if e <= 253 {
                f32::from_bits((254 - e) << 23)
            } else {
                f32::from_bits(1 << 22)
            };
            assert_eq!(step * inv, 1.0, "e = {e}");
            for _ in 0..200 {
                // Offsets over the whole f32 range, denormals included.
                let x = f32::from_bits(rng.below(0x7F00_0000) as u32);
                assert_eq!(
                    (x * inv).to_bits(),
                    (x / step).to_bits(),
                    "e = {e}, x = {x:e}"
                );
            }
        }
    }

    use super::{WIDTH, assign_slots, encode_boxes, step_exponent};
    use crate::aabb::Aabb;
    use crate::layout::WideNode;
    use glam::BVec3A;
    use glam::Vec3A;

    /// Child boxes from 1e-30 to 1e30 wide, some flat, some far from the origin.
    fn random_boxes(rng: &mut SplitMix64, it: usize) -> [Option<Aabb>; WIDTH] {
        let scale = [1e-30f32, 1e-3, 1.0, 1e3, 1e30][it % 5];
        let offset = [0.0f32, 1e4, -1e6, 3.0][it / 5 % 4];
        let mut boxes = [None; WIDTH];
        for b in boxes.iter_mut() {
            if rng.below(4) == 0 {
                continue;
            }
            let v = |rng: &mut SplitMix64, lo, hi| {
                Vec3A::new(rng.range(lo, hi), rng.range(lo, hi), rng.range(lo, hi))
            };
            let c = v(rng, -1.0, 1.0) * scale + Vec3A::splat(offset);
            let flat = if rng.below(3) == 0 { 0.0 } else { 1.0 };
            let e = v(rng, 0.0, 1.0) * scale * flat;
            *b = Some(Aabb::new(c - e, c + e));
        }
        boxes
    }

    /// The encoder as it was before slots became lanes (all axes of one slot per SIMD operation):
    /// the reference the lane version must match bit for bit. It writes origin, exponents, imask
    /// and the quantized child planes, as the lane version does.
    fn encode_boxes_by_slot(node: &mut WideNode, boxes: &[Option<Aabb>; WIDTH], imask: u8) {
        let mut all = Aabb::EMPTY;
        for b in boxes.iter().flatten() {
            all.grow(b);
        }
        if all.is_empty() {
            node.origin = [0.0; 3];
            node.set_exponents_imask([127; 3], imask);
            return;
        }
        let origin = all.min;
        let ext = all.max - origin;
        let mut e = [0u32; 3];
        for (a, ea) in e.iter_mut().enumerate() {
            *ea = step_exponent(ext[a]);
        }
        // Plane indices are small integers, held as floats (exact) so that they stay in SIMD lanes.
        let mut q = [(Vec3A::ZERO, Vec3A::ZERO); WIDTH];
        loop {
            let step = Vec3A::new(
                f32::from_bits(e[0] << 23),
                f32::from_bits(e[1] << 23),
                f32::from_bits(e[2] << 23),
            );
            // 1 / step, exact (a power of two; 2^-127 is the denormal 1 << 22), so multiplying by it
            // rounds exactly as dividing by `step` would, at a fraction of the latency.
            let inv = |e: u32| {
                if e <= 253 {
                    f32::from_bits((254 - e) << 23)
                } else {
                    f32::from_bits(1 << 22)
                }
            };
            let inv_step = Vec3A::new(inv(e[0]), inv(e[1]), inv(e[2]));
            let decode = |k: Vec3A| origin + k * step;
            let one = Vec3A::ONE;
            let top = Vec3A::splat(255.0);
            // Axes where some child box is not covered by its decoded planes.
            let mut missed = BVec3A::FALSE;
            for (slot, b) in boxes.iter().enumerate() {
                let Some(b) = b else { continue };
                // Offsets are >= 0 (the origin is the minimum), so truncation is floor; planes
                // clamp to 255.
                let mut lo = truncated3((b.min - origin) * inv_step, 255.0);
                loop {
                    let down = lo.cmpgt(Vec3A::ZERO) & decode(lo).cmpgt(b.min);
                    if !down.any() {
                        break;
                    }
                    lo -= Vec3A::select(down, one, Vec3A::ZERO);
                }
                let f = (b.max - origin) * inv_step;
                let mut hi = truncated3(f, 256.0);
                hi += Vec3A::select(hi.cmplt(f), one, Vec3A::ZERO);
                hi = hi.min(top);
                loop {
                    let up = hi.cmplt(top) & decode(hi).cmplt(b.max);
                    if !up.any() {
                        break;
                    }
                    hi += Vec3A::select(up, one, Vec3A::ZERO);
                }
                missed |= decode(hi).cmplt(b.max) | decode(lo).cmpgt(b.min);
                q[slot] = (lo, hi);
            }
            // Rounding of the origin addition left a plane unreachable: coarser step on that axis.
            // At the largest finite step the decoded planes already reach +-inf, so stop there.
            let retry = missed.bitmask();
            let mut again = false;
            for (a, ea) in e.iter_mut().enumerate() {
                if retry & (1 << a) != 0 && *ea < 254 {
                    *ea += 1;
                    again = true;
                }
            }
            if !again {
                break;
            }
        }
        node.origin = origin.into();
        node.set_exponents_imask(e.map(|x| x as u8), imask);
        // Bytes gathered per field and stored as whole words (empty slots stay 0).
        let mut planes = [[0u8; WIDTH]; 6];
        for (slot, b) in boxes.iter().enumerate() {
            if b.is_some() {
                let (lo, hi) = q[slot];
                for a in 0..3 {
                    planes[a][slot] = lo[a] as u8;
                    planes[3 + a][slot] = hi[a] as u8;
                }
            }
        }
        let words = |p: &[u8; WIDTH]| {
            [
                u32::from_le_bytes([p[0], p[1], p[2], p[3]]),
                u32::from_le_bytes([p[4], p[5], p[6], p[7]]),
            ]
        };
        node.lo_x = words(&planes[0]);
        node.lo_y = words(&planes[1]);
        node.lo_z = words(&planes[2]);
        node.hi_x = words(&planes[3]);
        node.hi_y = words(&planes[4]);
        node.hi_z = words(&planes[5]);
    }

    /// Non-negative lanes truncated to integers (kept as floats), clamped to `max` first, with NaN
    /// lanes taken as 0: what Rust's saturating `as u32` casts give, for the range that matters.
    #[inline]
    fn truncated3(v: Vec3A, max: f32) -> Vec3A {
        let v = Vec3A::select(v.cmpeq(v), v, Vec3A::ZERO);
        v.max(Vec3A::ZERO).min(Vec3A::splat(max)).trunc()
    }

    #[test]
    fn lane_encoder_matches_the_per_slot_one() {
        let mut rng = SplitMix64::new(31);
        for it in 0..20_000 {
            let boxes = random_boxes(&mut rng, it);
            let mut got = WideNode::default();
            encode_boxes(&mut got, &boxes, 0b1010_0101);
            let mut want = WideNode::default();
            encode_boxes_by_slot(&mut want, &boxes, 0b1010_0101);
            assert_eq!(got, want, "case {it}: {boxes:?}");
        }
    }

    #[test]
    fn decoded_child_boxes_contain_the_exact_ones_within_a_step_or_two() {
        let mut rng = SplitMix64::new(9);
        for it in 0..20_000 {
            let boxes = random_boxes(&mut rng, it);
            let mut node = WideNode::default();
            encode_boxes(&mut node, &boxes, 0);
            let step = node.scale();
            let origin = node.origin;
            // The kernel's decoding: origin + q * step in f32.
            let decode = |a: usize, q: u8| origin[a] + q as f32 * step[a];
            for (slot, b) in boxes.iter().enumerate() {
                let Some(b) = b else { continue };
                let (lo, hi) = node.quantized(slot);
                for a in 0..3 {
                    let ctx = format!("case {it}, slot {slot}, axis {a}: {b:?}");
                    assert!(
                        decode(a, lo[a]) <= b.min[a],
                        "{ctx}: low plane above the box"
                    );
                    assert!(
                        decode(a, hi[a]) >= b.max[a],
                        "{ctx}: high plane below the box"
                    );
                    // Loose by at most two grid steps (plus the rounding of the origin
                    // addition, which can exceed a step far from zero).
                    let slack = |x: f32| 2.0 * step[a] + 4.0 * f32::EPSILON * x.abs();
                    assert!(
                        decode(a, lo[a]) >= b.min[a] - slack(b.min[a]),
                        "{ctx}: low plane too loose"
                    );
                    assert!(
                        decode(a, hi[a]) <= b.max[a] + slack(b.max[a]),
                        "{ctx}: high plane too loose"
                    );
                }
            }
        }
    }

    #[test]
    fn slots_follow_the_octants_of_the_child_centres() {
        // Children in distinct octants of the parent centre land in the slot of their octant
        // (bit 0: +x, bit 1: +y, bit 2: +z), whatever order they come in.
        let mut rng = SplitMix64::new(2);
        for _ in 0..1000 {
            let mut octants: Vec<usize> = (0..WIDTH).collect();
            for i in (1..WIDTH).rev() {
                octants.swap(i, rng.below(i + 1));
            }
            let n = 1 + rng.below(WIDTH);
            let centres: Vec<Vec3A> = octants[..n]
                .iter()
                .map(|&o| {
                    let sign = |bit: usize| if o & bit != 0 { 1.0 } else { -1.0 };
                    Vec3A::new(sign(1), sign(2), sign(4)) * rng.range(0.5, 2.0)
                })
                .collect();
            let slots = assign_slots(Vec3A::ZERO, &centres);
            for (c, &o) in octants[..n].iter().enumerate() {
                assert_eq!(slots[o], Some(c as u8), "octants {:?}", &octants[..n]);
            }
            assert_eq!(slots.iter().flatten().count(), n);
        }
    }

    /// The slot assignment as its documentation states it, one scalar step at a time.
    fn slots_by_definition(parent: Vec3A, centres: &[Vec3A]) -> [Option<u8>; WIDTH] {
        let offsets: Vec<Vec3A> = centres
            .iter()
            .map(|&c| {
                let o = c - parent;
                if o.is_finite() { o } else { Vec3A::ZERO }
            })
            .collect();
        let strength: Vec<f32> = offsets
            .iter()
            .map(|o| o.x.abs() + o.y.abs() + o.z.abs())
            .collect();
        // Strongest first; a stable sort keeps ties in child order.
        let mut order: Vec<usize> = (0..centres.len()).collect();
        order.sort_by(|&a, &b| strength[b].total_cmp(&strength[a]));
        let mut slots = [None; WIDTH];
        for c in order {
            let o = offsets[c];
            let sign = |slot: usize, bit: usize| if slot & bit != 0 { 1.0 } else { -1.0 };
            let score = |s: usize| (sign(s, 1) * o.x + sign(s, 2) * o.y) + sign(s, 4) * o.z;
            let mut best: Option<usize> = None;
            for s in (0..WIDTH).filter(|&s| slots[s].is_none()) {
                if best.is_none_or(|b| score(s) > score(b)) {
                    best = Some(s);
                }
            }
            slots[best.unwrap()] = Some(c as u8);
        }
        slots
    }

    #[test]
    fn slot_assignment_matches_its_definition() {
        let mut rng = SplitMix64::new(21);
        for it in 0..20_000 {
            let n = 1 + rng.below(WIDTH);
            let parent = Vec3A::new(rng.range(-1.0, 1.0), 0.5, rng.range(-3.0, 3.0));
            let centres: Vec<Vec3A> = (0..n)
                .map(|_| match it % 4 {
                    // Few distinct values: equal strengths and equal scores.
                    0 => Vec3A::new(
                        rng.below(3) as f32 - 1.0,
                        rng.below(3) as f32 - 1.0,
                        rng.below(3) as f32 - 1.0,
                    ),
                    // Offsets that overflow the scores to infinity, or are not finite at all.
                    1 => Vec3A::new(
                        [3e38, -3e38, 1.0, f32::INFINITY][rng.below(4)],
                        [3e38, -3e38, 2.0][rng.below(3)],
                        [3e38, f32::NAN, -1.0][rng.below(3)],
                    ),
                    _ => Vec3A::new(
                        rng.range(-10.0, 10.0),
                        rng.range(-10.0, 10.0),
                        rng.range(-10.0, 10.0),
                    ),
                })
                .collect();
            let parent = if it % 4 == 0 { Vec3A::ZERO } else { parent };
            assert_eq!(
                assign_slots(parent, &centres),
                slots_by_definition(parent, &centres),
                "parent {parent:?}, centres {centres:?}"
            );
        }
    }

    #[test]
    fn children_crowding_one_octant_all_get_distinct_slots() {
        let mut rng = SplitMix64::new(3);
        for _ in 0..1000 {
            let n = 1 + rng.below(WIDTH);
            // Equal centres too: ties must still give every child its own slot.
            let centres: Vec<Vec3A> = (0..n)
                .map(|_| Vec3A::new(rng.below(2) as f32, 1.0, rng.below(2) as f32))
                .collect();
            let slots = assign_slots(Vec3A::ZERO, &centres);
            let mut seen = [false; WIDTH];
            for &c in slots.iter().flatten() {
                assert!(!seen[c as usize], "child {c} twice");
                seen[c as usize] = true;
            }
            assert_eq!(seen.iter().filter(|&&s| s).count(), n);
        }
    }
}
