// Ray tracing as a library user sees it: rays in, hits out (`hikari-render/src/bvh_trace.rs`,
// `hikari bench rays`). The BVH's resources are the binding set `bvh`,
// declared by hikari::bvh (BVH buffers, then what the cut-out test reads).
//
// Each workgroup owns a contiguous chunk of TRACE_RAYS_PER_THREAD * TRACE_WORKGROUP rays. With
// more than one ray per invocation, an invocation that finishes a ray starts another one of
// the chunk instead of idling until the slowest ray of its warp is done (persistent threads,
// Aila and Laine 2009, within a chunk): at a fixed stride, or (TRACE_DYNAMIC_FETCH) the next
// free ray, or (TRACE_WARP_REFILL) once enough lanes of its subgroup are free, all of them
// together, with neighbouring rays, so coherent rays stay in step. The rays of one chunk are
// neighbours in the buffer.

#import hikari::bvh::{Ray, Hit, bvh_begin, bvh_step, bvh_result}

// hikari-bvh's TriangleRecord, for the layout test only: the kernel reads the records as
// vec4s (hikari::bvh cannot declare it, see there).
struct TriangleRecord {
    v0: vec3<f32>,
    primitive: u32,
    v1: vec3<f32>,
    flags: u32,
    v2: vec3<f32>,
    _pad2: u32,
}

// hikari-render's cut-out records (scene_bvh.rs), for the layout test only: hikari::bvh reads
// them as vec4s too.
struct AlphaInstance {
    cutoff: f32,
    alpha: f32,
    texture: u32,
    first_triangle: u32,
}

struct AlphaTriangle {
    uv: array<vec2<f32>, 3>,
    alpha: vec2<u32>,
}

struct TraceParams {
    count: u32,
    // 0: rays in buffer order. Otherwise the rays are a row-major image this many pixels wide
    // (count a whole number of rows), traced in 8 x 8 tiles (`RayOrder::Image`).
    image_width: u32,
    pad0: u32,
    pad1: u32,
}

@group(0) @binding(0) var<storage, read> rays: array<Ray>;
@group(0) @binding(1) var<storage, read_write> hits: array<Hit>;
@group(0) @binding(2) var<uniform> params: TraceParams;

// `bvh_trace::TraceConfig` chooses these.
#ifdef TRACE_WORKGROUP_32
const TRACE_WORKGROUP: u32 = 32u;
#else ifdef TRACE_WORKGROUP_128
const TRACE_WORKGROUP: u32 = 128u;
#else
const TRACE_WORKGROUP: u32 = 64u;
#endif

#ifdef TRACE_RAYS_PER_THREAD_1
const TRACE_RAYS_PER_THREAD: u32 = 1u;
#else ifdef TRACE_RAYS_PER_THREAD_4
const TRACE_RAYS_PER_THREAD: u32 = 4u;
#else ifdef TRACE_RAYS_PER_THREAD_16
const TRACE_RAYS_PER_THREAD: u32 = 16u;
#else ifdef TRACE_RAYS_PER_THREAD_32
const TRACE_RAYS_PER_THREAD: u32 = 32u;
#else
const TRACE_RAYS_PER_THREAD: u32 = 8u;
#endif

// Free lanes a subgroup waits for before it starts new rays (TRACE_WARP_REFILL).
#ifdef TRACE_REFILL_MIN_4
const TRACE_REFILL_MIN: u32 = 4u;
#else ifdef TRACE_REFILL_MIN_8
const TRACE_REFILL_MIN: u32 = 8u;
#else ifdef TRACE_REFILL_MIN_24
const TRACE_REFILL_MIN: u32 = 24u;
#else ifdef TRACE_REFILL_MIN_32
const TRACE_REFILL_MIN: u32 = 32u;
#else
const TRACE_REFILL_MIN: u32 = 16u;
#endif

