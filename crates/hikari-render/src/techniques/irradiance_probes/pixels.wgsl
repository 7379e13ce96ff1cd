// The probes' irradiance at every pixel's surface, as the deferred lighting looks it up (lux,
// times the weather's diffuse balance; alpha 1 where probes cover the surface, else 0): the
// dump `irradiance_probes.pixels`, made only when `--dump` asks for it.

#import hikari::view::{View, world_from_depth}
#import hikari::octahedral::oct_decode
#import hikari::irradiance_probes::probe_irradiance_at

@group(0) @binding(0) var<uniform> view: View;
@group(0) @binding(1) var depth: texture_2d<f32>;
@group(0) @binding(2) var gbuffer_normal: texture_2d<f32>;
@group(0) @binding(3) var gbuffer_albedo: texture_2d<f32>;
@group(0) @binding(4) var out_irradiance: texture_storage_2d<rgba16float, write>;

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let pixel = gid.xy;
    if any(pixel >= textureDimensions(out_irradiance)) {
        return;
    }
    let d = textureLoad(depth, pixel, 0).r;
    var e = vec4<f32>(0.0);
    if d > 0.0 {
        let world = world_from_depth(view, pixel, d);
        let n = oct_decode(textureLoad(gbuffer_normal, pixel, 0).xy);
        e = probe_irradiance_at(world, n, textureLoad(gbuffer_albedo, pixel, 0).a);
    }
    // Half floats end at 65504 lux.
    textureStore(out_irradiance, pixel, vec4<f32>(min(e.rgb, vec3<f32>(65504.0)), e.w));
}
