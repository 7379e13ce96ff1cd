//! GPU-visible records: the compressed 8-wide node, triangle, instance, ray and hit structs.
//!
//! Every struct here is `#[repr(C)]`, `Pod`, a multiple of 16 bytes and holds only `u32`/`f32`
//! words, so a WGSL storage buffer can declare it either as the mirrored struct or as
//! `array<vec4<u32>>` and `bitcast` the fields. The byte tables are in the crate docs.

use bytemuck::{Pod, Zeroable};

/// Number of child slots of a wide node.
pub const WIDTH: usize = 8;
/// Most triangles a leaf child may reference (unary count in the top three meta bits).
pub const MAX_LEAF_TRIANGLES: usize = 3;
/// Internal children are announced in hit masks at bit `INTERNAL_BIT_BASE + (slot ^ octant)`.
pub const INTERNAL_BIT_BASE: u32 = 24;
/// `meta` of an internal child: `0b001_11000 | slot` (so the low five bits are `24 + slot`).
pub const META_INTERNAL: u8 = 0b0011_1000;

/// One compressed 8-wide BVH node (80 bytes, 5 x vec4).
///
/// Child `i`'s box decodes as `origin + q * 2^(exp - 127)` per axis, with `q` the child's 8-bit
/// lower or upper plane. Bytes are little-endian; the `[u32; 2]` fields hold 8 bytes, byte `i`
/// belonging to child slot `i`.
#[repr(C, align(16))]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct WideNode {
    /// Lower corner of the node's quantization grid (world or object space of the BLAS).
    pub origin: [f32; 3],
    /// Byte 0..3: biased exponents of the x, y, z grid step (`2^(e-127)`, i.e. the f32 exponent
    /// field); byte 3: `imask`, bit `slot` set if that child is an internal node.
    pub exp_imask: u32,
    /// Index of the first internal child in the node array; internal children are stored
    /// contiguously in slot order.
    pub child_base: u32,
    /// Index of the first triangle (BLAS) or instance (TLAS) referenced by this node's leaves.
    pub prim_base: u32,
    /// One byte per slot: 0 = empty; internal = `0b001_11000 | slot`; leaf = unary count in bits
    /// 5..8 (`0b001`, `0b011`, `0b111` for 1, 2, 3 primitives) and the offset from `prim_base`
    /// in bits 0..5.
    pub meta: [u32; 2],
    pub lo_x: [u32; 2],
    pub lo_y: [u32; 2],
    pub lo_z: [u32; 2],
    pub hi_x: [u32; 2],
    pub hi_y: [u32; 2],
    pub hi_z: [u32; 2],
}

#[inline]
fn byte_of(words: &[u32; 2], slot: usize) -> u8 {
    (words[slot >> 2] >> ((slot & 3) * 8)) as u8
}

#[inline]
fn set_byte(words: &mut [u32; 2], slot: usize, v: u8) {
    let shift = (slot & 3) * 8;
    let w = &mut words[slot >> 2];
    *w = (*w & !(0xFF << shift)) | ((v as u32) << shift);
}

