// particles.draw: camera-facing fog sprites composited over the hazed image, back to front
// (premultiplied: colour alpha L T, then the image times 1 - alpha), a thread a pixel. A
// 16 x 16 tile first marks, in a bit mask, the sprites whose screen rectangles (from the CPU)
// overlap it and that come nearer than its farthest surface; each pixel then meets the marked sprites' planes in index order, which is back to
// front. A haze-lit sprite takes the haze's froxel light L_i where the pixel's ray meets it (the
// talk's "haze lighting" mode: the light the haze pass computed, phase, shadows, sky visibility
// and local lights included), bicubic in x and y once its opacity passes `bicubic_opacity`,
// scaled by the talk's multiple-scattering term; a standard sprite the sun's light through an
// isotropic phase plus the sky's mean radiance, times its albedo. T is the haze's transmittance
// from the camera to the sprite. Compute rather than a raster pass with blending: on the H200
// the blended quads of the pond's mist took 5.4 ms at 2560x1440.
// Twin: `particles::reference::composite_pixel`.

#import hikari::view::{View, view_ray, world_from_depth}
#import hikari::haze::{HazeParams, optical_depth, opacity, slice_of_depth, bspline_axis}

struct ParticleGpu {
    // xyz: centre (world, m); w: radius (m).
    position_radius: vec4<f32>,
    // rgb: albedo (standard lighting); a: opacity, negative for a haze-lit particle.
    albedo_opacity: vec4<f32>,
    // The pixels it may cover: x0, y0, x1, y1 (inclusive; x0 > x1 when none).
    rect: vec4<f32>,
}

struct ParticleParams {
    // rgb: the sun's or moon's illuminance (lux) for standard lighting; w: 1 with the haze's
    // light to read, else 0.
    sun_lux: vec4<f32>,
    // xyz: unit vector towards the sun or moon; w: opacity above which the light is bicubic.
    sun_dir: vec4<f32>,
    // rgb: the sky's mean radiance (nits); w: soft-particle depth fade, a fraction of the radius.
    sky: vec4<f32>,
    // x: multiple-scattering ratio with the eye on the light's side (v.l = 1), y: with the eye
    // facing the light (v.l = -1); z: 1 / (the haze light's storage scale times its albedo);
    // w: 1 with haze (its extinction dims the sprite), else 0.
    ms: vec4<f32>,
    // x: sprites.
    count: vec4<u32>,
}

@group(0) @binding(0) var<uniform> view: View;
@group(0) @binding(1) var<uniform> params: ParticleParams;
@group(0) @binding(2) var<uniform> haze: HazeParams;
@group(0) @binding(3) var<storage, read> particles: array<ParticleGpu>;
@group(0) @binding(4) var depth_tex: texture_2d<f32>;
@group(0) @binding(5) var haze_light: texture_3d<f32>;
@group(0) @binding(6) var linear_sampler: sampler;
@group(0) @binding(7) var image_in: texture_2d<f32>;
@group(0) @binding(8) var image_out: texture_storage_2d<rgba16float, write>;

const PI: f32 = 3.14159265358979;
const TILE: u32 = 16u;
// Sprites marked per batch: the mask's 128 words.
const BATCH: u32 = 4096u;

var<workgroup> mask: array<atomic<u32>, 128>;
// The farthest surface in the tile (metres, as bits: non-negative floats order as integers):
// a sprite wholly beyond it is hidden in every pixel of the tile.
var<workgroup> tile_far: atomic<u32>;

// The haze light (L_i times the storage scale and albedo) at screen position uv, slice s:
// trilinear, or a B-spline in x and y (4 trilinear taps) for opaque sprites.
fn haze_light_at(uv: vec2<f32>, s: f32, bicubic: bool) -> vec3<f32> {
    let w = s / f32(haze.grid.z);
    if !bicubic {
        return textureSampleLevel(haze_light, linear_sampler, vec3<f32>(uv, w), 0.0).rgb;
    }
    let ax = bspline_axis(uv.x, f32(haze.grid.x));
    let ay = bspline_axis(uv.y, f32(haze.grid.y));
    var acc = vec3<f32>(0.0);
    for (var y = 0u; y < 2u; y++) {
        for (var x = 0u; x < 2u; x++) {
            let t = textureSampleLevel(haze_light, linear_sampler, vec3<f32>(ax.pos[x], ay.pos[y], w), 0.0).rgb;
            acc += t * (ax.weight[x] * ay.weight[y]);
        }
    }
    return acc;
}

