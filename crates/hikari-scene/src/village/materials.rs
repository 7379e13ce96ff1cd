//! The village's materials, created once and shared by index.
//!
//! Interior mask convention: every material used only outdoors says 0, every material used
//! only indoors (floors, ceilings, furniture, the temple's hall) says 1. Walls carry a
//! per-vertex mask instead (see [`crate::shapes::wall`]: 1 on the inside face, 0 outside,
//! 0.5 on edges and reveals), so their material leaves it unset.

use glam::Vec3;

use super::builder::Builder;
use crate::{Anisotropy, Material};

/// Luminance of the paper lanterns, nits. A paper shade glows at a few thousand nits near its
/// lamp; 2000 is the low end of the 2000-5000 nit range asked for, keeping the night street
/// bright next to the lanterns without making them the brightest thing in a daylight image
/// (white paper under a 100 000 lux sun reflects about 0.8 x 100 000 / π ≈ 25 000 nits).
pub const LANTERN_NITS: f32 = 2000.0;

/// Luminance of the small paper floor lamps (andon) inside the houses, nits: dimmer than
/// the street lanterns, as a candle or small bulb behind paper.
pub const ANDON_NITS: f32 = 600.0;

/// Warm lamp colour: a 3000 K black body in linear Rec.709 (sRGB (255, 180, 107) in Mitchell
/// Charity's black-body colour table, 10° observer, decoded to linear), scaled to luminance 1.
pub fn warm_white() -> Vec3 {
    let c = Vec3::new(1.0, 0.4564, 0.1470);
    c / hikari_math::color::luminance(c)
}

/// Indices of the village's materials in the scene.
pub struct Palette {
    pub terrain: usize,
    pub water: usize,
    pub plaster: usize,
    pub gable: usize,
    pub timber_out: usize,
    pub timber_in: usize,
    pub roof: usize,
    pub stone: usize,
    pub floor_boards: usize,
    pub tatami: usize,
    pub ceiling: usize,
    pub furniture: usize,
    pub fabric: usize,
    pub cushion: usize,
    pub lacquer_out: usize,
    pub lacquer_in: usize,
    pub gold: usize,
    pub bronze: usize,
    pub brushed_bronze: usize,
    pub bark: usize,
    pub ginkgo: usize,
    pub fallen_leaves: usize,
    pub maple: usize,
    pub needles: usize,
    pub lantern_paper: usize,
    /// The same paper without a candle behind it: a lantern that glows without a light
    /// inside would light the street only through the GI's rays (white speckle at night).
    pub lantern_paper_dark: usize,
    pub lantern_cap: usize,
    pub andon_paper: usize,
    pub rope: usize,
}

fn outdoor(m: Material) -> Material {
    Material {
        interior: Some(0.0),
        ..m
    }
}

fn indoor(m: Material) -> Material {
    Material {
        interior: Some(1.0),
        ..m
    }
}

fn rough(name: &str, base: Vec3, roughness: f32) -> Material {
    Material {
        roughness,
        ..Material::diffuse(name, base)
    }
}

fn leaves(name: &str, base: Vec3) -> Material {
    Material {
        double_sided: true,
        ..outdoor(rough(name, base, 0.6))
    }
}

