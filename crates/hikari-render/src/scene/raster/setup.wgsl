#define_import_path hikari::raster::setup

// Triangle setup of hikari's compute rasteriser, shared by the triangle and tile passes.
//
// Watertightness: a pixel centre is inside when every edge function is positive, or zero on a
// top-left edge. Each edge's plane equation A x + B y + C is computed from its two end points
// taken in a canonical order (lexicographic in x, then y) and negated as needed, so the two
// triangles sharing an edge get bit-exact opposite values and every pixel centre on the edge
// belongs to exactly one of them. Near-plane clipping interpolates from the inside end point,
// so neighbours clip a shared edge to the same point.

#import hikari::scene_gpu::{InstanceGpu, Chunk, CHUNK_TRIANGLES, INSTANCE_DOUBLE_SIDED}
#ifdef ALPHA_TEST
#import hikari::scene_gpu::{VertexAttr, MaterialGpu, NO_TEXTURE, wrap_uv}
#endif

@group(0) @binding(0) var<uniform> params: RasterParams;
#ifdef DEPTH_ONLY
// One u32 a texel per view: the bits of the NDC depth, whose order is the order of the depths.
@group(0) @binding(1) var<storage, read_write> target_texels: array<atomic<u32>>;
#else
// One u64 a pixel: NDC depth bits above the visibility id, so atomicMax keeps the nearest.
@group(0) @binding(1) var<storage, read_write> target_texels: array<atomic<u64>>;
#endif
// Tile queue: (triangle record, tile x | tile y << 12) in the first `config.y` entries, then
// up to LARGE_CAPACITY large triangles as (triangle record, view) followed by their tile
// rectangle (x | y << 16 of the first and of the last tile).
@group(0) @binding(2) var<storage, read_write> queue: array<vec2<u32>>;
// [0]: tile entries, [1]: large triangles, [2]: triangle records (all keep counting past
// their capacity, so a readback can tell an overflow).
@group(0) @binding(3) var<storage, read_write> queue_count: array<atomic<u32>>;
// Triangles set up once by the triangle pass for the tile and large passes, which would
// otherwise each fetch and set up their triangle again for every tile (a chain of five
// dependent loads, then the clip and the edge equations, in every workgroup).
@group(0) @binding(4) var<storage, read_write> records: array<TriRecord>;
// The scene, read by the triangle pass only (the later passes bind 0 to 4).
@group(0) @binding(5) var<storage, read> positions: array<vec4<f32>>;
@group(0) @binding(6) var<storage, read> indices: array<u32>;
@group(0) @binding(7) var<storage, read> instances: array<InstanceGpu>;
@group(0) @binding(8) var<storage, read> chunks: array<Chunk>;
#ifdef ALPHA_TEST
// What the alpha test reads besides (ALPHA_TEST variants only, whose tile pass binds 0 to 12
// too): the base colour's alpha, from the material, the vertex colours and the texture.
@group(0) @binding(9) var<storage, read> attributes: array<VertexAttr>;
@group(0) @binding(10) var<storage, read> materials: array<MaterialGpu>;
@group(0) @binding(11) var color_textures: texture_2d_array<f32>;
@group(0) @binding(12) var texture_sampler: sampler;
#endif

// The views one dispatch rasterises into (the camera, or the shadow cascades, whole or the
// strips a scrolled cascade uncovers).
struct RasterParams {
    view_proj: array<mat4x4<f32>, 8>,
    // width, height, 1 / width, 1 / height of each view's target, in pixels.
    viewport: vec4<f32>,
    // x: 1 to cull back faces of single-sided instances; y: capacity of the tile queue in
    // entries; z: number of views; w: number of chunks.
    config: vec4<u32>,
    // Per view: x the slice of the target (of width * height texels) it draws into; y the
    // origin, where its pixel (0, 0) is stored (DEPTH_ONLY: pixel p lands at (p + origin)
    // mod size, sizes powers of two); z, w the first pixel and the end (exclusive) of the
    // window it draws. Points packed as x | y << 16.
    views: array<vec4<u32>, 8>,
    // x: capacity of `records`; y: the first chunk (the alpha-tested passes draw the chunks
    // from `SceneGpu::first_alpha_chunk` on; the others from 0).
    limits: vec4<u32>,
}