// One sprite at the pixel whose ray from the camera is `ray` and whose surface lies `surface`
// metres away (a large number for the sky): premultiplied colour and alpha, alpha 0 where it
// does not cover the pixel.
fn sprite_at(p: ParticleGpu, pixel: vec2<u32>, ray: vec3<f32>, surface: f32) -> vec4<f32> {
    let cam = view.position.xyz;
    let centre = p.position_radius.xyz;
    let radius = p.position_radius.w;
    // Facing the camera: the plane through the centre normal to the line of sight.
    let to_eye = cam - centre;
    let f = select(view.forward_near.xyz, -normalize(to_eye), dot(to_eye, to_eye) > 1e-8);
    let denom = dot(ray, f);
    if denom <= 1e-6 {
        return vec4<f32>(0.0);
    }
    let up_hint = select(vec3<f32>(0.0, 1.0, 0.0), vec3<f32>(1.0, 0.0, 0.0), abs(f.y) > 0.99);
    let right = normalize(cross(f, up_hint));
    let up = cross(right, f);
    let dist = dot(centre - cam, f) / denom;
    let d = ray * dist;
    let offset = cam + d - centre;
    let corner = vec2<f32>(dot(offset, right), dot(offset, up)) / radius;
    let r2 = dot(corner, corner);
    if r2 >= 1.0 {
        return vec4<f32>(0.0);
    }
    // A soft puff: (1 - r^2)^2 of the sprite's opacity, faded before the surface behind it
    // and after the near plane.
    let haze_lit = p.albedo_opacity.a < 0.0;
    let peak = abs(p.albedo_opacity.a);
    var alpha = peak * (1.0 - r2) * (1.0 - r2);
    alpha *= clamp((surface - dist) / max(params.sky.w * radius, 1e-4), 0.0, 1.0);
    alpha *= clamp((dist - view.forward_near.w) / max(radius, 1e-4), 0.0, 1.0);
    if !(alpha > 1e-4) {
        return vec4<f32>(0.0);
    }
    var light: vec3<f32>;
    if haze_lit && params.sun_lux.w > 0.0 {
        let uv = (vec2<f32>(pixel) + 0.5) * view.viewport.zw;
        let s = slice_of_depth(haze, dot(d, view.forward_near.xyz));
        light = haze_light_at(uv, s, peak > params.sun_dir.w) * params.ms.z;
        // The talk's multiple scattering: the ratio of a back-scattering phase to the haze's,
        // between the eye on the light's side and the eye facing it, towards 1 as the sprite
        // thins.
        let ms = mix(params.ms.y, params.ms.x, 0.5 - 0.5 * dot(ray, params.sun_dir.xyz));
        light *= mix(1.0, ms, peak);
    } else {
        light = p.albedo_opacity.rgb * (params.sun_lux.rgb / (4.0 * PI) + params.sky.rgb);
    }
    let t = select(1.0, 1.0 - opacity(optical_depth(haze, cam, ray, dist)), params.ms.w > 0.0);
    var c = light * (alpha * t);
    // NaN fails the comparison: nothing non-finite reaches the image.
    c = select(vec3<f32>(0.0), min(c, vec3<f32>(65000.0)), c >= vec3<f32>(0.0));
    return vec4<f32>(c, alpha);
}

@compute @workgroup_size(16, 16, 1)
fn main(
    @builtin(global_invocation_id) gid: vec3<u32>,
    @builtin(workgroup_id) wid: vec3<u32>,
    @builtin(local_invocation_index) lid: u32,
) {
    let size = vec2<u32>(view.viewport.xy);
    let pixel = gid.xy;
    let inside = all(pixel < size);
    let tile_lo = vec2<f32>(wid.xy * TILE);
    let tile_hi = tile_lo + f32(TILE - 1u);

    var colour = vec3<f32>(0.0);
    var ray = vec3<f32>(0.0, 0.0, 1.0);
    var surface = 3.0e38;
    if inside {
        let raw = textureLoad(image_in, pixel, 0).rgb;
        colour = select(vec3<f32>(0.0), raw, (raw >= vec3<f32>(0.0)) & (raw <= vec3<f32>(3.0e38)));
        ray = view_ray(view, pixel);
        let depth = textureLoad(depth_tex, pixel, 0).r;
        // NaN fails the comparison: such a pixel is taken as the sky.
        if depth > 0.0 && depth <= 3.0e38 {
            surface = length(world_from_depth(view, pixel, depth) - view.position.xyz);
        }
    }
    if lid == 0u {
        atomicStore(&tile_far, 0u);
    }
    workgroupBarrier();
    if inside {
        atomicMax(&tile_far, bitcast<u32>(min(surface, 3.0e38)));
    }
    workgroupBarrier();
    let far = bitcast<f32>(atomicLoad(&tile_far));
    let cam = view.position.xyz;
    let count = params.count.x;
    for (var base = 0u; base < count; base += BATCH) {
        if lid < 128u {
            atomicStore(&mask[lid], 0u);
        }
        workgroupBarrier();
        let n = min(count - base, BATCH);
        for (var i = lid; i < n; i += TILE * TILE) {
            let p = particles[base + i];
            let r = p.rect;
            let near = length(p.position_radius.xyz - cam) - p.position_radius.w;
            if r.x <= tile_hi.x && r.z >= tile_lo.x && r.y <= tile_hi.y && r.w >= tile_lo.y && near < far {
                atomicOr(&mask[i / 32u], 1u << (i % 32u));
            }
        }
        workgroupBarrier();
        if inside {
            let words = (n + 31u) / 32u;
            for (var w = 0u; w < words; w++) {
                var bits = atomicLoad(&mask[w]);
                while bits != 0u {
                    let b = firstTrailingBit(bits);
                    bits &= bits - 1u;
                    let s = sprite_at(particles[base + w * 32u + b], pixel, ray, surface);
                    colour = s.rgb + colour * (1.0 - s.a);
                }
            }
        }
        workgroupBarrier();
    }
    if inside {
        let a = textureLoad(image_in, pixel, 0).a;
        textureStore(image_out, pixel, vec4<f32>(colour, select(1.0, a, a == a)));
    }
}
