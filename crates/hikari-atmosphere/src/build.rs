//! Precomputation of the tables: transmittance, single scattering, then scattering orders 2..n
//! (Bruneton & Neyret 2008's iteration, without the azimuth dimension, as Elek 2009 and the talk).
//!
//! The scattering tables have no azimuth: every texel is computed in the geometry where the view
//! and the sun are 90° apart in azimuth (`ν = μ μ_s`), the middle of the azimuth range; the
//! phase functions restore the angle to the sun at run time. All quantities are per unit
//! extraterrestrial solar illuminance (so the tables read in sr⁻¹ and are scaled by the sun's
//! illuminance in lux when looked up).
//!
//! hikari-render builds the same tables on the GPU (`techniques/sky/tables.wgsl`, which mirrors
//! this file function by function in f32) and tests them against this build; a change here
//! needs the same change there.

use std::f64::consts::PI;

use crate::geometry::{Shell, coord_from_unit, unit_from_coord};
use crate::params::AtmosphereParams;
use crate::phase;
use crate::table::Table;

/// The azimuth term matches the sun's angle at this fraction of the texel's mean scattering
/// distance: the transmittance to the sun is exponential in that angle, so the light's centroid
/// overstates where matching helps most. Measured against `tools/atmosphere_reference.py`'s
/// three-channel single scattering (docs/atmosphere.md): 0.4, 0.5, 0.6, 0.7 give 40.6, 44.3,
/// 48.5, 48.1 dB for the sun at 90°, and leave 30–85° within 1 dB of each other.
pub const DISTANCE_SCALE: f64 = 0.6;
/// The same after the Earth's shadow moved the start of the ray (twilight): 0, 0.2, 0.4, 0.6
/// give 24.5, 29.2, 36.2, 29.9 dB for the sun at 95°.
pub const DISTANCE_SCALE_SHADOWED: f64 = 0.4;

/// Table resolutions.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct TableSizes {
    /// Transmittance: `[mu, r]`.
    pub transmittance: [usize; 2],
    /// Scattering and the irradiance tables: `[mu, mu_s, r]` (`mu` even).
    pub scattering: [usize; 3],
    /// The scattering density of the multiple-scattering iteration: `[mu, mu_s, r]`.
    pub density: [usize; 3],
    /// Sky irradiance on a horizontal plane: `[mu_s, r]`.
    pub ground_irradiance: [usize; 2],
    /// Steps along a ray when integrating scattering.
    pub ray_steps: usize,
    /// Directions over the sphere for the scattering density: `[theta, phi]`.
    pub sphere: [usize; 2],
}

impl Default for TableSizes {
    fn default() -> Self {
        Self {
            transmittance: [256, 64],
            scattering: [128, 32, 32],
            density: [32, 32, 32],
            ground_irradiance: [64, 16],
            ray_steps: 50,
            sphere: [16, 16],
        }
    }
}

/// What a build measured.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct BuildReport {
    /// Per scattering order (index 0 = single scattering): the order's summed luminance over
    /// every scattering texel, relative to the sum of all orders before it (1 for order 1).
    pub order_contributions: Vec<f64>,
    /// Wall time of the build, ms.
    pub build_ms: f64,
}

/// The precomputed tables, in the working colour space, per unit solar illuminance.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Tables {
    /// Transmittance to the top of the atmosphere (`[mu, r]`).
    pub transmittance: Table,
    /// Rayleigh inscattering divided by the Rayleigh phase, all orders (orders ≥ 2 divided by
    /// the phase at the table's own geometry), sr⁻¹ per unit solar illuminance (`[mu, mu_s, r]`).
    pub rayleigh: Table,
    /// Rayleigh single inscattering alone divided by the Rayleigh phase (`[mu, mu_s, r]`):
    /// `rayleigh − rayleigh_single` is the multiple scattering, which the run-time Earth-shadow
    /// and azimuth terms leave alone (see [`crate::Atmosphere::sky_radiance`]).
    pub rayleigh_single: Table,
    /// Mie single inscattering divided by the Mie phase (`[mu, mu_s, r]`).
    pub mie: Table,
    /// Where along each texel's ray the single scattering happens: the mean distance, km,
    /// weighted by the scattered light (middle channel), of Rayleigh (x) and Mie (y); z is 0
    /// (`[mu, mu_s, r]`). The run-time azimuth term reads it.
    pub scattering_distance: Table,
    /// Light at each point that Rayleigh scatters, divided by the Rayleigh phase, before the
    /// density and coefficient: the talk's parallel "irradiance" table, per unit solar
    /// illuminance (lux per lux) (`[mu, mu_s, r]`).
    pub irradiance_rayleigh: Table,
    /// The same for Mie.
    pub irradiance_mie: Table,
    /// Sky irradiance (no direct sun) on a horizontal plane (`[mu_s, r]`), per unit solar
    /// illuminance.
    pub ground_irradiance: Table,
    /// Resolutions used.
    pub sizes: TableSizes,
}

