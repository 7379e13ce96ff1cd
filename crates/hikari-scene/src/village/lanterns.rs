//! Paper lanterns (chōchin) on wooden posts along the street and the temple path: a paper
//! barrel between black caps. Every other street lantern is lit: a point light inside and its
//! paper glowing ([`super::materials::LANTERN_NITS`]); the others are dark. A glowing paper
//! always has its light, so that what lights the street is sampled as a light, not found by
//! chance by one GI ray a pixel.
//!
//! The point light emits the luminous flux the paper would emit as a Lambertian surface of
//! that luminance, Φ = π L A (A the paper's area), so the light a lantern casts and how bright
//! it looks agree. It sits at the centre of the paper barrel; a renderer that traces shadow
//! rays has to let the lantern's own paper pass that light (the paper stands for the light
//! coming through it), or start the rays outside the lantern's radius.

use glam::{Mat4, Vec2, Vec3};

use super::builder::{Builder, placed};
use super::materials::{Palette, warm_white};
use super::terrain::Terrain;
use crate::shapes::{append, cuboid, frustum, lathe, rod};
use crate::{Light, Mesh};

/// Paper barrel height and largest radius, metres.
pub const PAPER_HEIGHT: f32 = 0.42;
pub const PAPER_RADIUS: f32 = 0.18;

/// The shared lantern meshes. Lantern frame: bottom of the paper at the origin, axis +Y.
pub struct Lantern {
    pub paper: usize,
    pub caps: usize,
    pub post: usize,
    /// Area of the paper, m².
    pub paper_area: f32,
}

/// Where a post hangs its lantern, in the post's frame (the arm reaches along +x).
const HANG: Vec3 = Vec3::new(0.62, 2.05, 0.0);

impl Lantern {
    pub fn new(b: &mut Builder) -> Lantern {
        let end_radius = 0.11;
        let profile: Vec<Vec2> = (0..=10)
            .map(|k| {
                let f = k as f32 / 10.0;
                Vec2::new(
                    end_radius + (PAPER_RADIUS - end_radius) * (std::f32::consts::PI * f).sin(),
                    PAPER_HEIGHT * f,
                )
            })
            .collect();
        let paper = lathe(&profile, 20).expect("fixed lantern profile");
        let paper_area = area(&paper);
        let mut caps = Mesh::default();
        let cap = frustum(end_radius + 0.01, end_radius + 0.01, 0.05, 20).expect("fixed sizes");
        append(&mut caps, &cap, Mat4::from_translation(Vec3::Y * -0.05));
        append(
            &mut caps,
            &cap,
            Mat4::from_translation(Vec3::Y * PAPER_HEIGHT),
        );
        // The cord it hangs by.
        let cord = rod(
            Vec3::Y * (PAPER_HEIGHT + 0.05),
            Vec3::Y * (2.6 - HANG.y),
            0.008,
            0.008,
            6,
        )
        .expect("fixed sizes");
        append(&mut caps, &cord, Mat4::IDENTITY);
        let mut post = Mesh::default();
        append(
            &mut post,
            &cuboid(Vec3::new(-0.06, -0.5, -0.06), Vec3::new(0.06, 2.75, 0.06)),
            Mat4::IDENTITY,
        );
        append(
            &mut post,
            &cuboid(Vec3::new(0.06, 2.6, -0.035), Vec3::new(0.72, 2.68, 0.035)),
            Mat4::IDENTITY,
        );
        Lantern {
            paper: b.mesh("lantern paper", paper),
            caps: b.mesh("lantern caps", caps),
            post: b.mesh("lantern post", post),
            paper_area,
        }
    }

    /// Adds a lantern (paper and caps) with its bottom at `transform`'s origin; returns the
    /// world centre of its paper.
    pub fn hang(&self, b: &mut Builder, paper: usize, caps: usize, transform: Mat4) -> Vec3 {
        b.instance(self.paper, paper, transform);
        b.instance(self.caps, caps, transform);
        transform.transform_point3(Vec3::Y * (0.5 * PAPER_HEIGHT))
    }

    /// Luminous flux of a Lambertian surface of the lantern paper's area (scaled by `scale`)
    /// at luminance `nits`: Φ = π L A.
    pub fn flux_lm(&self, nits: f32, scale: f32) -> f32 {
        std::f32::consts::PI * nits * self.paper_area * scale * scale
    }
}

/// Surface area of a mesh, m².
pub(super) fn area(m: &Mesh) -> f32 {
    m.indices
        .chunks_exact(3)
        .map(|t| {
            let [a, b, c] = [0, 1, 2].map(|i| m.positions[t[i] as usize]);
            0.5 * (b - a).cross(c - a).length()
        })
        .sum()
}

/// A placed lantern: the centre of its paper and whether a point light is inside.
pub struct Placed {
    pub centre: Vec3,
    pub lit: bool,
}

/// Posts along both edges of the street every 8 m, and along the temple path, the arms
/// reaching over the roadway; a point light in every other street lantern, whose paper glows,
/// the others' paper dark.
pub fn street(b: &mut Builder, pal: &Palette, terrain: &Terrain, lantern: &Lantern) -> Vec<Placed> {
    let s = &terrain.sites;
    let edge = s.street_half_width + 0.3;
    let mut posts = Vec::new();
    let mut x = s.street_x.0 + 4.0;
    let mut k = 0;
    while x < s.street_x.1 - 6.0 {
        // North posts' arms reach south (-z), south posts' north: yaw turns +x to -z or +z.
        posts.push((Vec2::new(x, edge), std::f32::consts::FRAC_PI_2, k % 2 == 0));
        posts.push((
            Vec2::new(x + 4.0, -edge),
            -std::f32::consts::FRAC_PI_2,
            k % 2 == 1,
        ));
        x += 8.0;
        k += 1;
    }
    let (a, c) = s.path;
    for f in [0.3, 0.6, 0.9] {
        let p = a.lerp(c, f);
        let e = s.path_half_width + 0.3;
        posts.push((p + Vec2::new(e, 0.0), std::f32::consts::PI, false));
        posts.push((p - Vec2::new(e, 0.0), 0.0, false));
    }
    let mut placed_lanterns = Vec::new();
    for (i, (p, yaw, lit)) in posts.into_iter().enumerate() {
        let ground = terrain.max_over(p, 0.1);
        let post = placed(Vec3::new(p.x, ground, p.y), yaw);
        b.instance(lantern.post, pal.timber_out, post);
        let centre = lantern.hang(
            b,
            if lit {
                pal.lantern_paper
            } else {
                pal.lantern_paper_dark
            },
            pal.lantern_cap,
            post * Mat4::from_translation(HANG),
        );
        if lit {
            b.scene.lights.push(Light::point_lumens(
                &format!("lantern light {i}"),
                centre,
                lantern.flux_lm(super::materials::LANTERN_NITS, 1.0),
                warm_white(),
            ));
        }
        placed_lanterns.push(Placed { centre, lit });
    }
    placed_lanterns
}
