#define_import_path hikari::brdf

// Physically based BRDF for direct lighting: the WGSL twin of hikari-math's `brdf` module
// (crates/hikari-math/src/brdf), same functions with a `brdf_` prefix, in f32. The CPU twin's
// docs carry the derivations and citations; this file keeps only what a shader reader needs.
//
// Conventions: v toward the viewer, l toward the light, h = normalize(v + l), all unit. Frame
// (t, b, n) orthonormal; "local" vectors are (dot(t, w), dot(b, w), dot(n, w)). alpha =
// perceptual_roughness^2 (Burley 2012). Units: D and the BRDF in 1/sr; brdf_evaluate returns
// BRDF * n.l, so multiplying by a light's irradiance (lux or W/m^2) gives radiance.
//
// Model: GGX NDF (Walter et al. 2007) with Burley 2012 anisotropy extended to [-1, 1] by sign,
// height-correlated Smith G2 (Heitz 2014) folded into V = G2 / (4 n.l n.v), Schlick Fresnel
// (Schlick 1994) on v.h, Lambert weighted by (1 - F(n.v)) (1 - F(n.l)) (Shirley et al. 1997)
// so that a white material never reflects more than it receives.

const BRDF_PI: f32 = 3.141592653589793;
// Must match hikari_math::brdf::material::MIN_PERCEPTUAL_ROUGHNESS: keeps 1 - (n.h)^2 resolvable
// against alpha^2 in f32.
const BRDF_MIN_PERCEPTUAL_ROUGHNESS: f32 = 0.045;
const BRDF_MIN_ALPHA: f32 = 0.002025;
// Normal-incidence reflectance of dielectrics (eta = 1.5).
const BRDF_DIELECTRIC_F0: f32 = 0.04;
// Burley 2012: aspect = sqrt(1 - 0.9 |anisotropy|).
const BRDF_ANISOTROPY_ASPECT_SCALE: f32 = 0.9;
// Stands in for Smith's Lambda = +inf below the horizon (WGSL has no infinity literal); large
// enough that G1 and G2 round to 0, small enough that 1 + 2 of them stays finite.
const BRDF_LAMBDA_BELOW_HORIZON: f32 = 1e30;

struct BrdfMaterial {
    base_color: vec3<f32>,
    perceptual_roughness: f32,
    metalness: f32,
    anisotropy: f32,
}

fn brdf_alpha_from_perceptual(perceptual_roughness: f32) -> f32 {
    let r = clamp(perceptual_roughness, BRDF_MIN_PERCEPTUAL_ROUGHNESS, 1.0);
    return r * r;
}

// (alpha_x, alpha_y) along t and b; alpha_x * alpha_y = alpha^2 keeps the peak of D.
fn brdf_anisotropic_alphas(perceptual_roughness: f32, anisotropy: f32) -> vec2<f32> {
    let alpha = brdf_alpha_from_perceptual(perceptual_roughness);
    let a = clamp(anisotropy, -1.0, 1.0);
    let aspect = sqrt(1.0 - BRDF_ANISOTROPY_ASPECT_SCALE * abs(a));
    let long_short = vec2<f32>(alpha / aspect, alpha * aspect);
    let widths = select(long_short.yx, long_short, a >= 0.0);
    return max(widths, vec2<f32>(BRDF_MIN_ALPHA));
}

fn brdf_f0_from_metalness(base_color: vec3<f32>, metalness: f32) -> vec3<f32> {
    return mix(vec3<f32>(BRDF_DIELECTRIC_F0), base_color, metalness);
}

// GGX D(h), 1/sr, isotropic, from n.h.
fn brdf_ggx_ndf(n_dot_h: f32, alpha: f32) -> f32 {
    if n_dot_h <= 0.0 {
        return 0.0;
    }
    let a2 = alpha * alpha;
    // (1 - c)(1 + c) rather than 1 - c^2: less cancellation near the peak.
    let sin2 = (1.0 - n_dot_h) * (1.0 + n_dot_h);
    let d = sin2 + n_dot_h * n_dot_h * a2;
    return a2 / (BRDF_PI * d * d);
}

