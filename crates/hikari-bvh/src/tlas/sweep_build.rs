//! The TLAS's own builder: instances sorted once along a Morton curve, then wide nodes emitted
//! top-down directly, each by splitting contiguous ranges of that order where the surface area
//! heuristic finds them cheapest. No partitioning, no binary tree, no collapse.
//!
//! Why not the BLAS builder: a TLAS is rebuilt every frame from at most a few thousand
//! instances, where the binned builder's fixed costs (clearing and sweeping 3 x 16 bins per
//! node, a partition, then a separate collapse of the binary tree) dominate. Here the sort is
//! one radix sort, a split of a range of `m` instances is two passes over `m` boxes that
//! already lie in order (or a pass over chunk boxes for large ranges), and the children are
//! contiguous ranges. The candidate splits are only those the Morton order allows, which is
//! where quality could be lost: on the village, rays visit 6-15% fewer TLAS nodes than in the
//! binned builder's tree and enter 1-2% more instances; on synthetic scenes the SAH cost came
//! out between 4% below and 14% above the binned builder's (see BENCHMARKS.md).
//!
//! A node is made the way the BLAS collapse makes one: starting from its whole range, the child
//! with the largest box is split until there are eight children or every child holds at most
//! eight instances. Then, while slots are free, the small child with the largest box whose
//! instances all fit in them is replaced by those instances: a ray that would have entered it
//! tests them in this node instead of visiting one more node (on the village, against not
//! doing so: a sixth fewer nodes, 5% fewer node visits per ray, under 1% more instances
//! entered, and a faster build). A child of one instance becomes a leaf slot, any other child
//! a node.

use super::morton::{Grid, sort_by_code};
use crate::aabb::Aabb;
use crate::build_sah::PrimRef;
use crate::layout::{META_INTERNAL, WIDTH, WideNode, leaf_meta};
use crate::wide::{assign_slots, encode_children};
use glam::{Vec3A, Vec3Swizzles};

/// From this many binary splits below the root on, ranges are split at their middle instead of
/// by SAH, so the tree depth (and the traversal stack) stays bounded whatever the input: SAH can
/// peel instances off one at a time (nested boxes of geometric sizes).
const MEDIAN_SPLIT_DEPTH: u32 = 40;
/// Ranges up to this size are split by an exact sweep over every position.
const EXACT_UP_TO: usize = 24;
/// Larger ranges first choose among the boundaries of chunks of about this many boxes...
const CHUNK: usize = 8;
/// ...and at most this many chunks.
const MAX_CHUNKS: usize = 32;

/// A range of the sorted instances that becomes a wide node.
#[derive(Clone, Copy)]
struct Pending {
    begin: u32,
    end: u32,
    node: u32,
    /// Wide levels from the root (1 = root).
    depth: u32,
    /// Binary splits from the root.
    splits: u32,
    bounds: Aabb,
}

/// The children of the node being made, in the order they were split off.
struct Kids {
    /// Ranges of the sorted instances.
    range: [(u32, u32); WIDTH],
    bounds: [Aabb; WIDTH],
    /// Binary splits from the root.
    splits: [u32; WIDTH],
    count: usize,
}

/// Buffers kept from one build to the next.
#[derive(Default)]
pub(crate) struct SweepBuilder {
    keys: Vec<u64>,
    keys_scratch: Vec<u64>,
    /// Instance boxes and ids in Morton order.
    boxes: Vec<PrimRef>,
    /// Per-position scratch of the splits (suffix and chunk boxes).
    scratch: Vec<Aabb>,
    stack: Vec<Pending>,
}

/// What [`SweepBuilder::build`] returns besides the nodes and leaves it writes.
pub(crate) struct Built {
    pub bounds: Aabb,
    /// Wide levels on the longest root-to-leaf path.
    pub depth: u32,
}

