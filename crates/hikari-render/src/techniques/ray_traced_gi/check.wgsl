// Verification kernel (not used by any frame): ray generation, the sample weight, the hit
// word's packing and the albedo of hits for given cases, compared with
// ray_traced_gi::reference in tests/render/ray_traced_gi.rs. Three vec4s in and out a case.
// In: (pixel x, pixel y, frame, distance), (normal, metalness), (albedo, 0).
// Out, as bits: (direction, cosine), (noise u1, u2, hit word, weight), (hit albedo, 0).

#import hikari::ray_traced_gi::{rtgi_blue_noise_2d, rtgi_cosine_direction, rtgi_uniform_weight, rtgi_pack_hit, rtgi_hit_albedo}

@group(0) @binding(0) var<storage, read> inputs: array<vec4<f32>>;
@group(0) @binding(1) var<storage, read_write> outputs: array<vec4<u32>>;

@compute @workgroup_size(64, 1, 1)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let c = gid.x;
    if 3u * c + 2u >= arrayLength(&inputs) || 3u * c + 2u >= arrayLength(&outputs) {
        return;
    }
    let a = inputs[3u * c];
    let b = inputs[3u * c + 1u];
    let e = inputs[3u * c + 2u];
    let u = rtgi_blue_noise_2d(vec2<u32>(u32(a.x), u32(a.y)), u32(a.z));
    let ray = rtgi_cosine_direction(b.xyz, u);
    let word = rtgi_pack_hit(a.w, e.rgb);
    outputs[3u * c] = bitcast<vec4<u32>>(ray);
    outputs[3u * c + 1u] = vec4<u32>(bitcast<vec2<u32>>(u), word, bitcast<u32>(rtgi_uniform_weight(u.x)));
    outputs[3u * c + 2u] = bitcast<vec4<u32>>(vec4<f32>(rtgi_hit_albedo(e.rgb, b.w), 0.0));
}
