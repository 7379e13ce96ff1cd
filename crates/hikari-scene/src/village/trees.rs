//! Trees, swaying in the wind by vertex animation ([`Deformation::Sway`]): golden ginkgos
//! ringing the temple courtyard and among the houses, green broadleaf trees in the village,
//! cedars on the hills; and fallen ginkgo leaves on the courtyard gravel.
//!
//! Each species has a few variants; every tree is an instance of one (random yaw, uniform
//! scale), so the trunk-and-branch mesh and the foliage mesh of a variant are shared. Both
//! carry the same sway, so they move together. Foliage is cards (small double-sided quads)
//! scattered through an ellipsoidal crown, facing roughly outwards.

use glam::{Mat4, Quat, Vec2, Vec3, Vec4};

use super::builder::Builder;
use super::materials::Palette;
use super::rng::Rng;
use super::terrain::{HALF_SIZE, Terrain};
use crate::shapes::{append, frustum, push_quad, rod};
use crate::{Deformation, Mesh};

#[derive(Clone, Copy)]
enum Shape {
    /// Trunk, branches and a crown of leaf cards.
    Broadleaf {
        crown_centre: f32,
        crown_radii: Vec3,
        leaf_size: f32,
        leaves: usize,
        branches: usize,
    },
    /// Trunk and stacked cones of foliage.
    Conifer { radius: f32, tiers: usize },
}

#[derive(Clone, Copy)]
struct Species {
    name: &'static str,
    height: f32,
    trunk_radius: f32,
    shape: Shape,
    sway_amplitude_m: f32,
    sway_frequency_hz: f32,
}

const GINKGO: Species = Species {
    name: "ginkgo",
    height: 12.0,
    trunk_radius: 0.3,
    shape: Shape::Broadleaf {
        crown_centre: 7.6,
        crown_radii: Vec3::new(3.4, 3.9, 3.4),
        leaf_size: 0.35,
        leaves: 1500,
        branches: 9,
    },
    sway_amplitude_m: 0.15,
    sway_frequency_hz: 0.25,
};

const MAPLE: Species = Species {
    name: "broadleaf",
    height: 9.0,
    trunk_radius: 0.22,
    shape: Shape::Broadleaf {
        crown_centre: 5.6,
        crown_radii: Vec3::new(3.4, 3.0, 3.4),
        leaf_size: 0.4,
        leaves: 1200,
        branches: 8,
    },
    sway_amplitude_m: 0.12,
    sway_frequency_hz: 0.3,
};

const CEDAR: Species = Species {
    name: "cedar",
    height: 18.0,
    trunk_radius: 0.35,
    shape: Shape::Conifer {
        radius: 3.2,
        tiers: 7,
    },
    sway_amplitude_m: 0.25,
    sway_frequency_hz: 0.18,
};

/// One variant's shared meshes.
struct Variant {
    wood: usize,
    foliage: usize,
    foliage_material: usize,
    height: f32,
}

/// Wind along +x and a little +z in the tree's own frame (rotated with each instance).
const WIND: Vec3 = Vec3::new(1.0, 0.0, 0.35);

