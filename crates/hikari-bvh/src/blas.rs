//! Bottom-level acceleration structure: one mesh, object space.

use crate::aabb::Aabb;
use crate::build_sah::parallel::{collect_pieces, map_dynamic, ranges, split_ranges, with_threads};
use crate::build_sah::{self, PrimRef, SahParams};
use crate::error::BvhError;
use crate::layout::{Hit, Ray, TRIANGLE_NON_OPAQUE, TriangleRecord, WideNode};
use crate::traverse::Stack;
use crate::triangle::is_degenerate;
use crate::wide;
use glam::{Vec3, Vec3A};
use std::sync::Mutex;

/// What to do with a triangle the builder cannot use.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum BadTriangle {
    /// Leave it out and count it in [`BlasStats`].
    #[default]
    Skip,
    /// Fail the build with an error naming the mesh and the triangle.
    Reject,
}

#[derive(Clone, Copy, Debug)]
pub struct BuildOptions {
    /// Zero-area triangles can never be hit by the watertight test; skipping them is harmless.
    pub degenerate: BadTriangle,
    /// Triangles with a NaN or infinite vertex, or a vertex index out of range.
    pub invalid: BadTriangle,
    /// Most triangles per leaf child (1..=3).
    pub max_leaf: usize,
    /// Build threads; 0 = the current rayon pool (the global one unless the caller installed
    /// another; its size follows `RAYON_NUM_THREADS`), another count gets a pool of that many
    /// threads for the build (at most 256). The BVH is the same for any count.
    pub threads: usize,
}

impl Default for BuildOptions {
    fn default() -> Self {
        Self {
            degenerate: BadTriangle::Skip,
            invalid: BadTriangle::Reject,
            max_leaf: 3,
            threads: 0,
        }
    }
}

/// Wall time of each build phase.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct BuildTimings {
    /// Validation and primitive boxes.
    pub validate: std::time::Duration,
    /// Binary SAH build.
    pub binary: std::time::Duration,
    /// Collapse to the wide layout and quantization.
    pub collapse: std::time::Duration,
    /// Triangle records in leaf order, and the copy of the index buffer kept for refit.
    pub triangles: std::time::Duration,
}

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct BlasStats {
    pub input_triangles: usize,
    pub triangles: usize,
    pub skipped_degenerate: usize,
    pub skipped_non_finite: usize,
    pub skipped_bad_index: usize,
    pub nodes: usize,
    /// Nodes on the longest root-to-leaf path; the kernel's stack needs this many entries
    /// (plus the TLAS depth).
    pub depth: u32,
    pub timings: BuildTimings,
}

impl BlasStats {
    pub fn skipped(&self) -> usize {
        self.skipped_degenerate + self.skipped_non_finite + self.skipped_bad_index
    }
}

/// A BLAS: compressed wide nodes and leaf-ordered triangles, plus the index buffer kept for refit.
#[derive(Clone, Debug)]
pub struct Blas {
    pub name: String,
    /// Root at index 0; `child_base` and `prim_base` are relative to this BLAS.
    pub nodes: Vec<WideNode>,
    pub triangles: Vec<TriangleRecord>,
    pub(crate) indices: Vec<[u32; 3]>,
    pub(crate) vertex_count: usize,
    pub bounds: Aabb,
    pub stats: BlasStats,
}

impl Blas {
    /// Builds a BLAS from an indexed triangle mesh, every triangle opaque. `name` appears in
    /// every error message.
    pub fn build(
        name: &str,
        positions: &[Vec3],
        indices: &[[u32; 3]],
        options: &BuildOptions,
    ) -> Result<Blas, BvhError> {
        Self::build_inner(name, positions, indices, None, options)
    }

    /// [`Blas::build`] with triangles that can be cut out: `non_opaque[t]` marks triangle `t`
    /// of `indices` (alpha-tested materials, glTF `alphaMode: MASK`). Hits on marked triangles
    /// go through the filter of the `*_filtered` traversals (and `bvh_accept_candidate` on the
    /// GPU); the tree itself is the same as without marks.
    pub fn build_with_opacity(
        name: &str,
        positions: &[Vec3],
        indices: &[[u32; 3]],
        non_opaque: &[bool],
        options: &BuildOptions,
    ) -> Result<Blas, BvhError> {
        if non_opaque.len() != indices.len() {
            return Err(BvhError::OpacityCount {
                mesh: name.into(),
                flags: non_opaque.len(),
                triangles: indices.len(),
            });
        }
        Self::build_inner(name, positions, indices, Some(non_opaque), options)
    }

