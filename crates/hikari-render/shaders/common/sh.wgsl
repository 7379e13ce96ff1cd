#define_import_path hikari::sh

// Real orthonormal spherical harmonics up to band 2: the WGSL twin of hikari-math's `sh` module.
//
// Convention (identical to hikari-math, see its crate docs): flat index i = l(l+1)+m, no
// Condon-Shortley phase, for a unit direction (x, y, z):
//   0: 1/(2√π)          1: √3/(2√π)·y      2: √3/(2√π)·z      3: √3/(2√π)·x
//   4: √15/(2√π)·xy     5: √15/(2√π)·yz    6: √5/(4√π)·(3z²−1) 7: √15/(2√π)·xz   8: √15/(4√π)·(x²−y²)
// L1 coefficients are stored as vec4(c0, c1, c2, c3) = (c0, y, z, x); note that Metro Exodus's
// float4 is ordered (x, y, z, c0) instead.

const SH_C0: f32 = 0.28209479177387814;
const SH_C1: f32 = 0.4886025119029199;
const SH_C2: f32 = 1.0925484305920792;
const SH_C3: f32 = 0.31539156525252005;
const SH_C4: f32 = 0.5462742152960396;
const SH_PI: f32 = 3.141592653589793;

// Clamped-cosine band factors π, 2π/3, π/4: irradiance = radiance SH scaled per band.
const SH_COSINE_BANDS: vec3<f32> = vec3<f32>(3.141592653589793, 2.0943951023931953, 0.7853981633974483);

// Deringing: Sloan 2017 window strength λ = SH_DERING_LAMBDA_SCALE · t / (1 − t), t searched on a
// depth-3 binary tree (Patry 2021). Must match hikari_math::sh::dering::LAMBDA_SCALE.
const SH_DERING_LAMBDA_SCALE: f32 = 0.3;

struct ShL2 {
    c: array<f32, 9>,
}

struct ShL2Rgb {
    c: array<vec3<f32>, 9>,
}

fn sh_basis_l1(d: vec3<f32>) -> vec4<f32> {
    return vec4<f32>(SH_C0, SH_C1 * d.y, SH_C1 * d.z, SH_C1 * d.x);
}

fn sh_basis_l2(d: vec3<f32>) -> array<f32, 9> {
    return array<f32, 9>(
        SH_C0,
        SH_C1 * d.y,
        SH_C1 * d.z,
        SH_C1 * d.x,
        SH_C2 * d.x * d.y,
        SH_C2 * d.y * d.z,
        SH_C3 * (3.0 * d.z * d.z - 1.0),
        SH_C2 * d.x * d.z,
        SH_C4 * (d.x * d.x - d.y * d.y),
    );
}

fn sh_eval_l1(c: vec4<f32>, d: vec3<f32>) -> f32 {
    return dot(c, sh_basis_l1(d));
}

fn sh_eval_l2(sh: ShL2, d: vec3<f32>) -> f32 {
    var y = sh_basis_l2(d);
    var c = sh.c;
    var acc = 0.0;
    for (var i = 0u; i < 9u; i++) {
        acc += c[i] * y[i];
    }
    return acc;
}

fn sh_eval_l2_rgb(sh: ShL2Rgb, d: vec3<f32>) -> vec3<f32> {
    var y = sh_basis_l2(d);
    var c = sh.c;
    var acc = vec3<f32>(0.0);
    for (var i = 0u; i < 9u; i++) {
        acc += c[i] * y[i];
    }
    return acc;
}

fn sh_band_of(i: u32) -> u32 {
    return select(select(2u, 1u, i < 4u), 0u, i == 0u);
}

fn sh_scale_bands_l2(sh: ShL2, f: vec3<f32>) -> ShL2 {
    var out = sh;
    for (var i = 0u; i < 9u; i++) {
        out.c[i] *= f[sh_band_of(i)];
    }
    return out;
}

fn sh_scale_bands_l2_rgb(sh: ShL2Rgb, f: vec3<f32>) -> ShL2Rgb {
    var out = sh;
    for (var i = 0u; i < 9u; i++) {
        out.c[i] *= f[sh_band_of(i)];
    }
    return out;
}

