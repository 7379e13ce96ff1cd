// Relights the irradiance probes from this frame's sky and sun or moon (Ghost of Tsushima's
// run-time relighting). One thread a probe; each workgroup takes one chunk of up to 64
// consecutive probes of the frame's work list. CPU twin: reference::relight_probe.
//
// Per probe: the sky's radiance SH times the probe's sky visibility (SH product truncated to
// L2); the bounced sky visibility times the sky's average radiance, plus the sun bounce (the
// light reflected by an imaginary ground and wall, negated reflected directions as windowed
// deltas, times the light's irradiance, the probe's mean bounced visibility and the clouds'
// shadow at the probe: the talk's "after applying cloud shadowing, which is dynamic so isn't
// captured by the sky visibility"); each part convolved with the clamped cosine and boosted
// on its own; their sum deringed.

#import hikari::clouds::cloud_shadow
#import hikari::sh::{ShL2Rgb, SH_C0, SH_COSINE_BANDS, sh_basis_l2, sh_band_of, sh_scale_bands_l2_rgb, sh_directionality_boost_rgb, sh_dering_l2_rgb}

struct RelightParams {
    // Unit direction towards the sun or moon; w unused.
    light_dir: vec4<f32>,
    // The light's RGB irradiance on a surface facing it, lux; w: sun-bounce scale.
    light_rgb: vec4<f32>,
    // x: chunks in the work list, y: RELIGHT_* flags.
    config: vec4<u32>,
    // x: directionality boost amount.
    amounts: vec4<f32>,
}

@group(0) @binding(0) var<uniform> params: RelightParams;
// The sky pass's buffer: 9 raw radiance coefficients (nits), then 9 deringed ones.
@group(0) @binding(1) var<storage, read> sky_sh: array<vec4<f32>, 18>;
// Gaunt coefficients of the L2 product, dense: (i * 9 + j) * 9 + k.
@group(0) @binding(2) var<storage, read> gaunt: array<f32, 729>;
// (first probe, probe count) per chunk.
@group(0) @binding(3) var<storage, read> chunks: array<vec2<u32>>;
// 9 per probe: (bounced sky visibility rgb, sky visibility) of coefficient k.
@group(0) @binding(4) var<storage, read> probe_data: array<vec4<f32>>;
// 9 per probe: irradiance SH (rgb; w 0), lux.
@group(0) @binding(5) var<storage, read_write> irradiance: array<vec4<f32>>;
// Per probe: position (metres; w: interior), where the clouds' shadow is read.
@group(0) @binding(6) var<storage, read> positions: array<vec4<f32>>;

const RELIGHT_BOUNCE: u32 = 1u;
const RELIGHT_SUN_BOUNCE: u32 = 2u;
const RELIGHT_BOOST: u32 = 4u;
const RELIGHT_DERING: u32 = 8u;
// Sloan 2017's window at strength 1/4, which leaves a projected delta with no negative lobe.
const LOBE_WINDOW: vec3<f32> = vec3<f32>(1.0, 0.5, 0.1);

// The sky SH folded into the Gaunt table once per workgroup: direct_k = sum_j m[j*9+k] vis_j.
var<workgroup> sky_gaunt: array<vec3<f32>, 81>;

@compute @workgroup_size(64, 1, 1)
fn main(@builtin(local_invocation_index) lid: u32, @builtin(workgroup_id) wg: vec3<u32>) {
    for (var e = lid; e < 81u; e += 64u) {
        let j = e / 9u;
        let k = e % 9u;
        var acc = vec3<f32>(0.0);
        for (var i = 0u; i < 9u; i++) {
            acc += sky_sh[i].xyz * gaunt[(i * 9u + j) * 9u + k];
        }
        sky_gaunt[e] = acc;
    }
    workgroupBarrier();
    let chunk = chunks[wg.x];
    if lid >= chunk.y {
        return;
    }
    let base = (chunk.x + lid) * 9u;
    let flags = params.config.y;
    let mean_sky = sky_sh[0].xyz * SH_C0;
    let mean_bounce = probe_data[base].xyz * SH_C0;
    let l = params.light_dir.xyz;
    var yg = sh_basis_l2(vec3<f32>(l.x, -l.y, l.z));
    var yw = sh_basis_l2(vec3<f32>(-l.x, l.y, -l.z));
    var lobe_window = LOBE_WINDOW;
    let ground_w = max(l.y, 0.0);
    let wall_w = select(0.0, length(l.xz), l.y > 0.0);
    let shadow = cloud_shadow(positions[chunk.x + lid].xyz);
    let sun = params.light_rgb.xyz * mean_bounce * (2.0 * params.light_rgb.w * shadow);
    var direct: ShL2Rgb;
    var bounced: ShL2Rgb;
    for (var k = 0u; k < 9u; k++) {
        var acc = vec3<f32>(0.0);
        for (var j = 0u; j < 9u; j++) {
            acc += sky_gaunt[j * 9u + k] * probe_data[base + j].w;
        }
        direct.c[k] = acc;
        var b = vec3<f32>(0.0);
        if (flags & RELIGHT_BOUNCE) != 0u {
            b = probe_data[base + k].xyz * mean_sky;
        }
        if (flags & RELIGHT_SUN_BOUNCE) != 0u {
            b += sun * ((ground_w * yg[k] + wall_w * yw[k]) * lobe_window[sh_band_of(k)]);
        }
        bounced.c[k] = b;
    }
    direct = sh_scale_bands_l2_rgb(direct, SH_COSINE_BANDS);
    bounced = sh_scale_bands_l2_rgb(bounced, SH_COSINE_BANDS);
    if (flags & RELIGHT_BOOST) != 0u {
        direct = sh_directionality_boost_rgb(direct, params.amounts.x);
        bounced = sh_directionality_boost_rgb(bounced, params.amounts.x);
    }
    var total: ShL2Rgb;
    for (var k = 0u; k < 9u; k++) {
        total.c[k] = direct.c[k] + bounced.c[k];
    }
    if (flags & RELIGHT_DERING) != 0u {
        total = sh_dering_l2_rgb(total);
    }
    for (var k = 0u; k < 9u; k++) {
        irradiance[base + k] = vec4<f32>(total.c[k], 0.0);
    }
}
