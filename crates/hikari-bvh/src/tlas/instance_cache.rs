//! What the TLAS builder derives from each instance (its world-to-object matrix and world box),
//! kept from one rebuild to the next. Most instances do not move between frames, and comparing
//! the 48 bytes of a transform costs far less than inverting it and transforming a box.
//!
//! An entry is reused only when the instance's transform (bit for bit) and BLAS index are the
//! ones it was derived from and that BLAS's box has not changed since (a refit moves it), so a
//! rebuild gives exactly the TLAS of a cold build.

use crate::aabb::Aabb;
use crate::blas::Blas;
use crate::tlas::{Instance, world_to_object};
use glam::Affine3A;

/// Instance lists longer than this are not cached: their data is derived every build into
/// entries per selected instance, so a huge list with few selected instances does not make the
/// builder hold an entry for every index.
pub(crate) const MAX_CACHED: usize = 64 * 1024;

/// What an entry was derived from.
#[derive(Clone, Copy)]
struct Source {
    transform: Affine3A,
    blas: u32,
    /// [`InstanceCache::blas_generation`] of that BLAS when the entry was derived.
    generation: u64,
    /// Index in the caller's instance list.
    instance: u32,
    state: State,
}

#[derive(Clone, Copy, PartialEq, Eq)]
enum State {
    /// Holds nothing yet.
    Empty,
    Usable,
    /// Left out: singular or non-finite transform, or a world box that is empty or not finite.
    Unusable,
}

const EMPTY_SOURCE: Source = Source {
    transform: Affine3A::IDENTITY,
    blas: 0,
    generation: 0,
    instance: 0,
    state: State::Empty,
};

/// Entries in three parallel arrays, so that the build reads only the boxes while it sorts and
/// splits, and the matrices only when it writes the instance records.
#[derive(Default)]
pub(crate) struct InstanceCache {
    sources: Vec<Source>,
    bounds: Vec<Aabb>,
    world_to_object: Vec<[[f32; 4]; 3]>,
    /// This build's entries are indexed by instance (else: one per selected instance, in
    /// selection order, derived afresh).
    by_instance: bool,
    /// Per BLAS index ever seen: the bits of its box at the last build (`None` if the last
    /// build had no BLAS at that index) and a counter bumped whenever that changes. Never
    /// shortened, so an entry derived many builds ago still sees every change since.
    blas_bounds: Vec<Option<[u32; 6]>>,
    blas_generation: Vec<u64>,
}

fn bounds_bits(b: &Aabb) -> [u32; 6] {
    let (lo, hi) = (b.min.to_array(), b.max.to_array());
    [lo[0], lo[1], lo[2], hi[0], hi[1], hi[2]].map(f32::to_bits)
}

/// Bitwise equality of the twelve used floats of two transforms (the fourth lane of each
/// column is padding and may hold anything).
#[cfg(target_arch = "x86_64")]
#[inline]
fn same_transform(a: &Affine3A, b: &Affine3A) -> bool {
    use std::arch::x86_64::{
        __m128, _mm_and_si128, _mm_castps_si128, _mm_cmpeq_epi32, _mm_movemask_epi8,
    };
    let eq = |x: glam::Vec3A, y: glam::Vec3A| {
        let (x, y): (__m128, __m128) = (x.into(), y.into());
        // SAFETY: SSE2 is part of the x86_64 baseline; these touch no memory.
        unsafe { _mm_cmpeq_epi32(_mm_castps_si128(x), _mm_castps_si128(y)) }
    };
    let m = &a.matrix3;
    let n = &b.matrix3;
    // SAFETY: as above.
    let all = unsafe {
        _mm_and_si128(
            _mm_and_si128(eq(m.x_axis, n.x_axis), eq(m.y_axis, n.y_axis)),
            _mm_and_si128(eq(m.z_axis, n.z_axis), eq(a.translation, b.translation)),
        )
    };
    // SAFETY: as above.
    let mask = unsafe { _mm_movemask_epi8(all) };
    mask & 0x0FFF == 0x0FFF
}

