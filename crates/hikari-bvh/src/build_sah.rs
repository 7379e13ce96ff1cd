//! Binary BVH over primitive boxes by binned SAH, the first stage of every BLAS build.
//!
//! Primitives travel as 32-byte [`PrimRef`]s that every split reorders with a stable partition
//! (left side first, each side in its previous order), so every pass over a node reads memory
//! sequentially. A large build runs in two parallel phases: the top levels are split level by
//! level with every thread binning and scattering a share of every node's primitives
//! ([`top_levels`]), then the remaining subtrees are built one per task into node ranges reserved
//! for them. Bins merge exactly (minima, maxima, counts) and a stable partition does not depend
//! on who moved which primitive, so the tree is identical for any thread count.

mod bins;
pub(crate) mod parallel;
mod top_levels;

use crate::aabb::Aabb;
use bins::Bins;
use glam::{Vec3A, Vec4};
use parallel::{map_dynamic, map_largest_first, ranges, split_ranges};
use top_levels::Subtree;

/// Tag that makes an id (< `MAX_PRIMS`) a normal float between 2 and 2^65.
const ID_TAG: u32 = 0x4000_0000;
/// Most primitives one build can take.
pub const MAX_PRIMS: usize = 1 << 29;

/// Bins per axis.
const BINS: usize = 16;
/// Below this depth the builder stops trusting SAH and splits at the median, so the tree depth
/// (and with it the traversal stack) stays bounded on adversarial input.
const MEDIAN_SPLIT_DEPTH: u32 = 40;
/// Nodes up to this size use an exact sweep instead of bins.
const SMALL_NODE: usize = 12;
/// Nodes smaller than this are never split by several threads together.
const MIN_PARALLEL_PRIMS: usize = 16 * 1024;
/// Nodes larger than this are split level by level (see [`top_levels`]), even on one thread.
const MAX_SUBTREE_PRIMS: usize = 64 * 1024;

/// A primitive's box; `lo.w` holds the primitive id as the bits of a normal float (`ID_TAG | id`):
/// the SIMD box arithmetic also runs on the w lane, and a raw small integer there would be a
/// denormal, which costs a microcode assist on every operation.
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
#[repr(C, align(16))]
pub struct PrimRef {
    pub lo: Vec4,
    pub hi: Vec4,
}

impl PrimRef {
    pub fn new(b: &Aabb, id: u32) -> Self {
        Self {
            lo: b.min.extend(f32::from_bits(ID_TAG | id)),
            hi: b.max.extend(0.0),
        }
    }
    #[inline]
    pub fn id(&self) -> u32 {
        self.lo.w.to_bits() & !ID_TAG
    }
    #[inline]
    pub fn lo3(&self) -> Vec3A {
        Vec3A::from_vec4(self.lo)
    }
    #[inline]
    pub fn hi3(&self) -> Vec3A {
        Vec3A::from_vec4(self.hi)
    }
    /// Twice the centroid: the halving never changes a split decision.
    #[inline]
    fn c2(&self) -> Vec3A {
        self.lo3() + self.hi3()
    }
}

/// A binary node. Children are allocated in pairs: `right = left + 1`.
#[derive(Clone, Copy, Debug)]
pub struct BinNode {
    pub bounds: Aabb,
    /// Left child index (internal) or first primitive in the reordered array (leaf).
    pub first: u32,
    /// Number of primitives of a leaf; 0 for an internal node.
    pub count: u32,
    /// Number of primitives in the subtree.
    pub prims: u32,
}

// SAFETY: every field is an f32 or u32 (through `Aabb`'s `Vec3A`s), for which all-zero bits are
// a valid value; the padding after `prims` needs no value.
unsafe impl bytemuck::Zeroable for BinNode {}

impl BinNode {
    #[inline]
    pub fn is_leaf(&self) -> bool {
        self.count > 0
    }
}

pub struct BinaryBvh {
    /// Root at index 0, siblings next to each other. A parallel build leaves unused entries
    /// between subtrees: walk the tree from the root rather than the array.
    pub nodes: Vec<BinNode>,
    /// Primitives in leaf order.
    pub prims: Vec<PrimRef>,
}