// The ray at position `i` (< params.count) of the tracing order. With an image width, the
// order walks 8-row bands, 8-column tiles inside a band and rows inside a tile (the last band
// and the last tile of each band may be smaller), a one-to-one map of 0..count onto itself:
// neighbouring invocations get neighbouring pixels in 2D, as from 8 x 8 workgroups. Divisors
// are never zero: the width is (record checks it), and i < count leaves at least one row in
// the band and one column in the tile.
fn trace_ray_index(i: u32) -> u32 {
    let w = params.image_width;
    if w == 0u {
        return i;
    }
    let band = i / (8u * w);
    let rows = min(8u, params.count / w - 8u * band);
    let o = i - band * 8u * w;
    let tile = o / (8u * rows);
    let cols = min(8u, w - 8u * tile);
    let k = o - tile * 8u * rows;
    return (8u * band + k / cols) * w + 8u * tile + k % cols;
}

#ifdef TRACE_DYNAMIC_FETCH
// Next ray of the chunk, relative to its start: taken by whichever invocation is free first.
var<workgroup> trace_next: atomic<u32>;
#else ifdef TRACE_WARP_REFILL
var<workgroup> trace_next: atomic<u32>;
#endif

#ifdef TRACE_WARP_REFILL
fn trace_count(ballot: vec4<u32>) -> u32 {
    return countOneBits(ballot.x) + countOneBits(ballot.y) + countOneBits(ballot.z) + countOneBits(ballot.w);
}

fn trace_rays(wid: vec3<u32>, nwg: vec3<u32>, lid: u32, stop_at_first: bool) {
    let chunk = TRACE_WORKGROUP * TRACE_RAYS_PER_THREAD;
    let start = (wid.y * nwg.x + wid.x) * chunk;
    let end = min(start + chunk, params.count);
    if lid == 0u {
        atomicStore(&trace_next, 0u);
    }
    workgroupBarrier();
    var ray = 0u;
    var tracing = false;
    loop {
        // Only a heuristic: if the lanes here are not the ones counted, rays still go to
        // exactly one lane each, as the reservation below counts the lanes that take part.
        let free_lanes = trace_count(subgroupBallot(!tracing));
        let looping = trace_count(subgroupBallot(true));
        if !tracing && (free_lanes >= TRACE_REFILL_MIN || free_lanes == looping) {
            let rank = subgroupExclusiveAdd(1u);
            let taking = subgroupAdd(1u);
            var base = 0u;
            if rank == 0u {
                base = atomicAdd(&trace_next, taking);
            }
            let i = start + subgroupBroadcastFirst(base) + rank;
            if i >= end {
                break;
            }
            ray = trace_ray_index(i);
            bvh_begin(rays[ray]);
            tracing = true;
        }
        if tracing {
            if bvh_step(stop_at_first) {
                hits[ray] = bvh_result();
                tracing = false;
            }
        }
    }
}
#else
fn trace_rays(wid: vec3<u32>, nwg: vec3<u32>, lid: u32, stop_at_first: bool) {
    let chunk = TRACE_WORKGROUP * TRACE_RAYS_PER_THREAD;
    let start = (wid.y * nwg.x + wid.x) * chunk;
    let end = min(start + chunk, params.count);
#ifdef TRACE_DYNAMIC_FETCH
    if lid == 0u {
        atomicStore(&trace_next, TRACE_WORKGROUP);
    }
    workgroupBarrier();
#endif
    var i = start + lid;
    if i >= end {
        return;
    }
    var ray = trace_ray_index(i);
    bvh_begin(rays[ray]);
    loop {
        if bvh_step(stop_at_first) {
            hits[ray] = bvh_result();
#ifdef TRACE_DYNAMIC_FETCH
            i = start + atomicAdd(&trace_next, 1u);
#else
            i += TRACE_WORKGROUP;
#endif
            if i >= end {
                break;
            }
            ray = trace_ray_index(i);
            bvh_begin(rays[ray]);
        }
    }
}
#endif

@compute @workgroup_size(TRACE_WORKGROUP, 1, 1)
fn closest_hit(
    @builtin(workgroup_id) wid: vec3<u32>,
    @builtin(num_workgroups) nwg: vec3<u32>,
    @builtin(local_invocation_index) lid: u32,
) {
    trace_rays(wid, nwg, lid, false);
}

@compute @workgroup_size(TRACE_WORKGROUP, 1, 1)
fn any_hit(
    @builtin(workgroup_id) wid: vec3<u32>,
    @builtin(num_workgroups) nwg: vec3<u32>,
    @builtin(local_invocation_index) lid: u32,
) {
    trace_rays(wid, nwg, lid, true);
}