// Anisotropic GGX D(h), 1/sr, from h in the tangent frame. Tangent components carry no
// cancellation, so this form is the accurate one for near-mirror materials in f32.
fn brdf_ggx_ndf_aniso(h_local: vec3<f32>, alpha_x: f32, alpha_y: f32) -> f32 {
    if h_local.z <= 0.0 {
        return 0.0;
    }
    let s = vec3<f32>(h_local.x / alpha_x, h_local.y / alpha_y, h_local.z);
    let d = dot(s, s);
    return 1.0 / (BRDF_PI * alpha_x * alpha_y * d * d);
}

fn brdf_smith_lambda(n_dot_w: f32, alpha: f32) -> f32 {
    if n_dot_w <= 0.0 {
        return BRDF_LAMBDA_BELOW_HORIZON;
    }
    let tan2 = (1.0 - n_dot_w) * (1.0 + n_dot_w) / (n_dot_w * n_dot_w);
    return 0.5 * (sqrt(1.0 + alpha * alpha * tan2) - 1.0);
}

fn brdf_smith_lambda_aniso(w_local: vec3<f32>, alpha_x: f32, alpha_y: f32) -> f32 {
    if w_local.z <= 0.0 {
        return BRDF_LAMBDA_BELOW_HORIZON;
    }
    let p = vec2<f32>(alpha_x * w_local.x, alpha_y * w_local.y);
    let a2tan2 = dot(p, p) / (w_local.z * w_local.z);
    return 0.5 * (sqrt(1.0 + a2tan2) - 1.0);
}

fn brdf_smith_g1(n_dot_w: f32, alpha: f32) -> f32 {
    return 1.0 / (1.0 + brdf_smith_lambda(n_dot_w, alpha));
}

fn brdf_smith_g1_aniso(w_local: vec3<f32>, alpha_x: f32, alpha_y: f32) -> f32 {
    return 1.0 / (1.0 + brdf_smith_lambda_aniso(w_local, alpha_x, alpha_y));
}

fn brdf_smith_g2_height_correlated(n_dot_v: f32, n_dot_l: f32, alpha: f32) -> f32 {
    return 1.0 / (1.0 + brdf_smith_lambda(n_dot_v, alpha) + brdf_smith_lambda(n_dot_l, alpha));
}

fn brdf_smith_g2_height_correlated_aniso(
    v_local: vec3<f32>,
    l_local: vec3<f32>,
    alpha_x: f32,
    alpha_y: f32,
) -> f32 {
    let lv = brdf_smith_lambda_aniso(v_local, alpha_x, alpha_y);
    let ll = brdf_smith_lambda_aniso(l_local, alpha_x, alpha_y);
    return 1.0 / (1.0 + lv + ll);
}

// V = G2 / (4 n.l n.v) with the 4 n.l n.v multiplied in, so it stays finite at grazing.
fn brdf_visibility(n_dot_v: f32, n_dot_l: f32, alpha: f32) -> f32 {
    if n_dot_v <= 0.0 || n_dot_l <= 0.0 {
        return 0.0;
    }
    let a2 = alpha * alpha;
    let lv = n_dot_l * sqrt(n_dot_v * n_dot_v + a2 * (1.0 - n_dot_v) * (1.0 + n_dot_v));
    let vl = n_dot_v * sqrt(n_dot_l * n_dot_l + a2 * (1.0 - n_dot_l) * (1.0 + n_dot_l));
    return 0.5 / (lv + vl);
}

