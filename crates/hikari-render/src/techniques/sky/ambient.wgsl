#define_import_path hikari::sky_ambient

// The sky's light as ambient: its deringed L2 SH (radiance, Rec.709 nits; `sh.wgsl` projects it
// every frame), with the weather's diffuse and specular balance. Binding set `sky_ambient`
// (`SkyFrame::ambient`). Sky visibility is 1 everywhere until the irradiance probes.

#import hikari::sh::{ShL2Rgb, sh_eval_l2_rgb, sh_irradiance_l2_rgb}

struct SkyAmbientParams {
    // x: diffuse scale, y: specular scale, z, w: unused.
    balance: vec4<f32>,
}

@group(#{SKY_AMBIENT_GROUP}) @binding(0) var<uniform> sky_ambient: SkyAmbientParams;
// 9 raw coefficients, then 9 deringed ones (xyz; w unused).
@group(#{SKY_AMBIENT_GROUP}) @binding(1) var<storage, read> sky_sh: array<vec4<f32>, 18>;

fn sky_ambient_sh() -> ShL2Rgb {
    var sh: ShL2Rgb;
    for (var i = 0u; i < 9u; i++) {
        sh.c[i] = sky_sh[9u + i].xyz;
    }
    return sh;
}

// Irradiance from the sky on a surface with unit normal n, lux, times the diffuse balance.
fn sky_ambient_irradiance(n: vec3<f32>) -> vec3<f32> {
    return max(sh_irradiance_l2_rgb(sky_ambient_sh(), n), vec3<f32>(0.0)) * sky_ambient.balance.x;
}

// The sky's radiance for a reflection along `r`, blurred towards the cosine-weighted mean with
// roughness, nits, times the specular balance.
fn sky_ambient_specular(r: vec3<f32>, perceptual_roughness: f32) -> vec3<f32> {
    let sh = sky_ambient_sh();
    let sharp = max(sh_eval_l2_rgb(sh, r), vec3<f32>(0.0));
    let blurred = max(sh_irradiance_l2_rgb(sh, r), vec3<f32>(0.0)) / 3.14159265358979;
    return mix(sharp, blurred, perceptual_roughness) * sky_ambient.balance.y;
}
