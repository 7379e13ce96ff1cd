// Compute rasteriser, pass 2. `main`: the tiles queued by `raster/triangles.wgsl`, one
// workgroup a tile at a time, workgroups looping over the queue. `large`: the triangles too
// large to queue tile by tile; every workgroup takes its share of each one's tiles. Both
// read the triangles' records set up by the triangle pass.
// ALPHA_TEST (`main` only): the entries of the alpha-tested triangles, which the triangle pass's
// ALPHA_TEST variant queued after every other entry (it runs after this pass's plain variant):
// the last queue_count[3] of the queue_count[0] entries. Each entry fetches its triangle again
// for the alpha test (`alpha_tri`).

#import hikari::raster::setup::{params, queue, queue_count, load_record, raster_tile_tri, raster_block_pixel, block_corner, block_touched, tile_touched_tri, TILE_SIZE, BLOCKS_PER_SIDE, LARGE_CAPACITY}
#ifdef ALPHA_TEST
#import hikari::raster::setup::{alpha_tri, raster_block_pixel_alpha}
#endif

var<workgroup> entry_count: u32;
#ifdef ALPHA_TEST
var<workgroup> entry_first: u32;
#endif
// Which blocks the current entry touches. Three masks in turn: iteration i sets mask i % 3,
// reads it after the barrier, and clears mask (i + 1) % 3, whose last readers passed the
// previous iteration's barrier and whose next writers wait for this one's.
var<workgroup> block_masks: array<atomic<u32>, 3>;

@compute @workgroup_size(64, 1, 1)
fn main(
    @builtin(workgroup_id) wg: vec3<u32>,
    @builtin(num_workgroups) groups: vec3<u32>,
    @builtin(local_invocation_index) lane: u32,
) {
    if lane == 0u {
#ifdef ALPHA_TEST
        let queued = atomicLoad(&queue_count[0]);
        entry_first = queued - min(atomicLoad(&queue_count[3]), queued);
        entry_count = min(queued, params.config.y);
#else
        entry_count = min(atomicLoad(&queue_count[0]), params.config.y);
#endif
        for (var k = 0u; k < 3u; k++) {
            atomicStore(&block_masks[k], 0u);
        }
    }
    let count = workgroupUniformLoad(&entry_count);
#ifdef ALPHA_TEST
    let first = workgroupUniformLoad(&entry_first);
#else
    let first = 0u;
#endif
    var slot = 0u;
    for (var e = first + wg.x; e < count; e += groups.x) {
        let entry = queue[e];
        let r = load_record(entry.x);
#ifdef ALPHA_TEST
        let alpha = alpha_tri(r.id, r.view);
#endif
        let origin = vec2<i32>(vec2<u32>(entry.y & 0xfffu, entry.y >> 12u) * TILE_SIZE);
        let next = (slot + 1u) % 3u;
        if lane == 0u {
            atomicStore(&block_masks[next], 0u);
        }
        // The 16 block tests shared out: one lane each, rather than each lane all 16.
        if lane < BLOCKS_PER_SIDE * BLOCKS_PER_SIDE && block_touched(r.tri, r.rect, block_corner(origin, lane)) {
            atomicOr(&block_masks[slot], 1u << lane);
        }
        workgroupBarrier();
        var blocks = atomicLoad(&block_masks[slot]);
        slot = next;
        while blocks != 0u {
            let b = firstTrailingBit(blocks);
            blocks &= blocks - 1u;
#ifdef ALPHA_TEST
            raster_block_pixel_alpha(r.tri, r.rect, block_corner(origin, b), lane, r.view, r.id, alpha);
#else
            raster_block_pixel(r.tri, r.rect, block_corner(origin, b), lane, r.view, r.id);
#endif
        }
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
                raster_tile_tri(r.tri, r.rect, tile, r.view, r.id, lane, 64u);
            }
        }
    }
}
