//! CPU twin of the sky's passes, built on hikari-atmosphere's own table mapping
//! (`Shell::scattering_uvw`, `Table::sample`) rather than a transcription of the shaders, and
//! on hikari-math's SH projection and deringing. Also what the `hikari sky` command draws with.

use glam::{DVec3, Vec3};

use hikari_atmosphere::geometry::Shell;
use hikari_atmosphere::table::Table;
use hikari_atmosphere::{Atmosphere, phase};
use hikari_math::sh::{Sh, basis, dering};

use super::SkyParams;

/// Directions the SH projection samples (as `sh.wgsl`).
pub const SH_SAMPLES: u32 = 4096;

/// Catmull-Rom weights of the four texels around fraction `f`.
pub fn catmull_rom(f: f64) -> [f64; 4] {
    let (f2, f3) = (f * f, f * f * f);
    [
        -0.5 * f3 + f2 - 0.5 * f,
        1.5 * f3 - 2.5 * f2 + 1.0,
        -1.5 * f3 + 2.0 * f2 + 0.5 * f,
        0.5 * f3 - 0.5 * f2,
    ]
}

/// `sky.resample` for one table: [mu, mu_s, r] at texel coordinate `t` along mu_s (t = u n −
/// 0.5), cubic, negative values clamped to 0, into a [mu, r] table. With `minus`, the
/// difference `table − minus` is resampled (the pass resamples `rayleigh − rayleigh_single`,
/// the multiple scattering).
pub fn resample(table: &Table, minus: Option<&Table>, t: f32) -> Table {
    let [nmu, nmus, nr] = table.size;
    let t = f64::from(t).clamp(0.0, (nmus - 1) as f64);
    let i = t.floor() as isize;
    let w = catmull_rom(t - i as f64);
    let mut data = Vec::with_capacity(nmu * nr);
    for r in 0..nr {
        for mu in 0..nmu {
            let mut sum = [0.0f64; 3];
            for (k, wk) in w.iter().enumerate() {
                let j = (i - 1 + k as isize).clamp(0, nmus as isize - 1) as usize;
                let v = table.at(mu, j, r);
                let m = minus.map_or([0.0; 3], |m| m.at(mu, j, r));
                for c in 0..3 {
                    sum[c] += wk * (v[c] - m[c]);
                }
            }
            data.push(sum.map(|v| v.max(0.0) as f32));
        }
    }
    Table {
        size: [nmu, nr, 1],
        data,
    }
}

/// The sky of one frame on the CPU: the parameters and the resampled multiple scattering.
pub struct SkyTwin<'a> {
    pub atmosphere: &'a Atmosphere,
    pub params: SkyParams,
    /// The multiple scattering (`rayleigh − rayleigh_single`) at the sun's and at the moon's
    /// angle.
    pub layers: [Table; 2],
}

fn v3(a: [f32; 4]) -> Vec3 {
    Vec3::new(a[0], a[1], a[2])
}

impl<'a> SkyTwin<'a> {
    pub fn new(atmosphere: &'a Atmosphere, params: SkyParams) -> Self {
        let t = &atmosphere.tables;
        let (cs, cm) = (params.light_coords[0], params.light_coords[1]);
        Self {
            atmosphere,
            params,
            layers: [
                resample(&t.rayleigh, Some(&t.rayleigh_single), cs),
                resample(&t.rayleigh, Some(&t.rayleigh_single), cm),
            ],
        }
    }

    fn shell(&self) -> Shell {
        let p = &self.atmosphere.params;
        Shell::new(p.bottom_radius_km, p.top_radius_km)
    }

    fn radius(&self) -> f64 {
        let s = self.params.shell;
        f64::from(s[0]) + f64::from(s[3]).clamp(0.0, f64::from(s[1]) - f64::from(s[0]) - 1e-3)
    }

    /// `sky_inscatter`: Rec.709 nits from direction `dir`, without the disks or the ground: the
    /// resampled multiple scattering plus the single scattering with the Earth-shadow and
    /// azimuth terms, read by hikari-atmosphere's own [`Atmosphere::single_scattering`].
    pub fn inscatter(&self, dir: Vec3) -> Vec3 {
        let d = dir.as_dvec3().normalize();
        let shell = self.shell();
        let r = self.radius();
        let mu = d.y.clamp(-1.0, 1.0);
        let sizes = self.atmosphere.tables.sizes.scattering;
        let (u_mu, _, u_r) = shell.scattering_uvw(r, mu, 0.0, shell.hits_ground(r, mu), sizes);
        let g = self.atmosphere.params.mie_g;
        let white = self.atmosphere.to_working(Vec3::ONE);
        let mut working = [0.0f64; 3];
        for (k, light) in [self.params.sun, self.params.moon].iter().enumerate() {
            if light[3] <= 0.0 {
                continue;
            }
            let l = v3(*light).as_dvec3();
            let nu = d.dot(l).clamp(-1.0, 1.0);
            let multiple = self.layers[k].sample(u_mu, u_r, 0.5);
            let (single, mie) = self.atmosphere.single_scattering(r, mu, l.y, nu);
            let (pr, pm) = (phase::rayleigh(nu), phase::cornette_shanks(nu, g));
            for c in 0..3 {
                let ray = multiple[c] + single[c];
                working[c] += (ray * pr + mie[c] * pm) * white[c] * f64::from(light[3]);
            }
        }
        self.atmosphere.to_rec709(working).max(Vec3::ZERO) * self.params.light_coords[2]
    }

