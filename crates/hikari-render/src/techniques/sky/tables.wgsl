// The atmosphere's tables built on the GPU: the same iteration, parameterisations, sizes and
// working colour space as hikari-atmosphere's `build` (its CPU twin, which this file mirrors
// function by function), in f32. Every table lives in one storage buffer `work` (vec4 texels,
// regions at the offsets in `p.offsets*`, each region laid out as hikari-atmosphere's `Table`:
// x fastest, then y, then z) and is sampled by hand with the CPU's rules (texel centres at
// (i + 0.5) / n, clamp to edge, (tri)linear), so a lookup here reads what the CPU's reads.
// `store` copies the four tables the sky samples into its textures.
//
// Where f32 would lose digits on the Earth's 6360 km radius, the formulas are rearranged
// (differences of squares as products, radii as r + q / (sqrt(r^2 + q) + r)); the values are
// the CPU's, only computed differently.
//
// Entry points, in build order (see `gpu_build.rs`): transmittance; single; ground (order 1);
// luminance (order 1); then per order n >= 2: density, multiple, ground, luminance; then
// irradiance and store. `luminance` applies the CPU's stopping rule (at least 4 orders, then
// stop once an order adds under 1 % of the luminance so far) by setting a flag in `work` that
// makes the later orders' passes return at once.

struct TableBuildParams {
    // Ground radius, top radius, horizon distance sqrt(top^2 - ground^2) (km), MU_S_MIN.
    shell: vec4<f32>,
    // Rayleigh scattering at sea level per working channel (km^-1); w: its scale height (km).
    rayleigh: vec4<f32>,
    // Ozone absorption at the peak per channel (km^-1); w: the peak's altitude (km).
    ozone: vec4<f32>,
    // Mie scattering, Mie extinction (km^-1), scale height (km), asymmetry g.
    mie: vec4<f32>,
    // Ozone half width (km), ground albedo, unused, unused.
    misc: vec4<f32>,
    // Luminance of a working-space colour: dot with these (Rec.709 Y through the space's matrix).
    luminance: vec4<f32>,
    // Transmittance [mu, r], ground irradiance [mu_s, r].
    sizes_2d: vec4<u32>,
    // Scattering [mu, mu_s, r], ray steps.
    sizes_scattering: vec4<u32>,
    // Density [mu, mu_s, r], unused.
    sizes_density: vec4<u32>,
    // Sphere directions [theta, phi]; this pass's scattering order; unused.
    sphere_order: vec4<u32>,
    // Regions of `work`: transmittance, Rayleigh single, Mie single, scattering distance.
    offsets0: vec4<u32>,
    // Delta (this order's multiple scattering), its sum over orders, J Rayleigh, J Mie.
    offsets1: vec4<u32>,
    // Sum of J Rayleigh, sum of J Mie, irradiance Rayleigh, irradiance Mie.
    offsets2: vec4<u32>,
    // Ground irradiance of each order (one slot per order, from order 1), their sum, control,
    // the luminance partials (one per workgroup of 64 scattering texels).
    offsets3: vec4<u32>,
}

@group(0) @binding(0) var<uniform> p: TableBuildParams;
@group(0) @binding(1) var<storage, read_write> work: array<vec4<f32>>;
@group(0) @binding(2) var out_rayleigh: texture_storage_3d<rgba32float, write>;
@group(0) @binding(3) var out_mie: texture_storage_3d<rgba32float, write>;
@group(0) @binding(4) var out_transmittance: texture_storage_2d<rgba32float, write>;
@group(0) @binding(5) var out_rayleigh_single: texture_storage_3d<rgba32float, write>;

const PI: f32 = 3.14159265358979;
// Steps of the transmittance integral (the CPU's `transmittance_to_top(.., 500)`).
const TRANSMITTANCE_STEPS: u32 = 500u;
// hikari-atmosphere's DISTANCE_SCALE and DISTANCE_SCALE_SHADOWED.
const DISTANCE_SCALE: f32 = 0.6;
const DISTANCE_SCALE_SHADOWED: f32 = 0.4;
const INF: f32 = 1e30;
// control (work[offsets3.z]): x total luminance so far, y 1 once stopped, z orders done;
// work[offsets3.z + k].w: the luminance contribution of order k (1-based).

fn bottom() -> f32 { return p.shell.x; }
fn top() -> f32 { return p.shell.y; }
fn horizon() -> f32 { return p.shell.z; }

