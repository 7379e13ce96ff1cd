// Zeroes the exposure histograms before `exposure.meter` adds to them.

@group(0) @binding(0) var<storage, read_write> histogram: array<u32>;

@compute @workgroup_size(256, 1, 1)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x < arrayLength(&histogram) {
        histogram[id.x] = 0u;
    }
}