#[derive(Clone, Copy, Debug)]
pub struct SahParams {
    /// Most primitives in one leaf.
    pub max_leaf: usize,
    /// Threads to use (1 = build entirely on the calling thread).
    pub threads: usize,
}

#[derive(Clone, Copy)]
struct Task {
    node: u32,
    begin: usize,
    end: usize,
    /// Box of the doubled centroids.
    cbounds: Aabb,
    depth: u32,
}

struct Split {
    axis: usize,
    bin: usize,
    bins: usize,
    left: Aabb,
    right: Aabb,
}

/// Builds a binary BVH. `prims` must be non-empty.
pub fn build(prims: Vec<PrimRef>, params: &SahParams) -> BinaryBvh {
    let mut scratch: Vec<PrimRef> = bytemuck::zeroed_vec(prims.len());
    build_in(prims, &mut scratch, params)
}

/// [`build`] with the caller's scratch space, at least as long as `prims`; its contents are
/// overwritten. A caller that needs a buffer of that size afterwards anyway can lend it here,
/// so that its pages are faulted in once.
pub(crate) fn build_in(
    prims: Vec<PrimRef>,
    scratch: &mut [PrimRef],
    params: &SahParams,
) -> BinaryBvh {
    let n = prims.len();
    // Enough subtrees that a thread drawing a large one last does not hold up the others for
    // long, each small enough to stay in a core's cache. The level-by-level top pays a few
    // barriers per level, but even on one thread it beats splitting the large nodes in place:
    // its scatter to the other buffer needs no copy back.
    let top = (n >= 2 * MIN_PARALLEL_PRIMS)
        .then(|| (n / (params.threads.max(1) * 8)).clamp(MIN_PARALLEL_PRIMS, MAX_SUBTREE_PRIMS));
    build_with(prims, &mut scratch[..n], params, top)
}

/// [`build_in`], with the top split level by level until no node holds more than
/// `top_threshold` primitives, if given. The tree does not depend on it. `scratch` is as long
/// as `prims`.
fn build_with(
    mut prims: Vec<PrimRef>,
    scratch: &mut [PrimRef],
    params: &SahParams,
    top_threshold: Option<usize>,
) -> BinaryBvh {
    assert!(!prims.is_empty());
    let n = prims.len();
    let threads = params.threads.max(1);
    let (bounds, cbounds) = root_bounds(&prims, threads);
    let root = Task {
        node: 0,
        begin: 0,
        end: n,
        cbounds,
        depth: 0,
    };
    let mut top = vec![BinNode {
        bounds,
        first: 0,
        count: 0,
        prims: n as u32,
    }];
    // Stable partitions move one side through `scratch`; the level-by-level top moves whole
    // nodes back and forth between it and `prims`.
    let mut subtrees = match top_threshold {
        Some(threshold) => {
            top_levels::split(&mut prims, scratch, root, &mut top, threshold, threads)
        }
        None => vec![Subtree {
            task: root,
            in_scratch: false,
        }],
    };
    subtrees.sort_by_key(|s| s.task.begin);

    // Each subtree of m primitives gets at most 2m - 2 nodes below its root (which already
    // sits in `top`), in a range of its own: subtrees fill them independently, and the unused
    // tails are never referenced (zeroed pages that are never touched cost no memory).
    let mut reserve = Vec::with_capacity(subtrees.len());
    let mut total = top.len();
    for s in &subtrees {
        let m = s.task.end - s.task.begin;
        reserve.push(total..total + 2 * m.max(1) - 2);
        total += 2 * m.max(1) - 2;
    }
    let mut nodes: Vec<BinNode> = bytemuck::zeroed_vec(total);
    nodes[..top.len()].copy_from_slice(&top);
    let prim_ranges: Vec<_> = subtrees.iter().map(|s| s.task.begin..s.task.end).collect();
    let jobs: Vec<_> = split_ranges(&mut nodes, &reserve)
        .into_iter()
        .zip(split_ranges(&mut prims, &prim_ranges))
        .zip(split_ranges(scratch, &prim_ranges))
        .zip(subtrees.iter().zip(&reserve))
        .map(|(((arena, prims), scratch), (s, r))| (s, r.start, arena, prims, scratch))
        .collect();
    let roots = map_largest_first(
        threads,
        jobs,
        |job| job.3.len(),
        |(s, base, arena, prims, scratch)| {
            if s.in_scratch {
                prims.copy_from_slice(scratch);
            }
            let mut arena = Arena {
                root: top[s.task.node as usize],
                root_index: s.task.node,
                nodes: arena,
                base: base as u32,
                used: 0,
            };
            let local = Task {
                begin: 0,
                end: prims.len(),
                ..s.task
            };
            build_tasks(prims, scratch, s.task.begin, &mut arena, local, params);
            (arena.root, arena.used)
        },
    );
    let mut used_end = top.len();
    for ((s, r), (root, used)) in subtrees.iter().zip(&reserve).zip(roots) {
        nodes[s.task.node as usize] = root;
        used_end = used_end.max(r.start + used);
    }
    // The serial path has one subtree: drop its unused tail. With several, gaps remain between
    // their ranges.
    nodes.truncate(used_end);
    BinaryBvh { nodes, prims }
}