// A set-up triangle: its edge equations and depth plane (xyz, as f32 bits), with the
// visibility id, the owned edges (bits 0-2) and view (bits 8-15), and the first and last
// pixel of its clamped rectangle (x | y << 16) in w.
struct TriRecord {
    edge_a: vec4<u32>,
    edge_b: vec4<u32>,
    edge_c: vec4<u32>,
    depth: vec4<u32>,
}

// Up to four screen-space vertices (xy in pixels, z the NDC depth): the triangle, or the
// quad left after near clipping. Plain fields, not arrays: dynamically indexed arrays would
// live in slow local memory.
struct Poly {
    count: u32,
    // The winding is clockwise on screen (negative area): edge functions are negated.
    flip: bool,
    va: vec3<f32>,
    vb: vec3<f32>,
    vc: vec3<f32>,
    vd: vec3<f32>,
}

// Pixels (inclusive) a polygon can touch, clamped to the target.
struct PixelRect {
    lo: vec2<i32>,
    hi: vec2<i32>,
}

const TILE_SIZE: u32 = 32u;
// Triangles whose box spans more tiles are rasterised by every workgroup of the large pass
// together, rather than by one thread queueing all their tiles. Every workgroup walks the list
// of large triangles to find its share of their tiles, so the threshold keeps them few: only
// the near-screen-filling ones.
const LARGE_TRIANGLE_TILES: u32 = 256u;
const LARGE_CAPACITY: u32 = 65536u;
// Triangles whose clamped bounding box holds more pixels go to the tile queue.
const SMALL_TRIANGLE_PIXELS: i32 = 96;

fn to_screen(c: vec4<f32>, size: vec2<f32>) -> vec3<f32> {
    let inv_w = 1.0 / c.w;
    return vec3<f32>((c.x * inv_w * 0.5 + 0.5) * size.x, (0.5 - c.y * inv_w * 0.5) * size.y, c.z * inv_w);
}

// Point where edge a-b crosses the near plane, interpolated from its inside end point so both
// triangles on the edge compute the same point.
fn near_crossing(a: vec4<f32>, b: vec4<f32>) -> vec4<f32> {
    let da = a.w - a.z;
    let db = b.w - b.z;
    if da >= 0.0 {
        return a + (b - a) * (da / (da - db));
    }
    return b + (a - b) * (db / (db - da));
}

fn cross2(a: vec2<f32>, b: vec2<f32>) -> f32 {
    return a.x * b.y - a.y * b.x;
}

// The polygon of a triangle with clip-space vertices c0, c1, c2; count 0 when it is culled
// (behind the near plane, outside a side of the frustum, back-facing and single-sided, or of
// zero area).
fn triangle_poly(c0: vec4<f32>, c1: vec4<f32>, c2: vec4<f32>, size: vec2<f32>, cull_back: bool) -> Poly {
    var out: Poly;
    out.count = 0u;
    // Entirely outside one side plane of the frustum.
    let outside_l = c0.x < -c0.w && c1.x < -c1.w && c2.x < -c2.w;
    let outside_r = c0.x > c0.w && c1.x > c1.w && c2.x > c2.w;
    let outside_b = c0.y < -c0.w && c1.y < -c1.w && c2.y < -c2.w;
    let outside_t = c0.y > c0.w && c1.y > c1.w && c2.y > c2.w;
    if outside_l || outside_r || outside_b || outside_t {
        return out;
    }
    // Near plane z <= w (reverse-Z: NDC depth <= 1).
    let in0 = c0.w - c0.z >= 0.0;
    let in1 = c1.w - c1.z >= 0.0;
    let in2 = c2.w - c2.z >= 0.0;
    var n = 3u;
    if in0 && in1 && in2 {
        out.va = to_screen(c0, size);
        out.vb = to_screen(c1, size);
        out.vc = to_screen(c2, size);
    } else {
        // Walk the edges c0-c1, c1-c2, c2-c0 (Sutherland-Hodgman with one plane), keeping
        // inside vertices and crossings in order.
        var v: array<vec4<f32>, 4>;
        n = 0u;
        let c = array<vec4<f32>, 3>(c0, c1, c2);
        let inside = array<bool, 3>(in0, in1, in2);
        for (var i = 0u; i < 3u; i++) {
            let j = (i + 1u) % 3u;
            if inside[i] {
                v[n] = c[i];
                n++;
            }
            if inside[i] != inside[j] {
                v[n] = near_crossing(c[i], c[j]);
                n++;
            }
        }
        if n < 3u {
            return out;
        }
        out.va = to_screen(v[0], size);
        out.vb = to_screen(v[1], size);
        out.vc = to_screen(v[2], size);
        out.vd = to_screen(v[3], size);
    }
    // Front faces are counter-clockwise in NDC, so clockwise (negative area) on the y-down
    // screen. Area of the whole polygon: the fan's first triangle has the polygon's winding.
    var area = cross2(out.vb.xy - out.va.xy, out.vc.xy - out.va.xy);
    if n == 4u {
        area += cross2(out.vc.xy - out.va.xy, out.vd.xy - out.va.xy);
    }
    if area == 0.0 || (cull_back && area > 0.0) {
        return out;
    }
    out.count = n;
    out.flip = area < 0.0;
    return out;
}