impl Tables {
    /// The tables' names, as `docs/atmosphere.md` lists them and `hikari sky --dump-table`
    /// takes them.
    pub const NAMES: [&'static str; 8] = [
        "transmittance",
        "rayleigh",
        "rayleigh_single",
        "mie",
        "scattering_distance",
        "irradiance_rayleigh",
        "irradiance_mie",
        "ground_irradiance",
    ];

    /// The table called `name` (one of [`Tables::NAMES`]), or `None`.
    pub fn by_name(&self, name: &str) -> Option<&Table> {
        Some(match name {
            "transmittance" => &self.transmittance,
            "rayleigh" => &self.rayleigh,
            "rayleigh_single" => &self.rayleigh_single,
            "mie" => &self.mie,
            "scattering_distance" => &self.scattering_distance,
            "irradiance_rayleigh" => &self.irradiance_rayleigh,
            "irradiance_mie" => &self.irradiance_mie,
            "ground_irradiance" => &self.ground_irradiance,
            _ => return None,
        })
    }
}

pub(crate) struct Ctx<'a> {
    pub p: &'a AtmosphereParams,
    pub shell: Shell,
    pub sizes: TableSizes,
    pub rayleigh: [f64; 3],
}

/// `exp(−∫ extinction)` from (`r`, `mu`) to the top by the trapezoid rule.
pub fn transmittance_to_top(p: &AtmosphereParams, r: f64, mu: f64, steps: usize) -> [f64; 3] {
    let shell = Shell::new(p.bottom_radius_km, p.top_radius_km);
    let d = shell.distance_to_top(r, mu);
    let dx = d / steps as f64;
    let mut tau = [0.0; 3];
    for i in 0..=steps {
        let di = i as f64 * dx;
        let ri = (di * di + 2.0 * r * mu * di + r * r).sqrt();
        let e = p.extinction(ri - p.bottom_radius_km);
        let w = if i == 0 || i == steps { 0.5 } else { 1.0 };
        for c in 0..3 {
            tau[c] += w * e[c] * dx;
        }
    }
    tau.map(|t| (-t).exp())
}

