// Lights the GI rays' hits (Metro Exodus's "deferred lighting of hits"): regenerates each
// pixel's ray from its pixel and frame, reads the hit word, and takes the radiance arriving
// along the ray: where the hit was visible last frame, last frame's lit image there; on a miss the sky in that direction (no sun or moon disk: direct light is the
// deferred pass's), on a hit the hit's albedo / π times the irradiance there from the sun or
// moon (its shadow maps inside a cascade, else a shadow ray), the sky's ambient light and the point and spot lights, plus the
// emission of the hit's instance (its material's, textures averaged) unless it is an area
// light, whose light the area-light pass gives every surface already. The word
// carries no normal, so a hit is lit as if it faced the ray. Output: the raw sample, encoded
// as luminance L1 SH + CoCg (uniform-hemisphere normalisation), AO and hit distance.

#import hikari::view::{View, world_from_depth}
#import hikari::octahedral::oct_decode
#import hikari::scene_gpu::{LightGpu, light_range, light_attenuation}
#import hikari::sh::{ShYCoCg, shy_encode}
#import hikari::bvh::{Ray, bvh_occluded}
#import hikari::sky::sky_background_no_disks
#import hikari::sun_shadows::{sun_visibility, shadow}
#import hikari::sky_ambient::sky_ambient_irradiance
#import hikari::ray_traced_gi::{RtGiParams, RTGI_SUN, RTGI_SKY, RTGI_SKY_AMBIENT, RTGI_SHADOW_MAPS, RTGI_REUSE_LIT, RTGI_PLACEHOLDER_SKY, RTGI_PUNCTUAL, RTGI_PI, RTGI_HIT_NOT_TRACED, RTGI_HIT_UNRESOLVED, rtgi_ray, rtgi_ray_origin, rtgi_is_hit, rtgi_hit_distance, rtgi_hit_albedo_of}

@group(0) @binding(0) var<uniform> view: View;
@group(0) @binding(1) var<uniform> params: RtGiParams;
@group(0) @binding(2) var depth: texture_2d<f32>;
@group(0) @binding(3) var gbuffer_normal: texture_2d<f32>;
@group(0) @binding(4) var<storage, read> hits: array<u32>;
@group(0) @binding(5) var<storage, read> hit_instances: array<u32>;
// Per scene instance: albedo, then emission in nits (reference::instance_table).
@group(0) @binding(6) var<storage, read> instance_table: array<vec4<f32>>;
@group(0) @binding(7) var<storage, read> lights: array<LightGpu>;
@group(0) @binding(8) var out_y: texture_storage_2d<rgba16float, write>;
// Co, Cg, AO (1 open), 0.
@group(0) @binding(9) var out_cocg_ao: texture_storage_2d<rgba16float, write>;
@group(0) @binding(10) var out_hit_distance: texture_storage_2d<r16float, write>;
// Last frame's lit image (nits) and view depth (`ray_traced_gi.lit`, `.view_depth`).
@group(0) @binding(11) var prev_lit: texture_2d<f32>;
@group(0) @binding(12) var prev_view_depth: texture_2d<f32>;
// This frame's G-buffer instance ids, to check that a reused texel shows the hit's instance.
@group(0) @binding(13) var gbuffer_instance: texture_2d<u32>;

const MAX_RADIANCE: f32 = 65000.0;

fn sky_placeholder(dir: vec3<f32>) -> vec3<f32> {
    return mix(params.sky_horizon.rgb, params.sky_zenith.rgb, sqrt(clamp(dir.y, 0.0, 1.0)));
}

fn miss_radiance(dir: vec3<f32>) -> vec3<f32> {
    let flags = params.config.y;
    if (flags & RTGI_SKY) != 0u {
        return sky_background_no_disks(dir);
    }
    if (flags & RTGI_PLACEHOLDER_SKY) != 0u {
        return sky_placeholder(dir);
    }
    return vec3<f32>(0.0);
}

