// Two-level traversal of hikari's compressed 8-wide BVH (Ylitie, Karras, Laine 2017), the GPU
// twin of hikari-bvh's `traverse.rs`: same node decoding, same visiting order (node groups,
// `slot ^ octant`), same watertight triangle test (Woop, Benthin, Wald 2013). Byte layouts are
// documented in hikari-bvh's crate docs; every record is read as whole vec4s so that each load
// is one 128-bit transaction whatever the driver makes of a struct load.
//
// A pass that traces binds the four BVH buffers first, @binding(0..4) in the order below
// (`BvhTrace::import` in hikari-render gives them in that order), and its own resources from
// @binding(4) on.

#define_import_path hikari::bvh

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
@group(0) @binding(0) var<storage, read> bvh_blas_nodes: array<vec4<u32>>;
// TriangleRecords, 3 vec4 each, all BLAS concatenated.
@group(0) @binding(1) var<storage, read> bvh_triangles: array<vec4<f32>>;
// WideNode records of the TLAS; never empty (an empty scene is one node without children).
@group(0) @binding(2) var<storage, read> bvh_tlas_nodes: array<vec4<u32>>;
// InstanceRecords in TLAS leaf order, 4 vec4 each.
@group(0) @binding(3) var<storage, read> bvh_instances: array<vec4<f32>>;

const BVH_MISS: u32 = 0xffffffffu;
// One entry per tree level below the root, TLAS and BLAS together; hikari-render refuses a
// scene whose depths need more (`bvh_trace::STACK_SIZE` mirrors this).
const BVH_STACK_SIZE: u32 = 24u;
const BVH_NODE_BITS: u32 = 0xff000000u;
// 1 + 2^-20: absorbs the rounding of the reassociated slab formula (see hikari-bvh).
const BVH_BOX_FAR_SCALE: f32 = 1.00000095367431640625;
const BVH_MIN_DIR: f32 = 1e-30;

// Per-ray constants, computed once in world space and again on entering each instance.
struct BvhPreparedRay {
    origin: vec3<f32>,
    inv_dir: vec3<f32>,
    // Axis permutation of the triangle test: k.z is the dominant axis of the direction.
    k: vec3<u32>,
    shear: vec3<f32>,
    // Bit a set if the direction along axis a is negative.
    octant: u32,
    t_min: f32,
}

fn bvh_prepare(origin: vec3<f32>, dir: vec3<f32>, t_min: f32) -> BvhPreparedRay {
    var r: BvhPreparedRay;
    r.origin = origin;
    r.t_min = t_min;
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
    var kx = (kz + 1u) % 3u;
    var ky = (kx + 1u) % 3u;
    // Keeps the winding of the projected triangle, so the sign convention of the edge
    // functions does not depend on the ray.
    if dir[kz] < 0.0 {
        let t = kx;
        kx = ky;
        ky = t;
    }
    r.k = vec3<u32>(kx, ky, kz);
    r.shear = vec3<f32>(dir[kx] / dir[kz], dir[ky] / dir[kz], 1.0 / dir[kz]);
    return r;
}

