#define_import_path hikari::sky

// The sky for other techniques: inscattered radiance towards any direction from the camera's
// altitude, the sun's and moon's disks, the ground below the horizon, and transmittance. Reads
// the per-frame 2D tables (`sky.resampled`: the multiple scattering resampled at this frame's
// sun and moon angles by `resample.wgsl`), the persistent transmittance table, and the
// persistent 3D single-scattering tables, which carry each texel's scattering distance in
// alpha: the single scattering is read per direction with the Earth-shadow and azimuth terms of
// hikari-atmosphere's `Atmosphere::sky_radiance` (`Ctx::single_parts`). Binding set `sky`
// (`SkyFrame::lookup`). The tables are in the atmosphere's working space per unit
// extraterrestrial illuminance; results here are linear Rec.709 nits. CPU twin:
// `sky::reference`. The table parameterisations mirror hikari-atmosphere's `Shell`.

struct SkyParams {
    // xyz: unit vector towards the sun; w: its extraterrestrial illuminance in lux (0: none).
    sun: vec4<f32>,
    // xyz: unit vector towards the moon; w: its extraterrestrial illuminance in lux.
    moon: vec4<f32>,
    // x: sun angular radius, y: moon angular radius (radians), z: moon illuminated fraction,
    // w: 1 to draw the disks.
    disks: vec4<f32>,
    // Ground radius, top radius, horizon distance sqrt(top^2 - ground^2) (km), camera altitude (km).
    shell: vec4<f32>,
    // Scattering table texels along mu, mu_s, r; w: Mie asymmetry g.
    table: vec4<f32>,
    // x, y: the sun's and moon's texel coordinates along mu_s; z: sky brightness; w: unused.
    light_coords: vec4<f32>,
    // Rows of the working space -> linear Rec.709 matrix.
    rec709_from_working: array<vec4<f32>, 3>,
    // D65 white (Rec.709 (1, 1, 1)) in the working space.
    white: vec4<f32>,
    // Transmittance texels along mu and r; z, w: unused.
    transmittance_size: vec4<f32>,
    // Radiance of the ground (albedo lit by sun and sky) in the working space, nits.
    ground: vec4<f32>,
}

