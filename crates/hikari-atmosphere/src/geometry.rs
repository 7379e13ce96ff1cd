//! Rays in a spherically symmetric atmosphere and the tables' parameterisations.
//!
//! A point is its distance `r` from the planet's centre (km); a direction its cosine `mu` with the
//! local zenith. The mappings follow Bruneton 2017 (the revised Bruneton & Neyret 2008): each
//! coordinate is a *distance* along a ray normalised to its range, which spends texels where the
//! quantities change fastest, near the horizon, and puts the horizon itself on a texel boundary
//! of the scattering table (rays that hit the ground and rays that do not live in separate
//! halves, never blended).

/// The two spheres and the derived horizon length.
#[derive(Clone, Copy, Debug)]
pub struct Shell {
    /// Ground radius, km.
    pub bottom: f64,
    /// Top of the atmosphere, km.
    pub top: f64,
    /// `sqrt(top² − bottom²)`: the distance to the top along the horizontal ray from the ground.
    pub h: f64,
}

/// The smallest sun zenith cosine the scattering tables cover: cos 102° (Bruneton 2017 for the
/// Earth), so twilight down to 12° below the horizon is represented.
pub const MU_S_MIN: f64 = -0.207_911_690_817_759_3;

/// Texel centres of an `n`-texel axis map `[0, 1]` to `[0.5 / n, 1 − 0.5 / n]`.
pub fn coord_from_unit(x: f64, n: usize) -> f64 {
    0.5 / n as f64 + x * (1.0 - 1.0 / n as f64)
}

/// Inverse of [`coord_from_unit`].
pub fn unit_from_coord(u: f64, n: usize) -> f64 {
    (u - 0.5 / n as f64) / (1.0 - 1.0 / n as f64)
}

fn safe_sqrt(x: f64) -> f64 {
    x.max(0.0).sqrt()
}

impl Shell {
    /// The shell for the given radii, km.
    pub fn new(bottom: f64, top: f64) -> Self {
        Self {
            bottom,
            top,
            h: safe_sqrt(top * top - bottom * bottom),
        }
    }

    /// Distance from `r` along `mu` to the top sphere (the far intersection), km.
    pub fn distance_to_top(&self, r: f64, mu: f64) -> f64 {
        (-r * mu + safe_sqrt(r * r * (mu * mu - 1.0) + self.top * self.top)).max(0.0)
    }

    /// Distance from `r` along `mu` to the ground (the near intersection), km; meaningful only
    /// when [`Shell::hits_ground`].
    pub fn distance_to_bottom(&self, r: f64, mu: f64) -> f64 {
        (-r * mu - safe_sqrt(r * r * (mu * mu - 1.0) + self.bottom * self.bottom)).max(0.0)
    }

    /// Whether the ray from `r` along `mu` meets the ground.
    pub fn hits_ground(&self, r: f64, mu: f64) -> bool {
        mu < 0.0 && r * r * (mu * mu - 1.0) + self.bottom * self.bottom >= 0.0
    }

    /// Where a ray ends: the ground when it hits it, else the top.
    pub fn distance_to_boundary(&self, r: f64, mu: f64, hits_ground: bool) -> f64 {
        if hits_ground {
            self.distance_to_bottom(r, mu)
        } else {
            self.distance_to_top(r, mu)
        }
    }

    /// Radius and zenith cosine after travelling `d` km from (`r`, `mu`).
    pub fn advance(&self, r: f64, mu: f64, d: f64) -> (f64, f64) {
        let rd = safe_sqrt(d * d + 2.0 * r * mu * d + r * r).clamp(self.bottom, self.top);
        let mud = ((r * mu + d) / rd).clamp(-1.0, 1.0);
        (rd, mud)
    }

    /// Transmittance table coordinates `(u_mu, u_r)` in [0, 1] for an `nmu × nr` table (rays that
    /// do not hit the ground only).
    pub fn transmittance_uv(&self, r: f64, mu: f64, nmu: usize, nr: usize) -> (f64, f64) {
        let rho = safe_sqrt(r * r - self.bottom * self.bottom);
        let d = self.distance_to_top(r, mu);
        let (d_min, d_max) = (self.top - r, rho + self.h);
        let x_mu = if d_max > d_min {
            (d - d_min) / (d_max - d_min)
        } else {
            0.0
        };
        (
            coord_from_unit(x_mu.clamp(0.0, 1.0), nmu),
            coord_from_unit(rho / self.h, nr),
        )
    }

    /// Inverse of [`Shell::transmittance_uv`] at texel centres: `(r, mu)`.
    pub fn transmittance_r_mu(&self, x_mu: f64, x_r: f64) -> (f64, f64) {
        let rho = self.h * x_r;
        let r = safe_sqrt(rho * rho + self.bottom * self.bottom);
        let (d_min, d_max) = (self.top - r, rho + self.h);
        let d = d_min + x_mu * (d_max - d_min);
        let mu = if d == 0.0 {
            1.0
        } else {
            (self.h * self.h - rho * rho - d * d) / (2.0 * r * d)
        };
        (r, mu.clamp(-1.0, 1.0))
    }