#[cfg(not(target_arch = "x86_64"))]
#[inline]
fn same_transform(a: &Affine3A, b: &Affine3A) -> bool {
    let bits = |t: &Affine3A| t.to_cols_array().map(f32::to_bits);
    bits(a) == bits(b)
}

impl InstanceCache {
    /// Starts a build over `instance_count` instances and `blases`: notes which BLAS boxes
    /// changed since the last build, and whether this build's entries are cached.
    pub(crate) fn begin(&mut self, instance_count: usize, blases: &[Blas]) {
        if self.blas_bounds.len() < blases.len() {
            self.blas_bounds.resize(blases.len(), None);
            self.blas_generation.resize(blases.len(), 0);
        }
        for (i, (old, generation)) in self
            .blas_bounds
            .iter_mut()
            .zip(&mut self.blas_generation)
            .enumerate()
        {
            let now = blases.get(i).map(|b| bounds_bits(&b.bounds));
            if *old != now {
                *old = now;
                *generation += 1;
            }
        }
        let by_instance = instance_count <= MAX_CACHED;
        // Entries made per selected instance are no instance's: start over after (and for)
        // such a build.
        if !(by_instance && self.by_instance) {
            self.sources.clear();
            self.bounds.clear();
            self.world_to_object.clear();
        }
        self.by_instance = by_instance;
        if by_instance && self.sources.len() < instance_count {
            self.sources.resize(instance_count, EMPTY_SOURCE);
            self.bounds.resize(instance_count, Aabb::EMPTY);
            self.world_to_object.resize(instance_count, [[0.0; 4]; 3]);
        }
    }

    /// The entry of instance `index` (whose BLAS index the caller checked), derived again
    /// unless still valid; `None` if the instance cannot enter the TLAS.
    #[inline]
    pub(crate) fn entry(&mut self, index: u32, inst: &Instance, blases: &[Blas]) -> Option<u32> {
        let generation = self.blas_generation[inst.blas as usize];
        let e = if self.by_instance {
            let s = &self.sources[index as usize];
            if s.state != State::Empty
                && s.blas == inst.blas
                && s.generation == generation
                && same_transform(&s.transform, &inst.transform)
            {
                return (s.state == State::Usable).then_some(index);
            }
            index as usize
        } else {
            self.sources.push(EMPTY_SOURCE);
            self.bounds.push(Aabb::EMPTY);
            self.world_to_object.push([[0.0; 4]; 3]);
            self.sources.len() - 1
        };
        let derived = world_to_object(&inst.transform).and_then(|w2o| {
            let bounds = blases[inst.blas as usize]
                .bounds
                .transformed(&inst.transform);
            (!bounds.is_empty() && bounds.is_finite()).then_some((w2o, bounds))
        });
        self.sources[e] = Source {
            transform: inst.transform,
            blas: inst.blas,
            generation,
            instance: index,
            state: if derived.is_some() {
                State::Usable
            } else {
                State::Unusable
            },
        };
        let (w2o, bounds) = derived?;
        self.world_to_object[e] = w2o;
        self.bounds[e] = bounds;
        Some(e as u32)
    }

    /// World boxes of all entries.
    #[inline]
    pub(crate) fn bounds(&self) -> &[Aabb] {
        &self.bounds
    }

    /// World-to-object matrix, instance index and BLAS index of a usable entry.
    #[inline]
    pub(crate) fn record_data(&self, entry: u32) -> (&[[f32; 4]; 3], u32, u32) {
        let s = &self.sources[entry as usize];
        (&self.world_to_object[entry as usize], s.instance, s.blas)
    }

    pub(crate) fn capacity_bytes(&self) -> usize {
        use std::mem::size_of;
        self.sources.capacity() * size_of::<Source>()
            + self.bounds.capacity() * size_of::<Aabb>()
            + self.world_to_object.capacity() * size_of::<[[f32; 4]; 3]>()
            + self.blas_bounds.capacity() * size_of::<Option<[u32; 6]>>()
            + self.blas_generation.capacity() * size_of::<u64>()
    }
}
