// Compute rasteriser, pass 2: the tiles of large triangles queued by `raster/triangles.wgsl`,
// one workgroup a tile at a time; workgroups loop over the queue.

#import hikari::raster::setup::{params, queue, queue_count, id_poly, poly_rect, poly_setup, setup_depth, write_pixel, TILE_SIZE}

const THREADS: u32 = 64u;

@compute @workgroup_size(64, 1, 1)
fn main(
    @builtin(workgroup_id) wg: vec3<u32>,
    @builtin(num_workgroups) groups: vec3<u32>,
    @builtin(local_invocation_index) lane: u32,
) {
    let count = min(atomicLoad(&queue_count[0]), params.config.y);
    let size = params.viewport.xy;
    for (var e = wg.x; e < count; e += groups.x) {
        let entry = queue[e];
        let id = entry.x;
        let view = entry.y >> 24u;
        let tile = vec2<u32>(entry.y & 0xfffu, (entry.y >> 12u) & 0xfffu);
        let poly = id_poly(id, view);
        if poly.count == 0u {
            continue;
        }
        let rect = poly_rect(poly, size);
        let setup = poly_setup(poly);
        let origin = vec2<i32>(tile * TILE_SIZE);
        for (var i = lane; i < TILE_SIZE * TILE_SIZE; i += THREADS) {
            let px = origin + vec2<i32>(vec2<u32>(i % TILE_SIZE, i / TILE_SIZE));
            if any(px < rect.lo) || any(px > rect.hi) {
                continue;
            }
            let d = setup_depth(setup, vec2<f32>(px) + 0.5);
            if d > 0.0 {
                write_pixel(view, px, d, id);
            }
        }
    }
}