// One triangle ready to rasterise: three edge equations (A, B, C), E(p) = A p.x + B p.y + C,
// oriented so that inside is positive (edge i is opposite vertex i), which of them own the
// pixel centres exactly on them, and the depth plane.
struct TriSetup {
    edge_a: vec3<f32>,
    edge_b: vec3<f32>,
    edge_c: vec3<f32>,
    own: vec3<bool>,
    depth: vec3<f32>,
}

// A polygon ready to rasterise: one triangle, or two for a quad (the fan 0-1-2, 0-2-3).
struct Setup {
    tris: u32,
    first: TriSetup,
    second: TriSetup,
}

// Plane equation of the directed edge a -> b, oriented by `flip`; w is 1 when the edge owns
// the pixel centres on it.
fn edge_equation(a: vec2<f32>, b: vec2<f32>, flip: bool) -> vec4<f32> {
    let swap = a.x > b.x || (a.x == b.x && a.y > b.y);
    let s = select(a, b, swap);
    let e = select(b, a, swap);
    let coef_a = s.y - e.y;
    let coef_b = e.x - s.x;
    let coef_c = -(coef_a * s.x + coef_b * s.y);
    let sign = select(1.0, -1.0, swap != flip);
    // Reversing an edge reverses its direction: exactly one of two neighbours owns it.
    let d = select(b - a, a - b, flip);
    let owns = d.y > 0.0 || (d.y == 0.0 && d.x < 0.0);
    return vec4<f32>(vec3<f32>(coef_a, coef_b, coef_c) * sign, select(0.0, 1.0, owns));
}

fn tri_setup(v0: vec3<f32>, v1: vec3<f32>, v2: vec3<f32>, flip: bool) -> TriSetup {
    var t: TriSetup;
    let q0 = edge_equation(v1.xy, v2.xy, flip);
    let q1 = edge_equation(v2.xy, v0.xy, flip);
    let q2 = edge_equation(v0.xy, v1.xy, flip);
    t.edge_a = q0.xyz;
    t.edge_b = q1.xyz;
    t.edge_c = q2.xyz;
    t.own = vec3<bool>(q0.w > 0.0, q1.w > 0.0, q2.w > 0.0);
    // The three edge functions sum to twice the area everywhere; their weighted sum
    // interpolates the vertex depths.
    let area = q0.z + q1.z + q2.z;
    t.depth = select(vec3<f32>(0.0), (t.edge_a * v0.z + t.edge_b * v1.z + t.edge_c * v2.z) / area, area > 0.0);
    return t;
}

fn poly_setup(poly: Poly) -> Setup {
    var s: Setup;
    s.tris = select(1u, 2u, poly.count == 4u);
    s.first = tri_setup(poly.va, poly.vb, poly.vc, poly.flip);
    if s.tris == 2u {
        s.second = tri_setup(poly.va, poly.vc, poly.vd, poly.flip);
    }
    return s;
}

// NDC depth of triangle t at pixel centre p (homogeneous h = (p, 1)), or -1 outside.
fn tri_depth(t: TriSetup, h: vec3<f32>) -> f32 {
    let e = vec3<f32>(dot(t.edge_a, h), dot(t.edge_b, h), dot(t.edge_c, h));
    let inside = e > vec3<f32>(0.0) | (e == vec3<f32>(0.0) & t.own);
    return select(-1.0, dot(t.depth, h), all(inside));
}

