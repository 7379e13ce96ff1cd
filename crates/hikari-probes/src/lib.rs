//! Irradiance-probe bakes: the data the baker produces and the renderer relights every frame,
//! and the file that carries it, in a crate of its own (no GPU code) so that the renderer reads
//! bakes without depending on the baker.
//!
//! A bake holds grid tiles (16x16x3 probes over a 200 m square: 12.5 m apart, 1.5, 10 and
//! 30 m above the terrain) and tetrahedral meshes (free probe positions, tetrahedra and their
//! adjacency). Every probe carries its sky visibility (mono L2 SH) and bounced sky visibility
//! (RGB L2 SH), both in the order l=0; l=1 m=-1,0,1; l=2 m=-2..2 of the real orthonormal
//! basis, and an interior flag. See [`model`]. [`locate`] finds the tetrahedron holding a
//! point by walking the adjacency (with barycentric weights), for tools and CPU twins.
//!
//! # File format, version 1
//!
//! All integers and floats little-endian; floats are IEEE-754 binary32 and must be finite.
//! Nothing is aligned beyond what the layout gives; readers copy.
//!
//! Header (80 bytes):
//!
//! | offset | bytes | type | field |
//! | --- | --- | --- | --- |
//! | 0 | 8 | `[u8; 8]` | magic `HIKPROBE` |
//! | 8 | 4 | u32 | format version, 1 |
//! | 12 | 4 | u32 | flags: bit 0 = complete (0 in a checkpoint); other bits 0 |
//! | 16 | 8 | u64 | total file length in bytes, checksum included |
//! | 24 | 32 | `[u8; 32]` | scene content key (caller's hash) |
//! | 56 | 4 | u32 | rays per probe (> 0) |
//! | 60 | 4 | f32 | grid spacing, metres (> 0) |
//! | 64 | 12 | `[f32; 3]` | layer heights above the ground, metres |
//! | 76 | 4 | u32 | section count S |
//!
//! Section table at byte 80: S entries of 24 bytes, grid tiles first, then meshes:
//!
//! | offset | bytes | type | field |
//! | --- | --- | --- | --- |
//! | 0 | 4 | u32 | kind: 1 = grid tile, 2 = tetrahedral mesh |
//! | 4 | 4 | u32 | probes in the section (768 for a tile) |
//! | 8 | 8 | u64 | byte offset of the section from the file's start |
//! | 16 | 8 | u64 | byte length of the section |
//!
//! Sections follow the table back to back (the first at 80 + 24 S). One probe's SH ("probe
//! SH", 144 bytes) is 9 f32 of sky visibility then 9 x 3 f32 of bounced sky visibility,
//! coefficient by coefficient, r g b within each.
//!
//! Grid tile (kind 1, 112 400 bytes); probe `(i, j, layer)` is number `(layer*16 + j)*16 + i`
//! and stands at `(x0 + i*spacing, ground[j*16 + i] + height[layer], z0 + j*spacing)`:
//!
//! | offset | bytes | type | field |
//! | --- | --- | --- | --- |
//! | 0 | 8 | `[i32; 2]` | tile coordinates (x, z), unique in the file |
//! | 8 | 8 | `[f32; 2]` | world x0, z0 of probe (0, 0), metres |
//! | 16 | 1024 | `[f32; 256]` | ground height under each column `j*16 + i`, metres |
//! | 1040 | 110 592 | 768 probe SH | probes |
//! | 111 632 | 768 | `[u8; 768]` | interior flags, 0 or 1 |
//!
//! Tetrahedral mesh (kind 2) of N probes (N from the table) and T tetrahedra,
//! 8 + 157 N + 32 T bytes:
//!
//! | offset | bytes | type | field |
//! | --- | --- | --- | --- |
//! | 0 | 4 | u32 | mesh id, unique in the file |
//! | 4 | 4 | u32 | tetrahedron count T |
//! | 8 | 12 N | `[f32; 3]` x N | probe positions, metres |
//! | 8 + 12 N | 144 N | N probe SH | probes |
//! | 8 + 156 N | 16 T | `[u32; 4]` x T | tetrahedra: four distinct probe indices < N |
//! | 8 + 156 N + 16 T | 16 T | `[u32; 4]` x T | neighbour across the face opposite vertex k, or `0xFFFF_FFFF` on the hull; mutual |
//! | 8 + 156 N + 32 T | N | `[u8; N]` | interior flags, 0 or 1 |
//!
//! Trailer: the last 4 bytes are the CRC-32 (IEEE 802.3 polynomial, as zlib's `crc32`) of
//! every byte before them.
//!
//! # Reading
//!
//! [`read_bake`] checks, in this order, and reports each as a distinct [`Problem`] naming the
//! file: missing file; shorter than a header; magic; version; length against the header
//! (truncated or trailing bytes); checksum; flags; scene key; settings; section table;
//! per-section counts against lengths; finiteness of every float; interior flags; tetrahedron
//! indices and adjacency; duplicate tiles or meshes. It never panics, on any bytes.
//!
//! # Resuming
//!
//! A baker calls [`resume`] to start (it loads `<file>.partial` when that holds a valid
//! checkpoint of the same scene and settings, and otherwise says why it was dropped), skips the
//! tiles and meshes the bake already has ([`Bake::has_tile`], [`Bake::has_mesh`]), calls
//! [`save_checkpoint`] every few seconds (rewrites `<file>.partial` atomically with the
//! complete flag clear), and [`finish`] at the end (writes `<file>` with the flag set and
//! removes the checkpoint). A checkpoint is an ordinary bake file; the renderer refuses it.

pub mod error;
mod file;
pub mod format;
pub mod locate;
pub mod model;
mod validate;

pub use error::{BakeFileError, Problem};
pub use file::{
    Resumed, finish, partial_path, read_any, read_bake, resume, save_checkpoint, write_bake,
};
pub use format::{FORMAT_VERSION, decode, encode};
pub use model::{
    Bake, BakeSettings, GridTile, HULL, ProbeSh, SceneKey, TILE_COLUMNS, TILE_LAYERS,
    TILE_PROBE_COUNT, TetMesh,
};
pub use validate::validate;
