// Frame-graph overhead benchmark: each pass reads and writes the same storage buffer, so every
// pass depends on the one before and the driver must put a barrier between them.

struct EmptyParams {
    value: vec4<f32>,
}

@group(0) @binding(0) var<uniform> params: EmptyParams;
@group(0) @binding(1) var<storage, read_write> sink: array<f32>;

@compute @workgroup_size(64, 1, 1)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x == 0u {
        sink[0] = sink[0] + params.value.x;
    }
}
