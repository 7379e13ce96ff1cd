//! Fork-join helpers on scoped std threads, shared by the build phases (primitive boxes, binary
//! build, collapse, triangle records). Each call starts its threads afresh (tens of microseconds
//! for 16 threads), which a build of a million triangles does only a handful of times.

use std::mem::MaybeUninit;
use std::ops::Range;

use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};

/// Calls `f` on every item on up to `threads` threads, the calling thread being one of them,
/// and returns the results in item order. Items are taken in order from a shared counter, so
/// callers put the largest first for balance; which thread ran an item never shows in the
/// result.
pub(crate) fn map_dynamic<T: Send, R: Send>(
    threads: usize,
    items: Vec<T>,
    f: impl Fn(T) -> R + Sync,
) -> Vec<R> {
    let n = items.len();
    let threads = threads.clamp(1, n.max(1));
    if threads == 1 {
        return items.into_iter().map(f).collect();
    }
    let slots: Vec<Mutex<Option<T>>> = items.into_iter().map(|t| Mutex::new(Some(t))).collect();
    let next = AtomicUsize::new(0);
    let work = || {
        let mut out = Vec::new();
        loop {
            let i = next.fetch_add(1, Ordering::Relaxed);
            if i >= n {
                return out;
            }
            // Every index is handed out once, so the slot is always full and never contended.
            let item = slots[i]
                .lock()
                .unwrap_or_else(|e| e.into_inner())
                .take()
                .expect("each work item is taken once");
            out.push((i, f(item)));
        }
    };
    let mut all: Vec<(usize, R)> = std::thread::scope(|scope| {
        let handles: Vec<_> = (1..threads).map(|_| scope.spawn(work)).collect();
        let mut all = work();
        for h in handles {
            all.extend(h.join().expect("BVH build thread panicked"));
        }
        all
    });
    all.sort_unstable_by_key(|r| r.0);
    all.into_iter().map(|r| r.1).collect()
}

/// [`map_dynamic`] handing out the items of largest `weight` first (ties in item order), so that
/// a large item drawn last does not hold up the others; results in item order.
pub(crate) fn map_largest_first<T: Send, R: Send>(
    threads: usize,
    items: Vec<T>,
    weight: impl Fn(&T) -> usize,
    f: impl Fn(T) -> R + Sync,
) -> Vec<R> {
    let mut order: Vec<usize> = (0..items.len()).collect();
    order.sort_by_key(|&i| std::cmp::Reverse(weight(&items[i])));
    let mut slots: Vec<Option<T>> = items.into_iter().map(Some).collect();
    let ordered: Vec<(usize, T)> = order
        .iter()
        .map(|&i| (i, slots[i].take().expect("indices are distinct")))
        .collect();
    let mut out: Vec<Option<R>> = slots.iter().map(|_| None).collect();
    for (i, r) in map_dynamic(threads, ordered, |(i, t)| (i, f(t))) {
        out[i] = Some(r);
    }
    out.into_iter()
        .map(|r| r.expect("every item is mapped"))
        .collect()
}

/// A vector of `len` elements written in parallel: piece `k` of `pieces` (ascending ranges that
/// cover `0..len`) is filled from the iterator `fill(k)`, which must yield exactly as many
/// elements as the piece holds.
///
/// Unlike filling a zeroed vector, nothing writes the memory twice: the allocator hands out
/// recycled memory for all but the largest vectors, and zeroing tens of megabytes on the calling
/// thread would cost more than the parallel fill itself.
pub(crate) fn collect_pieces<T: Send, I: Iterator<Item = T>>(
    threads: usize,
    len: usize,
    pieces: &[Range<usize>],
    fill: impl Fn(usize) -> I + Sync,
) -> Vec<T> {
    let mut covered = 0;
    for r in pieces {
        assert_eq!(r.start, covered, "pieces must cover 0..len in order");
        covered = r.end;
    }
    assert_eq!(covered, len, "pieces must cover 0..len");
    let mut v: Vec<T> = Vec::with_capacity(len);
    let parts: Vec<(usize, &mut [MaybeUninit<T>])> =
        split_ranges(&mut v.spare_capacity_mut()[..len], pieces)
            .into_iter()
            .enumerate()
            .collect();
    map_dynamic(threads, parts, |(k, out)| {
        let mut items = fill(k);
        for slot in out.iter_mut() {
            slot.write(
                items
                    .next()
                    .expect("a piece's iterator yields one element per slot"),
            );
        }
        assert!(
            items.next().is_none(),
            "a piece's iterator yields one element per slot"
        );
    });
    // SAFETY: the pieces cover 0..len (asserted above), and every slot of every piece was
    // written (a short iterator panics before this point, a long one too).
    unsafe { v.set_len(len) };
    v
}

/// Splits `0..len` into about `4 * threads` contiguous ranges of at least `min_len` (fewer when
/// `len` is small): enough pieces that an unlucky thread does not hold up the rest.
pub(crate) fn ranges(len: usize, threads: usize, min_len: usize) -> Vec<Range<usize>> {
    let pieces = (4 * threads).min(len / min_len.max(1)).max(1);
    let per = len.div_ceil(pieces).max(1);
    (0..len)
        .step_by(per)
        .map(|s| s..(s + per).min(len))
        .collect()
}

/// Splits `data` into the given ascending, contiguous ranges that cover it.
pub(crate) fn split_ranges<'a, T>(
    mut data: &'a mut [T],
    ranges: &[Range<usize>],
) -> Vec<&'a mut [T]> {
    let mut out = Vec::with_capacity(ranges.len());
    let mut at = 0;
    for r in ranges {
        let (_, rest) = data.split_at_mut(r.start - at);
        let (mine, rest) = rest.split_at_mut(r.len());
        out.push(mine);
        data = rest;
        at = r.end;
    }
    out
}
