// The rays the pre-trace left (the queue), traced through the scene's BVH with cut-outs, up
// to the near field's length; a hit takes its instance's albedo and records the instance and
// its triangle's geometric normal (in the pose its BLAS was last refitted to, turned into
// world space by the instance's normal matrix). Output: their hit words.

#import hikari::view::{View, world_from_depth}
#import hikari::octahedral::{oct_decode, oct_encode}
#import hikari::bvh::{Ray, Hit, bvh_begin, bvh_step, bvh_result, bvh_is_hit}
#import hikari::ray_traced_gi::{RtGiParams, rtgi_ray_direction, rtgi_ray_origin, rtgi_pack_hit, rtgi_pack_miss, rtgi_pack_normal, rtgi_unpack_normal, RTGI_NO_NORMAL}

@group(0) @binding(0) var<uniform> view: View;
@group(0) @binding(1) var<uniform> params: RtGiParams;
@group(0) @binding(2) var depth: texture_2d<f32>;
@group(0) @binding(3) var gbuffer_normal: texture_2d<f32>;
@group(0) @binding(4) var<storage, read> queue: array<u32>;
@group(0) @binding(5) var<storage, read_write> hits: array<u32>;
@group(0) @binding(6) var<storage, read_write> hit_instances: array<u32>;
// Per scene instance: albedo for hits, then emission (reference::instance_table).
@group(0) @binding(7) var<storage, read> instance_table: array<vec4<f32>>;
@group(0) @binding(8) var<storage, read_write> hit_normals: array<u32>;
// Per scene instance, three vec4: the rows of its normal matrix (xyz); w of the first the
// index of its mesh's first triangle in `triangle_normals`, of the second its triangle count
// (bitcast). Per mesh triangle: its geometric normal in object space (rtgi_pack_normal).
// `RtGiScene::normal_tables`.
@group(0) @binding(9) var<storage, read> instance_normals: array<vec4<f32>>;
@group(0) @binding(10) var<storage, read> triangle_normals: array<u32>;

// World-space geometric normal of triangle `primitive` of scene instance `instance` (unit, as
// wound in the mesh), packed; RTGI_NO_NORMAL where the tables do not hold it.
fn hit_normal(instance: u32, primitive: u32) -> u32 {
    if 3u * instance + 2u >= arrayLength(&instance_normals) {
        return RTGI_NO_NORMAL;
    }
    let r0 = instance_normals[3u * instance];
    let r1 = instance_normals[3u * instance + 1u];
    let r2 = instance_normals[3u * instance + 2u];
    let first = bitcast<u32>(r0.w);
    if primitive >= bitcast<u32>(r1.w) || first + primitive >= arrayLength(&triangle_normals) {
        return RTGI_NO_NORMAL;
    }
    let w = triangle_normals[first + primitive];
    if w == RTGI_NO_NORMAL {
        return RTGI_NO_NORMAL;
    }
    let no = oct_decode(rtgi_unpack_normal(w));
    let nw = vec3<f32>(dot(r0.xyz, no), dot(r1.xyz, no), dot(r2.xyz, no));
    if !(dot(nw, nw) > 0.0) {
        return RTGI_NO_NORMAL;
    }
    return rtgi_pack_normal(oct_encode(normalize(nw)));
}

// Rays an invocation traces, one after the other (persistent threads, Aila and Laine 2009):
// each workgroup owns a chunk of RAYS_PER_THREAD * 64 queue slots, and an invocation whose ray
// is done takes the chunk's next one instead of idling until the slowest ray of its warp ends
// (incoherent rays differ in length by orders of magnitude). hikari-bvh's trace kernel
// measured this as the fastest way to trace incoherent rays (BENCHMARKS.md).
const RAYS_PER_THREAD: u32 = 8u;
const WORKGROUP: u32 = 64u;

var<workgroup> next_slot: atomic<u32>;

// Starts queue slot k's ray; returns its pixel index.
fn begin_ray(k: u32) -> u32 {
    let i = queue[k + 1u];
    let size = textureDimensions(depth);
    let pixel = vec2<u32>(i % size.x, i / size.x);
    let d = textureLoad(depth, pixel, 0).r;
    let n = oct_decode(textureLoad(gbuffer_normal, pixel, 0).xy);
    let world = world_from_depth(view, pixel, d);
    let o = rtgi_ray_origin(world, n, view.position.xyz);
    let dir = rtgi_ray_direction(pixel, params.config.x, n).xyz;
    bvh_begin(Ray(o, 0.0, dir, params.distances.x));
    return i;
}

fn finish_ray(i: u32, hit: Hit) {
    var word = rtgi_pack_miss();
    var instance = 0xffffffffu;
    var normal = RTGI_NO_NORMAL;
    if bvh_is_hit(hit) {
        normal = hit_normal(hit.instance, hit.primitive);
        var albedo = vec3<f32>(0.5);
        if 2u * hit.instance < arrayLength(&instance_table) {
            albedo = instance_table[2u * hit.instance].rgb;
            instance = hit.instance;
        }
        word = rtgi_pack_hit(hit.t, albedo);
    }
    hits[i] = word;
    hit_instances[i] = instance;
    hit_normals[i] = normal;
}

@compute @workgroup_size(64, 1, 1)
fn main(
    @builtin(workgroup_id) wid: vec3<u32>,
    @builtin(num_workgroups) nwg: vec3<u32>,
    @builtin(local_invocation_index) lid: u32,
) {
    let chunk = WORKGROUP * RAYS_PER_THREAD;
    let start = (wid.y * nwg.x + wid.x) * chunk;
    let end = min(start + chunk, min(queue[0], arrayLength(&queue) - 1u));
    if lid == 0u {
        atomicStore(&next_slot, WORKGROUP);
    }
    workgroupBarrier();
    var k = start + lid;
    if k >= end {
        return;
    }
    var i = begin_ray(k);
    loop {
        if bvh_step(false) {
            finish_ray(i, bvh_result());
            k = start + atomicAdd(&next_slot, 1u);
            if k >= end {
                break;
            }
            i = begin_ray(k);
        }
    }
}