fn safe_sqrt(x: f32) -> f32 {
    return sqrt(max(x, 0.0));
}

fn coord_from_unit(x: f32, n: u32) -> f32 {
    let nf = f32(n);
    return 0.5 / nf + x * (1.0 - 1.0 / nf);
}

fn unit_from_coord(u: f32, n: u32) -> f32 {
    let nf = f32(n);
    return (u - 0.5 / nf) / (1.0 - 1.0 / nf);
}

fn centre(i: u32, n: u32) -> f32 {
    return unit_from_coord((f32(i) + 0.5) / f32(n), n);
}

// r^2 - bottom^2.
fn rho2_of(r: f32) -> f32 {
    return (r - bottom()) * (r + bottom());
}

// sqrt(r^2 + q) without squaring r: r + q / (sqrt(r^2 + q) + r).
fn radius_plus(r: f32, q: f32) -> f32 {
    return r + q / (safe_sqrt(r * r + q) + r);
}

fn distance_to_top(r: f32, mu: f32) -> f32 {
    let rm = r * mu;
    return max(-rm + safe_sqrt(rm * rm + (top() - r) * (top() + r)), 0.0);
}

fn distance_to_bottom(r: f32, mu: f32) -> f32 {
    let rm = r * mu;
    return max(-rm - safe_sqrt(rm * rm - rho2_of(r)), 0.0);
}

fn hits_ground(r: f32, mu: f32) -> bool {
    let rm = r * mu;
    return mu < 0.0 && rm * rm - rho2_of(r) >= 0.0;
}

fn distance_to_boundary(r: f32, mu: f32, hits: bool) -> f32 {
    if hits {
        return distance_to_bottom(r, mu);
    }
    return distance_to_top(r, mu);
}

// (r, mu) after d km.
fn advance(r: f32, mu: f32, d: f32) -> vec2<f32> {
    let rd = clamp(radius_plus(r, d * (d + 2.0 * r * mu)), bottom(), top());
    return vec2<f32>(rd, clamp((r * mu + d) / rd, -1.0, 1.0));
}

fn densities(h: f32) -> vec3<f32> {
    let ozone = max(1.0 - abs(h - p.ozone.w) / p.misc.x, 0.0);
    return vec3<f32>(exp(-h / p.rayleigh.w), exp(-h / p.mie.z), ozone);
}

fn extinction(h: f32) -> vec3<f32> {
    let d = densities(h);
    return p.rayleigh.xyz * d.x + p.mie.y * d.y + p.ozone.xyz * d.z;
}

fn rayleigh_phase(nu: f32) -> f32 {
    return 3.0 / (16.0 * PI) * (1.0 + nu * nu);
}

fn mie_phase(nu: f32) -> f32 {
    let g = p.mie.w;
    let k = 3.0 / (8.0 * PI) * (1.0 - g * g) / (2.0 + g * g);
    return k * (1.0 + nu * nu) / pow(max(1.0 + g * g - 2.0 * g * nu, 1e-12), 1.5);
}

// --- Sampling the regions of `work` as the CPU's `Table::sample` does. ---

struct Axis {
    i0: u32,
    i1: u32,
    f: f32,
}

fn axis(u: f32, n: u32) -> Axis {
    let t = clamp(u * f32(n) - 0.5, 0.0, f32(n - 1u));
    let i0 = min(u32(floor(t)), n - 1u);
    return Axis(i0, min(i0 + 1u, n - 1u), t - f32(i0));
}

fn sample2(base: u32, n: vec2<u32>, uv: vec2<f32>) -> vec3<f32> {
    let x = axis(uv.x, n.x);
    let y = axis(uv.y, n.y);
    let a = work[base + y.i0 * n.x + x.i0].xyz;
    let b = work[base + y.i0 * n.x + x.i1].xyz;
    let c = work[base + y.i1 * n.x + x.i0].xyz;
    let d = work[base + y.i1 * n.x + x.i1].xyz;
    return mix(mix(a, b, x.f), mix(c, d, x.f), y.f);
}

fn sample3(base: u32, n: vec3<u32>, uvw: vec3<f32>) -> vec3<f32> {
    let z = axis(uvw.z, n.z);
    let a = sample2(base + z.i0 * n.x * n.y, n.xy, uvw.xy);
    let b = sample2(base + z.i1 * n.x * n.y, n.xy, uvw.xy);
    return mix(a, b, z.f);
}

