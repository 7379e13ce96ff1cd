#define_import_path hikari::view

#import hikari::finite::is_finite3

// The camera of the frame. Reverse-Z with an infinite far plane: depth 1 at the near plane,
// 0 at infinity (the cleared value, so depth 0 means "sky").
struct View {
    view_proj: mat4x4<f32>,
    inv_view_proj: mat4x4<f32>,
    // xyz: camera position in metres; w unused.
    position: vec4<f32>,
    // width, height, 1 / width, 1 / height in pixels.
    viewport: vec4<f32>,
    // Last frame's view-projection, for motion vectors.
    prev_view_proj: mat4x4<f32>,
    // xyz: unit forward; w: near plane distance in metres.
    forward_near: vec4<f32>,
    // xy: this frame's sub-pixel jitter in pixels (x right, y down), already in view_proj
    // (prev_view_proj has none); zw unused.
    jitter: vec4<f32>,
}

// World position of the pixel centre `pixel` at reverse-Z depth `depth`.
fn world_from_depth(view: View, pixel: vec2<u32>, depth: f32) -> vec3<f32> {
    let uv = (vec2<f32>(pixel) + 0.5) * view.viewport.zw;
    let ndc = vec4<f32>(uv.x * 2.0 - 1.0, 1.0 - uv.y * 2.0, depth, 1.0);
    let w = view.inv_view_proj * ndc;
    return w.xyz / w.w;
}

// Unit direction from the camera through the pixel centre (valid at depth 0 too).
fn view_ray(view: View, pixel: vec2<u32>) -> vec3<f32> {
    return view_ray_uv(view, (vec2<f32>(pixel) + 0.5) * view.viewport.zw);
}

// Unit direction from the camera through the normalised screen position `uv` (0..1, y down).
fn view_ray_uv(view: View, uv: vec2<f32>) -> vec3<f32> {
    // A point on the near plane, which reverse-Z puts at depth 1.
    let near = view.inv_view_proj * vec4<f32>(uv.x * 2.0 - 1.0, 1.0 - uv.y * 2.0, 1.0, 1.0);
    return normalize(near.xyz / near.w - view.position.xyz);
}

// The smallest summed weight of the valid bilinear taps that a reprojected history needs.
const REPROJECTION_MIN_WEIGHT: f32 = 0.01;
// A bilinear fraction within this of 0 or 1 (pixels) snaps to it: a still camera's motion
// vectors carry rounding (of the order of 1e-3 pixel), which would otherwise blend a little
// of each neighbour into the history every frame.
const REPROJECTION_SNAP: f32 = 0.015625;

// Last frame's images at `pixel`'s surface, bilinearly: the 2x2 texels about
// `pixel + 0.5 + motion.xy` from `base` (`reprojection_tap` gives each); `valid` false where the motion or the point is not finite, or
// the position is off screen. A still camera (motion 0) has one tap of weight 1.
struct Reprojection {
    base: vec2<i32>,
    frac: vec2<f32>,
    // The texel nearest the position.
    nearest: vec2<i32>,
    valid: bool,
}

fn reprojection(pixel: vec2<u32>, motion: vec3<f32>, world: vec3<f32>, size: vec2<u32>) -> Reprojection {
    var r: Reprojection;
    let prev = vec2<f32>(pixel) + 0.5 + motion.xy;
    r.valid = is_finite3(motion) && is_finite3(world) && all(prev >= vec2<f32>(0.0)) && all(prev < vec2<f32>(size));
    if !r.valid {
        return r;
    }
    let b = floor(prev - 0.5);
    r.base = vec2<i32>(b);
    let f = prev - 0.5 - b;
    r.frac = select(f, round(f), abs(f - round(f)) < vec2<f32>(REPROJECTION_SNAP));
    r.nearest = vec2<i32>(prev);
    return r;
}

// Tap k (0 to 3) of a valid Reprojection: texel base + (k & 1, k >> 1) and its bilinear
// weight, 0 where the texel lies off an image of `size`.
struct ReprojectionTap {
    texel: vec2<u32>,
    weight: f32,
}

fn reprojection_tap(r: Reprojection, k: u32, size: vec2<u32>) -> ReprojectionTap {
    var tap: ReprojectionTap;
    let t = r.base + vec2<i32>(i32(k & 1u), i32(k >> 1u));
    if any(t < vec2<i32>(0)) || any(t >= vec2<i32>(size)) {
        return tap;
    }
    let wx = select(1.0 - r.frac.x, r.frac.x, (k & 1u) != 0u);
    let wy = select(1.0 - r.frac.y, r.frac.y, (k & 2u) != 0u);
    tap.texel = vec2<u32>(t);
    tap.weight = wx * wy;
    return tap;
}

// Whether a history texel's view depth `hz` is where `world` was seen last frame, within
// `tolerance` (a fraction of that depth): the temporal passes' disocclusion test. NaN fails.
fn history_depth_agrees(view: View, world: vec3<f32>, hz: f32, tolerance: f32) -> bool {
    let expected = (view.prev_view_proj * vec4<f32>(world, 1.0)).w;
    return abs(hz - expected) <= tolerance * abs(expected);
}
