// Lights the GI rays' hits (Metro Exodus's "deferred lighting of hits"): regenerates each
// pixel's ray from its pixel and frame, reads the hit word, and takes the radiance arriving
// along the ray. Where the hit was visible last frame: last frame's lit image there. On a
// miss: the sky in that direction (no sun or moon disk: direct light is the deferred pass's),
// seen through the clouds as the deferred lighting draws them.
// On a hit: the hit's albedo / π times the irradiance there, on a surface facing the hit's
// normal (`hit_normals`: the triangle's for BVH hits, the G-buffer's for the pre-trace's,
// turned to face the ray; -dir without one), from the sun or moon (its shadow maps inside a
// cascade, else a shadow ray, and the clouds' shadow), the sky's ambient light, the point and spot lights and the area
// lights (in closed form), each kind shadowed by one ray to one light picked by its
// unshadowed light; plus the emission of the hit's instance (its material's, textures
// averaged) unless it is an area light, whose direct light the area-light pass gives every
// surface already (its light on the hit is counted here). Output: the raw sample, encoded as
// luminance L1 SH + CoCg (uniform-hemisphere normalisation), AO and hit distance. Each
// sample's luminance is capped at a multiple of display white under last frame's exposure.
// Local lights are visited through the light grid (ray_traced_gi::light_grid): only those
// listed in the hit's cell, which are all that can reach it, in ascending order.
// CPU twins: ray_traced_gi::reference (punctual_irradiance, area_light_irradiance,
// pick_light, area_light_point, random), light_grid::LightGrid::lights_at.

#import hikari::view::{View, world_from_depth}
#import hikari::octahedral::oct_decode
#import hikari::scene_gpu::{LightGpu, light_range, light_attenuation}
#import hikari::sh::{ShYCoCg, shy_encode}
#import hikari::bvh::{Ray, bvh_occluded}
#import hikari::sky::sky_background_no_disks
#import hikari::sun_shadows::{sun_visibility, shadow}
#import hikari::sky_ambient::{sky_ambient_irradiance, sky_ambient_eval}
#import hikari::clouds::{clouds_over_sky, cloud_shadow}
#import hikari::area_polygon::{AreaLightGpu, AREA_LIGHT_DOUBLE_SIDED, AREA_LIGHT_FORCED, area_light_reach, area_triangle_vector_irradiance}
#import hikari::finite::is_finite4
#import hikari::ray_traced_gi::{RtGiParams, RTGI_SUN, RTGI_SKY, RTGI_SKY_AMBIENT, RTGI_SHADOW_MAPS, RTGI_REUSE_LIT, RTGI_PLACEHOLDER_SKY, RTGI_PUNCTUAL, RTGI_PUNCTUAL_SHADOWS, RTGI_AREA, RTGI_PI, RTGI_HIT_NOT_TRACED, RTGI_HIT_UNRESOLVED, rtgi_ray, rtgi_basis, rtgi_ray_origin, rtgi_is_hit, rtgi_hit_distance, rtgi_hit_albedo_of, rtgi_random, rtgi_unpack_normal, RTGI_NO_NORMAL}

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
// The area lights' tables (`area_lights::AreaLightScene`; layouts in area_lights/shade.wgsl).
@group(0) @binding(14) var<storage, read> area_lights: array<AreaLightGpu>;
@group(0) @binding(15) var<storage, read> area_triangles: array<AreaTriangleGpu>;
@group(0) @binding(16) var<storage, read> hit_normals: array<u32>;
// The grid of light lists (`ray_traced_gi::light_grid`): record 0 the origin (xyz) and cell
// size (w) as f32 bits, record 1 the cells along x, y, z, then per cell: first index, area
// lights, punctual lights. Indices: per cell its area lights, then its punctual lights.
@group(0) @binding(17) var<storage, read> light_grid: array<vec4<u32>>;
@group(0) @binding(18) var<storage, read> light_grid_indices: array<u32>;
// Last frame's exposure (`exposure.state`): x EV100, y 1 once written.
@group(0) @binding(19) var prev_exposure: texture_2d<f32>;

// The area lights' triangle record, as area_lights/shade.wgsl declares it (hikari::area_polygon says
// why it is not shared).
struct AreaTriangleGpu {
    p0_cdf: vec4<f32>,
    p1: vec4<f32>,
    p2: vec4<f32>,
}

