// The wide Gaussian upsampled from 64x32 to 256x128 with the cubic B-spline (16 taps, edges
// clamped): smooth where bilinear would show the coarse texels, and a little more blur. The
// homogeneous pair is filtered, then divided: log2 luminance relative to the grid's lower end.

#import hikari::local_tonemap::{LocalTonemapParams}

@group(0) @binding(0) var<uniform> params: LocalTonemapParams;
@group(0) @binding(1) var src: texture_2d<f32>;
@group(0) @binding(2) var dst: texture_storage_2d<r32float, write>;

fn bspline(t: f32) -> vec4<f32> {
    let t2 = t * t;
    let t3 = t2 * t;
    return vec4<f32>(
        (1.0 - t) * (1.0 - t) * (1.0 - t),
        3.0 * t3 - 6.0 * t2 + 4.0,
        -3.0 * t3 + 3.0 * t2 + 3.0 * t + 1.0,
        t3,
    ) / 6.0;
}

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let out_size = textureDimensions(dst);
    if any(id.xy >= out_size) {
        return;
    }
    let src_size = vec2<i32>(textureDimensions(src));
    let pos = (vec2<f32>(id.xy) + 0.5) * vec2<f32>(src_size) / vec2<f32>(out_size) - 0.5;
    let base = floor(pos);
    let wx = bspline(pos.x - base.x);
    let wy = bspline(pos.y - base.y);
    var sum = vec2<f32>(0.0);
    for (var j = 0; j < 4; j++) {
        for (var i = 0; i < 4; i++) {
            let q = clamp(vec2<i32>(base) + vec2<i32>(i - 1, j - 1), vec2<i32>(0), src_size - 1);
            sum += wx[i] * wy[j] * textureLoad(src, q, 0).xy;
        }
    }
    let v = select(params.tone.w - params.grid.x, sum.x / sum.y, sum.y > 0.0);
    textureStore(dst, id.xy, vec4<f32>(v, 0.0, 0.0, 0.0));
}