/// Box of all primitives and box of their doubled centroids.
fn root_bounds(prims: &[PrimRef], threads: usize) -> (Aabb, Aabb) {
    let pieces = ranges(prims.len(), threads, MIN_PARALLEL_PRIMS);
    let parts = map_dynamic(threads, pieces, |r| side_bounds(&prims[r]));
    let mut b = Aabb::EMPTY;
    let mut c = Aabb::EMPTY;
    for (pb, pc) in parts {
        b.grow(&pb);
        c.grow(&pc);
    }
    (b, c)
}

/// Where the nodes of one subtree go: its root (kept aside, as it lives in the top part of the
/// node array) and the range reserved for everything below it, filled from the front.
struct Arena<'a> {
    root: BinNode,
    root_index: u32,
    nodes: &'a mut [BinNode],
    /// Global index of `nodes[0]`.
    base: u32,
    used: usize,
}

impl Arena<'_> {
    #[inline]
    fn get_mut(&mut self, i: u32) -> &mut BinNode {
        if i == self.root_index {
            &mut self.root
        } else {
            &mut self.nodes[(i - self.base) as usize]
        }
    }

    /// Appends two siblings; returns the global index of the first.
    #[inline]
    fn push_pair(&mut self, pair: [BinNode; 2]) -> u32 {
        self.nodes[self.used..self.used + 2].copy_from_slice(&pair);
        self.used += 2;
        self.base + self.used as u32 - 2
    }
}

/// Builds the subtree below `root` (whose range is all of `prims`); `scratch` is as long as
/// `prims`, and `prim_offset` is the global index of `prims[0]`.
fn build_tasks(
    prims: &mut [PrimRef],
    scratch: &mut [PrimRef],
    prim_offset: usize,
    nodes: &mut Arena,
    root: Task,
    params: &SahParams,
) {
    let mut stack = vec![root];
    while let Some(task) = stack.pop() {
        let n = task.end - task.begin;
        // The wide collapse turns every subtree of at most `max_leaf` primitives into one leaf
        // child anyway, so splitting it here would only cost time.
        if n <= params.max_leaf.max(1) {
            let node = nodes.get_mut(task.node);
            node.first = (task.begin + prim_offset) as u32;
            node.count = n as u32;
            continue;
        }
        let range = &mut prims[task.begin..task.end];
        if n <= SMALL_NODE {
            let (mid, boxes) = small_split(range);
            // Children of a small node are small too and never read their centroid bounds.
            push_children(
                nodes,
                &mut stack,
                &task,
                task.begin + mid,
                boxes,
                [Aabb::EMPTY; 2],
            );
            continue;
        }
        let split = if task.depth < MEDIAN_SPLIT_DEPTH {
            find_split(range, &task.cbounds)
        } else {
            None
        };
        let (mid, left_box, right_box, left_cb, right_cb) = match split {
            Some(s) => {
                let (mid, lcb, rcb) =
                    partition(range, &mut scratch[task.begin..task.end], &task.cbounds, &s);
                (mid, s.left, s.right, lcb, rcb)
            }
            None => median_split(range, &task.cbounds),
        };
        push_children(
            nodes,
            &mut stack,
            &task,
            task.begin + mid,
            [left_box, right_box],
            [left_cb, right_cb],
        );
    }
}

