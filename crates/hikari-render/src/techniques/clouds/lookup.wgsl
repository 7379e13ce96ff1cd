#define_import_path hikari::clouds

// The clouds for other passes: over the sky (the paraboloid map, bilinear) and their shadow
// on the sun's light. Binding set `clouds` (`CloudsFrame::lookup`). Twin: `clouds::reference`.

#import hikari::cloud_density::{CloudParams, CLOUDS_ON, cloud_map_uv, cloud_shadow_at}

@group(#{CLOUDS_GROUP}) @binding(0) var<uniform> clouds: CloudParams;
@group(#{CLOUDS_GROUP}) @binding(1) var cloud_map: texture_2d<f32>;
@group(#{CLOUDS_GROUP}) @binding(2) var cloud_sampler: sampler;
// The sun's transmittance on a square of the layer's base (clouds.shadow_map; R32Float).
@group(#{CLOUDS_GROUP}) @binding(3) var cloud_shadow_map: texture_2d<f32>;

// `background` (the sky's radiance towards unit `dir`) behind the clouds, lit by `sun_lux`
// (RGB illuminance) and `sky_radiance` (the sky's mean radiance), nits.
fn clouds_over_sky(dir: vec3<f32>, background: vec3<f32>, sun_lux: vec3<f32>, sky_radiance: vec3<f32>) -> vec3<f32> {
    if (clouds.march.w & CLOUDS_ON) == 0u || dir.y <= 0.0 {
        return background;
    }
    let c = textureSampleLevel(cloud_map, cloud_sampler, cloud_map_uv(dir), 0.0);
    // The map's last texels before the horizon hold rays that graze the layer for tens of km;
    // fade the clouds out over the last degrees.
    let fade = clamp(dir.y / 0.035, 0.0, 1.0);
    let t = mix(1.0, clamp(c.b, 0.0, 1.0), fade);
    let l = background * t + (c.r * sun_lux + c.g * sky_radiance) * fade;
    return select(background, l, all(l >= vec3<f32>(0.0)) && all(l < vec3<f32>(3.0e38)));
}

// Sun (or moon) transmittance through the clouds above world position `pos`: from the shadow
// map where the path to the sun enters the layer inside it (bilinear between texel centres),
// else marched here. Twin: `clouds::reference::cloud_shadow`.
fn cloud_shadow(pos: vec3<f32>) -> f32 {
    // `CloudParams::with_shadow_map` places a map (w > 0) only with shadows on and a lit sun.
    let n = clouds.shadow.w;
    if n > 0.0 {
        let s = clouds.sun.xyz;
        let t0 = (clouds.layer.x - pos.y) / max(s.y, 0.05);
        // Texel coordinates of the entry point, texel centres at whole numbers.
        let c = (pos.xz + s.xz * t0 - clouds.shadow.xy) / clouds.shadow.z - 0.5;
        // Written so that NaN fails too.
        if t0 >= 0.0 && all(c >= vec2<f32>(0.0)) && all(c < vec2<f32>(n - 1.0)) {
            let i = vec2<u32>(c);
            let f = c - vec2<f32>(i);
            let a = textureLoad(cloud_shadow_map, i, 0).x;
            let b = textureLoad(cloud_shadow_map, i + vec2<u32>(1u, 0u), 0).x;
            let d = textureLoad(cloud_shadow_map, i + vec2<u32>(0u, 1u), 0).x;
            let e = textureLoad(cloud_shadow_map, i + vec2<u32>(1u, 1u), 0).x;
            return mix(mix(a, b, f.x), mix(d, e, f.x), f.y);
        }
    }
    return cloud_shadow_at(clouds, pos);
}
