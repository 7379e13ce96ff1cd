// Frame-graph overhead benchmark: a pass that binds a uniform and a read-only storage buffer
// and does (almost) nothing. Nothing is written, so consecutive passes need no barrier and
// their cost is the graph's and the driver's per-pass cost.

struct EmptyParams {
    value: vec4<f32>,
}

@group(0) @binding(0) var<uniform> params: EmptyParams;
@group(0) @binding(1) var<storage, read> source: array<f32>;

var<workgroup> scratch: f32;

@compute @workgroup_size(64, 1, 1)
fn main(@builtin(local_invocation_index) i: u32) {
    // Reads its inputs so the compiler cannot drop the bindings.
    if i == 0u && params.value.x < 0.0 {
        scratch = source[0];
    }
}
