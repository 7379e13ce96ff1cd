// Compute rasteriser: clears the windows of views that draw part of their target (the strips
// a scrolled shadow cascade uncovers); whole views are cleared by the copy engine.
// Dispatch: x * y workgroups of 256 threads cover the largest window, z is the view.

#import hikari::raster::setup::{params, target_texels, texel_index, view_window}

@compute @workgroup_size(256, 1, 1)
fn main(
    @builtin(global_invocation_id) gid: vec3<u32>,
    @builtin(num_workgroups) groups: vec3<u32>,
) {
    let view = gid.z;
    let win = view_window(view);
    let size = win.hi - win.lo + 1;
    if all(size == vec2<i32>(params.viewport.xy)) {
        return;
    }
    let i = gid.y * groups.x * 256u + gid.x;
    if i >= u32(size.x * size.y) {
        return;
    }
    let px = win.lo + vec2<i32>(i32(i % u32(size.x)), i32(i / u32(size.x)));
#ifdef DEPTH_ONLY
    atomicStore(&target_texels[texel_index(view, px)], 0u);
#else
    atomicStore(&target_texels[texel_index(view, px)], 0lu);
#endif
}
