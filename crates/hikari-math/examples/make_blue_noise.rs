//! Writes the committed blue-noise set `crates/hikari-math/data/blue_noise_64x64x64.bin`:
//! 64 void-and-cluster arrays of 64 x 64, u8 ranks, slice-major then row-major.
//!
//! Run: `cargo run --release -p hikari-math --example make_blue_noise`
//! (seconds in release; the library embeds the file so debug builds never regenerate it).

use hikari_math::sampling::blue_noise::{
    BLUE_NOISE_SEED, BLUE_NOISE_SIZE, BLUE_NOISE_SLICES, blue_noise_slices,
};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let slices = blue_noise_slices(BLUE_NOISE_SIZE, BLUE_NOISE_SLICES, BLUE_NOISE_SEED)?;
    let bytes: Vec<u8> = slices.concat();
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/data/blue_noise_64x64x64.bin");
    std::fs::write(path, &bytes)?;
    println!("wrote {} bytes to {path}", bytes.len());
    Ok(())
}
