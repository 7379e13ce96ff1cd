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
// Model (docs/brdf.md): GGX NDF (Walter et al. 2007) with Burley 2012 anisotropy extended to
// [-1, 1] by sign, height-correlated Smith G2 (Heitz 2014) folded into V = G2 / (4 n.l n.v),
// Schlick Fresnel (Schlick 1994) on v.h; plus the multiple-scattering lobe of Kulla & Conty
// 2017 and Lambert scaled by what the specular lobe leaves, (1 - E_d(n.v)) (1 - E_d(n.l)) /
// (1 - E_d,avg) (Kelemen & Szirmay-Kalos 2001), from the albedo tables of hikari::brdf_tables,
// so that a white material reflects what it receives at every roughness and angle. A specular
// weight s (KHR_materials_specular) scales the dielectric's whole specular lobe: Fresnel from
// F0 = lerp(0.04 s, base, m) to F90 = lerp(s, 1, m), and E_d becomes s E_d throughout.

#import hikari::brdf_tables::{BRDF_TABLE_SIZE, brdf_table_albedo_filtered, brdf_table_average}

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
    // Weight of the dielectric's specular lobe in [0, 1] (KHR_materials_specular): 0 is matte.
    specular: f32,
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

// Schlick's Fresnel rising from f0 at normal incidence to f90 at grazing (1 for the usual
// interface; a specular weight lowers it).
fn brdf_fresnel_schlick_f90(f0: vec3<f32>, f90: f32, cos_theta: f32) -> vec3<f32> {
    return f0 + (vec3<f32>(f90) - f0) * brdf_schlick_weight(cos_theta);
}

fn brdf_lambert(albedo: vec3<f32>) -> vec3<f32> {
    return albedo * (1.0 / BRDF_PI);
}

// Floor of 1 - E_avg in the compensation's denominators (hikari_math::brdf::energy::MIN_LOSS).
const BRDF_MIN_LOSS: f32 = 1e-6;

// Lambert scaled by the light the specular lobe (directional albedos e_o toward the viewer,
// e_i toward the light, average e_avg) lets into and out of the body.
fn brdf_albedo_scaled_lambert(albedo: vec3<f32>, e_o: f32, e_i: f32, e_avg: f32) -> vec3<f32> {
    return brdf_lambert(albedo) * ((1.0 - e_o) * (1.0 - e_i) / max(1.0 - e_avg, BRDF_MIN_LOSS));
}

// F_avg = 2 int F(mu) mu dmu for Schlick's Fresnel.
fn brdf_fresnel_schlick_average(f0: vec3<f32>) -> vec3<f32> {
    return f0 + (vec3<f32>(1.0) - f0) * (1.0 / 21.0);
}

// Kulla & Conty 2017: colour of the multiple-scattering lobe, F_avg^2 E_avg / (1 - F_avg (1 - E_avg)).
fn brdf_multiple_scattering_fresnel(f_avg: vec3<f32>, e_avg: f32) -> vec3<f32> {
    return f_avg * f_avg * e_avg / (vec3<f32>(1.0) - f_avg * (1.0 - e_avg));
}

// Perceptual roughness of the isotropic lobe with the anisotropic lobe's peak, (ax ay)^(1/4):
// where the compensation reads the tables (approximate for anisotropic lobes, docs/brdf.md).
fn brdf_isotropic_equivalent_roughness(alphas: vec2<f32>) -> f32 {
    return clamp(sqrt(sqrt(alphas.x * alphas.y)), BRDF_MIN_PERCEPTUAL_ROUGHNESS, 1.0);
}

// Table row of perceptual roughness r: rows sit at r_min + (1 - r_min) u^2. Returns the lower
// row's index and the upper row's weight.
fn brdf_table_row(perceptual_roughness: f32) -> vec2<f32> {
    let u = sqrt(max(perceptual_roughness - BRDF_MIN_PERCEPTUAL_ROUGHNESS, 0.0) / (1.0 - BRDF_MIN_PERCEPTUAL_ROUGHNESS));
    let p = clamp(u, 0.0, 1.0) * f32(BRDF_TABLE_SIZE - 1u);
    let j = min(floor(p), f32(BRDF_TABLE_SIZE - 2u));
    return vec2<f32>(j, p - j);
}

// (E, E_w) at mu = n.l on table row `row` (from brdf_table_row), bilinear in (sqrt(mu), r).
// The texture unit's bilinear filter does the interpolation (its weights may be rounded to a
// few bits on some GPUs: an error of a few 1e-4 at most, as neighbouring entries differ by
// under 0.1).
fn brdf_albedo_lookup_row(mu: f32, row: vec2<f32>) -> vec2<f32> {
    let p = sqrt(clamp(mu, 0.0, 1.0)) * f32(BRDF_TABLE_SIZE - 1u);
    return brdf_table_albedo_filtered(p, row.x + row.y);
}

