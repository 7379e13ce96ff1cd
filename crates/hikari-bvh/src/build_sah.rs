//! Binary BVH over primitive boxes by binned SAH, the first stage of every build (BLAS and TLAS).
//!
//! Primitives travel as 32-byte [`PrimRef`]s (box plus id) that the partition moves in place, so
//! every pass over a node reads memory sequentially. The top of the tree is built on one thread
//! until enough independent subtrees exist; those are then built on scoped threads into their own
//! node arrays and stitched in a fixed order, so the result is identical for any thread count.

use crate::aabb::Aabb;
use glam::{Vec3A, Vec4};

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
/// Subtrees smaller than this are never handed to another thread.
const MIN_PARALLEL_PRIMS: usize = 16 * 1024;

/// A primitive's box; `lo.w` holds the primitive id as the bits of a normal float (`ID_TAG | id`):
/// the SIMD box arithmetic also runs on the w lane, and a raw small integer there would be a
/// denormal, which costs a microcode assist on every operation.
#[derive(Clone, Copy, Debug)]
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
}

impl BinNode {
    #[inline]
    pub fn is_leaf(&self) -> bool {
        self.count > 0
    }
}

pub struct BinaryBvh {
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
pub fn build(mut prims: Vec<PrimRef>, params: &SahParams) -> BinaryBvh {
    assert!(!prims.is_empty());
    let mut bounds = Aabb::EMPTY;
    let mut cbounds = Aabb::EMPTY;
    for p in &prims {
        bounds.grow(&Aabb::new(p.lo3(), p.hi3()));
        cbounds.grow_point(p.c2());
    }
    // A binary tree over n primitives has at most 2n - 1 nodes.
    let mut nodes = Vec::with_capacity(2 * prims.len());
    nodes.push(BinNode {
        bounds,
        first: 0,
        count: 0,
    });
    let root = Task {
        node: 0,
        begin: 0,
        end: prims.len(),
        cbounds,
        depth: 0,
    };
    let threads = params.threads.max(1);
    if threads == 1 || prims.len() < 2 * MIN_PARALLEL_PRIMS {
        build_tasks(&mut prims, 0, &mut nodes, vec![root], params, None);
        return BinaryBvh { nodes, prims };
    }

    // Split the top sequentially until there are several subtrees per thread, so the threads
    // stay busy even when SAH splits are uneven.
    let threshold = (prims.len() / (threads * 4)).max(MIN_PARALLEL_PRIMS);
    let mut deferred = Vec::new();
    build_tasks(
        &mut prims,
        0,
        &mut nodes,
        vec![root],
        params,
        Some((threshold, &mut deferred)),
    );
    deferred.sort_by_key(|t: &Task| t.begin);

    // Hand out disjoint slices of the primitive array, one per deferred subtree.
    let mut slices: Vec<(Task, &mut [PrimRef])> = Vec::with_capacity(deferred.len());
    let mut rest: &mut [PrimRef] = &mut prims;
    let mut consumed = 0;
    for t in &deferred {
        let (_, tail) = rest.split_at_mut(t.begin - consumed);
        let (mine, tail) = tail.split_at_mut(t.end - t.begin);
        slices.push((*t, mine));
        rest = tail;
        consumed = t.end;
    }
    // Largest subtrees first, each to the least loaded thread: a fixed assignment, so the
    // work split (though not the result, which never depends on it) is reproducible too.
    let mut order: Vec<usize> = (0..slices.len()).collect();
    order.sort_by_key(|&i| std::cmp::Reverse(slices[i].1.len()));
    let mut groups: Vec<(usize, Vec<usize>)> = (0..threads).map(|_| (0, Vec::new())).collect();
    for i in order {
        let g = groups.iter_mut().min_by_key(|g| g.0).unwrap();
        g.0 += slices[i].1.len();
        g.1.push(i);
    }
    let mut work: Vec<Vec<(usize, Task, &mut [PrimRef])>> = Vec::new();
    let mut taken: Vec<Option<(Task, &mut [PrimRef])>> = slices.into_iter().map(Some).collect();
    for (_, members) in &groups {
        work.push(
            members
                .iter()
                .map(|&i| {
                    let (t, s) = taken[i].take().unwrap();
                    (i, t, s)
                })
                .collect(),
        );
    }
    let top: &[BinNode] = &nodes;
    let mut results: Vec<(usize, Vec<BinNode>)> = std::thread::scope(|scope| {
        let handles: Vec<_> = work
            .into_iter()
            .map(|jobs| {
                scope.spawn(move || {
                    jobs.into_iter()
                        .map(|(i, task, slice)| (i, build_subtree(slice, task, top, params)))
                        .collect::<Vec<_>>()
                })
            })
            .collect();
        handles
            .into_iter()
            .flat_map(|h| h.join().expect("BVH build thread panicked"))
            .collect()
    });
    results.sort_by_key(|r| r.0);
    for (task, (_, sub)) in deferred.iter().zip(results) {
        stitch(&mut nodes, task.node, sub);
    }
    BinaryBvh { nodes, prims }
}

/// Builds one deferred subtree into its own array, root at index 0, primitive indices global.
fn build_subtree(
    slice: &mut [PrimRef],
    task: Task,
    top: &[BinNode],
    params: &SahParams,
) -> Vec<BinNode> {
    let mut nodes = Vec::with_capacity(slice.len() * 2 / params.max_leaf.max(1) + 8);
    nodes.push(top[task.node as usize]);
    let local = Task {
        node: 0,
        begin: 0,
        end: slice.len(),
        ..task
    };
    build_tasks(slice, task.begin, &mut nodes, vec![local], params, None);
    nodes
}

/// Appends a subtree built with its root at local index 0, replacing the placeholder `at`.
fn stitch(nodes: &mut Vec<BinNode>, at: u32, sub: Vec<BinNode>) {
    // Local index i >= 1 moves to base + i - 1.
    fn remap(n: &BinNode, base: u32) -> BinNode {
        let mut n = *n;
        if !n.is_leaf() {
            n.first = base + n.first - 1;
        }
        n
    }
    let base = nodes.len() as u32;
    nodes[at as usize] = remap(&sub[0], base);
    nodes.extend(sub[1..].iter().map(|n| remap(n, base)));
}

fn build_tasks(
    prims: &mut [PrimRef],
    prim_offset: usize,
    nodes: &mut Vec<BinNode>,
    mut stack: Vec<Task>,
    params: &SahParams,
    mut defer: Option<(usize, &mut Vec<Task>)>,
) {
    while let Some(task) = stack.pop() {
        let n = task.end - task.begin;
        if let Some((threshold, deferred)) = defer.as_mut()
            && n <= *threshold
        {
            deferred.push(Task {
                begin: task.begin + prim_offset,
                end: task.end + prim_offset,
                ..task
            });
            continue;
        }
        let make_leaf = |nodes: &mut Vec<BinNode>| {
            let node = &mut nodes[task.node as usize];
            node.first = (task.begin + prim_offset) as u32;
            node.count = n as u32;
        };
        // The wide collapse turns every subtree of at most `max_leaf` primitives into one leaf
        // child anyway, so splitting it here would only cost time.
        if n <= params.max_leaf.max(1) {
            make_leaf(nodes);
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
                let (mid, lcb, rcb) = partition(range, &task.cbounds, &s);
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
    nodes: &mut Vec<BinNode>,
    stack: &mut Vec<Task>,
    task: &Task,
    split_at: usize,
    boxes: [Aabb; 2],
    cbounds: [Aabb; 2],
) {
    let left = nodes.len() as u32;
    for b in boxes {
        nodes.push(BinNode {
            bounds: b,
            first: 0,
            count: 0,
        });
    }
    let node = &mut nodes[task.node as usize];
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
        // The only split there is (common in the TLAS, with one instance per leaf).
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
    for axis in [0usize, 1, 2] {
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
    let nb = NB;
    let k = bin_scale(cb, nb);
    if k.cmpeq(Vec3A::ZERO).all() {
        return None;
    }
    // Two interleaved sets of bins: neighbouring primitives usually fall into the same bin, and
    // with one set every update would wait on the store of the previous one.
    let mut lo = [[[Vec3A::INFINITY; NB]; 3]; 2];
    let mut hi = [[[Vec3A::NEG_INFINITY; NB]; 3]; 2];
    let mut count = [[[0u32; NB]; 3]; 2];
    let mut pairs = prims.chunks_exact(2);
    for pair in &mut pairs {
        for (set, p) in pair.iter().enumerate() {
            let l = p.lo3();
            let h = p.hi3();
            let b = bin_index(l + h, cb.min, k, nb);
            for a in 0..3 {
                lo[set][a][b[a]] = lo[set][a][b[a]].min(l);
                hi[set][a][b[a]] = hi[set][a][b[a]].max(h);
                count[set][a][b[a]] += 1;
            }
        }
    }
    for p in pairs.remainder() {
        let l = p.lo3();
        let h = p.hi3();
        let b = bin_index(l + h, cb.min, k, nb);
        for a in 0..3 {
            lo[0][a][b[a]] = lo[0][a][b[a]].min(l);
            hi[0][a][b[a]] = hi[0][a][b[a]].max(h);
            count[0][a][b[a]] += 1;
        }
    }
    let [mut lo, lo1] = lo;
    let [mut hi, hi1] = hi;
    let [mut count, count1] = count;
    for a in 0..3 {
        for i in 0..nb {
            lo[a][i] = lo[a][i].min(lo1[a][i]);
            hi[a][i] = hi[a][i].max(hi1[a][i]);
            count[a][i] += count1[a][i];
        }
    }
    let mut best: Option<(f32, usize, usize)> = None;
    for a in 0..3 {
        if k[a] == 0.0 {
            continue;
        }
        // Right-to-left sweep: cost of the right side of each split plane.
        let mut right_cost = [0.0f32; NB];
        let mut l = Vec3A::INFINITY;
        let mut h = Vec3A::NEG_INFINITY;
        let mut cnt = 0;
        for i in (1..nb).rev() {
            cnt += count[a][i];
            if cnt > 0 {
                l = l.min(lo[a][i]);
                h = h.max(hi[a][i]);
                right_cost[i] = half_area(l, h) * cnt as f32;
            }
        }
        let mut l = Vec3A::INFINITY;
        let mut h = Vec3A::NEG_INFINITY;
        let mut cnt = 0;
        for i in 0..nb - 1 {
            cnt += count[a][i];
            if cnt == 0 {
                continue;
            }
            l = l.min(lo[a][i]);
            h = h.max(hi[a][i]);
            if cnt as usize == prims.len() {
                break;
            }
            let cost = half_area(l, h) * cnt as f32 + right_cost[i + 1];
            if best.is_none_or(|b| cost < b.0) {
                best = Some((cost, a, i));
            }
        }
    }
    let (_, axis, bin) = best?;
    let mut left = Aabb::EMPTY;
    let mut right = Aabb::EMPTY;
    for i in 0..nb {
        if count[axis][i] == 0 {
            continue;
        }
        let side = if i <= bin { &mut left } else { &mut right };
        side.grow(&Aabb::new(lo[axis][i], hi[axis][i]));
    }
    Some(Split {
        axis,
        bin,
        bins: nb,
        left,
        right,
    })
}

/// Moves primitives whose centroid bin is `<= bin` to the front; returns the split point and
/// the centroid boxes of both sides.
fn partition(prims: &mut [PrimRef], cb: &Aabb, s: &Split) -> (usize, Aabb, Aabb) {
    let (axis, bin, bins) = (s.axis, s.bin, s.bins);
    let k = bin_scale(cb, bins);
    let (mut lmin, mut lmax) = (Vec3A::INFINITY, Vec3A::NEG_INFINITY);
    let (mut rmin, mut rmax) = (Vec3A::INFINITY, Vec3A::NEG_INFINITY);
    // Branch-free Lomuto: a side decision per primitive is a coin flip for the branch
    // predictor, so swap unconditionally and advance the boundary by the decision instead.
    let mut l = 0;
    for i in 0..prims.len() {
        let p = prims[i];
        let c2 = p.c2();
        let left = bin_index(c2, cb.min, k, bins)[axis] <= bin;
        prims[i] = prims[l];
        prims[l] = p;
        l += left as usize;
        let m = glam::BVec3A::splat(left);
        lmin = lmin.min(Vec3A::select(m, c2, Vec3A::INFINITY));
        lmax = lmax.max(Vec3A::select(m, c2, Vec3A::NEG_INFINITY));
        rmin = rmin.min(Vec3A::select(m, Vec3A::INFINITY, c2));
        rmax = rmax.max(Vec3A::select(m, Vec3A::NEG_INFINITY, c2));
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
