#define_import_path hikari::math_check_io

// What every math_check verification kernel binds: one case per invocation, flat f32 records in
// and out (see src/checks/math_check.rs), so WGSL's vec3 padding plays no part in comparisons.

struct MathCheckParams {
    count: u32,
    pad_a: u32,
    pad_b: u32,
    pad_c: u32,
}

@group(0) @binding(0) var<uniform> params: MathCheckParams;
@group(0) @binding(1) var<storage, read> inputs: array<f32>;
@group(0) @binding(2) var<storage, read_write> outputs: array<f32>;

fn in_vec3(i: u32) -> vec3<f32> {
    return vec3<f32>(inputs[i], inputs[i + 1u], inputs[i + 2u]);
}

fn out_vec3(i: u32, v: vec3<f32>) {
    outputs[i] = v.x;
    outputs[i + 1u] = v.y;
    outputs[i + 2u] = v.z;
}
