// Verification kernels for the SH twin `hikari::sh`: not used by any frame. Each invocation reads
// one case from `inputs`, calls the twin and writes what hikari-math on the CPU must reproduce
// to `outputs` (tests/render/math_twins.rs). Cases are flat f32 records so that no WGSL array stride or
// vec3 padding rule stands between the two sides; the record sizes (IN_* / OUT_*) are mirrored
// by `Kernel::in_stride` / `Kernel::out_stride` in src/checks/math_check.rs.
// RGB SH are stored coefficient-major: c0.r, c0.g, c0.b, c1.r, ...

#import hikari::sh::{
    ShL2, ShL2Rgb, sh_basis_l1, sh_basis_l2, sh_eval_l1, sh_eval_l2, sh_eval_l2_rgb,
    sh_scale_bands_l2, sh_scale_bands_l2_rgb, sh_irradiance_l1, sh_irradiance_l2_rgb,
    sh_delta_l2, sh_window_sloan2017, sh_dering_window, sh_find_min_l2, sh_rgb_channel,
    sh_dering_strength_rgb, sh_dering_l2_rgb, sh_linear_max_dir_rgb, sh_directionality_boost_rgb,
}

#import hikari::math_check_io::{params, inputs, outputs, in_vec3, out_vec3}

fn in_l2(i: u32) -> ShL2 {
    var s: ShL2;
    for (var k = 0u; k < 9u; k++) {
        s.c[k] = inputs[i + k];
    }
    return s;
}

fn in_l2_rgb(i: u32) -> ShL2Rgb {
    var s: ShL2Rgb;
    for (var k = 0u; k < 9u; k++) {
        s.c[k] = in_vec3(i + 3u * k);
    }
    return s;
}

fn out_vec4(i: u32, v: vec4<f32>) {
    out_vec3(i, v.xyz);
    outputs[i + 3u] = v.w;
}

fn out_l2(i: u32, s: ShL2) {
    var c = s.c;
    for (var k = 0u; k < 9u; k++) {
        outputs[i + k] = c[k];
    }
}

fn out_l2_rgb(i: u32, s: ShL2Rgb) {
    var c = s.c;
    for (var k = 0u; k < 9u; k++) {
        out_vec3(i + 3u * k, c[k]);
    }
}

// In: mono L2 (9), RGB L2 (27), direction (3). Out: basis L1 (4), basis L2 (9),
// eval L1 of the mono's first 4 coefficients (1), eval L2 mono (1), eval L2 RGB (3).
const IN_EVAL: u32 = 39u;
const OUT_EVAL: u32 = 18u;

@compute @workgroup_size(64, 1, 1)
fn eval(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= params.count {
        return;
    }
    let i = id.x * IN_EVAL;
    let o = id.x * OUT_EVAL;
    let mono = in_l2(i);
    let rgb = in_l2_rgb(i + 9u);
    let d = in_vec3(i + 36u);
    out_vec4(o, sh_basis_l1(d));
    var y = sh_basis_l2(d);
    for (var k = 0u; k < 9u; k++) {
        outputs[o + 4u + k] = y[k];
    }
    var c = mono.c;
    outputs[o + 13u] = sh_eval_l1(vec4<f32>(c[0], c[1], c[2], c[3]), d);
    outputs[o + 14u] = sh_eval_l2(mono, d);
    out_vec3(o + 15u, sh_eval_l2_rgb(rgb, d));
}

// In: mono L1 (4), RGB L2 (27), normal (3). Out: irradiance L1 (1), irradiance L2 RGB (3).
const IN_IRRADIANCE: u32 = 34u;
const OUT_IRRADIANCE: u32 = 4u;

@compute @workgroup_size(64, 1, 1)
fn irradiance(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= params.count {
        return;
    }
    let i = id.x * IN_IRRADIANCE;
    let o = id.x * OUT_IRRADIANCE;
    let l1 = vec4<f32>(inputs[i], inputs[i + 1u], inputs[i + 2u], inputs[i + 3u]);
    let rgb = in_l2_rgb(i + 4u);
    let n = in_vec3(i + 31u);
    outputs[o] = sh_irradiance_l1(l1, n);
    out_vec3(o + 1u, sh_irradiance_l2_rgb(rgb, n));
}

