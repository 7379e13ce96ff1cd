// Compute rasteriser, pass 1: one thread a triangle. Small triangles are rasterised here by
// their thread; larger ones are set up into a record and split into TILE_SIZE tiles queued
// for `raster/tiles.wgsl` (`main`), and the largest are listed whole for its `large` entry
// point.
// ALPHA_TEST: the same for the chunks of cut-outs (from `limits.y` on), with the alpha test on
// every fragment; their larger triangles all go to the tile queue (none to the large list),
// counted apart in queue_count[3] as well, for the tile pass's ALPHA_TEST variant.
// Dispatch: x * y workgroups cover the chunks; each draws its chunk into every view that may
// see it.

#import hikari::raster::setup::{params, chunks, chunk_corner_outside, queue, queue_count, world_tri, view_poly, WorldTri, poly_rect, view_window, poly_setup, setup_depth, write_pixel_tested, tile_touched_tri, store_record, TILE_SIZE, SMALL_TRIANGLE_PIXELS, LARGE_TRIANGLE_TILES, LARGE_CAPACITY}
#import hikari::scene_gpu::CHUNK_TRIANGLES
#ifdef ALPHA_TEST
#import hikari::raster::setup::{alpha_tri, alpha_covers}
#endif

// Draws triangle `t` (visibility id `id`) into view `view`: small ones here, larger ones set
// up into records for the tile and large passes.
fn draw_triangle(t: WorldTri, id: u32, view: u32) {
    let poly = view_poly(t, view);
    if poly.count == 0u {
        return;
    }
    let rect = poly_rect(poly, view_window(view));
    let extent = rect.hi - rect.lo + 1;
    if extent.x <= 0 || extent.y <= 0 {
        return;
    }
    let setup = poly_setup(poly);
    if extent.x * extent.y <= SMALL_TRIANGLE_PIXELS {
#ifdef ALPHA_TEST
        let alpha = alpha_tri(id, view);
#endif
        for (var y = rect.lo.y; y <= rect.hi.y; y++) {
            for (var x = rect.lo.x; x <= rect.hi.x; x++) {
                let d = setup_depth(setup, vec2<f32>(f32(x), f32(y)) + 0.5);
#ifdef ALPHA_TEST
                if d > 0.0 && alpha_covers(alpha, vec2<i32>(x, y)) {
#else
                if d > 0.0 {
#endif
                    write_pixel_tested(view, vec2<i32>(x, y), d, id);
                }
            }
        }
        return;
    }
    let t_lo = vec2<u32>(rect.lo) / TILE_SIZE;
    let t_hi = vec2<u32>(rect.hi) / TILE_SIZE;
    let span = t_hi - t_lo + 1u;
#ifdef ALPHA_TEST
    let large = false;
#else
    let large = span.x * span.y > LARGE_TRIANGLE_TILES;
#endif
    // A quad left by near clipping becomes two records, each rasterised on its own.
    for (var k = 0u; k < setup.tris; k++) {
        var tri = setup.first;
        if k == 1u {
            tri = setup.second;
        }
        if large {
            // Every listed large triangle must have its record: the record first.
            let record = atomicAdd(&queue_count[2], 1u);
            if record >= params.limits.x {
                continue;
            }
            let slot = atomicAdd(&queue_count[1], 1u);
            if slot < LARGE_CAPACITY {
                store_record(record, tri, id, view, rect);
                // Its tile rectangle beside it, so that the large pass reads the record only
                // in the workgroups that draw some of its tiles.
                queue[params.config.y + slot * 2u] = vec2<u32>(record, view);
                queue[params.config.y + slot * 2u + 1u] = vec2<u32>(t_lo.x | (t_lo.y << 16u), t_hi.x | (t_hi.y << 16u));
            }
            continue;
        }
        // Queue only the tiles the triangle touches (thin triangles have mostly empty boxes):
        // count them, reserve the slots with one atomic, then write them.
        var touched = 0u;
        for (var ty = t_lo.y; ty <= t_hi.y; ty++) {
            for (var tx = t_lo.x; tx <= t_hi.x; tx++) {
                touched += select(0u, 1u, tile_touched_tri(tri, rect, vec2<u32>(tx, ty)));
            }
        }
        if touched == 0u {
            continue;
        }
        let record = atomicAdd(&queue_count[2], 1u);
        if record >= params.limits.x {
            continue;
        }
        store_record(record, tri, id, view, rect);
        let first = atomicAdd(&queue_count[0], touched);
#ifdef ALPHA_TEST
        atomicAdd(&queue_count[3], touched);
#endif
        let capacity = params.config.y;
        var slot = first;
        for (var ty = t_lo.y; ty <= t_hi.y; ty++) {
            for (var tx = t_lo.x; tx <= t_hi.x; tx++) {
                // Overflow: queue_count keeps growing past the capacity, so a readback can tell.
                if slot < capacity && tile_touched_tri(tri, rect, vec2<u32>(tx, ty)) {
                    queue[slot] = vec2<u32>(record, tx | (ty << 12u));
                    slot++;
                }
            }
        }
    }
}

// Per view: the frustum planes that every corner of this workgroup's chunk is outside of.
var<workgroup> chunk_outside: array<atomic<u32>, 8>;

@compute @workgroup_size(64, 1, 1)
fn main(
    @builtin(workgroup_id) wg: vec3<u32>,
    @builtin(num_workgroups) groups: vec3<u32>,
    @builtin(local_invocation_index) lane: u32,
) {
#ifdef ALPHA_TEST
    let chunk = wg.y * groups.x + wg.x + params.limits.y;
    if chunk - params.limits.y >= params.config.w {
        return;
    }
#else
    let chunk = wg.y * groups.x + wg.x;
    if chunk >= params.config.w {
        return;
    }
#endif
    let views = params.config.z;
    if lane < 8u {
        atomicStore(&chunk_outside[lane], 0x1fu);
    }
    workgroupBarrier();
    // Lane k tests corner k % 8 of the chunk's bounds in view k / 8: one transform a lane,
    // rather than all eight corners in every lane of a workgroup a view.
    if lane / 8u < views {
        atomicAnd(&chunk_outside[lane / 8u], chunk_corner_outside(chunks[chunk], lane / 8u, lane % 8u));
    }
    workgroupBarrier();
    let id = chunk * CHUNK_TRIANGLES + lane;
    var t: WorldTri;
    var fetched = false;
    for (var view = 0u; view < views; view++) {
        if atomicLoad(&chunk_outside[view]) != 0u {
            continue;
        }
        // Fetched once, for the first view that may see the chunk.
        if !fetched {
            t = world_tri(id);
            fetched = true;
        }
        if t.valid {
            draw_triangle(t, id, view);
        }
    }
}
