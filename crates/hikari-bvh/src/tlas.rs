//! Top-level acceleration structure over instances, rebuilt from scratch every frame from the
//! instances that survive culling (Metro's recipe: TLAS rebuild only, BLAS update only).

use crate::aabb::Aabb;
use crate::blas::Blas;
use crate::error::BvhError;
use crate::layout::{Hit, InstanceRecord, Ray, TriangleRecord, WideNode};
use crate::traverse::{self, TraversalStacks};
use glam::Affine3A;
use rayon::prelude::*;
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
    /// Selected instances left out: an index past the end of the instance list, a transform
    /// that is singular or not finite, or a world box that is empty or not finite.
    pub skipped_invalid: usize,
    /// Wide nodes.
    pub nodes: usize,
    /// Nodes on the longest root-to-leaf path (the kernel's TLAS stack needs this many entries).
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
        if selected.len() > crate::build_sah::MAX_PRIMS {
            return Err(BvhError::TooManyInstances {
                selected: selected.len(),
                max: crate::build_sah::MAX_PRIMS,
            });
        }
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

    /// [`Tlas::closest_hit`] where a hit on a non-opaque triangle counts only if
    /// `accept(instance, primitive, u, v)` returns true (see
    /// [`traverse::closest_hit_filtered`]).
    pub fn closest_hit_filtered(
        &self,
        blases: &[Blas],
        ray: &Ray,
        accept: impl FnMut(u32, u32, f32, f32) -> bool,
    ) -> Option<Hit> {
        traverse::closest_hit_filtered(
            &self.nodes,
            &self.instances,
            blases,
            ray,
            &mut TraversalStacks::default(),
            accept,
        )
    }

    /// [`Tlas::any_hit`] with the filter of [`Tlas::closest_hit_filtered`].
    pub fn any_hit_filtered(
        &self,
        blases: &[Blas],
        ray: &Ray,
        accept: impl FnMut(u32, u32, f32, f32) -> bool,
    ) -> bool {
        traverse::any_hit_filtered(
            &self.nodes,
            &self.instances,
            blases,
            ray,
            &mut TraversalStacks::default(),
            accept,
        )
    }

    /// Closest hits for a batch of rays on `threads` threads (0 = the current rayon pool, see
    /// [`crate::BuildOptions::threads`]), reusing traversal
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
    f: impl Fn(&Ray, &mut T, &mut TraversalStacks) + Sync + Send,
) {
    crate::build_sah::parallel::with_threads(threads, |threads| {
        if threads <= 1 {
            let mut stacks = TraversalStacks::default();
            for (ray, o) in rays.iter().zip(out) {
                f(ray, o, &mut stacks);
            }
            return;
        }
        // Enough rays per job that the stacks (reused within one) and the job overhead do not
        // show, and enough jobs that a slow chunk does not hold up the rest.
        let chunk = rays.len().div_ceil(8 * threads).clamp(1, 4096);
        rays.par_chunks(chunk)
            .zip(out.par_chunks_mut(chunk))
            .for_each_init(TraversalStacks::default, |stacks, (rays, out)| {
                for (ray, o) in rays.iter().zip(out) {
                    f(ray, o, stacks);
                }
            });
    });
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::build_sah::{PrimRef, SahParams};

    /// The builder the TLAS used before it had its own: binned SAH down to 8 instances, then
    /// the BLAS collapse with one instance per leaf slot. The reference for tree quality.
    pub(crate) fn binned_reference(
        instances: &[Instance],
        selected: &[u32],
        blases: &[Blas],
    ) -> Tlas {
        let offsets = blas_offsets(blases);
        let mut records = Vec::new();
        let mut prims = Vec::new();
        for &i in selected {
            let Some(inst) = instances.get(i as usize) else {
                continue;
            };
            let blas = &blases[inst.blas as usize];
            let Some(w2o) = world_to_object(&inst.transform) else {
                continue;
            };
            let bounds = blas.bounds.transformed(&inst.transform);
            if bounds.is_empty() || !bounds.is_finite() {
                continue;
            }
            let (node_off, tri_off) = offsets[inst.blas as usize];
            prims.push(PrimRef::new(&bounds, records.len() as u32));
            records.push(InstanceRecord {
                world_to_object: w2o,
                blas_node_offset: node_off,
                blas_triangle_offset: tri_off,
                instance_index: i,
                blas_index: inst.blas,
            });
        }
        let params = SahParams {
            max_leaf: crate::layout::WIDTH,
            threads: 1,
        };
        let binary = crate::build_sah::build(prims, &params);
        let wide = crate::wide::collapse(&binary, 1, 1);
        let leaf_records: Vec<InstanceRecord> = wide
            .leaf_prims
            .iter()
            .map(|&p| records[binary.prims[p as usize].id() as usize])
            .collect();
        Tlas {
            stats: TlasStats {
                instances: leaf_records.len(),
                skipped_invalid: 0,
                nodes: wide.nodes.len(),
                depth: wide.depth,
            },
            nodes: wide.nodes,
            instances: leaf_records,
            bounds: binary.nodes[0].bounds,
        }
    }

    /// Instances as a village places them (rows on a grid with equal rotations, props
    /// scattered between, a few large buildings), uniformly scattered, or in dense clusters.
    fn scene(kind: usize, count: usize, seed: u64) -> Vec<Instance> {
        let mut rng = crate::rng::SplitMix64::new(seed);
        (0..count)
            .map(|i| {
                let (centre, scale) = match kind {
                    0 if i % 3 == 0 => {
                        let cell = (i / 3) as f32;
                        let c = glam::Vec3::new(
                            (cell % 20.0) * 12.0,
                            0.0,
                            (cell / 20.0).floor() * 12.0,
                        );
                        (c, 3.0)
                    }
                    0 if i % 50 == 1 => (
                        glam::Vec3::new(rng.range(0.0, 240.0), 0.0, rng.range(0.0, 240.0)),
                        15.0,
                    ),
                    0 => (
                        glam::Vec3::new(
                            rng.range(0.0, 240.0),
                            rng.range(0.0, 2.0),
                            rng.range(0.0, 240.0),
                        ),
                        rng.range(0.2, 1.5),
                    ),
                    1 => (
                        glam::Vec3::new(
                            rng.range(-100.0, 100.0),
                            rng.range(-100.0, 100.0),
                            rng.range(-100.0, 100.0),
                        ),
                        rng.range(0.5, 3.0),
                    ),
                    _ => {
                        let cluster = (i % 7) as f32;
                        let c = glam::Vec3::new(
                            cluster * 40.0,
                            (cluster * 13.0) % 30.0,
                            (cluster * 71.0) % 90.0,
                        );
                        let d = glam::Vec3::new(
                            rng.range(-4.0, 4.0),
                            rng.range(-4.0, 4.0),
                            rng.range(-4.0, 4.0),
                        );
                        (c + d, rng.range(0.1, 1.0))
                    }
                };
                let rot = glam::Quat::from_rotation_y(if kind == 0 && i % 3 == 0 {
                    0.0
                } else {
                    rng.range(0.0, std::f32::consts::TAU)
                });
                Instance::new(
                    Affine3A::from_scale_rotation_translation(
                        glam::Vec3::splat(scale),
                        rot,
                        centre,
                    ),
                    (i % 2) as u32,
                )
            })
            .collect()
    }

    /// SAH cost against the binned builder's on scenes unlike the village: the instances a ray
    /// enters (the part issue 5 bounds) within 5%, and the nodes it visits not far off (the
    /// Morton order limits the candidate splits, and a node can hold small children's
    /// instances directly; on these scenes the total comes out between 4% below and 14% above).
    #[test]
    fn instances_entered_stay_within_five_percent_of_binned_sah() {
        let blases: Vec<Blas> = [
            crate::Mesh::random_soup(1, 40, 1.0, 0.5),
            crate::Mesh::random_soup(2, 30, 2.0, 1.0),
        ]
        .iter()
        .map(|m| Blas::from_mesh("m", m, &Default::default()).unwrap())
        .collect();
        for kind in 0..3 {
            for (count, seed) in [(300, 1), (1000, 2), (4000, 3)] {
                let instances = scene(kind, count, seed);
                let all: Vec<u32> = (0..count as u32).collect();
                let new = crate::sah_cost(&Tlas::build(&instances, &all, &blases).unwrap().nodes);
                let old = crate::sah_cost(&binned_reference(&instances, &all, &blases).nodes);
                println!(
                    "scene {kind}, {count}: SAH {:.3} ({:.3} + {:.3}), binned {:.3} ({:.3} + {:.3})",
                    new.total(),
                    new.nodes,
                    new.prims,
                    old.total(),
                    old.nodes,
                    old.prims
                );
                assert!(
                    new.prims <= 1.05 * old.prims && new.total() <= 1.2 * old.total(),
                    "scene {kind}, {count} instances: {new:?} vs binned {old:?}"
                );
            }
        }
    }
}
