//! The placeholder tonemap against its CPU twin.

mod common;

use hikari_render::graph::GraphRuntime;
use hikari_render::shader::{self, ShaderLibrary};
use hikari_render::techniques::placeholder_tonemap::{self, PlaceholderTonemap, TonemapParams};
use rand::{Rng, SeedableRng, rngs::SmallRng};

#[test]
fn placeholder_tonemap_matches_its_cpu_twin() {
    let Some(ctx) = common::gpu() else { return };
    let (w, h) = (64u32, 32u32);
    let mut rng = SmallRng::seed_from_u64(7);
    let mut hdr: Vec<[f32; 4]> = (0..w * h)
        .map(|_| {
            // Log-uniform over the range a frame sees, from starlight to the sun's reflection.
            let mut c = [0f32; 4];
            for v in c.iter_mut().take(3) {
                *v = 10f32.powf(rng.random_range(-3.0..4.8));
            }
            c[3] = 1.0;
            c
        })
        .collect();
    hdr[0] = [f32::NAN, -5.0, 0.0, 1.0];
    hdr[1] = [0.0, 0.0, 0.0, 1.0];
    let halves: Vec<half::f16> = hdr
        .iter()
        .flatten()
        .map(|&v| half::f16::from_f32(v))
        .collect();
    let input = common::texture_with_data(
        &ctx,
        wgpu::TextureFormat::Rgba16Float,
        w,
        h,
        bytemuck::cast_slice(&halves),
    );

    let mut lib = ShaderLibrary::new(shader::capabilities_for(ctx.features)).unwrap();
    let tonemap = PlaceholderTonemap::new(&ctx, &mut lib).unwrap();
    let params = TonemapParams::from_ev100(12.0);
    let mut rt = GraphRuntime::new();
    let mut g = rt.begin_frame(&ctx);
    let hdr_tex = g.import_texture("test.hdr", &input);
    let ldr = tonemap.record(&mut g, hdr_tex, [w, h], &params).unwrap();
    g.readback(ldr);
    let r = g.execute().unwrap();
    let out = r.image("placeholder_tonemap.ldr").unwrap();

    let mut worst = 0i32;
    for (i, px) in halves.chunks(4).enumerate() {
        let rgb = [px[0].to_f32(), px[1].to_f32(), px[2].to_f32()];
        let want = placeholder_tonemap::reference::apply(rgb, params.exposure[0]);
        for (got, exp) in out.rgba[i].iter().zip(want) {
            let diff = (got * 255.0).round() as i32 - (exp * 255.0).round() as i32;
            worst = worst.max(diff.abs());
        }
    }
    // One 8-bit step: the GPU's pow and the rounding of the unorm store may differ by that.
    assert!(worst <= 1, "largest difference {worst} steps");
    assert_eq!(
        &out.rgba[0][..3],
        &[0.0, 0.0, 0.0],
        "NaN and negatives become black"
    );
}
