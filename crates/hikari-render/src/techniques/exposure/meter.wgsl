// The exposure's histograms: log2 illuminance (lux) of every surface pixel, and log2 luminance
// (nits) of every pixel, sky included, for the highlight rule. Each workgroup counts into
// workgroup memory and adds its counts to the buffer once, so the global atomics see one add
// per bin and workgroup instead of one per pixel.

#import hikari::exposure::{ExposureParams, HISTOGRAM_BINS, LUMA, histogram_bin}

@group(0) @binding(0) var<uniform> params: ExposureParams;
@group(0) @binding(1) var radiance: texture_2d<f32>;
@group(0) @binding(2) var illuminance: texture_2d<f32>;
@group(0) @binding(3) var<storage, read_write> histogram: array<atomic<u32>>;

var<workgroup> local_bins: array<atomic<u32>, 256>;

@compute @workgroup_size(16, 16, 1)
fn main(
    @builtin(global_invocation_id) id: vec3<u32>,
    @builtin(local_invocation_index) lid: u32,
) {
    atomicStore(&local_bins[lid], 0u);
    workgroupBarrier();
    let size = textureDimensions(radiance);
    if all(id.xy < size) {
        let e = textureLoad(illuminance, id.xy, 0).r;
        // Negative marks the sky (no surface); NaN fails the test too.
        if e >= 0.0 {
            let b = histogram_bin(log2(max(e, 1e-30)), params.histogram.x, params.histogram.y);
            atomicAdd(&local_bins[b], 1u);
        }
        let y = dot(textureLoad(radiance, id.xy, 0).rgb, LUMA);
        let l = select(0.0, y, y >= 0.0);
        let b = histogram_bin(log2(max(l, 1e-30)), params.histogram.z, params.histogram.w);
        atomicAdd(&local_bins[HISTOGRAM_BINS + b], 1u);
    }
    workgroupBarrier();
    let n = atomicLoad(&local_bins[lid]);
    if n > 0u {
        atomicAdd(&histogram[lid], n);
    }
}
