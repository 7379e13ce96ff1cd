//! Octahedral unit-vector encoding, as `shaders/common/octahedral.wgsl`.

use glam::{Vec2, Vec3};

fn sign_not_zero(v: Vec2) -> Vec2 {
    Vec2::new(
        if v.x >= 0.0 { 1.0 } else { -1.0 },
        if v.y >= 0.0 { 1.0 } else { -1.0 },
    )
}

pub fn encode(n: Vec3) -> Vec2 {
    let p = Vec2::new(n.x, n.y) / (n.x.abs() + n.y.abs() + n.z.abs());
    if n.z >= 0.0 {
        p
    } else {
        (Vec2::ONE - Vec2::new(p.y, p.x).abs()) * sign_not_zero(p)
    }
}

pub fn decode(e: Vec2) -> Vec3 {
    let mut v = Vec3::new(e.x, e.y, 1.0 - e.x.abs() - e.y.abs());
    if v.z < 0.0 {
        let xy = (Vec2::ONE - Vec2::new(v.y, v.x).abs()) * sign_not_zero(Vec2::new(v.x, v.y));
        v = Vec3::new(xy.x, xy.y, v.z);
    }
    v.normalize()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_over_the_sphere() {
        // Fibonacci sphere: even coverage including both hemispheres and the seams.
        let n = 2000;
        for i in 0..n {
            let z = 1.0 - 2.0 * (i as f32 + 0.5) / n as f32;
            let phi = i as f32 * 2.399_963;
            let r = (1.0 - z * z).sqrt();
            let v = Vec3::new(r * phi.cos(), r * phi.sin(), z);
            let e = encode(v);
            assert!(e.abs().max_element() <= 1.0);
            assert!(decode(e).dot(v) > 1.0 - 1e-6, "{v}");
        }
    }
}