impl SweepBuilder {
    /// Builds the wide nodes over the instances `ids`, whose world boxes (finite, non-empty)
    /// are `bounds[id]`: `nodes` gets them (root first, every child after its parent) and
    /// `leaves` the ids in leaf order; both are cleared first. `ids` must not be empty.
    pub(crate) fn build(
        &mut self,
        bounds: &[Aabb],
        ids: &[u32],
        nodes: &mut Vec<WideNode>,
        leaves: &mut Vec<u32>,
    ) -> Built {
        debug_assert!(!ids.is_empty());
        let n = ids.len();
        let mut root = Aabb::EMPTY;
        let mut centres = Aabb::EMPTY;
        for &id in ids {
            let b = &bounds[id as usize];
            root.grow(b);
            centres.grow_point(b.center());
        }
        // Keys: Morton code, then the position in `ids`, which makes the order deterministic.
        let grid = Grid::new(&centres);
        self.keys.clear();
        self.keys.extend(
            ids.iter()
                .enumerate()
                .map(|(k, &id)| (grid.code(bounds[id as usize].center()) as u64) << 32 | k as u64),
        );
        sort_by_code(&mut self.keys, &mut self.keys_scratch);
        self.boxes.clear();
        self.boxes.extend(self.keys.iter().map(|&k| {
            let id = ids[k as u32 as usize];
            PrimRef::new(&bounds[id as usize], id)
        }));
        if self.scratch.len() < n {
            self.scratch.resize(n, Aabb::EMPTY);
        }

        nodes.clear();
        leaves.clear();
        leaves.reserve(n);
        nodes.push(WideNode::default());
        let mut depth = 1;
        self.stack.clear();
        self.stack.push(Pending {
            begin: 0,
            end: n as u32,
            node: 0,
            depth: 1,
            splits: 0,
            bounds: root,
        });
        while let Some(p) = self.stack.pop() {
            depth = depth.max(p.depth);
            let mut kids = Kids {
                range: [(0, 0); WIDTH],
                bounds: [Aabb::EMPTY; WIDTH],
                splits: [p.splits; WIDTH],
                count: 0,
            };
            let len = (p.end - p.begin) as usize;
            if len <= WIDTH {
                kids.count = len;
                for k in 0..len {
                    let i = p.begin + k as u32;
                    kids.range[k] = (i, i + 1);
                    kids.bounds[k] = aabb(&self.boxes[i as usize]);
                }
            } else {
                self.open(&p, &mut kids);
            }
            let count = kids.count;
            let mut centres = [Vec3A::ZERO; WIDTH];
            for (c, b) in centres.iter_mut().zip(&kids.bounds[..count]) {
                *c = b.center();
            }
            let slots = assign_slots(p.bounds.center(), &centres[..count]);

            let mut node = WideNode {
                child_base: nodes.len() as u32,
                prim_base: leaves.len() as u32,
                ..Default::default()
            };
            let mut meta = [0u8; WIDTH];
            let mut imask = 0u8;
            let mut leaf_offset = 0;
            let stack_start = self.stack.len();
            for (slot, k) in slots.iter().enumerate() {
                let Some(k) = *k else { continue };
                let (begin, end) = kids.range[k as usize];
                if end - begin == 1 {
                    leaves.push(self.boxes[begin as usize].id());
                    meta[slot] = leaf_meta(leaf_offset, 1);
                    leaf_offset += 1;
                } else {
                    // Internal children are allocated contiguously in slot order.
                    imask |= 1 << slot;
                    meta[slot] = META_INTERNAL | slot as u8;
                    self.stack.push(Pending {
                        begin,
                        end,
                        node: nodes.len() as u32,
                        depth: p.depth + 1,
                        splits: kids.splits[k as usize],
                        bounds: kids.bounds[k as usize],
                    });
                    nodes.push(WideNode::default());
                }
            }
            // Reversed so the lowest slot is popped, and emitted, first (depth-first order).
            self.stack[stack_start..].reverse();
            node.meta = [
                u32::from_le_bytes([meta[0], meta[1], meta[2], meta[3]]),
                u32::from_le_bytes([meta[4], meta[5], meta[6], meta[7]]),
            ];
            encode_children(&mut node, &kids.bounds[..count], &slots, imask);
            nodes[p.node as usize] = node;
        }
        Built {
            bounds: root,
            depth,
        }
    }

    pub(crate) fn capacity_bytes(&self) -> usize {
        use std::mem::size_of;
        (self.keys.capacity() + self.keys_scratch.capacity()) * size_of::<u64>()
            + self.boxes.capacity() * size_of::<PrimRef>()
            + self.scratch.capacity() * size_of::<Aabb>()
            + self.stack.capacity() * size_of::<Pending>()
    }