fn push_children(
    nodes: &mut Arena,
    stack: &mut Vec<Task>,
    task: &Task,
    split_at: usize,
    boxes: [Aabb; 2],
    cbounds: [Aabb; 2],
) {
    let child = |bounds, prims: usize| BinNode {
        bounds,
        first: 0,
        count: 0,
        prims: prims as u32,
    };
    let left = nodes.push_pair([
        child(boxes[0], split_at - task.begin),
        child(boxes[1], task.end - split_at),
    ]);
    let node = nodes.get_mut(task.node);
    node.first = left;
    node.count = 0;
    // Right first so the left subtree is built (and laid out) next.
    stack.push(Task {
        node: left + 1,
        begin: split_at,
        end: task.end,
        cbounds: cbounds[1],
        depth: task.depth + 1,
    });
    stack.push(Task {
        node: left,
        begin: task.begin,
        end: split_at,
        cbounds: cbounds[0],
        depth: task.depth + 1,
    });
}

fn side_bounds(ps: &[PrimRef]) -> (Aabb, Aabb) {
    let mut b = Aabb::EMPTY;
    let mut c = Aabb::EMPTY;
    for p in ps {
        b.grow(&Aabb::new(p.lo3(), p.hi3()));
        c.grow_point(p.c2());
    }
    (b, c)
}

/// Exact SAH over all `n - 1` object splits along each axis, for nodes small enough that
/// sorting is cheaper than binning. Reorders `prims` so the chosen left side comes first and
/// returns the split index and both child boxes.
fn small_split(prims: &mut [PrimRef]) -> (usize, [Aabb; 2]) {
    let n = prims.len();
    if n == 2 {
        // The only split there is.
        let b = |p: &PrimRef| Aabb::new(p.lo3(), p.hi3());
        return (1, [b(&prims[0]), b(&prims[1])]);
    }
    debug_assert!((2..=SMALL_NODE).contains(&n));
    let mut c2 = [Vec3A::ZERO; SMALL_NODE];
    for (c, p) in c2.iter_mut().zip(prims.iter()) {
        *c = p.c2();
    }
    let mut best_cost = f32::INFINITY;
    let mut best_order = [0u8; SMALL_NODE];
    let mut best_mid = n / 2;
    let mut order = [0u8; SMALL_NODE];
    // Without NaN the centroids are totally ordered, and the stable sort can be computed as
    // ranks without a branch (an insertion sort's comparisons are coin flips for a predictor).
    let ordered = c2[..n].iter().all(|c| c.cmpeq(*c).all());
    for axis in [0usize, 1, 2] {
        if ordered {
            stable_ranks(&c2[..n], axis, &mut order);
        } else {
            for (i, o) in order[..n].iter_mut().enumerate() {
                *o = i as u8;
            }
            for i in 1..n {
                let mut j = i;
                while j > 0 && c2[order[j - 1] as usize][axis] > c2[order[j] as usize][axis] {
                    order.swap(j - 1, j);
                    j -= 1;
                }
            }
        }
        let mut right = [0.0f32; SMALL_NODE];
        let (mut lo, mut hi) = (Vec3A::INFINITY, Vec3A::NEG_INFINITY);
        for i in (1..n).rev() {
            let p = &prims[order[i] as usize];
            lo = lo.min(p.lo3());
            hi = hi.max(p.hi3());
            right[i] = half_area(lo, hi) * (n - i) as f32;
        }
        let (mut lo, mut hi) = (Vec3A::INFINITY, Vec3A::NEG_INFINITY);
        for i in 0..n - 1 {
            let p = &prims[order[i] as usize];
            lo = lo.min(p.lo3());
            hi = hi.max(p.hi3());
            let cost = half_area(lo, hi) * (i + 1) as f32 + right[i + 1];
            if cost < best_cost {
                best_cost = cost;
                best_order = order;
                best_mid = i + 1;
            }
        }
    }
    if best_cost == f32::INFINITY {
        // Only NaN costs (cannot happen with validated input): keep the order, split in half.
        for (i, o) in best_order[..n].iter_mut().enumerate() {
            *o = i as u8;
        }
    }
    let mut sorted = [PrimRef {
        lo: glam::Vec4::ZERO,
        hi: glam::Vec4::ZERO,
    }; SMALL_NODE];
    for (dst, &src) in sorted.iter_mut().zip(&best_order[..n]) {
        *dst = prims[src as usize];
    }
    prims.copy_from_slice(&sorted[..n]);
    let left = side_bounds(&prims[..best_mid]).0;
    let right = side_bounds(&prims[best_mid..]).0;
    (best_mid, [left, right])
}

