// Polygonal area lights and shadowed point and spot lights (docs/area-lights.md).
//
// Area lights: the unshadowed light of each polygon in closed form (hikari::area_polygon,
// Lambert's vector irradiance of each front-facing triangle clipped to the surface's horizon: exact for the
// diffuse lobe), the specular lobe at a representative point with Karis's widening. Point and
// spot lights: as the deferred lighting shades them. Shadows within a budget of rays per pixel:
// a few lights picked at random in proportion to their unshadowed radiance (systematic
// sampling, offset per pixel and frame), each pick's light over its chance times its
// visibility, the ratio estimator of stochastic shadows (Heitz et al. 2018) over the rays that
// went to that light (points sampled by area, or on a disc of a point light's radius, weighted
// by their unshadowed integrand). Rays: hikari::bvh.
// Lights are culled per 16x16 tile against the bounds of the surfaces it sees (hikari::
// tile_bounds): a point or spot light beyond its range, an area light beyond the distance where
// its illuminance must fall below the frame's cut-off or wholly behind its one-sided plane.
// Output: radiance in nits (rgb) and the illuminance in lux these lights bring to the surface,
// shadowed (a), for the exposure meter; and the same unshadowed, for the shadow denoiser
// (area_lights/temporal.wgsl). CPU twin: area_lights::reference.

#import hikari::view::{View, world_from_depth}
#import hikari::octahedral::oct_decode
#import hikari::brdf::{BrdfMaterial, BrdfView, brdf_view, brdf_light_weights, brdf_apply_weights}
#import hikari::scene_gpu::{LightGpu, MaterialGpu, NO_TEXTURE, light_range, light_attenuation, wrap_uv}
#import hikari::bvh::{Ray, bvh_occluded}
#import hikari::tile_bounds::{TileBounds, tile_bounds, tile_bounds_distance2, TILE_BOUNDS_FAR}
#import hikari::area_polygon::{AreaLightGpu, AREA_LIGHT_DOUBLE_SIDED, AREA_LIGHT_FORCED, area_light_reach, area_triangle_vector_irradiance}

struct AreaTriangleGpu {
    p0_cdf: vec4<f32>,
    p1: vec4<f32>,
    p2: vec4<f32>,
}

struct AreaLightParams {
    // x: area lights; y: AREA_* flags; z: frame index; w: point and spot lights.
    config: vec4<u32>,
    // x: shadow rays per pixel (the budget); y: area lights per pixel; z: lights picked for
    // those rays per pixel (at most MAX_PER_PIXEL); w: 0.
    counts: vec4<u32>,
    // x: min flux (lm); y: point and spot radius (m) where a light has none of its own
    // (LightGpu.spot.z < 0); z: point and spot cut-off (lux); w: 0.
    values: vec4<f32>,
    // xy: this frame's random rotation of the sample pattern, in [0, 1).
    rotation: vec4<f32>,
}

const AREA_POLYGONS: u32 = 1u;
const AREA_PUNCTUAL: u32 = 2u;
const MAX_PER_PIXEL: u32 = 8u;
const NONE: u32 = 0xffffffffu;
// A pick's key: the light's index, with this bit for a point or spot light.
const PUNCTUAL_KEY: u32 = 0x80000000u;
const PI: f32 = 3.14159265358979;
const MAX_RADIANCE: f32 = 65000.0;
// Lights of each kind listed per tile at most; the rest are left out there (as the deferred
// lighting's tiles do).
const TILE_LIGHTS: u32 = 256u;
const TILE_THREADS: u32 = 256u;

