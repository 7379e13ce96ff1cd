// reflection_probes.prefilter: one roughness level of this frame's probes, the relit cube maps
// convolved with the GGX lobe (normal = view = reflection) by filtered importance sampling
// (Krivanek and Colbert 2008): each sample reads the relit mip chain at the level whose texels
// cover the solid angle the sample stands for. Level 0 is the relit map itself (a mirror).
// Twin: `reflection_probes::reference::prefilter_integral`, the integral it estimates (the
// mip chain of `downsample.wgsl` is checked through it).

#import hikari::reflection_probe_math::{rp_texel_direction, rp_hammersley}

struct PrefilterParams {
    // x: output level; y: levels; z: samples; w: texels a side of relit level 0.
    level: vec4<u32>,
    // x: 1 to write the relit probes in list order, 0 at their own layers; y: probes in all;
    // z: probes relit (listed in `relit_list`).
    probes: vec4<u32>,
}

@group(0) @binding(0) var<uniform> params: PrefilterParams;
@group(0) @binding(1) var relit: texture_cube_array<f32>;
@group(0) @binding(2) var relit_sampler: sampler;
@group(0) @binding(3) var out_level: texture_storage_2d_array<rgba16float, write>;
@group(0) @binding(4) var<storage, read> relit_list: array<u32>;

const PI: f32 = 3.14159265358979;

fn basis(n: vec3<f32>) -> mat3x3<f32> {
    // Duff et al. 2017.
    let s = select(-1.0, 1.0, n.z >= 0.0);
    let a = -1.0 / (s + n.z);
    let b = n.x * n.y * a;
    return mat3x3<f32>(vec3<f32>(1.0 + s * n.x * n.x * a, s * b, -s * n.x), vec3<f32>(b, s + n.y * n.y * a, -n.y), n);
}

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let size = textureDimensions(out_level).x;
    let count = params.probes.y;
    if any(gid.xy >= vec2<u32>(size)) || gid.z >= params.probes.z * 6u || count == 0u {
        return;
    }
    let face = gid.z % 6u;
    let cube = gid.z / 6u;
    let probe = min(relit_list[cube], count - 1u);
    let n = rp_texel_direction(face, gid.xy, size);
    let level = params.level.x;
    var value: vec3<f32>;
    if level == 0u || params.level.y <= 1u {
        value = textureSampleLevel(relit, relit_sampler, n, cube, 0.0).rgb;
    } else {
        let r = f32(level) / f32(params.level.y - 1u);
        let alpha = max(r * r, 1e-3);
        let a2 = alpha * alpha;
        let frame = basis(n);
        let samples = max(params.level.z, 1u);
        let n0 = f32(params.level.w);
        let texel_solid_angle = 4.0 * PI / (6.0 * n0 * n0);
        let max_lod = f32(textureNumLevels(relit) - 1);
        var sum = vec3<f32>(0.0);
        var weight = 0.0;
        for (var i = 0u; i < samples; i++) {
            let u = rp_hammersley(i, samples);
            let cos_h = sqrt((1.0 - u.x) / (1.0 + (a2 - 1.0) * u.x));
            let sin_h = sqrt(max(1.0 - cos_h * cos_h, 0.0));
            let phi = 2.0 * PI * u.y;
            let h = frame * vec3<f32>(sin_h * cos(phi), sin_h * sin(phi), cos_h);
            let l = 2.0 * cos_h * h - n;
            let n_dot_l = dot(n, l);
            if n_dot_l <= 0.0 {
                continue;
            }
            // pdf(l) = D(h) (n.h) / (4 v.h) = D(h) / 4 with v = n.
            let dd = cos_h * cos_h * (a2 - 1.0) + 1.0;
            let pdf = a2 / (PI * dd * dd) * 0.25;
            let sample_solid_angle = 1.0 / (f32(samples) * pdf);
            let lod = clamp(0.5 * log2(sample_solid_angle / texel_solid_angle) + 1.0, 0.0, max_lod);
            sum += textureSampleLevel(relit, relit_sampler, l, cube, lod).rgb * n_dot_l;
            weight += n_dot_l;
        }
        value = sum / max(weight, 1e-6);
    }
    // x = 1: the output holds this frame's probes only, in list order (to be compressed).
    let layer = select(probe, cube, params.probes.x == 1u) * 6u + face;
    textureStore(out_level, gid.xy, layer, vec4<f32>(value, 1.0));
}