    /// `sky_ground`: the ground's radiance seen along `dir` (below the horizon) through the
    /// air between it and the camera.
    pub fn ground(&self, dir: Vec3) -> Vec3 {
        let up = (-dir.y).clamp(1e-4, 1.0);
        let alt = self.params.shell[3];
        let (below, above) = (
            self.atmosphere.transmittance(0.0, up),
            self.atmosphere.transmittance(alt, up),
        );
        let g = self.params.ground;
        let w: [f64; 3] = std::array::from_fn(|c| {
            let t = if above[c] > 0.0 {
                (below[c] / above[c]).min(1.0)
            } else {
                1.0
            };
            f64::from(g[c]) * t
        });
        self.atmosphere.to_rec709(w).max(Vec3::ZERO)
    }

    /// `sky_background_no_disks`: inscattering, and the ground below the horizon.
    pub fn background_no_disks(&self, dir: Vec3) -> Vec3 {
        let mut l = self.inscatter(dir);
        if dir.y < 0.0 {
            l += self.ground(dir);
        }
        l
    }

    /// The sky's L2 SH (the convention of hikari-math's `sh`): raw and deringed.
    pub fn sh(&self) -> (Sh<Vec3, 9>, Sh<Vec3, 9>) {
        self.sh_with(|d| self.background_no_disks(d))
    }

    /// The L2 SH of `radiance` over the same directions, raw and deringed (`sh.wgsl`; with
    /// CLOUDS, `radiance` is the sky seen through the clouds).
    pub fn sh_with(&self, radiance: impl Fn(Vec3) -> Vec3) -> (Sh<Vec3, 9>, Sh<Vec3, 9>) {
        let mut sum = [DVec3::ZERO; 9];
        for i in 0..SH_SAMPLES {
            let d = fibonacci_dir(i, SH_SAMPLES);
            let l = radiance(d).as_dvec3();
            let y = basis::eval_l2_f64(d.as_dvec3());
            for (s, yk) in sum.iter_mut().zip(y) {
                *s += l * yk;
            }
        }
        let w = 4.0 * std::f64::consts::PI / f64::from(SH_SAMPLES);
        let mut raw = Sh::<Vec3, 9>::zero();
        for (c, s) in raw.coeffs.iter_mut().zip(sum) {
            *c = (s * w).as_vec3();
        }
        let deringed = dering::dering(&raw).sh;
        (raw, deringed)
    }
}

/// Direction `i` of an `n`-point spherical Fibonacci set (Y up; as `sh.wgsl`).
pub fn fibonacci_dir(i: u32, n: u32) -> Vec3 {
    const GOLDEN_ANGLE: f64 = 2.399_963_229_728_653_3;
    let z = 1.0 - (2.0 * f64::from(i) + 1.0) / f64::from(n);
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = GOLDEN_ANGLE * f64::from(i);
    DVec3::new(r * phi.cos(), z, r * phi.sin()).as_vec3()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn catmull_rom_weights_sum_to_one_and_interpolate() {
        for f in [0.0, 0.25, 0.5, 0.9] {
            let w = catmull_rom(f);
            assert!((w.iter().sum::<f64>() - 1.0).abs() < 1e-12);
        }
        assert_eq!(catmull_rom(0.0), [0.0, 1.0, 0.0, 0.0]);
        // Reproduces a straight line exactly.
        let f = 0.3;
        let w = catmull_rom(f);
        let line: f64 = (0..4).map(|k| w[k] * (k as f64 - 1.0)).sum();
        assert!((line - f).abs() < 1e-12);
    }

    #[test]
    fn the_fibonacci_set_has_zero_mean_and_unit_directions() {
        let mut m = Vec3::ZERO;
        for i in 0..SH_SAMPLES {
            let d = fibonacci_dir(i, SH_SAMPLES);
            assert!((d.length() - 1.0).abs() < 1e-5);
            m += d;
        }
        assert!(m.length() / (SH_SAMPLES as f32) < 1e-3, "{m}");
    }
}
