// Runs the probe lookup at given points, for tests/render/irradiance_probes.rs (GPU against
// reference::irradiance_at).

#import hikari::irradiance_probes::probe_irradiance_at

// Two per query: (position, 0), (normal, interior mask).
@group(0) @binding(0) var<storage, read> queries: array<vec4<f32>>;
@group(0) @binding(1) var<storage, read_write> results: array<vec4<f32>>;

@compute @workgroup_size(64, 1, 1)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= arrayLength(&results) {
        return;
    }
    let p = queries[2u * id.x];
    let n = queries[2u * id.x + 1u];
    results[id.x] = probe_irradiance_at(p.xyz, n.xyz, n.w);
}
