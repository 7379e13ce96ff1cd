#define_import_path hikari::rtgi_resolve

// Resolving the GI signal (luminance L1 SH + CoCg, `ShL1YCoCg`'s normalisation) at a pixel,
// for the deferred lighting: diffuse with the talk's bonus-slide formula, specular as Metro
// does it: the SH's dominant direction as one light, its loss of directionality turned into a
// rougher GGX lobe (`shy_specular_alpha`), lit with the irradiance the SH gives a plane facing
// that direction. CPU twin: ray_traced_gi::reference::resolve_diffuse / resolve_specular.
// Importing hikari::brdf brings the binding set `brdf_tables` with it.

#import hikari::sh::{ShYCoCg, shy_resolve_diffuse, shy_dominant_direction, shy_specular_alpha}
#import hikari::brdf::{brdf_ggx_ndf, brdf_visibility, brdf_fresnel_schlick_f90}

const RTGI_RESOLVE_PI: f32 = 3.14159265358979;

fn rtgi_signal(gi_y: vec4<f32>, gi_cocg: vec2<f32>) -> ShYCoCg {
    var s: ShYCoCg;
    s.y = gi_y;
    s.co_cg = gi_cocg;
    return s;
}

// Outgoing radiance of a white Lambertian surface with unit normal n (multiply by the diffuse
// albedo), nits.
fn rtgi_resolve_diffuse(s: ShYCoCg, n: vec3<f32>) -> vec3<f32> {
    return shy_resolve_diffuse(s, n);
}

// Reflected radiance (nits) towards unit v of a GGX surface with unit normal n, Fresnel from
// `f0` to `f90` (brdf_material_f0, brdf_material_f90) and GGX alpha `material_alpha`. Without
// a direction in the SH (all zero) the light is taken from the mirror direction with the
// widest lobe.
fn rtgi_resolve_specular(s: ShYCoCg, n: vec3<f32>, v: vec3<f32>, f0: vec3<f32>, f90: f32, material_alpha: f32) -> vec3<f32> {
    var l = shy_dominant_direction(s);
    if dot(l, l) == 0.0 {
        l = reflect(-v, n);
    }
    let alpha = shy_specular_alpha(s, material_alpha);
    let n_l = dot(n, l);
    let n_v = dot(n, v);
    if n_l <= 0.0 || n_v <= 0.0 {
        return vec3<f32>(0.0);
    }
    let e = RTGI_RESOLVE_PI * shy_resolve_diffuse(s, l);
    let h = normalize(v + l);
    let spec = brdf_ggx_ndf(dot(n, h), alpha) * brdf_visibility(n_v, n_l, alpha);
    return brdf_fresnel_schlick_f90(f0, f90, max(dot(v, h), 0.0)) * spec * e * n_l;
}