// Single-scattering albedos (E with F = 1, E_w with F = (1 - v.h)^5) at mu and roughness r.
fn brdf_albedo_lookup(mu: f32, perceptual_roughness: f32) -> vec2<f32> {
    return brdf_albedo_lookup_row(mu, brdf_table_row(perceptual_roughness));
}

// Their cosine-weighted averages (E_avg, E_w,avg) at roughness r.
fn brdf_albedo_average(perceptual_roughness: f32) -> vec2<f32> {
    let row = brdf_table_row(perceptual_roughness);
    let j = u32(row.x);
    return mix(brdf_table_average(j), brdf_table_average(j + 1u), row.y);
}

// Directional albedo of the dielectric's specular lobe (F0 = 0.04, single + multiple
// scattering) from (E, E_w) and the dielectric's multiple-scattering colour.
fn brdf_dielectric_albedo(e: vec2<f32>, dielectric_ms_fresnel: f32) -> f32 {
    return BRDF_DIELECTRIC_F0 * e.x + (1.0 - BRDF_DIELECTRIC_F0) * e.y + dielectric_ms_fresnel * (1.0 - e.x);
}

fn brdf_material_f0(m: BrdfMaterial) -> vec3<f32> {
    let metal = saturate(m.metalness);
    return vec3<f32>(BRDF_DIELECTRIC_F0 * saturate(m.specular) * (1.0 - metal)) + saturate(m.base_color) * metal;
}

fn brdf_material_f90(m: BrdfMaterial) -> f32 {
    return mix(saturate(m.specular), 1.0, saturate(m.metalness));
}

// The material's Fresnel at cosine `cos_theta`, F0 to F90.
fn brdf_material_fresnel(m: BrdfMaterial, cos_theta: f32) -> vec3<f32> {
    return brdf_fresnel_schlick_f90(brdf_material_f0(m), brdf_material_f90(m), cos_theta);
}

fn brdf_material_diffuse_albedo(m: BrdfMaterial) -> vec3<f32> {
    return saturate(m.base_color) * (1.0 - saturate(m.metalness));
}

// The compensation's material terms at table roughness r (hikari_math::brdf::energy::Compensation).
struct BrdfCompensation {
    // brdf_table_row(r).
    row: vec2<f32>,
    e_avg: f32,
    // (1 - m) s F_ms(0.04) + m F_ms(base colour).
    ms_fresnel: vec3<f32>,
    // F_ms(0.04), unweighted.
    dielectric_ms_fresnel: f32,
    // The specular weight s.
    specular: f32,
    // s E_d,avg.
    dielectric_avg: f32,
}

fn brdf_compensation(m: BrdfMaterial, perceptual_roughness: f32) -> BrdfCompensation {
    var c: BrdfCompensation;
    c.row = brdf_table_row(perceptual_roughness);
    let j = u32(c.row.x);
    let avg = mix(brdf_table_average(j), brdf_table_average(j + 1u), c.row.y);
    c.e_avg = avg.x;
    c.dielectric_ms_fresnel = brdf_multiple_scattering_fresnel(brdf_fresnel_schlick_average(vec3<f32>(BRDF_DIELECTRIC_F0)), avg.x).x;
    let metal_fms = brdf_multiple_scattering_fresnel(brdf_fresnel_schlick_average(saturate(m.base_color)), avg.x);
    c.specular = saturate(m.specular);
    c.ms_fresnel = mix(vec3<f32>(c.specular * c.dielectric_ms_fresnel), metal_fms, saturate(m.metalness));
    c.dielectric_avg = c.specular * brdf_dielectric_albedo(avg, c.dielectric_ms_fresnel);
    return c;
}

// What brdf_evaluate derives from the material and the view direction alone: computed once
// a pixel for all the lights that shade it.
struct BrdfView {
    t: vec3<f32>,
    b: vec3<f32>,
    n: vec3<f32>,
    v_local: vec3<f32>,
    alphas: vec2<f32>,
    // Fresnel reflectance at normal incidence and at grazing.
    f_normal: vec3<f32>,
    f_grazing: f32,
    // The specular weight s.
    specular: f32,
    // Albedo-scaled Lambert's view half: rho / pi (1 - E_d(n.v)) / (1 - E_d,avg).
    diffuse: vec3<f32>,
    // Multiple-scattering lobe's view half: F_ms (1 - E(n.v)) / (pi (1 - E_avg)).
    multiple: vec3<f32>,
    // Table row of the compensation's roughness (brdf_table_row).
    row: vec2<f32>,
    dielectric_ms_fresnel: f32,
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
    p.f_grazing = brdf_material_f90(m);
    let c = brdf_compensation(m, brdf_isotropic_equivalent_roughness(p.alphas));
    p.specular = c.specular;
    let e_v = brdf_albedo_lookup_row(p.v_local.z, c.row);
    p.diffuse = brdf_lambert(brdf_material_diffuse_albedo(m))
        * ((1.0 - c.specular * brdf_dielectric_albedo(e_v, c.dielectric_ms_fresnel)) / max(1.0 - c.dielectric_avg, BRDF_MIN_LOSS));
    p.multiple = c.ms_fresnel * ((1.0 - e_v.x) / (BRDF_PI * max(1.0 - c.e_avg, BRDF_MIN_LOSS)));
    p.row = c.row;
    p.dielectric_ms_fresnel = c.dielectric_ms_fresnel;
    p.v_stretched = length(p.v_local * vec3<f32>(p.alphas, 1.0));
    p.inv_alphas = 1.0 / p.alphas;
    p.spec_scale = 1.0 / (2.0 * BRDF_PI * p.alphas.x * p.alphas.y);
    return p;
}