/// Indices of `c2` (at most [`SMALL_NODE`], none NaN) in ascending order of `axis`, ties in
/// index order: each one's place is the number of values below it plus the equal ones before it.
fn stable_ranks(c2: &[Vec3A], axis: usize, order: &mut [u8; SMALL_NODE]) {
    const LANES: usize = SMALL_NODE.div_ceil(4) * 4;
    // Unused lanes hold NaN, which is neither below nor equal to anything.
    let mut key = [f32::NAN; LANES];
    for (k, c) in key.iter_mut().zip(c2) {
        *k = c[axis];
    }
    let mut lanes = [Vec4::ZERO; LANES / 4];
    for (l, k) in lanes.iter_mut().zip(key.chunks_exact(4)) {
        *l = Vec4::from_slice(k);
    }
    for (i, &k) in key[..c2.len()].iter().enumerate() {
        let k = Vec4::splat(k);
        let (mut below, mut equal) = (0u32, 0u32);
        for (g, l) in lanes.iter().enumerate() {
            below |= l.cmplt(k).bitmask() << (4 * g);
            equal |= l.cmpeq(k).bitmask() << (4 * g);
        }
        let place = below.count_ones() + (equal & ((1 << i) - 1)).count_ones();
        order[place as usize] = i as u8;
    }
}

#[inline]
fn bin_scale(cb: &Aabb, bins: usize) -> Vec3A {
    let ext = cb.max - cb.min;
    // Slightly below `bins` so the largest centroid lands in the last bin, not past it.
    let k = Vec3A::splat(bins as f32 * (1.0 - 1e-6)) / ext;
    Vec3A::select(ext.cmpgt(Vec3A::ZERO), k, Vec3A::ZERO)
}

#[inline]
fn bin_index(c2: Vec3A, cb_min: Vec3A, k: Vec3A, bins: usize) -> [usize; 3] {
    let b = ((c2 - cb_min) * k)
        .max(Vec3A::ZERO)
        .min(Vec3A::splat((bins - 1) as f32));
    truncate3(b)
}

/// Truncates three lanes that are known to lie in `[0, BINS)`; one packed conversion on x86_64
/// instead of three saturating scalar casts.
#[cfg(target_arch = "x86_64")]
#[inline]
fn truncate3(v: Vec3A) -> [usize; 3] {
    use std::arch::x86_64::{__m128, _mm_cvttps_epi32, _mm_storeu_si128};
    let m: __m128 = v.into();
    let mut out = [0i32; 4];
    // SAFETY: SSE2 is part of the x86_64 baseline; `out` is 16 writable bytes and the store is
    // the unaligned variant.
    unsafe { _mm_storeu_si128(out.as_mut_ptr().cast(), _mm_cvttps_epi32(m)) };
    [out[0] as usize, out[1] as usize, out[2] as usize]
}

#[cfg(not(target_arch = "x86_64"))]
#[inline]
fn truncate3(v: Vec3A) -> [usize; 3] {
    [v.x as usize, v.y as usize, v.z as usize]
}

#[inline]
fn half_area(lo: Vec3A, hi: Vec3A) -> f32 {
    let e = hi - lo;
    e.x * e.y + e.y * e.z + e.z * e.x
}

