// One axis of the grid's separable Gaussian. The values are homogeneous, so outside the grid
// counts as empty (zero) and the normalisation at lookup accounts for it.

#import hikari::local_tonemap::{BlurParams, gaussian}

@group(0) @binding(0) var<uniform> blur: BlurParams;
@group(0) @binding(1) var src: texture_3d<f32>;
@group(0) @binding(2) var dst: texture_storage_3d<rgba32float, write>;

@compute @workgroup_size(4, 4, 4)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = vec3<i32>(textureDimensions(src));
    let p = vec3<i32>(id);
    if any(p >= size) {
        return;
    }
    var axis = vec3<i32>(0);
    axis[blur.config.x] = 1;
    let r = i32(blur.config.y);
    var sum = vec4<f32>(0.0);
    var norm = 0.0;
    for (var i = -r; i <= r; i++) {
        let w = gaussian(i, blur.sigma.x);
        norm += w;
        let q = p + axis * i;
        if all(q >= vec3<i32>(0)) && all(q < size) {
            sum += w * textureLoad(src, q, 0);
        }
    }
    textureStore(dst, id, sum / norm);
}
