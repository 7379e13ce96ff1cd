// Verification kernel (not used by any frame) for `hikari::rtgi_resolve`, compared with
// ray_traced_gi::reference in tests/render/ray_traced_gi.rs.
// In, 5 vec4 a case: gi_y; (Co, Cg, material alpha, 0); (n, 0); (v, 0); (f0, f90).
// Out, 2 vec4: (diffuse, 0), (specular, 0).

#import hikari::rtgi_resolve::{rtgi_signal, rtgi_resolve_diffuse, rtgi_resolve_specular}

@group(0) @binding(0) var<storage, read> inputs: array<vec4<f32>>;
@group(0) @binding(1) var<storage, read_write> outputs: array<vec4<f32>>;

@compute @workgroup_size(64, 1, 1)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let c = gid.x;
    if 5u * c + 4u >= arrayLength(&inputs) || 2u * c + 1u >= arrayLength(&outputs) {
        return;
    }
    let a = inputs[5u * c + 1u];
    let s = rtgi_signal(inputs[5u * c], a.xy);
    let n = inputs[5u * c + 2u].xyz;
    let v = inputs[5u * c + 3u].xyz;
    let f = inputs[5u * c + 4u];
    outputs[2u * c] = vec4<f32>(rtgi_resolve_diffuse(s, n), 0.0);
    outputs[2u * c + 1u] = vec4<f32>(rtgi_resolve_specular(s, n, v, f.xyz, f.w, a.z), 0.0);
}
