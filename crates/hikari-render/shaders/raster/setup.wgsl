#define_import_path hikari::raster::setup

// Triangle setup of hikari's compute rasteriser, shared by the triangle and tile passes.
//
// Watertightness: a pixel centre is inside when every edge function is positive, or zero on a
// top-left edge. Each edge function is evaluated with its two end points in a canonical order
// (lexicographic in x, then y) and negated as needed, so the two triangles sharing an edge get
// bit-exact opposite values and every pixel centre on the edge belongs to exactly one of them.
// Near-plane clipping interpolates from the inside end point, so neighbours clip a shared edge
// to the same point.

#import hikari::scene_gpu::{InstanceGpu, Chunk, CHUNK_TRIANGLES, INSTANCE_DOUBLE_SIDED}

@group(0) @binding(0) var<uniform> params: RasterParams;
@group(0) @binding(1) var<storage, read> positions: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read> indices: array<u32>;
@group(0) @binding(3) var<storage, read> instances: array<InstanceGpu>;
@group(0) @binding(4) var<storage, read> chunks: array<Chunk>;
#ifdef DEPTH_ONLY
// One u32 a texel per view: the bits of the NDC depth, whose order is the order of the depths.
@group(0) @binding(5) var<storage, read_write> target_texels: array<atomic<u32>>;
#else
// One u64 a pixel: NDC depth bits above the visibility id, so atomicMax keeps the nearest.
@group(0) @binding(5) var<storage, read_write> target_texels: array<atomic<u64>>;
#endif
// Tile queue: (visibility id, tile x | tile y << 12 | view << 24).
@group(0) @binding(6) var<storage, read_write> queue: array<vec2<u32>>;
@group(0) @binding(7) var<storage, read_write> queue_count: array<atomic<u32>>;

// The views one dispatch rasterises into (the camera, or up to four shadow cascades).
struct RasterParams {
    view_proj: array<mat4x4<f32>, 4>,
    // width, height, 1 / width, 1 / height of each view's target, in pixels.
    viewport: vec4<f32>,
    // x: 1 to cull back faces of single-sided instances; y: capacity of the tile queue in
    // entries; z: number of views; w: number of chunks.
    config: vec4<u32>,
}

// Up to four screen-space vertices: the triangle, or the quad left after near clipping.
struct Poly {
    count: u32,
    // The winding is clockwise on screen (negative area): edge functions are negated.
    flip: bool,
    xy: array<vec2<f32>, 4>,
    // NDC depth, reverse-Z (1 near, 0 far).
    z: array<f32, 4>,
}

// Pixels (inclusive) a polygon can touch, clamped to the target.
struct PixelRect {
    lo: vec2<i32>,
    hi: vec2<i32>,
}

const TILE_SIZE: u32 = 32u;
// Triangles whose clamped bounding box holds more pixels go to the tile queue.
const SMALL_TRIANGLE_PIXELS: i32 = 96;

// The polygon of triangle `tri` of `chunk` seen through `view_proj`; count 0 when it is culled
// (behind the near plane, outside a side of the frustum, back-facing and single-sided, or of
// zero area).
fn triangle_poly(
    c: array<vec4<f32>, 3>,
    size: vec2<f32>,
    cull_back: bool,
) -> Poly {
    var out: Poly;
    out.count = 0u;
    // Entirely outside one side plane of the frustum.
    let outside_l = c[0].x < -c[0].w && c[1].x < -c[1].w && c[2].x < -c[2].w;
    let outside_r = c[0].x > c[0].w && c[1].x > c[1].w && c[2].x > c[2].w;
    let outside_b = c[0].y < -c[0].w && c[1].y < -c[1].w && c[2].y < -c[2].w;
    let outside_t = c[0].y > c[0].w && c[1].y > c[1].w && c[2].y > c[2].w;
    if outside_l || outside_r || outside_b || outside_t {
        return out;
    }
    // Clip against the near plane z <= w (reverse-Z: NDC depth <= 1).
    var clipped: array<vec4<f32>, 4>;
    var n = 0u;
    for (var i = 0u; i < 3u; i++) {
        let a = c[i];
        let b = c[(i + 1u) % 3u];
        let da = a.w - a.z;
        let db = b.w - b.z;
        if da >= 0.0 {
            clipped[n] = a;
            n++;
        }
        if (da >= 0.0) != (db >= 0.0) {
            if da >= 0.0 {
                clipped[n] = a + (b - a) * (da / (da - db));
            } else {
                clipped[n] = b + (a - b) * (db / (db - da));
            }
            n++;
        }
    }
    if n < 3u {
        return out;
    }
    for (var i = 0u; i < n; i++) {
        let p = clipped[i];
        let inv_w = 1.0 / p.w;
        out.xy[i] = vec2<f32>((p.x * inv_w * 0.5 + 0.5) * size.x, (0.5 - p.y * inv_w * 0.5) * size.y);
        out.z[i] = p.z * inv_w;
    }
    // Front faces are counter-clockwise in NDC, so clockwise (negative area) on the y-down
    // screen. Area of the whole polygon: the fan's first triangle has the polygon's winding.
    let area = edge(out.xy[0], out.xy[1], out.xy[2]) + select(0.0, edge(out.xy[0], out.xy[2], out.xy[3]), n == 4u);
    if area == 0.0 || (cull_back && area > 0.0) {
        return out;
    }
    out.count = n;
    out.flip = area < 0.0;
    return out;
}