@group(#{SKY_GROUP}) @binding(0) var<uniform> sky: SkyParams;
// Multiple scattering (Rayleigh of all orders minus single, / Rayleigh phase); layers: sun,
// moon; [mu, r].
@group(#{SKY_GROUP}) @binding(1) var sky_resampled: texture_2d_array<f32>;
@group(#{SKY_GROUP}) @binding(2) var sky_transmittance_table: texture_2d<f32>;
// [mu, mu_s, r]; rgb: Rayleigh single scattering / phase; a: its scattering distance (km).
@group(#{SKY_GROUP}) @binding(3) var sky_rayleigh_single: texture_3d<f32>;
// [mu, mu_s, r]; rgb: Mie single scattering / phase; a: its scattering distance (km).
@group(#{SKY_GROUP}) @binding(4) var sky_mie_single: texture_3d<f32>;

const SKY_PI: f32 = 3.14159265358979;
// Linear limb darkening I(mu) = 1 - u (1 - mu) of the sun's disk in the visible (Pierce &
// Slaughter 1977 give u ~ 0.6 around 550 nm); the mean over the disk is 1 - u / 3.
const SKY_LIMB_U: f32 = 0.6;
// hikari-atmosphere's geometry::MU_S_MIN (cos 102°: the tables' lowest light).
const SKY_MU_S_MIN: f32 = -0.2079116908177593;
// hikari-atmosphere's build::DISTANCE_SCALE and DISTANCE_SCALE_SHADOWED: the fraction of a
// texel's scattering distance at which the azimuth term matches the light's angle.
const SKY_DISTANCE_SCALE: f32 = 0.6;
const SKY_DISTANCE_SCALE_SHADOWED: f32 = 0.4;

fn sky_coord(x: f32, n: f32) -> f32 {
    return 0.5 / n + x * (1.0 - 1.0 / n);
}

fn sky_rec709_from_working(v: vec3<f32>) -> vec3<f32> {
    return vec3<f32>(dot(sky.rec709_from_working[0].xyz, v), dot(sky.rec709_from_working[1].xyz, v), dot(sky.rec709_from_working[2].xyz, v));
}

fn sky_radius() -> f32 {
    return sky.shell.x + clamp(sky.shell.w, 0.0, sky.shell.y - sky.shell.x - 1e-3);
}

// The camera's rho^2 = r^2 - bottom^2, from its altitude: the difference of two squares of
// 6360 km would lose most of f32's digits near the ground.
fn sky_radius_rho2() -> f32 {
    let a = clamp(sky.shell.w, 0.0, sky.shell.y - sky.shell.x - 1e-3);
    return a * (2.0 * sky.shell.x + a);
}

// Scattering table coordinates (u_mu, u_r) of a ray from radius r (rho2 = r^2 - bottom^2,
// computed without cancellation by the caller) with zenith cosine mu.
fn sky_scattering_uv(r: f32, rho2: f32, mu: f32) -> vec2<f32> {
    let bottom = sky.shell.x;
    let top = sky.shell.y;
    let h = sky.shell.z;
    let rho = sqrt(max(rho2, 0.0));
    let u_r = sky_coord(rho / h, sky.table.z);
    let r_mu = r * mu;
    let disc = r_mu * r_mu - rho2;
    let half_n = sky.table.x * 0.5;
    var u_mu: f32;
    if mu < 0.0 && disc >= 0.0 {
        let d = -r_mu - sqrt(max(disc, 0.0));
        let d_min = r - bottom;
        let d_max = rho;
        var x = 0.0;
        if d_max != d_min {
            x = clamp((d - d_min) / (d_max - d_min), 0.0, 1.0);
        }
        u_mu = 0.5 - 0.5 * sky_coord(x, half_n);
    } else {
        let d = -r_mu + sqrt(max(disc + h * h, 0.0));
        let d_min = top - r;
        let d_max = rho + h;
        let x = clamp((d - d_min) / (d_max - d_min), 0.0, 1.0);
        u_mu = 0.5 + 0.5 * sky_coord(x, half_n);
    }
    return vec2<f32>(u_mu, u_r);
}

// `Shell::x_mu_s`'s distance fraction a(mu_s).
fn sky_mu_s_a(mu_s: f32) -> f32 {
    let bottom = sky.shell.x;
    let h = sky.shell.z;
    let d_min = sky.shell.y - bottom;
    // The distance from the ground to the top along mu_s: -R mu_s + sqrt(R^2 mu_s^2 + h^2).
    let rm = bottom * mu_s;
    let d = max(-rm + sqrt(rm * rm + h * h), 0.0);
    return (d - d_min) / (h - d_min);
}

// The light-angle texel coordinate in [0, 1] of the scattering tables (`Shell::x_mu_s`), texel
// centred; `big_a` is sky_mu_s_a(SKY_MU_S_MIN), computed once by the caller.
fn sky_u_mu_s(mu_s: f32, big_a: f32) -> f32 {
    let a = sky_mu_s_a(mu_s);
    return sky_coord(clamp(max(1.0 - a / big_a, 0.0) / (1.0 + a), 0.0, 1.0), sky.table.y);
}

fn sky_load_single(mie: bool, c: vec3<i32>) -> vec4<f32> {
    if mie {
        return textureLoad(sky_mie_single, c, 0);
    }
    return textureLoad(sky_rayleigh_single, c, 0);
}

// Trilinear in a single-scattering table, with the CPU's rules (`Table::sample`).
fn sky_trilinear(mie: bool, uvw: vec3<f32>) -> vec4<f32> {
    let size = vec3<f32>(textureDimensions(sky_mie_single));
    let t = clamp(uvw * size - 0.5, vec3<f32>(0.0), size - 1.0);
    let i0 = vec3<i32>(floor(t));
    let i1 = min(i0 + 1, vec3<i32>(size) - 1);
    let f = t - vec3<f32>(i0);
    var out = vec4<f32>(0.0);
    for (var k = 0; k < 8; k++) {
        let pick = vec3<bool>((k & 1) != 0, (k & 2) != 0, (k & 4) != 0);
        let w = select(1.0 - f, f, pick);
        out += (w.x * w.y * w.z) * sky_load_single(mie, select(i0, i1, pick));
    }
    return out;
}

// The Rayleigh (x) and Mie (y) scattering distances (alpha of the two single-scattering
// tables), trilinear with the weights shared.
fn sky_scattering_distances(uvw: vec3<f32>) -> vec2<f32> {
    let size = vec3<f32>(textureDimensions(sky_mie_single));
    let t = clamp(uvw * size - 0.5, vec3<f32>(0.0), size - 1.0);
    let i0 = vec3<i32>(floor(t));
    let i1 = min(i0 + 1, vec3<i32>(size) - 1);
    let f = t - vec3<f32>(i0);
    var out = vec2<f32>(0.0);
    for (var k = 0; k < 8; k++) {
        let pick = vec3<bool>((k & 1) != 0, (k & 2) != 0, (k & 4) != 0);
        let w = select(1.0 - f, f, pick);
        let c = select(i0, i1, pick);
        out += (w.x * w.y * w.z) * vec2<f32>(textureLoad(sky_rayleigh_single, c, 0).w, textureLoad(sky_mie_single, c, 0).w);
    }
    return out;
}

// Bilinear with clamp to edge and texel centres at (i + 0.5) / n, as the CPU tables sample.
fn sky_bilinear(layer: i32, uv: vec2<f32>) -> vec3<f32> {
    let size = vec2<f32>(textureDimensions(sky_resampled));
    let t = clamp(uv * size - 0.5, vec2<f32>(0.0), size - 1.0);
    let i0 = vec2<i32>(floor(t));
    let i1 = min(i0 + 1, vec2<i32>(size) - 1);
    let f = t - vec2<f32>(i0);
    let a = textureLoad(sky_resampled, vec2<i32>(i0.x, i0.y), layer, 0).rgb;
    let b = textureLoad(sky_resampled, vec2<i32>(i1.x, i0.y), layer, 0).rgb;
    let c = textureLoad(sky_resampled, vec2<i32>(i0.x, i1.y), layer, 0).rgb;
    let d = textureLoad(sky_resampled, vec2<i32>(i1.x, i1.y), layer, 0).rgb;
    return mix(mix(a, b, f.x), mix(c, d, f.x), f.y);
}

fn sky_rayleigh_phase(nu: f32) -> f32 {
    return 3.0 / (16.0 * SKY_PI) * (1.0 + nu * nu);
}

fn sky_mie_phase(nu: f32, g: f32) -> f32 {
    let g2 = g * g;
    let k = 3.0 / (8.0 * SKY_PI) * (1.0 - g2) / (2.0 + g2);
    return k * (1.0 + nu * nu) / pow(max(1.0 + g2 - 2.0 * g * nu, 1e-6), 1.5);
}

// Transmittance (working space) from radius r (rho2 = r^2 - bottom^2) along zenith cosine mu
// to the top, read from the table whether or not the ray meets the ground (`Ctx::trans_top`).
fn sky_trans_top(r: f32, rho2: f32, mu: f32) -> vec3<f32> {
    let top = sky.shell.y;
    let h = sky.shell.z;
    let rho = sqrt(max(rho2, 0.0));
    let d = max(-r * mu + sqrt(max(r * r * mu * mu - rho2 + h * h, 0.0)), 0.0);
    let d_min = top - r;
    let d_max = rho + h;
    var x_mu = 0.0;
    if d_max > d_min {
        x_mu = clamp((d - d_min) / (d_max - d_min), 0.0, 1.0);
    }
    let n = sky.transmittance_size.xy;
    let uv = vec2<f32>(sky_coord(x_mu, n.x), sky_coord(rho / h, n.y));
    let t = clamp(uv * n - 0.5, vec2<f32>(0.0), n - 1.0);
    let i0 = vec2<i32>(floor(t));
    let i1 = min(i0 + 1, vec2<i32>(n) - 1);
    let f = t - vec2<f32>(i0);
    let a = textureLoad(sky_transmittance_table, vec2<i32>(i0.x, i0.y), 0).rgb;
    let b = textureLoad(sky_transmittance_table, vec2<i32>(i1.x, i0.y), 0).rgb;
    let c = textureLoad(sky_transmittance_table, vec2<i32>(i0.x, i1.y), 0).rgb;
    let e = textureLoad(sky_transmittance_table, vec2<i32>(i1.x, i1.y), 0).rgb;
    return mix(mix(a, b, f.x), mix(c, e, f.x), f.y);
}

// Transmittance (working space) from `altitude_km` to space along zenith cosine `mu`; 0 where
// the ray meets the ground.
fn sky_transmittance_working(altitude_km: f32, mu: f32) -> vec3<f32> {
    let bottom = sky.shell.x;
    let r = bottom + clamp(altitude_km, 1e-4, sky.shell.y - bottom);
    let rho2 = (r - bottom) * (r + bottom);
    if mu < 0.0 && r * r * mu * mu - rho2 >= 0.0 {
        return vec3<f32>(0.0);
    }
    return sky_trans_top(r, rho2, mu);
}

// Transmittance over the first part of a ray from (r, rho2, mu) that ends at (r_d, rho2_d,
// mu_d), as a ratio of two table reads taken in the direction that stays above the ground
// (`Ctx::trans_between`).
fn sky_trans_between(r: f32, rho2: f32, mu: f32, hits_ground: bool, r_d: f32, rho2_d: f32, mu_d: f32) -> vec3<f32> {
    var a: vec3<f32>;
    var b: vec3<f32>;
    if hits_ground {
        a = sky_trans_top(r_d, rho2_d, -mu_d);
        b = sky_trans_top(r, rho2, -mu);
    } else {
        a = sky_trans_top(r, rho2, mu);
        b = sky_trans_top(r_d, rho2_d, mu_d);
    }
    return select(vec3<f32>(0.0), min(a / max(b, vec3<f32>(1e-30)), vec3<f32>(1.0)), b > vec3<f32>(0.0));
}

// How far a ray from (r, rho2, mu) runs inside the Earth's shadow (the half cylinder of the
// ground's radius behind the planet) before leaving it, km, for a light of zenith cosine mu_s
// at cosine nu from the ray; 0 when the start is lit (`Shell::shadow_length`). The root is
// taken in the form without cancellation.
fn sky_shadow_length(r: f32, rho2: f32, mu: f32, mu_s: f32, nu: f32) -> f32 {
    // The start's squared distance to the light's axis minus bottom^2, without cancellation.
    let rs = r * mu_s;
    let c = rho2 - rs * rs;
    if mu_s >= 0.0 || c >= 0.0 {
        return 0.0;
    }
    let a = max(1.0 - nu * nu, 0.0);
    let b = r * (mu - mu_s * nu);
    let q = sqrt(max(b * b - a * c, 0.0));
    if b > 0.0 {
        return max(-c / (b + q), 0.0);
    }
    if a <= 1e-12 {
        return 3.0e38;
    }
    return max((q - b) / a, 0.0);
}

struct SkySingle {
    rayleigh: vec3<f32>,
    mie: vec3<f32>,
}

// Single Rayleigh and Mie scattering divided by their phases (working space, per unit
// illuminance) from (r, rho2) along mu, for a light of zenith cosine mu_s at cosine nu from
// the ray, with the run-time Earth-shadow and azimuth terms (`Ctx::single_parts`): a ray that
// starts in the shadow is read from where it leaves it, times the transmittance to there; the
// table is read at the light angle that matches the true ray's at the texel's scattering
// distance.
fn sky_single(r0: f32, rho2_0: f32, mu0: f32, mu_s0: f32, nu: f32) -> SkySingle {
    let bottom = sky.shell.x;
    let h = sky.shell.z;
    var r = r0;
    var rho2 = rho2_0;
    var mu = mu0;
    var mu_s = mu_s0;
    var tl = vec3<f32>(1.0);
    var k = SKY_DISTANCE_SCALE;
    let shadow = sky_shadow_length(r0, rho2_0, mu0, mu_s0, nu);
    if shadow > 0.0 {
        let rmu = r0 * mu0;
        let disc = rmu * rmu - rho2_0;
        let hits = mu0 < 0.0 && disc >= 0.0;
        var boundary = max(-rmu + sqrt(max(disc + h * h, 0.0)), 0.0);
        if hits {
            boundary = max(-rmu - sqrt(max(disc, 0.0)), 0.0);
        }
        if shadow >= boundary {
            return SkySingle(vec3<f32>(0.0), vec3<f32>(0.0));
        }
        // The exit point: r_l^2 - bottom^2 = rho^2 + l (l + 2 r mu).
        rho2 = clamp(rho2_0 + shadow * (shadow + 2.0 * rmu), 0.0, h * h);
        r = sqrt(rho2 + bottom * bottom);
        mu = clamp((rmu + shadow) / r, -1.0, 1.0);
        mu_s = clamp((r0 * mu_s0 + shadow * nu) / r, -1.0, 1.0);
        tl = sky_trans_between(r0, rho2_0, mu0, hits, r, rho2, mu);
        k = SKY_DISTANCE_SCALE_SHADOWED;
    }
    let uv = sky_scattering_uv(r, rho2, mu);
    let big_a = sky_mu_s_a(SKY_MU_S_MIN);
    // Rayleigh (x) and Mie (y) scattering distances, scaled.
    let de = sky_scattering_distances(vec3<f32>(uv.x, sky_u_mu_s(mu_s, big_a), uv.y)) * k;
    let shifted = clamp((r * mu_s + de * nu) / max(r + de * mu, vec2<f32>(1.0)), vec2<f32>(-1.0), vec2<f32>(1.0));
    let ray = sky_trilinear(false, vec3<f32>(uv.x, sky_u_mu_s(shifted.x, big_a), uv.y)).rgb;
    let mie = sky_trilinear(true, vec3<f32>(uv.x, sky_u_mu_s(shifted.y, big_a), uv.y)).rgb;
    return SkySingle(ray * tl, mie * tl);
}

// One light's inscattering (working space, nits): the resampled multiple scattering in `layer`
// and the single scattering with the azimuth terms, times the phases at the true angle.
fn sky_light_inscatter(layer: i32, uv: vec2<f32>, r: f32, rho2: f32, mu: f32, light: vec4<f32>, dir: vec3<f32>) -> vec3<f32> {
    let nu = clamp(dot(dir, light.xyz), -1.0, 1.0);
    let single = sky_single(r, rho2, mu, light.y, nu);
    let ray = sky_bilinear(layer, uv) + single.rayleigh;
    return (ray * sky_rayleigh_phase(nu) + single.mie * sky_mie_phase(nu, sky.table.w)) * sky.white.xyz * light.w;
}

// Inscattered radiance towards the camera from direction `dir` (unit, world), Rec.709 nits:
// the sun's and the moon's light scattered by the air, without the disks or the ground.
fn sky_inscatter(dir: vec3<f32>) -> vec3<f32> {
    let r = sky_radius();
    let rho2 = sky_radius_rho2();
    let mu = clamp(dir.y, -1.0, 1.0);
    let uv = sky_scattering_uv(r, rho2, mu);
    var working = vec3<f32>(0.0);
    if sky.sun.w > 0.0 {
        working += sky_light_inscatter(0, uv, r, rho2, mu, sky.sun, dir);
    }
    if sky.moon.w > 0.0 {
        working += sky_light_inscatter(1, uv, r, rho2, mu, sky.moon, dir);
    }
    return max(sky_rec709_from_working(working), vec3<f32>(0.0)) * sky.light_coords.z;
}

// White light of unit luminance-free value 1 after the path from `altitude_km` to space along
// `mu`, linear Rec.709.
fn sky_transmittance(altitude_km: f32, mu: f32) -> vec3<f32> {
    return max(sky_rec709_from_working(sky_transmittance_working(altitude_km, mu) * sky.white.xyz), vec3<f32>(0.0));
}

// The sun's limb-darkened disk and the moon's disk lit by phase, Rec.709 nits, seen through the
// atmosphere; zero away from them.
fn sky_disks(dir: vec3<f32>) -> vec3<f32> {
    if sky.disks.w == 0.0 {
        return vec3<f32>(0.0);
    }
    var out = vec3<f32>(0.0);
    let alt = sky.shell.w;
    let sun_r = sky.disks.x;
    let cs = dot(dir, sky.sun.xyz);
    if sky.sun.w > 0.0 && cs > cos(sun_r) {
        let s = sqrt(max(1.0 - cs * cs, 0.0)) / sin(sun_r);
        let mu = sqrt(max(1.0 - s * s, 0.0));
        let mean = sky.sun.w / (SKY_PI * sun_r * sun_r);
        let limb = (1.0 - SKY_LIMB_U * (1.0 - mu)) / (1.0 - SKY_LIMB_U / 3.0);
        out += mean * limb * sky_transmittance(alt, dir.y);
    }
    let moon_r = sky.disks.y;
    let cm = dot(dir, sky.moon.xyz);
    if sky.moon.w > 0.0 && cm > cos(moon_r) && sky.disks.z > 0.0 {
        // The point of the moon's sphere seen in `dir`: its normal faces the observer.
        let q = (dir - sky.moon.xyz * cm) / sin(moon_r);
        let n = q - sky.moon.xyz * sqrt(max(1.0 - dot(q, q), 0.0));
        if dot(n, sky.sun.xyz) > 0.0 {
            // Uniform over the lit part, which then gives the moon's illuminance.
            let mean = sky.moon.w / (SKY_PI * moon_r * moon_r * sky.disks.z);
            out += mean * sky_transmittance(alt, dir.y);
        }
    }
    return out * sky.light_coords.z;
}

// The ground below the horizon, seen through the air between it and the camera (the path up
// from the ground towards the camera, as a ratio of two transmittances to space).
fn sky_ground(dir: vec3<f32>) -> vec3<f32> {
    let up = clamp(-dir.y, 1e-4, 1.0);
    let below = sky_transmittance_working(0.0, up);
    let above = sky_transmittance_working(sky.shell.w, up);
    let t = select(vec3<f32>(1.0), min(below / max(above, vec3<f32>(1e-30)), vec3<f32>(1.0)), above > vec3<f32>(0.0));
    return max(sky_rec709_from_working(sky.ground.xyz * t), vec3<f32>(0.0));
}

// Everything seen along `dir` where no geometry is: inscattering, the disks, and below the
// horizon the ground.
fn sky_background(dir: vec3<f32>) -> vec3<f32> {
    var l = sky_inscatter(dir) + sky_disks(dir);
    if dir.y < 0.0 {
        l += sky_ground(dir);
    }
    return l;
}

// The same without the disks: what the sky's SH holds.
fn sky_background_no_disks(dir: vec3<f32>) -> vec3<f32> {
    var l = sky_inscatter(dir);
    if dir.y < 0.0 {
        l += sky_ground(dir);
    }
    return l;
}
