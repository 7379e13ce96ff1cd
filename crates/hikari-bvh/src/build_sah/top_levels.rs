//! The top levels of a large build, split one level at a time by all threads together.
//!
//! Building the top on one thread and only then handing subtrees to threads leaves the other
//! threads idle through the largest nodes: for a million triangles, the first six or so levels
//! each touch every primitive. Here each level's primitives (all nodes of the level, end to
//! end) are cut into one contiguous share per thread. A level takes three steps, the first two
//! parallel over the shares (rayon fork-join, so every step sees the previous one complete):
//!
//! 1. every share is binned, one set of bins per piece (a share's part of one node);
//! 2. every share merges the bins of the nodes its pieces belong to, picks the same SAH split
//!    as a single thread would (the merge is exact), and scatters its pieces into the other
//!    buffer: the left and right counts of earlier pieces, read off their bins, say where its
//!    primitives go, so the result is exactly the stable partition of the whole node;
//! 3. the calling thread appends the children and plans the next level. Nodes of at most
//!    `threshold` primitives leave the level loop as subtrees for [`super::build`] to finish.
//!
//! Nodes move between `prims` and `scratch` at every level; a subtree remembers which one
//! holds it.

use super::bins::Bins;
use super::{
    BINS, BinNode, MEDIAN_SPLIT_DEPTH, PrimRef, Split, Task, bin_index, bin_scale, median_split,
};
use crate::aabb::Aabb;
use glam::Vec3A;
use rayon::prelude::*;
use std::ops::Range;
use std::sync::OnceLock;

/// A node left for a single thread to finish.
#[derive(Clone, Copy)]
pub(super) struct Subtree {
    pub task: Task,
    /// Its primitives are in `scratch` rather than `prims`.
    pub in_scratch: bool,
}

/// A contiguous share of one node's primitives, binned and scattered by one thread.
struct Piece {
    /// Index into `Level::tasks`.
    node: usize,
    range: Range<usize>,
}

/// Median split of a node without an SAH plane, done by one thread.
struct Median {
    mid: usize,
    boxes: [Aabb; 2],
    cbounds: [Aabb; 2],
}

/// One level: the nodes being split and the per-share results the threads fill in.
struct Level {
    tasks: Vec<Task>,
    pieces: Vec<Piece>,
    /// Thread `t` owns pieces `thread_start[t]..thread_start[t + 1]`.
    thread_start: Vec<usize>,
    /// Node `j` owns pieces `node_start[j]..node_start[j + 1]`.
    node_start: Vec<usize>,
    src_in_scratch: bool,
    bins: Vec<OnceLock<Bins<BINS>>>,
    /// Per node: the SAH split, or None where the node falls back to the median.
    splits: Vec<OnceLock<Option<Split>>>,
    /// Per piece: doubled-centroid boxes of its left and right primitives.
    piece_cbounds: Vec<OnceLock<[Aabb; 2]>>,
    medians: Vec<OnceLock<Median>>,
}

impl Level {
    fn new(tasks: Vec<Task>, src_in_scratch: bool, threads: usize) -> Level {
        let total: usize = tasks.iter().map(|t| t.end - t.begin).sum();
        let per = total.div_ceil(threads).max(1);
        let mut pieces = Vec::new();
        let mut thread_start = vec![0; threads + 1];
        let mut node_start = Vec::with_capacity(tasks.len() + 1);
        // Position of the current node's first primitive with all nodes laid end to end.
        let mut at = 0;
        for (j, t) in tasks.iter().enumerate() {
            node_start.push(pieces.len());
            let mut b = t.begin;
            while b < t.end {
                let owner = (at + b - t.begin) / per;
                // Cut where the owner's share ends.
                let e = t.end.min(t.begin + (owner + 1) * per - at);
                pieces.push(Piece {
                    node: j,
                    range: b..e,
                });
                thread_start[owner + 1] = pieces.len();
                b = e;
            }
            at += t.end - t.begin;
        }
        node_start.push(pieces.len());
        // Threads without a share start (and end) where the previous one ended.
        for t in 1..=threads {
            thread_start[t] = thread_start[t].max(thread_start[t - 1]);
        }
        let np = pieces.len();
        let nn = tasks.len();
        Level {
            tasks,
            pieces,
            thread_start,
            node_start,
            src_in_scratch,
            bins: (0..np).map(|_| OnceLock::new()).collect(),
            splits: (0..nn).map(|_| OnceLock::new()).collect(),
            piece_cbounds: (0..np).map(|_| OnceLock::new()).collect(),
            medians: (0..nn).map(|_| OnceLock::new()).collect(),
        }
    }

    fn decide(&self, j: usize) -> Option<Split> {
        let task = &self.tasks[j];
        if task.depth >= MEDIAN_SPLIT_DEPTH {
            return None;
        }
        let k = bin_scale(&task.cbounds, BINS);
        if k.cmpeq(Vec3A::ZERO).all() {
            return None;
        }
        let mut merged = Bins::<BINS>::empty();
        for q in self.node_start[j]..self.node_start[j + 1] {
            merged.merge(self.piece_bins_at(q));
        }
        merged.best_split(k, task.end - task.begin)
    }

