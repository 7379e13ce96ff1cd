#define_import_path hikari::tile_bounds

// Bounds of the surfaces a 16x16 tile of pixels sees, for culling lights per tile (the deferred
// lighting, area_lights.shade). Reduced as a tree in workgroup memory: contended shared
// atomics on six addresses cost more than the lighting they save.

const TILE_BOUNDS_SIZE: u32 = 16u;
// Larger than any scene coordinate: the bounds of a pixel on the sky, which no light reaches.
const TILE_BOUNDS_FAR: f32 = 3.0e38;

var<workgroup> tile_bounds_lo: array<vec3<f32>, 256>;
var<workgroup> tile_bounds_hi: array<vec3<f32>, 256>;

struct TileBounds {
    lo: vec3<f32>,
    hi: vec3<f32>,
}

// The box around every invocation's [lo, hi] (a sky pixel passes lo = FAR, hi = -FAR); empty
// (lo.x > hi.x) when the tile sees only sky. Every invocation of the 16x16 workgroup must call
// it (barriers), `lid` its local_invocation_index.
fn tile_bounds(lid: u32, lo: vec3<f32>, hi: vec3<f32>) -> TileBounds {
    tile_bounds_lo[lid] = lo;
    tile_bounds_hi[lid] = hi;
    workgroupBarrier();
    for (var stride = TILE_BOUNDS_SIZE * TILE_BOUNDS_SIZE / 2u; stride > 0u; stride >>= 1u) {
        if lid < stride {
            tile_bounds_lo[lid] = min(tile_bounds_lo[lid], tile_bounds_lo[lid + stride]);
            tile_bounds_hi[lid] = max(tile_bounds_hi[lid], tile_bounds_hi[lid + stride]);
        }
        workgroupBarrier();
    }
    return TileBounds(tile_bounds_lo[0], tile_bounds_hi[0]);
}

// Squared distance (m^2) from `p` to the nearest point of the box.
fn tile_bounds_distance2(b: TileBounds, p: vec3<f32>) -> f32 {
    let d = clamp(p, b.lo, b.hi) - p;
    return dot(d, d);
}
