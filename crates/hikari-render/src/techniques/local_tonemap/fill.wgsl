// Fills the bilateral grid with homogeneous log luminance (w V, w): one workgroup per 64x32
// cell, each pixel weighted linearly to the two slices nearest its log luminance and not at
// all in x and y (the blur that follows is wide there). Sums are taken in workgroup memory,
// in fixed point (integer adds commute, so the grid is the same on every run and GPU), and
// written once a cell: no global atomics. The column's sums over all slices are the cell's
// mean log luminance for the wide Gaussian.

#import hikari::local_tonemap::{LocalTonemapParams, GRID_W, GRID_H, GRID_D, grid_log2}

@group(0) @binding(0) var<uniform> params: LocalTonemapParams;
@group(0) @binding(1) var radiance: texture_2d<f32>;
@group(0) @binding(2) var<storage, read> exposure: vec4<f32>;
@group(0) @binding(3) var grid: texture_storage_3d<rgba32float, write>;
@group(0) @binding(4) var coarse: texture_storage_2d<rgba32float, write>;

// Fixed-point unit of a weight: 1/1024 per pixel. A cell's sums stay below 2^32 for cells of
// up to 2^32 / (1024 × 48 EV) = 87000 pixels (a 64x32 grid over 178 Mpx).
const FIXED: f32 = 1024.0;

var<workgroup> acc_wv: array<atomic<u32>, 64>;
var<workgroup> acc_w: array<atomic<u32>, 64>;

fn flush(k: i32, w0: u32, w1: u32, wv0: u32, wv1: u32) {
    let k0 = u32(clamp(k, 0, i32(GRID_D) - 1));
    let k1 = u32(clamp(k + 1, 0, i32(GRID_D) - 1));
    atomicAdd(&acc_w[k0], w0);
    atomicAdd(&acc_w[k1], w1);
    atomicAdd(&acc_wv[k0], wv0);
    atomicAdd(&acc_wv[k1], wv1);
}

// 64 threads across a cell (60 px wide at 3840: one column each, neighbours read neighbouring
// texels), 4 bands of rows down it. Each thread walks its column downwards and keeps the sums
// of its current run of pixels that share a slice pair in registers, adding them to workgroup
// memory only when the pair changes: neighbouring pixels mostly share one, so the workgroup's
// atomics (256 threads on the same one or two slices, which serialise) drop by the run length.
// The integer sums are those of one add per pixel, so the grid is unchanged to the bit.
@compute @workgroup_size(64, 4, 1)
fn main(
    @builtin(workgroup_id) cell: vec3<u32>,
    @builtin(local_invocation_id) lid3: vec3<u32>,
    @builtin(local_invocation_index) lid: u32,
) {
    if lid < GRID_D {
        atomicStore(&acc_wv[lid], 0u);
        atomicStore(&acc_w[lid], 0u);
    }
    workgroupBarrier();
    let size = textureDimensions(radiance);
    let lo = cell.xy * size / vec2<u32>(GRID_W, GRID_H);
    let hi = (cell.xy + 1u) * size / vec2<u32>(GRID_W, GRID_H);
    let rows = hi.y - lo.y;
    let y0 = lo.y + rows * lid3.y / 4u;
    let y1 = lo.y + rows * (lid3.y + 1u) / 4u;
    let scale = exposure.x;
    for (var x = lo.x + lid3.x; x < hi.x; x += 64u) {
        var run = -2;
        var w0s = 0u;
        var w1s = 0u;
        var wv0s = 0u;
        var wv1s = 0u;
        for (var y = y0; y < y1; y++) {
            let v = grid_log2(textureLoad(radiance, vec2<u32>(x, y), 0).rgb, scale, params);
            let t = v * params.grid.y - 0.5;
            let kf = floor(t);
            let k = i32(kf);
            let w1 = u32(round((t - kf) * FIXED));
            let w0 = u32(FIXED) - w1;
            if k != run {
                if run != -2 {
                    flush(run, w0s, w1s, wv0s, wv1s);
                }
                run = k;
                w0s = 0u;
                w1s = 0u;
                wv0s = 0u;
                wv1s = 0u;
            }
            w0s += w0;
            w1s += w1;
            wv0s += u32(round(f32(w0) * v));
            wv1s += u32(round(f32(w1) * v));
        }
        if run != -2 {
            flush(run, w0s, w1s, wv0s, wv1s);
        }
    }
    workgroupBarrier();
    if lid < GRID_D {
        let wv = f32(atomicLoad(&acc_wv[lid])) / FIXED;
        let w = f32(atomicLoad(&acc_w[lid])) / FIXED;
        textureStore(grid, vec3<u32>(cell.xy, lid), vec4<f32>(wv, w, 0.0, 0.0));
    }
    if lid == 0u {
        var wv = 0u;
        var w = 0u;
        for (var k = 0u; k < GRID_D; k++) {
            wv += atomicLoad(&acc_wv[k]);
            w += atomicLoad(&acc_w[k]);
        }
        textureStore(coarse, cell.xy, vec4<f32>(f32(wv) / FIXED, f32(w) / FIXED, 0.0, 0.0));
    }
}
