// Verification kernel for the BRDF twin `hikari::brdf` (with its tables `hikari::brdf_tables`):
// not used by any frame. One invocation per case, flat f32 records (sizes mirrored by
// `Kernel::in_stride` / `Kernel::out_stride` in src/checks/math_check.rs), compared with
// hikari-math's `brdf` module in tests/render/math_twins.rs.

#import hikari::brdf::{
    BrdfMaterial, brdf_evaluate, brdf_evaluate_isotropic, brdf_view, brdf_light_weights,
    brdf_albedo_lookup, brdf_albedo_average, brdf_anisotropic_alphas,
    brdf_isotropic_equivalent_roughness,
}

#import hikari::math_check_io::{params, inputs, outputs, in_vec3, out_vec3}

// In: base colour (3), perceptual roughness, metalness, anisotropy (3), n, t, b, v, l (5 x 3),
// specular weight.
// Out: brdf_evaluate (3), brdf_evaluate_isotropic (3), brdf_light_weights (4),
// brdf_albedo_lookup(n.v, isotropic-equivalent roughness) (2), brdf_albedo_average(same) (2).
const IN_BRDF: u32 = 22u;
const OUT_BRDF: u32 = 14u;

@compute @workgroup_size(64, 1, 1)
fn eval(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= params.count {
        return;
    }
    let i = id.x * IN_BRDF;
    let o = id.x * OUT_BRDF;
    let m = BrdfMaterial(in_vec3(i), inputs[i + 3u], inputs[i + 4u], inputs[i + 5u], inputs[i + 21u]);
    let n = in_vec3(i + 6u);
    let t = in_vec3(i + 9u);
    let b = in_vec3(i + 12u);
    let v = in_vec3(i + 15u);
    let l = in_vec3(i + 18u);
    out_vec3(o, brdf_evaluate(m, n, t, b, v, l));
    out_vec3(o + 3u, brdf_evaluate_isotropic(m, n, v, l));
    let w = brdf_light_weights(brdf_view(m, n, t, b, v), l);
    outputs[o + 6u] = w.x;
    outputs[o + 7u] = w.y;
    outputs[o + 8u] = w.z;
    outputs[o + 9u] = w.w;
    let r = brdf_isotropic_equivalent_roughness(brdf_anisotropic_alphas(m.perceptual_roughness, m.anisotropy));
    let e = brdf_albedo_lookup(dot(n, v), r);
    let avg = brdf_albedo_average(r);
    outputs[o + 10u] = e.x;
    outputs[o + 11u] = e.y;
    outputs[o + 12u] = avg.x;
    outputs[o + 13u] = avg.y;
}