// --- The parameterisations (hikari-atmosphere's `Shell`). ---

fn transmittance_uv(r: f32, mu: f32) -> vec2<f32> {
    let rho = safe_sqrt(rho2_of(r));
    let d = distance_to_top(r, mu);
    let d_min = top() - r;
    let d_max = rho + horizon();
    var x_mu = 0.0;
    if d_max > d_min {
        x_mu = (d - d_min) / (d_max - d_min);
    }
    return vec2<f32>(coord_from_unit(clamp(x_mu, 0.0, 1.0), p.sizes_2d.x), coord_from_unit(rho / horizon(), p.sizes_2d.y));
}

fn trans_top(r: f32, mu: f32) -> vec3<f32> {
    return sample2(p.offsets0.x, p.sizes_2d.xy, transmittance_uv(r, mu));
}

fn trans_sun(r: f32, mu_s: f32) -> vec3<f32> {
    if hits_ground(r, mu_s) {
        return vec3<f32>(0.0);
    }
    return trans_top(r, mu_s);
}

fn trans_between(r: f32, mu: f32, d: f32, hits: bool) -> vec3<f32> {
    let e = advance(r, mu, d);
    var a: vec3<f32>;
    var b: vec3<f32>;
    if hits {
        a = trans_top(e.x, -e.y);
        b = trans_top(r, -mu);
    } else {
        a = trans_top(r, mu);
        b = trans_top(e.x, e.y);
    }
    return select(vec3<f32>(0.0), min(a / max(b, vec3<f32>(1e-38)), vec3<f32>(1.0)), b > vec3<f32>(0.0));
}

fn mu_s_a(mu_s: f32) -> f32 {
    let d_min = top() - bottom();
    return (distance_to_top(bottom(), mu_s) - d_min) / (horizon() - d_min);
}

fn x_mu_s(mu_s: f32) -> f32 {
    let a = mu_s_a(mu_s);
    let big_a = mu_s_a(p.shell.w);
    return clamp(max(1.0 - a / big_a, 0.0) / (1.0 + a), 0.0, 1.0);
}

fn mu_s_from_x(x: f32) -> f32 {
    let d_min = top() - bottom();
    let big_a = mu_s_a(p.shell.w);
    let a = (big_a - x * big_a) / (1.0 + x * big_a);
    let d = d_min + min(a, big_a) * (horizon() - d_min);
    if d == 0.0 {
        return 1.0;
    }
    let h = horizon();
    return clamp((h - d) * (h + d) / (2.0 * bottom() * d), -1.0, 1.0);
}

fn scattering_uvw(r: f32, mu: f32, mu_s: f32, hits: bool) -> vec3<f32> {
    let n = p.sizes_scattering;
    let rho2 = rho2_of(r);
    let rho = safe_sqrt(rho2);
    let u_r = coord_from_unit(rho / horizon(), n.z);
    let r_mu = r * mu;
    let disc = r_mu * r_mu - rho2;
    let half_n = n.x / 2u;
    var u_mu: f32;
    if hits {
        let d = -r_mu - safe_sqrt(disc);
        let d_min = r - bottom();
        let d_max = rho;
        var x = 0.0;
        if d_max != d_min {
            x = clamp((d - d_min) / (d_max - d_min), 0.0, 1.0);
        }
        u_mu = 0.5 - 0.5 * coord_from_unit(x, half_n);
    } else {
        let h = horizon();
        let d = -r_mu + safe_sqrt(disc + h * h);
        let d_min = top() - r;
        let d_max = rho + h;
        let x = clamp((d - d_min) / (d_max - d_min), 0.0, 1.0);
        u_mu = 0.5 + 0.5 * coord_from_unit(x, half_n);
    }
    return vec3<f32>(u_mu, coord_from_unit(x_mu_s(mu_s), n.y), u_r);
}

fn scat_uvw(r: f32, mu: f32, mu_s: f32) -> vec3<f32> {
    return scattering_uvw(r, mu, mu_s, hits_ground(r, mu));
}

