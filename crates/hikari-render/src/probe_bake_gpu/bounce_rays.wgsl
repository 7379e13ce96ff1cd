// The surface each probe ray hit, and its secondary rays: the twin of the hit shading in
// hikari-bake's transport.rs (probe_transport). Per probe ray it writes `surfaces[i]`:
// w = -1 when the hit counts as a miss (a degenerate triangle, as the CPU's closest hit
// returns none), w = 0 when the surface sends no light to the probe (the back of a
// single-sided surface, black, or no secondary rays asked for), else w = 1 and the albedo in
// rgb, and its `bounce_rays` cosine-distributed rays (rays that are not needed get an empty
// interval, which every traversal misses at once).

#import hikari::probe_bake::{BakeParams, BakeRay, BakeHit, BAKE_MISS, bake_index}

@group(0) @binding(0) var<storage, read> hits: array<BakeHit>;
@group(0) @binding(1) var<storage, read> directions: array<vec4<f32>>;
// Per probe ray: the rotation of its secondary pattern (hikari_bake::transport::bounce_shift,
// a 64-bit hash computed on the CPU).
@group(0) @binding(2) var<storage, read> shifts: array<vec2<f32>>;
// hikari_bake::transport_tables::TransportTables.
@group(0) @binding(3) var<storage, read> instances: array<vec4<u32>>;
@group(0) @binding(4) var<storage, read> triangles: array<vec4<f32>>;
@group(0) @binding(5) var<storage, read_write> bounce_rays: array<BakeRay>;
@group(0) @binding(6) var<storage, read_write> surfaces: array<vec4<f32>>;
@group(0) @binding(7) var<uniform> params: BakeParams;

const INSTANCE_ROWS: u32 = 5u;
const NO_COLORS: u32 = 0xffffffffu;
const DOUBLE_SIDED: u32 = 1u;
const PI: f32 = 3.14159265358979323846;

fn to_world(r0: vec4<f32>, r1: vec4<f32>, r2: vec4<f32>, p: vec3<f32>) -> vec3<f32> {
    return vec3<f32>(dot(r0.xyz, p) + r0.w, dot(r1.xyz, p) + r1.w, dot(r2.xyz, p) + r2.w);
}

// Linear RGB clamped to [0, 1]; NaN or infinite gives black (hikari-bake's surfaces.rs).
fn sanitize(a: vec3<f32>) -> vec3<f32> {
    let finite = all(abs(a) <= vec3<f32>(3.4e38));
    return select(vec3<f32>(0.0), clamp(a, vec3<f32>(0.0), vec3<f32>(1.0)), finite);
}

// glam's Vec3::any_orthonormal_pair (Duff et al. 2017); the sign of -0 is -1 as in copysign.
fn orthonormal_pair(n: vec3<f32>) -> array<vec3<f32>, 2> {
    let sign = select(1.0, -1.0, (bitcast<u32>(n.z) & 0x80000000u) != 0u);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    return array<vec3<f32>, 2>(
        vec3<f32>(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x),
        vec3<f32>(b, sign + n.y * n.y * a, -n.y),
    );
}

// hikari_math::sampling::sphere::cosine_hemisphere.
fn cosine_hemisphere(u: vec2<f32>) -> vec3<f32> {
    let r = sqrt(u.x);
    let phi = 2.0 * PI * u.y;
    return vec3<f32>(r * cos(phi), r * sin(phi), sqrt(max(1.0 - u.x, 0.0)));
}

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = bake_index(gid, params);
    if i >= params.probes * params.rays_per_probe {
        return;
    }
    let m = params.bounce_rays;
    let h = hits[i];
    var surface = vec4<f32>(0.0);
    var origin = vec3<f32>(0.0);
    var normal = vec3<f32>(0.0, 0.0, 1.0);
    if h.instance != BAKE_MISS {
        let r = h.instance * INSTANCE_ROWS;
        let r0 = bitcast<vec4<f32>>(instances[r]);
        let r1 = bitcast<vec4<f32>>(instances[r + 1u]);
        let r2 = bitcast<vec4<f32>>(instances[r + 2u]);
        let info = bitcast<vec4<f32>>(instances[r + 3u]);
        let refs = instances[r + 4u];
        let t0 = refs.x + h.primitive * 3u;
        let a = to_world(r0, r1, r2, triangles[t0].xyz);
        let b = to_world(r0, r1, r2, triangles[t0 + 1u].xyz);
        let c = to_world(r0, r1, r2, triangles[t0 + 2u].xyz);
        let n_raw = cross(b - a, c - a) * info.w;
        let len = length(n_raw);
        if !(len > 1e-30) {
            surface.w = -1.0;
        } else {
            let n = n_raw / len;
            let k = i % params.rays_per_probe;
            let back = dot(n, directions[k].xyz) > 0.0;
            let double_sided = (refs.z & DOUBLE_SIDED) != 0u;
            if m > 0u && (!back || double_sided) {
                normal = select(n, -n, back);
                var rho = info.xyz;
                if refs.y != NO_COLORS {
                    let c0 = triangles[refs.y + h.primitive * 3u];
                    let c1 = triangles[refs.y + h.primitive * 3u + 1u];
                    let c2 = triangles[refs.y + h.primitive * 3u + 2u];
                    // w = 0 marks a corner without a colour: the CPU then takes white.
                    if c0.w * c1.w * c2.w > 0.0 {
                        rho = rho * (c0.xyz * (1.0 - h.u - h.v) + c1.xyz * h.u + c2.xyz * h.v);
                    }
                }
                rho = sanitize(rho);
                if any(rho != vec3<f32>(0.0)) {
                    let p = a + (b - a) * h.u + (c - a) * h.v;
                    let big = max(abs(a), max(abs(b), abs(c)));
                    let scale = max(big.x, max(big.y, big.z));
                    origin = p + normal * (params.surface_offset + params.offset_per_metre * scale);
                    surface = vec4<f32>(rho, 1.0);
                }
            }
        }
    }
    surfaces[i] = surface;
    if m == 0u {
        return;
    }
    if surface.w <= 0.0 {
        for (var j = 0u; j < m; j++) {
            bounce_rays[i * m + j] = BakeRay(vec3<f32>(0.0), 1.0, vec3<f32>(0.0, 0.0, 1.0), 0.0);
        }
        return;
    }
    let onb = orthonormal_pair(normal);
    let shift = shifts[i];
    for (var j = 0u; j < m; j++) {
        // hikari_bake::transport::bounce_sample.
        var u = vec2<f32>((f32(j) + 0.5) / f32(m), fract(f32(j) * 0.618034)) + shift;
        u = fract(u);
        let l = cosine_hemisphere(u);
        let dir = normalize(onb[0] * l.x + onb[1] * l.y + normal * l.z);
        bounce_rays[i * m + j] = BakeRay(origin, params.t_min, dir, params.far);
    }
}
