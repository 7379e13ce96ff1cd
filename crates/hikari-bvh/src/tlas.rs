//! Top-level acceleration structure over instances, rebuilt from scratch every frame from the
//! instances that survive culling (Metro's recipe: TLAS rebuild only, BLAS update only).

use crate::aabb::Aabb;
use crate::blas::Blas;
use crate::error::BvhError;
use crate::layout::{Hit, InstanceRecord, Ray, TriangleRecord, WideNode};
use crate::traverse::{self, TraversalStacks};
use glam::Affine3A;
use std::cell::RefCell;

mod instance_cache;
mod morton;
mod sweep_build;

/// One placement of a BLAS in the world.
#[derive(Clone, Copy, Debug)]
pub struct Instance {
    /// Object-to-world affine transform (any invertible 3x4: rotation, scale, shear, mirror).
    pub transform: Affine3A,
    /// Index into the BLAS list; many instances may share one BLAS.
    pub blas: u32,
    /// Logical (game) visibility: a hidden instance never enters the TLAS.
    pub visible: bool,
}

impl Instance {
    pub fn new(transform: Affine3A, blas: u32) -> Self {
        Self {
            transform,
            blas,
            visible: true,
        }
    }
    /// World-space box of the instance.
    pub fn world_bounds(&self, blases: &[Blas]) -> Aabb {
        blases
            .get(self.blas as usize)
            .map_or(Aabb::EMPTY, |b| b.bounds.transformed(&self.transform))
    }
}

/// Row-major 3x4 world-to-object matrix, or `None` if the transform is not invertible/finite.
pub fn world_to_object(transform: &Affine3A) -> Option<[[f32; 4]; 3]> {
    let det = transform.matrix3.determinant();
    if !(det.is_finite() && det != 0.0 && transform.translation.is_finite()) {
        return None;
    }
    let inv = transform.inverse();
    let m = inv.matrix3;
    let t = inv.translation;
    let rows = [
        [m.x_axis.x, m.y_axis.x, m.z_axis.x, t.x],
        [m.x_axis.y, m.y_axis.y, m.z_axis.y, t.y],
        [m.x_axis.z, m.y_axis.z, m.z_axis.z, t.z],
    ];
    rows.iter()
        .all(|r| r.iter().all(|v| v.is_finite()))
        .then_some(rows)
}

/// Where each BLAS starts in the packed GPU buffers (see [`PackedBlases`]).
pub fn blas_offsets(blases: &[Blas]) -> Vec<(u32, u32)> {
    blas_offsets_iter(blases).collect()
}

fn blas_offsets_iter(blases: &[Blas]) -> impl Iterator<Item = (u32, u32)> + '_ {
    let mut nodes = 0u32;
    let mut tris = 0u32;
    blases.iter().map(move |b| {
        let o = (nodes, tris);
        nodes += b.nodes.len() as u32;
        tris += b.triangles.len() as u32;
        o
    })
}

/// All BLAS concatenated for upload: node and triangle buffers the kernel indexes with the
/// offsets stored in each [`InstanceRecord`].
pub struct PackedBlases {
    pub nodes: Vec<WideNode>,
    pub triangles: Vec<TriangleRecord>,
    pub offsets: Vec<(u32, u32)>,
}

impl PackedBlases {
    pub fn new(blases: &[Blas]) -> Self {
        Self {
            nodes: blases
                .iter()
                .flat_map(|b| b.nodes.iter().copied())
                .collect(),
            triangles: blases
                .iter()
                .flat_map(|b| b.triangles.iter().copied())
                .collect(),
            offsets: blas_offsets(blases),
        }
    }
}

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct TlasStats {
    /// Instances in the TLAS.
    pub instances: usize,
    /// Selected instances left out because their transform is singular or not finite, or their
    /// BLAS box is empty.
    pub skipped_invalid: usize,
    pub nodes: usize,
    pub depth: u32,
}

#[derive(Clone, Debug, Default)]
pub struct Tlas {
    pub nodes: Vec<WideNode>,
    /// Leaf-ordered instance records (the TLAS's "triangles").
    pub instances: Vec<InstanceRecord>,
    pub bounds: Aabb,
    pub stats: TlasStats,
}

/// What a TLAS rebuild keeps from one build to the next: its buffers, so that a rebuild
/// allocates only the arrays of the TLAS it returns, and what it derived from each instance
/// (world-to-object matrix, world box), derived again only for instances whose transform, BLAS
/// index or BLAS box changed. [`Tlas::build`] keeps one per thread; own one to control when its
/// memory is released.
#[derive(Default)]
pub struct TlasBuilder {
    offsets: Vec<(u32, u32)>,
    cache: instance_cache::InstanceCache,
    /// Cache entries of this build's instances, in selection order.
    entries: Vec<u32>,
    sweep: sweep_build::SweepBuilder,
    /// Cache entries in leaf order.
    leaves: Vec<u32>,
}

/// Instances above which [`Tlas::build`] gives its per-thread buffers back after a build rather
/// than holding them (about 300 bytes per instance) until the thread ends.
const KEEP_BUFFERS_UP_TO: usize = 64 * 1024;

thread_local! {
    static BUILDER: RefCell<TlasBuilder> = RefCell::default();
}

