// One workgroup per probe: its rays' contributions to sky visibility (rays that escape) and
// bounced sky visibility (albedo times the fraction of the hit's secondary rays that escape),
// projected on L2 SH with the CPU's per-ray weights (4π/n · Y(ω), uploaded), summed per
// invocation and then in workgroup memory, in f32. Out per probe, 40 floats: 9 sky, 27
// bounced (coefficient-major, RGB), enclosed probe rays, hits that traced secondary rays.

#import hikari::probe_bake::{BakeParams, BakeHit, BAKE_MISS, BAKE_WORKGROUP}

@group(0) @binding(0) var<storage, read> hits: array<BakeHit>;
@group(0) @binding(1) var<storage, read> surfaces: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read> bounce_hits: array<BakeHit>;
// Three rows per probe ray: Y0..3, Y4..7, Y8 (times the ray's solid angle).
@group(0) @binding(3) var<storage, read> weights: array<vec4<f32>>;
@group(0) @binding(4) var<storage, read_write> sums: array<f32>;
@group(0) @binding(5) var<uniform> params: BakeParams;

const SUMS: u32 = 38u;
const OUT_STRIDE: u32 = 40u;

var<workgroup> partial: array<array<f32, 38>, 64>;

@compute @workgroup_size(64)
fn main(@builtin(workgroup_id) wid: vec3<u32>, @builtin(local_invocation_index) lid: u32) {
    let p = wid.x;
    let n = params.rays_per_probe;
    let m = params.bounce_rays;
    var s: array<f32, 38>;
    for (var q = 0u; q < SUMS; q++) {
        s[q] = 0.0;
    }
    for (var k = lid; k < n; k += BAKE_WORKGROUP) {
        let i = p * n + k;
        let h = hits[i];
        let surface = surfaces[i];
        let w0 = weights[k * 3u];
        let w1 = weights[k * 3u + 1u];
        let w2 = weights[k * 3u + 2u];
        var y = array<f32, 9>(w0.x, w0.y, w0.z, w0.w, w1.x, w1.y, w1.z, w1.w, w2.x);
        if h.instance == BAKE_MISS || surface.w < 0.0 {
            for (var c = 0u; c < 9u; c++) {
                s[c] += y[c];
            }
            continue;
        }
        if h.t < params.enclosure_radius {
            s[36] += 1.0;
        }
        if surface.w > 0.0 {
            var escaped = 0u;
            for (var j = 0u; j < m; j++) {
                if bounce_hits[i * m + j].instance == BAKE_MISS {
                    escaped += 1u;
                }
            }
            let radiance = surface.xyz * (f32(escaped) / f32(m));
            for (var c = 0u; c < 9u; c++) {
                s[9u + c * 3u] += y[c] * radiance.x;
                s[10u + c * 3u] += y[c] * radiance.y;
                s[11u + c * 3u] += y[c] * radiance.z;
            }
            s[37] += 1.0;
        }
    }
    partial[lid] = s;
    workgroupBarrier();
    for (var stride = BAKE_WORKGROUP / 2u; stride > 0u; stride = stride / 2u) {
        if lid < stride {
            for (var q = 0u; q < SUMS; q++) {
                partial[lid][q] += partial[lid + stride][q];
            }
        }
        workgroupBarrier();
    }
    if lid == 0u {
        for (var q = 0u; q < SUMS; q++) {
            sums[p * OUT_STRIDE + q] = partial[0][q];
        }
    }
}
