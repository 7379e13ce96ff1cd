// Ray tracing as a library user sees it: rays in, hits out, one invocation per ray
// (`hikari-render/src/passes/bvh_trace.rs`, `hikari bench rays`). The BVH buffers are
// @binding(0..4), declared by hikari::bvh.

#import hikari::bvh::{Ray, Hit, bvh_closest_hit, bvh_any_hit}

// hikari-bvh's TriangleRecord, for the layout test only: the kernel reads the records as
// vec4s (hikari::bvh cannot declare it, see there).
struct TriangleRecord {
    v0: vec3<f32>,
    primitive: u32,
    v1: vec3<f32>,
    _pad1: u32,
    v2: vec3<f32>,
    _pad2: u32,
}

struct TraceParams {
    count: u32,
    pad0: u32,
    pad1: u32,
    pad2: u32,
}

@group(0) @binding(4) var<storage, read> rays: array<Ray>;
@group(0) @binding(5) var<storage, read_write> hits: array<Hit>;
@group(0) @binding(6) var<uniform> params: TraceParams;

// Dispatches are 2D once the rays outnumber one dimension's workgroup limit; the ray index is
// the linear workgroup index times the workgroup size plus the local index.
fn ray_index(wid: vec3<u32>, nwg: vec3<u32>, lid: u32) -> u32 {
    return (wid.y * nwg.x + wid.x) * 64u + lid;
}

@compute @workgroup_size(64, 1, 1)
fn closest_hit(
    @builtin(workgroup_id) wid: vec3<u32>,
    @builtin(num_workgroups) nwg: vec3<u32>,
    @builtin(local_invocation_index) lid: u32,
) {
    let i = ray_index(wid, nwg, lid);
    if i >= params.count {
        return;
    }
    hits[i] = bvh_closest_hit(rays[i]);
}

@compute @workgroup_size(64, 1, 1)
fn any_hit(
    @builtin(workgroup_id) wid: vec3<u32>,
    @builtin(num_workgroups) nwg: vec3<u32>,
    @builtin(local_invocation_index) lid: u32,
) {
    let i = ray_index(wid, nwg, lid);
    if i >= params.count {
        return;
    }
    hits[i] = bvh_any_hit(rays[i]);
}