fn bvh_permute(p: vec3<f32>, k: vec3<u32>) -> vec3<f32> {
    return vec3<f32>(p[k.x], p[k.y], p[k.z]);
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
fn bvh_intersect_triangle(r: BvhPreparedRay, v0: vec3<f32>, v1: vec3<f32>, v2: vec3<f32>, t_max: f32) -> BvhTriHit {
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
    if t > r.t_min && t < t_max {
        res.t = t;
        res.u = e.y * inv_det;
        res.v = e.z * inv_det;
        res.hit = true;
    }
    return res;
}

// Slot s's byte of an 8-byte field held as two words.
fn bvh_byte(w: vec2<u32>, s: u32) -> u32 {
    return extractBits(w[s >> 2u], (s & 3u) * 8u, 8u);
}

// Tests the ray against the 8 child boxes of the node whose first vec4 is `n0`. Returns the
// internal-child bits at slot ^ octant (0..8) and the leaf triangle bits (0..24, relative to
// prim_base), as hikari-bvh's `intersect_node_scalar`.
fn bvh_intersect_node(n0: vec4<u32>, n1: vec4<u32>, n2: vec4<u32>, n3: vec4<u32>, n4: vec4<u32>, r: BvhPreparedRay, t_max: f32) -> vec2<u32> {
    let p = bitcast<vec3<f32>>(n0.xyz);
    let e = n0.w;
    let grid = vec3<f32>(
        bitcast<f32>((e & 0xffu) << 23u),
        bitcast<f32>(((e >> 8u) & 0xffu) << 23u),
        bitcast<f32>(((e >> 16u) & 0xffu) << 23u),
    );
    let imask = e >> 24u;
    let adj_scale = grid * r.inv_dir;
    let adj_origin = (p - r.origin) * r.inv_dir;
    let meta_words = n1.zw;
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
    var node_hits = 0u;
    var tri_hits = 0u;
    for (var s = 0u; s < 8u; s++) {
        let m = bvh_byte(meta_words, s);
        let tnx = f32(bvh_byte(near_x, s)) * adj_scale.x + adj_origin.x;
        let tny = f32(bvh_byte(near_y, s)) * adj_scale.y + adj_origin.y;
        let tnz = f32(bvh_byte(near_z, s)) * adj_scale.z + adj_origin.z;
        let tfx = f32(bvh_byte(far_x, s)) * adj_scale.x + adj_origin.x;
        let tfy = f32(bvh_byte(far_y, s)) * adj_scale.y + adj_origin.y;
        let tfz = f32(bvh_byte(far_z, s)) * adj_scale.z + adj_origin.z;
        let t_near = max(max(max(r.t_min, tnx), tny), tnz);
        let t_far = min(min(min(t_max, tfx), tfy), tfz);
        if m != 0u && t_near <= t_far * BVH_BOX_FAR_SCALE {
            if (imask & (1u << s)) != 0u {
                node_hits |= 1u << (s ^ r.octant);
            } else {
                let count = countOneBits(m >> 5u);
                tri_hits |= ((1u << count) - 1u) << (m & 0x1fu);
            }
        }
    }
    return vec2<u32>(node_hits, tri_hits);
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

// The walk over TLAS and BLAS in one loop with one stack. The state is the current node group
// (`group`: base node index, hit bits << 24 | imask) and primitive group (`prims`: base index,
// bits); a leaf primitive is a triangle inside a BLAS and an instance in the TLAS. Entering an
// instance keeps the TLAS groups in registers and walks the BLAS above the TLAS's stack
// entries (`stack_floor`); when the BLAS is done they come back, so the order of work is
// exactly the CPU twin's nested walks. `stop_at_first` is a constant at every call site and folds away.
fn bvh_trace(ray: Ray, stop_at_first: bool) -> Hit {
    var best = bvh_miss();
    var t_max = ray.t_max;
    let world = bvh_prepare(ray.origin, ray.dir, ray.t_min);
    var r = world;
    var stack: array<vec2<u32>, BVH_STACK_SIZE>;
    var sp = 0u;
    var stack_floor = 0u;
    var in_blas = false;
    var node_offset = 0u;
    var prim_offset = 0u;
    var instance = 0u;
    var saved_group = vec2<u32>(0u);
    var saved_prims = vec2<u32>(0u);
    // The root as the only member of a synthetic group: slot 0 with imask bit 0.
    var group = vec2<u32>(0u, (1u << (24u + r.octant)) | 1u);
    var prims = vec2<u32>(0u);
    loop {
        if prims.y != 0u {
            if in_blas {
                loop {
                    let k = firstTrailingBit(prims.y);
                    prims.y &= prims.y - 1u;
                    let i = 3u * (prims.x + k);
                    let w0 = bvh_triangles[i];
                    let w1 = bvh_triangles[i + 1u];
                    let w2 = bvh_triangles[i + 2u];
                    let h = bvh_intersect_triangle(r, w0.xyz, w1.xyz, w2.xyz, t_max);
                    if h.hit {
                        t_max = h.t;
                        best.t = h.t;
                        best.u = h.u;
                        best.v = h.v;
                        best.primitive = bitcast<u32>(w0.w);
                        best.instance = instance;
                        if stop_at_first {
                            return best;
                        }
                    }
                    if prims.y == 0u {
                        break;
                    }
                }
            } else {
                let k = firstTrailingBit(prims.y);
                prims.y &= prims.y - 1u;
                let inst = bvh_load_instance(prims.x + k);
                let m0 = inst.world_to_object[0];
                let m1 = inst.world_to_object[1];
                let m2 = inst.world_to_object[2];
                let o = ray.origin;
                let d = ray.dir;
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
                r = bvh_prepare(oo, od, ray.t_min);
                saved_group = group;
                saved_prims = prims;
                stack_floor = sp;
                in_blas = true;
                node_offset = inst.blas_node_offset;
                prim_offset = inst.blas_triangle_offset;
                instance = inst.instance_index;
                group = vec2<u32>(node_offset, (1u << (24u + r.octant)) | 1u);
                prims = vec2<u32>(0u);
            }
            continue;
        }
        if (group.y & BVH_NODE_BITS) != 0u {
            let pos = firstTrailingBit(group.y >> 24u);
            group.y &= ~(1u << (24u + pos));
            let slot = pos ^ r.octant;
            let below = group.y & 0xffu & ((1u << slot) - 1u);
            let index = 5u * (group.x + countOneBits(below));
            if (group.y & BVH_NODE_BITS) != 0u {
                stack[sp] = group;
                sp += 1u;
            }
            var n0: vec4<u32>;
            var n1: vec4<u32>;
            var n2: vec4<u32>;
            var n3: vec4<u32>;
            var n4: vec4<u32>;
            if in_blas {
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
            let h = bvh_intersect_node(n0, n1, n2, n3, n4, r, t_max);
            group = vec2<u32>(n1.x + node_offset, (h.x << 24u) | (n0.w >> 24u));
            prims = vec2<u32>(n1.y + prim_offset, h.y);
            continue;
        }
        if sp > stack_floor {
            sp -= 1u;
            group = stack[sp];
            continue;
        }
        if !in_blas {
            break;
        }
        // This instance is done: back to the TLAS, with t_max as the BLAS left it.
        in_blas = false;
        r = world;
        stack_floor = 0u;
        node_offset = 0u;
        prim_offset = 0u;
        group = saved_group;
        prims = saved_prims;
    }
    return best;
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