// Whether the sun shadow maps cover x (the cascade selection of `sun_visibility`).
fn in_a_cascade(x: vec3<f32>, n: vec3<f32>) -> bool {
    let res = shadow.config.y;
    let margin = (shadow.config.z + 2.0) / res;
    for (var c = 0u; c < u32(shadow.config.x); c++) {
        let p = x + n * (shadow.texel_world[c] * shadow.config.w);
        let s = shadow.light_view_proj[c] * vec4<f32>(p, 1.0);
        let uv = vec2<f32>(s.x * 0.5 + 0.5, 0.5 - s.y * 0.5);
        if all(uv > vec2<f32>(margin)) && all(uv < vec2<f32>(1.0 - margin)) {
            return true;
        }
    }
    return false;
}

// The sun's visibility at x: the shadow maps inside a cascade, else a shadow ray.
fn sun_visible(x: vec3<f32>, n: vec3<f32>) -> f32 {
    if (params.config.y & RTGI_SHADOW_MAPS) != 0u && in_a_cascade(x, n) {
        return sun_visibility(x, n);
    }
    return select(1.0, 0.0, bvh_occluded(Ray(x, 0.0, params.sun.xyz, 1.0e5)));
}

// Last frame's lit image where x was visible then (on screen, and its view depth within 1 %
// of the depth stored there), as radiance towards that camera; w = 0 where it was not.
// Screen texel of world point x under a view-projection, or none (x < 0).
fn texel_of(view_proj: mat4x4<f32>, x: vec3<f32>, size: vec2<f32>) -> vec2<f32> {
    let c = view_proj * vec4<f32>(x, 1.0);
    if !(c.w > 0.0) {
        return vec2<f32>(-1.0);
    }
    let ndc = c.xy / c.w;
    let s = vec2<f32>((ndc.x * 0.5 + 0.5) * size.x, (0.5 - ndc.y * 0.5) * size.y);
    if any(s < vec2<f32>(0.0)) || any(s >= size) {
        return vec2<f32>(-1.0);
    }
    return s;
}

fn reused_lit(x: vec3<f32>, instance: u32) -> vec4<f32> {
    if (params.config.y & RTGI_REUSE_LIT) == 0u {
        return vec4<f32>(0.0);
    }
    // The depth test below cannot tell surfaces apart that lie closer than 1 % of the view
    // depth: a hit on the Cornell box's ceiling beside its light (0.5 mm below it) read the
    // light's texel and brought its 5000 nits back as a firefly. The surface seen there now
    // must be the hit's instance.
    let now = texel_of(view.view_proj, x, vec2<f32>(textureDimensions(gbuffer_instance)));
    if now.x >= 0.0 && textureLoad(gbuffer_instance, vec2<u32>(now), 0).x != instance {
        return vec4<f32>(0.0);
    }
    let c = view.prev_view_proj * vec4<f32>(x, 1.0);
    if !(c.w > 0.0) {
        return vec4<f32>(0.0);
    }
    let ndc = c.xy / c.w;
    let size = vec2<f32>(textureDimensions(prev_lit));
    let s = vec2<f32>((ndc.x * 0.5 + 0.5) * size.x, (0.5 - ndc.y * 0.5) * size.y);
    if any(s < vec2<f32>(0.0)) || any(s >= size) {
        return vec4<f32>(0.0);
    }
    let p = vec2<u32>(s);
    let z = textureLoad(prev_view_depth, p, 0).x;
    if !(abs(z - c.w) <= 0.01 * c.w) {
        return vec4<f32>(0.0);
    }
    let l = textureLoad(prev_lit, p, 0).rgb;
    if !all(l >= vec3<f32>(0.0)) || !all(l <= vec3<f32>(65000.0)) {
        return vec4<f32>(0.0);
    }
    return vec4<f32>(l, 1.0);
}

