//! The BC6H encoder on the CPU: the twin of `encode.wgsl`, integer for integer, so the two
//! agree block for block. One mode, the single-subset 10-bit one (mode 11 in D3D's numbering:
//! two endpoints stored whole, 16 four-bit indices), as Narkowicz's real-time encoder uses:
//! endpoints from the block's bounding box in half-float bit space (where BC6H interpolates,
//! close to logarithmic), each channel's diagonal turned to follow the block's brightness, and
//! each texel's index the nearest of the 16 interpolated colours. `Quality::High` also tries
//! the box inset by 1/32 and 1/16 of its extent and keeps the block with the least error.

/// BC6H's 4-bit interpolation weights, out of 64.
pub const WEIGHTS: [u32; 16] = [0, 4, 9, 13, 17, 21, 26, 30, 34, 38, 43, 47, 51, 55, 60, 64];
/// The largest finite half, as bits: what BC6H_UF16 holds at most.
pub const MAX_HALF_BITS: u32 = 0x7bff;
/// Bytes of one 4x4 block.
pub const BLOCK_BYTES: usize = 16;

#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Quality {
    /// The bounding box as it is.
    #[default]
    Fast,
    /// The best of the box and two insets.
    High,
}

impl std::str::FromStr for Quality {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "fast" => Ok(Self::Fast),
            "high" => Ok(Self::High),
            _ => Err(format!("quality `{s}`: fast or high")),
        }
    }
}

/// A channel value as BC6H_UF16 stores it, in half-float bits: negative values and NaN become
/// 0 (the format has no sign), values past the largest half become it.
pub fn half_bits(x: f32) -> u32 {
    if x > 0.0 {
        u32::from(half::f16::from_f32(x.min(65504.0)).to_bits()).min(MAX_HALF_BITS)
    } else {
        0
    }
}

/// A 10-bit endpoint's value in the 16-bit space BC6H interpolates in.
fn unquantize(q: u32) -> u32 {
    match q {
        0 => 0,
        1023 => 0xffff,
        q => q * 64 + 32,
    }
}

/// The 10-bit endpoint whose value is nearest half bits `h`. `h * 64 / 31` is its place in
/// the interpolation space and the endpoints sit at `q * 64 + 32`, so `h / 31` is nearest but
/// at the ends, where 0 and 1023 stand for 0 and 0xffff: its neighbours are compared too (in
/// the space scaled by 31, exactly; a tie keeps the lower).
pub fn quantize(h: u32) -> u32 {
    let q = (h / 31).min(1023);
    let distance = |q: u32| (unquantize(q) * 31).abs_diff(h * 64);
    let mut best = q;
    for c in [q.saturating_sub(1), (q + 1).min(1023)] {
        if distance(c) < distance(best) || (distance(c) == distance(best) && c < best) {
            best = c;
        }
    }
    best
}

/// The colour index `i` decodes to between quantized endpoints `q0` and `q1`, half bits.
pub fn palette(q0: [u32; 3], q1: [u32; 3], i: usize) -> [u32; 3] {
    let w = WEIGHTS[i];
    std::array::from_fn(|c| {
        let v = (unquantize(q0[c]) * (64 - w) + unquantize(q1[c]) * w + 32) >> 6;
        (v * 31) >> 6
    })
}

fn error(a: [u32; 3], b: [u32; 3]) -> u32 {
    (0..3)
        .map(|c| {
            let d = a[c].abs_diff(b[c]);
            d * d
        })
        .fold(0u32, u32::saturating_add)
}

/// One encoded block: endpoints, indices and the summed squared error in half bits.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Block {
    pub q0: [u32; 3],
    pub q1: [u32; 3],
    pub indices: [u32; 16],
    pub error: u32,
}

/// The block with endpoints `e0`, `e1` (half bits) for `texels`.
fn fit(texels: &[[u32; 3]; 16], e0: [u32; 3], e1: [u32; 3]) -> Block {
    let q0 = e0.map(quantize);
    let q1 = e1.map(quantize);
    let colours: [[u32; 3]; 16] = std::array::from_fn(|i| palette(q0, q1, i));
    let mut indices = [0u32; 16];
    let mut total = 0u32;
    for (t, texel) in texels.iter().enumerate() {
        let mut best = (u32::MAX, 0u32);
        for (i, c) in colours.iter().enumerate() {
            let e = error(*c, *texel);
            if e < best.0 {
                best = (e, i as u32);
            }
        }
        indices[t] = best.1;
        total = total.saturating_add(best.0);
    }
    // The first texel's index is stored in 3 bits: its top bit must be 0. The palette read
    // backwards with the endpoints swapped is the same palette.
    if indices[0] >= 8 {
        return Block {
            q0: q1,
            q1: q0,
            indices: indices.map(|i| 15 - i),
            error: total,
        };
    }
    Block {
        q0,
        q1,
        indices,
        error: total,
    }
}

