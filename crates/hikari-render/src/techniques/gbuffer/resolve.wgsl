// G-buffer resolve: turns the visibility buffer (depth and triangle id a pixel) into the
// G-buffer. Barycentrics come from intersecting the pixel's camera ray with the triangle, and
// texture derivatives from the rays through the neighbouring pixel centres, so textures are
// filtered as a rasteriser's quads would. CPU twin: `gbuffer::reference`.

#import hikari::view::View
#import hikari::octahedral::oct_encode
#import hikari::scene_gpu::{VertexAttr, InstanceGpu, MaterialGpu, Chunk, CHUNK_TRIANGLES, NO_TEXTURE, INSTANCE_DOUBLE_SIDED, INSTANCE_OWN_NORMAL_MATRIX, INSTANCE_MOVED, EXTRA_BITANGENT_NEGATIVE, EXTRA_HAS_TANGENT, EXTRA_HAS_INTERIOR, wrap_uv}

@group(0) @binding(0) var<uniform> view: View;
@group(0) @binding(1) var<storage, read> visibility: array<vec2<u32>>;
@group(0) @binding(2) var<storage, read> positions: array<vec4<f32>>;
// Last frame's `positions`: they differ only where a mesh deforms.
@group(0) @binding(3) var<storage, read> prev_positions: array<vec4<f32>>;
@group(0) @binding(4) var<storage, read> attributes: array<VertexAttr>;
@group(0) @binding(5) var<storage, read> indices: array<u32>;
@group(0) @binding(6) var<storage, read> instances: array<InstanceGpu>;
@group(0) @binding(7) var<storage, read> materials: array<MaterialGpu>;
@group(0) @binding(8) var<storage, read> chunks: array<Chunk>;
@group(0) @binding(9) var color_textures: texture_2d_array<f32>;
@group(0) @binding(10) var data_textures: texture_2d_array<f32>;
@group(0) @binding(11) var texture_sampler: sampler;
@group(0) @binding(12) var out_depth: texture_storage_2d<r32float, write>;
@group(0) @binding(13) var out_normal: texture_storage_2d<rgba16float, write>;
@group(0) @binding(14) var out_albedo: texture_storage_2d<rgba8unorm, write>;
@group(0) @binding(15) var out_material: texture_storage_2d<rgba8unorm, write>;
@group(0) @binding(16) var out_motion: texture_storage_2d<rgba16float, write>;
@group(0) @binding(17) var out_emissive: texture_storage_2d<rgba16float, write>;
@group(0) @binding(18) var out_instance: texture_storage_2d<r32uint, write>;
@group(0) @binding(19) var out_vertex_normal: texture_storage_2d<rgba8snorm, write>;

const NO_INSTANCE: u32 = 0xffffffffu;
// Largest finite f16 is 65504.
const MAX_HALF: f32 = 65000.0;

// Any unit vector perpendicular to n (Duff et al. 2017); twin of scene_gpu::orthonormal_tangent.
fn orthonormal_tangent(n: vec3<f32>) -> vec3<f32> {
    let s = select(-1.0, 1.0, n.z >= 0.0);
    let a = -1.0 / (s + n.z);
    let b = n.x * n.y * a;
    return vec3<f32>(1.0 + s * n.x * n.x * a, s * b, -s * n.x);
}

fn unpack_oct(p: u32) -> vec3<f32> {
    let e = unpack2x16snorm(p);
    var v = vec3<f32>(e, 1.0 - abs(e.x) - abs(e.y));
    if v.z < 0.0 {
        let s = select(vec2<f32>(-1.0), vec2<f32>(1.0), v.xy >= vec2<f32>(0.0));
        v = vec3<f32>((1.0 - abs(v.yx)) * s, v.z);
    }
    return normalize(v);
}

// Point on the near plane seen through a pixel position (not necessarily a centre).
fn near_point(p: vec2<f32>) -> vec3<f32> {
    let uv = p * view.viewport.zw;
    let w = view.inv_view_proj * vec4<f32>(uv.x * 2.0 - 1.0, 1.0 - uv.y * 2.0, 1.0, 1.0);
    return w.xyz / w.w;
}