impl TlasBuilder {
    /// Builds the TLAS over `selected` (indices into `instances`); see [`Tlas::build`].
    pub fn build(
        &mut self,
        instances: &[Instance],
        selected: &[u32],
        blases: &[Blas],
    ) -> Result<Tlas, BvhError> {
        let Self {
            offsets,
            cache,
            entries,
            sweep,
            leaves,
        } = self;
        offsets.clear();
        offsets.extend(blas_offsets_iter(blases));
        cache.begin(instances.len(), blases);
        entries.clear();
        let mut stats = TlasStats::default();
        for &i in selected {
            let Some(inst) = instances.get(i as usize) else {
                stats.skipped_invalid += 1;
                continue;
            };
            if inst.blas as usize >= blases.len() {
                return Err(BvhError::BadBlasIndex {
                    instance: i as usize,
                    blas: inst.blas,
                    blas_count: blases.len(),
                });
            }
            match cache.entry(i, inst, blases) {
                Some(e) => entries.push(e),
                None => stats.skipped_invalid += 1,
            }
        }
        if entries.is_empty() {
            return Ok(Tlas {
                stats,
                ..Default::default()
            });
        }
        // Nodes hold about four instances on average: room enough not to regrow.
        let mut nodes = Vec::with_capacity(entries.len() / 3 + 1);
        let built = sweep.build(cache.bounds(), entries, &mut nodes, leaves);
        let records: Vec<InstanceRecord> = leaves
            .iter()
            .map(|&e| {
                let (world_to_object, instance_index, blas_index) = cache.record_data(e);
                let (blas_node_offset, blas_triangle_offset) = offsets[blas_index as usize];
                InstanceRecord {
                    world_to_object: *world_to_object,
                    blas_node_offset,
                    blas_triangle_offset,
                    instance_index,
                    blas_index,
                }
            })
            .collect();
        stats.instances = records.len();
        stats.nodes = nodes.len();
        stats.depth = built.depth;
        Ok(Tlas {
            nodes,
            instances: records,
            bounds: built.bounds,
            stats,
        })
    }

    /// Bytes held between builds.
    pub fn capacity_bytes(&self) -> usize {
        use std::mem::size_of;
        self.offsets.capacity() * size_of::<(u32, u32)>()
            + self.cache.capacity_bytes()
            + (self.entries.capacity() + self.leaves.capacity()) * size_of::<u32>()
            + self.sweep.capacity_bytes()
    }
}

impl Tlas {
    /// Builds the TLAS over `selected` (indices into `instances`, e.g. from
    /// [`crate::cull::cull_instances`]); hits report the index into `instances`. Reuses buffers
    /// kept per thread (see [`TlasBuilder`]).
    pub fn build(
        instances: &[Instance],
        selected: &[u32],
        blases: &[Blas],
    ) -> Result<Tlas, BvhError> {
        BUILDER.with(|cell| match cell.try_borrow_mut() {
            Ok(mut builder) => {
                let tlas = builder.build(instances, selected, blases);
                if selected.len() > KEEP_BUFFERS_UP_TO {
                    *builder = TlasBuilder::default();
                }
                tlas
            }
            // Only reachable if a build on this thread were re-entered.
            Err(_) => TlasBuilder::default().build(instances, selected, blases),
        })
    }

    pub fn closest_hit(&self, blases: &[Blas], ray: &Ray) -> Option<Hit> {
        traverse::closest_hit(
            &self.nodes,
            &self.instances,
            blases,
            ray,
            &mut TraversalStacks::default(),
        )
    }

    pub fn any_hit(&self, blases: &[Blas], ray: &Ray) -> bool {
        traverse::any_hit(
            &self.nodes,
            &self.instances,
            blases,
            ray,
            &mut TraversalStacks::default(),
        )
    }

    /// Closest hits for a batch of rays on `threads` threads (0 = all cores), reusing traversal
    /// stacks; what the offline bake uses when no GPU is wanted. Misses are [`Hit::NONE`].
    pub fn closest_hits(&self, blases: &[Blas], rays: &[Ray], threads: usize) -> Vec<Hit> {
        let mut out = vec![Hit::NONE; rays.len()];
        for_each_chunk(rays, &mut out, threads, |ray, hit, stacks| {
            *hit = traverse::closest_hit(&self.nodes, &self.instances, blases, ray, stacks)
                .unwrap_or(Hit::NONE);
        });
        out
    }

    /// Any-hit results for a batch of rays (true = occluded within `t_max`).
    pub fn any_hits(&self, blases: &[Blas], rays: &[Ray], threads: usize) -> Vec<bool> {
        let mut out = vec![false; rays.len()];
        for_each_chunk(rays, &mut out, threads, |ray, hit, stacks| {
            *hit = traverse::any_hit(&self.nodes, &self.instances, blases, ray, stacks);
        });
        out
    }

    /// Bytes the kernel reads for the TLAS: nodes plus instance records.
    pub fn gpu_bytes(&self) -> usize {
        std::mem::size_of_val(self.nodes.as_slice())
            + std::mem::size_of_val(self.instances.as_slice())
    }
}

fn for_each_chunk<T: Send>(
    rays: &[Ray],
    out: &mut [T],
    threads: usize,
    f: impl Fn(&Ray, &mut T, &mut TraversalStacks) + Sync,
) {
    let threads = crate::blas::thread_count(threads).max(1);
    let chunk = rays.len().div_ceil(threads).max(1);
    std::thread::scope(|scope| {
        for (rays, out) in rays.chunks(chunk).zip(out.chunks_mut(chunk)) {
            let f = &f;
            scope.spawn(move || {
                let mut stacks = TraversalStacks::default();
                for (ray, o) in rays.iter().zip(out) {
                    f(ray, o, &mut stacks);
                }
            });
        }
    });
}
