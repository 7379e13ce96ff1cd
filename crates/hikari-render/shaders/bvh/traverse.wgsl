// Two-level traversal of hikari's compressed 8-wide BVH (Ylitie, Karras, Laine 2017), the GPU
// twin of hikari-bvh's `traverse.rs`: same node decoding, same node visiting order (node
// groups, `slot ^ octant`), same watertight triangle test (Woop, Benthin, Wald 2013); a node's
// triangles may be tested a few steps later (BVH_TRIANGLES_PER_STEP), which changes no result
// but the choice between hits at exactly the same distance. Byte layouts are
// documented in hikari-bvh's crate docs; every record is read as whole vec4s so that each load
// is one 128-bit transaction whatever the driver makes of a struct load.
//
// The BVH buffers, and what the cut-out test reads, are the binding set `bvh`, in a group of
// their own (`BvhBuffers::binding_set` in hikari-render makes it); a pass that traces binds it
// with `.set(...)` beside its own resources in group 0. One ray per invocation: `bvh_closest_hit(ray)`, `bvh_any_hit(ray)`,
// `bvh_occluded(ray)`. Kernels that trace many rays per invocation (bvh/trace.wgsl) drive the
// walk themselves: `bvh_begin(ray)`, then `bvh_step` until it returns true, then `bvh_result()`.
//
// BvhTrace builds bvh/trace.wgsl without wgpu's runtime checks (no index clamping, no loop
// counters; see `bvh_trace.rs`). Every index below stays in range because BvhTrace validates
// the BVH it uploads (child and primitive indices, depth against BVH_STACK_SIZE); keep it that
// way when editing. A pass importing this module may drop the checks too only if its own
// indices are as safe.

#define_import_path hikari::bvh

#import hikari::scene_gpu::wrap_uv

// Mirrors of hikari-bvh's layout structs (registered in hikari-render's layout test;
// TriangleRecord's mirror is in bvh/trace.wgsl, as naga_oil refuses member names that end in a
// digit in an importable module).
struct Ray {
    origin: vec3<f32>,
    t_min: f32,
    dir: vec3<f32>,
    t_max: f32,
}

// A miss has primitive == instance == BVH_MISS and t = +inf.
struct Hit {
    t: f32,
    u: f32,
    v: f32,
    primitive: u32,
    instance: u32,
    _pad: array<u32, 3>,
}

struct InstanceRecord {
    world_to_object: array<vec4<f32>, 3>,
    blas_node_offset: u32,
    blas_triangle_offset: u32,
    instance_index: u32,
    blas_index: u32,
}

