// Frame-graph overhead benchmark: a pass that binds one uniform and does (almost) nothing, so
// its cost is the graph's and the driver's per-pass cost.

struct EmptyParams {
    value: vec4<f32>,
}

@group(0) @binding(0) var<uniform> params: EmptyParams;
@group(0) @binding(1) var<storage, read_write> sink: array<f32>;

@compute @workgroup_size(64, 1, 1)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x == 0u && params.value.x < 0.0 {
        sink[0] = params.value.x;
    }
}