    /// Splits the range of `p` (more than [`WIDTH`] instances) into `kids`: repeatedly the
    /// child with the largest box (the one most rays enter) among those of more than
    /// [`WIDTH`] instances, until there are [`WIDTH`] children or none is that large; then
    /// fills free slots with the instances of small children, largest box first.
    fn open(&mut self, p: &Pending, kids: &mut Kids) {
        kids.range[0] = (p.begin, p.end);
        kids.bounds[0] = p.bounds;
        let mut count = 1;
        // Per child, the area that ranks it for opening; negative: not opened.
        let mut rank = [-1.0f32; WIDTH];
        rank[0] = open_rank(p.end - p.begin, &p.bounds);
        while count < WIDTH {
            let mut best = 0;
            for k in 1..count {
                if rank[k] > rank[best] {
                    best = k;
                }
            }
            if rank[best] < 0.0 {
                break;
            }
            let (begin, end) = kids.range[best];
            let range = begin as usize..end as usize;
            let (mid, left, right) = split(
                &self.boxes[range.clone()],
                &kids.bounds[best],
                &mut self.scratch[range],
                kids.splits[best],
            );
            let mid = begin + mid as u32;
            let splits = kids.splits[best] + 1;
            kids.range[best] = (begin, mid);
            kids.range[count] = (mid, end);
            kids.bounds[best] = left;
            kids.bounds[count] = right;
            kids.splits[best] = splits;
            kids.splits[count] = splits;
            rank[best] = open_rank(mid - begin, &left);
            rank[count] = open_rank(end - mid, &right);
            count += 1;
        }
        // Slots left free: the small child with the largest box whose instances all fit
        // becomes leaf slots of this node (one node fewer to visit), and so on.
        loop {
            let free = WIDTH - count;
            let mut best = usize::MAX;
            let mut best_area = f32::NEG_INFINITY;
            for k in 0..count {
                let (b, e) = kids.range[k];
                let len = (e - b) as usize;
                if len >= 2 && len - 1 <= free {
                    let a = half_area(&kids.bounds[k]);
                    // NaN areas (boxes near +-f32::MAX) compare false: taken only if alone.
                    if best == usize::MAX || a > best_area {
                        best = k;
                        best_area = a;
                    }
                }
            }
            if best == usize::MAX {
                break;
            }
            let (b, e) = kids.range[best];
            kids.range[best] = (b, b + 1);
            kids.bounds[best] = aabb(&self.boxes[b as usize]);
            for i in b + 1..e {
                kids.range[count] = (i, i + 1);
                kids.bounds[count] = aabb(&self.boxes[i as usize]);
                count += 1;
            }
        }
        kids.count = count;
    }
}

/// How urgently a child of `len` instances is split: its area if it holds more than [`WIDTH`]
/// (infinite if the area is NaN, from boxes near +-f32::MAX), -1 if it is not split.
#[inline]
fn open_rank(len: u32, bounds: &Aabb) -> f32 {
    if len as usize <= WIDTH {
        return -1.0;
    }
    let a = half_area(bounds);
    if a.is_nan() { f32::INFINITY } else { a }
}

/// Half the surface area of a non-empty box.
#[inline]
fn half_area(b: &Aabb) -> f32 {
    let e = b.max - b.min;
    e.x * e.y + e.y * e.z + e.z * e.x
}

/// The box of an instance record.
#[inline]
fn aabb(p: &PrimRef) -> Aabb {
    Aabb::new(p.lo3(), p.hi3())
}

/// Splits a range of at least two boxes (whose union is `bounds`) where the surface area
/// heuristic is lowest (see [`SplitCost`]); returns the split position and both sides' boxes.
/// `scratch` is as long as `boxes`.
///
/// Small ranges try every position. A large one is cut into equal chunks, the best chunk
/// boundary is found from the chunks' boxes (one cheap pass over the range instead of two
/// dependent sweeps), and then every position between the two neighbouring boundaries is tried.
fn split(
    boxes: &[PrimRef],
    bounds: &Aabb,
    scratch: &mut [Aabb],
    splits: u32,
) -> (usize, Aabb, Aabb) {
    let m = boxes.len();
    debug_assert!(m >= 2);
    if splits < MEDIAN_SPLIT_DEPTH {
        let cost = SplitCost::new(m, bounds);
        let found = if m <= EXACT_UP_TO {
            sweep(boxes, 0, m, Aabb::EMPTY, Aabb::EMPTY, &cost, scratch)
        } else {
            chunked(boxes, &cost, scratch)
        };
        // None only if every cost was NaN (boxes of infinite area): fall back to the middle.
        if let Some(found) = found {
            return found;
        }
    }
    let mid = m / 2;
    (mid, union(&boxes[..mid]), union(&boxes[mid..]))
}

