// Verification kernel for the Metro Exodus YCoCg + L1 encoding of `hikari::sh`: not used by any
// frame. One invocation per case, flat f32 records (sizes mirrored by `Kernel::in_stride` /
// `Kernel::out_stride` in src/checks/math_check.rs), compared with hikari-math's
// `sh::ycocg` in tests/render/math_twins.rs.

#import hikari::sh::{
    ShYCoCg, sh_rgb_to_ycocg, sh_ycocg_to_rgb, shy_encode, shy_to_color, shy_resolve_diffuse,
    shy_dominant_direction, shy_directionality, shy_specular_alpha,
}

#import hikari::math_check_io::{params, inputs, outputs, in_vec3, out_vec3}

// In: colour (3), direction (3), an accumulated encoding: Y L1 (c0, y, z, x) (4) and CoCg (2),
// normal (3), material GGX alpha (1).
// Out: rgb_to_ycocg(colour) (3), ycocg_to_rgb(colour read as YCoCg) (3), encode(colour,
// direction): Y L1 (4) and CoCg (2); of the accumulated encoding: to_color (3),
// resolve_diffuse(normal) (3), dominant direction (3), directionality (1), specular alpha (1).
const IN_YCOCG: u32 = 16u;
const OUT_YCOCG: u32 = 23u;

@compute @workgroup_size(64, 1, 1)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= params.count {
        return;
    }
    let i = id.x * IN_YCOCG;
    let o = id.x * OUT_YCOCG;
    let color = in_vec3(i);
    out_vec3(o, sh_rgb_to_ycocg(color));
    out_vec3(o + 3u, sh_ycocg_to_rgb(color));
    let e = shy_encode(color, in_vec3(i + 3u));
    out_vec3(o + 6u, e.y.xyz);
    outputs[o + 9u] = e.y.w;
    outputs[o + 10u] = e.co_cg.x;
    outputs[o + 11u] = e.co_cg.y;
    var s: ShYCoCg;
    s.y = vec4<f32>(inputs[i + 6u], inputs[i + 7u], inputs[i + 8u], inputs[i + 9u]);
    s.co_cg = vec2<f32>(inputs[i + 10u], inputs[i + 11u]);
    out_vec3(o + 12u, shy_to_color(s));
    out_vec3(o + 15u, shy_resolve_diffuse(s, in_vec3(i + 12u)));
    out_vec3(o + 18u, shy_dominant_direction(s));
    outputs[o + 21u] = shy_directionality(s);
    outputs[o + 22u] = shy_specular_alpha(s, inputs[i + 15u]);
}
