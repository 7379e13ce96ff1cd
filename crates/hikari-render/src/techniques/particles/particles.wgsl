// particles.draw: camera-facing fog sprites blended over the hazed image, back to front
// (premultiplied: colour alpha L T, then the image times 1 - alpha). A haze-lit particle takes
// the haze's froxel light L_i at its fragment (the talk's "haze lighting" mode: the light the
// haze pass computed, phase, shadows, sky visibility and local lights included), bicubic in
// x and y once its opacity passes `bicubic_opacity`, scaled by the talk's multiple-scattering
// term; a standard particle the sun's light through an isotropic phase plus the sky's mean
// radiance, times its albedo. T is the haze's transmittance from the camera to the fragment.
// Twin: `particles::reference::fragment`.

#import hikari::view::View
#import hikari::haze::{HazeParams, optical_depth, opacity, slice_of_depth, bspline_axis}

struct ParticleGpu {
    // xyz: centre (world, m); w: radius (m).
    position_radius: vec4<f32>,
    // rgb: albedo (standard lighting); a: opacity, negative for a haze-lit particle.
    albedo_opacity: vec4<f32>,
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
}

@group(0) @binding(0) var<uniform> view: View;
@group(0) @binding(1) var<uniform> params: ParticleParams;
@group(0) @binding(2) var<uniform> haze: HazeParams;
@group(0) @binding(3) var<storage, read> particles: array<ParticleGpu>;
@group(0) @binding(4) var depth_tex: texture_2d<f32>;
@group(0) @binding(5) var haze_light: texture_3d<f32>;
@group(0) @binding(6) var linear_sampler: sampler;

const PI: f32 = 3.14159265358979;

struct VsOut {
    @builtin(position) clip: vec4<f32>,
    // Sprite coordinates, -1 to 1 across its radius.
    @location(0) corner: vec2<f32>,
    @location(1) @interpolate(flat) index: u32,
    @location(2) world: vec3<f32>,
}

@vertex
fn vs(@builtin(vertex_index) v: u32, @builtin(instance_index) i: u32) -> VsOut {
    let p = particles[i];
    // Two triangles: corners (-1,-1) (1,-1) (1,1) and (-1,-1) (1,1) (-1,1).
    var corners = array<vec2<f32>, 6>(
        vec2<f32>(-1.0, -1.0), vec2<f32>(1.0, -1.0), vec2<f32>(1.0, 1.0),
        vec2<f32>(-1.0, -1.0), vec2<f32>(1.0, 1.0), vec2<f32>(-1.0, 1.0),
    );
    let c = corners[v];
    let centre = p.position_radius.xyz;
    // Facing the camera: the plane through the centre normal to the line of sight.
    let to_eye = view.position.xyz - centre;
    let f = select(view.forward_near.xyz, -normalize(to_eye), dot(to_eye, to_eye) > 1e-8);
    let up_hint = select(vec3<f32>(0.0, 1.0, 0.0), vec3<f32>(1.0, 0.0, 0.0), abs(f.y) > 0.99);
    let right = normalize(cross(f, up_hint));
    let up = cross(right, f);
    let world = centre + (right * c.x + up * c.y) * p.position_radius.w;
    var out: VsOut;
    out.clip = view.view_proj * vec4<f32>(world, 1.0);
    out.corner = c;
    out.index = i;
    out.world = world;
    return out;
}

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

@fragment
fn fs(in: VsOut) -> @location(0) vec4<f32> {
    let p = particles[in.index];
    let r2 = dot(in.corner, in.corner);
    if r2 >= 1.0 {
        discard;
    }
    // A soft puff: (1 - r^2)^2 of the sprite's opacity.
    let falloff = (1.0 - r2) * (1.0 - r2);
    let haze_lit = p.albedo_opacity.a < 0.0;
    let peak = abs(p.albedo_opacity.a);
    var alpha = peak * falloff;
    let cam = view.position.xyz;
    let d = in.world - cam;
    let dist = length(d);
    let v = d / max(dist, 1e-6);
    // Soft particles: fade where the sprite nears the surface behind it.
    let pixel = vec2<u32>(in.clip.xy);
    let depth = textureLoad(depth_tex, pixel, 0).r;
    if depth > 0.0 {
        let ndc = vec4<f32>(in.clip.x * view.viewport.z * 2.0 - 1.0, 1.0 - in.clip.y * view.viewport.w * 2.0, depth, 1.0);
        let s = view.inv_view_proj * ndc;
        let surface = length(s.xyz / s.w - cam);
        alpha *= clamp((surface - dist) / max(params.sky.w * p.position_radius.w, 1e-4), 0.0, 1.0);
    }
    // And near the camera, rather than cutting it at the near plane.
    alpha *= clamp((dist - view.forward_near.w) / max(p.position_radius.w, 1e-4), 0.0, 1.0);
    if !(alpha > 1e-4) {
        discard;
    }
    let to_eye_dot_l = dot(-v, params.sun_dir.xyz);
    var light: vec3<f32>;
    if haze_lit && params.sun_lux.w > 0.0 {
        let uv = in.clip.xy * view.viewport.zw;
        let s = slice_of_depth(haze, dot(d, view.forward_near.xyz));
        light = haze_light_at(uv, s, peak > params.sun_dir.w) * params.ms.z;
        // The talk's multiple scattering: the ratio of a back-scattering phase to the haze's,
        // between the eye on the light's side and the eye facing it, towards 1 as the sprite
        // thins.
        let ms = mix(params.ms.y, params.ms.x, 0.5 + 0.5 * to_eye_dot_l);
        light *= mix(1.0, ms, peak);
    } else {
        light = p.albedo_opacity.rgb * (params.sun_lux.rgb / (4.0 * PI) + params.sky.rgb);
    }
    let t = select(1.0, 1.0 - opacity(optical_depth(haze, cam, v, dist)), params.ms.w > 0.0);
    var c = light * (alpha * t);
    // NaN fails the comparison: nothing non-finite reaches the image.
    c = select(vec3<f32>(0.0), min(c, vec3<f32>(65000.0)), c >= vec3<f32>(0.0));
    return vec4<f32>(c, alpha);
}