// The light-dependent factors of brdf_evaluate_view, scalars, such that
//   brdf_evaluate_view(p, l) =
//     f_normal w.x + (f_grazing - f_normal) w.y + diffuse w.z + multiple w.w:
// w.x = D V n.l, w.y = D V n.l Schlick(v.h) (from F = f0 + (f90 - f0) Schlick),
// w.z = (1 - E_d(n.l)) n.l, w.w = (1 - E(n.l)) n.l. A caller summing many lights sums their
// weighted light colours and applies the material's colours once (brdf_apply_weights), rather
// than four colour products a light.
fn brdf_light_weights(p: BrdfView, l: vec3<f32>) -> vec4<f32> {
    let l_local = vec3<f32>(dot(p.t, l), dot(p.b, l), dot(p.n, l));
    if p.v_local.z <= 0.0 || l_local.z <= 0.0 {
        return vec4<f32>(0.0);
    }
    let h_local = normalize(p.v_local + l_local);
    // D (brdf_ggx_ndf_aniso) times V (brdf_visibility_stretched) over one division: with both
    // sides above the surface h is too, and the denominators are positive.
    let s = vec3<f32>(h_local.xy * p.inv_alphas, h_local.z);
    let dd = dot(s, s);
    let vis_den = l_local.z * p.v_stretched + p.v_local.z * length(l_local * vec3<f32>(p.alphas, 1.0));
    let spec = l_local.z * p.spec_scale / (dd * dd * vis_den);
    let e_l = brdf_albedo_lookup_row(l_local.z, p.row);
    let diffuse = (1.0 - p.specular * brdf_dielectric_albedo(e_l, p.dielectric_ms_fresnel)) * l_local.z;
    return vec4<f32>(spec, spec * brdf_schlick_weight(dot(p.v_local, h_local)), diffuse, (1.0 - e_l.x) * l_local.z);
}

// Radiance from light weights summed with their colours: a = sum c w.x, b = sum c w.y,
// c = sum c w.z, d = sum c w.w (see brdf_light_weights).
fn brdf_apply_weights(p: BrdfView, a: vec3<f32>, b: vec3<f32>, c: vec3<f32>, d: vec3<f32>) -> vec3<f32> {
    return p.f_normal * a + (vec3<f32>(p.f_grazing) - p.f_normal) * b + p.diffuse * c + p.multiple * d;
}

// brdf_evaluate for a prepared view: BRDF * n.l, 0 when v or l is at or below the surface.
fn brdf_evaluate_view(p: BrdfView, l: vec3<f32>) -> vec3<f32> {
    let w = brdf_light_weights(p, l);
    return brdf_apply_weights(p, vec3<f32>(w.x), vec3<f32>(w.y), vec3<f32>(w.z), vec3<f32>(w.w));
}

// BRDF * n.l, 1/sr, per RGB channel; 0 when v or l is at or below the surface.
fn brdf_evaluate(m: BrdfMaterial, n: vec3<f32>, t: vec3<f32>, b: vec3<f32>, v: vec3<f32>, l: vec3<f32>) -> vec3<f32> {
    return brdf_evaluate_view(brdf_view(m, n, t, b, v), l);
}

// brdf_evaluate without a tangent frame; anisotropy is ignored (the compensation reads the
// material's own roughness).
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
        * brdf_fresnel_schlick_f90(f0, brdf_material_f90(m), dot(v, h));
    let c = brdf_compensation(m, clamp(m.perceptual_roughness, BRDF_MIN_PERCEPTUAL_ROUGHNESS, 1.0));
    let e_v = brdf_albedo_lookup_row(n_dot_v, c.row);
    let e_l = brdf_albedo_lookup_row(n_dot_l, c.row);
    let ms = c.ms_fresnel * ((1.0 - e_v.x) * (1.0 - e_l.x) / (BRDF_PI * max(1.0 - c.e_avg, BRDF_MIN_LOSS)));
    let diff = brdf_albedo_scaled_lambert(
        brdf_material_diffuse_albedo(m),
        c.specular * brdf_dielectric_albedo(e_v, c.dielectric_ms_fresnel),
        c.specular * brdf_dielectric_albedo(e_l, c.dielectric_ms_fresnel),
        c.dielectric_avg,
    );
    return (spec + ms + diff) * n_dot_l;
}
