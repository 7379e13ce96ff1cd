#define_import_path hikari::brdf_tables

// The BRDF's directional albedo tables (hikari_math::brdf::albedo, docs/brdf.md), as the
// binding set `brdf_tables` (`BrdfTables::binding_set` in hikari-render): one read-only
// storage buffer of vec2, uploaded once from `AlbedoTables::gpu_data`.
//
// Single-scattering directional albedo of the GGX lobe (height-correlated Smith):
// .x = E (F = 1), .y = E_w (F = (1 - v.h)^5). Row j: perceptual roughness
// r_min + (1 - r_min) (j / (N - 1))^2, r_min = BRDF_MIN_PERCEPTUAL_ROUGHNESS;
// column i: x = i / (N - 1) with n.v = x^2, at j * N + i. Then the cosine-weighted
// hemispherical averages (.x = E_avg, .y = E_w,avg) at N * N + j.
const BRDF_TABLE_SIZE: u32 = 32u;

@group(#{BRDF_TABLES_GROUP}) @binding(0) var<storage, read> brdf_table_data: array<vec2<f32>>;
// The N x N (E, E_w) part again as a texture (x: column i, y: row j), read with the sampler's
// bilinear filter: one fetch where the light loop would otherwise load four entries.
@group(#{BRDF_TABLES_GROUP}) @binding(1) var brdf_albedo_texture: texture_2d<f32>;
@group(#{BRDF_TABLES_GROUP}) @binding(2) var brdf_albedo_sampler: sampler;

// (E, E_w) at continuous table coordinates: column p in [0, N - 1], row q in [0, N - 1].
fn brdf_table_albedo_filtered(p: f32, q: f32) -> vec2<f32> {
    let uv = (vec2<f32>(p, q) + 0.5) / f32(BRDF_TABLE_SIZE);
    return textureSampleLevel(brdf_albedo_texture, brdf_albedo_sampler, uv, 0.0).xy;
}

fn brdf_table_albedo(k: u32) -> vec2<f32> {
    return brdf_table_data[k];
}

fn brdf_table_average(j: u32) -> vec2<f32> {
    return brdf_table_data[BRDF_TABLE_SIZE * BRDF_TABLE_SIZE + j];
}