fn density_uvw(r: f32, mu: f32, mu_s: f32) -> vec3<f32> {
    let n = p.sizes_density;
    let rho = safe_sqrt(rho2_of(r));
    return vec3<f32>(coord_from_unit(0.5 * (mu + 1.0), n.x), coord_from_unit(x_mu_s(mu_s), n.y), coord_from_unit(rho / horizon(), n.z));
}

fn ground_uv(r: f32, mu_s: f32) -> vec2<f32> {
    return vec2<f32>(
        coord_from_unit(clamp((mu_s + 0.2) / 1.2, 0.0, 1.0), p.sizes_2d.z),
        coord_from_unit(clamp((r - bottom()) / (top() - bottom()), 0.0, 1.0), p.sizes_2d.w),
    );
}

struct Texel {
    r: f32,
    mu: f32,
    mu_s: f32,
    hits: bool,
    // r^2 - bottom^2 from the texel's own rho: (r - bottom)(r + bottom) in f32 would carry the
    // rounding of r (0.5 m at 6360 km), a few km^2, enough to flip a grazing ray's test.
    rho2: f32,
}

// The (r, mu, mu_s, hits_ground) of scattering texel `i` (`scat_texel`, `scattering_r_mu`).
fn scat_texel(i: u32) -> Texel {
    let n = p.sizes_scattering;
    let x = i % n.x;
    let y = (i / n.x) % n.y;
    let z = i / (n.x * n.y);
    let rho = horizon() * centre(z, n.z);
    let r = radius_plus(bottom(), rho * rho);
    let half_n = n.x / 2u;
    let u_mu = (f32(x) + 0.5) / f32(n.x);
    var mu: f32;
    var hits: bool;
    if u_mu < 0.5 {
        let xm = unit_from_coord(1.0 - 2.0 * u_mu, half_n);
        let d_min = r - bottom();
        let d = d_min + xm * (rho - d_min);
        mu = select(-(rho * rho + d * d) / (2.0 * r * d), -1.0, d == 0.0);
        hits = true;
    } else {
        let xm = unit_from_coord(2.0 * u_mu - 1.0, half_n);
        let d_min = top() - r;
        let h = horizon();
        let d = d_min + xm * (rho + h - d_min);
        mu = select(((h - rho) * (h + rho) - d * d) / (2.0 * r * d), 1.0, d == 0.0);
        hits = false;
    }
    let mu_s = mu_s_from_x(centre(y, n.y));
    return Texel(r, clamp(mu, -1.0, 1.0), mu_s, hits, rho * rho);
}

// --- Single scattering with the run-time Earth-shadow and azimuth terms (`single_parts`). ---

fn shadow_length(r: f32, mu: f32, mu_s: f32, nu: f32) -> f32 {
    let rs = r * mu_s;
    let c = rho2_of(r) - rs * rs;
    if mu_s >= 0.0 || c >= 0.0 {
        return 0.0;
    }
    let a = max(1.0 - nu * nu, 0.0);
    let b = r * (mu - mu_s * nu);
    if a <= 1e-12 {
        if b > 0.0 {
            return -c / (2.0 * b);
        }
        return INF;
    }
    return max((-b + safe_sqrt(b * b - a * c)) / a, 0.0);
}

struct Parts {
    rayleigh: vec3<f32>,
    mie: vec3<f32>,
}

fn single_parts(r0: f32, mu0: f32, mu_s0: f32, nu: f32) -> Parts {
    let shadow = shadow_length(r0, mu0, mu_s0, nu);
    var r = r0;
    var mu = mu0;
    var mu_s = mu_s0;
    var tl = vec3<f32>(1.0);
    var k = DISTANCE_SCALE;
    if shadow > 0.0 {
        let hits = hits_ground(r0, mu0);
        if shadow >= INF || shadow >= distance_to_boundary(r0, mu0, hits) {
            return Parts(vec3<f32>(0.0), vec3<f32>(0.0));
        }
        let e = advance(r0, mu0, shadow);
        r = e.x;
        mu = e.y;
        mu_s = clamp((r0 * mu_s0 + shadow * nu) / e.x, -1.0, 1.0);
        tl = trans_between(r0, mu0, shadow, hits);
        k = DISTANCE_SCALE_SHADOWED;
    }
    let n = p.sizes_scattering.xyz;
    let de = sample3(p.offsets0.w, n, scat_uvw(r, mu, mu_s)).xy * k;
    let shift_r = clamp((r * mu_s + de.x * nu) / max(r + de.x * mu, 1.0), -1.0, 1.0);
    let shift_m = clamp((r * mu_s + de.y * nu) / max(r + de.y * mu, 1.0), -1.0, 1.0);
    let ray = sample3(p.offsets0.y, n, scat_uvw(r, mu, shift_r)) * tl;
    let mie = sample3(p.offsets0.z, n, scat_uvw(r, mu, shift_m)) * tl;
    return Parts(ray, mie);
}

