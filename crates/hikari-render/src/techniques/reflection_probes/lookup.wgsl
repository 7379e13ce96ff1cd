#define_import_path hikari::reflection_probes

// The relit reflection probes for the deferred lighting: the prefiltered radiance a surface
// reflects, from the probes whose boxes hold it (smallest box first, each fading out over its
// blend distance into the next: the talk's nesting), each read along the reflection vector
// parallax-corrected against its box, at the roughness the talk's roughness parallax
// compensation gives, times the talk's luminance normalisation and horizon occlusion.
// Binding set `reflection_probes` (`ReflectionProbesFrame::lookup`).
// Twin: `reflection_probes::reference::lookup`.

#import hikari::reflection_probe_math::{ReflectionProbeGpu, rp_box_exit, rp_box_weight, rp_horizon_occlusion, rp_compensated_alpha}

struct ReflectionProbeParams {
    // x: probes; y: roughness levels; z: RP_* flags.
    config: vec4<u32>,
    // x: the normalisation's largest ratio.
    values: vec4<f32>,
}

const RP_ON: u32 = 1u;
const RP_HORIZON: u32 = 2u;
const RP_PARALLAX_ROUGHNESS: u32 = 4u;
const RP_NORMALIZE: u32 = 8u;
const RP_LUMA: vec3<f32> = vec3<f32>(0.2126, 0.7152, 0.0722);

@group(#{REFLECTION_PROBES_GROUP}) @binding(0) var<uniform> rp_params: ReflectionProbeParams;
// Sorted by the boxes' volume, smallest first.
@group(#{REFLECTION_PROBES_GROUP}) @binding(1) var<storage, read> rp_probes: array<ReflectionProbeGpu>;
@group(#{REFLECTION_PROBES_GROUP}) @binding(2) var rp_radiance: texture_cube_array<f32>;
@group(#{REFLECTION_PROBES_GROUP}) @binding(3) var rp_sampler: sampler;
// Per probe: luminance of the irradiance at its capture point, mean and x, y, z slopes (lux).
@group(#{REFLECTION_PROBES_GROUP}) @binding(4) var<storage, read> rp_capture_light: array<vec4<f32>>;

// Reflected radiance (rgb, nits, before Fresnel) at world point x of mapped normal nm and
// vertex normal nv, seen from direction v (unit, towards the eye), GGX perceptual roughness
// `roughness`; `e_luma`: the luminance of the irradiance the surface receives (lux), which the
// normalisation compares with the probe's. w: the probes' coverage (0 to 1); the caller's own
// specular fills the rest.
fn reflection_probe_radiance(x: vec3<f32>, nm: vec3<f32>, nv: vec3<f32>, v: vec3<f32>, roughness: f32, e_luma: f32) -> vec4<f32> {
    let flags = rp_params.config.z;
    if (flags & RP_ON) == 0u {
        return vec4<f32>(0.0);
    }
    let r = reflect(-v, nm);
    let alpha = roughness * roughness;
    let levels = f32(max(rp_params.config.y, 1u) - 1u);
    var sum = vec3<f32>(0.0);
    var covered = 0.0;
    for (var i = 0u; i < rp_params.config.x; i++) {
        let p = rp_probes[i];
        let w = rp_box_weight(p, x);
        if w <= 0.0 {
            continue;
        }
        let t = rp_box_exit(p, x, r);
        let hit = x + r * t;
        let dir = hit - p.capture.xyz;
        var a = alpha;
        if (flags & RP_PARALLAX_ROUGHNESS) != 0u {
            a = rp_compensated_alpha(alpha, t, length(dir));
        }
        let lod = sqrt(a) * levels;
        var c = textureSampleLevel(rp_radiance, rp_sampler, dir, i, lod).rgb;
        if (flags & RP_NORMALIZE) != 0u {
            let l = rp_capture_light[i];
            let at_capture = l.x + dot(l.yzw, nm);
            c *= clamp(e_luma / max(at_capture, 1e-6), 0.0, rp_params.values.x);
        }
        let take = (1.0 - covered) * w;
        sum += c * take;
        covered += take;
        if covered >= 0.999 {
            break;
        }
    }
    if (flags & RP_HORIZON) != 0u {
        sum *= 1.0 - rp_horizon_occlusion(nm, nv, r, alpha);
    }
    return vec4<f32>(sum, covered);
}