// NDC depth at pixel centre p, or -1 when p is outside.
fn setup_depth(s: Setup, p: vec2<f32>) -> f32 {
    let h = vec3<f32>(p, 1.0);
    let d = tri_depth(s.first, h);
    if d >= 0.0 || s.tris == 1u {
        return d;
    }
    return tri_depth(s.second, h);
}

// Whether triangle t may cover a pixel centre of the inclusive rectangle [p0, p1] of centres:
// false when some edge is negative at every one of them.
fn tri_touches(t: TriSetup, p0: vec2<f32>, p1: vec2<f32>) -> bool {
    // Each edge at the rectangle's corner where it is largest.
    let c0 = vec3<f32>(select(p0.x, p1.x, t.edge_a.x > 0.0), select(p0.y, p1.y, t.edge_a.y > 0.0), 1.0);
    let c1 = vec3<f32>(select(p0.x, p1.x, t.edge_b.x > 0.0), select(p0.y, p1.y, t.edge_b.y > 0.0), 1.0);
    let c2 = vec3<f32>(select(p0.x, p1.x, t.edge_c.x > 0.0), select(p0.y, p1.y, t.edge_c.y > 0.0), 1.0);
    return dot(t.edge_a, c0) >= 0.0 && dot(t.edge_b, c1) >= 0.0 && dot(t.edge_c, c2) >= 0.0;
}

// The tile pass draws a tile as 4x4 blocks of 8x8 pixels by 64 threads, one pixel a thread,
// and only the blocks the triangle touches: most queued triangles cover a small part of their
// tiles, and testing every pixel of them cost more than drawing.
const BLOCK: u32 = 8u;
const BLOCKS_PER_SIDE: u32 = 4u;

// Top-left pixel of block `b` (0 to 15, row by row) of the tile at pixel `origin`.
fn block_corner(origin: vec2<i32>, b: u32) -> vec2<i32> {
    return origin + vec2<i32>(vec2<u32>(b % BLOCKS_PER_SIDE, b / BLOCKS_PER_SIDE) * BLOCK);
}

// Whether triangle t may cover a pixel centre of the block at `corner` within `rect`.
fn block_touched(t: TriSetup, rect: PixelRect, corner: vec2<i32>) -> bool {
    let lo = max(corner, rect.lo);
    let hi = min(corner + i32(BLOCK) - 1, rect.hi);
    return all(lo <= hi) && tri_touches(t, vec2<f32>(lo) + 0.5, vec2<f32>(hi) + 0.5);
}

// Draws this thread's pixel (lane % 8, lane / 8) of the block at `corner`.
fn raster_block_pixel(t: TriSetup, rect: PixelRect, corner: vec2<i32>, lane: u32, view: u32, id: u32) {
    let px = corner + vec2<i32>(vec2<u32>(lane % BLOCK, lane / BLOCK));
    if all(px >= rect.lo) && all(px <= rect.hi) {
        let d = tri_depth(t, vec3<f32>(vec2<f32>(px) + 0.5, 1.0));
        if d > 0.0 {
            write_pixel(view, px, d, id);
        }
    }
}

// Every pixel of `tile` within `rect` that triangle t covers, drawn by `threads` threads. For
// triangles that cover whole tiles (the large pass): there the block tests only add work.
fn raster_tile_tri(t: TriSetup, rect: PixelRect, tile: vec2<u32>, view: u32, id: u32, lane: u32, threads: u32) {
    let origin = vec2<i32>(tile * TILE_SIZE);
    for (var i = lane; i < TILE_SIZE * TILE_SIZE; i += threads) {
        let px = origin + vec2<i32>(vec2<u32>(i % TILE_SIZE, i / TILE_SIZE));
        if any(px < rect.lo) || any(px > rect.hi) {
            continue;
        }
        let d = tri_depth(t, vec3<f32>(vec2<f32>(px) + 0.5, 1.0));
        if d > 0.0 {
            write_pixel(view, px, d, id);
        }
    }
}

// Whether triangle t may cover a pixel centre of `tile` within `rect`.
fn tile_touched_tri(t: TriSetup, rect: PixelRect, tile: vec2<u32>) -> bool {
    let lo = max(vec2<i32>(tile * TILE_SIZE), rect.lo);
    let hi = min(vec2<i32>(tile * TILE_SIZE + TILE_SIZE - 1u), rect.hi);
    return tri_touches(t, vec2<f32>(lo) + 0.5, vec2<f32>(hi) + 0.5);
}

