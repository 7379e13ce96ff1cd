// Deferred sun light on the G-buffer (Lambert for now; the scenes issue brings GGX), plus the
// clearly named placeholders for sky and ambient light that the atmosphere and probe issues
// replace. Output: radiance in nits.

#import hikari::view::{View, view_ray}
#import hikari::octahedral::oct_decode

struct SunParams {
    // xyz: unit vector towards the sun; w: illuminance in lux.
    direction_lux: vec4<f32>,
    // rgb: sun colour with luminance 1.
    color: vec4<f32>,
    // rgb: placeholder sky radiance at the zenith, in nits; w unused.
    sky_zenith: vec4<f32>,
    // rgb: placeholder sky radiance at the horizon, in nits; w unused.
    sky_horizon: vec4<f32>,
}

@group(0) @binding(0) var<uniform> view: View;
@group(0) @binding(1) var depth: texture_depth_2d;
@group(0) @binding(2) var gbuffer_normal: texture_2d<f32>;
@group(0) @binding(3) var gbuffer_albedo: texture_2d<f32>;
@group(0) @binding(4) var out_radiance: texture_storage_2d<rgba16float, write>;
@group(0) @binding(5) var<uniform> params: SunParams;

const PI: f32 = 3.14159265358979;
// Largest finite f16 is 65504; stay below it so no pixel turns into infinity.
const MAX_RADIANCE: f32 = 65000.0;

fn sky_placeholder(dir: vec3<f32>) -> vec3<f32> {
    let t = clamp(dir.y, 0.0, 1.0);
    return mix(params.sky_horizon.rgb, params.sky_zenith.rgb, sqrt(t));
}

// Irradiance from the placeholder sky on a surface with normal n: the sky is treated as a
// uniform upper hemisphere of the mean of zenith and horizon, the ground as black, which
// gives E = pi * L * (1 + n.y) / 2.
fn ambient_placeholder(n: vec3<f32>) -> vec3<f32> {
    let l = 0.5 * (params.sky_zenith.rgb + params.sky_horizon.rgb);
    return PI * l * 0.5 * (1.0 + n.y);
}

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(out_radiance);
    if any(id.xy >= size) {
        return;
    }
    let pixel = id.xy;
    let d = textureLoad(depth, pixel, 0);
    var radiance: vec3<f32>;
    if d <= 0.0 {
        radiance = sky_placeholder(view_ray(view, pixel));
    } else {
        let n = oct_decode(textureLoad(gbuffer_normal, pixel, 0).xy);
        let albedo = textureLoad(gbuffer_albedo, pixel, 0).rgb;
        let ndotl = max(dot(n, params.direction_lux.xyz), 0.0);
        let irradiance = params.color.rgb * params.direction_lux.w * ndotl + ambient_placeholder(n);
        radiance = albedo / PI * irradiance;
    }
    // NaN fails every comparison, so this also turns NaN into 0.
    radiance = select(vec3<f32>(0.0), min(radiance, vec3<f32>(MAX_RADIANCE)), radiance >= vec3<f32>(0.0));
    textureStore(out_radiance, pixel, vec4<f32>(radiance, 1.0));
}