// Edge function of the directed edge a -> b at p, evaluated in canonical end point order.
fn edge(a: vec2<f32>, b: vec2<f32>, p: vec2<f32>) -> f32 {
    let swap = a.x > b.x || (a.x == b.x && a.y > b.y);
    let s = select(a, b, swap);
    let e = select(b, a, swap);
    let v = (e.x - s.x) * (p.y - s.y) - (e.y - s.y) * (p.x - s.x);
    return select(v, -v, swap);
}

// Whether a pixel centre exactly on edge a -> b (of a triangle oriented so inside is
// positive) belongs to this triangle. Reversing the edge flips the answer, which is all
// watertightness needs.
fn owns_edge(a: vec2<f32>, b: vec2<f32>) -> bool {
    let d = b - a;
    return d.y > 0.0 || (d.y == 0.0 && d.x < 0.0);
}

fn poly_rect(poly: Poly, size: vec2<f32>) -> PixelRect {
    var lo = min(min(poly.xy[0], poly.xy[1]), poly.xy[2]);
    var hi = max(max(poly.xy[0], poly.xy[1]), poly.xy[2]);
    if poly.count == 4u {
        lo = min(lo, poly.xy[3]);
        hi = max(hi, poly.xy[3]);
    }
    // Pixel i has its centre at i + 0.5.
    let first = clamp(ceil(lo - 0.5), vec2<f32>(0.0), size);
    let last = clamp(floor(hi - 0.5), vec2<f32>(-1.0), size - 1.0);
    return PixelRect(vec2<i32>(first), vec2<i32>(last));
}

// NDC depth of the polygon at pixel centre p, or a negative value when p is outside.
fn poly_depth(poly: Poly, p: vec2<f32>) -> f32 {
    let tris = select(1u, 2u, poly.count == 4u);
    for (var k = 0u; k < tris; k++) {
        let v0 = poly.xy[0];
        let v1 = poly.xy[1u + k];
        let v2 = poly.xy[2u + k];
        var e0 = edge(v1, v2, p);
        var e1 = edge(v2, v0, p);
        var e2 = edge(v0, v1, p);
        // Orient so that inside is positive.
        let flip = poly.flip;
        var a0 = v1;
        var b0 = v2;
        var a1 = v2;
        var b1 = v0;
        var a2 = v0;
        var b2 = v1;
        if flip {
            e0 = -e0;
            e1 = -e1;
            e2 = -e2;
            a0 = v2;
            b0 = v1;
            a1 = v0;
            b1 = v2;
            a2 = v1;
            b2 = v0;
        }
        let in0 = e0 > 0.0 || (e0 == 0.0 && owns_edge(a0, b0));
        let in1 = e1 > 0.0 || (e1 == 0.0 && owns_edge(a1, b1));
        let in2 = e2 > 0.0 || (e2 == 0.0 && owns_edge(a2, b2));
        if in0 && in1 && in2 {
            let w = vec3<f32>(e0, e1, e2) / (e0 + e1 + e2);
            return w.x * poly.z[0] + w.y * poly.z[1u + k] + w.z * poly.z[2u + k];
        }
    }
    return -1.0;
}

// Polygon of visibility id `id` in view `view`, and whether the instance is double-sided.
fn id_poly(id: u32, view: u32) -> Poly {
    var none: Poly;
    none.count = 0u;
    let chunk = chunks[id / CHUNK_TRIANGLES];
    let lane = id % CHUNK_TRIANGLES;
    if lane >= chunk.count {
        return none;
    }
    let inst = instances[chunk.instance];
    let tri = chunk.first_triangle + lane;
    let view_proj = params.view_proj[view];
    var c: array<vec4<f32>, 3>;
    for (var k = 0u; k < 3u; k++) {
        let p = positions[indices[tri * 3u + k]];
        c[k] = view_proj * (inst.model * vec4<f32>(p.xyz, 1.0));
    }
    let cull_back = params.config.x != 0u && (inst.flags & INSTANCE_DOUBLE_SIDED) == 0u;
    return triangle_poly(c, params.viewport.xy, cull_back);
}

fn write_pixel(view: u32, px: vec2<i32>, depth: f32, id: u32) {
    if depth <= 0.0 {
        return;
    }
    let w = u32(params.viewport.x);
    let i = view * w * u32(params.viewport.y) + u32(px.y) * w + u32(px.x);
#ifdef DEPTH_ONLY
    atomicMax(&target_texels[i], bitcast<u32>(depth));
#else
    atomicMax(&target_texels[i], (u64(bitcast<u32>(depth)) << 32u) | u64(id));
#endif
}
