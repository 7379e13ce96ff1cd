// Projects the sky's radiance (inscattering and the ground, without the disks: the directional
// light carries the sun and moon) to L2 SH with 4096 directions of a spherical Fibonacci set,
// then derings it as Ghost of Tsushima does (Sloan 2017's window; hikari::sh's Newton step and
// depth-3 binary search). One workgroup of 64 threads, 64 samples each. CPU twin:
// reference::sky_sh.

#import hikari::sky::sky_background_no_disks
#import hikari::sh::{ShL2Rgb, sh_basis_l2, sh_dering_l2_rgb}

@group(0) @binding(0) var<storage, read_write> out_sh: array<vec4<f32>, 18>;

const SAMPLES: u32 = 4096u;
const THREADS: u32 = 64u;
const GOLDEN_ANGLE: f32 = 2.39996322972865332;

var<workgroup> partial: array<array<vec3<f32>, 9>, THREADS>;

// Direction i of the spherical Fibonacci set: equal-area bands in z, golden-angle azimuths.
fn fibonacci_dir(i: u32) -> vec3<f32> {
    let z = 1.0 - (2.0 * f32(i) + 1.0) / f32(SAMPLES);
    let r = sqrt(max(1.0 - z * z, 0.0));
    let phi = GOLDEN_ANGLE * f32(i);
    return vec3<f32>(r * cos(phi), z, r * sin(phi));
}

@compute @workgroup_size(64, 1, 1)
fn main(@builtin(local_invocation_index) lid: u32) {
    var acc: array<vec3<f32>, 9>;
    for (var k = 0u; k < 9u; k++) {
        acc[k] = vec3<f32>(0.0);
    }
    for (var s = lid; s < SAMPLES; s += THREADS) {
        let d = fibonacci_dir(s);
        let l = sky_background_no_disks(d);
        let y = sh_basis_l2(d);
        for (var k = 0u; k < 9u; k++) {
            acc[k] += l * y[k];
        }
    }
    partial[lid] = acc;
    workgroupBarrier();
    for (var stride = THREADS / 2u; stride > 0u; stride >>= 1u) {
        if lid < stride {
            for (var k = 0u; k < 9u; k++) {
                partial[lid][k] += partial[lid + stride][k];
            }
        }
        workgroupBarrier();
    }
    if lid == 0u {
        var sh: ShL2Rgb;
        let w = 4.0 * 3.14159265358979 / f32(SAMPLES);
        for (var k = 0u; k < 9u; k++) {
            sh.c[k] = partial[0][k] * w;
            out_sh[k] = vec4<f32>(sh.c[k], 0.0);
        }
        let d = sh_dering_l2_rgb(sh);
        for (var k = 0u; k < 9u; k++) {
            out_sh[9u + k] = vec4<f32>(d.c[k], 0.0);
        }
    }
}
