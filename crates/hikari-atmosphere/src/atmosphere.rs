//! The built atmosphere and its run-time lookups (what the GPU twin will mirror).
//!
//! Directions are world-space unit vectors with +Y up (the glTF convention the renderer uses);
//! altitudes in km above the ground; illuminance in lux; radiance in nits (cd m⁻² sr⁻¹ per lux
//! of the light, i.e. lux sr⁻¹). Inputs and outputs are linear Rec.709 unless a name says
//! "working": the tables live in the working space ([`crate::ColorSpace`]).

use glam::Vec3;

use crate::build::{BuildReport, Ctx, TableSizes, Tables, build};
use crate::geometry::Shell;
use crate::params::AtmosphereParams;
use crate::{AtmosphereError, phase};

/// Parameters plus their precomputed tables.
#[derive(Clone, Debug)]
pub struct Atmosphere {
    /// The validated parameters.
    pub params: AtmosphereParams,
    /// The tables (working space, per unit solar illuminance).
    pub tables: Tables,
    /// What the build measured (per-order contributions, time).
    pub report: BuildReport,
    to709: [[f64; 3]; 3],
    from709: [[f64; 3]; 3],
}

fn mat(m: &[[f64; 3]; 3], v: [f64; 3]) -> [f64; 3] {
    std::array::from_fn(|r| m[r][0] * v[0] + m[r][1] * v[1] + m[r][2] * v[2])
}

fn finite_or_zero(v: [f64; 3]) -> Vec3 {
    Vec3::from_array(v.map(|x| if x.is_finite() { x as f32 } else { 0.0 }))
}

impl Atmosphere {
    /// Validates `params` and builds every table at the default sizes.
    pub fn new(params: AtmosphereParams) -> Result<Self, AtmosphereError> {
        Self::with_sizes(params, TableSizes::default())
    }

    /// [`Atmosphere::with_sizes`], built once and shared while the same parameters and sizes are
    /// asked for: the last two builds are kept, so alternating between two weathers (or a
    /// renderer and the `hikari sky` command in one process) does not rebuild. A table build
    /// is a pure function of its inputs, so every caller may share one.
    pub fn shared(
        params: &AtmosphereParams,
        sizes: TableSizes,
    ) -> Result<std::sync::Arc<Self>, AtmosphereError> {
        use std::sync::{Arc, Mutex};
        type Cache = Vec<(AtmosphereParams, TableSizes, Arc<Atmosphere>)>;
        static CACHE: Mutex<Cache> = Mutex::new(Vec::new());
        let mut cache = CACHE.lock().unwrap_or_else(|e| e.into_inner());
        if let Some((_, _, a)) = cache.iter().find(|(p, s, _)| p == params && *s == sizes) {
            return Ok(a.clone());
        }
        let a = Arc::new(Self::with_sizes(params.clone(), sizes)?);
        cache.push((params.clone(), sizes, a.clone()));
        if cache.len() > 2 {
            cache.remove(0);
        }
        Ok(a)
    }

    /// The same with chosen table sizes.
    pub fn with_sizes(
        params: AtmosphereParams,
        sizes: TableSizes,
    ) -> Result<Self, AtmosphereError> {
        params.validate()?;
        for (field, ok) in [
            (
                "sizes.transmittance",
                sizes.transmittance.iter().all(|&n| (2..=4096).contains(&n)),
            ),
            (
                "sizes.scattering",
                sizes.scattering.iter().all(|&n| (2..=1024).contains(&n))
                    && sizes.scattering[0].is_multiple_of(2),
            ),
            (
                "sizes.density",
                sizes.density.iter().all(|&n| (2..=1024).contains(&n)),
            ),
            (
                "sizes.ground_irradiance",
                sizes
                    .ground_irradiance
                    .iter()
                    .all(|&n| (2..=4096).contains(&n)),
            ),
            ("sizes.ray_steps", (1..=10_000).contains(&sizes.ray_steps)),
            (
                "sizes.sphere",
                sizes.sphere.iter().all(|&n| (1..=1024).contains(&n)),
            ),
        ] {
            if !ok {
                return Err(AtmosphereError::OutOfRange {
                    field,
                    value: f64::NAN,
                    allowed: "texel counts in [2, 1024] (4096 for 2D tables), scattering mu even; steps >= 1",
                });
            }
        }
        let (tables, report) = build(&params, sizes);
        let (to709, from709) = (
            params.color_space.to_rec709(),
            params.color_space.from_rec709(),
        );
        Ok(Self {
            params,
            tables,
            report,
            to709,
            from709,
        })
    }

