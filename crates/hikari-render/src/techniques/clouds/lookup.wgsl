#define_import_path hikari::clouds

// The clouds for other passes: over the sky (the paraboloid map, bilinear) and their shadow
// on the sun's light. Binding set `clouds` (`CloudsFrame::lookup`). Twin: `clouds::reference`.

#import hikari::cloud_density::{CloudParams, CLOUDS_ON, cloud_map_uv, cloud_shadow_at}

@group(#{CLOUDS_GROUP}) @binding(0) var<uniform> clouds: CloudParams;
@group(#{CLOUDS_GROUP}) @binding(1) var cloud_map: texture_2d<f32>;
@group(#{CLOUDS_GROUP}) @binding(2) var cloud_sampler: sampler;

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

// Sun (or moon) transmittance through the clouds above world position `pos`.
fn cloud_shadow(pos: vec3<f32>) -> f32 {
    return cloud_shadow_at(clouds, pos);
}