fn find_split(prims: &[PrimRef], cb: &Aabb) -> Option<Split> {
    // Bin arrays sized at compile time: small nodes are the majority, and for them clearing and
    // sweeping 16 bins per axis costs more than binning their few primitives.
    if prims.len() < 64 {
        find_split_n::<{ BINS / 2 }>(prims, cb)
    } else {
        find_split_n::<BINS>(prims, cb)
    }
}

fn find_split_n<const NB: usize>(prims: &[PrimRef], cb: &Aabb) -> Option<Split> {
    let k = bin_scale(cb, NB);
    if k.cmpeq(Vec3A::ZERO).all() {
        return None;
    }
    Bins::<NB>::accumulate(prims, cb.min, k).best_split(k, prims.len())
}

/// Stable partition: primitives whose centroid bin is `<= bin` first, each side in its previous
/// order (the parallel top levels produce exactly this order). Returns the split point and the
/// doubled-centroid boxes of both sides. `scratch` is as long as `prims`.
fn partition(
    prims: &mut [PrimRef],
    scratch: &mut [PrimRef],
    cb: &Aabb,
    s: &Split,
) -> (usize, Aabb, Aabb) {
    let (axis, bin, bins) = (s.axis, s.bin, s.bins);
    let k = bin_scale(cb, bins);
    // Branch-free: a side decision per primitive is a coin flip for the branch predictor, so
    // every primitive is written to both places and only the cursor of its side advances. Left
    // ones compact in place (the write cursor never passes the read cursor), right ones wait in
    // `scratch`.
    let mut l = 0;
    let mut r = 0;
    for i in 0..prims.len() {
        let p = prims[i];
        let left = bin_index(p.c2(), cb.min, k, bins)[axis] <= bin;
        prims[l] = p;
        scratch[r] = p;
        l += left as usize;
        r += !left as usize;
    }
    // Centroid boxes of the two sides in separate passes over each side (the left one still in
    // cache): cheaper than selecting a side per primitive above.
    let (mut lmin, mut lmax) = (Vec3A::INFINITY, Vec3A::NEG_INFINITY);
    for p in &prims[..l] {
        let c2 = p.c2();
        lmin = lmin.min(c2);
        lmax = lmax.max(c2);
    }
    let (mut rmin, mut rmax) = (Vec3A::INFINITY, Vec3A::NEG_INFINITY);
    for (dst, p) in prims[l..].iter_mut().zip(&scratch[..r]) {
        *dst = *p;
        let c2 = p.c2();
        rmin = rmin.min(c2);
        rmax = rmax.max(c2);
    }
    (l, Aabb::new(lmin, lmax), Aabb::new(rmin, rmax))
}

