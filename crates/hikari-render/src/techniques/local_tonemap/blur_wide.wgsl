// One axis of the wide 13-tap Gaussian over the 64x32 homogeneous mean log luminance.

#import hikari::local_tonemap::{BlurParams, gaussian}

@group(0) @binding(0) var<uniform> blur: BlurParams;
@group(0) @binding(1) var src: texture_2d<f32>;
@group(0) @binding(2) var dst: texture_storage_2d<rgba32float, write>;

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = vec2<i32>(textureDimensions(src));
    let p = vec2<i32>(id.xy);
    if any(p >= size) {
        return;
    }
    var axis = vec2<i32>(0);
    axis[blur.config.x] = 1;
    let r = i32(blur.config.y);
    var sum = vec4<f32>(0.0);
    var norm = 0.0;
    for (var i = -r; i <= r; i++) {
        let w = gaussian(i, blur.sigma.x);
        norm += w;
        let q = p + axis * i;
        if all(q >= vec2<i32>(0)) && all(q < size) {
            sum += w * textureLoad(src, q, 0);
        }
    }
    textureStore(dst, id.xy, sum / norm);
}
