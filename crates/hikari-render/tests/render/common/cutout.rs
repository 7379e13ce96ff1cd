//! The built-in `cutout` scene traced analytically on the CPU, for the cut-out tests of the
//! rasteriser (`alpha.rs`) and of the BVH (`bvh_alpha.rs`): its ground square and its two
//! double-sided quads in the plane z = 0, covered where `builtin::cutout_checker_covered` and
//! `builtin::cutout_ramp_alpha` (against the ramp's cut-off) say, at the exact texture
//! coordinate where a ray crosses a quad, with the band within which a GPU's bilinear alpha may
//! answer either way (each test's module doc says why the band is what it is).

use glam::{Vec2, Vec3};
use hikari_scene::builtin::{self, CUTOUT_CHECKER_CELLS, CUTOUT_RAMP_CUTOFF, CUTOUT_TEXTURE_SIZE};

/// Instances of the `cutout` scene (see `builtin::cutout`).
pub const GROUND: u32 = 0;
pub const CHECKER: u32 = 1;
pub const RAMP: u32 = 2;
/// Half the side of the ground square, metres.
pub const GROUND_HALF: f32 = 6.0;
/// UV distance from a cut-out edge within which GPU and reference may disagree.
pub const CUT_BAND: f32 = 0.25 / CUTOUT_TEXTURE_SIZE as f32;
/// Distance from a quad's or the ground's outline, metres, within which they may disagree.
pub const OUTLINE_BAND: f32 = 1e-3;
/// Where the quads stand: centre x and instance; each spans x ± 1, y from 0.25 to 2.25 at
/// z = 0, with u = 0 at its left end (-x) and v = 0 at its top.
pub const QUADS: [(f32, u32); 2] = [(-1.25, CHECKER), (1.25, RAMP)];

pub fn covered(instance: u32, uv: Vec2) -> bool {
    if instance == CHECKER {
        builtin::cutout_checker_covered(uv)
    } else {
        builtin::cutout_ramp_alpha(uv.x) >= CUTOUT_RAMP_CUTOFF
    }
}

pub fn near_cut(instance: u32, uv: Vec2) -> bool {
    let cells = CUTOUT_CHECKER_CELLS as f32;
    let to_integer = |x: f32| (x - x.round()).abs();
    if instance == CHECKER {
        to_integer(uv.x * cells) < CUT_BAND * cells || to_integer(uv.y * cells) < CUT_BAND * cells
    } else {
        (uv.x - 0.25).abs() < CUT_BAND
    }
}

/// What a ray sees first, whether that answer is within the tolerance band of another, and
/// whether it went through a hole (crossed a quad's inside where the alpha test cuts it out).
#[derive(Clone, Copy, Debug)]
pub struct Traced {
    /// Instance and distance.
    pub hit: Option<(u32, f32)>,
    pub ambiguous: bool,
    pub through_hole: bool,
}

/// The first surface along `o + t d` for t in (t_min, t_max), with the alpha test (or without,
/// `alpha_test` false: the quads whole). The ground faces +Y; `ground_from_below` counts it
/// from below too (the BVH culls no faces; the rasteriser culls its back).
pub fn trace(
    o: Vec3,
    d: Vec3,
    t_min: f32,
    t_max: f32,
    alpha_test: bool,
    ground_from_below: bool,
) -> Traced {
    let in_range = |t: f32| t > t_min && t < t_max;
    let mut out = Traced {
        hit: None,
        ambiguous: false,
        through_hole: false,
    };
    if d.y < 0.0 || (ground_from_below && d.y != 0.0) {
        let t = -o.y / d.y;
        let p = o + d * t;
        let edge = GROUND_HALF - p.x.abs().max(p.z.abs());
        if in_range(t) && edge.abs() < OUTLINE_BAND {
            out.ambiguous = true;
        }
        if in_range(t) && edge > 0.0 {
            out.hit = Some((GROUND, t));
        }
    }
    if d.z != 0.0 {
        let t = -o.z / d.z;
        let nearer = out.hit.is_none_or(|(_, h)| t < h);
        if in_range(t) && nearer {
            let p = o + d * t;
            for (x, instance) in QUADS {
                // 2 m quads: UV is metres / 2.
                let uv = Vec2::new(p.x - (x - 1.0), 2.25 - p.y) / 2.0;
                let inside = uv.cmpge(Vec2::ZERO).all() && uv.cmple(Vec2::ONE).all();
                let outline = uv.min(Vec2::ONE - uv).min_element().abs() * 2.0;
                if outline < OUTLINE_BAND || (inside && alpha_test && near_cut(instance, uv)) {
                    out.ambiguous = true;
                }
                if inside {
                    if !alpha_test || covered(instance, uv) {
                        out.hit = Some((instance, t));
                    } else {
                        out.through_hole = true;
                    }
                }
            }
        }
    }
    out
}