// Radiance of the previous order towards (mu, mu_s, nu) at r: single scattering for order 2,
// else the last order's delta table.
fn previous_radiance(order: u32, r: f32, mu: f32, mu_s: f32, nu: f32) -> vec3<f32> {
    if order <= 2u {
        let s = single_parts(r, mu, mu_s, nu);
        return s.rayleigh * rayleigh_phase(nu) + s.mie * mie_phase(nu);
    }
    return sample3(p.offsets1.x, p.sizes_scattering.xyz, scat_uvw(r, mu, mu_s));
}

fn control() -> vec4<f32> {
    return work[p.offsets3.z];
}

fn stopped() -> bool {
    return control().y > 0.5;
}

// --- Passes. ---

@compute @workgroup_size(64, 1, 1)
fn transmittance(@builtin(global_invocation_id) gid: vec3<u32>) {
    let n = p.sizes_2d.xy;
    let i = gid.x;
    if i >= n.x * n.y {
        return;
    }
    let x_mu = centre(i % n.x, n.x);
    let x_r = centre(i / n.x, n.y);
    // transmittance_r_mu
    let rho = horizon() * x_r;
    let r = radius_plus(bottom(), rho * rho);
    let d_min = top() - r;
    let d_max = rho + horizon();
    let dd = d_min + x_mu * (d_max - d_min);
    let h = horizon();
    let mu = clamp(select(((h - rho) * (h + rho) - dd * dd) / (2.0 * r * dd), 1.0, dd == 0.0), -1.0, 1.0);
    // transmittance_to_top
    let d = distance_to_top(r, mu);
    let dx = d / f32(TRANSMITTANCE_STEPS);
    var tau = vec3<f32>(0.0);
    for (var k = 0u; k <= TRANSMITTANCE_STEPS; k++) {
        let di = f32(k) * dx;
        let ri = radius_plus(r, di * (di + 2.0 * r * mu));
        let w = select(1.0, 0.5, k == 0u || k == TRANSMITTANCE_STEPS);
        tau += w * extinction(ri - bottom()) * dx;
    }
    work[p.offsets0.x + i] = vec4<f32>(exp(-tau), 0.0);
}

struct Ray {
    a: vec3<f32>,
    b: vec3<f32>,
    // Integrals of distance times the middle channel of a and b.
    db: vec2<f32>,
}

// Single scattering of a texel's ray: `integrate_ray` with the direct sun as the source.
fn integrate_single(t: Texel) -> Ray {
    let n = p.sizes_scattering.w;
    let d_end = distance_to_boundary(t.r, t.mu, t.hits);
    let dx = d_end / f32(n);
    let nu = t.mu * t.mu_s;
    var out = Ray(vec3<f32>(0.0), vec3<f32>(0.0), vec2<f32>(0.0));
    for (var i = 0u; i <= n; i++) {
        let d = f32(i) * dx;
        let e = advance(t.r, t.mu, d);
        let mu_s_d = clamp((t.r * t.mu_s + d * nu) / e.x, -1.0, 1.0);
        let tv = trans_between(t.r, t.mu, d, t.hits);
        // hits_ground(r_d, mu_s_d) without r_d: r_d mu_s_d = r mu_s + d nu and r_d^2 - bottom^2
        // = rho^2 + d (d + 2 r mu) exactly; a sample near the sun's horizon keeps its side.
        let rs = t.r * t.mu_s + d * nu;
        let hidden = rs < 0.0 && rs * rs - (t.rho2 + d * (d + 2.0 * t.r * t.mu)) >= 0.0;
        let ts = select(trans_top(e.x, mu_s_d), vec3<f32>(0.0), hidden);
        let dens = densities(e.x - bottom());
        let sa = ts * dens.x * p.rayleigh.xyz;
        let sb = ts * dens.y * p.mie.x;
        let w = select(dx, 0.5 * dx, i == 0u || i == n);
        out.a += w * tv * sa;
        out.b += w * tv * sb;
        out.db += w * d * vec2<f32>(tv.y * sa.y, tv.y * sb.y);
    }
    return out;
}