    fn piece_bins_at(&self, q: usize) -> &Bins<BINS> {
        self.bins[q]
            .get()
            .expect("every piece is binned before the split")
    }
}

/// One of the two primitive buffers, shared by all shares of a level.
///
/// Within one step of a level the shares read the source buffer and write disjoint ranges of
/// the destination (the stable partition's prefix counts give every share its own output
/// ranges); the steps are separate parallel calls. Plain slices cannot express "disjoint ranges decided
/// at run time by other threads", hence the raw pointer.
#[derive(Clone, Copy)]
struct SharedPrims {
    ptr: *mut PrimRef,
    len: usize,
}

// SAFETY: access goes through `get`/`get_mut`, whose callers keep reads and writes of one range
// in different steps of a level (see the type's comment).
unsafe impl Send for SharedPrims {}
unsafe impl Sync for SharedPrims {}

impl SharedPrims {
    fn new(v: &mut [PrimRef]) -> Self {
        Self {
            ptr: v.as_mut_ptr(),
            len: v.len(),
        }
    }

    /// # Safety
    /// No thread may write `r` while the returned slice lives.
    unsafe fn get(&self, r: Range<usize>) -> &[PrimRef] {
        assert!(r.start <= r.end && r.end <= self.len);
        // SAFETY: in bounds (checked above); the caller rules out concurrent writes.
        unsafe { std::slice::from_raw_parts(self.ptr.add(r.start), r.len()) }
    }

    /// # Safety
    /// No other thread may read or write `r` while the returned slice lives.
    #[allow(clippy::mut_from_ref)]
    unsafe fn get_mut(&self, r: Range<usize>) -> &mut [PrimRef] {
        assert!(r.start <= r.end && r.end <= self.len);
        // SAFETY: in bounds (checked above); the caller guarantees exclusive access.
        unsafe { std::slice::from_raw_parts_mut(self.ptr.add(r.start), r.len()) }
    }
}

/// What only the calling thread touches: the node array and the finished subtrees.
struct Leader<'a> {
    nodes: &'a mut Vec<BinNode>,
    subtrees: Vec<Subtree>,
    threshold: usize,
}

/// Splits `root` (all of `prims`, node 0 of `nodes`) level by level, in `threads` shares per
/// level run on the current rayon pool, until every remaining node holds at most `threshold`
/// primitives; returns those nodes. `scratch` is as long as `prims`.
pub(super) fn split(
    prims: &mut [PrimRef],
    scratch: &mut [PrimRef],
    root: Task,
    nodes: &mut Vec<BinNode>,
    threshold: usize,
    threads: usize,
) -> Vec<Subtree> {
    debug_assert_eq!(prims.len(), scratch.len());
    if root.end - root.begin <= threshold {
        return vec![Subtree {
            task: root,
            in_scratch: false,
        }];
    }
    let prims = SharedPrims::new(prims);
    let scratch = SharedPrims::new(scratch);
    let mut leader = Leader {
        nodes,
        subtrees: Vec::new(),
        threshold,
    };
    let mut level = Level::new(vec![root], false, threads);
    while !level.tasks.is_empty() {
        let (src, dst) = if level.src_in_scratch {
            (scratch, prims)
        } else {
            (prims, scratch)
        };
        for_each_share(threads, |t| bin_share(&level, t, src));
        for_each_share(threads, |t| scatter_share(&level, t, src, dst));
        level = next_level(&level, &mut leader, threads);
    }
    leader.subtrees
}

/// `f(t)` for every share `t` of a level, each its own rayon job (one share per thread, so no
/// finer split is worth it).
fn for_each_share(threads: usize, f: impl Fn(usize) + Sync + Send) {
    if threads == 1 {
        f(0);
    } else {
        (0..threads).into_par_iter().with_max_len(1).for_each(f);
    }
}

/// Step 1: bins every piece of share `t`.
fn bin_share(level: &Level, t: usize, src: SharedPrims) {
    for q in level.thread_start[t]..level.thread_start[t + 1] {
        let p = &level.pieces[q];
        let task = &level.tasks[p.node];
        let k = bin_scale(&task.cbounds, BINS);
        // SAFETY: nobody writes the source buffer in this step.
        let ps = unsafe { src.get(p.range.clone()) };
        let _ = level.bins[q].set(Bins::accumulate(ps, task.cbounds.min, k));
    }
}