@group(0) @binding(0) var<uniform> view: View;
@group(0) @binding(1) var<uniform> params: AreaLightParams;
@group(0) @binding(2) var depth: texture_2d<f32>;
@group(0) @binding(3) var gbuffer_normal: texture_2d<f32>;
@group(0) @binding(4) var gbuffer_albedo: texture_2d<f32>;
@group(0) @binding(5) var gbuffer_material: texture_2d<f32>;
@group(0) @binding(6) var<storage, read> area_lights: array<AreaLightGpu>;
@group(0) @binding(7) var<storage, read> area_triangles: array<AreaTriangleGpu>;
@group(0) @binding(8) var<storage, read> lights: array<LightGpu>;
@group(0) @binding(9) var out_radiance: texture_storage_2d<rgba16float, write>;
// The same lights unshadowed, in closed form (no noise): the shadow denoiser's visibility is
// out_radiance over this.
@group(0) @binding(10) var out_unshadowed: texture_storage_2d<rgba16float, write>;
// Per area triangle two vec4: its UVs (u0, v0, u1, v1), (u2, v2, 1 / the texture's mean
// luminance, 0) (PolygonLights::uvs); and what a textured emitter's texture is read from.
@group(0) @binding(11) var<storage, read> area_uvs: array<vec4<f32>>;
@group(0) @binding(12) var<storage, read> materials: array<MaterialGpu>;
@group(0) @binding(13) var color_textures: texture_2d_array<f32>;
@group(0) @binding(14) var texture_sampler: sampler;
// Alpha: the dielectric specular weight (KHR_materials_specular) the BRDF reads.
@group(0) @binding(15) var gbuffer_emissive: texture_2d<f32>;

// The lights that may reach the tile, in index order (so that the per-pixel selection breaks
// ties and sums as over all lights): chunks of 256 lights are tested one per invocation into
// bit masks (words 0-7 point and spot, 8-15 area), which 16 invocations then append.
var<workgroup> chunk_mask: array<atomic<u32>, 16>;
var<workgroup> tile_punctual: array<u32, TILE_LIGHTS>;
var<workgroup> tile_area: array<u32, TILE_LIGHTS>;
// Listed point and spot lights (x) and area lights (y), possibly past TILE_LIGHTS.
var<workgroup> tile_counts: vec2<u32>;

// The sample pattern: Roberts's R2 sequence, shifted per pixel by interleaved gradient noise
// (Jimenez 2014) and per frame by one random rotation shared by every pixel.
fn sample_2d(pixel: vec2<u32>, i: u32) -> vec2<f32> {
    let p = vec2<f32>(pixel);
    let ign = fract(52.9829189 * fract(0.06711056 * p.x + 0.00583715 * p.y));
    let ign2 = fract(52.9829189 * fract(0.06711056 * (p.x + 5.0) + 0.00583715 * (p.y + 7.0)));
    let r2 = fract(f32(i) * vec2<f32>(0.7548776662, 0.5698402910));
    return fract(r2 + vec2<f32>(ign, ign2) + params.rotation.xy);
}

fn luminance(c: vec3<f32>) -> f32 {
    return dot(c, vec3<f32>(0.2126, 0.7152, 0.0722));
}

// A punctual light's illuminance factor `d2` metres squared away in unit direction `l`
// (surface to light), with the frame's cut-off (as the deferred lighting).
fn punctual_attenuation(light: LightGpu, l: vec3<f32>, d2: f32) -> f32 {
    let range = light_range(light, params.values.z);
    return light_attenuation(light, l, 1.0 / max(d2, 1e-4), d2 / (range * range));
}

// Whether area light `i` can light a surface at `lo..hi` (a point, or a tile's bounds): bright
// enough to be a light, within its reach, not wholly behind its one-sided plane.
fn area_light_reaches(i: u32, lo: vec3<f32>, hi: vec3<f32>) -> bool {
    let light = area_lights[i];
    if light.radiance_flux.w < params.values.x && (light.range.z & AREA_LIGHT_FORCED) == 0u {
        return false;
    }
    let c = light.centroid_radius.xyz;
    let reach = area_light_reach(light, params.values.z);
    if tile_bounds_distance2(TileBounds(lo, hi), c) >= reach * reach {
        return false;
    }
    // The box's corner furthest in front of the plane.
    let nl = light.normal_area.xyz;
    let front = select(lo, hi, nl > vec3<f32>(0.0));
    let r = light.centroid_radius.w;
    return (light.range.z & AREA_LIGHT_DOUBLE_SIDED) != 0u || length(nl) <= 0.99 || dot(front - c, nl) >= -r;
}