    /// Scattering table coordinates `(u_mu, u_mu_s, u_r)` in [0, 1] for a table of
    /// `nmu × nmus × nr` texels (`nmu` even: ground rays in the lower half).
    pub fn scattering_uvw(
        &self,
        r: f64,
        mu: f64,
        mu_s: f64,
        hits_ground: bool,
        [nmu, nmus, nr]: [usize; 3],
    ) -> (f64, f64, f64) {
        let rho = safe_sqrt(r * r - self.bottom * self.bottom);
        let u_r = coord_from_unit(rho / self.h, nr);
        let r_mu = r * mu;
        let disc = r_mu * r_mu - r * r + self.bottom * self.bottom;
        let half = nmu / 2;
        let u_mu = if hits_ground {
            let d = -r_mu - safe_sqrt(disc);
            let (d_min, d_max) = (r - self.bottom, rho);
            let x = if d_max == d_min {
                0.0
            } else {
                ((d - d_min) / (d_max - d_min)).clamp(0.0, 1.0)
            };
            0.5 - 0.5 * coord_from_unit(x, half)
        } else {
            let d = -r_mu + safe_sqrt(disc + self.h * self.h);
            let (d_min, d_max) = (self.top - r, rho + self.h);
            let x = ((d - d_min) / (d_max - d_min)).clamp(0.0, 1.0);
            0.5 + 0.5 * coord_from_unit(x, half)
        };
        (u_mu, coord_from_unit(self.x_mu_s(mu_s), nmus), u_r)
    }

    fn mu_s_a(&self, mu_s: f64) -> f64 {
        let (d_min, d_max) = (self.top - self.bottom, self.h);
        (self.distance_to_top(self.bottom, mu_s) - d_min) / (d_max - d_min)
    }

    /// The sun-angle coordinate in [0, 1] (before texel centring): dense near and below the
    /// horizon, where the light changes fastest; 0 at the zenith, 1 at [`MU_S_MIN`].
    pub fn x_mu_s(&self, mu_s: f64) -> f64 {
        let a = self.mu_s_a(mu_s);
        let big_a = self.mu_s_a(MU_S_MIN);
        ((1.0 - a / big_a).max(0.0) / (1.0 + a)).clamp(0.0, 1.0)
    }

    /// Inverse of [`Shell::x_mu_s`].
    pub fn mu_s_from_x(&self, x: f64) -> f64 {
        let (d_min, d_max) = (self.top - self.bottom, self.h);
        let big_a = self.mu_s_a(MU_S_MIN);
        let a = (big_a - x * big_a) / (1.0 + x * big_a);
        let d = d_min + a.min(big_a) * (d_max - d_min);
        if d == 0.0 {
            1.0
        } else {
            ((self.h * self.h - d * d) / (2.0 * self.bottom * d)).clamp(-1.0, 1.0)
        }
    }

    /// Inverse of [`Shell::scattering_uvw`]'s `u_mu` and `u_r` at texel centres: `(r, mu,
    /// hits_ground)`.
    pub fn scattering_r_mu(&self, u_mu: f64, u_r: f64, nmu: usize, nr: usize) -> (f64, f64, bool) {
        let rho = self.h * unit_from_coord(u_r, nr);
        let r = safe_sqrt(rho * rho + self.bottom * self.bottom);
        let half = nmu / 2;
        if u_mu < 0.5 {
            let x = unit_from_coord(1.0 - 2.0 * u_mu, half);
            let (d_min, d_max) = (r - self.bottom, rho);
            let d = d_min + x * (d_max - d_min);
            let mu = if d == 0.0 {
                -1.0
            } else {
                -(rho * rho + d * d) / (2.0 * r * d)
            };
            (r, mu.clamp(-1.0, 1.0), true)
        } else {
            let x = unit_from_coord(2.0 * u_mu - 1.0, half);
            let (d_min, d_max) = (self.top - r, rho + self.h);
            let d = d_min + x * (d_max - d_min);
            let mu = if d == 0.0 {
                1.0
            } else {
                (self.h * self.h - rho * rho - d * d) / (2.0 * r * d)
            };
            (r, mu.clamp(-1.0, 1.0), false)
        }
    }
}

impl Shell {
    /// How far a ray from (`r`, `mu`) travels inside the Earth's shadow before it leaves it, km,
    /// for a sun of zenith cosine `mu_s` at `nu` (cosine) from the ray: 0 when the start is lit.
    ///
    /// The shadow of a point sun is the half cylinder of the ground's radius behind the planet
    /// (`y·s < 0`, distance to the sun's axis under `bottom`). A ray starting inside it leaves it
    /// once (the region is convex) through the cylinder's side: above the ground, the plane
    /// `y·s = 0` lies inside the planet within the cylinder.
    pub fn shadow_length(&self, r: f64, mu: f64, mu_s: f64, nu: f64) -> f64 {
        let r2 = self.bottom * self.bottom;
        // The start x = r·up; its distance² to the sun's axis.
        let c = r * r * (1.0 - mu_s * mu_s) - r2;
        if mu_s >= 0.0 || c >= 0.0 {
            return 0.0;
        }
        // |y⊥(t)|² = |x⊥|² + 2t x⊥·v⊥ + t²|v⊥|², with x⊥·v⊥ = r(mu − mu_s nu), |v⊥|² = 1 − nu².
        let a = (1.0 - nu * nu).max(0.0);
        let b = r * (mu - mu_s * nu);
        if a <= 1e-12 {
            return if b > 0.0 {
                -c / (2.0 * b)
            } else {
                f64::INFINITY
            };
        }
        let t = (-b + (b * b - a * c).max(0.0).sqrt()) / a;
        t.max(0.0)
    }
}