    fn build_inner(
        name: &str,
        positions: &[Vec3],
        indices: &[[u32; 3]],
        non_opaque: Option<&[bool]>,
        options: &BuildOptions,
    ) -> Result<Blas, BvhError> {
        if indices.is_empty() {
            return Err(BvhError::EmptyMesh { mesh: name.into() });
        }
        if indices.len() > build_sah::MAX_PRIMS {
            return Err(BvhError::TooManyTriangles {
                mesh: name.into(),
                triangles: indices.len(),
                max: build_sah::MAX_PRIMS,
            });
        }
        // More threads than this only add start-up and join costs (and an absurd request
        // could fail to start them all).
        with_threads(options.threads.min(MAX_BUILD_THREADS), |threads| {
            Self::build_on(name, positions, indices, non_opaque, options, threads)
        })
    }

    /// The build proper, on the current rayon pool split `threads` ways (1 = the calling thread
    /// alone).
    fn build_on(
        name: &str,
        positions: &[Vec3],
        indices: &[[u32; 3]],
        non_opaque: Option<&[bool]>,
        options: &BuildOptions,
        threads: usize,
    ) -> Result<Blas, BvhError> {
        let mut stats = BlasStats {
            input_triangles: indices.len(),
            ..Default::default()
        };
        let t_validate = std::time::Instant::now();
        let prims = prim_refs(name, positions, indices, options, threads, &mut stats)?;
        let max_leaf = options.max_leaf.clamp(1, crate::layout::MAX_LEAF_TRIANGLES);
        stats.timings.validate = t_validate.elapsed();
        let t_binary = std::time::Instant::now();
        // The triangle records' buffer is as large as the binary build's scratch space needs
        // (48 bytes per triangle against 32), so it is lent to the build first: its pages are
        // faulted in once, by the build's threads.
        let mut triangles: Vec<TriangleRecord> = bytemuck::zeroed_vec(prims.len());
        let scratch_bytes = std::mem::size_of::<PrimRef>() * prims.len();
        let bytes: &mut [u8] = bytemuck::cast_slice_mut(&mut triangles);
        let scratch: &mut [PrimRef] = bytemuck::cast_slice_mut(&mut bytes[..scratch_bytes]);
        let binary = build_sah::build_in(prims, scratch, &SahParams { max_leaf, threads });
        stats.timings.binary = t_binary.elapsed();
        let t_collapse = std::time::Instant::now();
        let bounds = binary.nodes[0].bounds;
        let wide = wide::collapse(&binary, max_leaf, threads);
        stats.timings.collapse = t_collapse.elapsed();
        let t_triangles = std::time::Instant::now();
        debug_assert_eq!(triangles.len(), wide.leaf_prims.len());
        let pieces = ranges(triangles.len(), threads, CHUNK);
        let work: Vec<_> = split_ranges(&mut triangles, &pieces)
            .into_iter()
            .zip(&pieces)
            .collect();
        map_dynamic(threads, work, |(out, r)| {
            for (rec, &p) in out.iter_mut().zip(&wide.leaf_prims[r.clone()]) {
                let id = binary.prims[p as usize].id();
                let tri = indices[id as usize];
                *rec = TriangleRecord {
                    v0: positions[tri[0] as usize].into(),
                    primitive: id,
                    v1: positions[tri[1] as usize].into(),
                    flags: match non_opaque {
                        Some(marks) if marks[id as usize] => TRIANGLE_NON_OPAQUE,
                        _ => 0,
                    },
                    v2: positions[tri[2] as usize].into(),
                    _pad2: 0,
                };
            }
        });
        // The index buffer is kept for refit.
        let kept_indices = copy_parallel(indices, threads);
        stats.timings.triangles = t_triangles.elapsed();
        stats.triangles = triangles.len();
        stats.nodes = wide.nodes.len();
        stats.depth = wide.depth;
        Ok(Blas {
            name: name.into(),
            nodes: wide.nodes,
            triangles,
            indices: kept_indices,
            vertex_count: positions.len(),
            bounds,
            stats,
        })
    }