// WideNode records, 5 vec4 each, all BLAS concatenated.
@group(#{BVH_GROUP}) @binding(0) var<storage, read> bvh_blas_nodes: array<vec4<u32>>;
// TriangleRecords, 3 vec4 each, all BLAS concatenated.
@group(#{BVH_GROUP}) @binding(1) var<storage, read> bvh_triangles: array<vec4<f32>>;
// WideNode records of the TLAS; never empty (an empty scene is one node without children).
@group(#{BVH_GROUP}) @binding(2) var<storage, read> bvh_tlas_nodes: array<vec4<u32>>;
// InstanceRecords in TLAS leaf order, 4 vec4 each.
@group(#{BVH_GROUP}) @binding(3) var<storage, read> bvh_instances: array<vec4<f32>>;
// Cut-outs (read by bvh_accept_candidate only, for triangles marked non-opaque; layouts in
// hikari-render's scene_bvh.rs). AlphaInstance records, one vec4 per instance index: cut-off
// (0: opaque material), material alpha, texture layer | wrap << 24, first AlphaTriangle.
@group(#{BVH_GROUP}) @binding(4) var<storage, read> bvh_alpha_instances: array<vec4<u32>>;
// AlphaTriangle records, 2 vec4 each: uv0, uv1 / uv2, vertex alphas as unorm16 (a0 | a1 << 16, a2).
@group(#{BVH_GROUP}) @binding(5) var<storage, read> bvh_alpha_triangles: array<vec4<u32>>;
// The scene's base colour textures (sRGB array; alpha is linear) and a linear repeating sampler.
@group(#{BVH_GROUP}) @binding(6) var bvh_alpha_textures: texture_2d_array<f32>;
@group(#{BVH_GROUP}) @binding(7) var bvh_alpha_sampler: sampler;

const BVH_MISS: u32 = 0xffffffffu;
// One entry per tree level below the root, TLAS and BLAS together; hikari-render refuses a
// scene whose depths need more (`bvh_trace::STACK_SIZE` mirrors this).
const BVH_STACK_SIZE: u32 = 24u;
const BVH_NODE_BITS: u32 = 0xff000000u;
// 1 + 2^-20: absorbs the rounding of the reassociated slab formula (see hikari-bvh).
const BVH_BOX_FAR_SCALE: f32 = 1.00000095367431640625;
const BVH_MIN_DIR: f32 = 1e-30;
// Triangles a walk step tests at most; the rest wait for the next steps, while the warp's other
// lanes test nodes, which keeps the lanes of a warp busy alike (BENCHMARKS.md). 24 is all of a
// node's. `bvh_trace::TraceConfig::triangles_per_step` chooses for bvh/trace.wgsl; importers
// get 2, measured the best with one ray per invocation.
#ifdef BVH_TRIANGLES_PER_STEP_1
const BVH_TRIANGLES_PER_STEP: u32 = 1u;
#else ifdef BVH_TRIANGLES_PER_STEP_3
const BVH_TRIANGLES_PER_STEP: u32 = 3u;
#else ifdef BVH_TRIANGLES_PER_STEP_4
const BVH_TRIANGLES_PER_STEP: u32 = 4u;
#else ifdef BVH_TRIANGLES_PER_STEP_ALL
const BVH_TRIANGLES_PER_STEP: u32 = 24u;
#else
const BVH_TRIANGLES_PER_STEP: u32 = 2u;
#endif

// Per-ray constants, computed once in world space and again on entering each instance.
struct BvhPreparedRay {
    origin: vec3<f32>,
    inv_dir: vec3<f32>,
    shear: vec3<f32>,
    // Axis permutation of the triangle test, kx | ky << 2 | kz << 4 (each 0..2); kz is the
    // dominant axis of the direction.
    k: u32,
    // Bit a set if the direction along axis a is negative.
    octant: u32,
}

fn bvh_prepare(origin: vec3<f32>, dir: vec3<f32>) -> BvhPreparedRay {
    var r: BvhPreparedRay;
    r.origin = origin;
    let sgn = bitcast<vec3<u32>>(dir) & vec3<u32>(0x80000000u);
    // A tiny value of the same sign instead of zero keeps `0 * inf` out of the box test.
    let tiny = bitcast<vec3<f32>>(sgn | vec3<u32>(bitcast<u32>(BVH_MIN_DIR)));
    let safe = select(dir, tiny, abs(dir) < vec3<f32>(BVH_MIN_DIR));
    r.inv_dir = vec3<f32>(1.0) / safe;
    r.octant = (sgn.x >> 31u) | (sgn.y >> 30u) | (sgn.z >> 29u);
    let ad = abs(dir);
    var kz = 2u;
    if ad.x >= ad.y && ad.x >= ad.z {
        kz = 0u;
    } else if ad.y >= ad.z {
        kz = 1u;
    }
    var kx = select(kz + 1u, 0u, kz == 2u);
    var ky = select(kx + 1u, 0u, kx == 2u);
    // Keeps the winding of the projected triangle, so the sign convention of the edge
    // functions does not depend on the ray.
    if dir[kz] < 0.0 {
        let t = kx;
        kx = ky;
        ky = t;
    }
    r.k = kx | (ky << 2u) | (kz << 4u);
    r.shear = vec3<f32>(dir[kx] / dir[kz], dir[ky] / dir[kz], 1.0 / dir[kz]);
    return r;
}

fn bvh_permute(p: vec3<f32>, k: u32) -> vec3<f32> {
    return vec3<f32>(p[k & 3u], p[(k >> 2u) & 3u], p[k >> 4u]);
}

struct BvhTriHit {
    t: f32,
    u: f32,
    v: f32,
    hit: bool,
}

// Watertight ray/triangle test: (t, u, v), u and v the weights of v1 and v2, for a hit with
// t_min < t < t_max.
//
// The three vertices are processed as lanes of vec3s, and each edge function is evaluated with
// its two endpoints in a canonical order (then negated if swapped). Without fused multiply-add
// this is bit for bit the CPU twin's `cx * by - cy * bx` (a product is commutative and rounding
// to nearest is symmetric). Drivers may fuse multiply-adds, which would make `cx * by - cy * bx`
// and its mirror in the neighbouring triangle round differently; in canonical order both
// triangles evaluate a shared edge from the same operands in the same order, so as long as the
// driver fuses every lane alike the edge keeps one sign and no ray slips between them.
fn bvh_intersect_triangle(r: BvhPreparedRay, v0: vec3<f32>, v1: vec3<f32>, v2: vec3<f32>, t_min: f32, t_max: f32) -> BvhTriHit {
    var res: BvhTriHit;
    res.hit = false;
    let a = bvh_permute(v0 - r.origin, r.k);
    let b = bvh_permute(v1 - r.origin, r.k);
    let c = bvh_permute(v2 - r.origin, r.k);
    let z = vec3<f32>(a.z, b.z, c.z);
    let x = vec3<f32>(a.x, b.x, c.x) - r.shear.x * z;
    let y = vec3<f32>(a.y, b.y, c.y) - r.shear.y * z;
    // Edge functions U = e(C, B), V = e(A, C), W = e(B, A) with e(P, Q) = Px Qy - Py Qx.
    let px = x.zxy;
    let py = y.zxy;
    let qx = x.yzx;
    let qy = y.yzx;
    let swap = (qx < px) | ((qx == px) & (qy < py));
    let sx = select(px, qx, swap);
    let sy = select(py, qy, swap);
    let tx = select(qx, px, swap);
    let ty = select(qy, py, swap);
    let e0 = sx * ty - sy * tx;
    let e = select(e0, -e0, swap);
    if any(e < vec3<f32>(0.0)) && any(e > vec3<f32>(0.0)) {
        return res;
    }
    let det = e.x + e.y + e.z;
    if det == 0.0 {
        return res;
    }
    let zs = r.shear.z * z;
    let t_scaled = e.x * zs.x + e.y * zs.y + e.z * zs.z;
    let inv_det = 1.0 / det;
    let t = t_scaled * inv_det;
    // Written so that NaN fails.
    if t > t_min && t < t_max {
        res.t = t;
        res.u = e.y * inv_det;
        res.v = e.z * inv_det;
        res.hit = true;
    }
    return res;
}

// The 8-bit plane at bit `shift` of `w`, as f32. (Placing the byte in the mantissa of 2^23 and
// subtracting 2^23 is exact too, but measured 5-9% slower on an H200: the conversion takes
// the byte select for free.)
fn bvh_plane(w: u32, shift: u32) -> f32 {
    return f32(extractBits(w, shift, 8u));
}

// Whether the child box at bit `shift` of the four-slot plane words overlaps [t_min, t_max];
// `n*` / `f*` hold the near and far planes per axis (already swapped for negative directions).
fn bvh_slot_hit(shift: u32, nx: u32, ny: u32, nz: u32, fx: u32, fy: u32, fz: u32, scale: vec3<f32>, org: vec3<f32>, t_min: f32, t_max: f32) -> bool {
    let tnx = bvh_plane(nx, shift) * scale.x + org.x;
    let tny = bvh_plane(ny, shift) * scale.y + org.y;
    let tnz = bvh_plane(nz, shift) * scale.z + org.z;
    let tfx = bvh_plane(fx, shift) * scale.x + org.x;
    let tfy = bvh_plane(fy, shift) * scale.y + org.y;
    let tfz = bvh_plane(fz, shift) * scale.z + org.z;
    let t_near = max(max(tnx, tny), max(tnz, t_min));
    let t_far = min(min(tfx, tfy), min(tfz, t_max));
    return t_near <= t_far * BVH_BOX_FAR_SCALE;
}

// Four slots (one word of each 8-byte field). Returns their hit bits: for a hit leaf, its
// primitives' bits (the unary count in meta bits 5..8 shifted to the offset in bits 0..5); for
// a hit internal child, bit 24 + (slot ^ octant). Both come from one formula: an internal
// child's meta is 0b001_11000 | slot, so its count is 1 and its offset is 24 + slot, and the
// octant is XORed into the offsets of internal children only (leaf offsets never have bits 3
// and 4 both set, internal ones always do). Empty slots have meta 0 and set nothing.
fn bvh_intersect_quad(meta_word: u32, nx: u32, ny: u32, nz: u32, fx: u32, fy: u32, fz: u32, scale: vec3<f32>, org: vec3<f32>, t_min: f32, t_max: f32, octant: u32) -> u32 {
    let inner = meta_word & (meta_word << 1u) & 0x10101010u;
    let index = (meta_word ^ ((inner >> 4u) * octant)) & 0x1f1f1f1fu;
    let bits = (meta_word >> 5u) & 0x07070707u;
    var mask = 0u;
    if bvh_slot_hit(0u, nx, ny, nz, fx, fy, fz, scale, org, t_min, t_max) {
        mask |= extractBits(bits, 0u, 3u) << extractBits(index, 0u, 5u);
    }
    if bvh_slot_hit(8u, nx, ny, nz, fx, fy, fz, scale, org, t_min, t_max) {
        mask |= extractBits(bits, 8u, 3u) << extractBits(index, 8u, 5u);
    }
    if bvh_slot_hit(16u, nx, ny, nz, fx, fy, fz, scale, org, t_min, t_max) {
        mask |= extractBits(bits, 16u, 3u) << extractBits(index, 16u, 5u);
    }
    if bvh_slot_hit(24u, nx, ny, nz, fx, fy, fz, scale, org, t_min, t_max) {
        mask |= extractBits(bits, 24u, 3u) << extractBits(index, 24u, 5u);
    }
    return mask;
}

// Tests the ray against the 8 child boxes of the node held in n0..n4. Returns the internal-child
// bits at 24 + (slot ^ octant) and the leaf primitive bits at 0..24 (relative to prim_base),
// the two halves of hikari-bvh's `intersect_node_scalar`.
fn bvh_intersect_node(n0: vec4<u32>, n1: vec4<u32>, n2: vec4<u32>, n3: vec4<u32>, n4: vec4<u32>, r: BvhPreparedRay, t_min: f32, t_max: f32) -> u32 {
    let p = bitcast<vec3<f32>>(n0.xyz);
    let e = n0.w;
    let grid = vec3<f32>(
        bitcast<f32>((e & 0xffu) << 23u),
        bitcast<f32>(((e >> 8u) & 0xffu) << 23u),
        bitcast<f32>(((e >> 16u) & 0xffu) << 23u),
    );
    let scale = grid * r.inv_dir;
    let org = (p - r.origin) * r.inv_dir;
    // A negative direction meets the upper plane first.
    let neg_x = (r.octant & 1u) != 0u;
    let neg_y = (r.octant & 2u) != 0u;
    let neg_z = (r.octant & 4u) != 0u;
    let near_x = select(n2.xy, n3.zw, neg_x);
    let far_x = select(n3.zw, n2.xy, neg_x);
    let near_y = select(n2.zw, n4.xy, neg_y);
    let far_y = select(n4.xy, n2.zw, neg_y);
    let near_z = select(n3.xy, n4.zw, neg_z);
    let far_z = select(n4.zw, n3.xy, neg_z);
    return bvh_intersect_quad(n1.z, near_x.x, near_y.x, near_z.x, far_x.x, far_y.x, far_z.x, scale, org, t_min, t_max, r.octant)
        | bvh_intersect_quad(n1.w, near_x.y, near_y.y, near_z.y, far_x.y, far_y.y, far_z.y, scale, org, t_min, t_max, r.octant);
}

fn bvh_load_instance(i: u32) -> InstanceRecord {
    var rec: InstanceRecord;
    rec.world_to_object[0] = bvh_instances[4u * i];
    rec.world_to_object[1] = bvh_instances[4u * i + 1u];
    rec.world_to_object[2] = bvh_instances[4u * i + 2u];
    let tail = bitcast<vec4<u32>>(bvh_instances[4u * i + 3u]);
    rec.blas_node_offset = tail.x;
    rec.blas_triangle_offset = tail.y;
    rec.instance_index = tail.z;
    rec.blas_index = tail.w;
    return rec;
}

fn bvh_miss() -> Hit {
    var h: Hit;
    h.t = bitcast<f32>(0x7f800000u);
    h.u = 0.0;
    h.v = 0.0;
    h.primitive = BVH_MISS;
    h.instance = BVH_MISS;
    return h;
}

fn bvh_is_hit(h: Hit) -> bool {
    return h.primitive != BVH_MISS;
}

// The state of one ray's walk over TLAS and BLAS with one loop and one stack. `group` is the
// current node group (base node index, hit bits << 24 | imask) and `prims` the primitive group
// (base index, bits); a leaf primitive is a triangle inside a BLAS and an instance in the TLAS.
// Entering an instance keeps the TLAS groups in `saved_*` and walks the BLAS above the TLAS's
// stack entries (`stack_floor`); when the BLAS is done they come back, so the order of work is
// exactly the CPU twin's nested walks.
struct BvhWalk {
    // The world-space ray, kept to prepare it again on leaving an instance.
    origin: vec3<f32>,
    t_min: f32,
    dir: vec3<f32>,
    // The ray's t_max, shrunk to the closest hit so far.
    t_max: f32,
    // The ray prepared in the space of the tree being walked.
    r: BvhPreparedRay,
    group: vec2<u32>,
    prims: vec2<u32>,
    sp: u32,
    stack_floor: u32,
    in_blas: bool,
    node_offset: u32,
    prim_offset: u32,
    instance: u32,
    saved_group: vec2<u32>,
    saved_prims: vec2<u32>,
    hit_u: f32,
    hit_v: f32,
    hit_primitive: u32,
    hit_instance: u32,
}

var<private> bvh_w: BvhWalk;

// In private memory, which the driver keeps in the L1 cache. (A stack in workgroup memory was
// measured 2-3 times slower on an H200, probably because the shared-memory carve-out shrinks
// the L1 cache that the nodes are read through.)
var<private> bvh_stack: array<vec2<u32>, BVH_STACK_SIZE>;

fn bvh_push(g: vec2<u32>) {
    bvh_stack[bvh_w.sp] = g;
    bvh_w.sp += 1u;
}

fn bvh_pop() -> vec2<u32> {
    bvh_w.sp -= 1u;
    return bvh_stack[bvh_w.sp];
}

// Starts a walk for `ray` (discarding any walk in progress).
fn bvh_begin(ray: Ray) {
    bvh_w.origin = ray.origin;
    bvh_w.t_min = ray.t_min;
    bvh_w.dir = ray.dir;
    bvh_w.t_max = ray.t_max;
    bvh_w.r = bvh_prepare(ray.origin, ray.dir);
    // The root as the only member of a synthetic group: slot 0 with imask bit 0.
    bvh_w.group = vec2<u32>(0u, (1u << (24u + bvh_w.r.octant)) | 1u);
    bvh_w.prims = vec2<u32>(0u);
    bvh_w.sp = 0u;
    bvh_w.stack_floor = 0u;
    bvh_w.in_blas = false;
    bvh_w.node_offset = 0u;
    bvh_w.prim_offset = 0u;
    bvh_w.instance = 0u;
    bvh_w.hit_u = 0.0;
    bvh_w.hit_v = 0.0;
    bvh_w.hit_primitive = BVH_MISS;
    bvh_w.hit_instance = BVH_MISS;
}

// The hit of the walk (valid once bvh_step returned true).
fn bvh_result() -> Hit {
    if bvh_w.hit_primitive == BVH_MISS {
        return bvh_miss();
    }
    var h: Hit;
    h.t = bvh_w.t_max;
    h.u = bvh_w.hit_u;
    h.v = bvh_w.hit_v;
    h.primitive = bvh_w.hit_primitive;
    h.instance = bvh_w.hit_instance;
    return h;
}

// TriangleRecord.flags (the w of a record's second vec4) bit: hits on the triangle are
// candidates for bvh_accept_candidate (alpha cut-outs, glTF alphaMode MASK).
const BVH_TRIANGLE_NON_OPAQUE: u32 = 1u;

const BVH_ALPHA_NO_TEXTURE: u32 = 0x00ffffffu;

// Whether a candidate hit on a non-opaque triangle counts: `instance` is the instance index
// as hits report it, `primitive` the triangle's index in its mesh, `u`, `v` the weights of v1
// and v2. Called only for triangles flagged BVH_TRIANGLE_NON_OPAQUE; a rejected candidate is
// skipped and the walk goes on (closest and any hit alike).
//
// The rasteriser's alpha test (raster/setup.wgsl, alpha_covers) at the hit: material alpha
// times the interpolated vertex colour alpha times the base colour texture's A, bilinear at
// mip 0 (cut-out edges stay where the full-resolution texture puts them, at any distance),
// against the material's cut-off. CPU twin: scene_bvh::SceneAlphaFilter. Indices past the
// tables (a caller's mistake: BvhTrace refuses what it can see) accept the hit rather than
// read out of bounds, as the kernel runs without runtime checks.
fn bvh_accept_candidate(instance: u32, primitive: u32, u: f32, v: f32) -> bool {
#ifdef BVH_ALPHA
    if instance >= arrayLength(&bvh_alpha_instances) {
        return true;
    }
    let rec = bvh_alpha_instances[instance];
    let cutoff = bitcast<f32>(rec.x);
    if !(cutoff > 0.0) {
        return true;
    }
    let i = 2u * (rec.w + primitive);
    if rec.w + primitive >= arrayLength(&bvh_alpha_triangles) / 2u {
        return true;
    }
    let t0 = bvh_alpha_triangles[i];
    let t1 = bvh_alpha_triangles[i + 1u];
    let w = vec3<f32>(1.0 - u - v, u, v);
    let material_alpha = bitcast<f32>(rec.y);
    let vertex_alpha = vec3<f32>(unpack2x16unorm(t1.z), unpack2x16unorm(t1.w).x) * material_alpha;
    var alpha = dot(vertex_alpha, w);
    let layer = rec.z & BVH_ALPHA_NO_TEXTURE;
    if layer != BVH_ALPHA_NO_TEXTURE {
        let uv = bitcast<vec2<f32>>(t0.xy) * w.x + bitcast<vec2<f32>>(t0.zw) * w.y + bitcast<vec2<f32>>(t1.xy) * w.z;
        let size = textureDimensions(bvh_alpha_textures);
        alpha *= textureSampleLevel(bvh_alpha_textures, bvh_alpha_sampler, wrap_uv(uv, rec.z >> 24u, size), layer, 0.0).a;
    }
    // NaN fails: no hit.
    return alpha >= cutoff;
#else
    // Kernels built without TraceConfig::alpha: the host refuses TLASes with cut-outs.
    return true;
#endif
}

// One iteration of the walk: the next node of the current group (unless primitives are
// pending), then the primitives it hit (the next BVH_TRIANGLES_PER_STEP triangles of a BLAS
// leaf, or entering one instance of a TLAS leaf), then a pop when the group is used up. An
// iteration costs a warp about one node test plus a few triangle tests whatever its lanes are
// doing, so its lanes stay busy alike. Returns true when the walk is over: the tree is
// exhausted, or (`stop_at_first`) a hit was found. `stop_at_first` is a constant at every call
// site and folds away.
fn bvh_step(stop_at_first: bool) -> bool {
    if bvh_w.prims.y == 0u && (bvh_w.group.y & BVH_NODE_BITS) != 0u {
        let g = bvh_w.group;
        let pos = firstTrailingBit(g.y >> 24u);
        let rest = g.y & ~(1u << (24u + pos));
        let slot = pos ^ bvh_w.r.octant;
        let index = 5u * (g.x + countOneBits(g.y & 0xffu & ((1u << slot) - 1u)));
        if (rest & BVH_NODE_BITS) != 0u {
            bvh_push(vec2<u32>(g.x, rest));
        }
        var n0: vec4<u32>;
        var n1: vec4<u32>;
        var n2: vec4<u32>;
        var n3: vec4<u32>;
        var n4: vec4<u32>;
        if bvh_w.in_blas {
            n0 = bvh_blas_nodes[index];
            n1 = bvh_blas_nodes[index + 1u];
            n2 = bvh_blas_nodes[index + 2u];
            n3 = bvh_blas_nodes[index + 3u];
            n4 = bvh_blas_nodes[index + 4u];
        } else {
            n0 = bvh_tlas_nodes[index];
            n1 = bvh_tlas_nodes[index + 1u];
            n2 = bvh_tlas_nodes[index + 2u];
            n3 = bvh_tlas_nodes[index + 3u];
            n4 = bvh_tlas_nodes[index + 4u];
        }
        let m = bvh_intersect_node(n0, n1, n2, n3, n4, bvh_w.r, bvh_w.t_min, bvh_w.t_max);
        bvh_w.group = vec2<u32>(n1.x + bvh_w.node_offset, (m & BVH_NODE_BITS) | (n0.w >> 24u));
        bvh_w.prims = vec2<u32>(n1.y + bvh_w.prim_offset, m & 0x00ffffffu);
    }
    if bvh_w.prims.y != 0u {
        if bvh_w.in_blas {
            var bits = bvh_w.prims.y;
            let base = bvh_w.prims.x;
            var budget = BVH_TRIANGLES_PER_STEP;
            loop {
                let k = firstTrailingBit(bits);
                bits &= bits - 1u;
                let i = 3u * (base + k);
                let w0 = bvh_triangles[i];
                let w1 = bvh_triangles[i + 1u];
                let w2 = bvh_triangles[i + 2u];
                let h = bvh_intersect_triangle(bvh_w.r, w0.xyz, w1.xyz, w2.xyz, bvh_w.t_min, bvh_w.t_max);
                // `||` short-circuits: an opaque triangle's hit pays one test of a word already
                // loaded, and only flagged triangles call the filter.
                if h.hit && ((bitcast<u32>(w1.w) & BVH_TRIANGLE_NON_OPAQUE) == 0u
                    || bvh_accept_candidate(bvh_w.instance, bitcast<u32>(w0.w), h.u, h.v)) {
                    bvh_w.t_max = h.t;
                    bvh_w.hit_u = h.u;
                    bvh_w.hit_v = h.v;
                    bvh_w.hit_primitive = bitcast<u32>(w0.w);
                    bvh_w.hit_instance = bvh_w.instance;
                    if stop_at_first {
                        return true;
                    }
                }
                budget -= 1u;
                if bits == 0u || budget == 0u {
                    break;
                }
            }
            bvh_w.prims.y = bits;
        } else {
            let k = firstTrailingBit(bvh_w.prims.y);
            bvh_w.prims.y &= bvh_w.prims.y - 1u;
            let inst = bvh_load_instance(bvh_w.prims.x + k);
            let m0 = inst.world_to_object[0];
            let m1 = inst.world_to_object[1];
            let m2 = inst.world_to_object[2];
            let o = bvh_w.origin;
            let d = bvh_w.dir;
            let oo = vec3<f32>(
                m0.x * o.x + m0.y * o.y + m0.z * o.z + m0.w,
                m1.x * o.x + m1.y * o.y + m1.z * o.z + m1.w,
                m2.x * o.x + m2.y * o.y + m2.z * o.z + m2.w,
            );
            let od = vec3<f32>(
                m0.x * d.x + m0.y * d.y + m0.z * d.z,
                m1.x * d.x + m1.y * d.y + m1.z * d.z,
                m2.x * d.x + m2.y * d.y + m2.z * d.z,
            );
            // The direction is not renormalized, so t means the same in both spaces.
            bvh_w.r = bvh_prepare(oo, od);
            bvh_w.saved_group = bvh_w.group;
            bvh_w.saved_prims = bvh_w.prims;
            bvh_w.stack_floor = bvh_w.sp;
            bvh_w.in_blas = true;
            bvh_w.node_offset = inst.blas_node_offset;
            bvh_w.prim_offset = inst.blas_triangle_offset;
            bvh_w.instance = inst.instance_index;
            bvh_w.group = vec2<u32>(inst.blas_node_offset, (1u << (24u + bvh_w.r.octant)) | 1u);
            bvh_w.prims = vec2<u32>(0u);
            return false;
        }
    }
    if (bvh_w.group.y & BVH_NODE_BITS) == 0u {
        if bvh_w.sp > bvh_w.stack_floor {
            bvh_w.group = bvh_pop();
        } else if bvh_w.prims.y != 0u {
            // Triangles of this tree still to test (BVH_TRIANGLES_PER_STEP).
        } else if bvh_w.in_blas {
            // This instance is done: back to the TLAS, with t_max as the BLAS left it.
            bvh_w.in_blas = false;
            bvh_w.r = bvh_prepare(bvh_w.origin, bvh_w.dir);
            bvh_w.stack_floor = 0u;
            bvh_w.node_offset = 0u;
            bvh_w.prim_offset = 0u;
            bvh_w.group = bvh_w.saved_group;
            bvh_w.prims = bvh_w.saved_prims;
        } else {
            return true;
        }
    }
    return false;
}

// The whole walk for one ray.
fn bvh_trace(ray: Ray, stop_at_first: bool) -> Hit {
    bvh_begin(ray);
    loop {
        if bvh_step(stop_at_first) {
            break;
        }
    }
    return bvh_result();
}

// Closest hit with ray.t_min < t < ray.t_max.
fn bvh_closest_hit(ray: Ray) -> Hit {
    return bvh_trace(ray, false);
}

// The first hit found with ray.t_min < t < ray.t_max (not the closest), or a miss.
fn bvh_any_hit(ray: Ray) -> Hit {
    return bvh_trace(ray, true);
}

// Occlusion only, for shadow and AO rays.
fn bvh_occluded(ray: Ray) -> bool {
    return bvh_is_hit(bvh_trace(ray, true));
}