impl WideNode {
    #[inline]
    pub fn exponents(&self) -> [u8; 3] {
        let e = self.exp_imask;
        [e as u8, (e >> 8) as u8, (e >> 16) as u8]
    }
    #[inline]
    pub fn imask(&self) -> u8 {
        (self.exp_imask >> 24) as u8
    }
    pub fn set_exponents_imask(&mut self, e: [u8; 3], imask: u8) {
        self.exp_imask =
            e[0] as u32 | (e[1] as u32) << 8 | (e[2] as u32) << 16 | (imask as u32) << 24;
    }
    #[inline]
    pub fn meta(&self, slot: usize) -> u8 {
        byte_of(&self.meta, slot)
    }
    pub fn set_meta(&mut self, slot: usize, v: u8) {
        set_byte(&mut self.meta, slot, v);
    }
    /// Quantized planes of a slot: `[lo_x, lo_y, lo_z]`, `[hi_x, hi_y, hi_z]`.
    #[inline]
    pub fn quantized(&self, slot: usize) -> ([u8; 3], [u8; 3]) {
        (
            [
                byte_of(&self.lo_x, slot),
                byte_of(&self.lo_y, slot),
                byte_of(&self.lo_z, slot),
            ],
            [
                byte_of(&self.hi_x, slot),
                byte_of(&self.hi_y, slot),
                byte_of(&self.hi_z, slot),
            ],
        )
    }
    pub fn set_quantized(&mut self, slot: usize, lo: [u8; 3], hi: [u8; 3]) {
        set_byte(&mut self.lo_x, slot, lo[0]);
        set_byte(&mut self.lo_y, slot, lo[1]);
        set_byte(&mut self.lo_z, slot, lo[2]);
        set_byte(&mut self.hi_x, slot, hi[0]);
        set_byte(&mut self.hi_y, slot, hi[1]);
        set_byte(&mut self.hi_z, slot, hi[2]);
    }
    /// Grid step per axis, `2^(e-127)`, built from the exponent bits as the kernel does.
    #[inline]
    pub fn scale(&self) -> [f32; 3] {
        let e = self.exponents();
        [
            f32::from_bits((e[0] as u32) << 23),
            f32::from_bits((e[1] as u32) << 23),
            f32::from_bits((e[2] as u32) << 23),
        ]
    }
    /// Decoded box of a non-empty slot.
    pub fn child_box(&self, slot: usize) -> crate::Aabb {
        let (lo, hi) = self.quantized(slot);
        let s = self.scale();
        let o = self.origin;
        let f = |a: usize, q: u8| o[a] + q as f32 * s[a];
        crate::Aabb::new(
            glam::Vec3A::new(f(0, lo[0]), f(1, lo[1]), f(2, lo[2])),
            glam::Vec3A::new(f(0, hi[0]), f(1, hi[1]), f(2, hi[2])),
        )
    }
    /// Child slot kind decoded from `meta` and `imask`.
    pub fn slot_kind(&self, slot: usize) -> SlotKind {
        let m = self.meta(slot);
        if m == 0 {
            SlotKind::Empty
        } else if self.imask() & (1 << slot) != 0 {
            let rel = (self.imask() as u32 & ((1u32 << slot) - 1)).count_ones();
            SlotKind::Internal(self.child_base + rel)
        } else {
            SlotKind::Leaf {
                first: self.prim_base + (m & 0x1F) as u32,
                count: (m >> 5).count_ones(),
            }
        }
    }
}

/// What a child slot holds, decoded (CPU convenience; the kernel decodes the bits inline).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SlotKind {
    Empty,
    Internal(u32),
    Leaf { first: u32, count: u32 },
}

/// Unary leaf count for `meta`'s top three bits.
pub(crate) fn leaf_meta(offset: u32, count: u32) -> u8 {
    debug_assert!((1..=3).contains(&count) && offset + count <= 24);
    let unary = (1u32 << count) - 1;
    ((unary << 5) | offset) as u8
}

/// `TriangleRecord::flags` bit: hits on this triangle are candidates that a filter may reject
/// (alpha cut-outs: glTF `alphaMode: MASK`). Clear = opaque, every hit stands. All other bits
/// are zero.
pub const TRIANGLE_NON_OPAQUE: u32 = 1;

/// One triangle in leaf order (48 bytes, 3 x vec4): the three vertices, as given, the index of
/// the triangle in the source mesh and its flags.
///
/// | bytes | field       | WGSL (`array<vec4<f32>>`, record `i` at `3 i`) |
/// |-------|-------------|------------------------------------------------|
/// | 0-11  | `v0`        | `[3i].xyz`                                     |
/// | 12-15 | `primitive` | `bitcast<u32>([3i].w)`                         |
/// | 16-27 | `v1`        | `[3i+1].xyz`                                   |
/// | 28-31 | `flags`     | `bitcast<u32>([3i+1].w)`, bit 0 = [`TRIANGLE_NON_OPAQUE`] |
/// | 32-43 | `v2`        | `[3i+2].xyz`                                   |
/// | 44-47 | `_pad2`     | zero                                           |
#[repr(C, align(16))]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct TriangleRecord {
    pub v0: [f32; 3],
    /// Index of the triangle in the mesh's index buffer (what hits report as `primitive`).
    pub primitive: u32,
    pub v1: [f32; 3],
    /// [`TRIANGLE_NON_OPAQUE`] or 0 (the word was padding before, so zeroed records are
    /// opaque).
    pub flags: u32,
    pub v2: [f32; 3],
    pub _pad2: u32,
}

impl TriangleRecord {
    /// True unless the triangle is marked [`TRIANGLE_NON_OPAQUE`].
    #[inline]
    pub fn is_opaque(&self) -> bool {
        self.flags & TRIANGLE_NON_OPAQUE == 0
    }
}