impl Ctx<'_> {
    pub fn trans_top(&self, t: &Table, r: f64, mu: f64) -> [f64; 3] {
        let [nmu, nr] = self.sizes.transmittance;
        let (u, v) = self.shell.transmittance_uv(r, mu, nmu, nr);
        t.sample(u, v, 0.5)
    }

    /// Transmittance to the sun (a point source): zero once the Earth hides it.
    pub fn trans_sun(&self, t: &Table, r: f64, mu_s: f64) -> [f64; 3] {
        if self.shell.hits_ground(r, mu_s) {
            [0.0; 3]
        } else {
            self.trans_top(t, r, mu_s)
        }
    }

    /// Transmittance over `d` km from (`r`, `mu`), as a ratio of two table lookups.
    pub fn trans_between(&self, t: &Table, r: f64, mu: f64, d: f64, hits_ground: bool) -> [f64; 3] {
        let (rd, mud) = self.shell.advance(r, mu, d);
        let (a, b) = if hits_ground {
            (self.trans_top(t, rd, -mud), self.trans_top(t, r, -mu))
        } else {
            (self.trans_top(t, r, mu), self.trans_top(t, rd, mud))
        };
        std::array::from_fn(|c| {
            if b[c] > 0.0 {
                (a[c] / b[c]).min(1.0)
            } else {
                0.0
            }
        })
    }

    pub fn scat_uvw(&self, r: f64, mu: f64, mu_s: f64) -> (f64, f64, f64) {
        let hits = self.shell.hits_ground(r, mu);
        self.shell
            .scattering_uvw(r, mu, mu_s, hits, self.sizes.scattering)
    }

    fn density_uvw(&self, r: f64, mu: f64, mu_s: f64) -> (f64, f64, f64) {
        let [nmu, nmus, nr] = self.sizes.density;
        let rho = (r * r - self.shell.bottom * self.shell.bottom)
            .max(0.0)
            .sqrt();
        (
            coord_from_unit(0.5 * (mu + 1.0), nmu),
            coord_from_unit(self.shell.x_mu_s(mu_s), nmus),
            coord_from_unit(rho / self.shell.h, nr),
        )
    }

    fn ground_uv(&self, r: f64, mu_s: f64) -> (f64, f64) {
        let [nmus, nr] = self.sizes.ground_irradiance;
        let s = &self.shell;
        (
            coord_from_unit(((mu_s + 0.2) / 1.2).clamp(0.0, 1.0), nmus),
            coord_from_unit(((r - s.bottom) / (s.top - s.bottom)).clamp(0.0, 1.0), nr),
        )
    }

    /// Single Rayleigh and Mie inscattering divided by their phases, from (`r`, `mu`) with the
    /// sun at (`mu_s`, `nu`), with the two run-time terms that stand in for the missing azimuth:
    ///
    /// * **Earth's shadow**: a ray that starts in the planet's shadow (twilight) sees no single
    ///   scattering until it leaves it, `l` km on ([`Shell::shadow_length`]); beyond, every point
    ///   is lit, so the light is `T(x, x_l) S(x_l)`: the table read at the exit point, times the
    ///   transmittance to it.
    /// * **Sun angle along the ray**: a texel holds the ray whose sun lies 90° away in azimuth,
    ///   along which the sun's zenith cosine at distance `d` is `(r mu_s + d mu mu_s) / r_d`;
    ///   along the true ray it is `(r mu_s + d nu) / r_d`. The table is read at the `mu_s'` that
    ///   makes the two agree at a distance `d_e` where the texel's light scatters
    ///   (`scattering_distance` times [`DISTANCE_SCALE`]): `mu_s' = (r mu_s + d_e nu) / (r +
    ///   d_e mu)`, separately for Rayleigh and Mie. Exact at `d_e`, first order around it.
    #[allow(clippy::too_many_arguments)]
    pub fn single_parts(
        &self,
        t: &Table,
        rayleigh_single: &Table,
        mie: &Table,
        distance: &Table,
        r: f64,
        mu: f64,
        mu_s: f64,
        nu: f64,
    ) -> ([f64; 3], [f64; 3]) {
        let shadow = self.shell.shadow_length(r, mu, mu_s, nu);
        let (r, mu, mu_s, tl) = if shadow > 0.0 {
            let hits = self.shell.hits_ground(r, mu);
            if !shadow.is_finite() || shadow >= self.shell.distance_to_boundary(r, mu, hits) {
                return ([0.0; 3], [0.0; 3]);
            }
            let (rl, mul) = self.shell.advance(r, mu, shadow);
            let mu_sl = ((r * mu_s + shadow * nu) / rl).clamp(-1.0, 1.0);
            (rl, mul, mu_sl, self.trans_between(t, r, mu, shadow, hits))
        } else {
            (r, mu, mu_s, [1.0; 3])
        };
        let (u, v, w) = self.scat_uvw(r, mu, mu_s);
        let k = if shadow > 0.0 {
            DISTANCE_SCALE_SHADOWED
        } else {
            DISTANCE_SCALE
        };
        let de = distance.sample(u, v, w).map(|d| d * k);
        let at = |table: &Table, d: f64| {
            let shifted = ((r * mu_s + d * nu) / (r + d * mu).max(1.0)).clamp(-1.0, 1.0);
            let (u, v, w) = self.scat_uvw(r, mu, shifted);
            mul(table.sample(u, v, w), tl)
        };
        (at(rayleigh_single, de[0]), at(mie, de[1]))
    }

    pub fn ground_irradiance(&self, e: &Table, r: f64, mu_s: f64) -> [f64; 3] {
        let (u, v) = self.ground_uv(r, mu_s);
        e.sample(u, v, 0.5)
    }
}

