// The rays the pre-trace left (the queue), traced through the scene's BVH with cut-outs, up
// to the near field's length; a hit takes its instance's albedo and records the instance. Output: their hit words.
// Invocations past the queue's count return at once; the queue keeps the live ones together.

#import hikari::view::{View, world_from_depth}
#import hikari::octahedral::oct_decode
#import hikari::bvh::{Ray, bvh_closest_hit, bvh_is_hit}
#import hikari::ray_traced_gi::{RtGiParams, rtgi_ray_direction, rtgi_ray_origin, rtgi_pack_hit, rtgi_pack_miss}

@group(0) @binding(0) var<uniform> view: View;
@group(0) @binding(1) var<uniform> params: RtGiParams;
@group(0) @binding(2) var depth: texture_2d<f32>;
@group(0) @binding(3) var gbuffer_normal: texture_2d<f32>;
@group(0) @binding(4) var<storage, read> queue: array<u32>;
@group(0) @binding(5) var<storage, read_write> hits: array<u32>;
@group(0) @binding(6) var<storage, read_write> hit_instances: array<u32>;
// Per scene instance: albedo for hits, then emission (reference::instance_table).
@group(0) @binding(7) var<storage, read> instance_table: array<vec4<f32>>;

@compute @workgroup_size(64, 1, 1)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let k = gid.x + gid.y * nwg.x * 64u;
    if k >= queue[0] || k + 1u >= arrayLength(&queue) {
        return;
    }
    let i = queue[k + 1u];
    let size = textureDimensions(depth);
    let pixel = vec2<u32>(i % size.x, i / size.x);
    let d = textureLoad(depth, pixel, 0).r;
    let n = oct_decode(textureLoad(gbuffer_normal, pixel, 0).xy);
    let world = world_from_depth(view, pixel, d);
    let o = rtgi_ray_origin(world, n, view.position.xyz);
    let dir = rtgi_ray_direction(pixel, params.config.x, n).xyz;
    let hit = bvh_closest_hit(Ray(o, 0.0, dir, params.distances.x));
    var word = rtgi_pack_miss();
    var instance = 0xffffffffu;
    if bvh_is_hit(hit) {
        var albedo = vec3<f32>(0.5);
        if 2u * hit.instance < arrayLength(&instance_table) {
            albedo = instance_table[2u * hit.instance].rgb;
            instance = hit.instance;
        }
        word = rtgi_pack_hit(hit.t, albedo);
    }
    hits[i] = word;
    hit_instances[i] = instance;
}
