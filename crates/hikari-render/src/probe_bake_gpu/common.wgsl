#define_import_path hikari::probe_bake

// Shared by the GPU probe bake's kernels (probe_bake_gpu/mod.rs, `BakeParams`).

struct BakeParams {
    probes: u32,
    rays_per_probe: u32,
    bounce_rays: u32,
    // Invocations per row of a 2D dispatch (workgroups along x times 64).
    row_width: u32,
    // Metres: a probe ray hitting closer counts as enclosed.
    enclosure_radius: f32,
    // Metres along a ray before which hits are ignored (hikari-bake's RAY_T_MIN).
    t_min: f32,
    // Metres a secondary ray starts off its surface, plus this per metre of the triangle's
    // largest coordinate (hikari-bake's SURFACE_OFFSET, SURFACE_OFFSET_PER_METRE).
    surface_offset: f32,
    offset_per_metre: f32,
    // +infinity, the end of every ray (a uniform, since WGSL has no infinite literal).
    far: f32,
    pad_a: u32,
    pad_b: u32,
    pad_c: u32,
}

// hikari_bvh::Ray.
struct BakeRay {
    origin: vec3<f32>,
    t_min: f32,
    dir: vec3<f32>,
    t_max: f32,
}

// hikari_bvh::Hit; a miss has instance == BAKE_MISS.
struct BakeHit {
    t: f32,
    u: f32,
    v: f32,
    primitive: u32,
    instance: u32,
    pad_a: u32,
    pad_b: u32,
    pad_c: u32,
}

const BAKE_MISS: u32 = 0xffffffffu;
const BAKE_WORKGROUP: u32 = 64u;

// Flat index of an invocation of a 2D dispatch of 64-wide workgroups.
fn bake_index(gid: vec3<u32>, params: BakeParams) -> u32 {
    return gid.x + gid.y * params.row_width;
}