/// Cost of splitting `m` boxes at position `i` into a left box `L` and a right box `R`:
/// `area(L) * i + area(R) * (m - i)` (the surface area heuristic, areas halved), plus
/// `1e-5 * area(all) * |2i - m|`. The last term is far below any real difference between
/// splits; it breaks ties, which rounding makes inexact, toward the middle, so that many equal
/// boxes are split evenly instead of one at a time.
struct SplitCost {
    m: f32,
    bias: f32,
}

impl SplitCost {
    fn new(m: usize, bounds: &Aabb) -> Self {
        SplitCost {
            m: m as f32,
            bias: 1e-5 * half_area(bounds),
        }
    }

    /// `i` as a float (exact below 2^24).
    #[inline]
    fn at(&self, left: &Aabb, right: &Aabb, i: f32) -> f32 {
        // Both half areas at once: lanes (x y, y z, z x) of each extent, weighted, summed.
        let (el, er) = (left.max - left.min, right.max - right.min);
        let v = el * el.yzx() * i + er * er.yzx() * (self.m - i);
        v.element_sum() + self.bias * (2.0 * i - self.m).abs()
    }
}

/// [`split`] of a large range: the best chunk boundary, then the exact sweep around it.
fn chunked(
    boxes: &[PrimRef],
    cost: &SplitCost,
    scratch: &mut [Aabb],
) -> Option<(usize, Aabb, Aabb)> {
    let m = boxes.len();
    let chunks = (m / CHUNK).clamp(2, MAX_CHUNKS);
    // Chunk k is boxes[bound[k]..bound[k + 1]].
    let mut bound = [0usize; MAX_CHUNKS + 1];
    for (k, b) in bound[..=chunks].iter_mut().enumerate() {
        *b = k * m / chunks;
    }
    // Chunk boxes, then the boxes of all chunks from k on, in the scratch space (at least
    // `2 * chunks + 1` long, as chunks hold several boxes each).
    let (chunk, after) = scratch.split_at_mut(chunks);
    for (k, c) in chunk.iter_mut().enumerate() {
        *c = union(&boxes[bound[k]..bound[k + 1]]);
    }
    after[chunks] = Aabb::EMPTY;
    for k in (1..chunks).rev() {
        after[k] = after[k + 1].union(&chunk[k]);
    }
    let mut before = Aabb::EMPTY;
    let mut best_cost = f32::INFINITY;
    let mut best = None;
    for k in 1..chunks {
        // The chunks before k - 1, kept for the exact sweep.
        let previous = before;
        before.grow(&chunk[k - 1]);
        let c = cost.at(&before, &after[k], bound[k] as f32);
        if c < best_cost {
            best_cost = c;
            best = Some((k, previous));
        }
    }
    let (k, previous) = best?;
    let next = after[k + 1];
    sweep(
        boxes,
        bound[k - 1],
        bound[k + 1],
        previous,
        next,
        cost,
        scratch,
    )
}

/// The cheapest split of `boxes` among the positions strictly between `lo` and `hi`, where
/// `before` is the box of `boxes[..lo]` and `after` that of `boxes[hi..]`: the split position,
/// left box and right box. `None` if every cost is NaN. The first of equal costs wins.
fn sweep(
    boxes: &[PrimRef],
    lo: usize,
    hi: usize,
    before: Aabb,
    after: Aabb,
    cost: &SplitCost,
    suffix: &mut [Aabb],
) -> Option<(usize, Aabb, Aabb)> {
    let mut acc = after;
    for i in (lo + 1..hi).rev() {
        acc.grow(&aabb(&boxes[i]));
        suffix[i] = acc;
    }
    let mut acc = before;
    let mut best_cost = f32::INFINITY;
    let mut best = None;
    let mut fi = lo as f32;
    for i in lo + 1..hi {
        acc.grow(&aabb(&boxes[i - 1]));
        fi += 1.0;
        let c = cost.at(&acc, &suffix[i], fi);
        if c < best_cost {
            best_cost = c;
            best = Some((i, acc));
        }
    }
    best.map(|(i, left)| (i, left, suffix[i]))
}

