//! # hikari-bvh: the CPU side of hikari's ray-tracing core
//!
//! No GPU hikari runs on exposes ray-tracing hardware to wgpu, so rays are traced in WGSL
//! compute shaders against this crate's own BVH. The crate builds the structures (a BLAS per
//! mesh, a TLAS over instances), keeps deforming meshes up to date (refit plus Metro Exodus'
//! throttling), defines the GPU byte layout, and traverses that exact layout on the CPU: the
//! traversal in [`traverse`] is the twin of the future kernel (same node decoding, same visiting
//! order, same watertight triangle test), used by tests and by the offline bake.
//!
//! ## Using it
//!
//! ```
//! use glam::{Affine3A, Vec3};
//! use hikari_bvh::{Blas, BuildOptions, CullSettings, Frustum, Instance, Mesh, Ray, Tlas};
//!
//! // One BLAS per mesh (object space). Bad triangles are rejected or skipped per BuildOptions.
//! let mesh = Mesh::terrain(16);
//! let blases = vec![Blas::from_mesh("terrain", &mesh, &BuildOptions::default())?];
//!
//! // Instances share BLAS; every frame, cull and rebuild the TLAS from the survivors.
//! let instances = vec![
//!     Instance::new(Affine3A::IDENTITY, 0),
//!     Instance::new(Affine3A::from_translation(Vec3::new(0.0, 0.0, 250.0)), 0),
//! ];
//! let view_proj = glam::Mat4::perspective_rh(1.0, 1.5, 0.1, 500.0)
//!     * glam::Mat4::look_at_rh(Vec3::new(0.0, 50.0, -150.0), Vec3::ZERO, Vec3::Y);
//! let (kept, _stats) = hikari_bvh::cull_instances(
//!     &instances,
//!     &blases,
//!     Vec3::new(0.0, 50.0, -150.0),
//!     &Frustum::from_view_proj(&view_proj),
//!     &CullSettings { margin: 20.0, ..Default::default() },
//! );
//! let tlas = Tlas::build(&instances, &kept, &blases)?;
//!
//! // Closest hit (t, instance, primitive, barycentrics) and any hit within t_max.
//! let ray = Ray::new(Vec3::new(3.0, 50.0, 2.0), Vec3::NEG_Y, 0.0, f32::INFINITY);
//! let hit = tlas.closest_hit(&blases, &ray).expect("the terrain is below");
//! assert_eq!(hit.instance, 0);
//! let shadow = Ray { t_max: 5.0, ..ray };
//! assert!(!tlas.any_hit(&blases, &shadow));
//!
//! // For the GPU: upload PackedBlases::new(&blases).{nodes, triangles} once (and again after
//! // refits), and tlas.{nodes, instances} every frame.
//! # Ok::<(), hikari_bvh::BvhError>(())
//! ```
//!
//! Deforming meshes: [`Blas::refit`] with new positions (same index buffer), driven by a
//! [`RefitScheduler`]: call `touch(id, visible, radius, distance)` when an entity's geometry
//! moves, then `select()` once per frame and refit the returned ids; `RefitBatch::outdated`
//! reports how many stay stale.
//!
//! ## Why a compressed 8-wide BVH
//!
//! The layout follows Ylitie, Karras and Laine, *Efficient Incoherent Ray Traversal on GPUs
//! Through Compressed Wide BVHs* (HPG 2017). Incoherent rays on a GPU are bound by memory
//! traffic and by divergent stack work, and this layout cuts both: one 80-byte node holds eight
//! child boxes quantized to 8 bits per plane (a binary BVH spends 64 bytes on two boxes), the
//! tree is a third as deep as a binary one, and the traversal state is a *node group* (a base
//! index plus a bit mask of children still to visit), so one 8-byte stack entry stands for up to
//! eight pending children. Children sit in slots chosen by the octant their centre points to,
//! and a ray visits slots in the order `slot ^ ray_octant`, which is roughly front to back
//! without any sorting. Everything the kernel needs (`countOneBits`, `firstTrailingBit`,
//! `bitcast`, `extractBits`) is core WGSL, and every field is a `u32` or `f32`, so a storage
//! buffer can be read as `array<vec4<u32>>`. A 4-wide uncompressed BVH would be simpler to
//! decode but reads about twice the bytes per box and needs an explicit sort per node; the
//! CWBVH was judged the better fit for the throughput targets of issue 5. On the 1M-triangle
//! terrain, incoherent AO-style rays visit about 11 nodes and test about 6 triangles each.
//!
//! ## GPU byte layout
//!
//! All records are little-endian, 16-byte aligned, and sized in whole `vec4`s. Offsets in bytes.
//!
//! ### [`WideNode`] (80 bytes = 5 x vec4)
//!
//! | offset | size | field | meaning |
//! |---|---|---|---|
//! | 0 | 12 | `origin: vec3<f32>` | lower corner of the quantization grid `p` |
//! | 12 | 1 | `e.x: u8` | x grid step is `2^(e.x - 127)`, i.e. `bitcast<f32>(e.x << 23)` |
//! | 13 | 1 | `e.y: u8` | same for y |
//! | 14 | 1 | `e.z: u8` | same for z |
//! | 15 | 1 | `imask: u8` | bit `s` set: slot `s` holds an internal node |
//! | 16 | 4 | `child_base: u32` | node index of the first internal child |
//! | 20 | 4 | `prim_base: u32` | index of the first triangle (BLAS) / instance (TLAS) of the leaves |
//! | 24 | 8 | `meta[8]: u8` | per slot, see below |
//! | 32 | 8 | `q_lo_x[8]: u8` | per slot lower x plane |
//! | 40 | 8 | `q_lo_y[8]: u8` | |
//! | 48 | 8 | `q_lo_z[8]: u8` | |
//! | 56 | 8 | `q_hi_x[8]: u8` | per slot upper x plane |
//! | 64 | 8 | `q_hi_y[8]: u8` | |
//! | 72 | 8 | `q_hi_z[8]: u8` | |
//!
//! Byte `s` of each 8-byte array belongs to slot `s` (so slot `s` of `meta` is byte
//! `24 + s`, bits `8 * (s % 4)` of word `6 + s / 4`). Child `s`'s box is
//! `p + q_lo * step .. p + q_hi * step` per axis; the builder guarantees that this box, evaluated
//! in f32, contains everything below the child.
//!
//! `meta[s]`: `0` = empty slot. Internal child: `0b001_11000 | s` (low five bits `24 + s`), and
//! its node index is `child_base + countOneBits(imask & ((1 << s) - 1))`: internal children are
//! stored contiguously in slot order. Leaf child: bits 5..8 hold the primitive count in unary
//! (`0b001`, `0b011`, `0b111` = 1, 2, 3) and bits 0..5 the offset from `prim_base`; a node's
//! leaves reference at most 24 consecutive primitives.
//!
//! In a BLAS, `child_base` and `prim_base` are relative to the BLAS; the kernel adds the
//! instance's `blas_node_offset` / `blas_triangle_offset`. The root is node 0 and every child
//! index is larger than its parent's (nodes are emitted depth-first).
//!
//! ### [`TriangleRecord`] (48 bytes = 3 x vec4), in leaf order
//!
//! | offset | field |
//! |---|---|
//! | 0 | `v0: vec3<f32>` |
//! | 12 | `primitive: u32`: triangle index in the source mesh (reported in hits) |
//! | 16 | `v1: vec3<f32>`, then `flags: u32` (bit 0: [`layout::TRIANGLE_NON_OPAQUE`]) |
//! | 32 | `v2: vec3<f32>`, then 4 bytes padding |
//!
//! ### [`InstanceRecord`] (64 bytes = 4 x vec4), the TLAS's leaf primitives, in leaf order
//!
//! | offset | field |
//! |---|---|
//! | 0 | `world_to_object: 3 x vec4<f32>`, row-major: `p_obj.i = dot(row_i.xyz, p) + row_i.w` |
//! | 48 | `blas_node_offset: u32`: the BLAS root in the packed node buffer |
//! | 52 | `blas_triangle_offset: u32`: the BLAS's first triangle in the packed triangle buffer |
//! | 56 | `instance_index: u32`: index in the caller's instance list (reported in hits) |
//! | 60 | `blas_index: u32` |
//!
//! ### [`Ray`] (32 bytes) and [`Hit`] (32 bytes)
//!
//! `Ray`: `origin: vec3<f32>` (0), `t_min: f32` (12), `dir: vec3<f32>` (16, not necessarily
//! normalized; `t` is in units of `dir`, in world and object space alike), `t_max: f32` (28).
//! `Hit`: `t: f32` (0), `u: f32` (4, weight of `v1`), `v: f32` (8, weight of `v2`),
//! `primitive: u32` (12), `instance: u32` (16), padding (20..32). A miss has
//! `primitive == instance == 0xFFFF_FFFF` and `t = +inf`.
//!
//! ### Mirrored WGSL declarations
//!
//! These follow WGSL's alignment rules to the byte offsets above (a `vec3<f32>` followed by a
//! 4-byte field packs into one 16-byte slot; array strides are 80, 48, 64, 32 and 32):
//!
//! ```text
//! struct WideNode {
//!     origin: vec3<f32>, exp_imask: u32,          // e.x | e.y << 8 | e.z << 16 | imask << 24
//!     child_base: u32, prim_base: u32, meta: vec2<u32>,
//!     lo_x: vec2<u32>, lo_y: vec2<u32>, lo_z: vec2<u32>,
//!     hi_x: vec2<u32>, hi_y: vec2<u32>, hi_z: vec2<u32>,
//! }
//! struct TriangleRecord { v0: vec3<f32>, primitive: u32, v1: vec3<f32>, pad1: u32, v2: vec3<f32>, pad2: u32 }
//! struct InstanceRecord {
//!     world_to_object: array<vec4<f32>, 3>,
//!     blas_node_offset: u32, blas_triangle_offset: u32, instance_index: u32, blas_index: u32,
//! }
//! struct Ray { origin: vec3<f32>, t_min: f32, dir: vec3<f32>, t_max: f32 }
//! struct Hit { t: f32, u: f32, v: f32, primitive: u32, instance: u32, pad0: u32, pad1: u32, pad2: u32 }
//! ```
//!
//! Slot `s`'s byte of a `vec2<u32>` field `f` is `extractBits(f[s >> 2], 8 * (s & 3), 8)`.
//!
//! ## Traversal (what the kernel does)
//!
//! Per ray: `octant` = sign bits of `dir` (bit `a` set if negative), `inv_dir = 1 / dir` with
//! components smaller than 1e-30 replaced by `±1e-30` (no `0 * inf`), and the shear constants
//! of the watertight test. Start with the node group `[0, (1 << (24 + octant)) | 1]` (the root
//! as "slot 0 of a node whose imask is 1"). Loop:
//!
//! 1. If the group has node bits (24..32): take the lowest, `pos`; `slot = pos ^ octant`;
//!    node index = `base + countOneBits(group.imask & ((1 << slot) - 1))`; push the group if
//!    bits remain. Test the 8 child boxes: per axis
//!    `t = q * (step * inv_dir) + (origin - ray.origin) * inv_dir`, with `q_hi` as the near
//!    plane when the axis is negative in `octant`; hit if
//!    `max(t_near, t_min) <= min(t_far, t_max) * (1 + 2^-20)`. Hit internal children set bit
//!    `24 + (slot ^ octant)` of the new group `[child_base, bits | imask]`; hit leaves set
//!    their primitive bits (offset .. offset + count) of the triangle group `[prim_base, bits]`.
//! 2. Test every primitive of the triangle group (lowest bit first). Closest hit shrinks
//!    `t_max`; any hit returns at the first hit.
//! 3. If the current group has no node bits left, pop one; stop when the stack is empty.
//!
//! Two levels: the TLAS is walked the same way; its "primitives" are instances, and entering
//! one transforms the ray into object space (the direction is not renormalized, so `t` carries
//! over) and walks the BLAS with the same loop. On the GPU the BLAS walk can continue on the
//! same stack array above the TLAS entries; the CPU twin keeps two stacks. The stack needs one
//! entry per tree level: [`BlasStats::depth`] + [`TlasStats::depth`] entries.
//!
//! The triangle test is Woop, Benthin and Wald, *Watertight Ray/Triangle Intersection* (JCGT
//! 2013), without the double-precision fallback (WGSL has no portable f64): an edge function
//! that rounds to exactly zero counts as inside for both triangles sharing that edge, so rays
//! can never slip through a shared edge. There is no back-face culling.
//!
//! ## Cut-outs: non-opaque triangles and the any-hit filter
//!
//! A triangle marked [`layout::TRIANGLE_NON_OPAQUE`] ([`Blas::build_with_opacity`]; hikari-render's
//! `scene_bvh::blases` marks every triangle of a mesh some instance draws with a glTF MASK or
//! BLEND material) is a *candidate*: a hit on it counts only if a filter accepts it, and a
//! rejected candidate neither shrinks `t_max` nor ends an any-hit walk, so the ray goes on
//! through the hole. The CPU traversals take the filter as a closure (`*_filtered`:
//! `accept(instance, primitive, u, v)`); the GPU kernel calls `bvh_accept_candidate` with the
//! same arguments, which in hikari-render evaluates the material's alpha (factor × vertex
//! colour A × base colour texture A, bilinear at mip 0) against its cut-off, from tables bound
//! with the BVH (`scene_bvh::BvhAlpha`; its CPU twin is `scene_bvh::SceneAlphaFilter`).
//!
//! Cost. Opaque triangles pay one test of the flags word, which the triangle test loads anyway;
//! the filter runs only for hits on marked triangles, and costs there one 16-byte instance
//! record, one 32-byte triangle record (UVs and vertex alphas) and one bilinear texture fetch
//! at mip 0 (cache misses on distant cut-outs: mip 0 keeps the cut-out's edges where the
//! full-resolution texture puts them). The larger cost is in the walk: a rejected candidate
//! leaves `t_max` where it was, so closest-hit rays keep visiting the nodes behind a cut-out,
//! and any-hit rays (shadows, AO) cannot stop at the first candidate; dense foliage traces like
//! several layers of geometry. Marking only the triangles whose material needs it (not whole
//! scenes) keeps that cost to the cut-outs.
//!
//! ## Build
//!
//! 1. Validation ([`BuildOptions`]): triangles with NaN/infinite vertices or indices out of
//!    range are rejected (default) or skipped; zero-area triangles are skipped (default) or
//!    rejected. Errors ([`BvhError`]) name the mesh and the triangle; skipped counts are in
//!    [`BlasStats`].
//! 2. Binary BVH by binned SAH ([`build_sah`]): primitive boxes are moved in place as 32-byte
//!    records; 16 centroid bins per axis (8 below 64 primitives), an exact object-split sweep
//!    for nodes of at most 12, leaves of at most 3 primitives, and a median split as the
//!    fallback when no plane separates the centroids or the depth passes 40 (so every input
//!    terminates with bounded depth). The top levels are split level by level by all threads
//!    together (each bins its share of the triangles, the bins merge exactly, and a stable
//!    partition scatters the shares), then subtrees of at most 16K-64K primitives are built as
//!    tasks into node ranges reserved for them, so the tree is identical for any thread count.
//! 3. Collapse to the wide layout ([`wide`]): starting from a binary node, repeatedly open the
//!    child with the largest surface area until there are 8 children; any child with at most 3
//!    triangles becomes a leaf. Children are assigned to octant slots greedily by how well their
//!    centre offset aligns with each slot's corner, then quantized: the grid step per axis is
//!    the smallest power of two with `255 * step >= extent`; lower planes round down and upper
//!    planes up, checked by decoding in f32. Nodes are emitted depth-first (the order the
//!    binary nodes lie in memory); subtrees of at most 8K primitives are collapsed as separate
//!    jobs, scheduled dynamically on threads, and assembled in a fixed order.
//!
//! The TLAS has a builder of its own ([`tlas`]), rebuilt every frame over at most a few thousand
//! instances, where the binned builder's fixed costs per node dominate: instances are sorted
//! once by the 30-bit Morton code of their box centre (radix sort), and wide nodes are emitted
//! top-down directly, with no binary tree. A node's range of that order is split where the SAH
//! cost is lowest (every position for up to 24 instances; else the best boundary of at most 32
//! equal chunks, then every position around it), the child with the largest box first, until
//! the node has 8 children or none holds more than 8 instances; free slots then take the
//! instances of small children directly, and a child of one instance is a leaf slot (one
//! instance per slot). Slots and quantization as in step 3. What a rebuild
//! derives from each instance (world-to-object matrix, world box) is kept and derived again only
//! for instances whose transform, BLAS index or BLAS box changed.
//!
//! [`Blas::refit`] keeps the topology and slot assignment, recomputes boxes bottom-up
//! (children follow parents, so one reverse sweep suffices) and re-quantizes every node. Triangles skipped at build time (for
//! example degenerate in the build pose) stay out after a refit; rebuild to bring them back.

pub mod aabb;
pub mod blas;
pub mod build_sah;
pub mod cull;
pub mod error;
pub mod layout;
pub mod mesh;
pub mod reference;
pub mod refit;
/// The workspace's seeded generator (SplitMix64), re-exported for tests, examples and benches.
pub use hikari_math::sampling::rng;
pub mod sah_cost;
pub mod throttle;
pub mod tlas;
pub mod traverse;
pub mod triangle;
pub mod wide;

pub use aabb::Aabb;
pub use blas::{BadTriangle, Blas, BlasStats, BuildOptions, BuildTimings};
pub use cull::{CullSettings, CullStats, Frustum, cull_instances};
pub use error::BvhError;
pub use layout::{Hit, InstanceRecord, Ray, TriangleRecord, WideNode};
pub use mesh::Mesh;
pub use sah_cost::{SahCost, sah_cost};
pub use throttle::{RefitBatch, RefitScheduler, ThrottleSettings};
pub use tlas::{Instance, PackedBlases, Tlas, TlasBuilder, TlasStats};
pub use traverse::{Stack, TraversalStacks};