// Irradiance E(n) from radiance SH.
fn sh_irradiance_l2_rgb(sh: ShL2Rgb, n: vec3<f32>) -> vec3<f32> {
    return sh_eval_l2_rgb(sh_scale_bands_l2_rgb(sh, SH_COSINE_BANDS), n);
}

fn sh_irradiance_l1(c: vec4<f32>, n: vec3<f32>) -> f32 {
    return SH_COSINE_BANDS.x * SH_C0 * c.x + SH_COSINE_BANDS.y * SH_C1 * dot(c.wyz, n);
}

// SH of a delta function of integral w in direction d.
fn sh_delta_l2(d: vec3<f32>, w: f32) -> ShL2 {
    var out: ShL2;
    var y = sh_basis_l2(d);
    for (var i = 0u; i < 9u; i++) {
        out.c[i] = w * y[i];
    }
    return out;
}

// ---- Deringing (Patry 2021 after Sloan 2017) ----

fn sh_window_sloan2017(lambda: f32) -> vec3<f32> {
    let l = max(lambda, 0.0);
    return vec3<f32>(1.0, 1.0 / (1.0 + 4.0 * l), 1.0 / (1.0 + 36.0 * l));
}

fn sh_dering_window(t: f32) -> vec3<f32> {
    if t >= 1.0 {
        return vec3<f32>(1.0, 0.0, 0.0);
    }
    let tt = max(t, 0.0);
    return sh_window_sloan2017(SH_DERING_LAMBDA_SCALE * tt / (1.0 - tt));
}

struct ShPoly {
    f: f32,
    g: vec3<f32>,
    h: mat3x3<f32>,
}

// Value, gradient and Hessian of the polynomial extension of the L2 function.
fn sh_poly(c: array<f32, 9>, v: vec3<f32>) -> ShPoly {
    var p: ShPoly;
    p.f = SH_C0 * c[0] + SH_C1 * (c[1] * v.y + c[2] * v.z + c[3] * v.x)
        + SH_C2 * (c[4] * v.x * v.y + c[5] * v.y * v.z + c[7] * v.x * v.z)
        + SH_C3 * c[6] * (3.0 * v.z * v.z - 1.0) + SH_C4 * c[8] * (v.x * v.x - v.y * v.y);
    p.g = vec3<f32>(
        SH_C1 * c[3] + SH_C2 * (c[4] * v.y + c[7] * v.z) + 2.0 * SH_C4 * c[8] * v.x,
        SH_C1 * c[1] + SH_C2 * (c[4] * v.x + c[5] * v.z) - 2.0 * SH_C4 * c[8] * v.y,
        SH_C1 * c[2] + SH_C2 * (c[5] * v.y + c[7] * v.x) + 6.0 * SH_C3 * c[6] * v.z,
    );
    // Symmetric, so column order = row order.
    p.h = mat3x3<f32>(
        vec3<f32>(2.0 * SH_C4 * c[8], SH_C2 * c[4], SH_C2 * c[7]),
        vec3<f32>(SH_C2 * c[4], -2.0 * SH_C4 * c[8], SH_C2 * c[5]),
        vec3<f32>(SH_C2 * c[7], SH_C2 * c[5], 6.0 * SH_C3 * c[6]),
    );
    return p;
}

fn sh_any_orthonormal_pair(v: vec3<f32>) -> mat2x3<f32> {
    // Frisvad-style frame, as glam's any_orthonormal_pair.
    let s = select(-1.0, 1.0, v.z >= 0.0);
    let a = -1.0 / (s + v.z);
    let b = v.x * v.y * a;
    return mat2x3<f32>(
        vec3<f32>(1.0 + s * v.x * v.x * a, s * b, -s * v.x),
        vec3<f32>(b, s + v.y * v.y * a, -v.y),
    );
}

