// Compute rasteriser, pass 1: one thread a triangle. Small triangles are rasterised here by
// their thread; larger ones are split into TILE_SIZE tiles queued for `raster/tiles.wgsl`.
// Dispatch: x * y workgroups cover the chunks, z is the view.

#import hikari::raster::setup::{params, queue, queue_count, id_poly, poly_rect, poly_depth, write_pixel, TILE_SIZE, SMALL_TRIANGLE_PIXELS}
#import hikari::scene_gpu::CHUNK_TRIANGLES

@compute @workgroup_size(64, 1, 1)
fn main(
    @builtin(workgroup_id) wg: vec3<u32>,
    @builtin(num_workgroups) groups: vec3<u32>,
    @builtin(local_invocation_index) lane: u32,
) {
    let chunk = wg.y * groups.x + wg.x;
    if chunk >= params.config.w {
        return;
    }
    let view = wg.z;
    let id = chunk * CHUNK_TRIANGLES + lane;
    let poly = id_poly(id, view);
    if poly.count == 0u {
        return;
    }
    let size = params.viewport.xy;
    let rect = poly_rect(poly, size);
    let extent = rect.hi - rect.lo + 1;
    if extent.x <= 0 || extent.y <= 0 {
        return;
    }
    if extent.x * extent.y <= SMALL_TRIANGLE_PIXELS {
        for (var y = rect.lo.y; y <= rect.hi.y; y++) {
            for (var x = rect.lo.x; x <= rect.hi.x; x++) {
                let d = poly_depth(poly, vec2<f32>(f32(x), f32(y)) + 0.5);
                if d > 0.0 {
                    write_pixel(view, vec2<i32>(x, y), d, id);
                }
            }
        }
        return;
    }
    let t_lo = vec2<u32>(rect.lo) / TILE_SIZE;
    let t_hi = vec2<u32>(rect.hi) / TILE_SIZE;
    let tiles = (t_hi.x - t_lo.x + 1u) * (t_hi.y - t_lo.y + 1u);
    let first = atomicAdd(&queue_count[0], tiles);
    let capacity = params.config.y;
    for (var k = 0u; k < tiles; k++) {
        let slot = first + k;
        if slot >= capacity {
            // Overflow: queue_count keeps growing past the capacity, so a readback can tell.
            break;
        }
        let w = t_hi.x - t_lo.x + 1u;
        let t = t_lo + vec2<u32>(k % w, k / w);
        queue[slot] = vec2<u32>(id, t.x | (t.y << 12u) | (view << 24u));
    }
}