/// Encodes one block of 16 texels (row by row, half bits).
pub fn encode_block(texels: &[[u32; 3]; 16], quality: Quality) -> Block {
    let mut lo = [u32::MAX; 3];
    let mut hi = [0u32; 3];
    for t in texels {
        for c in 0..3 {
            lo[c] = lo[c].min(t[c]);
            hi[c] = hi[c].max(t[c]);
        }
    }
    // Each channel's diagonal follows the block's brightness: a channel that falls where the
    // sum rises runs from its maximum to its minimum. Integer covariance on values shifted to
    // 10 and 12 bits, which keeps every sum inside i32 on the GPU.
    let sums: [i32; 3] = std::array::from_fn(|c| texels.iter().map(|t| (t[c] >> 5) as i32).sum());
    let brightness = |t: &[u32; 3]| ((t[0] + t[1] + t[2]) >> 5) as i32;
    let s_sum: i32 = texels.iter().map(brightness).sum();
    let flip: [bool; 3] = std::array::from_fn(|c| {
        let xs: i32 = texels
            .iter()
            .map(|t| (t[c] >> 5) as i32 * brightness(t))
            .sum();
        16 * xs - sums[c] * s_sum < 0
    });
    let ends = |inset_shift: Option<u32>| {
        let mut e0 = [0u32; 3];
        let mut e1 = [0u32; 3];
        for c in 0..3 {
            let d = inset_shift.map_or(0, |k| (hi[c] - lo[c]) >> k);
            let (a, b) = (lo[c] + d, hi[c] - d);
            (e0[c], e1[c]) = if flip[c] { (b, a) } else { (a, b) };
        }
        (e0, e1)
    };
    let (e0, e1) = ends(None);
    let mut best = fit(texels, e0, e1);
    if quality == Quality::High {
        for k in [5, 4] {
            let (e0, e1) = ends(Some(k));
            let b = fit(texels, e0, e1);
            if b.error < best.error {
                best = b;
            }
        }
    }
    best
}

/// Writes `n` bits of `v` at bit `pos` (from bit 0 of byte 0).
fn put(bits: &mut u128, pos: u32, n: u32, v: u32) {
    *bits |= u128::from(v & ((1u32 << n) - 1)) << pos;
}

/// The block's 16 bytes: mode 0b00011 (5 bits), the endpoints' 10 bits each (r0, g0, b0, r1,
/// g1, b1), the first index in 3 bits and the other 15 in 4.
pub fn pack(b: &Block) -> [u8; 16] {
    let mut bits = 0u128;
    put(&mut bits, 0, 5, 0b00011);
    let mut pos = 5;
    for q in [b.q0, b.q1] {
        for v in q {
            put(&mut bits, pos, 10, v);
            pos += 10;
        }
    }
    put(&mut bits, pos, 3, b.indices[0]);
    pos += 3;
    for &i in &b.indices[1..] {
        put(&mut bits, pos, 4, i);
        pos += 4;
    }
    debug_assert_eq!(pos, 128);
    bits.to_le_bytes()
}

/// Reads back a block this encoder wrote (mode 0b00011 only): the 16 texels' half bits.
pub fn decode(bytes: &[u8; 16]) -> Option<[[u32; 3]; 16]> {
    let bits = u128::from_le_bytes(*bytes);
    let get = |pos: u32, n: u32| ((bits >> pos) as u32) & ((1u32 << n) - 1);
    if get(0, 5) != 0b00011 {
        return None;
    }
    let q: [u32; 6] = std::array::from_fn(|k| get(5 + 10 * k as u32, 10));
    let (q0, q1) = ([q[0], q[1], q[2]], [q[3], q[4], q[5]]);
    Some(std::array::from_fn(|t| {
        let i = if t == 0 {
            get(65, 3)
        } else {
            get(68 + 4 * (t as u32 - 1), 4)
        };
        palette(q0, q1, i as usize)
    }))
}

/// An RGB float image as BC6H_UF16 blocks, row by row; edges past the image repeat its last
/// row and column.
pub fn encode_image(rgb: &[[f32; 3]], width: u32, height: u32, quality: Quality) -> Vec<u8> {
    let (bw, bh) = (width.div_ceil(4), height.div_ceil(4));
    let mut out = Vec::with_capacity((bw * bh) as usize * BLOCK_BYTES);
    for by in 0..bh {
        for bx in 0..bw {
            let texels = block_texels(rgb, width, height, bx, by);
            out.extend_from_slice(&pack(&encode_block(&texels, quality)));
        }
    }
    out
}

/// Block (`bx`, `by`)'s texels in half bits, clamped to the image.
pub fn block_texels(rgb: &[[f32; 3]], width: u32, height: u32, bx: u32, by: u32) -> [[u32; 3]; 16] {
    std::array::from_fn(|t| {
        let x = (bx * 4 + t as u32 % 4).min(width - 1);
        let y = (by * 4 + t as u32 / 4).min(height - 1);
        rgb[(y * width + x) as usize].map(half_bits)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quantize_picks_the_nearest_endpoint() {
        for h in (0..=MAX_HALF_BITS).step_by(7) {
            let q = quantize(h);
            let at = |q: u32| unquantize(q) as f64 * 31.0 / 64.0;
            let d = (at(q) - h as f64).abs();
            for other in [q.saturating_sub(1), (q + 1).min(1023)] {
                assert!(
                    d <= (at(other) - h as f64).abs() + 1e-9,
                    "h {h}: {q} vs {other}"
                );
            }
        }
    }

    #[test]
    fn a_flat_block_decodes_to_within_the_quantization_step() {
        let x = half_bits(3.5);
        let texels = [[x, x, x]; 16];
        let b = encode_block(&texels, Quality::Fast);
        let d = decode(&pack(&b)).unwrap();
        for t in d {
            assert!(t[0].abs_diff(x) <= 31, "{t:?} vs {x}");
        }
    }
}
