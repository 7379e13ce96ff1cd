// Screen-space pre-trace (Metro Exodus): the pixel's GI ray marched against the depth buffer
// at a constant screen-space step. A step that goes from in front of the surface (or within
// the thickness behind it) to behind it is a hit, which takes its distance and the G-buffer's
// albedo and instance; a ray it cannot resolve (off screen, behind a surface by more than the
// thickness for a whole step, or longer than the march) goes into the queue for the BVH.
// Output: one hit word a pixel.

#import hikari::view::{View, world_from_depth}
#import hikari::octahedral::oct_decode
#import hikari::finite::is_finite3
#import hikari::ray_traced_gi::{RtGiParams, RTGI_PRETRACE, RTGI_BVH, RTGI_HIT_NOT_TRACED, RTGI_HIT_UNRESOLVED, rtgi_ray_direction, rtgi_ray_origin, rtgi_pack_hit, rtgi_pack_miss, rtgi_hit_albedo, rtgi_pack_normal, RTGI_NO_NORMAL}

@group(0) @binding(0) var<uniform> view: View;
@group(0) @binding(1) var<uniform> params: RtGiParams;
@group(0) @binding(2) var depth: texture_2d<f32>;
@group(0) @binding(3) var gbuffer_normal: texture_2d<f32>;
@group(0) @binding(4) var gbuffer_albedo: texture_2d<f32>;
@group(0) @binding(5) var gbuffer_material: texture_2d<f32>;
@group(0) @binding(6) var gbuffer_motion: texture_2d<f32>;
@group(0) @binding(7) var gbuffer_instance: texture_2d<u32>;
@group(0) @binding(8) var<storage, read_write> hits: array<u32>;
// The scene instance of each hit (0xffffffff: none), for its emission.
@group(0) @binding(9) var<storage, read_write> hit_instances: array<u32>;
// Word 0: count; then pixel indices.
@group(0) @binding(10) var<storage, read_write> queue: array<atomic<u32>>;
// Each hit's normal (rtgi_pack_normal): the G-buffer's at the texel the ray crossed.
@group(0) @binding(11) var<storage, read_write> hit_normals: array<u32>;

const NO_INSTANCE: u32 = 0xffffffffu;
// The pixel the pre-trace hit, if any.
var<private> hit_pixel: vec2<u32>;

// A G-buffer depth that holds a surface: finite, in (0, 1] (0 is the sky).
fn is_surface(d: f32) -> bool {
    return is_finite3(vec3<f32>(d)) && d > 0.0 && d <= 1.0;
}

fn to_pixel(h: vec4<f32>) -> vec2<f32> {
    let ndc = h.xy / h.w;
    return vec2<f32>((ndc.x * 0.5 + 0.5) * view.viewport.x, (0.5 - ndc.y * 0.5) * view.viewport.y);
}

