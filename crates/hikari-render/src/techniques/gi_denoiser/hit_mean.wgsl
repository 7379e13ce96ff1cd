// The harmonic mean of the finite, positive hit distances over each pixel's 5x5 neighbourhood
// (0 where none hit), once a frame for both denoisers' radius caps (`hit_radius_cap` in
// common.wgsl). A 16x16 tile loads its 20x20 apron of reciprocals into workgroup memory once
// and sums them separably: five along rows, then five down columns.
// CPU twin: gi_denoiser/reference.rs `hit_mean` (which sums in the same order per row).

#import hikari::finite::is_finite_f

// This frame's hit distance in metres (0: a miss or no ray).
@group(0) @binding(0) var hit_distance_tex: texture_2d<f32>;
@group(0) @binding(1) var out_mean: texture_storage_2d<r32float, write>;

const TILE: u32 = 16u;
const WINDOW: u32 = 2u;
const APRON: u32 = TILE + 2u * WINDOW;

// (1 / d, 1) for a hit, (0, 0) otherwise, over the apron.
var<workgroup> reciprocals: array<vec2<f32>, 400>;
// Five-wide row sums: APRON rows of TILE.
var<workgroup> row_sums: array<vec2<f32>, 320>;

@compute @workgroup_size(16, 16, 1)
fn main(
    @builtin(workgroup_id) group: vec3<u32>,
    @builtin(local_invocation_index) local: u32,
) {
    let size = vec2<i32>(textureDimensions(hit_distance_tex));
    let origin = vec2<i32>(group.xy * TILE) - vec2<i32>(i32(WINDOW));
    for (var i = local; i < APRON * APRON; i += TILE * TILE) {
        let q = origin + vec2<i32>(i32(i % APRON), i32(i / APRON));
        var r = vec2<f32>(0.0);
        if all(q >= vec2<i32>(0)) && all(q < size) {
            let d = textureLoad(hit_distance_tex, q, 0).x;
            if d > 0.0 && is_finite_f(d) {
                r = vec2<f32>(1.0 / d, 1.0);
            }
        }
        reciprocals[i] = r;
    }
    workgroupBarrier();
    for (var i = local; i < APRON * TILE; i += TILE * TILE) {
        let row = i / TILE;
        let x = i % TILE;
        var sum = vec2<f32>(0.0);
        for (var dx = 0u; dx <= 2u * WINDOW; dx++) {
            sum += reciprocals[row * APRON + x + dx];
        }
        row_sums[i] = sum;
    }
    workgroupBarrier();
    let l = vec2<u32>(local % TILE, local / TILE);
    let pixel = vec2<i32>(group.xy * TILE + l);
    if any(pixel >= size) {
        return;
    }
    var sum = vec2<f32>(0.0);
    for (var dy = 0u; dy <= 2u * WINDOW; dy++) {
        sum += row_sums[(l.y + dy) * TILE + l.x];
    }
    let mean = select(0.0, sum.y / sum.x, sum.y > 0.0);
    textureStore(out_mean, pixel, vec4<f32>(mean, 0.0, 0.0, 0.0));
}