// Barycentrics (of p1, p2) where the ray o + t d meets the plane of the triangle.
fn ray_barycentrics(o: vec3<f32>, d: vec3<f32>, p0: vec3<f32>, e1: vec3<f32>, e2: vec3<f32>) -> vec2<f32> {
    let pv = cross(d, e2);
    let inv_det = 1.0 / dot(e1, pv);
    let tv = o - p0;
    let qv = cross(tv, e1);
    return vec2<f32>(dot(tv, pv), dot(d, qv)) * inv_det;
}

struct UvGrad {
    uv: vec2<f32>,
    ddx: vec2<f32>,
    ddy: vec2<f32>,
}

fn sample_color(layer: u32, wrap: u32, g: UvGrad) -> vec4<f32> {
    if layer == NO_TEXTURE {
        return vec4<f32>(1.0);
    }
    return textureSampleGrad(color_textures, texture_sampler, wrap_uv(g.uv, wrap, textureDimensions(color_textures)), layer, g.ddx, g.ddy);
}

fn sample_data(layer: u32, wrap: u32, g: UvGrad) -> vec4<f32> {
    if layer == NO_TEXTURE {
        return vec4<f32>(1.0);
    }
    return textureSampleGrad(data_textures, texture_sampler, wrap_uv(g.uv, wrap, textureDimensions(data_textures)), layer, g.ddx, g.ddy);
}

fn unpack_color(c: vec2<u32>) -> vec4<f32> {
    return vec4<f32>(unpack2x16unorm(c.x), unpack2x16unorm(c.y));
}

fn mat3_of(m: mat4x4<f32>) -> mat3x3<f32> {
    return mat3x3<f32>(m[0].xyz, m[1].xyz, m[2].xyz);
}

fn project_to_pixel(m: mat4x4<f32>, p: vec4<f32>) -> vec2<f32> {
    let c = m * p;
    let ndc = c.xy / c.w;
    return vec2<f32>(ndc.x * 0.5 + 0.5, 0.5 - ndc.y * 0.5) * view.viewport.xy;
}

// Clamped to what f16 holds, and NaN (which fails every comparison) to 0: nothing non-finite
// reaches the G-buffer.
fn finite_half2(v: vec2<f32>) -> vec2<f32> {
    return select(vec2<f32>(0.0), clamp(v, vec2<f32>(-MAX_HALF), vec2<f32>(MAX_HALF)), abs(v) <= vec2<f32>(MAX_HALF * 2.0));
}

