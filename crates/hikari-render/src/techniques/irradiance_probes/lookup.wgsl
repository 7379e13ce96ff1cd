#define_import_path hikari::irradiance_probes

// Irradiance from the relit probes at a surface point: the tetrahedral mesh that holds the
// point (found by walking adjacency from the tetrahedron of the mesh's start grid nearest the
// point), blended with the grid over PROBE_BLEND_MARGIN metres inside the mesh's bounds (the
// mesh's weight falls linearly to 0 at the bounds), else the grid (bilinear over columns,
// linear between layers); probe weights scaled by the interior mask
// (w for interior probes, 1 - w for exterior ones) and renormalised, or left as they are when
// that leaves nothing. Binding set `irradiance_probes` (`ProbesFrame::lookup`); layout of the
// buffers in gpu_data.rs. CPU twin: reference::irradiance_at.

struct ProbeLookupParams {
    // World x, z of grid column (0, 0), metres; spacing, metres; ambient diffuse scale.
    grid: vec4<f32>,
    // Grid columns along x and z, tiles along x, PROBES_* flags.
    grid_size: vec4<u32>,
    // Meshes; word offsets in probe_topology of the tetrahedra, adjacency and meshes.
    topology: vec4<u32>,
}

@group(#{IRRADIANCE_PROBES_GROUP}) @binding(0) var<uniform> probe_params: ProbeLookupParams;
// 9 per probe: irradiance SH (rgb), lux.
@group(#{IRRADIANCE_PROBES_GROUP}) @binding(1) var<storage, read> probe_irradiance: array<vec4<f32>>;
// Per probe: position (metres), 1 for interior probes.
@group(#{IRRADIANCE_PROBES_GROUP}) @binding(2) var<storage, read> probe_positions: array<vec4<f32>>;
@group(#{IRRADIANCE_PROBES_GROUP}) @binding(3) var<storage, read> probe_topology: array<u32>;

const PROBES_PRESENT: u32 = 1u;
const PROBES_GRID: u32 = 2u;
const PROBES_INTERIOR_MASK: u32 = 4u;
const PROBE_NONE: u32 = 0xffffffffu;
const PROBE_TILE_SIDE: u32 = 16u;
const PROBE_COLUMNS: u32 = 256u;
const PROBE_MAX_WALK: u32 = 256u;
const PROBE_INSIDE_EPSILON: f32 = 1e-5;
// reference::BLEND_MARGIN_M and gpu_data::START_CELLS.
const PROBE_BLEND_MARGIN: f32 = 1.0;
const PROBE_START_CELLS: f32 = 4.0;

// Weighted sums of probe irradiance, with and without the interior mask.
struct ProbeSum {
    masked: vec3<f32>,
    masked_w: f32,
    plain: vec3<f32>,
    plain_w: f32,
}

// The band-2 zonal term is written 3 z^2 - |n|^2 (equal to 3 z^2 - 1 on the unit sphere), so
// that n = 0 leaves the constant term alone: the irradiance averaged over every normal.
fn probe_eval(probe: u32, n: vec3<f32>) -> vec3<f32> {
    let b = probe * 9u;
    return 0.28209479177387814 * probe_irradiance[b].xyz
        + 0.4886025119029199 * (probe_irradiance[b + 1u].xyz * n.y + probe_irradiance[b + 2u].xyz * n.z + probe_irradiance[b + 3u].xyz * n.x)
        + 1.0925484305920792 * (probe_irradiance[b + 4u].xyz * (n.x * n.y) + probe_irradiance[b + 5u].xyz * (n.y * n.z) + probe_irradiance[b + 7u].xyz * (n.x * n.z))
        + 0.31539156525252005 * probe_irradiance[b + 6u].xyz * (3.0 * n.z * n.z - dot(n, n))
        + 0.5462742152960396 * probe_irradiance[b + 8u].xyz * (n.x * n.x - n.y * n.y);
}

fn probe_add(s: ProbeSum, probe: u32, w: f32, n: vec3<f32>, mask: f32) -> ProbeSum {
    var out = s;
    if w <= 0.0 {
        return out;
    }
    let e = probe_eval(probe, n);
    let wm = w * select(1.0 - mask, mask, probe_positions[probe].w > 0.5);
    out.plain += e * w;
    out.plain_w += w;
    out.masked += e * wm;
    out.masked_w += wm;
    return out;
}

// The masked, renormalised mean of a sum; the plain one where the mask leaves nothing; 0 for
// an empty sum.
fn probe_resolve(s: ProbeSum) -> vec3<f32> {
    if s.plain_w <= 0.0 {
        return vec3<f32>(0.0);
    }
    return select(s.plain / s.plain_w, s.masked / s.masked_w, s.masked_w > 1e-6);
}

fn probe_position(probe: u32) -> vec3<f32> {
    return probe_positions[probe].xyz;
}

// Barycentrics of p in tetrahedron t; all -1 for a degenerate one.
fn probe_barycentrics(t: u32, p: vec3<f32>) -> vec4<f32> {
    let o = probe_params.topology.y + 4u * t;
    let v3 = probe_position(probe_topology[o + 3u]);
    let a = probe_position(probe_topology[o]) - v3;
    let b = probe_position(probe_topology[o + 1u]) - v3;
    let c = probe_position(probe_topology[o + 2u]) - v3;
    let q = p - v3;
    let det = dot(a, cross(b, c));
    if abs(det) < 1e-12 {
        return vec4<f32>(-1.0, 0.0, 0.0, 0.0);
    }
    let b0 = dot(q, cross(b, c)) / det;
    let b1 = dot(a, cross(q, c)) / det;
    let b2 = dot(a, cross(b, q)) / det;
    return vec4<f32>(b0, b1, b2, 1.0 - b0 - b1 - b2);
}

// Adds mesh m's probes around p to s; returns the mesh's blend weight (1 without a grid), or -1
// when the mesh does not hold p.
fn probe_mesh_sum(m: u32, p: vec3<f32>, n: vec3<f32>, mask: f32, has_grid: bool, s: ptr<function, ProbeSum>) -> f32 {
    let mo = probe_params.topology.w + 12u * m;
    let lo = vec3<f32>(bitcast<f32>(probe_topology[mo]), bitcast<f32>(probe_topology[mo + 1u]), bitcast<f32>(probe_topology[mo + 2u]));
    let hi = vec3<f32>(bitcast<f32>(probe_topology[mo + 3u]), bitcast<f32>(probe_topology[mo + 4u]), bitcast<f32>(probe_topology[mo + 5u]));
    if probe_topology[mo + 7u] == 0u || any(p < lo) || any(p > hi) {
        return -1.0;
    }
    let cell = vec3<u32>(clamp((p - lo) / max(hi - lo, vec3<f32>(1e-6)) * PROBE_START_CELLS, vec3<f32>(0.0), vec3<f32>(PROBE_START_CELLS - 1.0)));
    let cells = u32(PROBE_START_CELLS);
    var t = probe_topology[probe_topology[mo + 10u] + cell.x + cells * (cell.y + cells * cell.z)];
    let d = min(p - lo, hi - p);
    let a = select(1.0, clamp(min(d.x, min(d.y, d.z)) / PROBE_BLEND_MARGIN, 0.0, 1.0), has_grid);
    for (var step = 0u; step < PROBE_MAX_WALK; step++) {
        let b = probe_barycentrics(t, p);
        // The first smallest coordinate, as the twin picks it.
        var k = 0u;
        var mn = b.x;
        if b.y < mn { k = 1u; mn = b.y; }
        if b.z < mn { k = 2u; mn = b.z; }
        if b.w < mn { k = 3u; mn = b.w; }
        if mn >= -PROBE_INSIDE_EPSILON {
            let o = probe_params.topology.y + 4u * t;
            var acc = *s;
            acc = probe_add(acc, probe_topology[o], max(b.x, 0.0), n, mask);
            acc = probe_add(acc, probe_topology[o + 1u], max(b.y, 0.0), n, mask);
            acc = probe_add(acc, probe_topology[o + 2u], max(b.z, 0.0), n, mask);
            acc = probe_add(acc, probe_topology[o + 3u], max(b.w, 0.0), n, mask);
            *s = acc;
            return a;
        }
        let next = probe_topology[probe_params.topology.z + 4u * t + k];
        if next == PROBE_NONE {
            return -1.0;
        }
        t = next;
    }
    return -1.0;
}

// Adds the grid's probes around p to s, their weights times `scale`.
fn probe_grid_sum(p: vec3<f32>, n: vec3<f32>, mask: f32, scale: f32, acc: ptr<function, ProbeSum>) {
    var s = *acc;
    let cols = vec2<f32>(probe_params.grid_size.xy);
    let g = (p.xz - probe_params.grid.xy) / probe_params.grid.z;
    let gc = clamp(g, vec2<f32>(0.0), cols - 1.0);
    let i0 = vec2<u32>(min(floor(gc), max(cols - 2.0, vec2<f32>(0.0))));
    let f = clamp(gc - vec2<f32>(i0), vec2<f32>(0.0), vec2<f32>(1.0));
    for (var c = 0u; c < 4u; c++) {
        let ci = i0 + vec2<u32>(c & 1u, c >> 1u);
        if ci.x >= probe_params.grid_size.x || ci.y >= probe_params.grid_size.y {
            continue;
        }
        let wx = select(1.0 - f.x, f.x, (c & 1u) == 1u);
        let wz = select(1.0 - f.y, f.y, (c >> 1u) == 1u);
        let tile = probe_topology[(ci.y / PROBE_TILE_SIDE) * probe_params.grid_size.z + ci.x / PROBE_TILE_SIDE];
        if tile == PROBE_NONE {
            continue;
        }
        let col = tile + (ci.y % PROBE_TILE_SIDE) * PROBE_TILE_SIDE + ci.x % PROBE_TILE_SIDE;
        let h1 = probe_positions[col + PROBE_COLUMNS].y;
        let upper = select(0u, 1u, p.y > h1);
        let ha = probe_positions[col + upper * PROBE_COLUMNS].y;
        let hb = probe_positions[col + (upper + 1u) * PROBE_COLUMNS].y;
        let t = clamp((p.y - ha) / max(hb - ha, 1e-4), 0.0, 1.0);
        let base = col + upper * PROBE_COLUMNS;
        s = probe_add(s, base, wx * wz * (1.0 - t) * scale, n, mask);
        s = probe_add(s, base + PROBE_COLUMNS, wx * wz * t * scale, n, mask);
    }
    *acc = s;
}

// Irradiance (lux, rgb) at world position p on a surface with unit normal n and interior mask
// `interior` (the G-buffer's albedo.a); w: 1 where probes cover p, else 0 (and rgb 0). With
// n = 0: the irradiance averaged over every normal (reference::average_irradiance_at).
fn probe_irradiance_at(p: vec3<f32>, n: vec3<f32>, interior: f32) -> vec4<f32> {
    let flags = probe_params.grid_size.w;
    if (flags & PROBES_PRESENT) == 0u {
        return vec4<f32>(0.0);
    }
    let mask = select(0.5, clamp(interior, 0.0, 1.0), (flags & PROBES_INTERIOR_MASK) != 0u);
    // The mesh's and the grid's sums are masked and renormalised each on its own, then
    // blended: continuous across the mesh's bounds whatever the mask (reference::blended_weights).
    var ms = ProbeSum(vec3<f32>(0.0), 0.0, vec3<f32>(0.0), 0.0);
    var gs = ProbeSum(vec3<f32>(0.0), 0.0, vec3<f32>(0.0), 0.0);
    let has_grid = (flags & PROBES_GRID) != 0u;
    var a = -1.0;
    for (var m = 0u; m < probe_params.topology.x && a < 0.0; m++) {
        a = probe_mesh_sum(m, p, n, mask, has_grid, &ms);
    }
    if a < 1.0 && has_grid {
        probe_grid_sum(p, n, mask, 1.0, &gs);
    }
    if gs.plain_w <= 0.0 {
        a = select(a, 1.0, a >= 0.0);
    }
    a = max(a, 0.0);
    let covered = (a > 0.0 && ms.plain_w > 0.0) || (a < 1.0 && gs.plain_w > 0.0);
    if !covered {
        return vec4<f32>(0.0);
    }
    let e = a * probe_resolve(ms) + (1.0 - a) * probe_resolve(gs);
    return vec4<f32>(max(e, vec3<f32>(0.0)) * probe_params.grid.w, 1.0);
}