const SUM_THREADS: u32 = 256u;
var<workgroup> partial: array<f32, SUM_THREADS>;

// Sums `value` over the 64 threads of a texel pass's workgroup into the workgroup's slot of
// the luminance partials (`offsets3.w`), which `luminance` adds up: the order's luminance
// costs one small reduction per workgroup instead of a second sweep over the table.
fn store_partial(lid: u32, group: u32, value: f32) {
    partial[lid] = value;
    workgroupBarrier();
    for (var stride = 32u; stride > 0u; stride >>= 1u) {
        if lid < stride {
            partial[lid] += partial[lid + stride];
        }
        workgroupBarrier();
    }
    if lid == 0u {
        work[p.offsets3.w + group] = vec4<f32>(partial[0], 0.0, 0.0, 0.0);
    }
}

@compute @workgroup_size(64, 1, 1)
fn single(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(local_invocation_index) lid: u32, @builtin(workgroup_id) wg: vec3<u32>) {
    let n = p.sizes_scattering;
    let i = gid.x;
    var lum = 0.0;
    if i < n.x * n.y * n.z {
        let t = scat_texel(i);
        let s = integrate_single(t);
        work[p.offsets0.y + i] = vec4<f32>(s.a, 0.0);
        work[p.offsets0.z + i] = vec4<f32>(s.b, 0.0);
        let dr = select(0.0, s.db.x / s.a.y, s.a.y > 0.0);
        let dm = select(0.0, s.db.y / s.b.y, s.b.y > 0.0);
        work[p.offsets0.w + i] = vec4<f32>(dr, dm, 0.0, 0.0);
        // The CPU's luminance_sum: single scattering times its phases at the texel's angle.
        let nu = t.mu * t.mu_s;
        lum = dot(p.luminance.xyz, s.a) * rayleigh_phase(nu) + dot(p.luminance.xyz, s.b) * mie_phase(nu);
    }
    store_partial(lid, wg.x, lum);
}

// Sky irradiance on a horizontal plane from the previous order's radiance (order 1: single
// scattering), for the ground table of `order`.
@compute @workgroup_size(64, 1, 1)
fn ground(@builtin(global_invocation_id) gid: vec3<u32>) {
    let n = p.sizes_2d.zw;
    let i = gid.x;
    let order = p.sphere_order.z;
    if i >= n.x * n.y || (order > 1u && stopped()) {
        return;
    }
    let mu_s = -0.2 + 1.2 * centre(i % n.x, n.x);
    let r = bottom() + (top() - bottom()) * centre(i / n.x, n.y);
    let nt = p.sphere_order.x;
    let np = p.sphere_order.y;
    let dt = 0.5 * PI / f32(nt);
    let dp = 2.0 * PI / f32(np);
    let sun = vec3<f32>(0.0, safe_sqrt(1.0 - mu_s * mu_s), mu_s);
    var e = vec3<f32>(0.0);
    // Order 1's table reads single scattering; order n's the delta of order n (passed as n + 1
    // to previous_radiance, which reads the table of the order before its argument).
    let prev = select(order + 1u, 2u, order == 1u);
    for (var it = 0u; it < nt; it++) {
        let theta = (f32(it) + 0.5) * dt;
        let st = sin(theta);
        let ct = cos(theta);
        for (var ip = 0u; ip < np; ip++) {
            let phi = (f32(ip) + 0.5) * dp;
            let dir = vec3<f32>(st * cos(phi), st * sin(phi), ct);
            let l = previous_radiance(prev, r, ct, mu_s, dot(dir, sun));
            e += l * (ct * st * dt * dp);
        }
    }
    work[p.offsets3.x + (order - 1u) * n.x * n.y + i] = vec4<f32>(e, 0.0);
}

