#define_import_path hikari::sky

// The sky for other techniques: inscattered radiance towards any direction from the camera's
// altitude, the sun's and moon's disks, the ground below the horizon, and transmittance. Reads
// the per-frame 2D tables (`sky.resampled`, the 3D tables resampled at this frame's sun and
// moon angles by `resample.wgsl`) and the persistent transmittance table. Binding set `sky`
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
// Layers: sun Rayleigh, sun Mie, moon Rayleigh, moon Mie; [mu, r].
@group(#{SKY_GROUP}) @binding(1) var sky_resampled: texture_2d_array<f32>;
@group(#{SKY_GROUP}) @binding(2) var sky_transmittance_table: texture_2d<f32>;

const SKY_PI: f32 = 3.14159265358979;
// Linear limb darkening I(mu) = 1 - u (1 - mu) of the sun's disk in the visible (Pierce &
// Slaughter 1977 give u ~ 0.6 around 550 nm); the mean over the disk is 1 - u / 3.
const SKY_LIMB_U: f32 = 0.6;

fn sky_coord(x: f32, n: f32) -> f32 {
    return 0.5 / n + x * (1.0 - 1.0 / n);
}

fn sky_rec709_from_working(v: vec3<f32>) -> vec3<f32> {
    return vec3<f32>(dot(sky.rec709_from_working[0].xyz, v), dot(sky.rec709_from_working[1].xyz, v), dot(sky.rec709_from_working[2].xyz, v));
}

fn sky_radius() -> f32 {
    return sky.shell.x + clamp(sky.shell.w, 0.0, sky.shell.y - sky.shell.x - 1e-3);
}

// Scattering table coordinates (u_mu, u_r) of a ray from radius r with zenith cosine mu.
fn sky_scattering_uv(r: f32, mu: f32) -> vec2<f32> {
    let bottom = sky.shell.x;
    let top = sky.shell.y;
    let h = sky.shell.z;
    // (r - bottom)(r + bottom) rather than r^2 - bottom^2: the difference of two squares of
    // 6360 km would lose most of f32's digits near the ground.
    let alt = r - bottom;
    let rho2 = alt * (r + bottom);
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

// Inscattered radiance towards the camera from direction `dir` (unit, world), Rec.709 nits:
// the sun's and the moon's light scattered by the air, without the disks or the ground.
fn sky_inscatter(dir: vec3<f32>) -> vec3<f32> {
    let uv = sky_scattering_uv(sky_radius(), clamp(dir.y, -1.0, 1.0));
    var working = vec3<f32>(0.0);
    if sky.sun.w > 0.0 {
        let nu = dot(dir, sky.sun.xyz);
        let s = sky_bilinear(0, uv) * sky_rayleigh_phase(nu) + sky_bilinear(1, uv) * sky_mie_phase(nu, sky.table.w);
        working += s * sky.white.xyz * sky.sun.w;
    }
    if sky.moon.w > 0.0 {
        let nu = dot(dir, sky.moon.xyz);
        let s = sky_bilinear(2, uv) * sky_rayleigh_phase(nu) + sky_bilinear(3, uv) * sky_mie_phase(nu, sky.table.w);
        working += s * sky.white.xyz * sky.moon.w;
    }
    return max(sky_rec709_from_working(working), vec3<f32>(0.0)) * sky.light_coords.z;
}

// Transmittance (working space) from `altitude_km` to space along zenith cosine `mu`; 0 where
// the ray meets the ground.
fn sky_transmittance_working(altitude_km: f32, mu: f32) -> vec3<f32> {
    let bottom = sky.shell.x;
    let top = sky.shell.y;
    let h = sky.shell.z;
    let r = bottom + clamp(altitude_km, 1e-4, top - bottom);
    let rho2 = (r - bottom) * (r + bottom);
    if mu < 0.0 && r * r * mu * mu - rho2 >= 0.0 {
        return vec3<f32>(0.0);
    }
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