fn punctual_light_reaches(i: u32, b: TileBounds) -> bool {
    let range = light_range(lights[i], params.values.z);
    return tile_bounds_distance2(b, lights[i].position_range.xyz) < range * range;
}

// Lists the lights that may reach the tile `b` (see tile_punctual). Every invocation calls it.
fn cull_lights(lid: u32, b: TileBounds) {
    if lid == 0u {
        tile_counts = vec2<u32>(0u);
    }
    let flags = params.config.y;
    let np = select(0u, params.config.w, (flags & AREA_PUNCTUAL) != 0u);
    let na = select(0u, params.config.x, (flags & AREA_POLYGONS) != 0u);
    let seen = b.lo.x <= b.hi.x;
    for (var base = 0u; base < max(np, na); base += TILE_THREADS) {
        if lid < 16u {
            atomicStore(&chunk_mask[lid], 0u);
        }
        workgroupBarrier();
        let i = base + lid;
        let bit = 1u << (lid % 32u);
        if seen && i < np && punctual_light_reaches(i, b) {
            atomicOr(&chunk_mask[lid / 32u], bit);
        }
        if seen && i < na && area_light_reaches(i, b.lo, b.hi) {
            atomicOr(&chunk_mask[8u + lid / 32u], bit);
        }
        workgroupBarrier();
        if lid < 16u {
            let kind = lid / 8u;
            var at = tile_counts[kind];
            for (var k = kind * 8u; k < lid; k++) {
                at += countOneBits(atomicLoad(&chunk_mask[k]));
            }
            var bits = atomicLoad(&chunk_mask[lid]);
            while bits != 0u {
                let id = base + (lid % 8u) * 32u + firstTrailingBit(bits);
                bits &= bits - 1u;
                if at < TILE_LIGHTS {
                    if kind == 0u {
                        tile_punctual[at] = id;
                    } else {
                        tile_area[at] = id;
                    }
                }
                at++;
            }
        }
        workgroupBarrier();
        if lid == 0u {
            var added = vec2<u32>(0u);
            for (var k = 0u; k < 8u; k++) {
                added += vec2<u32>(countOneBits(atomicLoad(&chunk_mask[k])), countOneBits(atomicLoad(&chunk_mask[8u + k])));
            }
            tile_counts += added;
        }
        workgroupBarrier();
    }
}

// Inserts light `id` of score `s` into the list of the `keep` best, largest first (ties keep
// the earlier light). The loops run to the constant MAX_PER_PIXEL so that the compiler unrolls
// them and keeps the arrays in registers: indexed by a variable, lavapipe puts them in memory.
fn insert_best(sel: ptr<function, array<u32, MAX_PER_PIXEL>>, score: ptr<function, array<f32, MAX_PER_PIXEL>>, keep: u32, id_in: u32, s_in: f32) {
    var s = s_in;
    var id = id_in;
    for (var k = 0u; k < MAX_PER_PIXEL; k++) {
        if k < keep && s > (*score)[k] {
            let ts = (*score)[k];
            let ti = (*sel)[k];
            (*score)[k] = s;
            (*sel)[k] = id;
            s = ts;
            id = ti;
        }
    }
}

// Entry `k` of `sel`, through a constant-bound loop (see insert_best).
fn pick(sel: ptr<function, array<u32, MAX_PER_PIXEL>>, k: u32) -> u32 {
    var id = NONE;
    for (var j = 0u; j < MAX_PER_PIXEL; j++) {
        if j == k {
            id = (*sel)[j];
        }
    }
    return id;
}

fn orthonormal(n: vec3<f32>) -> vec3<f32> {
    let a = select(vec3<f32>(1.0, 0.0, 0.0), vec3<f32>(0.0, 1.0, 0.0), abs(n.x) > 0.9);
    return normalize(cross(n, a));
}

struct Sums {
    a: vec3<f32>,
    b: vec3<f32>,
    c: vec3<f32>,
    d: vec3<f32>,
}