// The order's summed luminance over every scattering texel (the partials its `single` or
// `multiple` pass left, one per workgroup of 64 texels), and the stopping rule.
@compute @workgroup_size(256, 1, 1)
fn luminance(@builtin(local_invocation_index) lid: u32) {
    let n = p.sizes_scattering;
    let groups = (n.x * n.y * n.z + 63u) / 64u;
    let order = p.sphere_order.z;
    var sum = 0.0;
    for (var i = lid; i < groups; i += SUM_THREADS) {
        sum += work[p.offsets3.w + i].x;
    }
    partial[lid] = sum;
    workgroupBarrier();
    for (var stride = SUM_THREADS / 2u; stride > 0u; stride >>= 1u) {
        if lid < stride {
            partial[lid] += partial[lid + stride];
        }
        workgroupBarrier();
    }
    if lid == 0u {
        let c = control();
        if order == 1u {
            work[p.offsets3.z] = vec4<f32>(partial[0], 0.0, 1.0, 0.0);
            work[p.offsets3.z + 1u] = vec4<f32>(0.0, 0.0, 0.0, 1.0);
        } else if c.y < 0.5 {
            let lum = partial[0];
            let contribution = select(0.0, lum / c.x, c.x > 0.0);
            let stop = order >= 4u && contribution < 0.01;
            work[p.offsets3.z] = vec4<f32>(c.x + lum, select(0.0, 1.0, stop), f32(order), 0.0);
            work[p.offsets3.z + order] = vec4<f32>(0.0, 0.0, 0.0, contribution);
        }
    }
}

// The scattering density of `order` (the light scattered at each point towards each
// direction, divided by nothing: `scattered_light`), from the previous order and the ground.
@compute @workgroup_size(64, 1, 1)
fn density(@builtin(global_invocation_id) gid: vec3<u32>) {
    let n = p.sizes_density;
    let i = gid.x;
    let order = p.sphere_order.z;
    if i >= n.x * n.y * n.z || stopped() {
        return;
    }
    let mu = 2.0 * centre(i % n.x, n.x) - 1.0;
    let mu_s = mu_s_from_x(centre((i / n.x) % n.y, n.y));
    let rho = horizon() * centre(i / (n.x * n.y), n.z);
    let r = radius_plus(bottom(), rho * rho);
    let view = vec3<f32>(safe_sqrt(1.0 - mu * mu), 0.0, mu);
    let sun = vec3<f32>(0.0, safe_sqrt(1.0 - mu_s * mu_s), mu_s);
    let nt = p.sphere_order.x;
    let np = p.sphere_order.y;
    let dt = PI / f32(nt);
    let dp = 2.0 * PI / f32(np);
    let ng = p.sizes_2d.zw;
    let ground_base = p.offsets3.x + (max(order, 3u) - 3u) * ng.x * ng.y;
    var jr = vec3<f32>(0.0);
    var jm = vec3<f32>(0.0);
    for (var it = 0u; it < nt; it++) {
        let theta = (f32(it) + 0.5) * dt;
        let st = sin(theta);
        let ct = cos(theta);
        for (var ip = 0u; ip < np; ip++) {
            let phi = (f32(ip) + 0.5) * dp;
            let dir = vec3<f32>(st * cos(phi), st * sin(phi), ct);
            var l = previous_radiance(order, r, ct, mu_s, dot(dir, sun));
            // hits_ground(r, ct) with the texel's exact rho^2 (see Texel::rho2).
            if ct < 0.0 && (r * ct) * (r * ct) - rho * rho >= 0.0 {
                let d = distance_to_bottom(r, ct);
                let g = vec3<f32>(d * dir.x, d * dir.y, r + d * dir.z);
                let mu_s_g = dot(g, sun) / length(g);
                var e: vec3<f32>;
                if order == 2u {
                    e = trans_sun(bottom(), mu_s_g) * max(mu_s_g, 0.0);
                } else {
                    e = sample2(ground_base, ng, ground_uv(bottom(), mu_s_g));
                }
                let tg = trans_between(r, ct, d, true);
                l += tg * e * (p.misc.y / PI);
            }
            let c = dot(dir, view);
            let dw = st * dt * dp;
            jr += l * (dw * rayleigh_phase(c));
            jm += l * (dw * mie_phase(c));
        }
    }
    work[p.offsets1.z + i] = vec4<f32>(jr, 0.0);
    work[p.offsets1.w + i] = vec4<f32>(jm, 0.0);
    work[p.offsets2.x + i] += vec4<f32>(jr, 0.0);
    work[p.offsets2.y + i] += vec4<f32>(jm, 0.0);
}

