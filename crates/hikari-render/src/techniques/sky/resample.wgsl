// Resamples the multiple scattering of the persistent 3D tables [mu, mu_s, r] (Rayleigh of all
// orders minus Rayleigh single, both divided by the Rayleigh phase) at this frame's sun and
// moon zenith angles into 2D tables [mu, r], with cubic (Catmull-Rom) filtering along mu_s so that a
// light moving through the densely spaced texels near the horizon does not show the kinks of
// linear interpolation. Negative lobes of the cubic are clamped to 0. The single scattering is
// not resampled: the lookup reads it per pixel at light angles shifted by the azimuth and
// Earth-shadow terms (`lookup.wgsl`). CPU twin: reference::resample.

struct ResampleParams {
    // Scattering table texels along mu, mu_s, r; w: unused.
    table: vec4<f32>,
    // x, y: the sun's and moon's texel coordinates along mu_s.
    light_coords: vec4<f32>,
}

@group(0) @binding(0) var<uniform> params: ResampleParams;
@group(0) @binding(1) var rayleigh: texture_3d<f32>;
// rgb: Rayleigh single scattering / phase (a: its scattering distance, unused here).
@group(0) @binding(2) var rayleigh_single: texture_3d<f32>;
// Layers: sun, moon.
@group(0) @binding(3) var out_table: texture_storage_2d_array<rgba32float, write>;

// Catmull-Rom weights of the four texels around fraction f.
fn catmull_rom(f: f32) -> vec4<f32> {
    let f2 = f * f;
    let f3 = f2 * f;
    return vec4<f32>(
        -0.5 * f3 + f2 - 0.5 * f,
        1.5 * f3 - 2.5 * f2 + 1.0,
        -1.5 * f3 + 2.0 * f2 + 0.5 * f,
        0.5 * f3 - 0.5 * f2,
    );
}

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let size = textureDimensions(out_table);
    if gid.x >= size.x || gid.y >= size.y || gid.z >= 2u {
        return;
    }
    let n_mus = i32(params.table.y);
    // Texel coordinate along mu_s: t = u n - 0.5, clamped to the table as the CPU sampling is.
    let t = clamp(select(params.light_coords.x, params.light_coords.y, gid.z == 1u), 0.0, f32(n_mus - 1));
    let i = i32(floor(t));
    let w = catmull_rom(t - f32(i));
    var sum = vec3<f32>(0.0);
    for (var k = 0; k < 4; k++) {
        let j = clamp(i - 1 + k, 0, n_mus - 1);
        let c = vec3<i32>(i32(gid.x), j, i32(gid.y));
        sum += w[k] * (textureLoad(rayleigh, c, 0).rgb - textureLoad(rayleigh_single, c, 0).rgb);
    }
    textureStore(out_table, gid.xy, gid.z, vec4<f32>(max(sum, vec3<f32>(0.0)), 0.0));
}