var<private> sums: Sums;
// Illuminance (lux) arriving from the lights shaded so far.
var<private> lux: f32;
// The pixel's light unshadowed: radiance (nits, rgb) and illuminance (lux, a).
var<private> unshadowed: vec4<f32>;

fn add_light(w: vec4<f32>, e: vec3<f32>) {
    sums.a += e * w.x;
    sums.b += e * w.y;
    sums.c += e * w.z;
    sums.d += e * w.w;
}

// PCG's output permutation (O'Neill 2014) as a hash.
fn pcg(v: u32) -> u32 {
    let state = v * 747796405u + 2891336453u;
    let word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

// The pixel's offset in [0, 1) of its picks' positions this frame: a hash of the pixel, moved
// each frame by the golden ratio (a Weyl sequence, in 32-bit fixed point), so that over frames
// the positions stratify the pixel's lights for TAA to average; frame 0 repeats.
fn pick_offset(pixel: vec2<u32>) -> f32 {
    let h = pcg(pixel.x ^ pcg(pixel.y ^ 0x5bd1e995u)) + params.config.z * 2654435769u;
    return f32(h >> 8u) * (1.0 / 16777216.0);
}

// Places the picks that fall on a light of unshadowed radiance `c.rgb` (nits) and illuminance
// `c.a` (lux), walked in the same order as the lights were summed into W: systematic sampling
// by weight w = luminance(c), pick s at (s + offset) W / picks along the lights' running sum
// `cum`, so light j is picked about picks w_j / W times (at least once when w_j >= W / picks).
// Each pick keeps (c / w) and its light's key; `last` is the last light of weight, which takes
// any pick that rounding leaves past the end. Constant-bound loop (see insert_best).
fn place(keys: ptr<function, array<u32, MAX_PER_PIXEL>>, ratios: ptr<function, array<vec4<f32>, MAX_PER_PIXEL>>, cum: ptr<function, f32>, last: ptr<function, vec4<f32>>, last_key: ptr<function, u32>, step: f32, offset: f32, key: u32, c: vec4<f32>) {
    let w = luminance(c.rgb);
    if !(w > 0.0) {
        return;
    }
    *cum += w;
    *last = c / w;
    *last_key = key;
    let picks = params.counts.z;
    for (var s = 0u; s < MAX_PER_PIXEL; s++) {
        if s < picks && (*keys)[s] == NONE && (f32(s) + offset) * step < *cum {
            (*keys)[s] = key;
            (*ratios)[s] = c / w;
        }
    }
}

// Entry `k` of `a`, through a constant-bound loop (see insert_best).
fn get4(a: ptr<function, array<vec4<f32>, MAX_PER_PIXEL>>, k: u32) -> vec4<f32> {
    var v = vec4<f32>(0.0);
    for (var j = 0u; j < MAX_PER_PIXEL; j++) {
        if j == k {
            v = (*a)[j];
        }
    }
    return v;
}

fn put4(a: ptr<function, array<vec4<f32>, MAX_PER_PIXEL>>, k: u32, v: vec4<f32>) {
    for (var j = 0u; j < MAX_PER_PIXEL; j++) {
        if j == k {
            (*a)[j] = v;
        }
    }
}

// A textured emitter's luminance at barycentrics `b` (of p0, p1, p2) of its triangle `j`,
// over the texture's mean: the closed forms take the light at its mean colour, and the shadow
// rays' ratio carries the texture's variation over the light. 1 for an untextured light.
// Twin: reference::texture_factor.
fn texture_factor(light: AreaLightGpu, j: u32, b: vec3<f32>) -> f32 {
    if light.range.w == 0u || 2u * j + 1u >= arrayLength(&area_uvs) || light.range.w > arrayLength(&materials) {
        return 1.0;
    }
    let m = materials[light.range.w - 1u];
    let layer = m.textures.w;
    if layer == NO_TEXTURE {
        return 1.0;
    }
    let a = area_uvs[2u * j];
    let c = area_uvs[2u * j + 1u];
    let uv = a.xy * b.x + a.zw * b.y + c.xy * b.z;
    let wrap = (m.more_textures.y >> 12u) & 15u;
    let t = textureSampleLevel(color_textures, texture_sampler, wrap_uv(uv, wrap, textureDimensions(color_textures)), layer, 0.0).rgb;
    return luminance(t) * c.z;
}

// Shadow ray `r` of the pixel towards the light of `key`: (its weight if unblocked, its
// weight), the ratio estimator's terms. Area lights: a point by area (a triangle by its share,
// the square-root warp), weighted by the unshadowed integrand cos cos / d^2, the unblocked
// term also by a textured emitter's texture there (texture_factor); point and spot
// lights: a point on a disc of the light's radius (its own, else the setting's) facing the
// surface, weight 1.
fn shadow_ray(key: u32, r: u32, pixel: vec2<u32>, origin: vec3<f32>, n: vec3<f32>) -> vec2<f32> {
    if (key & PUNCTUAL_KEY) != 0u {
        let light = lights[key & ~PUNCTUAL_KEY];
        let axis = normalize(light.position_range.xyz - origin);
        let t = orthonormal(axis);
        let b = cross(axis, t);
        let u = sample_2d(pixel, 64u + r);
        // The light's own radius, or the setting's where the scene gives none.
        let radius = select(params.values.y, light.spot.z, light.spot.z >= 0.0);
        let rho = radius * sqrt(u.x);
        let phi = 2.0 * PI * u.y;
        let p = light.position_range.xyz + rho * (cos(phi) * t + sin(phi) * b);
        let to_p = p - origin;
        let dist = length(to_p);
        let blocked = bvh_occluded(Ray(origin, 0.0, to_p / max(dist, 1e-6), dist * (1.0 - 1e-3)));
        return vec2<f32>(select(1.0, 0.0, blocked), 1.0);
    }
    let light = area_lights[key];
    let first = light.range.x;
    let last = first + light.range.y - 1u;
    let double_sided = (light.range.z & AREA_LIGHT_DOUBLE_SIDED) != 0u;
    let u = sample_2d(pixel, r);
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
    let hi = tri.p0_cdf.w;
    let ux = clamp((u.x - lo) / max(hi - lo, 1e-12), 0.0, 1.0);
    let su = sqrt(ux);
    let p = tri.p0_cdf.xyz * (1.0 - su) + tri.p1.xyz * (su * (1.0 - u.y)) + tri.p2.xyz * (su * u.y);
    let to_p = p - origin;
    let dist = length(to_p);
    if !(dist > 1e-6) {
        return vec2<f32>(0.0);
    }
    let dir = to_p / dist;
    let ng = normalize(cross(tri.p1.xyz - tri.p0_cdf.xyz, tri.p2.xyz - tri.p0_cdf.xyz));
    var cos_l = -dot(dir, ng);
    if double_sided {
        cos_l = abs(cos_l);
    }
    let w = max(dot(dir, n), 0.0) * max(cos_l, 0.0) / (dist * dist);
    if !(w > 0.0) {
        return vec2<f32>(0.0);
    }
    let blocked = bvh_occluded(Ray(origin, 0.0, dir, dist * (1.0 - 1e-3)));
    let f = texture_factor(light, j, vec3<f32>(1.0 - su, su * (1.0 - u.y), su * u.y));
    return vec2<f32>(select(w * f, 0.0, blocked), w);
}

// Stores `v` at entry `k` of `a` through a constant-bound loop (see insert_best).
fn put(a: ptr<function, array<f32, MAX_PER_PIXEL>>, k: u32, v: f32) {
    for (var j = 0u; j < MAX_PER_PIXEL; j++) {
        if j == k {
            (*a)[j] = v;
        }
    }
}

// Adds area light `i`'s unshadowed light to the sums; returns it: radiance (nits, rgb) and
// illuminance (lux, a), 0 where it brings none.
fn shade_area_light(i: u32, world: vec3<f32>, n: vec3<f32>, v: vec3<f32>, brdf: BrdfView) -> vec4<f32> {
    let light = area_lights[i];
    let double_sided = (light.range.z & AREA_LIGHT_DOUBLE_SIDED) != 0u;
    var f = vec3<f32>(0.0);
    for (var j = light.range.x; j < light.range.x + light.range.y; j++) {
        let tri = area_triangles[j];
        f += area_triangle_vector_irradiance(tri.p0_cdf.xyz, tri.p1.xyz, tri.p2.xyz, world, n, double_sided);
    }
    // Irradiance per unit radiance (sr): the light's projected solid angle.
    let e = dot(f, n);
    if !(e > 0.0) {
        return vec4<f32>(0.0);
    }
    let radiance = light.radiance_flux.rgb * e;
    let e_lux = luminance(radiance);
    lux += e_lux;
    // Diffuse lobes from the direction of the vector irradiance.
    let l_d = normalize(f);
    let w_d = brdf_light_weights(brdf, l_d) / max(dot(n, l_d), 1e-4);
    // Specular at the representative point: the reflected ray's hit of the light's mean plane,
    // pulled into the disc of the light's bounding radius; the lobe widened by the light's
    // size seen from the point, its peak lowered to keep its energy (Karis 2013).
    let c = light.centroid_radius.xyz;
    let radius = light.centroid_radius.w;
    let nl = light.normal_area.xyz;
    let r = reflect(-v, n);
    var p = c;
    let denom = dot(r, nl);
    if length(nl) > 0.1 && abs(denom) > 1e-6 {
        let t = dot(c - world, nl) / denom;
        if t > 0.0 {
            p = world + r * t;
        }
    }
    var off = p - c;
    if length(nl) > 0.1 {
        off -= normalize(nl) * dot(off, normalize(nl));
    }
    let lo = length(off);
    if lo > radius {
        off *= radius / lo;
    }
    var l_s = normalize(c + off - world);
    if dot(l_s, n) <= 1e-4 {
        l_s = l_d;
    }
    let alpha = sqrt(brdf.alphas.x * brdf.alphas.y);
    let size = sqrt(light.normal_area.w / PI) / max(length(c - world), 1e-4);
    let widened = min(alpha + 0.5 * size, 1.0);
    let norm = (alpha / widened) * (alpha / widened);
    let w_s = brdf_light_weights(brdf, l_s) * (norm / max(dot(n, l_s), 1e-4));
    let w = vec4<f32>(w_s.x, w_s.y, w_d.z, w_d.w);
    add_light(w, radiance);
    let unshadowed = brdf_apply_weights(brdf, radiance * w.x, radiance * w.y, radiance * w.z, radiance * w.w);
    return vec4<f32>(unshadowed, e_lux);
}

fn shade(pixel: vec2<u32>, d: f32) -> vec3<f32> {
    let world = world_from_depth(view, pixel, d);
    let to_eye = view.position.xyz - world;
    let v = normalize(to_eye);
    let nt = textureLoad(gbuffer_normal, pixel, 0);
    let n = oct_decode(nt.xy);
    let ta = oct_decode(nt.zw);
    let t = normalize(ta - n * dot(n, ta));
    let b = cross(n, t);
    let albedo = textureLoad(gbuffer_albedo, pixel, 0);
    let mat = textureLoad(gbuffer_material, pixel, 0);
    let m = BrdfMaterial(albedo.rgb, mat.x, mat.y, mat.z, textureLoad(gbuffer_emissive, pixel, 0).a);
    let brdf = brdf_view(m, n, t, b, v);
    // Off the surface by a thousandth of the distance to the eye (and a millimetre), which the
    // depth buffer's reconstruction error stays well under.
    let origin = world + n * (1e-3 + 1e-3 * length(to_eye));
    sums = Sums(vec3<f32>(0.0), vec3<f32>(0.0), vec3<f32>(0.0), vec3<f32>(0.0));
    lux = 0.0;
    let flags = params.config.y;
    // The picks for the shadow rays (see place), the sum W of the lights' weights, and the
    // area lights' unshadowed light by slot (the walk of the picks reads it again).
    var keys: array<u32, MAX_PER_PIXEL>;
    var ratios: array<vec4<f32>, MAX_PER_PIXEL>;
    var area_light: array<vec4<f32>, MAX_PER_PIXEL>;
    var total = 0.0;
    for (var k = 0u; k < MAX_PER_PIXEL; k++) {
        keys[k] = NONE;
        ratios[k] = vec4<f32>(0.0);
        area_light[k] = vec4<f32>(0.0);
    }
    var sel: array<u32, MAX_PER_PIXEL>;
    var keep = 0u;

    if (flags & AREA_POLYGONS) != 0u {
        // The lights of largest flux / distance^2 here, at most counts.y, largest first.
        var score: array<f32, MAX_PER_PIXEL>;
        keep = min(params.counts.y, MAX_PER_PIXEL);
        for (var k = 0u; k < MAX_PER_PIXEL; k++) {
            sel[k] = NONE;
            score[k] = 0.0;
        }
        let listed = min(tile_counts.y, TILE_LIGHTS);
        for (var t = 0u; t < listed; t++) {
            let i = tile_area[t];
            let light = area_lights[i];
            let to_c = light.centroid_radius.xyz - world;
            let r = light.centroid_radius.w;
            // Wholly below the horizon; or out of reach or behind at this very point.
            if dot(to_c, n) < -r || !area_light_reaches(i, world, world) {
                continue;
            }
            insert_best(&sel, &score, keep, i, light.radiance_flux.w / max(dot(to_c, to_c), r * r));
        }
        for (var k = 0u; k < keep; k++) {
            let id = pick(&sel, k);
            if id == NONE {
                break;
            }
            let c = shade_area_light(id, world, n, v, brdf);
            total += luminance(c.rgb);
            put4(&area_light, k, c);
        }
    }

    if (flags & AREA_PUNCTUAL) != 0u {
        let listed = min(tile_counts.x, TILE_LIGHTS);
        for (var t = 0u; t < listed; t++) {
            let i = tile_punctual[t];
            let light = lights[i];
            let to_light = light.position_range.xyz - world;
            let d2 = dot(to_light, to_light);
            let l = to_light * inverseSqrt(max(d2, 1e-8));
            let e = light.intensity.rgb * punctual_attenuation(light, l, d2);
            if !(luminance(e) > 0.0) {
                continue;
            }
            let e_lux = luminance(e) * max(dot(n, l), 0.0);
            lux += e_lux;
            let w = brdf_light_weights(brdf, l);
            add_light(w, e);
            total += luminance(brdf_apply_weights(brdf, e * w.x, e * w.y, e * w.z, e * w.w));
        }
    }

    // Without rays (or where no light brings radiance), the unshadowed sum.
    var radiance = brdf_apply_weights(brdf, sums.a, sums.b, sums.c, sums.d);
    unshadowed = vec4<f32>(radiance, lux);
    // The shadows: `picks` lights picked by systematic sampling of their weights (see place),
    // each pick's rays (the budget split over the picks), its visibility the ratio estimator
    // over all the rays that went to the same light, and the pixel's light
    // W / picks x sum over picks of visibility x (light / weight): unbiased in the selection,
    // never negative, and of exact luminance where the picked lights are wholly visible (the
    // weights are the lights' luminances; only the colour varies with the picks).
    let picks = params.counts.z;
    if picks > 0u && total > 0.0 {
        // The walk of the picks: the same lights in the same order, the area lights' light as
        // stored, the point and spot lights' computed again as above.
        let step = total / f32(picks);
        let offset = pick_offset(pixel);
        var cum = 0.0;
        var last = vec4<f32>(0.0);
        var last_key = NONE;
        for (var k = 0u; k < keep; k++) {
            let id = pick(&sel, k);
            if id == NONE {
                break;
            }
            place(&keys, &ratios, &cum, &last, &last_key, step, offset, id, get4(&area_light, k));
        }
        if (flags & AREA_PUNCTUAL) != 0u {
            let listed = min(tile_counts.x, TILE_LIGHTS);
            for (var t = 0u; t < listed; t++) {
                let i = tile_punctual[t];
                let light = lights[i];
                let to_light = light.position_range.xyz - world;
                let d2 = dot(to_light, to_light);
                let l = to_light * inverseSqrt(max(d2, 1e-8));
                let e = light.intensity.rgb * punctual_attenuation(light, l, d2);
                if !(luminance(e) > 0.0) {
                    continue;
                }
                let w = brdf_light_weights(brdf, l);
                let c = brdf_apply_weights(brdf, e * w.x, e * w.y, e * w.z, e * w.w);
                place(&keys, &ratios, &cum, &last, &last_key, step, offset, i | PUNCTUAL_KEY, vec4<f32>(c, luminance(e) * max(dot(n, l), 0.0)));
            }
        }
        for (var k = 0u; k < MAX_PER_PIXEL; k++) {
            if k < picks && keys[k] == NONE {
                keys[k] = last_key;
                ratios[k] = last;
            }
        }
        var num: array<f32, MAX_PER_PIXEL>;
        var den: array<f32, MAX_PER_PIXEL>;
        for (var k = 0u; k < MAX_PER_PIXEL; k++) {
            num[k] = 0.0;
            den[k] = 0.0;
        }
        let each = params.counts.x / picks;
        let extra = params.counts.x % picks;
        for (var s = 0u; s < picks; s++) {
            let key = pick(&keys, s);
            if key == NONE {
                continue;
            }
            let first = s * each + min(s, extra);
            let rays = each + select(0u, 1u, s < extra);
            var nd = vec2<f32>(0.0);
            for (var r = first; r < first + rays; r++) {
                nd += shadow_ray(key, r, pixel, origin, n);
            }
            put(&num, s, nd.x);
            put(&den, s, nd.y);
        }
        var shadowed = vec4<f32>(0.0);
        for (var s = 0u; s < MAX_PER_PIXEL; s++) {
            if s < picks && keys[s] != NONE {
                var nn = 0.0;
                var dd = 0.0;
                for (var q = 0u; q < MAX_PER_PIXEL; q++) {
                    if q < picks && keys[q] == keys[s] {
                        nn += num[q];
                        dd += den[q];
                    }
                }
                let vis = select(1.0, nn / dd, dd > 0.0);
                shadowed += vis * ratios[s];
            }
        }
        shadowed *= total / f32(picks);
        radiance = shadowed.rgb;
        lux = shadowed.a;
    }
    return radiance;
}

@compute @workgroup_size(16, 16, 1)
fn main(
    @builtin(global_invocation_id) gid: vec3<u32>,
    @builtin(local_invocation_index) lid: u32,
) {
    let size = textureDimensions(out_radiance);
    let pixel = gid.xy;
    let inside = all(pixel < size);
    // No lights this frame (a uniform branch, before any barrier).
    if params.config.y == 0u {
        if inside {
            textureStore(out_radiance, pixel, vec4<f32>(0.0));
            textureStore(out_unshadowed, pixel, vec4<f32>(0.0));
        }
        return;
    }
    var d = 0.0;
    var lo = vec3<f32>(TILE_BOUNDS_FAR);
    var hi = vec3<f32>(-TILE_BOUNDS_FAR);
    if inside {
        d = textureLoad(depth, pixel, 0).r;
        if d > 0.0 {
            lo = world_from_depth(view, pixel, d);
            hi = lo;
        }
    }
    cull_lights(lid, tile_bounds(lid, lo, hi));
    let listed = workgroupUniformLoad(&tile_counts);
    if !inside {
        return;
    }
    var radiance = vec3<f32>(0.0);
    lux = 0.0;
    unshadowed = vec4<f32>(0.0);
    // Tiles no light reaches (and the sky) skip the shading.
    if d > 0.0 && listed.x + listed.y > 0u {
        radiance = shade(pixel, d);
    }
    // NaN fails every comparison, so this also turns NaN into 0.
    let out = vec4<f32>(radiance, lux);
    textureStore(out_radiance, pixel, select(vec4<f32>(0.0), min(out, vec4<f32>(MAX_RADIANCE)), out >= vec4<f32>(0.0)));
    textureStore(out_unshadowed, pixel, select(vec4<f32>(0.0), min(unshadowed, vec4<f32>(MAX_RADIANCE)), unshadowed >= vec4<f32>(0.0)));
}