    /// Bytes the kernel reads: nodes plus triangles.
    pub fn gpu_bytes(&self) -> usize {
        std::mem::size_of_val(self.nodes.as_slice())
            + std::mem::size_of_val(self.triangles.as_slice())
    }

    /// Closest hit in object space (`instance` is reported as 0).
    pub fn intersect(&self, ray: &Ray) -> Option<Hit> {
        self.intersect_with(ray, &mut Stack::default())
    }

    /// [`Blas::intersect`] reusing a stack, which also counts the work done.
    pub fn intersect_with(&self, ray: &Ray, stack: &mut Stack) -> Option<Hit> {
        crate::traverse::closest_hit_blas(&self.nodes, &self.triangles, ray, 0, stack)
    }

    /// True if anything is hit with `t_min < t < t_max`.
    pub fn occluded(&self, ray: &Ray) -> bool {
        self.occluded_with(ray, &mut Stack::default())
    }

    pub fn occluded_with(&self, ray: &Ray, stack: &mut Stack) -> bool {
        crate::traverse::any_hit_blas(&self.nodes, &self.triangles, ray, stack)
    }

    /// [`Blas::intersect`] where a hit on a non-opaque triangle (see
    /// [`Blas::build_with_opacity`]) counts only if `accept(0, primitive, u, v)` returns true.
    pub fn intersect_filtered(
        &self,
        ray: &Ray,
        accept: impl FnMut(u32, u32, f32, f32) -> bool,
    ) -> Option<Hit> {
        crate::traverse::closest_hit_blas_filtered(
            &self.nodes,
            &self.triangles,
            ray,
            0,
            &mut Stack::default(),
            accept,
        )
    }

    /// [`Blas::occluded`] with the filter of [`Blas::intersect_filtered`].
    pub fn occluded_filtered(
        &self,
        ray: &Ray,
        accept: impl FnMut(u32, u32, f32, f32) -> bool,
    ) -> bool {
        crate::traverse::any_hit_blas_filtered(
            &self.nodes,
            &self.triangles,
            ray,
            0,
            &mut Stack::default(),
            accept,
        )
    }
}

/// Most threads one build uses, whatever [`BuildOptions::threads`] asks for.
const MAX_BUILD_THREADS: usize = 256;

/// Triangles per piece of the parallel passes over the mesh.
const CHUNK: usize = 16 * 1024;

/// Bad triangles met by one piece of the validation pass.
#[derive(Default)]
struct Rejects {
    /// Skipped triangles, in order.
    skipped: Vec<u32>,
    counts: BlasStats,
    /// The piece's first error (with `BadTriangle::Reject`).
    error: Option<BvhError>,
}

