//! CPU twin of the sun shadow lookup (`techniques/sun_shadows/lookup.wgsl`): cascade selection
//! and 3x3 bilinear PCF over read-back shadow maps.

use glam::{Mat4, Vec2, Vec3};

use crate::techniques::sun_shadows::ShadowParams;

/// `origin`: where texel (0, 0) is stored; texel t is at (t + origin) mod res.
fn bilinear_lit(
    texels: &[f32],
    base: usize,
    res: i32,
    origin: [i32; 2],
    st: Vec2,
    receiver: f32,
) -> f32 {
    let p = st.floor();
    let f = st - p;
    let lit = |dx: i32, dy: i32| {
        let x = (p.x as i32 + dx + origin[0]).rem_euclid(res);
        let y = (p.y as i32 + dy + origin[1]).rem_euclid(res);
        if texels[base + (y * res + x) as usize] <= receiver {
            1.0
        } else {
            0.0
        }
    };
    let top = lit(0, 0) * (1.0 - f.x) + lit(1, 0) * f.x;
    let bottom = lit(0, 1) * (1.0 - f.x) + lit(1, 1) * f.x;
    top * (1.0 - f.y) + bottom * f.y
}

/// Sun visibility in [0, 1] at `world` with unit normal `n`; `texels` are the depths of all
/// cascades, cascade-major, each scrolled by its origin.
pub fn visibility(p: &ShadowParams, texels: &[f32], world: Vec3, n: Vec3) -> f32 {
    let cascades = p.config[0] as usize;
    let res = p.config[1];
    let spacing = p.config[2];
    let margin = (spacing + 2.0) / res;
    for c in 0..cascades {
        let q = world + n * (p.texel_world[c] * p.config[3]);
        let s = Mat4::from_cols_array_2d(&p.light_view_proj[c]) * q.extend(1.0);
        let uv = Vec2::new(s.x * 0.5 + 0.5, 0.5 - s.y * 0.5);
        if uv.cmpgt(Vec2::splat(margin)).all() && uv.cmplt(Vec2::splat(1.0 - margin)).all() {
            let receiver = s.z + p.depth_bias[c];
            let st = uv * res - 0.5;
            let base = c * (res as usize) * (res as usize);
            let origin = [(p.origin[c] & 0xffff) as i32, (p.origin[c] >> 16) as i32];
            let mut sum = 0.0;
            for y in -1..=1 {
                for x in -1..=1 {
                    let o = Vec2::new(x as f32, y as f32) * spacing;
                    sum += bilinear_lit(texels, base, res as i32, origin, st + o, receiver);
                }
            }
            return sum / 9.0;
        }
    }
    1.0
}
