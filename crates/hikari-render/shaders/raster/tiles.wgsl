// Compute rasteriser, pass 2. `main`: the tiles queued by `raster/triangles.wgsl`, one
// workgroup a tile at a time, workgroups looping over the queue. `large`: the triangles too
// large to queue tile by tile; every workgroup takes its share of each one's tiles.

#import hikari::raster::setup::{params, queue, queue_count, id_poly, poly_rect, poly_setup, raster_tile, tile_touched, TILE_SIZE, LARGE_CAPACITY}

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
        raster_tile(poly_setup(poly), poly_rect(poly, size), tile, view, id, lane, THREADS);
    }
}

@compute @workgroup_size(64, 1, 1)
fn large(
    @builtin(workgroup_id) wg: vec3<u32>,
    @builtin(num_workgroups) groups: vec3<u32>,
    @builtin(local_invocation_index) lane: u32,
) {
    let count = min(atomicLoad(&queue_count[1]), LARGE_CAPACITY);
    let size = params.viewport.xy;
    for (var e = 0u; e < count; e++) {
        let entry = queue[params.config.y + e];
        let id = entry.x;
        let view = entry.y;
        let poly = id_poly(id, view);
        if poly.count == 0u {
            continue;
        }
        let rect = poly_rect(poly, size);
        let setup = poly_setup(poly);
        let t_lo = vec2<u32>(rect.lo) / TILE_SIZE;
        let t_hi = vec2<u32>(rect.hi) / TILE_SIZE;
        let span = t_hi - t_lo + 1u;
        for (var t = wg.x; t < span.x * span.y; t += groups.x) {
            let tile = t_lo + vec2<u32>(t % span.x, t / span.x);
            if tile_touched(setup, rect, tile) {
                raster_tile(setup, rect, tile, view, id, lane, THREADS);
            }
        }
    }
}