// One Riemannian Newton step on the sphere toward a minimum (stays if not locally convex).
fn sh_newton_step(c: array<f32, 9>, v: vec3<f32>) -> vec3<f32> {
    let p = sh_poly(c, v);
    let t = sh_any_orthonormal_pair(v);
    let t1 = t[0];
    let t2 = t[1];
    let vg = dot(v, p.g);
    let a11 = dot(t1, p.h * t1) - vg;
    let a12 = dot(t1, p.h * t2);
    let a22 = dot(t2, p.h * t2) - vg;
    let det = a11 * a22 - a12 * a12;
    if !(a11 > 0.0 && det > 0.0) {
        return v;
    }
    let g1 = dot(t1, p.g);
    let g2 = dot(t2, p.g);
    var step = t1 * (-(a22 * g1 - a12 * g2) / det) + t2 * (-(-a12 * g1 + a11 * g2) / det);
    let len = length(step);
    if len > 1.0 {
        step /= len;
    }
    let w = v + step;
    let wl = length(w);
    return select(v, w / wl, wl > 0.0);
}

// Estimated minimum: xyz = direction, w = value. One Newton step from −(band-1 direction) and 14
// fixed directions, then one refinement step from the best (same as the CPU twin).
fn sh_find_min_l2(sh: ShL2) -> vec4<f32> {
    let c = sh.c;
    let s = 0.57735026918962573;
    var starts = array<vec3<f32>, 15>(
        vec3<f32>(0.0, 0.0, 1.0),
        vec3<f32>(1.0, 0.0, 0.0), vec3<f32>(-1.0, 0.0, 0.0),
        vec3<f32>(0.0, 1.0, 0.0), vec3<f32>(0.0, -1.0, 0.0),
        vec3<f32>(0.0, 0.0, 1.0), vec3<f32>(0.0, 0.0, -1.0),
        vec3<f32>(s, s, s), vec3<f32>(s, s, -s), vec3<f32>(s, -s, s), vec3<f32>(s, -s, -s),
        vec3<f32>(-s, s, s), vec3<f32>(-s, s, -s), vec3<f32>(-s, -s, s), vec3<f32>(-s, -s, -s),
    );
    let lin = -vec3<f32>(c[3], c[1], c[2]);
    let ll = length(lin);
    var first = 1u;
    if ll > 0.0 {
        starts[0] = lin / ll;
        first = 0u;
    }
    var best = vec4<f32>(0.0, 0.0, 1.0, 3.4e38);
    for (var i = first; i < 15u; i++) {
        let v0 = starts[i];
        let f0 = sh_poly(c, v0).f;
        if f0 < best.w {
            best = vec4<f32>(v0, f0);
        }
        let v1 = sh_newton_step(c, v0);
        let f1 = sh_poly(c, v1).f;
        if f1 < best.w {
            best = vec4<f32>(v1, f1);
        }
    }
    let r = sh_newton_step(c, best.xyz);
    let fr = sh_poly(c, r).f;
    if fr < best.w {
        best = vec4<f32>(r, fr);
    }
    return best;
}

fn sh_rgb_channel(sh: ShL2Rgb, k: u32) -> ShL2 {
    var out: ShL2;
    var c = sh.c;
    for (var i = 0u; i < 9u; i++) {
        out.c[i] = c[i][k];
    }
    return out;
}

fn sh_rgb_non_negative(sh: ShL2Rgb) -> bool {
    for (var k = 0u; k < 3u; k++) {
        if sh_find_min_l2(sh_rgb_channel(sh, k)).w < 0.0 {
            return false;
        }
    }
    return true;
}