/// Box of a non-empty run of boxes, with two accumulators so that consecutive boxes do not wait
/// on each other.
fn union(boxes: &[PrimRef]) -> Aabb {
    let (mut a, mut b) = (Aabb::EMPTY, Aabb::EMPTY);
    let mut pairs = boxes.chunks_exact(2);
    for p in &mut pairs {
        a.grow(&aabb(&p[0]));
        b.grow(&aabb(&p[1]));
    }
    for x in pairs.remainder() {
        a.grow(&aabb(x));
    }
    a.union(&b)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::SplitMix64;

    fn refs(boxes: &[Aabb]) -> Vec<PrimRef> {
        boxes
            .iter()
            .enumerate()
            .map(|(i, b)| PrimRef::new(b, i as u32))
            .collect()
    }

    fn union_of(boxes: &[Aabb]) -> Aabb {
        boxes.iter().fold(Aabb::EMPTY, |u, b| u.union(b))
    }

    /// Every split position's cost from boxes made from scratch, and the cheapest (first of
    /// equal ones).
    fn cheapest_by_brute_force(boxes: &[Aabb]) -> (usize, f32) {
        let m = boxes.len();
        let cost = SplitCost::new(m, &union_of(boxes));
        (1..m)
            .map(|i| {
                let c = cost.at(&union_of(&boxes[..i]), &union_of(&boxes[i..]), i as f32);
                (i, c)
            })
            .fold((0, f32::INFINITY), |b, c| if c.1 < b.1 { c } else { b })
    }

    fn random_boxes(rng: &mut SplitMix64, m: usize) -> Vec<Aabb> {
        let mut boxes: Vec<Aabb> = (0..m)
            .map(|_| {
                let c = Vec3A::new(
                    rng.range(-50.0, 50.0),
                    rng.range(-5.0, 5.0),
                    rng.range(-50.0, 50.0),
                );
                let e = Vec3A::new(
                    rng.range(0.1, 3.0),
                    rng.range(0.1, 3.0),
                    rng.range(0.1, 3.0),
                );
                Aabb::new(c - e, c + e)
            })
            .collect();
        // Roughly in order along x, as a Morton order would have them.
        boxes.sort_by(|a, b| a.min.x.total_cmp(&b.min.x));
        boxes
    }

    fn split_of(boxes: &[Aabb]) -> (usize, Aabb, Aabb) {
        let m = boxes.len();
        split(&refs(boxes), &union_of(boxes), &mut vec![Aabb::EMPTY; m], 0)
    }

    #[test]
    fn small_ranges_split_where_the_cost_is_lowest() {
        let mut rng = SplitMix64::new(41);
        for _ in 0..2000 {
            let m = 2 + rng.below(EXACT_UP_TO - 1);
            let boxes = random_boxes(&mut rng, m);
            let (mid, left, right) = split_of(&boxes);
            assert_eq!(mid, cheapest_by_brute_force(&boxes).0, "{m} boxes");
            assert_eq!(left, union_of(&boxes[..mid]));
            assert_eq!(right, union_of(&boxes[mid..]));
        }
    }

    #[test]
    fn large_ranges_split_nearly_where_the_cost_is_lowest() {
        // The chunked search may miss the cheapest position, but its split must be a real one
        // with the right boxes, and nearly as cheap.
        let mut rng = SplitMix64::new(42);
        for _ in 0..300 {
            let m = EXACT_UP_TO + 1 + rng.below(2000);
            let boxes = random_boxes(&mut rng, m);
            let (mid, left, right) = split_of(&boxes);
            assert!((1..m).contains(&mid));
            assert_eq!(left, union_of(&boxes[..mid]));
            assert_eq!(right, union_of(&boxes[mid..]));
            let got = SplitCost::new(m, &union_of(&boxes)).at(&left, &right, mid as f32);
            let (_, best) = cheapest_by_brute_force(&boxes);
            assert!(got <= best * 1.1, "{m} boxes: cost {got}, cheapest {best}");
        }
    }

    #[test]
    fn equal_boxes_split_in_the_middle() {
        for m in [2usize, 3, 10, 24, 25, 100, 1000, 4097] {
            let boxes = vec![Aabb::new(Vec3A::splat(1.0), Vec3A::splat(2.5)); m];
            let (mid, _, _) = split_of(&boxes);
            // Rounding may move it a little, never far.
            assert!(
                mid.abs_diff(m / 2) <= (m / 16).max(1),
                "{m} boxes split at {mid}"
            );
        }
    }

    #[test]
    fn boxes_of_infinite_area_split_in_the_middle() {
        let huge = Aabb::new(Vec3A::splat(-3e38), Vec3A::splat(3e38));
        for m in [2usize, 5, 40] {
            let (mid, left, right) = split_of(&vec![huge; m]);
            assert_eq!(mid, m / 2);
            assert_eq!((left, right), (huge, huge));
        }
    }
}
