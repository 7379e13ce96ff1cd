// Compute rasteriser, pass 2. `main`: the tiles queued by `raster/triangles.wgsl`, one
// workgroup a tile at a time, workgroups looping over the queue. `large`: the triangles too
// large to queue tile by tile; every workgroup takes its share of each one's tiles. Both
// read the triangles' records set up by the triangle pass.

#import hikari::raster::setup::{params, queue, queue_count, load_record, raster_tile_tri, tile_touched_tri, LARGE_CAPACITY}

const THREADS: u32 = 64u;

@compute @workgroup_size(64, 1, 1)
fn main(
    @builtin(workgroup_id) wg: vec3<u32>,
    @builtin(num_workgroups) groups: vec3<u32>,
    @builtin(local_invocation_index) lane: u32,
) {
    let count = min(atomicLoad(&queue_count[0]), params.config.y);
    for (var e = wg.x; e < count; e += groups.x) {
        let entry = queue[e];
        let r = load_record(entry.x);
        let tile = vec2<u32>(entry.y & 0xfffu, entry.y >> 12u);
        raster_tile_tri(r.tri, r.rect, tile, r.view, r.id, lane, THREADS);
    }
}

@compute @workgroup_size(64, 1, 1)
fn large(
    @builtin(workgroup_id) wg: vec3<u32>,
    @builtin(num_workgroups) groups: vec3<u32>,
    @builtin(local_invocation_index) lane: u32,
) {
    let count = min(atomicLoad(&queue_count[1]), LARGE_CAPACITY);
    // The tiles of all large triangles, one after the other, are dealt to the workgroups in
    // turn: `first_slot` is where this triangle's first tile falls in that deal. A workgroup
    // reads the records only of the triangles it draws tiles of.
    var first_slot = 0u;
    for (var e = 0u; e < count; e++) {
        let at = params.config.y + e * 2u;
        let rect_bits = queue[at + 1u];
        let t_lo = vec2<u32>(rect_bits.x & 0xffffu, rect_bits.x >> 16u);
        let t_hi = vec2<u32>(rect_bits.y & 0xffffu, rect_bits.y >> 16u);
        let span = t_hi - t_lo + 1u;
        let tiles = span.x * span.y;
        let mine = (wg.x + groups.x - first_slot) % groups.x;
        first_slot = (first_slot + tiles) % groups.x;
        if mine >= tiles {
            continue;
        }
        let r = load_record(queue[at].x);
        for (var t = mine; t < tiles; t += groups.x) {
            let tile = t_lo + vec2<u32>(t % span.x, t / span.x);
            if tile_touched_tri(r.tri, r.rect, tile) {
                raster_tile_tri(r.tri, r.rect, tile, r.view, r.id, lane, THREADS);
            }
        }
    }
}