// Dering strength t in [0, 1] for RGB SH (one strength for all channels, keeping hue).
fn sh_dering_strength_rgb(sh: ShL2Rgb) -> f32 {
    if any(sh.c[0] < vec3<f32>(0.0)) {
        return 1.0;
    }
    if sh_rgb_non_negative(sh) {
        return 0.0;
    }
    var lo = 0.0;
    var hi = 1.0;
    for (var i = 0u; i < 3u; i++) {
        let mid = 0.5 * (lo + hi);
        if sh_rgb_non_negative(sh_scale_bands_l2_rgb(sh, sh_dering_window(mid))) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    return hi;
}

fn sh_dering_l2_rgb(sh: ShL2Rgb) -> ShL2Rgb {
    if any(sh.c[0] < vec3<f32>(0.0)) {
        var zero: ShL2Rgb;
        return zero;
    }
    return sh_scale_bands_l2_rgb(sh, sh_dering_window(sh_dering_strength_rgb(sh)));
}

// ---- Directionality boost (Patry 2021) ----

const SH_LUMA: vec3<f32> = vec3<f32>(0.2126, 0.7152, 0.0722);

// Direction of the maximum of the linear part of the Rec.709 luminance; zero if none.
fn sh_linear_max_dir_rgb(sh: ShL2Rgb) -> vec3<f32> {
    let v = vec3<f32>(dot(sh.c[3], SH_LUMA), dot(sh.c[1], SH_LUMA), dot(sh.c[2], SH_LUMA));
    let l = length(v);
    return select(vec3<f32>(0.0), v / l, l > 0.0);
}

// lerp toward a delta in the linear-maximum direction with the same band-0 (talk: amount 0.25).
fn sh_directionality_boost_rgb(sh: ShL2Rgb, amount: f32) -> ShL2Rgb {
    let d = sh_linear_max_dir_rgb(sh);
    if all(d == vec3<f32>(0.0)) {
        return sh;
    }
    let w = sh.c[0] / SH_C0;
    var y = sh_basis_l2(d);
    var out = sh;
    for (var i = 0u; i < 9u; i++) {
        out.c[i] = mix(sh.c[i], w * y[i], amount);
    }
    return out;
}

// ---- Metro Exodus YCoCg + L1 luminance SH (GDC 2019 bonus slides) ----

struct ShYCoCg {
    // Y as L1 SH: (c0, y, z, x).
    y: vec4<f32>,
    co_cg: vec2<f32>,
}

fn sh_rgb_to_ycocg(c: vec3<f32>) -> vec3<f32> {
    let co = c.r - c.b;
    let t = c.b + co * 0.5;
    let cg = c.g - t;
    return vec3<f32>(t + cg * 0.5, co, cg);
}

fn sh_ycocg_to_rgb(v: vec3<f32>) -> vec3<f32> {
    let t = v.x - v.z * 0.5;
    let g = v.z + t;
    let b = t - v.y * 0.5;
    return vec3<f32>(b + v.y, g, b);
}

fn shy_encode(color: vec3<f32>, dir: vec3<f32>) -> ShYCoCg {
    let v = sh_rgb_to_ycocg(color);
    var out: ShYCoCg;
    out.y = sh_basis_l1(dir) * max(v.x, 0.0);
    out.co_cg = v.yz;
    return out;
}

fn shy_to_color(s: ShYCoCg) -> vec3<f32> {
    return max(sh_ycocg_to_rgb(vec3<f32>(s.y.x / SH_C0, s.co_cg)), vec3<f32>(0.0));
}

// Diffuse radiance of a white Lambertian surface (irradiance / π); samples from a uniform
// hemisphere (pdf 1/2π), hence the factor 2 = 2π/π.
fn shy_resolve_diffuse(s: ShYCoCg, n: vec3<f32>) -> vec3<f32> {
    let d = dot(s.y.wyz, n);
    let y = max(2.0 * ((2.0 * SH_PI / 3.0) * SH_C1 * d + SH_PI * SH_C0 * s.y.x), 0.0);
    let co_cg = s.co_cg * (SH_C0 * y / (s.y.x + 1e-6));
    return max(sh_ycocg_to_rgb(vec3<f32>(y, co_cg)), vec3<f32>(0.0));
}

fn shy_dominant_direction(s: ShYCoCg) -> vec3<f32> {
    let v = s.y.wyz;
    let l = length(v);
    return select(vec3<f32>(0.0), v / l, l > 0.0);
}

// Mean resultant length of the luminance distribution, in [0, 1].
fn shy_directionality(s: ShYCoCg) -> f32 {
    if s.y.x <= 0.0 {
        return 0.0;
    }
    return clamp(length(s.y.yzw) * SH_C0 / (SH_C1 * s.y.x), 0.0, 1.0);
}

// GGX alpha for specular from the SH: material alpha widened by the light's angular spread.
fn shy_specular_alpha(s: ShYCoCg, material_alpha: f32) -> f32 {
    let r = min(shy_directionality(s), 0.999999);
    let kappa = r * (3.0 - r * r) / (1.0 - r * r);
    let alpha_l2 = 2.0 / (kappa + 2.0);
    return min(sqrt(material_alpha * material_alpha + alpha_l2), 1.0);
}