const NO_LIGHT: u32 = 0xffffffffu;

const MAX_RADIANCE: f32 = 65000.0;

// The light lists of x's grid cell: first index, area lights, punctual lights (0, 0, 0
// outside the grid, where no local light reaches).
fn grid_cell(x: vec3<f32>) -> vec3<u32> {
    let h = light_grid[0];
    let dims = light_grid[1].xyz;
    let g = floor((x - bitcast<vec3<f32>>(h.xyz)) / bitcast<f32>(h.w));
    // NaN fails both comparisons: no cell.
    if !(all(g >= vec3<f32>(0.0)) && all(g < vec3<f32>(dims))) {
        return vec3<u32>(0u);
    }
    let c = vec3<u32>(g);
    return light_grid[2u + (c.z * dims.y + c.y) * dims.x + c.x].xyz;
}

fn sky_placeholder(dir: vec3<f32>) -> vec3<f32> {
    return mix(params.sky_horizon.rgb, params.sky_zenith.rgb, sqrt(clamp(dir.y, 0.0, 1.0)));
}

fn miss_radiance(dir: vec3<f32>) -> vec3<f32> {
    let flags = params.config.y;
    if (flags & RTGI_SKY) != 0u {
        // The clouds' light as the deferred lighting draws them over the sky: the sun's
        // illuminance and the sky's mean radiance (band 0 of its SH).
        let sun_lux = select(vec3<f32>(0.0), params.sun_color.rgb * params.sun.w, (flags & RTGI_SUN) != 0u);
        let mean_sky = sky_ambient_eval(vec3<f32>(0.0, 1.0, 0.0), vec3<f32>(1.0, 0.0, 0.0));
        return clouds_over_sky(dir, sky_background_no_disks(dir), sun_lux, mean_sky);
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

fn luminance(c: vec3<f32>) -> f32 {
    return dot(c, vec3<f32>(0.2126, 0.7152, 0.0722));
}

// Whether area light `i` may light x on a surface facing n, by the area-light pass's culling:
// not a light dimmer than its minimum flux (unless flagged), not beyond the distance where it
// must fall below the frame's cut-off, not wholly behind its one-sided plane or below the
// surface's horizon.
fn area_light_reaches(i: u32, x: vec3<f32>, n: vec3<f32>) -> bool {
    let light = area_lights[i];
    let forced = (light.range.z & AREA_LIGHT_FORCED) != 0u;
    let double_sided = (light.range.z & AREA_LIGHT_DOUBLE_SIDED) != 0u;
    if light.radiance_flux.w < params.area.y && !forced {
        return false;
    }
    let c = light.centroid_radius.xyz;
    let r = light.centroid_radius.w;
    let reach = area_light_reach(light, params.distances.w);
    let to_c = c - x;
    let nl = light.normal_area.xyz;
    return !(dot(to_c, to_c) >= reach * reach || dot(to_c, n) < -r
        || (!double_sided && length(nl) > 0.99 && dot(x - c, nl) < -r));
}

// What a hit picks area light `i` by: its flux over the squared distance to its centroid
// (the area-light pass's ranking), 0 where it cannot reach x. Cheap, so that a hit in reach of
// hundreds of lit windows integrates one polygon, not hundreds.
fn area_light_score(i: u32, x: vec3<f32>, n: vec3<f32>) -> f32 {
    if !area_light_reaches(i, x, n) {
        return 0.0;
    }
    let light = area_lights[i];
    let to_c = light.centroid_radius.xyz - x;
    let r = light.centroid_radius.w;
    return light.radiance_flux.w / max(dot(to_c, to_c), max(r * r, 1e-6));
}

// Unshadowed irradiance (lux) of area light `i` at x on a surface facing n: 0 where it cannot
// reach x, else the polygon integration.
fn area_light_irradiance(i: u32, x: vec3<f32>, n: vec3<f32>) -> vec3<f32> {
    if !area_light_reaches(i, x, n) {
        return vec3<f32>(0.0);
    }
    let light = area_lights[i];
    let double_sided = (light.range.z & AREA_LIGHT_DOUBLE_SIDED) != 0u;
    var f = vec3<f32>(0.0);
    for (var j = light.range.x; j < light.range.x + light.range.y; j++) {
        let tri = area_triangles[j];
        f += area_triangle_vector_irradiance(tri.p0_cdf.xyz, tri.p1.xyz, tri.p2.xyz, x, n, double_sided);
    }
    return light.radiance_flux.rgb * max(dot(f, n), 0.0);
}

// One shadow ray from x to a point of area light `i` sampled by area (u: two numbers in
// [0, 1)): 1 if it reaches it, 0 if blocked. A point the surface or the light turns away from
// carries no weight in the area-light pass's ratio estimator, which with one ray gives 1.
fn area_light_visible(i: u32, x: vec3<f32>, n: vec3<f32>, u: vec2<f32>) -> f32 {
    let light = area_lights[i];
    let first = light.range.x;
    let last = first + light.range.y - 1u;
    var j = first;
    var lo = 0.0;
    loop {
        let cdf = area_triangles[j].p0_cdf.w;
        if u.x <= cdf || j >= last {
            break;
        }
        lo = cdf;
        j++;
    }
    let tri = area_triangles[j];
    let ux = clamp((u.x - lo) / max(tri.p0_cdf.w - lo, 1e-12), 0.0, 1.0);
    let su = sqrt(ux);
    let p = tri.p0_cdf.xyz * (1.0 - su) + tri.p1.xyz * (su * (1.0 - u.y)) + tri.p2.xyz * (su * u.y);
    let to_p = p - x;
    let dist = length(to_p);
    if !(dist > 1e-6) {
        return 1.0;
    }
    let dir = to_p / dist;
    let ng = cross(tri.p1.xyz - tri.p0_cdf.xyz, tri.p2.xyz - tri.p0_cdf.xyz);
    var cos_l = -dot(dir, ng);
    if (light.range.z & AREA_LIGHT_DOUBLE_SIDED) != 0u {
        cos_l = abs(cos_l);
    }
    if !(dot(dir, n) > 0.0 && cos_l > 0.0) {
        return 1.0;
    }
    return select(1.0, 0.0, bvh_occluded(Ray(x, 0.0, dir, dist * (1.0 - 1e-3))));
}

// One light picked in proportion to its weight in one pass over the candidates: a running
// choice on one random number `u`, rescaled after each candidate so that it stays uniform
// (twin: reference::pick_weighted). `chosen` NO_LIGHT while no weight was above 0.
struct LightPick {
    u: f32,
    total: f32,
    chosen: u32,
    weight: f32,
    value: vec3<f32>,
}

fn light_pick(u: f32) -> LightPick {
    return LightPick(u, 0.0, NO_LIGHT, 0.0, vec3<f32>(0.0));
}

// Offers light i with weight w (and a value kept with it) to the pick.
fn offer(p: ptr<function, LightPick>, i: u32, w: f32, value: vec3<f32>) {
    if !(w > 0.0) {
        return;
    }
    (*p).total += w;
    let q = w / (*p).total;
    if (*p).u < q {
        (*p).chosen = i;
        (*p).weight = w;
        (*p).value = value;
        (*p).u = (*p).u / q;
    } else {
        (*p).u = ((*p).u - q) / max(1.0 - q, 1e-7);
    }
    (*p).u = min((*p).u, 0.99999994);
}

// Irradiance (lux) at x on a surface facing n from the area lights, with one polygon
// integration and one shadow ray: one light is picked in proportion to its score (one pass, a
// running choice on one random number, rescaled after each light), and its unshadowed light
// times the scores' sum over its own score, times its visibility, is the estimate: unbiased,
// since every light that can light x has a score above 0. The shadow is the ratio
// estimator's with one ray (Heitz et al. 2018).
fn area_irradiance(pixel: vec2<u32>, x: vec3<f32>, n: vec3<f32>) -> vec3<f32> {
    if (params.config.y & RTGI_AREA) == 0u {
        return vec3<f32>(0.0);
    }
    let frame = params.config.x;
    var pick = light_pick(rtgi_random(pixel, frame, 0u));
    let count = min(u32(params.area.x), arrayLength(&area_lights));
    // Only the lights listed in x's cell can reach it: the others score 0 (light_grid).
    let cell = grid_cell(x);
    for (var k = 0u; k < cell.y; k++) {
        let i = light_grid_indices[cell.x + k];
        if i >= count {
            continue;
        }
        offer(&pick, i, area_light_score(i, x, n), vec3<f32>(0.0));
    }
    let chosen = pick.chosen;
    if chosen == NO_LIGHT {
        return vec3<f32>(0.0);
    }
    let e = area_light_irradiance(chosen, x, n);
    if !(luminance(e) > 0.0) {
        return vec3<f32>(0.0);
    }
    let est = e * (pick.total / pick.weight);
    let q = roulette_chance(est);
    if rtgi_random(pixel, frame, 4u) >= q {
        return vec3<f32>(0.0);
    }
    let uv = vec2<f32>(rtgi_random(pixel, frame, 1u), rtgi_random(pixel, frame, 2u));
    return est * (area_light_visible(chosen, x, n, uv) / q);
}

// The chance (in (0, 1]) that the shadow ray of a local light's estimate `est` (lux) is
// traced: 1 at or above the roulette's illuminance, else in proportion to it (reference::
// roulette_chance). The light is divided by it where traced and 0 where not.
fn roulette_chance(est: vec3<f32>) -> f32 {
    let level = params.area.z;
    if !(level > 0.0) {
        return 1.0;
    }
    return clamp(luminance(est) / level, 1e-6, 1.0);
}

// Irradiance (lux) at x on a surface facing n from the sun or moon and the sky.
fn irradiance(x: vec3<f32>, n: vec3<f32>) -> vec3<f32> {
    let flags = params.config.y;
    var e = vec3<f32>(0.0);
    let l = params.sun.xyz;
    let c = dot(n, l);
    if (flags & RTGI_SUN) != 0u && params.sun.w > 0.0 && c > 0.0 {
        e += params.sun_color.rgb * (params.sun.w * c * sun_visible(x, n) * cloud_shadow(x));
    }
    if (flags & RTGI_SKY_AMBIENT) != 0u {
        if (flags & RTGI_SKY) != 0u {
            e += sky_ambient_irradiance(n);
        } else if (flags & RTGI_PLACEHOLDER_SKY) != 0u {
            e += RTGI_PI * 0.5 * (params.sky_zenith.rgb + params.sky_horizon.rgb) * 0.5 * (1.0 + n.y);
        }
    }
    return e;
}

// Unshadowed irradiance (lux) of point or spot light `i` at x on a surface facing n: inverse
// square, the deferred lighting's window and cut-off, the spot cone, Lambert's cosine.
fn punctual_light_irradiance(i: u32, x: vec3<f32>, n: vec3<f32>) -> vec3<f32> {
    let light = lights[i];
    let to_light = light.position_range.xyz - x;
    let d2 = max(dot(to_light, to_light), 1e-8);
    let range = light_range(light, params.distances.w);
    let dir = to_light * inverseSqrt(d2);
    let a = light_attenuation(light, dir, 1.0 / d2, d2 / (range * range));
    return light.intensity.rgb * (a * max(dot(n, dir), 0.0));
}

// Irradiance (lux) at x on a surface facing n from the point and spot lights. Shadowed
// (RTGI_PUNCTUAL_SHADOWS, when the frame shadows them): one light picked in proportion to the
// luminance of its unshadowed irradiance, as for the area lights, and one shadow ray to its
// centre; its light times the sum's luminance over its own if the ray passes, else 0, which
// is unbiased for the lights' shadowed sum with point lights. Else the unshadowed sum.
fn punctual_irradiance(pixel: vec2<u32>, x: vec3<f32>, n: vec3<f32>) -> vec3<f32> {
    let flags = params.config.y;
    if (flags & RTGI_PUNCTUAL) == 0u {
        return vec3<f32>(0.0);
    }
    let count = min(params.config.w, arrayLength(&lights));
    // Only the lights listed in x's cell can reach it: the others give 0 (light_grid).
    let cell = grid_cell(x);
    let first = cell.x + cell.y;
    if (flags & RTGI_PUNCTUAL_SHADOWS) == 0u {
        var e = vec3<f32>(0.0);
        for (var k = 0u; k < cell.z; k++) {
            let i = light_grid_indices[first + k];
            if i < count {
                e += punctual_light_irradiance(i, x, n);
            }
        }
        return e;
    }
    var pick = light_pick(rtgi_random(pixel, params.config.x, 3u));
    for (var k = 0u; k < cell.z; k++) {
        let i = light_grid_indices[first + k];
        if i >= count {
            continue;
        }
        let e = punctual_light_irradiance(i, x, n);
        offer(&pick, i, luminance(e), e);
    }
    let chosen = pick.chosen;
    if chosen == NO_LIGHT {
        return vec3<f32>(0.0);
    }
    let est = pick.value * (pick.total / pick.weight);
    let q = roulette_chance(est);
    if rtgi_random(pixel, params.config.x, 5u) >= q {
        return vec3<f32>(0.0);
    }
    // A point on a disc of the light's radius facing the hit (its own radius, else the
    // area-light pass's `punctual_radius_m`), as the direct light's shadows: soft at hits too.
    // Twin: reference::punctual_shadow_target.
    let light = lights[chosen];
    let radius = select(params.area.w, light.spot.z, light.spot.z >= 0.0);
    let tb = rtgi_basis(normalize(light.position_range.xyz - x));
    let rho = radius * sqrt(rtgi_random(pixel, params.config.x, 6u));
    let phi = 2.0 * RTGI_PI * rtgi_random(pixel, params.config.x, 7u);
    let to_light = light.position_range.xyz + tb[0] * (rho * cos(phi)) + tb[1] * (rho * sin(phi)) - x;
    let dist = length(to_light);
    if bvh_occluded(Ray(x, 0.0, to_light / max(dist, 1e-6), dist * (1.0 - 1e-3))) {
        return vec3<f32>(0.0);
    }
    return est / q;
}

// The cap on a sample's luminance (nits), 0 for none: params.exposure.x times the radiance
// that last frame's exposure maps to display white, 1.2 · 2^EV100 (exposure/adapt.wgsl); none
// where there is no last frame (the CPU meter knows only the sun and the sky: in a scene lit
// by its own lights, the Cornell box, its floor of 1e-3 lux took the first frame's GI away). A ray that hits a post beside a lamp
// (E = I / d²) would otherwise bring thousands of times the frame's light in one sample, more
// than the accumulation's firefly clamp, relative to a dark history, holds back.
// Twin: reference::hit_radiance_cap_nits.
fn radiance_cap() -> f32 {
    let k = params.exposure.x;
    if !(k > 0.0) {
        return 0.0;
    }
    let prev = textureLoad(prev_exposure, vec2<u32>(0u), 0);
    // NaN fails the range test: no cap then.
    if !(params.exposure.z > 0.5 && prev.y > 0.5 && abs(prev.x) < 64.0) {
        return 0.0;
    }
    return k * 1.2 * exp2(prev.x);
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
        // The hit's normal, facing the ray.
        var hn = -dir;
        let packed_normal = hit_normals[pixel.y * size.x + pixel.x];
        if packed_normal != RTGI_NO_NORMAL {
            let m = oct_decode(rtgi_unpack_normal(packed_normal));
            hn = select(m, -m, dot(m, dir) > 0.0);
        }
        // Back along the ray a little, off the surface it hit.
        let eps = 1.0e-3 + 1.0e-3 * distance;
        let x = o + dir * (distance - eps) + hn * eps;
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
            let e = irradiance(x, hn) + punctual_irradiance(pixel, x, hn) + area_irradiance(pixel, x, hn);
            radiance = rtgi_hit_albedo_of(word) / RTGI_PI * e + own;
        }
    } else {
        radiance = miss_radiance(dir);
    }
    // NaN fails every comparison, so this also turns NaN into 0.
    radiance = select(vec3<f32>(0.0), min(radiance, vec3<f32>(MAX_RADIANCE)), radiance >= vec3<f32>(0.0));
    // Twin: reference::cap_sample_radiance.
    let cap = radiance_cap();
    let y = luminance(radiance);
    if cap > 0.0 && y > cap {
        radiance *= cap / y;
    }
    let s = shy_encode(radiance, dir);
    let w = ray.w;
    var sample_y = s.y * w;
    var co_cg = s.co_cg * w;
    // The whole sample, not only the radiance: a non-finite direction or weight gives a
    // non-finite SH even from finite radiance. Such a sample is dropped (zero).
    if !is_finite4(sample_y) || !is_finite4(vec4<f32>(co_cg, 0.0, 0.0)) {
        sample_y = vec4<f32>(0.0);
        co_cg = vec2<f32>(0.0);
    }
    textureStore(out_y, pixel, sample_y);
    textureStore(out_cocg_ao, pixel, vec4<f32>(co_cg, select(1.0, ao, is_finite4(vec4<f32>(ao))), 0.0));
    textureStore(out_hit_distance, pixel, vec4<f32>(distance, 0.0, 0.0, 0.0));
}
