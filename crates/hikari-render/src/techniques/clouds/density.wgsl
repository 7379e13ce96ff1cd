#define_import_path hikari::cloud_density

// The cloud layer's density (after Schneider 2015: coverage-remapped fBm between a base and a
// top altitude), with octaves faded where a sample's footprint would alias them (the talk's
// cloud density anti-aliasing), and the paraboloid map's mapping. No bindings: the march writes
// the map and the lookups read it. CPU twin: `clouds::reference` (same names).

struct CloudParams {
    // Base and top altitude (m), Earth radius (m), the map's eye altitude (m).
    layer: vec4<f32>,
    // Coverage 0..1, extinction at full density (1/m), 1 / feature size (1/m), albedo.
    shape: vec4<f32>,
    // xz: where the noise's origin lies in world metres (the wind's offset); z: the most
    // metres a view ray marches in the layer; w: unused.
    offset: vec4<f32>,
    // xyz: unit vector towards the sun or moon; w: 1 when it lights the clouds.
    sun: vec4<f32>,
    // Forward g, backward g, backward scale (multiple scattering), 0.
    phase: vec4<f32>,
    // View steps, light steps, map size (texels a side), CLOUDS_* flags.
    march: vec4<u32>,
    // Time slices, this frame's slice, 0, 0.
    slice: vec4<u32>,
    // The shadow map: xy its corner on the layer's base (world x, z, metres), z metres a
    // texel, w texels a side (0: no map; cloud_shadow_at everywhere).
    shadow: vec4<f32>,
}

const CLOUDS_ON: u32 = 1u;
const CLOUDS_SHADOWS: u32 = 2u;
const CLOUDS_DENSITY_AA: u32 = 4u;
const CLOUDS_MULTIPLE: u32 = 8u;
const CLOUD_OCTAVES: u32 = 4u;
const CLOUD_PI: f32 = 3.14159265358979;

fn cloud_hash(c: vec3<i32>) -> f32 {
    let u = bitcast<vec3<u32>>(c);
    var h = (u.x * 0x8da6b343u) ^ (u.y * 0xd8163841u) ^ (u.z * 0xcb1ab31fu);
    h ^= h >> 16u;
    h *= 0x7feb352du;
    h ^= h >> 15u;
    h *= 0x846ca68bu;
    h ^= h >> 16u;
    return f32(h >> 8u) / 16777216.0;
}

// Trilinear value noise with quintic fades, in [0, 1).
fn cloud_value_noise(p: vec3<f32>) -> f32 {
    let fl = floor(p);
    let i = vec3<i32>(fl);
    let f = p - fl;
    let u = f * f * f * (f * (f * 6.0 - 15.0) + 10.0);
    let c000 = cloud_hash(i);
    let c100 = cloud_hash(i + vec3<i32>(1, 0, 0));
    let c010 = cloud_hash(i + vec3<i32>(0, 1, 0));
    let c110 = cloud_hash(i + vec3<i32>(1, 1, 0));
    let c001 = cloud_hash(i + vec3<i32>(0, 0, 1));
    let c101 = cloud_hash(i + vec3<i32>(1, 0, 1));
    let c011 = cloud_hash(i + vec3<i32>(0, 1, 1));
    let c111 = cloud_hash(i + vec3<i32>(1, 1, 1));
    let x00 = mix(c000, c100, u.x);
    let x10 = mix(c010, c110, u.x);
    let x01 = mix(c001, c101, u.x);
    let x11 = mix(c011, c111, u.x);
    return mix(mix(x00, x10, u.y), mix(x01, x11, u.y), u.z);
}

// Extinction (1/m) at world-space horizontal position `xz` (metres) and `height` above the
// ground, for a sample whose footprint is `footprint` metres wide (0: a point).
fn cloud_density(p: CloudParams, xz: vec2<f32>, height: f32, footprint: f32) -> f32 {
    let h = (height - p.layer.x) / (p.layer.y - p.layer.x);
    if h <= 0.0 || h >= 1.0 {
        return 0.0;
    }
    // Rounded base, softer top.
    let profile = clamp(h * 5.0, 0.0, 1.0) * clamp((1.0 - h) * 2.5, 0.0, 1.0);
    let q = vec3<f32>(xz.x - p.offset.x, height, xz.y - p.offset.y) * p.shape.z;
    var sum = 0.0;
    var norm = 0.0;
    var amp = 1.0;
    var freq = 1.0;
    let aa = (p.march.w & CLOUDS_DENSITY_AA) != 0u;
    for (var o = 0u; o < CLOUD_OCTAVES; o++) {
        // An octave whose period is less than two footprints would alias: fade it to its mean.
        var keep = 1.0;
        if aa {
            let period = 1.0 / (p.shape.z * freq);
            keep = clamp(period / (2.0 * max(footprint, 1e-3)) - 0.5, 0.0, 1.0);
        }
        let n = mix(0.5, cloud_value_noise(q * freq + f32(o) * 17.0), keep);
        sum += amp * n;
        norm += amp;
        amp *= 0.5;
        freq *= 2.0;
    }
    let n = sum / norm;
    // Coverage c: the noise's top c of its range becomes cloud.
    let c = p.shape.x;
    let cover = clamp((n - (1.0 - c)) * 4.0, 0.0, 1.0);
    return p.shape.y * cover * profile;
}

// Paraboloid map of the upper hemisphere (y up): texel coordinates (0..1) of unit `d`.
fn cloud_map_uv(d: vec3<f32>) -> vec2<f32> {
    return d.xz / (1.0 + max(d.y, 0.0)) * 0.5 + 0.5;
}

fn cloud_map_dir(uv: vec2<f32>) -> vec3<f32> {
    let q = uv * 2.0 - 1.0;
    let r2 = dot(q, q);
    return normalize(vec3<f32>(2.0 * q.x, 1.0 - r2, 2.0 * q.y) / (1.0 + r2));
}

// Distance along unit `d` from a point `r0` metres from the Earth's centre at zenith cosine
// `mu` to the sphere of radius `r`, outward root (the far side), or -1 when it misses.
fn cloud_sphere_exit(r0: f32, mu: f32, r: f32) -> f32 {
    let b = r0 * mu;
    let disc = b * b - r0 * r0 + r * r;
    if disc < 0.0 {
        return -1.0;
    }
    return -b + sqrt(disc);
}

// Sun transmittance through the layer from a ground point at world `pos` (flat layer, the
// sun's path capped at 20 layer thicknesses near the horizon); 4 samples.
fn cloud_shadow_at(p: CloudParams, pos: vec3<f32>) -> f32 {
    if (p.march.w & (CLOUDS_ON | CLOUDS_SHADOWS)) != (CLOUDS_ON | CLOUDS_SHADOWS) || p.sun.w == 0.0 {
        return 1.0;
    }
    let s = p.sun.xyz;
    let sy = max(s.y, 0.05);
    let t0 = max(p.layer.x - pos.y, 0.0) / sy;
    let t1 = max(p.layer.y - pos.y, 0.0) / sy;
    if t1 <= t0 {
        return 1.0;
    }
    let dt = (t1 - t0) / 4.0;
    var tau = 0.0;
    for (var i = 0u; i < 4u; i++) {
        let t = t0 + (f32(i) + 0.5) * dt;
        let x = pos + s * t;
        tau += cloud_density(p, x.xz, pos.y + sy * t, dt) * dt;
    }
    return exp(-tau);
}
