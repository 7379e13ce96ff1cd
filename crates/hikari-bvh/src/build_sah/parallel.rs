//! Fork-join helpers on rayon, shared by the build phases (primitive boxes, binary build,
//! collapse, triangle records). They run on the current rayon pool (the global one, sized by
//! `RAYON_NUM_THREADS` or `rayon::ThreadPoolBuilder::build_global`, unless a caller installed
//! another), so a build started from a rayon task shares its threads instead of starting more.

use rayon::prelude::*;
use std::mem::MaybeUninit;
use std::ops::Range;

/// Runs `f(threads)` where the build helpers see `threads` threads: 0 asks for the current
/// rayon pool, whatever its size; a count other than the pool's gets a pool of its own for
/// this call (1 runs on the calling thread alone). Returns what `f` returns.
pub(crate) fn with_threads<R: Send>(requested: usize, f: impl FnOnce(usize) -> R + Send) -> R {
    let current = rayon::current_num_threads();
    if requested == 0 || requested == current {
        return f(current);
    }
    if requested == 1 {
        return f(1);
    }
    match rayon::ThreadPoolBuilder::new()
        .num_threads(requested)
        .build()
    {
        Ok(pool) => pool.install(|| f(requested)),
        // The threads could not be started: the current pool builds the same tree.
        Err(_) => f(current),
    }
}

/// Calls `f` on every item on the current rayon pool (on the calling thread alone if
/// `threads` is 1) and returns the results in item order. Every item is a job of its own, so
/// callers put the largest first for balance; which thread ran an item never shows in the
/// result.
pub(crate) fn map_dynamic<T: Send, R: Send>(
    threads: usize,
    items: Vec<T>,
    f: impl Fn(T) -> R + Sync + Send,
) -> Vec<R> {
    if threads <= 1 || items.len() <= 1 {
        return items.into_iter().map(f).collect();
    }
    items.into_par_iter().with_max_len(1).map(f).collect()
}

/// [`map_dynamic`] handing out the items of largest `weight` first (ties in item order), so that
/// a large item drawn last does not hold up the others; results in item order.
pub(crate) fn map_largest_first<T: Send, R: Send>(
    threads: usize,
    items: Vec<T>,
    weight: impl Fn(&T) -> usize,
    f: impl Fn(T) -> R + Sync + Send,
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
    fill: impl Fn(usize) -> I + Sync + Send,
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
