// Projects the sky's radiance (inscattering and the ground, without the disks: the directional
// light carries the sun and moon) to L2 SH with 4096 directions of a spherical Fibonacci set,
// then derings it as Ghost of Tsushima does (Sloan 2017's window; hikari::sh's Newton step and
// depth-3 binary search). CPU twin: reference::sky_sh.
//
// Two passes, so that the 4096 lookups spread over the GPU instead of queueing on one
// workgroup: `project` runs a direction a thread in 64 workgroups and sums each workgroup's
// 64 terms in workgroup memory; `finish` adds the 64 partial sums and derings.

#import hikari::sky::sky_background_no_disks
#import hikari::sh::{ShL2Rgb, SH_C0, SH_C1, SH_C2, SH_C3, SH_C4, sh_dering_l2_rgb}

// project: 64 workgroups x 9 partial coefficients (xyz). finish: reads them.
@group(0) @binding(0) var<storage, read_write> partials: array<vec4<f32>, 576>;
// finish: 9 raw coefficients, then 9 deringed ones.
@group(0) @binding(1) var<storage, read_write> out_sh: array<vec4<f32>, 18>;

const SAMPLES: u32 = 4096u;
const THREADS: u32 = 64u;
const GOLDEN_ANGLE: f32 = 2.39996322972865332;

var<workgroup> terms: array<array<vec3<f32>, 9>, THREADS>;

// Adds the workgroup's 64 rows of `terms` into row 0, a tree of halvings.
fn sum_terms(lid: u32) {
    workgroupBarrier();
    for (var stride = THREADS / 2u; stride > 0u; stride >>= 1u) {
        if lid < stride {
            for (var k = 0u; k < 9u; k++) {
                terms[lid][k] += terms[lid + stride][k];
            }
        }
        workgroupBarrier();
    }
}

// Direction i of the spherical Fibonacci set: equal-area bands in z, golden-angle azimuths.
fn fibonacci_dir(i: u32) -> vec3<f32> {
    let z = 1.0 - (2.0 * f32(i) + 1.0) / f32(SAMPLES);
    let r = sqrt(max(1.0 - z * z, 0.0));
    let phi = GOLDEN_ANGLE * f32(i);
    return vec3<f32>(r * cos(phi), z, r * sin(phi));
}

@compute @workgroup_size(64, 1, 1)
fn project(@builtin(local_invocation_index) lid: u32, @builtin(workgroup_id) wg: vec3<u32>) {
    let d = fibonacci_dir(wg.x * THREADS + lid);
    let l = sky_background_no_disks(d);
    terms[lid][0] = l * SH_C0;
    terms[lid][1] = l * (SH_C1 * d.y);
    terms[lid][2] = l * (SH_C1 * d.z);
    terms[lid][3] = l * (SH_C1 * d.x);
    terms[lid][4] = l * (SH_C2 * d.x * d.y);
    terms[lid][5] = l * (SH_C2 * d.y * d.z);
    terms[lid][6] = l * (SH_C3 * (3.0 * d.z * d.z - 1.0));
    terms[lid][7] = l * (SH_C2 * d.x * d.z);
    terms[lid][8] = l * (SH_C4 * (d.x * d.x - d.y * d.y));
    sum_terms(lid);
    if lid < 9u {
        partials[wg.x * 9u + lid] = vec4<f32>(terms[0][lid], 0.0);
    }
}

@compute @workgroup_size(64, 1, 1)
fn finish(@builtin(local_invocation_index) lid: u32) {
    // Thread g loads workgroup g's partial sums; then the same tree as `project`.
    for (var k = 0u; k < 9u; k++) {
        terms[lid][k] = partials[lid * 9u + k].xyz;
    }
    sum_terms(lid);
    if lid == 0u {
        var sh: ShL2Rgb;
        let w = 4.0 * 3.14159265358979 / f32(SAMPLES);
        for (var k = 0u; k < 9u; k++) {
            sh.c[k] = terms[0][k] * w;
            out_sh[k] = vec4<f32>(sh.c[k], 0.0);
        }
        let d = sh_dering_l2_rgb(sh);
        for (var k = 0u; k < 9u; k++) {
            out_sh[9u + k] = vec4<f32>(d.c[k], 0.0);
        }
    }
}
