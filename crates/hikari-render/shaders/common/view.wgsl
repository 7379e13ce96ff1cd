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
    let uv = (vec2<f32>(pixel) + 0.5) * view.viewport.zw;
    // A point on the near plane, which reverse-Z puts at depth 1.
    let near = view.inv_view_proj * vec4<f32>(uv.x * 2.0 - 1.0, 1.0 - uv.y * 2.0, 1.0, 1.0);
    return normalize(near.xyz / near.w - view.position.xyz);
}

// The texel of last frame's images that holds `pixel`'s surface, by the G-buffer's motion
// (xy in pixels, z the view depth) and the surface's world position: none (-1) where either is
// not finite or the texel is off screen. The temporal passes' reprojection (nearest texel).
fn reprojected_texel(pixel: vec2<u32>, motion: vec3<f32>, world: vec3<f32>, size: vec2<u32>) -> vec2<i32> {
    let prev = vec2<f32>(pixel) + 0.5 + motion.xy;
    if !is_finite3(motion) || !is_finite3(world) || any(prev < vec2<f32>(0.0)) || any(prev >= vec2<f32>(size)) {
        return vec2<i32>(-1);
    }
    return vec2<i32>(prev);
}

// Whether a history texel's view depth `hz` is where `world` was seen last frame, within
// `tolerance` (a fraction of that depth): the temporal passes' disocclusion test. NaN fails.
fn history_depth_agrees(view: View, world: vec3<f32>, hz: f32, tolerance: f32) -> bool {
    let expected = (view.prev_view_proj * vec4<f32>(world, 1.0)).w;
    return abs(hz - expected) <= tolerance * abs(expected);
}