/// Step 2: decides the splits of the nodes of share `t` (whichever share gets there first) and
/// scatters its pieces; a node without an SAH split is median-split by the share holding its
/// first piece.
fn scatter_share(level: &Level, t: usize, src: SharedPrims, dst: SharedPrims) {
    for q in level.thread_start[t]..level.thread_start[t + 1] {
        let j = level.pieces[q].node;
        match level.splits[j].get_or_init(|| level.decide(j)) {
            Some(s) => scatter(level, q, s, src, dst),
            None if q == level.node_start[j] => {
                let task = &level.tasks[j];
                let r = task.begin..task.end;
                // SAFETY: without a split, no other share touches this node's range in either
                // buffer during this step: its other pieces are skipped.
                let (from, to) = unsafe { (src.get_mut(r.clone()), dst.get_mut(r)) };
                let (mid, lb, rb, lcb, rcb) = median_split(from, &task.cbounds);
                to.copy_from_slice(from);
                let _ = level.medians[j].set(Median {
                    mid,
                    boxes: [lb, rb],
                    cbounds: [lcb, rcb],
                });
            }
            None => {}
        }
    }
}

/// Moves piece `q` of its node to the destination buffer: its left primitives after the left
/// ones of earlier pieces, its right ones after all left ones and the right ones of earlier
/// pieces.
fn scatter(level: &Level, q: usize, s: &Split, src: SharedPrims, dst: SharedPrims) {
    let p = &level.pieces[q];
    let task = &level.tasks[p.node];
    let (mut left_before, mut right_before, mut left_total) = (0, 0, 0);
    let mut mine = 0;
    for r in level.node_start[p.node]..level.node_start[p.node + 1] {
        let lc = level.piece_bins_at(r).left_count(s.axis, s.bin);
        if r < q {
            left_before += lc;
            right_before += level.pieces[r].range.len() - lc;
        } else if r == q {
            mine = lc;
        }
        left_total += lc;
    }
    let left_at = task.begin + left_before;
    let right_at = task.begin + left_total + right_before;
    // SAFETY: nobody writes the source in this step; the prefix sums give every piece of the
    // node its own destination ranges, and nodes of a level cover disjoint ranges.
    let (from, to_left, to_right) = unsafe {
        (
            src.get(p.range.clone()),
            dst.get_mut(left_at..left_at + mine),
            dst.get_mut(right_at..right_at + p.range.len() - mine),
        )
    };
    let k = bin_scale(&task.cbounds, BINS);
    let (mut lmin, mut lmax) = (Vec3A::INFINITY, Vec3A::NEG_INFINITY);
    let (mut rmin, mut rmax) = (Vec3A::INFINITY, Vec3A::NEG_INFINITY);
    let (mut l, mut r) = (0, 0);
    for p in from {
        let c2 = p.lo3() + p.hi3();
        if bin_index(c2, task.cbounds.min, k, BINS)[s.axis] <= s.bin {
            to_left[l] = *p;
            l += 1;
            lmin = lmin.min(c2);
            lmax = lmax.max(c2);
        } else {
            to_right[r] = *p;
            r += 1;
            rmin = rmin.min(c2);
            rmax = rmax.max(c2);
        }
    }
    debug_assert_eq!(l, mine);
    let _ = level.piece_cbounds[q].set([Aabb::new(lmin, lmax), Aabb::new(rmin, rmax)]);
}

/// Appends the children of every node of `level` and returns the level of those still above
/// the threshold; the others become subtrees.
fn next_level(level: &Level, leader: &mut Leader, threads: usize) -> Level {
    let mut next = Vec::new();
    for (j, task) in level.tasks.iter().enumerate() {
        let split = level.splits[j]
            .get()
            .expect("every node of a level has a piece");
        let (mid, boxes, cbounds) = match split {
            Some(s) => {
                let pieces = level.node_start[j]..level.node_start[j + 1];
                let mut left = 0;
                let mut cb = [Aabb::EMPTY; 2];
                for q in pieces {
                    left += level.piece_bins_at(q).left_count(s.axis, s.bin);
                    let pc = level.piece_cbounds[q]
                        .get()
                        .expect("every piece is scattered");
                    cb[0].grow(&pc[0]);
                    cb[1].grow(&pc[1]);
                }
                (task.begin + left, [s.left, s.right], cb)
            }
            None => {
                let m = level.medians[j]
                    .get()
                    .expect("a node without a split is median-split");
                (task.begin + m.mid, m.boxes, m.cbounds)
            }
        };
        let first = leader.nodes.len() as u32;
        let ranges = [task.begin..mid, mid..task.end];
        for (b, r) in boxes.iter().zip(&ranges) {
            leader.nodes.push(BinNode {
                bounds: *b,
                first: 0,
                count: 0,
                prims: r.len() as u32,
            });
        }
        leader.nodes[task.node as usize].first = first;
        for (c, r) in ranges.into_iter().enumerate() {
            let child = Task {
                node: first + c as u32,
                begin: r.start,
                end: r.end,
                cbounds: cbounds[c],
                depth: task.depth + 1,
            };
            if r.len() > leader.threshold {
                next.push(child);
            } else {
                leader.subtrees.push(Subtree {
                    task: child,
                    in_scratch: !level.src_in_scratch,
                });
            }
        }
    }
    Level::new(next, !level.src_in_scratch, threads)
}