/// Radiance of the previous order arriving at a point, as a function of direction.
enum Previous<'a> {
    Single {
        rayleigh: &'a Table,
        mie: &'a Table,
        distance: &'a Table,
        transmittance: &'a Table,
    },
    Multiple(&'a Table),
}

/// What lights the ground for the ground-reflection term of an order.
enum GroundLight<'a> {
    DirectSun,
    Sky(&'a Table),
}

fn add(a: &mut [f64; 3], b: [f64; 3], w: f64) {
    for c in 0..3 {
        a[c] += w * b[c];
    }
}

fn mul(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    std::array::from_fn(|c| a[c] * b[c])
}

/// A local frame with the zenith on +z, the view in the x-z plane and the sun in the y-z plane
/// (azimuths 90° apart).
fn frame(mu: f64, mu_s: f64) -> ([f64; 3], [f64; 3]) {
    let view = [(1.0 - mu * mu).max(0.0).sqrt(), 0.0, mu];
    let sun = [0.0, (1.0 - mu_s * mu_s).max(0.0).sqrt(), mu_s];
    (view, sun)
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

impl Ctx<'_> {
    fn previous_radiance(&self, prev: &Previous, r: f64, mu: f64, mu_s: f64, nu: f64) -> [f64; 3] {
        let (u, v, w) = self.scat_uvw(r, mu, mu_s);
        match prev {
            Previous::Single {
                rayleigh,
                mie,
                distance,
                transmittance,
            } => {
                let (pr, pm) = (
                    phase::rayleigh(nu),
                    phase::cornette_shanks(nu, self.p.mie_g),
                );
                let (a, b) =
                    self.single_parts(transmittance, rayleigh, mie, distance, r, mu, mu_s, nu);
                std::array::from_fn(|c| a[c] * pr + b[c] * pm)
            }
            Previous::Multiple(t) => t.sample(u, v, w),
        }
    }

    /// `∫ L_prev(ω_i) p(ω_i · ω) dω_i` for Rayleigh and Mie at (`r`, `mu`, `mu_s`), including the
    /// light the ground reflects.
    fn scattered_light(
        &self,
        t: &Table,
        prev: &Previous,
        ground: &GroundLight,
        r: f64,
        mu: f64,
        mu_s: f64,
    ) -> ([f64; 3], [f64; 3]) {
        let (view, sun) = frame(mu, mu_s);
        let [nt, np] = self.sizes.sphere;
        let (dt, dp) = (PI / nt as f64, 2.0 * PI / np as f64);
        let (mut jr, mut jm) = ([0.0; 3], [0.0; 3]);
        for it in 0..nt {
            let theta = (it as f64 + 0.5) * dt;
            let (st, ct) = theta.sin_cos();
            for ip in 0..np {
                let phi = (ip as f64 + 0.5) * dp;
                let dir = [st * phi.cos(), st * phi.sin(), ct];
                let nu_i = dot(dir, sun);
                let mut l = self.previous_radiance(prev, r, ct, mu_s, nu_i);
                if self.shell.hits_ground(r, ct) {
                    let d = self.shell.distance_to_bottom(r, ct);
                    let g = [d * dir[0], d * dir[1], r + d * dir[2]];
                    let rg = (dot(g, g)).sqrt();
                    let mu_s_g = dot(g, sun) / rg;
                    let e = match ground {
                        GroundLight::DirectSun => {
                            let ts = self.trans_sun(t, self.shell.bottom, mu_s_g);
                            ts.map(|v| v * mu_s_g.max(0.0))
                        }
                        GroundLight::Sky(e) => self.ground_irradiance(e, self.shell.bottom, mu_s_g),
                    };
                    let tg = self.trans_between(t, r, ct, d, true);
                    add(&mut l, mul(tg, e), self.p.ground_albedo / PI);
                }
                let cos = dot(dir, view);
                let dw = st * dt * dp;
                add(&mut jr, l, dw * phase::rayleigh(cos));
                add(&mut jm, l, dw * phase::cornette_shanks(cos, self.p.mie_g));
            }
        }
        (jr, jm)
    }

    /// Sky irradiance on a horizontal plane from the radiance of one order.
    fn hemisphere_irradiance(&self, prev: &Previous, r: f64, mu_s: f64) -> [f64; 3] {
        let [nt, np] = self.sizes.sphere;
        let (dt, dp) = (0.5 * PI / nt as f64, 2.0 * PI / np as f64);
        let sun = [0.0, (1.0 - mu_s * mu_s).max(0.0).sqrt(), mu_s];
        let mut e = [0.0; 3];
        for it in 0..nt {
            let theta = (it as f64 + 0.5) * dt;
            let (st, ct) = theta.sin_cos();
            for ip in 0..np {
                let phi = (ip as f64 + 0.5) * dp;
                let dir = [st * phi.cos(), st * phi.sin(), ct];
                let l = self.previous_radiance(prev, r, ct, mu_s, dot(dir, sun));
                add(&mut e, l, ct * st * dt * dp);
            }
        }
        e
    }

    fn ground_table(&self, prev: &Previous) -> Table {
        let [nmus, nr] = self.sizes.ground_irradiance;
        let s = self.shell;
        Table::from_fn([nmus, nr, 1], |x, y, _| {
            let mu_s = -0.2 + 1.2 * unit_from_coord((x as f64 + 0.5) / nmus as f64, nmus);
            let r =
                s.bottom + (s.top - s.bottom) * unit_from_coord((y as f64 + 0.5) / nr as f64, nr);
            self.hemisphere_irradiance(prev, r, mu_s)
        })
    }

    /// The (r, mu, mu_s, hits_ground) of a scattering texel.
    fn scat_texel(&self, x: usize, y: usize, z: usize) -> (f64, f64, f64, bool) {
        let [nmu, nmus, nr] = self.sizes.scattering;
        let (r, mu, hits) = self.shell.scattering_r_mu(
            (x as f64 + 0.5) / nmu as f64,
            (z as f64 + 0.5) / nr as f64,
            nmu,
            nr,
        );
        let mu_s = self
            .shell
            .mu_s_from_x(unit_from_coord((y as f64 + 0.5) / nmus as f64, nmus));
        (r, mu, mu_s, hits)
    }

    /// Integrates `T(x, y) · source(y)` along the texel's view ray (trapezoid rule); also the
    /// integrals of the distance times the middle channel of each.
    fn integrate_ray(
        &self,
        t: &Table,
        (r, mu, mu_s, hits): (f64, f64, f64, bool),
        source: impl Fn(f64, f64, f64) -> ([f64; 3], [f64; 3]),
    ) -> ([f64; 3], [f64; 3], [f64; 2]) {
        let n = self.sizes.ray_steps;
        let d_end = self.shell.distance_to_boundary(r, mu, hits);
        let dx = d_end / n as f64;
        let nu = mu * mu_s;
        let (mut a, mut b, mut db) = ([0.0; 3], [0.0; 3], [0.0; 2]);
        for i in 0..=n {
            let d = i as f64 * dx;
            let (rd, mud) = self.shell.advance(r, mu, d);
            let mu_s_d = ((r * mu_s + d * nu) / rd).clamp(-1.0, 1.0);
            let tv = self.trans_between(t, r, mu, d, hits);
            let (sa, sb) = source(rd, mud, mu_s_d);
            let w = if i == 0 || i == n { 0.5 * dx } else { dx };
            add(&mut a, mul(tv, sa), w);
            add(&mut b, mul(tv, sb), w);
            db[0] += w * d * tv[1] * sa[1];
            db[1] += w * d * tv[1] * sb[1];
        }
        (a, b, db)
    }
}

