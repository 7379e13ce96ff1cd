// reflection_probes.capture: one cube face of one probe, from the G-buffer the rasteriser drew
// with a 90-degree camera at the capture point along the face's axis. Each texel takes the
// G-buffer pixel its direction projects to (whatever the camera's roll, a texel centre lands
// on a pixel centre) and keeps what relighting needs: the albedo light is reflected with and
// the interior mask, the normal and the distance from the capture point (0: sky), and the
// emission. Checked against the room geometry it captures (tests/reflection_probes.rs: the
// mirror floor in an emissive room), the G-buffer itself against its own twin.

#import hikari::view::{View, world_from_depth}
#import hikari::reflection_probe_math::rp_texel_direction

struct CaptureParams {
    // x: face; y: layer of the capture arrays (probe * 6 + face); z: texels a side.
    face: vec4<u32>,
    // xyz: capture point.
    capture: vec4<f32>,
}

@group(0) @binding(0) var<uniform> view: View;
@group(0) @binding(1) var<uniform> params: CaptureParams;
@group(0) @binding(2) var depth: texture_2d<f32>;
@group(0) @binding(3) var gbuffer_normal: texture_2d<f32>;
@group(0) @binding(4) var gbuffer_albedo: texture_2d<f32>;
@group(0) @binding(5) var gbuffer_material: texture_2d<f32>;
@group(0) @binding(6) var gbuffer_emissive: texture_2d<f32>;
@group(0) @binding(7) var out_albedo: texture_storage_2d_array<rgba8unorm, write>;
@group(0) @binding(8) var out_normal_depth: texture_storage_2d_array<rgba16float, write>;
@group(0) @binding(9) var out_emission: texture_storage_2d_array<rgba16float, write>;

// Largest finite f16 is 65504.
const MAX_HALF: f32 = 65000.0;

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let n = params.face.z;
    if any(gid.xy >= vec2<u32>(n)) {
        return;
    }
    let dir = rp_texel_direction(params.face.x, gid.xy, n);
    let c = view.view_proj * vec4<f32>(params.capture.xyz + dir, 1.0);
    let ndc = c.xy / c.w;
    let px_f = vec2<f32>(ndc.x * 0.5 + 0.5, 0.5 - ndc.y * 0.5) * view.viewport.xy;
    let px = vec2<u32>(clamp(px_f, vec2<f32>(0.0), view.viewport.xy - 1.0));
    let layer = params.face.y;
    let d = textureLoad(depth, px, 0).r;
    if d <= 0.0 {
        textureStore(out_albedo, gid.xy, layer, vec4<f32>(0.0));
        textureStore(out_normal_depth, gid.xy, layer, vec4<f32>(0.0));
        textureStore(out_emission, gid.xy, layer, vec4<f32>(0.0));
        return;
    }
    let world = world_from_depth(view, px, d);
    let distance = min(length(world - params.capture.xyz), MAX_HALF);
    let albedo = textureLoad(gbuffer_albedo, px, 0);
    let material = textureLoad(gbuffer_material, px, 0);
    // Metals reflect their F0 (the base colour): Metro's hit albedo, base (1 - F0) + F0.
    let m = clamp(material.y, 0.0, 1.0);
    let reflect_albedo = mix(albedo.rgb, albedo.rgb * (1.0 - albedo.rgb) + albedo.rgb, m) * material.w;
    textureStore(out_albedo, gid.xy, layer, vec4<f32>(clamp(reflect_albedo, vec3<f32>(0.0), vec3<f32>(1.0)), albedo.a));
    textureStore(out_normal_depth, gid.xy, layer, vec4<f32>(textureLoad(gbuffer_normal, px, 0).xy, max(distance, 1e-3), 0.0));
    textureStore(out_emission, gid.xy, layer, vec4<f32>(min(textureLoad(gbuffer_emissive, px, 0).rgb, vec3<f32>(MAX_HALF)), 0.0));
}
