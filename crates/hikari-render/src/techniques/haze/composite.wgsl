// haze.composite: each pixel's radiance seen through the haze. With density anti-aliasing the
// pixel's own opacity is recomputed in closed form along its ray and multiplies the grid's
// L / alpha; the grid is read with a tricubic B-spline as 8 trilinear taps (Sigg and Hadwiger
// 2005). Twin: `haze::reference::composite_pixel`.

#import hikari::view::{View, view_ray, world_from_depth}
#import hikari::haze::{HazeParams, HAZE_DENSITY_AA, HAZE_TRICUBIC, optical_depth, opacity, slice_of_depth, bspline_axis}

@group(0) @binding(0) var<uniform> view: View;
@group(0) @binding(1) var<uniform> params: HazeParams;
@group(0) @binding(2) var depth_tex: texture_2d<f32>;
@group(0) @binding(3) var lit_tex: texture_2d<f32>;
@group(0) @binding(4) var grid: texture_3d<f32>;
@group(0) @binding(5) var grid_sampler: sampler;
@group(0) @binding(6) var out_tex: texture_storage_2d<rgba16float, write>;

fn sample_grid(uvw: vec3<f32>, tricubic: bool) -> vec4<f32> {
    if !tricubic {
        return textureSampleLevel(grid, grid_sampler, uvw, 0.0);
    }
    let size = vec3<f32>(params.grid.xyz);
    let ax = bspline_axis(uvw.x, size.x);
    let ay = bspline_axis(uvw.y, size.y);
    let az = bspline_axis(uvw.z, size.z);
    var acc = vec4<f32>(0.0);
    for (var z = 0u; z < 2u; z++) {
        for (var y = 0u; y < 2u; y++) {
            for (var x = 0u; x < 2u; x++) {
                let p = vec3<f32>(ax.pos[x], ay.pos[y], az.pos[z]);
                acc += textureSampleLevel(grid, grid_sampler, p, 0.0) * (ax.weight[x] * ay.weight[y] * az.weight[z]);
            }
        }
    }
    return acc;
}

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = vec2<u32>(view.viewport.xy);
    if any(id.xy >= size) {
        return;
    }
    let uv = (vec2<f32>(id.xy) + 0.5) * view.viewport.zw;
    let v = view_ray(view, id.xy);
    let cam = view.position.xyz;
    let fwd = view.forward_near.xyz;
    let far = params.scatter.w;
    var dist = far;
    var z = far * max(dot(v, fwd), 1e-4);
    let depth = textureLoad(depth_tex, id.xy, 0).r;
    // NaN fails the comparison: such a pixel is taken as the sky.
    if depth > 0.0 && depth <= 3.0e38 {
        let d = world_from_depth(view, id.xy, depth) - cam;
        let l = length(d);
        if l < far {
            dist = l;
            z = dot(d, fwd);
        }
    }
    let uvw = vec3<f32>(uv, (slice_of_depth(params, z) - 0.5) / f32(params.grid.z));
    let s = sample_grid(uvw, (params.grid.w & HAZE_TRICUBIC) != 0u);
    let raw = textureLoad(lit_tex, id.xy, 0);
    let lit = select(vec3<f32>(0.0), raw.rgb, (raw.rgb >= vec3<f32>(0.0)) & (raw.rgb <= vec3<f32>(3.0e38)));
    let inv_scale = 1.0 / params.scatter.z;
    var out: vec3<f32>;
    if (params.grid.w & HAZE_DENSITY_AA) != 0u {
        let alpha = opacity(optical_depth(params, cam, v, dist));
        out = lit * (1.0 - alpha) + s.rgb * (alpha * inv_scale);
    } else {
        let alpha = clamp(s.a, 0.0, 1.0);
        out = lit * (1.0 - alpha) + s.rgb * inv_scale;
    }
    out = select(lit, max(out, vec3<f32>(0.0)), all(out >= vec3<f32>(-3.0e38)) && all(out <= vec3<f32>(3.0e38)));
    textureStore(out_tex, id.xy, vec4<f32>(out, select(1.0, raw.a, raw.a == raw.a)));
}
