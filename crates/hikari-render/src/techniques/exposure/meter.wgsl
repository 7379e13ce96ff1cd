// The exposure's histograms: log2 illuminance (lux) of every surface pixel, and log2 luminance
// (nits) of every pixel, sky included, for the highlight rule.
//
// Counting is what costs here, not reading: 256 threads adding to the same one or two bins of
// workgroup memory serialise. So each thread walks a column of ROWS pixels downwards (the
// threads of a row read neighbouring texels) and counts its current run of equal bins in a
// register, adding it to workgroup memory only when the bin changes; neighbouring pixels mostly
// share a bin. The workgroup then adds its non-zero bins to the buffer once. The counts are the
// same integers as one add per pixel.

#import hikari::exposure::{ExposureParams, HISTOGRAM_BINS, LUMA, histogram_bin}

@group(0) @binding(0) var<uniform> params: ExposureParams;
@group(0) @binding(1) var radiance: texture_2d<f32>;
@group(0) @binding(2) var illuminance: texture_2d<f32>;
@group(0) @binding(3) var<storage, read_write> histogram: array<atomic<u32>>;

var<workgroup> local_bins: array<atomic<u32>, 256>;

// Rows each thread walks: a workgroup covers 64 x (4 ROWS) pixels. `Exposure::record`
// dispatches accordingly (`METER_ROWS`).
const ROWS: u32 = 16u;
const NO_BIN: u32 = 0xffffffffu;

@compute @workgroup_size(64, 4, 1)
fn main(
    @builtin(global_invocation_id) id: vec3<u32>,
    @builtin(local_invocation_index) lid: u32,
) {
    atomicStore(&local_bins[lid], 0u);
    workgroupBarrier();
    // One count a surface pixel of the illuminance (the render's size) and, at the same
    // place, the radiance's pixel (the output's size, larger below render scale 1).
    let size = textureDimensions(illuminance);
    let out_size = textureDimensions(radiance);
    let y0 = id.y * ROWS;
    if id.x < size.x {
        var e_bin = NO_BIN;
        var e_n = 0u;
        var l_bin = NO_BIN;
        var l_n = 0u;
        for (var y = y0; y < min(y0 + ROWS, size.y); y++) {
            let p = vec2<u32>(id.x, y);
            let e = textureLoad(illuminance, p, 0).r;
            // Negative marks the sky (no surface); NaN fails the test too.
            if e >= 0.0 {
                let b = histogram_bin(log2(max(e, 1e-30)), params.histogram.x, params.histogram.y);
                if b != e_bin {
                    if e_n > 0u {
                        atomicAdd(&local_bins[e_bin], e_n);
                    }
                    e_bin = b;
                    e_n = 0u;
                }
                e_n += 1u;
            }
            let lum = dot(textureLoad(radiance, p * out_size / size, 0).rgb, LUMA);
            let l = select(0.0, lum, lum >= 0.0);
            let b = HISTOGRAM_BINS
                + histogram_bin(log2(max(l, 1e-30)), params.histogram.z, params.histogram.w);
            if b != l_bin {
                if l_n > 0u {
                    atomicAdd(&local_bins[l_bin], l_n);
                }
                l_bin = b;
                l_n = 0u;
            }
            l_n += 1u;
        }
        if e_n > 0u {
            atomicAdd(&local_bins[e_bin], e_n);
        }
        if l_n > 0u {
            atomicAdd(&local_bins[l_bin], l_n);
        }
    }
    workgroupBarrier();
    let n = atomicLoad(&local_bins[lid]);
    if n > 0u {
        atomicAdd(&histogram[lid], n);
    }
}