fn brdf_visibility_aniso(v_local: vec3<f32>, l_local: vec3<f32>, alpha_x: f32, alpha_y: f32) -> f32 {
    if v_local.z <= 0.0 || l_local.z <= 0.0 {
        return 0.0;
    }
    let stretch = vec3<f32>(alpha_x, alpha_y, 1.0);
    return brdf_visibility_stretched(v_local.z, length(v_local * stretch), l_local.z, length(l_local * stretch));
}

// brdf_visibility_aniso from each side's cosine and stretched length |w_local * (ax, ay, 1)|,
// so that a caller can compute the view's half once for many lights.
fn brdf_visibility_stretched(v_z: f32, v_stretched: f32, l_z: f32, l_stretched: f32) -> f32 {
    return 0.5 / (l_z * v_stretched + v_z * l_stretched);
}

fn brdf_schlick_weight(cos_theta: f32) -> f32 {
    let m = 1.0 - clamp(cos_theta, 0.0, 1.0);
    let m2 = m * m;
    return m2 * m2 * m;
}

fn brdf_fresnel_schlick(f0: vec3<f32>, cos_theta: f32) -> vec3<f32> {
    return f0 + (vec3<f32>(1.0) - f0) * brdf_schlick_weight(cos_theta);
}

fn brdf_lambert(albedo: vec3<f32>) -> vec3<f32> {
    return albedo * (1.0 / BRDF_PI);
}

fn brdf_fresnel_weighted_lambert(albedo: vec3<f32>, f0: vec3<f32>, n_dot_v: f32, n_dot_l: f32) -> vec3<f32> {
    if n_dot_v <= 0.0 || n_dot_l <= 0.0 {
        return vec3<f32>(0.0);
    }
    let tv = vec3<f32>(1.0) - brdf_fresnel_schlick(f0, n_dot_v);
    let tl = vec3<f32>(1.0) - brdf_fresnel_schlick(f0, n_dot_l);
    return brdf_lambert(albedo) * tv * tl;
}

fn brdf_material_f0(m: BrdfMaterial) -> vec3<f32> {
    return brdf_f0_from_metalness(saturate(m.base_color), saturate(m.metalness));
}

fn brdf_material_diffuse_albedo(m: BrdfMaterial) -> vec3<f32> {
    return saturate(m.base_color) * (1.0 - saturate(m.metalness));
}

// What brdf_evaluate derives from the material and the view direction alone: computed once
// a pixel for all the lights that shade it.
struct BrdfView {
    t: vec3<f32>,
    b: vec3<f32>,
    n: vec3<f32>,
    v_local: vec3<f32>,
    alphas: vec2<f32>,
    // Fresnel reflectance at normal incidence.
    f_normal: vec3<f32>,
    // Lambert times the view side's Fresnel transmission 1 - F(n.v).
    diffuse: vec3<f32>,
    // |v_local * (alpha_x, alpha_y, 1)|: the view's half of the height-correlated visibility.
    v_stretched: f32,
    // 1 / alpha_x, 1 / alpha_y: multiplications, not divisions, for every light's D.
    inv_alphas: vec2<f32>,
    // 1 / (2 pi alpha_x alpha_y): D's normalisation times V's 1/2.
    spec_scale: f32,
}

fn brdf_view(m: BrdfMaterial, n: vec3<f32>, t: vec3<f32>, b: vec3<f32>, v: vec3<f32>) -> BrdfView {
    var p: BrdfView;
    p.t = t;
    p.b = b;
    p.n = n;
    p.v_local = vec3<f32>(dot(t, v), dot(b, v), dot(n, v));
    p.alphas = brdf_anisotropic_alphas(m.perceptual_roughness, m.anisotropy);
    p.f_normal = brdf_material_f0(m);
    p.diffuse = brdf_lambert(brdf_material_diffuse_albedo(m)) * (vec3<f32>(1.0) - brdf_fresnel_schlick(p.f_normal, p.v_local.z));
    p.v_stretched = length(p.v_local * vec3<f32>(p.alphas, 1.0));
    p.inv_alphas = 1.0 / p.alphas;
    p.spec_scale = 1.0 / (2.0 * BRDF_PI * p.alphas.x * p.alphas.y);
    return p;
}

