#define_import_path hikari::sky_ambient

// The sky's light as ambient: its deringed L2 SH (radiance, Rec.709 nits; `sh.wgsl` projects it
// every frame), with the weather's diffuse and specular balance. Binding set `sky_ambient`
// (`SkyFrame::ambient`). Sky visibility is 1 everywhere until the irradiance probes.

#import hikari::sh::{SH_C0, SH_C1, SH_C2, SH_C3, SH_C4, SH_COSINE_BANDS}

struct SkyAmbientParams {
    // x: diffuse scale, y: specular scale, z, w: unused.
    balance: vec4<f32>,
}

@group(#{SKY_AMBIENT_GROUP}) @binding(0) var<uniform> sky_ambient: SkyAmbientParams;
// 9 raw coefficients, then 9 deringed ones (xyz; w unused).
@group(#{SKY_AMBIENT_GROUP}) @binding(1) var<storage, read> sky_sh: array<vec4<f32>, 18>;

// The deringed SH evaluated at d with each band scaled by `bands`: written out term by term
// from the buffer, with no local arrays (a dynamically indexed array lives in slow local
// memory on some GPUs, and every pixel evaluates this twice). Every thread reads the same 9
// coefficients.
fn sky_ambient_eval(d: vec3<f32>, bands: vec3<f32>) -> vec3<f32> {
    let b0 = bands.x * SH_C0 * sky_sh[9u].xyz;
    let b1 = bands.y * SH_C1 * (sky_sh[10u].xyz * d.y + sky_sh[11u].xyz * d.z + sky_sh[12u].xyz * d.x);
    let b2 = bands.z * (SH_C2 * (sky_sh[13u].xyz * (d.x * d.y) + sky_sh[14u].xyz * (d.y * d.z) + sky_sh[16u].xyz * (d.x * d.z))
        + SH_C3 * sky_sh[15u].xyz * (3.0 * d.z * d.z - 1.0)
        + SH_C4 * sky_sh[17u].xyz * (d.x * d.x - d.y * d.y));
    return b0 + b1 + b2;
}

// Irradiance from the sky on a surface with unit normal n, lux, times the diffuse balance.
fn sky_ambient_irradiance(n: vec3<f32>) -> vec3<f32> {
    return max(sky_ambient_eval(n, SH_COSINE_BANDS), vec3<f32>(0.0)) * sky_ambient.balance.x;
}

// The sky's irradiance averaged over every normal (its constant term), lux, times the diffuse
// balance.
fn sky_ambient_average_irradiance() -> vec3<f32> {
    return max(sky_ambient_eval(vec3<f32>(0.0), vec3<f32>(SH_COSINE_BANDS.x, 0.0, 0.0)), vec3<f32>(0.0)) * sky_ambient.balance.x;
}

// The sky's radiance for a reflection along `r`, blurred towards the cosine-weighted mean with
// roughness, nits, times the specular balance.
fn sky_ambient_specular(r: vec3<f32>, perceptual_roughness: f32) -> vec3<f32> {
    let sharp = max(sky_ambient_eval(r, vec3<f32>(1.0)), vec3<f32>(0.0));
    let blurred = max(sky_ambient_eval(r, SH_COSINE_BANDS), vec3<f32>(0.0)) / 3.14159265358979;
    return mix(sharp, blurred, perceptual_roughness) * sky_ambient.balance.y;
}