fn pack_pixel(p: vec2<i32>) -> u32 {
    return u32(p.x) | (u32(p.y) << 16u);
}

fn unpack_pixel(bits: u32) -> vec2<i32> {
    return vec2<i32>(vec2<u32>(bits & 0xffffu, bits >> 16u));
}

fn store_record(slot: u32, t: TriSetup, id: u32, view: u32, rect: PixelRect) {
    let own = select(0u, 1u, t.own.x) | select(0u, 2u, t.own.y) | select(0u, 4u, t.own.z);
    records[slot] = TriRecord(
        vec4<u32>(bitcast<vec3<u32>>(t.edge_a), id),
        vec4<u32>(bitcast<vec3<u32>>(t.edge_b), own | (view << 8u)),
        vec4<u32>(bitcast<vec3<u32>>(t.edge_c), pack_pixel(rect.lo)),
        vec4<u32>(bitcast<vec3<u32>>(t.depth), pack_pixel(rect.hi)),
    );
}

struct Record {
    tri: TriSetup,
    id: u32,
    view: u32,
    rect: PixelRect,
}

fn load_record(slot: u32) -> Record {
    let r = records[slot];
    var t: TriSetup;
    t.edge_a = bitcast<vec3<f32>>(r.edge_a.xyz);
    t.edge_b = bitcast<vec3<f32>>(r.edge_b.xyz);
    t.edge_c = bitcast<vec3<f32>>(r.edge_c.xyz);
    t.depth = bitcast<vec3<f32>>(r.depth.xyz);
    let bits = r.edge_b.w;
    t.own = vec3<bool>((bits & 1u) != 0u, (bits & 2u) != 0u, (bits & 4u) != 0u);
    return Record(t, r.edge_a.w, (bits >> 8u) & 0xffu, PixelRect(unpack_pixel(r.edge_c.w), unpack_pixel(r.depth.w)));
}

fn poly_rect(poly: Poly, window: PixelRect) -> PixelRect {
    var lo = min(min(poly.va.xy, poly.vb.xy), poly.vc.xy);
    var hi = max(max(poly.va.xy, poly.vb.xy), poly.vc.xy);
    if poly.count == 4u {
        lo = min(lo, poly.vd.xy);
        hi = max(hi, poly.vd.xy);
    }
    // Pixel i has its centre at i + 0.5.
    let w_lo = vec2<f32>(window.lo);
    let w_hi = vec2<f32>(window.hi);
    let first = clamp(ceil(lo - 0.5), w_lo, w_hi + 1.0);
    let last = clamp(floor(hi - 0.5), w_lo - 1.0, w_hi);
    // Clamped again as integers: a NaN corner (from a view matrix given through the library)
    // survives the float clamp, and the kernels run without index checks.
    return PixelRect(clamp(vec2<i32>(first), window.lo, window.hi + 1), clamp(vec2<i32>(last), window.lo - 1, window.hi));
}

// The pixels view `view` draws, inclusive.
fn view_window(view: u32) -> PixelRect {
    let v = params.views[view];
    return PixelRect(unpack_pixel(v.z), unpack_pixel(v.w) - 1);
}

// A triangle of the scene in world space, fetched once for all the views that draw it.
struct WorldTri {
    valid: bool,
    cull_back: bool,
    // Vertices, homogeneous.
    va: vec4<f32>,
    vb: vec4<f32>,
    vc: vec4<f32>,
}

// The triangle of visibility id `id`; invalid past its chunk's last triangle.
fn world_tri(id: u32) -> WorldTri {
    var t: WorldTri;
    let chunk = chunks[id / CHUNK_TRIANGLES];
    let lane = id % CHUNK_TRIANGLES;
    t.valid = lane < chunk.count;
    if !t.valid {
        return t;
    }
    let inst = instances[chunk.instance];
    let tri = chunk.first_triangle + lane;
    t.va = inst.model * vec4<f32>(positions[indices[tri * 3u]].xyz, 1.0);
    t.vb = inst.model * vec4<f32>(positions[indices[tri * 3u + 1u]].xyz, 1.0);
    t.vc = inst.model * vec4<f32>(positions[indices[tri * 3u + 2u]].xyz, 1.0);
    t.cull_back = params.config.x != 0u && (inst.flags & INSTANCE_DOUBLE_SIDED) == 0u;
    return t;
}