/// Fallback when SAH finds no plane (all centroids equal, or too deep): split by count along the
/// widest centroid axis, so every input terminates.
fn median_split(prims: &mut [PrimRef], cb: &Aabb) -> (usize, Aabb, Aabb, Aabb, Aabb) {
    let ext = cb.extent();
    let axis = if ext.x >= ext.y && ext.x >= ext.z {
        0
    } else if ext.y >= ext.z {
        1
    } else {
        2
    };
    let mid = prims.len() / 2;
    if ext[axis] > 0.0 {
        prims.select_nth_unstable_by(mid, |a, b| a.c2()[axis].total_cmp(&b.c2()[axis]));
    }
    let (lb, lcb) = side_bounds(&prims[..mid]);
    let (rb, rcb) = side_bounds(&prims[mid..]);
    (mid, lb, rb, lcb, rcb)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::SplitMix64;

    /// The tree as a sequence of (box, leaf primitive ids) in depth-first order: what every
    /// later stage reads, independent of where nodes sit in the array.
    fn canonical(b: &BinaryBvh) -> Vec<([u32; 6], Vec<u32>)> {
        let mut out = Vec::new();
        let mut stack = vec![0u32];
        while let Some(i) = stack.pop() {
            let n = &b.nodes[i as usize];
            let bx = [n.bounds.min, n.bounds.max].map(|v| v.to_array().map(f32::to_bits));
            let key = [bx[0][0], bx[0][1], bx[0][2], bx[1][0], bx[1][1], bx[1][2]];
            if n.is_leaf() {
                let ids = b.prims[n.first as usize..(n.first + n.count) as usize]
                    .iter()
                    .map(PrimRef::id)
                    .collect();
                out.push((key, ids));
            } else {
                out.push((key, Vec::new()));
                stack.push(n.first + 1);
                stack.push(n.first);
            }
        }
        out
    }

    /// Boxes in clumps of different density, with many equal coordinates (a grid) so that ties
    /// in the exact small-node sweep depend on primitive order.
    fn boxes(seed: u64, count: usize) -> Vec<PrimRef> {
        let mut rng = SplitMix64::new(seed);
        (0..count)
            .map(|i| {
                let c = if i % 3 == 0 {
                    Vec3A::new(
                        rng.range(-50.0, 50.0),
                        rng.range(-50.0, 50.0),
                        rng.range(-50.0, 50.0),
                    )
                } else {
                    Vec3A::new(rng.below(40) as f32, (i % 5) as f32, rng.below(40) as f32) * 0.25
                };
                let e = Vec3A::new(
                    rng.range(0.0, 0.5),
                    rng.range(0.0, 0.5),
                    rng.range(0.0, 0.5),
                );
                PrimRef::new(&Aabb::new(c - e, c + e), i as u32)
            })
            .collect()
    }

    #[test]
    fn top_levels_give_the_tree_of_a_serial_build() {
        for (seed, count) in [(1, 20_000), (2, 3_001)] {
            let prims = boxes(seed, count);
            let params = |threads| SahParams {
                max_leaf: 3,
                threads,
            };
            let mut scratch = vec![PrimRef::new(&Aabb::EMPTY, 0); prims.len()];
            let serial = canonical(&build_with(prims.clone(), &mut scratch, &params(1), None));
            for (threads, threshold) in [(1, 1000), (3, 700), (8, 64), (16, 5000)] {
                let got = canonical(&build_with(
                    prims.clone(),
                    &mut scratch,
                    &params(threads),
                    Some(threshold),
                ));
                assert!(
                    got == serial,
                    "{count} boxes, {threads} threads, top down to {threshold}: tree differs"
                );
            }
        }
    }

    #[test]
    fn top_levels_median_split_gives_the_tree_of_a_serial_build() {
        // Equal centroids: no SAH plane anywhere, every node is split at the median.
        let b = Aabb::new(Vec3A::ZERO, Vec3A::ONE);
        let prims: Vec<PrimRef> = (0..5000).map(|i| PrimRef::new(&b, i)).collect();
        let params = SahParams {
            max_leaf: 3,
            threads: 4,
        };
        let mut scratch = vec![PrimRef::new(&Aabb::EMPTY, 0); prims.len()];
        let serial = canonical(&build_with(prims.clone(), &mut scratch, &params, None));
        let top = canonical(&build_with(prims, &mut scratch, &params, Some(300)));
        assert!(top == serial);
    }

    #[test]
    fn stable_ranks_sort_like_a_stable_sort() {
        let mut rng = SplitMix64::new(12);
        for it in 0..5000 {
            let n = 2 + rng.below(SMALL_NODE - 1);
            // Few distinct values (many ties), signed zeros among them, or arbitrary values.
            let value = |rng: &mut SplitMix64| match it % 3 {
                0 => rng.below(3) as f32,
                1 => [0.0, -0.0, 1.0][rng.below(3)],
                _ => rng.range(-1e3, 1e3),
            };
            let c2: Vec<Vec3A> = (0..n)
                .map(|_| Vec3A::new(value(&mut rng), value(&mut rng), value(&mut rng)))
                .collect();
            for axis in 0..3 {
                // Ties (-0 and +0 included) in index order.
                let mut want: Vec<u8> = (0..n as u8).collect();
                want.sort_by(|&a, &b| {
                    c2[a as usize][axis]
                        .partial_cmp(&c2[b as usize][axis])
                        .unwrap()
                        .then(a.cmp(&b))
                });
                let mut got = [0u8; SMALL_NODE];
                stable_ranks(&c2, axis, &mut got);
                assert_eq!(&got[..n], &want[..], "{c2:?}, axis {axis}");
            }
        }
    }
}
