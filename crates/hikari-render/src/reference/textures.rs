//! The scene's textures as the CPU twins sample them: what the G-buffer's resolve, the BVH's
//! cut-outs and the GI's instance albedo read on the GPU.

/// The texture images the twin samples, by scene texture index (RGBA8 as in the scene).
pub struct TwinTextures<'a> {
    pub scene: &'a hikari_scene::Scene,
}

fn srgb_to_linear(c: f64) -> f64 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// Texel index `i` (any integer) of a row of `n` texels under `mode`, as the Vulkan spec
/// addresses texels (repeat: modulo; mirrored: modulo 2n, reflected; clamp: to the edge).
pub fn address(i: i64, n: i64, mode: hikari_scene::Wrap) -> i64 {
    match mode {
        hikari_scene::Wrap::Repeat => i.rem_euclid(n),
        hikari_scene::Wrap::MirroredRepeat => {
            let m = i.rem_euclid(2 * n);
            if m >= n { 2 * n - 1 - m } else { m }
        }
        hikari_scene::Wrap::ClampToEdge => i.clamp(0, n - 1),
    }
}

impl TwinTextures<'_> {
    /// Bilinear sample of texture `index` at `uv`, sRGB-decoded when `srgb`.
    pub fn sample(&self, index: usize, uv: glam::DVec2, srgb: bool) -> glam::DVec4 {
        let t = &self.scene.textures[index];
        let (w, h) = (t.width as i64, t.height as i64);
        let u = uv.x * w as f64 - 0.5;
        let v = uv.y * h as f64 - 0.5;
        let (x0, y0) = (u.floor(), v.floor());
        let (fx, fy) = (u - x0, v - y0);
        let texel = |x: i64, y: i64| {
            let (x, y) = (address(x, w, t.wrap_s), address(y, h, t.wrap_t));
            let i = ((y * w + x) * 4) as usize;
            let c = |k: usize| {
                let b = t.data[i + k] as f64 / 255.0;
                if srgb && k < 3 { srgb_to_linear(b) } else { b }
            };
            glam::DVec4::new(c(0), c(1), c(2), c(3))
        };
        let (x0, y0) = (x0 as i64, y0 as i64);
        let top = texel(x0, y0) * (1.0 - fx) + texel(x0 + 1, y0) * fx;
        let bottom = texel(x0, y0 + 1) * (1.0 - fx) + texel(x0 + 1, y0 + 1) * fx;
        top * (1.0 - fy) + bottom * fy
    }
}