// The polygon of `t` in view `view`.
fn view_poly(t: WorldTri, view: u32) -> Poly {
    let m = params.view_proj[view];
    return triangle_poly(m * t.va, m * t.vb, m * t.vc, params.viewport.xy, t.cull_back);
}

// Which planes of view `view`'s frustum corner `corner` (0 to 7) of a chunk's bounds is
// outside of, as bits: the sides narrowed to the view's window (left, right, bottom, top),
// then the near plane. A chunk whose eight corners share a bit is unseen.
fn chunk_corner_outside(chunk: Chunk, view: u32, corner: u32) -> u32 {
    // The window's edges in NDC (y up); exactly -1 and 1 for a whole view.
    let win = view_window(view);
    let ndc_lo = vec2<f32>(win.lo) * params.viewport.zw * 2.0 - 1.0;
    let ndc_hi = vec2<f32>(win.hi + 1) * params.viewport.zw * 2.0 - 1.0;
    let p = select(chunk.bounds_lo.xyz, chunk.bounds_hi.xyz, vec3<bool>((corner & 1u) != 0u, (corner & 2u) != 0u, (corner & 4u) != 0u));
    let c = params.view_proj[view] * (instances[chunk.instance].model * vec4<f32>(p, 1.0));
    return select(0u, 1u, c.x < ndc_lo.x * c.w)
        | select(0u, 2u, c.x > ndc_hi.x * c.w)
        | select(0u, 4u, c.y < -ndc_hi.y * c.w)
        | select(0u, 8u, c.y > -ndc_lo.y * c.w)
        | select(0u, 16u, c.w - c.z < 0.0);
}

// Index in `target_texels` of pixel `px` of view `view`.
fn texel_index(view: u32, px: vec2<i32>) -> u32 {
    let size = vec2<u32>(params.viewport.xy);
    let v = params.views[view];
#ifdef DEPTH_ONLY
    let at = (vec2<u32>(px) + vec2<u32>(unpack_pixel(v.y))) & (size - 1u);
#else
    let at = vec2<u32>(px);
#endif
    return v.x * size.x * size.y + at.y * size.x + at.x;
}

// Keeps the nearest fragment of a texel. Nothing waits for the atomic's result, so a thread
// issues it and goes on; a plain load first, to let occluded fragments skip the atomic, stalls
// the thread on the load instead, and was slower in the tile and large passes (H200, 4K:
// 15-20 %; BENCHMARKS.md, session 7).
fn write_pixel(view: u32, px: vec2<i32>, depth: f32, id: u32) {
    if depth > 0.0 {
        atomicMax(&target_texels[texel_index(view, px)], texel_value(depth, id));
    }
}

// write_pixel with that plain load first, for the small triangles the triangle pass draws
// thread by thread into the visibility buffer: there many fragments land on the same texels
// (small objects behind one another), and skipping their atomics pays. Shadow maps draw
// without it, which was faster there too.
fn write_pixel_tested(view: u32, px: vec2<i32>, depth: f32, id: u32) {
#ifdef DEPTH_ONLY
    write_pixel(view, px, depth, id);
#else
    if depth > 0.0 {
        let i = texel_index(view, px);
        let value = texel_value(depth, id);
        if value > atomicLoad(&target_texels[i]) {
            atomicMax(&target_texels[i], value);
        }
    }
#endif
}

#ifdef DEPTH_ONLY
fn texel_value(depth: f32, id: u32) -> u32 {
    return bitcast<u32>(depth);
}
#else
fn texel_value(depth: f32, id: u32) -> u64 {
    return (u64(bitcast<u32>(depth)) << 32u) | u64(id);
}
#endif