// Irradiance (lux) at x on a surface facing n.
fn irradiance(x: vec3<f32>, n: vec3<f32>) -> vec3<f32> {
    let flags = params.config.y;
    var e = vec3<f32>(0.0);
    let l = params.sun.xyz;
    let c = dot(n, l);
    if (flags & RTGI_SUN) != 0u && params.sun.w > 0.0 && c > 0.0 {
        e += params.sun_color.rgb * (params.sun.w * c * sun_visible(x, n));
    }
    if (flags & RTGI_SKY_AMBIENT) != 0u {
        if (flags & RTGI_SKY) != 0u {
            e += sky_ambient_irradiance(n);
        } else if (flags & RTGI_PLACEHOLDER_SKY) != 0u {
            e += RTGI_PI * 0.5 * (params.sky_zenith.rgb + params.sky_horizon.rgb) * 0.5 * (1.0 + n.y);
        }
    }
    if (flags & RTGI_PUNCTUAL) != 0u {
        for (var i = 0u; i < min(params.config.w, arrayLength(&lights)); i++) {
            let light = lights[i];
            let to_light = light.position_range.xyz - x;
            let d2 = max(dot(to_light, to_light), 1e-8);
            let range = light_range(light, params.distances.w);
            let dir = to_light * inverseSqrt(d2);
            let a = light_attenuation(light, dir, 1.0 / d2, d2 / (range * range));
            e += light.intensity.rgb * (a * max(dot(n, dir), 0.0));
        }
    }
    return e;
}

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let size = textureDimensions(depth);
    if any(gid.xy >= size) {
        return;
    }
    let pixel = gid.xy;
    let word = hits[pixel.y * size.x + pixel.x];
    if word == RTGI_HIT_NOT_TRACED || word == RTGI_HIT_UNRESOLVED {
        textureStore(out_y, pixel, vec4<f32>(0.0));
        textureStore(out_cocg_ao, pixel, vec4<f32>(0.0, 0.0, 1.0, 0.0));
        textureStore(out_hit_distance, pixel, vec4<f32>(0.0));
        return;
    }
    let d = textureLoad(depth, pixel, 0).r;
    let n = oct_decode(textureLoad(gbuffer_normal, pixel, 0).xy);
    let world = world_from_depth(view, pixel, d);
    let o = rtgi_ray_origin(world, n, view.position.xyz);
    let ray = rtgi_ray(pixel, params.config.x, n);
    let dir = ray.xyz;
    var radiance: vec3<f32>;
    var ao = 1.0;
    var distance = 0.0;
    if rtgi_is_hit(word) {
        distance = rtgi_hit_distance(word);
        ao = select(1.0, 0.0, distance < params.distances.y);
        // Back along the ray a little, off the surface it hit.
        let x = o + dir * (distance - (1.0e-3 + 1.0e-3 * distance));
        // The talk's "first bounce from all lights": the lit image where the hit was seen.
        let instance = hit_instances[pixel.y * size.x + pixel.x];
        let lit = reused_lit(o + dir * distance, instance);
        var emission = vec4<f32>(0.0);
        if 2u * instance + 1u < arrayLength(&instance_table) {
            emission = instance_table[2u * instance + 1u];
        }
        // An area light's emission reaches every surface through the area-light pass already
        // (w = 1 in the table); counted here too, the direct light would be counted twice.
        let own = emission.rgb * (1.0 - emission.w);
        if lit.w > 0.0 {
            radiance = max(lit.rgb - emission.rgb * emission.w, vec3<f32>(0.0));
        } else {
            radiance = rtgi_hit_albedo_of(word) / RTGI_PI * irradiance(x, -dir) + own;
        }
    } else {
        radiance = miss_radiance(dir);
    }
    // NaN fails every comparison, so this also turns NaN into 0.
    radiance = select(vec3<f32>(0.0), min(radiance, vec3<f32>(MAX_RADIANCE)), radiance >= vec3<f32>(0.0));
    let s = shy_encode(radiance, dir);
    let w = ray.w;
    textureStore(out_y, pixel, s.y * w);
    textureStore(out_cocg_ao, pixel, vec4<f32>(s.co_cg * w, ao, 0.0));
    textureStore(out_hit_distance, pixel, vec4<f32>(distance, 0.0, 0.0, 0.0));
}