    fn ctx(&self) -> Ctx<'_> {
        Ctx {
            p: &self.params,
            shell: self.shell(),
            sizes: self.tables.sizes,
            rayleigh: self.params.rayleigh(),
        }
    }

    fn shell(&self) -> Shell {
        Shell::new(self.params.bottom_radius_km, self.params.top_radius_km)
    }

    /// Linear Rec.709 → working space.
    pub fn to_working(&self, rgb: Vec3) -> [f64; 3] {
        mat(&self.from709, rgb.as_dvec3().to_array())
    }

    /// Working space → linear Rec.709.
    pub fn to_rec709(&self, v: [f64; 3]) -> Vec3 {
        finite_or_zero(mat(&self.to709, v))
    }

    /// Transmittance from `altitude_km` along a ray of zenith cosine `cos_zenith` to space, per
    /// working-space channel (0 where the ray hits the ground). Bilinear in the table.
    pub fn transmittance(&self, altitude_km: f32, cos_zenith: f32) -> [f64; 3] {
        let r = self.radius(altitude_km);
        self.ctx().trans_sun(
            &self.tables.transmittance,
            r,
            f64::from(cos_zenith).clamp(-1.0, 1.0),
        )
    }

    /// `light_rec709` (lux or nits, linear Rec.709) after the path from `altitude_km` to space
    /// along `cos_zenith`, in linear Rec.709: the filter is applied in the working space.
    pub fn attenuate(&self, altitude_km: f32, cos_zenith: f32, light_rec709: Vec3) -> Vec3 {
        let t = self.transmittance(altitude_km, cos_zenith);
        let l = self.to_working(light_rec709);
        self.to_rec709(std::array::from_fn(|c| t[c] * l[c]))
    }

    /// The extraterrestrial sun (D65 white, [`AtmosphereParams::solar_illuminance_lux`]) as
    /// linear Rec.709 lux.
    pub fn solar_illuminance(&self) -> Vec3 {
        Vec3::splat(self.params.solar_illuminance_lux as f32)
    }

    /// The sun's illuminance at the ground on a plane facing it, linear Rec.709 lux, for the sun
    /// `sun_zenith_rad` from the zenith (0 once it is below the horizon; a point sun).
    pub fn sun_illuminance_at_ground(&self, sun_zenith_rad: f32) -> Vec3 {
        self.attenuate(0.0, sun_zenith_rad.cos(), self.solar_illuminance())
    }

    fn radius(&self, altitude_km: f32) -> f64 {
        let a = f64::from(altitude_km);
        let a = if a.is_finite() { a } else { 0.0 };
        (self.params.bottom_radius_km + a.max(0.0)).max(self.params.bottom_radius_km + 1e-4)
    }

    /// Inscattered sky radiance (nits, linear Rec.709) seen from `altitude_km` looking along
    /// `view_dir`, lit by a light in `sun_dir` whose extraterrestrial illuminance is
    /// `sun_illuminance` (linear Rec.709 lux). The sun's disk and the ground's own reflected light
    /// are not included. Trilinear in the tables; the phase functions at the true angle between
    /// view and sun. A camera above the atmosphere is moved to where the view ray enters it.
    pub fn sky_radiance(
        &self,
        altitude_km: f32,
        view_dir: Vec3,
        sun_dir: Vec3,
        sun_illuminance: Vec3,
    ) -> Vec3 {
        let [rgb, _, _] = self.sky_radiance_parts(altitude_km, view_dir, sun_dir);
        let e = self.to_working(sun_illuminance);
        self.to_rec709(std::array::from_fn(|c| rgb[c] * e[c]))
    }

    /// Working-space sky radiance per unit sun illuminance, and the Rayleigh and Mie table values
    /// (divided by their phases) it came from.
    pub fn sky_radiance_parts(
        &self,
        altitude_km: f32,
        view_dir: Vec3,
        sun_dir: Vec3,
    ) -> [[f64; 3]; 3] {
        let v = view_dir.as_dvec3().normalize_or_zero();
        let s = sun_dir.as_dvec3().normalize_or_zero();
        if v == glam::DVec3::ZERO || s == glam::DVec3::ZERO {
            return [[0.0; 3]; 3];
        }
        let shell = self.shell();
        let mut r = self.radius(altitude_km);
        let mut mu = v.y;
        let mut mu_s = s.y;
        let nu = v.dot(s);
        if r > shell.top {
            // Enter the atmosphere along the view ray, if it does at all.
            let b = r * mu;
            let disc = b * b - r * r + shell.top * shell.top;
            if disc < 0.0 || -b - disc.sqrt() < 0.0 {
                return [[0.0; 3]; 3];
            }
            let d = -b - disc.sqrt();
            let p = glam::DVec3::new(0.0, r, 0.0) + v * d;
            let up = p.normalize();
            r = shell.top;
            mu = v.dot(up);
            mu_s = s.dot(up);
        }
        let ctx = self.ctx();
        let tables = &self.tables;
        let (a, b, c) = ctx.scat_uvw(r, mu, mu_s);
        let all = tables.rayleigh.sample(a, b, c);
        let single = tables.rayleigh_single.sample(a, b, c);
        let (single_r, mie) = ctx.single_parts(
            &tables.transmittance,
            &tables.rayleigh_single,
            &tables.mie,
            &tables.scattering_distance,
            r,
            mu,
            mu_s,
            nu,
        );
        let ray: [f64; 3] = std::array::from_fn(|k| all[k] - single[k] + single_r[k]);
        let (pr, pm) = (
            phase::rayleigh(nu),
            phase::cornette_shanks(nu, self.params.mie_g),
        );
        [std::array::from_fn(|k| ray[k] * pr + mie[k] * pm), ray, mie]
    }

    /// Single Rayleigh and Mie inscattering divided by their phases (working space, per unit
    /// sun illuminance, sr⁻¹) from radius `r_km` (from the planet's centre) along a ray of
    /// zenith cosine `mu`, for a light of zenith cosine `mu_s` at cosine `nu` from the ray, with
    /// the run-time Earth-shadow and azimuth terms that [`Atmosphere::sky_radiance`] applies
    /// (docs/atmosphere.md, *Run-time azimuth terms*). The frame's sky (hikari-render's
    /// `lookup.wgsl` and its CPU twin) adds these to the multiple scattering
    /// (`rayleigh − rayleigh_single`) read without them.
    pub fn single_scattering(
        &self,
        r_km: f64,
        mu: f64,
        mu_s: f64,
        nu: f64,
    ) -> ([f64; 3], [f64; 3]) {
        let t = &self.tables;
        self.ctx().single_parts(
            &t.transmittance,
            &t.rayleigh_single,
            &t.mie,
            &t.scattering_distance,
            r_km,
            mu.clamp(-1.0, 1.0),
            mu_s.clamp(-1.0, 1.0),
            nu.clamp(-1.0, 1.0),
        )
    }

    /// The talk's "irradiance" tables at a point: light that Rayleigh and Mie scatter toward
    /// `view_dir` divided by their phases, before density (working space, per unit sun
    /// illuminance, lux per lux). Multiply by `β ρ(h) p(ν)` and the sun's illuminance.
    pub fn scattering_irradiance(
        &self,
        altitude_km: f32,
        view_dir: Vec3,
        sun_dir: Vec3,
    ) -> ([f64; 3], [f64; 3]) {
        let ctx = self.ctx();
        let r = self.radius(altitude_km).min(self.params.top_radius_km);
        let v = view_dir.as_dvec3().normalize_or_zero();
        let s = sun_dir.as_dvec3().normalize_or_zero();
        let (a, b, c) = ctx.scat_uvw(r, v.y, s.y);
        (
            self.tables.irradiance_rayleigh.sample(a, b, c),
            self.tables.irradiance_mie.sample(a, b, c),
        )
    }

    /// Sky irradiance (no direct sun) on a horizontal plane at `altitude_km`, linear Rec.709 lux,
    /// for a sun `sun_zenith_rad` from the zenith whose extraterrestrial illuminance is
    /// `sun_illuminance` (Rec.709 lux).
    pub fn sky_irradiance(
        &self,
        altitude_km: f32,
        sun_zenith_rad: f32,
        sun_illuminance: Vec3,
    ) -> Vec3 {
        let r = self.radius(altitude_km).min(self.params.top_radius_km);
        let e = self.ctx().ground_irradiance(
            &self.tables.ground_irradiance,
            r,
            f64::from(sun_zenith_rad.cos()),
        );
        let l = self.to_working(sun_illuminance);
        self.to_rec709(std::array::from_fn(|c| e[c] * l[c]))
    }
}
