// Verification kernels for the colour twin `hikari::color`: not used by any frame. One
// invocation per case, flat f32 records (sizes mirrored by `Kernel::in_stride` /
// `Kernel::out_stride` in src/checks/math_check.rs), compared with hikari-math's `color`
// module in tests/render/math_twins.rs.

#import hikari::color::{
    REC709_TO_XYZ, XYZ_TO_REC709, REC709_TO_ACESCG, ACESCG_TO_REC709, REC709_TO_TONEMAP,
    TONEMAP_TO_REC709, REC709_TO_LMS_RAYLEIGH, LMS_RAYLEIGH_TO_REC709, PURKINJE_LMSR_FROM_REC709,
    PURKINJE_RGB_FROM_LMS_GAIN, luminance_rec709, srgb_encode, srgb_decode, srgb_encode3,
    srgb_decode3, purkinje_shift,
}

#import hikari::math_check_io::{params, inputs, outputs, in_vec3, out_vec3}

// In: linear x (1), encoded e (1), colour (3).
// Out: srgb_encode(x), srgb_decode(e), srgb_encode3(colour) (3), srgb_decode3(colour) (3),
// luminance_rec709(colour) (1).
const IN_TRANSFER: u32 = 5u;
const OUT_TRANSFER: u32 = 9u;

@compute @workgroup_size(64, 1, 1)
fn transfer(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= params.count {
        return;
    }
    let i = id.x * IN_TRANSFER;
    let o = id.x * OUT_TRANSFER;
    let c = in_vec3(i + 2u);
    outputs[o] = srgb_encode(inputs[i]);
    outputs[o + 1u] = srgb_decode(inputs[i + 1u]);
    out_vec3(o + 2u, srgb_encode3(c));
    out_vec3(o + 5u, srgb_decode3(c));
    outputs[o + 8u] = luminance_rec709(c);
}

// In: a vector (3). Out: each constant matrix times it, in declaration order: the eight 3x3
// colour-space matrices (8 x 3), PURKINJE_LMSR_FROM_REC709 (4), PURKINJE_RGB_FROM_LMS_GAIN (3).
const IN_MATRICES: u32 = 3u;
const OUT_MATRICES: u32 = 31u;

@compute @workgroup_size(64, 1, 1)
fn matrices(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= params.count {
        return;
    }
    let v = in_vec3(id.x * IN_MATRICES);
    let o = id.x * OUT_MATRICES;
    out_vec3(o, REC709_TO_XYZ * v);
    out_vec3(o + 3u, XYZ_TO_REC709 * v);
    out_vec3(o + 6u, REC709_TO_ACESCG * v);
    out_vec3(o + 9u, ACESCG_TO_REC709 * v);
    out_vec3(o + 12u, REC709_TO_TONEMAP * v);
    out_vec3(o + 15u, TONEMAP_TO_REC709 * v);
    out_vec3(o + 18u, REC709_TO_LMS_RAYLEIGH * v);
    out_vec3(o + 21u, LMS_RAYLEIGH_TO_REC709 * v);
    let lmsr = PURKINJE_LMSR_FROM_REC709 * v;
    out_vec3(o + 24u, lmsr.xyz);
    outputs[o + 27u] = lmsr.w;
    out_vec3(o + 28u, PURKINJE_RGB_FROM_LMS_GAIN * v);
}

// In: linear Rec.709 colour (3). Out: purkinje_shift with the generated matrices (3).
const IN_PURKINJE: u32 = 3u;
const OUT_PURKINJE: u32 = 3u;

@compute @workgroup_size(64, 1, 1)
fn purkinje(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= params.count {
        return;
    }
    out_vec3(
        id.x * OUT_PURKINJE,
        purkinje_shift(in_vec3(id.x * IN_PURKINJE), PURKINJE_LMSR_FROM_REC709, PURKINJE_RGB_FROM_LMS_GAIN),
    );
}