fn make_variant(
    b: &mut Builder,
    pal: &Palette,
    sp: &Species,
    index: usize,
    rng: &mut Rng,
) -> Variant {
    let h = sp.height * rng.range(0.9, 1.1);
    let sway = Deformation::Sway {
        amplitude_m: sp.sway_amplitude_m,
        frequency_hz: sp.sway_frequency_hz * rng.range(0.85, 1.15),
        phase: rng.range(0.0, std::f32::consts::TAU),
        direction: WIND,
        base_y: 0.0,
        height_m: h,
    };
    let mut wood = Mesh::default();
    let mut foliage = Mesh::default();
    let foliage_material = match sp.shape {
        Shape::Broadleaf {
            crown_centre,
            crown_radii,
            leaf_size,
            leaves,
            branches,
        } => {
            let s = h / sp.height;
            let (cc, radii) = (crown_centre * s, crown_radii * s);
            let trunk_top = cc + 0.3 * radii.y;
            let lean = Vec3::new(rng.signed(0.3), 0.0, rng.signed(0.3));
            let r0 = sp.trunk_radius * s;
            let trunk = rod(
                Vec3::Y * -0.3,
                Vec3::Y * trunk_top + lean,
                r0,
                0.45 * r0,
                10,
            )
            .expect("positive trunk");
            append(&mut wood, &trunk, Mat4::IDENTITY);
            for i in 0..branches {
                let f = i as f32 / branches as f32;
                let y = cc - 0.6 * radii.y + f * 0.9 * radii.y;
                let start = Vec3::Y * y + lean * (y / trunk_top);
                let azimuth = i as f32 * 2.39996 + rng.signed(0.3);
                let elevation = rng.range(0.45, 0.95);
                let dir = Vec3::new(
                    azimuth.cos() * elevation.cos(),
                    elevation.sin(),
                    azimuth.sin() * elevation.cos(),
                );
                let len = radii.x * rng.range(0.55, 0.9);
                let branch = rod(start, start + dir * len, 0.35 * r0, 0.06 * r0, 6)
                    .expect("positive branch");
                append(&mut wood, &branch, Mat4::IDENTITY);
            }
            let centre = Vec3::Y * cc + lean;
            for _ in 0..leaves {
                // A direction uniform on the sphere, a radius biased to the crown's surface.
                let z = rng.range(-1.0, 1.0);
                let a = rng.range(0.0, std::f32::consts::TAU);
                let d = Vec3::new(
                    (1.0 - z * z).sqrt() * a.cos(),
                    z,
                    (1.0 - z * z).sqrt() * a.sin(),
                );
                let p = centre + d * radii * (0.55 + 0.45 * rng.unit().sqrt());
                let n = (d + Vec3::new(rng.signed(0.7), rng.signed(0.7), rng.signed(0.7)))
                    .normalize_or(Vec3::Y);
                let t0 = n.any_orthonormal_vector();
                let spin = rng.range(0.0, std::f32::consts::TAU);
                let t = t0 * spin.cos() + n.cross(t0) * spin.sin();
                let size = leaf_size * rng.range(0.7, 1.2);
                let (eu, ev) = (t * size, n.cross(t) * size * 0.8);
                let c0 = p - 0.5 * eu - 0.5 * ev;
                push_quad(&mut foliage, [c0, c0 + eu, c0 + eu + ev, c0 + ev]);
                let shade = rng.range(0.8, 1.15);
                let green = rng.range(0.85, 1.1);
                foliage
                    .colors
                    .get_or_insert_with(Vec::new)
                    .extend([Vec4::new(shade, shade * green, shade, 1.0); 4]);
            }
            if sp.name == GINKGO.name {
                pal.ginkgo
            } else {
                pal.maple
            }
        }
        Shape::Conifer { radius, tiers } => {
            let r0 = sp.trunk_radius * h / sp.height;
            let trunk = rod(Vec3::Y * -0.3, Vec3::Y * h, r0, 0.04, 8).expect("positive trunk");
            append(&mut wood, &trunk, Mat4::IDENTITY);
            for k in 0..tiers {
                let f = k as f32 / tiers as f32;
                let y = h * (0.22 + 0.62 * f);
                let r = radius * (1.0 - 0.8 * f) * rng.range(0.9, 1.1);
                let cone = frustum(r, 0.0, (h - y).min(0.32 * h), 10).expect("positive tier");
                append(&mut foliage, &cone, Mat4::from_translation(Vec3::Y * y));
            }
            pal.needles
        }
    };
    wood.deformation = Some(sway);
    foliage.deformation = Some(sway);
    Variant {
        wood: b.mesh(&format!("{} {index} wood", sp.name), wood),
        foliage: b.mesh(&format!("{} {index} foliage", sp.name), foliage),
        foliage_material,
        height: h,
    }
}

fn plant(b: &mut Builder, pal: &Palette, v: &Variant, terrain: &Terrain, at: Vec2, rng: &mut Rng) {
    let y = terrain.min_over(at, 0.4);
    let t = Mat4::from_scale_rotation_translation(
        Vec3::splat(rng.range(0.85, 1.15)),
        Quat::from_rotation_y(rng.range(0.0, std::f32::consts::TAU)),
        Vec3::new(at.x, y, at.y),
    );
    b.instance(v.wood, pal.bark, t);
    b.instance(v.foliage, v.foliage_material, t);
}

/// Where trees must not stand: discs (centre, radius) on the ground.
pub struct KeepOut {
    pub discs: Vec<(Vec2, f32)>,
}

impl KeepOut {
    fn clear(&self, p: Vec2, trees: &[Vec2], spacing: f32) -> bool {
        self.discs.iter().all(|(c, r)| p.distance(*c) > *r)
            && trees.iter().all(|t| t.distance(p) > spacing)
    }
}