fn march(o: vec3<f32>, dir: vec3<f32>) -> u32 {
    let fwd = view.forward_near.xyz;
    let near = view.forward_near.w;
    let z0 = dot(o - view.position.xyz, fwd);
    let dz = dot(dir, fwd);
    var len = params.pretrace.w;
    // Stay in front of the near plane, where the projection is defined.
    if dz < 0.0 {
        len = min(len, (z0 - 2.0 * near) / -dz);
    }
    if !(len > 0.0) {
        return RTGI_HIT_UNRESOLVED;
    }
    let e = o + dir * len;
    let h0 = view.view_proj * vec4<f32>(o, 1.0);
    let h1 = view.view_proj * vec4<f32>(e, 1.0);
    let s0 = to_pixel(h0);
    let s1 = to_pixel(h1);
    let span = max(length(s1 - s0), 1e-6);
    let step = params.pretrace.x;
    let steps = min(u32(params.pretrace.y), u32(ceil(span / step)));
    let size = vec2<f32>(view.viewport.xy);
    // The ray's view depth at the previous step: a step whose segment spans the surface's
    // depth (from in front, within the thickness, to behind) hits it, however long the step
    // is in depth.
    var prev_z = h0.w;
    for (var i = 1u; i <= steps; i++) {
        let k = min(f32(i) * step / span, 1.0);
        let s = mix(s0, s1, k);
        if any(s < vec2<f32>(0.0)) || any(s >= size) {
            return RTGI_HIT_UNRESOLVED;
        }
        // 1/w and x/w interpolate linearly in screen space; clip w is the view depth.
        let inv_w = mix(1.0 / h0.w, 1.0 / h1.w, k);
        let ray_z = 1.0 / inv_w;
        let p = vec2<u32>(s);
        let z_before = prev_z;
        prev_z = ray_z;
        if !is_surface(textureLoad(depth, p, 0).r) {
            continue;
        }
        // A non-finite view depth fails the comparison and the texel is passed over.
        let surf_z = textureLoad(gbuffer_motion, p, 0).z;
        if ray_z > surf_z * 1.002 {
            if min(z_before, ray_z) > surf_z * (1.0 + params.pretrace.z) {
                // Behind the surface all along the step: what is there is unknown.
                return RTGI_HIT_UNRESOLVED;
            }
            // Bisect the step for where the ray crosses the depth buffer.
            var lo = select(0.0, min(f32(i - 1u) * step / span, 1.0), i > 1u);
            var hi = k;
            var q = p;
            for (var b = 0u; b < 4u; b++) {
                let mid = 0.5 * (lo + hi);
                let pm = vec2<u32>(clamp(mix(s0, s1, mid), vec2<f32>(0.0), size - 1.0));
                let zm = 1.0 / mix(1.0 / h0.w, 1.0 / h1.w, mid);
                if is_surface(textureLoad(depth, pm, 0).r) && zm > textureLoad(gbuffer_motion, pm, 0).z {
                    hi = mid;
                    q = pm;
                } else {
                    lo = mid;
                }
            }
            hit_pixel = q;
            let x = mix(o / h0.w, e / h1.w, hi) / mix(1.0 / h0.w, 1.0 / h1.w, hi);
            let base = textureLoad(gbuffer_albedo, q, 0).rgb;
            let metal = textureLoad(gbuffer_material, q, 0).y;
            return rtgi_pack_hit(length(x - o), rtgi_hit_albedo(base, metal));
        }
    }
    return RTGI_HIT_UNRESOLVED;
}

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let size = textureDimensions(depth);
    if any(gid.xy >= size) {
        return;
    }
    let pixel = gid.xy;
    let i = pixel.y * size.x + pixel.x;
    let d = textureLoad(depth, pixel, 0).r;
    let n = oct_decode(textureLoad(gbuffer_normal, pixel, 0).xy);
    // A bad G-buffer texel (non-finite depth or normal) traces nothing.
    if !is_surface(d) || !is_finite3(n) || !(dot(n, n) > 0.5) {
        hits[i] = RTGI_HIT_NOT_TRACED;
        hit_instances[i] = NO_INSTANCE;
        hit_normals[i] = RTGI_NO_NORMAL;
        return;
    }
    let world = world_from_depth(view, pixel, d);
    let o = rtgi_ray_origin(world, n, view.position.xyz);
    let dir = rtgi_ray_direction(pixel, params.config.x, n).xyz;
    var word = RTGI_HIT_UNRESOLVED;
    let flags = params.config.y;
    if (flags & RTGI_PRETRACE) != 0u {
        word = march(o, dir);
    }
    var instance = NO_INSTANCE;
    var normal = RTGI_NO_NORMAL;
    if word != RTGI_HIT_UNRESOLVED {
        instance = textureLoad(gbuffer_instance, hit_pixel, 0).x;
        // The crossed texel's normal, unless it is not finite (rtgi_pack_normal would turn
        // it into some valid-looking direction).
        let e = textureLoad(gbuffer_normal, hit_pixel, 0).xy;
        if is_finite3(vec3<f32>(e, 0.0)) {
            normal = rtgi_pack_normal(e);
        }
    }
    hit_instances[i] = instance;
    hit_normals[i] = normal;
    if word == RTGI_HIT_UNRESOLVED {
        if (flags & RTGI_BVH) != 0u {
            let slot = atomicAdd(&queue[0], 1u);
            atomicStore(&queue[slot + 1u], i);
        } else {
            word = rtgi_pack_miss();
        }
    }
    hits[i] = word;
}
