//! A small seeded mutator for the tests: deterministic, so a failure reproduces from its seed
//! and index, and crude next to libFuzzer's (no coverage feedback), but enough to keep every
//! target exercised on inputs near the seeds in CI.

/// SplitMix64: a tiny generator with good enough statistics for picking mutations.
#[derive(Clone, Debug)]
pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Self {
        Self(seed)
    }

    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in `0..n` (`n > 0`).
    pub fn below(&mut self, n: usize) -> usize {
        (self.next_u64() % n as u64) as usize
    }
}

/// Numbers that break size and index arithmetic, as text and as little-endian bytes.
const INTERESTING: &[u64] = &[
    0,
    1,
    2,
    0x7f,
    0x80,
    0xff,
    0x100,
    0x7fff,
    0xffff,
    0x1_0000,
    0x7fff_ffff,
    0x8000_0000,
    0xffff_ffff,
    0x1_0000_0000,
    0x7fff_ffff_ffff_ffff,
    u64::MAX,
];

const INTERESTING_TEXT: &[&str] = &[
    "0",
    "-1",
    "1e308",
    "-1e308",
    "nan",
    "inf",
    "-inf",
    "4294967296",
    "18446744073709551615",
    "9223372036854775807",
    "-9223372036854775808",
    "1e-45",
    "\"",
    "[",
    "{",
    "\n",
    "=",
    ".",
];

/// One to four mutations of `input`, drawing on `others` for splices.
pub fn mutate(rng: &mut Rng, input: &[u8], others: &[Vec<u8>]) -> Vec<u8> {
    let mut out = input.to_vec();
    for _ in 0..1 + rng.below(4) {
        mutate_once(rng, &mut out, others);
    }
    out
}

fn mutate_once(rng: &mut Rng, out: &mut Vec<u8>, others: &[Vec<u8>]) {
    let at = |rng: &mut Rng, len: usize| if len == 0 { 0 } else { rng.below(len + 1) };
    match rng.below(9) {
        // Bit flip.
        0 if !out.is_empty() => {
            let i = rng.below(out.len());
            out[i] ^= 1 << rng.below(8);
        }
        // Random byte.
        1 if !out.is_empty() => {
            let i = rng.below(out.len());
            out[i] = rng.next_u64() as u8;
        }
        // Truncation.
        2 => {
            let n = at(rng, out.len());
            out.truncate(n);
        }
        // Delete a run.
        3 if !out.is_empty() => {
            let i = rng.below(out.len());
            let n = (1 + rng.below(16)).min(out.len() - i);
            out.drain(i..i + n);
        }
        // Duplicate a run (repeats structure: nested tables, JSON arrays).
        4 if !out.is_empty() => {
            let i = rng.below(out.len());
            let n = (1 + rng.below(64)).min(out.len() - i);
            let run: Vec<u8> = out[i..i + n].to_vec();
            let j = at(rng, out.len());
            out.splice(j..j, run);
        }
        // Overwrite with a big binary number.
        5 if out.len() >= 8 => {
            let v = INTERESTING[rng.below(INTERESTING.len())];
            let width = [1, 2, 4, 8][rng.below(4)];
            let i = rng.below(out.len() - width + 1);
            out[i..i + width].copy_from_slice(&v.to_le_bytes()[..width]);
        }
        // Insert a number or token as text.
        6 => {
            let t = INTERESTING_TEXT[rng.below(INTERESTING_TEXT.len())];
            let j = at(rng, out.len());
            out.splice(j..j, t.bytes());
        }
        // Replace a digit run with a big number in text (counts, lengths, indices).
        7 => {
            let digits: Vec<usize> = (0..out.len())
                .filter(|&i| out[i].is_ascii_digit())
                .collect();
            if let Some(&i) = digits.get(rng.below(digits.len().max(1))) {
                let end = (i..out.len())
                    .find(|&k| !out[k].is_ascii_digit())
                    .unwrap_or(out.len());
                let t = INTERESTING_TEXT[rng.below(INTERESTING_TEXT.len())];
                out.splice(i..end, t.bytes());
            }
        }
        // Splice: the head of this input and the tail of another.
        _ if !others.is_empty() => {
            let other = &others[rng.below(others.len())];
            let i = at(rng, out.len());
            let j = at(rng, other.len());
            out.truncate(i);
            out.extend_from_slice(&other[j..]);
        }
        _ => out.push(rng.next_u64() as u8),
    }
}
