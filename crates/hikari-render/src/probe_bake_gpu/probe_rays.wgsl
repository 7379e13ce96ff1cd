// Probe rays of the GPU bake: ray k of probe p leaves the probe along the CPU's Fibonacci
// direction k (uploaded, so both trace the same directions), from t_min to infinity.

#import hikari::probe_bake::{BakeParams, BakeRay, bake_index}

@group(0) @binding(0) var<storage, read> positions: array<vec4<f32>>;
@group(0) @binding(1) var<storage, read> directions: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read_write> rays: array<BakeRay>;
@group(0) @binding(3) var<uniform> params: BakeParams;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = bake_index(gid, params);
    if i >= params.probes * params.rays_per_probe {
        return;
    }
    let p = i / params.rays_per_probe;
    let k = i - p * params.rays_per_probe;
    rays[i] = BakeRay(positions[p].xyz, params.t_min, directions[k].xyz, params.far);
}
