//! BC6H: the GPU encoder against its CPU twin block for block, the blocks read by an
//! independent decoder (bcdec_rs) as the encoder meant them, and the error on HDR images within
//! what the format's 10-bit endpoints allow.

use hikari_render::bc6h::{self, Bc6hEncoder, Quality, reference};
use rand::rngs::SmallRng;
use rand::{Rng, SeedableRng};

use crate::common;

/// An HDR test image of values a half holds exactly (so the GPU's conversion has nothing to
/// round): smooth gradients over five decades; with `specials`, coloured noise, black and a
/// few texels past what the format holds (negative, NaN, infinite).
fn image(w: u32, h: u32, seed: u64, specials: bool) -> Vec<[f32; 3]> {
    let mut rng = SmallRng::seed_from_u64(seed);
    (0..w * h)
        .map(|k| {
            // Without `specials` the colour changes along rows only within a block (y is taken
            // at the block's top): each block's colours lie on a line, as the mode assumes.
            let row = if specials { k / w } else { k / w / 4 * 4 };
            let (x, y) = ((k % w) as f32 / w as f32, row as f32 / h as f32);
            let base = 10f32.powf(-2.0 + 5.0 * x);
            // Noise only with `specials`: colours off any line are the single-subset mode's
            // worst case, which the twin tests want and the error bound does not.
            let noise = |rng: &mut SmallRng, lo: f32| {
                if specials {
                    rng.random_range(lo..1.0)
                } else {
                    1.0
                }
            };
            let mut c = [
                base * (0.5 + y),
                base * (1.5 - y) * noise(&mut rng, 0.8),
                base * (0.6 + 0.4 * (7.0 * x + 3.0 * y).sin()) * noise(&mut rng, 0.2),
            ];
            match if specials { k % 53 } else { 0 } {
                7 => c = [0.0; 3],
                11 => c[0] = -1.0,
                13 => c[1] = f32::NAN,
                17 => c[2] = f32::INFINITY,
                _ => {}
            }
            c.map(|v| half::f16::from_f32(v).to_f32())
        })
        .collect()
}

#[test]
fn the_gpu_encoder_writes_the_cpu_twins_blocks_exactly() {
    let ctx = common::gpu_context();
    let enc = Bc6hEncoder::new(&ctx).unwrap();
    for (w, h, quality) in [(16, 12, Quality::Fast), (13, 10, Quality::High)] {
        let img = image(w, h, u64::from(w), true);
        let gpu = enc.encode_rgb(&ctx, &img, w, h, quality).unwrap();
        let cpu = reference::encode_image(&img, w, h, quality);
        assert_eq!(gpu.len(), cpu.len());
        let differ = gpu
            .chunks(16)
            .zip(cpu.chunks(16))
            .filter(|(a, b)| a != b)
            .count();
        assert_eq!(differ, 0, "{w}x{h} {quality:?}: {differ} blocks differ");
    }
}

#[test]
fn an_independent_decoder_reads_the_blocks_as_the_encoder_meant() {
    let (w, h) = (24, 16);
    let img = image(w, h, 3, true);
    for quality in [Quality::Fast, Quality::High] {
        let blocks = reference::encode_image(&img, w, h, quality);
        let ours = bc6h::decode_image(&blocks, w, h).unwrap();
        let bx = w.div_ceil(4) as usize;
        for (k, block) in blocks.chunks(16).enumerate() {
            let mut theirs = [0.0f32; 48];
            bcdec_rs::bc6h_float(block, &mut theirs, 12, false);
            for t in 0..16 {
                let (x, y) = ((k % bx) * 4 + t % 4, (k / bx) * 4 + t / 4);
                let ours = ours[y * w as usize + x];
                let theirs = [theirs[3 * t], theirs[3 * t + 1], theirs[3 * t + 2]];
                assert_eq!(ours, theirs, "block {k} texel {t} ({quality:?})");
            }
        }
    }
}

/// BC6H's 10-bit endpoints step 31 half-float codes apart, about 3 % in value (a half's
/// 10-bit mantissa): a smooth block's colours land within about half a step, 0.02 in log2,
/// and the 4-bit interpolation between them adds as much again. 0.05 bounds the RMS.
#[test]
fn the_error_on_hdr_images_is_within_the_formats_steps_and_high_is_no_worse() {
    let (w, h) = (64, 32);
    let img = image(w, h, 9, false);
    let err = |q| {
        let blocks = reference::encode_image(&img, w, h, q);
        bc6h::error(&img, &bc6h::decode_image(&blocks, w, h).unwrap())
    };
    let (fast, high) = (err(Quality::Fast), err(Quality::High));
    eprintln!("fast {fast:?}\nhigh {high:?}");
    assert!(fast.rms_log2 < 0.05, "{fast:?}");
    assert!(high.rms_log2 <= fast.rms_log2, "{high:?} vs {fast:?}");
    assert!(fast.mean_relative < 0.05, "{fast:?}");
}