/// Validates every triangle and returns the boxes of those kept, in triangle order; counts the
/// skipped ones in `stats`. Pieces of the index buffer are checked in parallel; with several
/// bad triangles, the error names the first, as a serial pass would.
fn prim_refs(
    name: &str,
    positions: &[Vec3],
    indices: &[[u32; 3]],
    options: &BuildOptions,
    threads: usize,
    stats: &mut BlasStats,
) -> Result<Vec<PrimRef>, BvhError> {
    let pieces = ranges(indices.len(), threads, CHUNK);
    let rejects: Vec<Mutex<Rejects>> = pieces.iter().map(|_| Mutex::default()).collect();
    // One box per triangle, so that the common case (nothing to skip) writes every box once,
    // straight into place; bad triangles get a placeholder, removed below.
    let mut prims = collect_pieces(threads, indices.len(), &pieces, |k| {
        let mut failed = false;
        let rejects = &rejects[k];
        pieces[k].clone().map(move |t| {
            let bad = if failed {
                None
            } else {
                match check_triangle(name, positions, indices[t], t, options) {
                    Ok(b) => return PrimRef::new(&b, t as u32),
                    Err(bad) => Some(bad),
                }
            };
            if let Some(bad) = bad {
                let mut r = rejects.lock().unwrap_or_else(|e| e.into_inner());
                match bad {
                    Bad::Error(e) => {
                        r.error = Some(e);
                        failed = true;
                    }
                    Bad::Skip(count) => {
                        r.skipped.push(t as u32);
                        count(&mut r.counts);
                    }
                }
            }
            PrimRef::new(&Aabb::new(Vec3A::ZERO, Vec3A::ZERO), t as u32)
        })
    });
    let mut skipped = Vec::new();
    for r in rejects {
        let r = r.into_inner().unwrap_or_else(|e| e.into_inner());
        // Pieces are in triangle order, so the first error met is the first bad triangle.
        if let Some(e) = r.error {
            return Err(e);
        }
        stats.skipped_bad_index += r.counts.skipped_bad_index;
        stats.skipped_non_finite += r.counts.skipped_non_finite;
        stats.skipped_degenerate += r.counts.skipped_degenerate;
        skipped.extend(r.skipped);
    }
    if !skipped.is_empty() {
        // Rare (bad input): drop the placeholders. `skipped` is sorted.
        let mut next = skipped.iter().peekable();
        prims.retain(|p| {
            if next.peek() == Some(&&p.id()) {
                next.next();
                false
            } else {
                true
            }
        });
    }
    if prims.is_empty() {
        return Err(BvhError::NoValidTriangles {
            mesh: name.into(),
            total: indices.len(),
            degenerate: stats.skipped_degenerate,
            non_finite: stats.skipped_non_finite,
            out_of_range: stats.skipped_bad_index,
        });
    }
    Ok(prims)
}

/// Why a triangle is left out: an error, or a skip with the counter it adds to.
enum Bad {
    Error(BvhError),
    Skip(fn(&mut BlasStats)),
}

/// The box of triangle `t`, or why it cannot be used.
fn check_triangle(
    name: &str,
    positions: &[Vec3],
    tri: [u32; 3],
    t: usize,
    options: &BuildOptions,
) -> Result<Aabb, Bad> {
    if let Some(&bad) = tri.iter().find(|&&i| i as usize >= positions.len()) {
        if options.invalid == BadTriangle::Reject {
            return Err(Bad::Error(BvhError::IndexOutOfRange {
                mesh: name.into(),
                triangle: t,
                index: bad,
                vertex_count: positions.len(),
            }));
        }
        return Err(Bad::Skip(|s| s.skipped_bad_index += 1));
    }
    let v = tri.map(|i| Vec3A::from(positions[i as usize]));
    if let Some(k) = (0..3).find(|&k| !v[k].is_finite()) {
        if options.invalid == BadTriangle::Reject {
            return Err(Bad::Error(BvhError::NonFiniteVertex {
                mesh: name.into(),
                triangle: t,
                vertex: tri[k],
                value: v[k].into(),
            }));
        }
        return Err(Bad::Skip(|s| s.skipped_non_finite += 1));
    }
    if is_degenerate(v[0], v[1], v[2]) {
        if options.degenerate == BadTriangle::Reject {
            return Err(Bad::Error(BvhError::DegenerateTriangle {
                mesh: name.into(),
                triangle: t,
            }));
        }
        return Err(Bad::Skip(|s| s.skipped_degenerate += 1));
    }
    Ok(Aabb::new(
        v[0].min(v[1]).min(v[2]),
        v[0].max(v[1]).max(v[2]),
    ))
}

/// `data.to_vec()` in parallel pieces: the index buffer of a large mesh is tens of megabytes.
fn copy_parallel<T: Copy + Send + Sync>(data: &[T], threads: usize) -> Vec<T> {
    let pieces = ranges(data.len(), threads, 4 * CHUNK);
    collect_pieces(threads, data.len(), &pieces, |k| {
        data[pieces[k].clone()].iter().copied()
    })
}

impl Blas {
    /// [`Blas::build`] from a [`crate::Mesh`].
    pub fn from_mesh(
        name: &str,
        mesh: &crate::Mesh,
        options: &BuildOptions,
    ) -> Result<Blas, BvhError> {
        Blas::build(name, &mesh.positions, &mesh.indices, options)
    }
}