fn write_sky(px: vec2<u32>) {
    // The sky moves only with the camera's rotation: project the direction at infinity.
    let centre = vec2<f32>(px) + 0.5;
    let dir = near_point(centre) - view.position.xyz;
    let prev = project_to_pixel(view.prev_view_proj, vec4<f32>(dir, 0.0));
    textureStore(out_depth, px, vec4<f32>(0.0));
    textureStore(out_normal, px, vec4<f32>(0.0));
    textureStore(out_albedo, px, vec4<f32>(0.0));
    textureStore(out_material, px, vec4<f32>(0.0));
    textureStore(out_motion, px, vec4<f32>(finite_half2(prev - centre + view.jitter.xy), 0.0, 0.0));
    textureStore(out_emissive, px, vec4<f32>(0.0));
    textureStore(out_instance, px, vec4<u32>(NO_INSTANCE));
    textureStore(out_vertex_normal, px, vec4<f32>(0.0));
}

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let size = textureDimensions(out_depth);
    if any(gid.xy >= size) {
        return;
    }
    let px = gid.xy;
    let vis = visibility[px.y * size.x + px.x];
    if vis.y == 0u {
        write_sky(px);
        return;
    }
    let id = vis.x;
    let chunk = chunks[id / CHUNK_TRIANGLES];
    let tri = chunk.first_triangle + id % CHUNK_TRIANGLES;
    // Fields read one by one: the two matrices most instances need not are then not loaded.
    let ci = chunk.instance;
    let model = instances[ci].model;
    let inst_flags = instances[ci].flags;
    let mat = materials[instances[ci].material];
    let i = vec3<u32>(indices[tri * 3u], indices[tri * 3u + 1u], indices[tri * 3u + 2u]);
    let q0 = positions[i.x].xyz;
    let q1 = positions[i.y].xyz;
    let q2 = positions[i.z].xyz;
    let p0 = (model * vec4<f32>(q0, 1.0)).xyz;
    let e1 = (model * vec4<f32>(q1, 1.0)).xyz - p0;
    let e2 = (model * vec4<f32>(q2, 1.0)).xyz - p0;

    let o = view.position.xyz;
    let centre = vec2<f32>(px) + 0.5;
    let d = near_point(centre) - o;
    let b = ray_barycentrics(o, d, p0, e1, e2);
    let w = vec3<f32>(1.0 - b.x - b.y, b.x, b.y);

    let a0 = attributes[i.x];
    let a1 = attributes[i.y];
    let a2 = attributes[i.z];
    let uv0 = a0.uv;
    let duv1 = a1.uv - uv0;
    let duv2 = a2.uv - uv0;
    var g: UvGrad;
    g.uv = uv0 + duv1 * b.x + duv2 * b.y;
    // Texture derivatives only for textured materials: the neighbours' rays cost as much as
    // the pixel's own.
    let textured = any(mat.textures != vec4<u32>(NO_TEXTURE)) || mat.more_textures.x != NO_TEXTURE;
    g.ddx = vec2<f32>(0.0);
    g.ddy = vec2<f32>(0.0);
    if textured {
        let bx = ray_barycentrics(o, near_point(centre + vec2<f32>(1.0, 0.0)) - o, p0, e1, e2);
        let by = ray_barycentrics(o, near_point(centre + vec2<f32>(0.0, 1.0)) - o, p0, e1, e2);
        g.ddx = duv1 * (bx.x - b.x) + duv2 * (bx.y - b.y);
        g.ddy = duv1 * (by.x - b.x) + duv2 * (by.y - b.y);
    }

    // Frames: geometric normal faces the camera on double-sided surfaces (single-sided back
    // faces were culled); shading normal and tangent follow it.
    // A rotation with uniform scale (most instances) has its own 3x3 as the normal matrix up to
    // a scale, which the normalisation removes.
    var normal_model = mat3_of(model);
    if (inst_flags & INSTANCE_OWN_NORMAL_MATRIX) != 0u {
        normal_model = mat3_of(instances[ci].normal_model);
    }
    var ng = normalize(cross(e1, e2));
    var n = normalize(normal_model * (unpack_oct(a0.normal) * w.x + unpack_oct(a1.normal) * w.y + unpack_oct(a2.normal) * w.z));
    let facing = select(1.0, -1.0, dot(ng, d) > 0.0 && (inst_flags & INSTANCE_DOUBLE_SIDED) != 0u);
    n *= facing;
    ng *= facing;
    // Before the normal map: the reflection probes' horizon occlusion compares the two.
    var n_vertex = n;
    if !all(n_vertex == n_vertex) || dot(n_vertex, n_vertex) < 0.5 {
        n_vertex = ng;
    }
    let model3 = mat3_of(model);
    var t = model3 * (unpack_oct(a0.tangent) * w.x + unpack_oct(a1.tangent) * w.y + unpack_oct(a2.tangent) * w.z);
    t = t - n * dot(n, t);
    if (a0.extra & EXTRA_HAS_TANGENT) == 0u || dot(t, t) < 1e-12 {
        t = orthonormal_tangent(n);
    } else {
        t = normalize(t);
    }
    let handedness = select(1.0, -1.0, (a0.extra & EXTRA_BITANGENT_NEGATIVE) != 0u);
    var bt = cross(n, t) * handedness;

    let wraps = mat.more_textures.y;
    let nt = mat.textures.z;
    if nt != NO_TEXTURE {
        let s = sample_data(nt, (wraps >> 8u) & 15u, g).xy * 2.0 - 1.0;
        let xy = s * mat.emissive.w;
        let tn = vec3<f32>(xy, sqrt(max(0.0, 1.0 - dot(xy, xy))));
        let mapped = t * tn.x + bt * tn.y + n * tn.z;
        if dot(mapped, mapped) > 1e-12 {
            n = normalize(mapped);
            t = normalize(t - n * dot(n, t));
            bt = cross(n, t) * handedness;
        }
    }
    // Degenerate vertex data (zero normals) must not leak NaN into the G-buffer.
    if !all(n == n) || dot(n, n) < 0.5 {
        n = ng;
        t = orthonormal_tangent(n);
        bt = cross(n, t);
    }
    // KHR_materials_anisotropy: the direction is the tangent rotated in the tangent plane.
    let rot = mat.params.w;
    let aniso_dir = normalize(t * cos(rot) + bt * sin(rot));

    let vertex_color = unpack_color(a0.color) * w.x + unpack_color(a1.color) * w.y + unpack_color(a2.color) * w.z;
    let base = mat.base_color.rgb * vertex_color.rgb * sample_color(mat.textures.x, wraps & 15u, g).rgb;
    let mr = sample_data(mat.textures.y, (wraps >> 4u) & 15u, g);
    let roughness = clamp(mat.params.x * mr.g, 0.0, 1.0);
    let metalness = clamp(mat.params.y * mr.b, 0.0, 1.0);
    let occlusion_tex = sample_data(mat.more_textures.x, (wraps >> 16u) & 15u, g).r;
    let occlusion = 1.0 + mat.extra.x * (occlusion_tex - 1.0);
    let emissive = mat.emissive.rgb * sample_color(mat.textures.w, (wraps >> 12u) & 15u, g).rgb;

    let vertex_interior = f32(a0.extra & 0xffffu) * w.x + f32(a1.extra & 0xffffu) * w.y + f32(a2.extra & 0xffffu) * w.z;
    // `Mesh::interior_at`'s order: the mesh's own mask, else the material's, else the default
    // (which a mesh without a mask carries in its vertices).
    let material_wins = mat.extra.y >= 0.0 && (a0.extra & EXTRA_HAS_INTERIOR) == 0u;
    let interior = select(vertex_interior / 65535.0, mat.extra.y, material_wins);

    // Motion: where this surface point was last frame, minus where it is now, in pixels. Now is
    // the pixel centre less this frame's jitter: `prev_view_proj` is unjittered.
    // A deforming mesh's vertices were elsewhere last frame: the same barycentrics on last
    // frame's triangle. Still meshes (the same vertices) keep the exact point of the ray.
    let world = p0 + e1 * b.x + e2 * b.y;
    let r0 = prev_positions[i.x].xyz;
    let r1 = prev_positions[i.y].xyz;
    let r2 = prev_positions[i.z].xyz;
    let deformed = any(r0 != q0) || any(r1 != q1) || any(r2 != q2);
    let q = select(q0 * w.x + q1 * w.y + q2 * w.z, r0 * w.x + r1 * w.y + r2 * w.z, deformed);
    var prev_world = vec4<f32>(world, 1.0);
    if (inst_flags & INSTANCE_MOVED) != 0u {
        prev_world = instances[ci].prev_model * vec4<f32>(q, 1.0);
    } else if deformed {
        prev_world = model * vec4<f32>(q, 1.0);
    }
    let prev = project_to_pixel(view.prev_view_proj, prev_world);
    let view_depth = dot(world - o, view.forward_near.xyz);

    textureStore(out_depth, px, vec4<f32>(bitcast<f32>(vis.y), 0.0, 0.0, 0.0));
    textureStore(out_normal, px, vec4<f32>(oct_encode(n), oct_encode(aniso_dir)));
    textureStore(out_albedo, px, vec4<f32>(clamp(base, vec3<f32>(0.0), vec3<f32>(1.0)), clamp(interior, 0.0, 1.0)));
    textureStore(out_material, px, vec4<f32>(roughness, metalness, clamp(mat.params.z, 0.0, 1.0), clamp(occlusion, 0.0, 1.0)));
    textureStore(out_motion, px, vec4<f32>(finite_half2(prev - centre + view.jitter.xy), finite_half2(vec2<f32>(view_depth, 0.0))));
    // Alpha: the dielectric specular weight (KHR_materials_specular), which the BRDF reads.
    textureStore(out_emissive, px, vec4<f32>(clamp(emissive, vec3<f32>(0.0), vec3<f32>(MAX_HALF)), clamp(mat.extra.w, 0.0, 1.0)));
    textureStore(out_instance, px, vec4<u32>(chunk.instance, 0u, 0u, 0u));
    textureStore(out_vertex_normal, px, vec4<f32>(n_vertex, 0.0));
}