#ifdef ALPHA_TEST
// The alpha test of one triangle in one view (glTF MASK: a fragment is kept where the base
// colour alpha is at least the material's cut-off).
//
// Barycentrics at a pixel come from the triangle's clip-space vertices c_i, not from the
// records (whose edges are those of the clipped polygon): a point with barycentrics b has
// clip position sum(b_i c_i), so the pixel's homogeneous NDC n = (x, y, 1) is proportional to
// A b, where A's columns are the c_i's x, y, w. Hence b is proportional to A^-1 n, whose rows
// are cross products of A's columns: three dot products a pixel, then a division by their sum
// (which makes them sum to 1 and removes A's determinant). Perspective-correct, as the
// resolve's ray intersection, and exact for the orthographic shadow views too (w = 1).
struct AlphaTri {
    plane_a: vec3<f32>,
    plane_b: vec3<f32>,
    plane_c: vec3<f32>,
    uv_a: vec2<f32>,
    uv_b: vec2<f32>,
    uv_c: vec2<f32>,
    // Per vertex: material alpha times vertex colour alpha.
    alpha: vec3<f32>,
    // Base colour texture layer (NO_TEXTURE: none) and its wrap bits.
    layer: u32,
    wrap: u32,
    cutoff: f32,
}

fn alpha_tri(id: u32, view: u32) -> AlphaTri {
    var a: AlphaTri;
    let chunk = chunks[id / CHUNK_TRIANGLES];
    let tri = chunk.first_triangle + id % CHUNK_TRIANGLES;
    let i = vec3<u32>(indices[tri * 3u], indices[tri * 3u + 1u], indices[tri * 3u + 2u]);
    let m = params.view_proj[view] * instances[chunk.instance].model;
    let c0 = (m * vec4<f32>(positions[i.x].xyz, 1.0)).xyw;
    let c1 = (m * vec4<f32>(positions[i.y].xyz, 1.0)).xyw;
    let c2 = (m * vec4<f32>(positions[i.z].xyz, 1.0)).xyw;
    a.plane_a = cross(c1, c2);
    a.plane_b = cross(c2, c0);
    a.plane_c = cross(c0, c1);
    let mat = materials[instances[chunk.instance].material];
    let v0 = attributes[i.x];
    let v1 = attributes[i.y];
    let v2 = attributes[i.z];
    a.uv_a = v0.uv;
    a.uv_b = v1.uv;
    a.uv_c = v2.uv;
    // Vertex colour alpha: the high half of the second word (unorm16x4, RGBA).
    a.alpha = vec3<f32>(unpack2x16unorm(v0.color.y).y, unpack2x16unorm(v1.color.y).y, unpack2x16unorm(v2.color.y).y) * mat.base_color.a;
    a.layer = mat.textures.x;
    a.wrap = mat.more_textures.y & 15u;
    a.cutoff = mat.extra.z;
    return a;
}

// Whether the fragment at pixel `px` passes the alpha test. The texture is read at mip 0:
// the cut-out's edges are then where the full-resolution texture puts them at any distance
// (coarser mips average alpha, and thin cut-outs would shrink or vanish with distance), at the
// price of texture cache misses on distant cut-outs.
fn alpha_covers(a: AlphaTri, px: vec2<i32>) -> bool {
    let p = (vec2<f32>(px) + 0.5) * params.viewport.zw;
    let n = vec3<f32>(p.x * 2.0 - 1.0, 1.0 - p.y * 2.0, 1.0);
    let b = vec3<f32>(dot(a.plane_a, n), dot(a.plane_b, n), dot(a.plane_c, n));
    let w = b / (b.x + b.y + b.z);
    var alpha = dot(a.alpha, w);
    if a.layer != NO_TEXTURE {
        let uv = a.uv_a * w.x + a.uv_b * w.y + a.uv_c * w.z;
        alpha *= textureSampleLevel(color_textures, texture_sampler, wrap_uv(uv, a.wrap, textureDimensions(color_textures)), a.layer, 0.0).a;
    }
    // NaN (a pixel centre on a degenerate triangle's edge) fails: no fragment.
    return alpha >= a.cutoff;
}

// raster_block_pixel with the alpha test.
fn raster_block_pixel_alpha(t: TriSetup, rect: PixelRect, corner: vec2<i32>, lane: u32, view: u32, id: u32, a: AlphaTri) {
    let px = corner + vec2<i32>(vec2<u32>(lane % BLOCK, lane / BLOCK));
    if all(px >= rect.lo) && all(px <= rect.hi) {
        let d = tri_depth(t, vec3<f32>(vec2<f32>(px) + 0.5, 1.0));
        if d > 0.0 && alpha_covers(a, px) {
            write_pixel(view, px, d, id);
        }
    }
}
#endif