// Multiple scattering of `order`: the density integrated along each texel's ray.
@compute @workgroup_size(64, 1, 1)
fn multiple(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(local_invocation_index) lid: u32, @builtin(workgroup_id) wg: vec3<u32>) {
    let n = p.sizes_scattering;
    let i = gid.x;
    var lum = 0.0;
    if i < n.x * n.y * n.z && !stopped() {
        lum = dot(p.luminance.xyz, multiple_texel(i));
    }
    store_partial(lid, wg.x, lum);
}

// Order n's multiple scattering of texel i, written to the delta table and added to the sum.
fn multiple_texel(i: u32) -> vec3<f32> {
    let n = p.sizes_scattering;
    let t = scat_texel(i);
    let steps = n.w;
    let d_end = distance_to_boundary(t.r, t.mu, t.hits);
    let dx = d_end / f32(steps);
    let nu = t.mu * t.mu_s;
    let nd = p.sizes_density.xyz;
    var a = vec3<f32>(0.0);
    for (var k = 0u; k <= steps; k++) {
        let d = f32(k) * dx;
        let e = advance(t.r, t.mu, d);
        let mu_s_d = clamp((t.r * t.mu_s + d * nu) / e.x, -1.0, 1.0);
        let tv = trans_between(t.r, t.mu, d, t.hits);
        let uvw = density_uvw(e.x, e.y, mu_s_d);
        let dens = densities(e.x - bottom());
        let jr = sample3(p.offsets1.z, nd, uvw);
        let jm = sample3(p.offsets1.w, nd, uvw);
        let s = jr * dens.x * p.rayleigh.xyz + jm * dens.y * p.mie.x;
        let w = select(dx, 0.5 * dx, k == 0u || k == steps);
        a += w * tv * s;
    }
    work[p.offsets1.x + i] = vec4<f32>(a, 0.0);
    work[p.offsets1.y + i] += vec4<f32>(a, 0.0);
    return a;
}

// The talk's irradiance tables: direct sun plus the summed density divided by each phase.
@compute @workgroup_size(64, 1, 1)
fn irradiance(@builtin(global_invocation_id) gid: vec3<u32>) {
    let n = p.sizes_scattering;
    let i = gid.x;
    if i >= n.x * n.y * n.z {
        return;
    }
    let t = scat_texel(i);
    let direct = trans_sun(t.r, t.mu_s);
    let uvw = density_uvw(t.r, t.mu, t.mu_s);
    let nd = p.sizes_density.xyz;
    let nu = t.mu * t.mu_s;
    work[p.offsets2.z + i] = vec4<f32>(direct + sample3(p.offsets2.x, nd, uvw) / rayleigh_phase(nu), 0.0);
    work[p.offsets2.w + i] = vec4<f32>(direct + sample3(p.offsets2.y, nd, uvw) / mie_phase(nu), 0.0);
}

// The sky's textures (Rayleigh of all orders; Rayleigh single with the Rayleigh scattering
// distance in alpha; Mie single with the Mie scattering distance in alpha; transmittance) and
// the ground irradiance summed over the orders that ran.
@compute @workgroup_size(64, 1, 1)
fn store(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.x;
    let n = p.sizes_scattering;
    if i < n.x * n.y * n.z {
        let t = scat_texel(i);
        let c = vec3<u32>(i % n.x, (i / n.x) % n.y, i / (n.x * n.y));
        let ray = work[p.offsets0.y + i].xyz + work[p.offsets1.y + i].xyz / rayleigh_phase(t.mu * t.mu_s);
        let distance = work[p.offsets0.w + i].xy;
        textureStore(out_rayleigh, c, vec4<f32>(ray, 0.0));
        textureStore(out_rayleigh_single, c, vec4<f32>(work[p.offsets0.y + i].xyz, distance.x));
        textureStore(out_mie, c, vec4<f32>(work[p.offsets0.z + i].xyz, distance.y));
    }
    let nt = p.sizes_2d.xy;
    if i < nt.x * nt.y {
        textureStore(out_transmittance, vec2<u32>(i % nt.x, i / nt.x), work[p.offsets0.x + i]);
    }
    let ng = p.sizes_2d.zw;
    if i < ng.x * ng.y {
        let orders = u32(control().z);
        var e = vec3<f32>(0.0);
        for (var k = 0u; k < orders; k++) {
            e += work[p.offsets3.x + k * ng.x * ng.y + i].xyz;
        }
        work[p.offsets3.y + i] = vec4<f32>(e, 0.0);
    }
}