// In: mono L2 (9), RGB L2 (27), band factors (3), Sloan λ (1), dering strength t (1).
// Out: scaled mono (9), scaled RGB (27), Sloan 2017 window (3), deringing window (3).
const IN_BANDS: u32 = 41u;
const OUT_BANDS: u32 = 42u;

@compute @workgroup_size(64, 1, 1)
fn bands(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= params.count {
        return;
    }
    let i = id.x * IN_BANDS;
    let o = id.x * OUT_BANDS;
    let f = in_vec3(i + 36u);
    out_l2(o, sh_scale_bands_l2(in_l2(i), f));
    out_l2_rgb(o + 9u, sh_scale_bands_l2_rgb(in_l2_rgb(i + 9u), f));
    out_vec3(o + 36u, sh_window_sloan2017(inputs[i + 39u]));
    out_vec3(o + 39u, sh_dering_window(inputs[i + 40u]));
}

// In: direction (3), weight (1). Out: the delta's L2 coefficients (9).
const IN_DELTA: u32 = 4u;
const OUT_DELTA: u32 = 9u;

@compute @workgroup_size(64, 1, 1)
fn delta(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= params.count {
        return;
    }
    let i = id.x * IN_DELTA;
    out_l2(id.x * OUT_DELTA, sh_delta_l2(in_vec3(i), inputs[i + 3u]));
}

// In: mono L2 (9). Out: estimated minimum direction (3) and value (1).
const IN_FIND_MIN: u32 = 9u;
const OUT_FIND_MIN: u32 = 4u;

@compute @workgroup_size(64, 1, 1)
fn find_min(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= params.count {
        return;
    }
    out_vec4(id.x * OUT_FIND_MIN, sh_find_min_l2(in_l2(id.x * IN_FIND_MIN)));
}

// Directions for the GPU's own scan of the deringed result: a Fibonacci sphere.
const DERING_SCAN: u32 = 512u;

// In: RGB L2 (27). Out: strength (1), deringed RGB (27), the twin's estimated minimum of each
// deringed channel (3), the smallest value of each deringed channel over DERING_SCAN
// directions, evaluated with sh_eval_l2_rgb (3).
const IN_DERING: u32 = 27u;
const OUT_DERING: u32 = 34u;

@compute @workgroup_size(64, 1, 1)
fn dering(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= params.count {
        return;
    }
    let o = id.x * OUT_DERING;
    let sh = in_l2_rgb(id.x * IN_DERING);
    outputs[o] = sh_dering_strength_rgb(sh);
    let d = sh_dering_l2_rgb(sh);
    out_l2_rgb(o + 1u, d);
    for (var k = 0u; k < 3u; k++) {
        outputs[o + 28u + k] = sh_find_min_l2(sh_rgb_channel(d, k)).w;
    }
    var lo = vec3<f32>(3.4e38);
    for (var j = 0u; j < DERING_SCAN; j++) {
        let z = 1.0 - (2.0 * f32(j) + 1.0) / f32(DERING_SCAN);
        let r = sqrt(max(1.0 - z * z, 0.0));
        // Golden angle, so successive points spread evenly in azimuth.
        let phi = 2.399963229728653 * f32(j);
        lo = min(lo, sh_eval_l2_rgb(d, vec3<f32>(r * cos(phi), r * sin(phi), z)));
    }
    out_vec3(o + 31u, lo);
}

// In: RGB L2 (27), amount (1). Out: linear-maximum direction (3), boosted RGB (27).
const IN_BOOST: u32 = 28u;
const OUT_BOOST: u32 = 30u;

@compute @workgroup_size(64, 1, 1)
fn boost(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= params.count {
        return;
    }
    let i = id.x * IN_BOOST;
    let o = id.x * OUT_BOOST;
    let sh = in_l2_rgb(i);
    out_vec3(o, sh_linear_max_dir_rgb(sh));
    out_l2_rgb(o + 3u, sh_directionality_boost_rgb(sh, inputs[i + 27u]));
}