fn luminance_sum(table: &Table, to_rec709: &[[f64; 3]; 3], scale: impl Fn(usize) -> f64) -> f64 {
    let y = hikari_math::color::REC709_LUMA.map(f64::from);
    let wy: [f64; 3] = std::array::from_fn(|c| (0..3).map(|k| y[k] * to_rec709[k][c]).sum());
    table
        .data
        .iter()
        .enumerate()
        .map(|(i, v)| scale(i) * (0..3).map(|c| wy[c] * f64::from(v[c])).sum::<f64>())
        .sum()
}

/// Builds every table for validated parameters.
pub fn build(p: &AtmosphereParams, sizes: TableSizes) -> (Tables, BuildReport) {
    let start = std::time::Instant::now();
    let ctx = Ctx {
        p,
        shell: Shell::new(p.bottom_radius_km, p.top_radius_km),
        sizes,
        rayleigh: p.rayleigh(),
    };
    let [tmu, tr] = sizes.transmittance;
    let transmittance = Table::from_fn([tmu, tr, 1], |x, y, _| {
        let (r, mu) = ctx.shell.transmittance_r_mu(
            unit_from_coord((x as f64 + 0.5) / tmu as f64, tmu),
            unit_from_coord((y as f64 + 0.5) / tr as f64, tr),
        );
        transmittance_to_top(p, r, mu, 500)
    });
    let t = &transmittance;
    let ss = sizes.scattering;
    let h = |r: f64| r - p.bottom_radius_km;

    // Order 1: sunlight scattered once, divided by the phase functions.
    let single: Vec<([f64; 3], [f64; 3], [f64; 2])> =
        crate::parallel::map(ss.iter().product(), |i| {
            let texel = ctx.scat_texel(i % ss[0], (i / ss[0]) % ss[1], i / (ss[0] * ss[1]));
            ctx.integrate_ray(t, texel, |rd, _mud, mu_s_d| {
                let ts = ctx.trans_sun(t, rd, mu_s_d);
                let [dr, dm, _] = p.densities(h(rd));
                (
                    std::array::from_fn(|c| ts[c] * dr * ctx.rayleigh[c]),
                    ts.map(|v| v * dm * p.mie_scattering_per_km),
                )
            })
        });
    let as_table = |v: Vec<[f64; 3]>| Table {
        size: ss,
        data: v.into_iter().map(|a| a.map(|x| x as f32)).collect(),
    };
    let rayleigh_single = as_table(single.iter().map(|s| s.0).collect());
    let mie = as_table(single.iter().map(|s| s.1).collect());
    let mean = |sum: f64, weight: f64| if weight > 0.0 { sum / weight } else { 0.0 };
    let scattering_distance = as_table(
        single
            .iter()
            .map(|s| [mean(s.2[0], s.0[1]), mean(s.2[1], s.1[1]), 0.0])
            .collect(),
    );
    let nu0 = |i: usize| {
        let (_, mu, mu_s, _) = ctx.scat_texel(i % ss[0], (i / ss[0]) % ss[1], i / (ss[0] * ss[1]));
        mu * mu_s
    };
    let to709 = p.color_space.to_rec709();
    let single_lum = luminance_sum(&rayleigh_single, &to709, |i| phase::rayleigh(nu0(i)))
        + luminance_sum(&mie, &to709, |i| phase::cornette_shanks(nu0(i), p.mie_g));

    let first = Previous::Single {
        rayleigh: &rayleigh_single,
        mie: &mie,
        distance: &scattering_distance,
        transmittance: t,
    };
    let mut ground_orders = vec![ctx.ground_table(&first)];
    let mut multiple_sum = vec![[0.0f64; 3]; ss.iter().product()];
    let sd = sizes.density;
    let mut light_r = vec![[0.0f64; 3]; sd.iter().product()];
    let mut light_m = light_r.clone();
    let mut contributions = vec![1.0];
    let mut total_lum = single_lum;
    let mut delta: Option<Table> = None;
    for order in 2..=p.max_scattering_orders as usize {
        let prev = match &delta {
            None => Previous::Single {
                rayleigh: &rayleigh_single,
                mie: &mie,
                distance: &scattering_distance,
                transmittance: t,
            },
            Some(d) => Previous::Multiple(d),
        };
        let ground = if order == 2 {
            GroundLight::DirectSun
        } else {
            GroundLight::Sky(&ground_orders[order - 3])
        };
        let light = crate::parallel::map(sd.iter().product(), |i| {
            let (x, y, z) = (i % sd[0], (i / sd[0]) % sd[1], i / (sd[0] * sd[1]));
            let mu = 2.0 * unit_from_coord((x as f64 + 0.5) / sd[0] as f64, sd[0]) - 1.0;
            let mu_s = ctx
                .shell
                .mu_s_from_x(unit_from_coord((y as f64 + 0.5) / sd[1] as f64, sd[1]));
            let rho = ctx.shell.h * unit_from_coord((z as f64 + 0.5) / sd[2] as f64, sd[2]);
            let r = (rho * rho + p.bottom_radius_km * p.bottom_radius_km).sqrt();
            ctx.scattered_light(t, &prev, &ground, r, mu, mu_s)
        });
        for (i, (a, b)) in light.iter().enumerate() {
            add(&mut light_r[i], *a, 1.0);
            add(&mut light_m[i], *b, 1.0);
        }
        let jr = Table {
            size: sd,
            data: light.iter().map(|l| l.0.map(|v| v as f32)).collect(),
        };
        let jm = Table {
            size: sd,
            data: light.iter().map(|l| l.1.map(|v| v as f32)).collect(),
        };
        let radiance = crate::parallel::map(ss.iter().product(), |i| {
            let texel = ctx.scat_texel(i % ss[0], (i / ss[0]) % ss[1], i / (ss[0] * ss[1]));
            ctx.integrate_ray(t, texel, |rd, mud, mu_s_d| {
                let (u, v, w) = ctx.density_uvw(rd, mud, mu_s_d);
                let [dr, dm, _] = p.densities(h(rd));
                let (a, b) = (jr.sample(u, v, w), jm.sample(u, v, w));
                (
                    std::array::from_fn(|c| {
                        a[c] * dr * ctx.rayleigh[c] + b[c] * dm * p.mie_scattering_per_km
                    }),
                    [0.0; 3],
                )
            })
            .0
        });
        let d = as_table(radiance);
        for (acc, v) in multiple_sum.iter_mut().zip(&d.data) {
            add(acc, v.map(f64::from), 1.0);
        }
        let lum = luminance_sum(&d, &to709, |_| 1.0);
        contributions.push(if total_lum > 0.0 {
            lum / total_lum
        } else {
            0.0
        });
        total_lum += lum;
        ground_orders.push(ctx.ground_table(&Previous::Multiple(&d)));
        delta = Some(d);
        if order >= 4 && *contributions.last().unwrap_or(&0.0) < 0.01 {
            break;
        }
    }

    let rayleigh = Table {
        size: ss,
        data: (0..multiple_sum.len())
            .map(|i| {
                let pr = phase::rayleigh(nu0(i));
                let s = rayleigh_single.data[i];
                std::array::from_fn(|c| (f64::from(s[c]) + multiple_sum[i][c] / pr) as f32)
            })
            .collect(),
    };
    let jr_sum = Table {
        size: sd,
        data: light_r.iter().map(|v| v.map(|x| x as f32)).collect(),
    };
    let jm_sum = Table {
        size: sd,
        data: light_m.iter().map(|v| v.map(|x| x as f32)).collect(),
    };
    let irradiance = |sum: &Table, phase_fn: &(dyn Fn(f64) -> f64 + Sync)| {
        Table::from_fn(ss, |x, y, z| {
            let (r, mu, mu_s, _) = ctx.scat_texel(x, y, z);
            let direct = ctx.trans_sun(t, r, mu_s);
            let (u, v, w) = ctx.density_uvw(r, mu, mu_s);
            let ms = sum.sample(u, v, w);
            let ph = phase_fn(mu * mu_s);
            std::array::from_fn(|c| direct[c] + ms[c] / ph)
        })
    };
    let irradiance_rayleigh = irradiance(&jr_sum, &phase::rayleigh);
    let irradiance_mie = irradiance(&jm_sum, &|nu| phase::cornette_shanks(nu, p.mie_g));
    let mut ground_irradiance = ground_orders[0].clone();
    for g in &ground_orders[1..] {
        for (a, b) in ground_irradiance.data.iter_mut().zip(&g.data) {
            for c in 0..3 {
                a[c] += b[c];
            }
        }
    }
    let tables = Tables {
        transmittance,
        rayleigh,
        rayleigh_single,
        mie,
        scattering_distance,
        irradiance_rayleigh,
        irradiance_mie,
        ground_irradiance,
        sizes,
    };
    let report = BuildReport {
        order_contributions: contributions,
        build_ms: start.elapsed().as_secs_f64() * 1e3,
    };
    (tables, report)
}
