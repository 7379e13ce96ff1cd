#define_import_path hikari::octahedral

// Octahedral unit-vector encoding (Meyer et al. 2010; Cigolle et al. 2014, "A Survey of
// Efficient Representations for Independent Unit Vectors"), to [-1, 1]^2.

fn sign_not_zero(v: vec2<f32>) -> vec2<f32> {
    return select(vec2<f32>(-1.0), vec2<f32>(1.0), v >= vec2<f32>(0.0));
}

fn oct_encode(n: vec3<f32>) -> vec2<f32> {
    let p = n.xy / (abs(n.x) + abs(n.y) + abs(n.z));
    if n.z >= 0.0 {
        return p;
    }
    return (1.0 - abs(p.yx)) * sign_not_zero(p);
}

fn oct_decode(e: vec2<f32>) -> vec3<f32> {
    var v = vec3<f32>(e, 1.0 - abs(e.x) - abs(e.y));
    if v.z < 0.0 {
        v = vec3<f32>((1.0 - abs(v.yx)) * sign_not_zero(v.xy), v.z);
    }
    return normalize(v);
}
