// G-buffer: rasterises every instance, pulling vertices from storage buffers.

#import hikari::view::View
#import hikari::octahedral::oct_encode

struct Vertex {
    position: vec4<f32>,
    normal: vec4<f32>,
}

struct Instance {
    model: mat4x4<f32>,
    // Inverse transpose of the model matrix's upper 3x3, padded to 4x4.
    normal_model: mat4x4<f32>,
    // rgb: linear base colour; a: perceptual roughness.
    base_color_roughness: vec4<f32>,
    // x: metalness; yzw: emitted luminance in nits.
    metal_emissive: vec4<f32>,
}

@group(0) @binding(0) var<uniform> view: View;
@group(0) @binding(1) var<storage, read> vertices: array<Vertex>;
@group(0) @binding(2) var<storage, read> instances: array<Instance>;

struct VsOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) normal: vec3<f32>,
    @location(1) @interpolate(flat) instance: u32,
}

@vertex
fn vs(@builtin(vertex_index) vertex: u32, @builtin(instance_index) instance: u32) -> VsOut {
    let v = vertices[vertex];
    let inst = instances[instance];
    var out: VsOut;
    out.clip = view.view_proj * (inst.model * vec4<f32>(v.position.xyz, 1.0));
    out.normal = (inst.normal_model * vec4<f32>(v.normal.xyz, 0.0)).xyz;
    out.instance = instance;
    return out;
}

struct GBufferOut {
    // Octahedral world-space normal.
    @location(0) normal: vec4<f32>,
    // rgb: base colour; a: perceptual roughness.
    @location(1) albedo: vec4<f32>,
}

@fragment
fn fs(in: VsOut) -> GBufferOut {
    let inst = instances[in.instance];
    var out: GBufferOut;
    out.normal = vec4<f32>(oct_encode(normalize(in.normal)), 0.0, 0.0);
    out.albedo = inst.base_color_roughness;
    return out;
}