impl Palette {
    pub fn new(b: &mut Builder) -> Palette {
        let bronze = Vec3::new(0.72, 0.50, 0.30);
        let timber = Vec3::new(0.20, 0.12, 0.065);
        let lacquer = Vec3::new(0.50, 0.07, 0.035);
        Palette {
            // White: the terrain's vertex colours hold grass, earth, gravel and mud.
            terrain: b.material(outdoor(rough("terrain", Vec3::ONE, 0.95))),
            // Still water: a dark base (the little light scattered back out of the water) and
            // a near-mirror surface.
            water: b.material(outdoor(rough(
                "pond water",
                Vec3::new(0.02, 0.03, 0.035),
                0.05,
            ))),
            plaster: b.material(rough("plaster", Vec3::new(0.74, 0.71, 0.64), 0.9)),
            gable: b.material(outdoor(rough(
                "gable plaster",
                Vec3::new(0.70, 0.67, 0.60),
                0.9,
            ))),
            timber_out: b.material(outdoor(rough("timber", timber, 0.7))),
            timber_in: b.material(indoor(rough("timber (indoor)", timber, 0.6))),
            roof: b.material(outdoor(rough(
                "roof tiles",
                Vec3::new(0.10, 0.105, 0.115),
                0.55,
            ))),
            stone: b.material(outdoor(rough("stone", Vec3::new(0.42, 0.40, 0.37), 0.85))),
            floor_boards: b.material(indoor(rough(
                "floor boards",
                Vec3::new(0.40, 0.26, 0.14),
                0.45,
            ))),
            tatami: b.material(indoor(rough("tatami", Vec3::new(0.56, 0.54, 0.30), 0.8))),
            ceiling: b.material(indoor(rough("ceiling", Vec3::new(0.45, 0.32, 0.20), 0.7))),
            furniture: b.material(indoor(rough("furniture", Vec3::new(0.30, 0.17, 0.08), 0.4))),
            // White base: the futon's vertex colours give mattress, quilt and pillow.
            fabric: b.material(indoor(rough("bedding", Vec3::ONE, 0.9))),
            cushion: b.material(indoor(rough("cushion", Vec3::new(0.45, 0.10, 0.10), 0.9))),
            lacquer_out: b.material(outdoor(rough("red lacquer", lacquer, 0.35))),
            lacquer_in: b.material(indoor(rough("red lacquer (indoor)", lacquer, 0.35))),
            gold: b.material(indoor(Material {
                metalness: 1.0,
                roughness: 0.3,
                ..Material::diffuse("gold leaf", Vec3::new(1.0, 0.78, 0.34))
            })),
            bronze: b.material(outdoor(Material {
                metalness: 1.0,
                roughness: 0.2,
                ..Material::diffuse("polished bronze", bronze)
            })),
            // Lathe-turned rim: brushed along the circumference, which is the mesh's tangent.
            brushed_bronze: b.material(outdoor(Material {
                metalness: 1.0,
                roughness: 0.3,
                anisotropy: Some(Anisotropy {
                    strength: 0.8,
                    rotation: 0.0,
                }),
                ..Material::diffuse("brushed bronze", bronze)
            })),
            bark: b.material(outdoor(rough("bark", Vec3::new(0.17, 0.13, 0.10), 0.9))),
            ginkgo: b.material(leaves("ginkgo leaves", Vec3::new(0.80, 0.58, 0.06))),
            fallen_leaves: b.material(leaves("fallen ginkgo leaves", Vec3::new(0.75, 0.52, 0.07))),
            maple: b.material(leaves("green leaves", Vec3::new(0.12, 0.26, 0.06))),
            needles: b.material(leaves("cedar needles", Vec3::new(0.05, 0.15, 0.06))),
            lantern_paper: b.material(outdoor(Material {
                base_color: Vec3::new(0.80, 0.76, 0.66),
                roughness: 0.9,
                emissive_nits: warm_white() * LANTERN_NITS,
                double_sided: true,
                ..Material::diffuse("lantern paper", Vec3::ONE)
            })),
            lantern_paper_dark: b.material(outdoor(Material {
                base_color: Vec3::new(0.80, 0.76, 0.66),
                roughness: 0.9,
                double_sided: true,
                ..Material::diffuse("unlit lantern paper", Vec3::ONE)
            })),
            lantern_cap: b.material(outdoor(rough("black lacquer", Vec3::splat(0.03), 0.3))),
            andon_paper: b.material(indoor(Material {
                base_color: Vec3::new(0.80, 0.76, 0.66),
                roughness: 0.9,
                emissive_nits: warm_white() * ANDON_NITS,
                ..Material::diffuse("andon paper", Vec3::ONE)
            })),
            rope: b.material(outdoor(rough("rope", Vec3::new(0.55, 0.45, 0.30), 0.9))),
        }
    }
}