/// Plants all the trees; returns (centre xz, height) of each ginkgo on the courtyard ring.
pub fn build(
    b: &mut Builder,
    pal: &Palette,
    terrain: &Terrain,
    seed: u64,
    keep_out: &KeepOut,
) -> Vec<(Vec2, f32)> {
    let mut rng = Rng::stream(seed, "trees");
    let ginkgos: Vec<Variant> = (0..3)
        .map(|i| make_variant(b, pal, &GINKGO, i, &mut rng))
        .collect();
    let maples: Vec<Variant> = (0..2)
        .map(|i| make_variant(b, pal, &MAPLE, i, &mut rng))
        .collect();
    let cedars: Vec<Variant> = (0..2)
        .map(|i| make_variant(b, pal, &CEDAR, i, &mut rng))
        .collect();
    let s = &terrain.sites;
    let mut planted: Vec<Vec2> = Vec::new();

    // The courtyard ring, open to the south where the path comes in.
    let mut ring = Vec::new();
    let n = 22;
    for k in 0..n {
        let a = std::f32::consts::TAU * k as f32 / n as f32 + rng.signed(0.05);
        let dir = Vec2::new(a.cos(), a.sin());
        if dir.dot(Vec2::NEG_Y) > 22f32.to_radians().cos() {
            continue;
        }
        let p = s.courtyard_centre + dir * (s.courtyard_radius + 3.5 + rng.signed(0.8));
        if !keep_out.clear(p, &[], 0.0) {
            continue;
        }
        let v = &ginkgos[rng.below(ginkgos.len())];
        plant(b, pal, v, terrain, p, &mut rng);
        ring.push((p, v.height));
        planted.push(p);
    }

    // Village trees, away from the street, path, houses, pond and courtyard.
    let mut village = 0;
    for _ in 0..4000 {
        if village >= 28 {
            break;
        }
        let p = Vec2::new(rng.range(-85.0, 75.0), rng.range(-65.0, 45.0));
        let ok = s.plain_distance(p) < 1.0
            && s.distance_to_street(p) > 6.0
            && s.distance_to_path(p) > 5.0
            && p.distance(s.pond_centre) > s.pond_shore_radius() + 4.0
            && p.distance(s.courtyard_centre) > s.courtyard_radius + 8.0
            && keep_out.clear(p, &planted, 7.0);
        if !ok {
            continue;
        }
        let v = if rng.chance(0.25) {
            &ginkgos[rng.below(ginkgos.len())]
        } else {
            &maples[rng.below(maples.len())]
        };
        plant(b, pal, v, terrain, p, &mut rng);
        planted.push(p);
        village += 1;
    }

    // Cedars on the hills around the valley.
    let mut forest = 0;
    let edge = HALF_SIZE - 5.0;
    for _ in 0..20000 {
        if forest >= 230 {
            break;
        }
        let p = Vec2::new(rng.range(-edge, edge), rng.range(-edge, edge));
        let ok = s.plain_distance(p) > 1.05
            && p.distance(s.courtyard_centre) > s.courtyard_radius + 12.0
            && keep_out.clear(p, &planted, 6.5);
        if !ok {
            continue;
        }
        let v = &cedars[rng.below(cedars.len())];
        plant(b, pal, v, terrain, p, &mut rng);
        planted.push(p);
        forest += 1;
    }
    ring
}

/// Fallen ginkgo leaves: small quads lying on the courtyard gravel (a little tilted, 5 to
/// 35 mm above it), denser towards the ring of trees, none under the temple or the bell
/// tower. One mesh in world space.
pub fn fallen_leaves(terrain: &Terrain, seed: u64, count: usize, keep_out: &[(Vec2, f32)]) -> Mesh {
    let mut rng = Rng::stream(seed, "fallen leaves");
    let s = &terrain.sites;
    // The courtyard is level out to two metres beyond its radius.
    let radius = s.courtyard_radius + 1.5;
    let mut m = Mesh::default();
    let mut colors = Vec::new();
    let mut placed = 0;
    while placed < count {
        let r = radius * rng.unit().powf(0.35);
        let a = rng.range(0.0, std::f32::consts::TAU);
        let p = s.courtyard_centre + r * Vec2::new(a.cos(), a.sin());
        if keep_out.iter().any(|(c, rr)| p.distance(*c) < *rr) {
            continue;
        }
        let tilt = Quat::from_rotation_x(rng.signed(0.2)) * Quat::from_rotation_z(rng.signed(0.2));
        let q = Quat::from_rotation_y(rng.range(0.0, std::f32::consts::TAU)) * tilt;
        let size = rng.range(0.05, 0.08);
        let (eu, ev) = (q * Vec3::X * size, q * Vec3::NEG_Z * size * 0.8);
        let centre = Vec3::new(p.x, s.courtyard_y + 0.02, p.y);
        let c0 = centre - 0.5 * eu - 0.5 * ev;
        push_quad(&mut m, [c0, c0 + eu, c0 + eu + ev, c0 + ev]);
        let tone = rng.range(0.75, 1.1);
        let brown = rng.range(0.0, 0.35);
        colors.extend([Vec4::new(tone, tone * (1.0 - 0.4 * brown), tone * (1.0 - brown), 1.0); 4]);
        placed += 1;
    }
    m.colors = Some(colors);
    m
}
