// Copies what the rasteriser drew this frame (whole cascades, or the strips a scrolled one
// uncovered) from its depth buffer into the lookup's texture array. Buffer and layers store a
// texel at the same wrapped place (`techniques/sun_shadows/mod.rs`), so a whole layer is copied as it
// lies, four texels a thread (on the H200 a buffer-to-texture copy command took about four
// times as long), and a strip texel by texel through the wrap-around.
// Twin: a plain copy, checked by tests/render/direct_lighting.rs through the lookup.

struct CopyParams {
    // Per region: x the layer, y the origin, z and w the first texel and the end (exclusive)
    // of its window; points packed as x | y << 16.
    regions: array<vec4<u32>, 8>,
    // x: resolution; y: number of regions.
    config: vec4<u32>,
}

@group(0) @binding(0) var<uniform> params: CopyParams;
@group(0) @binding(1) var<storage, read> texels: array<vec4<u32>>;
@group(0) @binding(2) var map: texture_storage_2d_array<r32uint, write>;

fn unpack_point(bits: u32) -> vec2<u32> {
    return vec2<u32>(bits & 0xffffu, bits >> 16u);
}

// Dispatch: res / 4 threads along x (16x16 workgroups: 1.8x faster on the H200 than 64x1 for
// whole layers), y as many rows as the largest region needs; z is the region. Thread
// (x, y) is item y * res / 4 + x: a four-texel piece of a whole layer (row by row, as the
// texels lie), or a texel of a strip.
@compute @workgroup_size(16, 16, 1)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    let res = params.config.x;
    if gid.z >= params.config.y || gid.x >= res / 4u {
        return;
    }
    let region = params.regions[gid.z];
    let layer = region.x;
    let lo = unpack_point(region.z);
    let size = unpack_point(region.w) - lo;
    let i = gid.y * (res / 4u) + gid.x;
    if all(size == vec2<u32>(res)) {
        if gid.y >= res {
            return;
        }
        let quad = texels[layer * res * res / 4u + i];
        for (var k = 0u; k < 4u; k++) {
            textureStore(map, vec2<u32>(gid.x * 4u + k, gid.y), layer, vec4<u32>(quad[k], 0u, 0u, 0u));
        }
        return;
    }
    if i >= size.x * size.y {
        return;
    }
    let texel = lo + vec2<u32>(i % size.x, i / size.x);
    let at = (texel + unpack_point(region.y)) & vec2<u32>(res - 1u);
    let flat = layer * res * res + at.y * res + at.x;
    textureStore(map, at, layer, vec4<u32>(texels[flat / 4u][flat % 4u], 0u, 0u, 0u));
}