// The light-dependent factors of brdf_evaluate_view, scalars, such that
//   brdf_evaluate_view(p, l) = f_normal * w.x + (1 - f_normal) * (w.y + diffuse * w.z):
// w.x = D V n.l, w.y = D V n.l Schlick(v.h), w.z = (1 - Schlick(n.l)) n.l, from F = f0 +
// (1 - f0) Schlick. A caller summing many lights sums their weighted light colours and applies
// the material's colours once (brdf_apply_weights), rather than three colour products a light.
fn brdf_light_weights(p: BrdfView, l: vec3<f32>) -> vec3<f32> {
    let l_local = vec3<f32>(dot(p.t, l), dot(p.b, l), dot(p.n, l));
    if p.v_local.z <= 0.0 || l_local.z <= 0.0 {
        return vec3<f32>(0.0);
    }
    let h_local = normalize(p.v_local + l_local);
    // D (brdf_ggx_ndf_aniso) times V (brdf_visibility_stretched) over one division: with both
    // sides above the surface h is too, and the denominators are positive.
    let s = vec3<f32>(h_local.xy * p.inv_alphas, h_local.z);
    let dd = dot(s, s);
    let vis_den = l_local.z * p.v_stretched + p.v_local.z * length(l_local * vec3<f32>(p.alphas, 1.0));
    let spec = l_local.z * p.spec_scale / (dd * dd * vis_den);
    return vec3<f32>(spec, spec * brdf_schlick_weight(dot(p.v_local, h_local)), (1.0 - brdf_schlick_weight(l_local.z)) * l_local.z);
}

// Radiance from light weights summed with their colours: a = sum c w.x, b = sum c w.y,
// c = sum c w.z (see brdf_light_weights).
fn brdf_apply_weights(p: BrdfView, a: vec3<f32>, b: vec3<f32>, c: vec3<f32>) -> vec3<f32> {
    return p.f_normal * a + (vec3<f32>(1.0) - p.f_normal) * (b + p.diffuse * c);
}

// brdf_evaluate for a prepared view: BRDF * n.l, 0 when v or l is at or below the surface.
fn brdf_evaluate_view(p: BrdfView, l: vec3<f32>) -> vec3<f32> {
    let w = brdf_light_weights(p, l);
    return brdf_apply_weights(p, vec3<f32>(w.x), vec3<f32>(w.y), vec3<f32>(w.z));
}

// BRDF * n.l, 1/sr, per RGB channel; 0 when v or l is at or below the surface.
fn brdf_evaluate(m: BrdfMaterial, n: vec3<f32>, t: vec3<f32>, b: vec3<f32>, v: vec3<f32>, l: vec3<f32>) -> vec3<f32> {
    return brdf_evaluate_view(brdf_view(m, n, t, b, v), l);
}

// brdf_evaluate without a tangent frame; anisotropy is ignored.
fn brdf_evaluate_isotropic(m: BrdfMaterial, n: vec3<f32>, v: vec3<f32>, l: vec3<f32>) -> vec3<f32> {
    let n_dot_v = dot(n, v);
    let n_dot_l = dot(n, l);
    if n_dot_v <= 0.0 || n_dot_l <= 0.0 {
        return vec3<f32>(0.0);
    }
    let h = normalize(v + l);
    let alpha = brdf_alpha_from_perceptual(m.perceptual_roughness);
    let f0 = brdf_material_f0(m);
    let spec = brdf_ggx_ndf(dot(n, h), alpha)
        * brdf_visibility(n_dot_v, n_dot_l, alpha)
        * brdf_fresnel_schlick(f0, dot(v, h));
    let diff = brdf_fresnel_weighted_lambert(brdf_material_diffuse_albedo(m), f0, n_dot_v, n_dot_l);
    return (spec + diff) * n_dot_l;
}
