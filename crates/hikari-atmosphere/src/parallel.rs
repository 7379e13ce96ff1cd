//! A parallel map on rayon's pool: the build is a handful of big loops over independent texels,
//! and rayon's work stealing evens out texels of very different cost (ground rays, long grazing
//! rays) that fixed chunks on scoped threads did not.

use rayon::prelude::*;

/// `(0..n).map(f)` collected in order, computed on every available core.
pub fn map<T: Send>(n: usize, f: impl Fn(usize) -> T + Sync + Send) -> Vec<T> {
    (0..n).into_par_iter().with_min_len(64).map(f).collect()
}
