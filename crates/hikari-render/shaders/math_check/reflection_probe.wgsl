// Verification kernel for `hikari::reflection_probe_math`: not used by any frame. One
// invocation per case, flat f32 records (sizes mirrored by `Kernel::in_stride` /
// `Kernel::out_stride` in src/checks/math_check.rs), compared with
// `reflection_probes::reference` in tests/reflection_probes.rs.

#import hikari::reflection_probe_math::{rp_texel_direction, rp_face_uv, rp_horizon_occlusion, rp_compensated_alpha}
#import hikari::math_check_io::{params, inputs, outputs, in_vec3, out_vec3}

// In: mapped normal (3), vertex normal (3), reflection (3), GGX alpha (1), eye and capture
// distances (2), a direction (3), a face, texel x, y and texels a side (4).
// Out: horizon occlusion (1), compensated alpha (1), the direction's (u, v, face) (3), the
// texel's direction (3).
const IN_RP: u32 = 19u;
const OUT_RP: u32 = 8u;

@compute @workgroup_size(64, 1, 1)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= params.count {
        return;
    }
    let i = id.x * IN_RP;
    let o = id.x * OUT_RP;
    outputs[o] = rp_horizon_occlusion(in_vec3(i), in_vec3(i + 3u), in_vec3(i + 6u), inputs[i + 9u]);
    outputs[o + 1u] = rp_compensated_alpha(inputs[i + 9u], inputs[i + 10u], inputs[i + 11u]);
    out_vec3(o + 2u, rp_face_uv(in_vec3(i + 12u)));
    out_vec3(o + 5u, rp_texel_direction(u32(inputs[i + 15u]), vec2<u32>(u32(inputs[i + 16u]), u32(inputs[i + 17u])), u32(inputs[i + 18u])));
}