/// One TLAS leaf instance (64 bytes, 4 x vec4).
#[repr(C, align(16))]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct InstanceRecord {
    /// World-to-object affine transform, row-major 3x4: `p_obj.x = dot(row0.xyz, p) + row0.w`.
    pub world_to_object: [[f32; 4]; 3],
    /// First node of the BLAS in the packed BLAS node buffer (its root).
    pub blas_node_offset: u32,
    /// First triangle of the BLAS in the packed triangle buffer; BLAS `prim_base` values are
    /// relative to it, and so are `child_base` values relative to `blas_node_offset`.
    pub blas_triangle_offset: u32,
    /// Index of the instance in the caller's instance list (what hits report as `instance`).
    pub instance_index: u32,
    /// Index of the BLAS in the caller's BLAS list (the CPU twin reads its slices from there).
    pub blas_index: u32,
}

/// A ray as the kernel reads it (32 bytes). `dir` need not be normalized; `t` is measured in
/// units of `dir`, in world and object space alike (instance transforms keep `t`).
#[repr(C, align(16))]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct Ray {
    pub origin: [f32; 3],
    pub t_min: f32,
    pub dir: [f32; 3],
    pub t_max: f32,
}

impl Ray {
    pub fn new(origin: glam::Vec3, dir: glam::Vec3, t_min: f32, t_max: f32) -> Self {
        Self {
            origin: origin.into(),
            t_min,
            dir: dir.into(),
            t_max,
        }
    }
}

/// A hit as the kernel writes it (32 bytes). A miss has `instance == MISS` and `t = +inf`.
/// The hit point is `(1 - u - v) * v0 + u * v1 + v * v2`.
#[repr(C, align(16))]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct Hit {
    pub t: f32,
    pub u: f32,
    pub v: f32,
    pub primitive: u32,
    pub instance: u32,
    pub _pad: [u32; 3],
}

impl Hit {
    pub const MISS: u32 = u32::MAX;
    pub const NONE: Hit = Hit {
        t: f32::INFINITY,
        u: 0.0,
        v: 0.0,
        primitive: Hit::MISS,
        instance: Hit::MISS,
        _pad: [0; 3],
    };
    pub fn is_hit(&self) -> bool {
        self.primitive != Hit::MISS
    }
}

impl Default for Hit {
    fn default() -> Self {
        Hit::NONE
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    #[test]
    fn sizes_and_alignment() {
        assert_eq!(std::mem::size_of::<WideNode>(), 80);
        assert_eq!(std::mem::align_of::<WideNode>(), 16);
        assert_eq!(std::mem::size_of::<TriangleRecord>(), 48);
        assert_eq!(std::mem::size_of::<InstanceRecord>(), 64);
        assert_eq!(std::mem::size_of::<Ray>(), 32);
        assert_eq!(std::mem::size_of::<Hit>(), 32);
        assert_eq!(std::mem::offset_of!(WideNode, exp_imask), 12);
        assert_eq!(std::mem::offset_of!(WideNode, child_base), 16);
        assert_eq!(std::mem::offset_of!(WideNode, prim_base), 20);
        assert_eq!(std::mem::offset_of!(WideNode, meta), 24);
        assert_eq!(std::mem::offset_of!(WideNode, lo_x), 32);
        assert_eq!(std::mem::offset_of!(WideNode, hi_z), 72);
        assert_eq!(std::mem::offset_of!(TriangleRecord, primitive), 12);
        assert_eq!(std::mem::offset_of!(TriangleRecord, flags), 28);
        assert_eq!(std::mem::offset_of!(TriangleRecord, _pad2), 44);
    }

    #[test]
    fn byte_packing_roundtrip() {
        let mut n = WideNode::default();
        for s in 0..8 {
            n.set_meta(s, s as u8 + 1);
            n.set_quantized(s, [s as u8, 10 + s as u8, 20], [200, 201 + s as u8, 255]);
        }
        n.set_exponents_imask([120, 127, 130], 0b1010_0101);
        for s in 0..8 {
            assert_eq!(n.meta(s), s as u8 + 1);
            assert_eq!(
                n.quantized(s),
                ([s as u8, 10 + s as u8, 20], [200, 201 + s as u8, 255])
            );
        }
        assert_eq!(n.exponents(), [120, 127, 130]);
        assert_eq!(n.imask(), 0b1010_0101);
        assert_eq!(n.scale(), [2f32.powi(-7), 1.0, 8.0]);
        let bytes: &[u8] = bytemuck::bytes_of(&n);
        assert_eq!(bytes[24 + 3], 4); // meta of slot 3
        assert_eq!(bytes[15], 0b1010_0101); // imask
    }
}
