//! Particle emitters: volumes of camera-facing fog or smoke sprites, Ghost of Tsushima's "local
//! fog" (Patry 2021, the haze section). A particle has no state: its place, size and opacity
//! are functions of its emitter, its index and the scene's clock, so a still is the same at
//! any frame count and a time-lapse shows the smoke drift.

use glam::Vec3;

use crate::SceneError;

/// The most particles one emitter may hold.
pub const MAX_PARTICLES: u32 = 65_536;

/// A box in which particles are born, drift and fade.
#[derive(Clone, Debug, PartialEq)]
pub struct ParticleEmitter {
    pub name: String,
    /// Centre of the box particles are born in, world metres.
    pub centre: Vec3,
    /// Half the box's size along x, y and z, metres (each >= 0).
    pub half_extents: Vec3,
    /// Particles alive at once, 1 to [`MAX_PARTICLES`].
    pub count: u32,
    /// Sprite radius at birth and at death, metres (each > 0); it grows linearly between.
    pub size_m: [f32; 2],
    /// Opacity at the middle of a particle's life, (0, 1]; it fades in and out as
    /// `sin(pi * age)`.
    pub opacity: f32,
    /// Drift, metres a second (wind, or the rise of smoke).
    pub velocity_mps: Vec3,
    /// Seconds a particle lives (> 0); their births are spread evenly over it.
    pub lifetime_s: f32,
    /// Single-scattering albedo under the standard lighting (each channel in [0, 1]).
    pub albedo: Vec3,
    /// The talk's "haze lighting" mode: lit by the haze's froxel light (its `L_i`); else by the
    /// sun or moon and the sky's mean radiance, unshadowed (the talk's standard particle
    /// lighting, kept for A/B comparisons).
    pub haze_lit: bool,
    pub seed: u32,
    /// Local hours `[from, to]` (each in [0, 24], different) between which the emitter shows,
    /// as morning mist or evening smoke does: every particle's opacity fades in over the
    /// window's first hour and out over its last (over half the window if that is shorter);
    /// `from > to` runs through midnight. `None`: at every hour.
    pub hours: Option<[f32; 2]>,
}

impl Default for ParticleEmitter {
    fn default() -> Self {
        Self {
            name: "particles".into(),
            centre: Vec3::ZERO,
            half_extents: Vec3::splat(1.0),
            count: 64,
            size_m: [0.5, 1.0],
            opacity: 0.3,
            velocity_mps: Vec3::ZERO,
            lifetime_s: 10.0,
            albedo: Vec3::splat(0.9),
            haze_lit: true,
            seed: 0,
            hours: None,
        }
    }
}

/// One sprite at one moment.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Particle {
    pub position: Vec3,
    pub radius_m: f32,
    pub opacity: f32,
}

/// A 32-bit integer hash (Wang's), the same on every platform.
fn hash(mut x: u32) -> u32 {
    x = (x ^ 61) ^ (x >> 16);
    x = x.wrapping_mul(9);
    x ^= x >> 4;
    x = x.wrapping_mul(0x27d4_eb2d);
    x ^ (x >> 15)
}

fn unit(x: u32) -> f32 {
    (hash(x) >> 8) as f32 / (1u32 << 24) as f32
}

impl ParticleEmitter {
    pub fn validate(&self) -> Result<(), SceneError> {
        let err = |what: String| SceneError::Particles {
            emitter: self.name.clone(),
            what,
        };
        if !self.centre.is_finite() {
            return Err(err(format!("centre {} is not finite", self.centre)));
        }
        if !self.half_extents.is_finite() || self.half_extents.min_element() < 0.0 {
            return Err(err(format!(
                "half_extents {} must be finite and >= 0",
                self.half_extents
            )));
        }
        if self.count == 0 || self.count > MAX_PARTICLES {
            return Err(err(format!(
                "count {} must be 1 to {MAX_PARTICLES}",
                self.count
            )));
        }
        if !self.size_m.iter().all(|s| s.is_finite() && *s > 0.0) {
            return Err(err(format!(
                "size_m {:?} must be two finite radii > 0",
                self.size_m
            )));
        }
        if !(self.opacity > 0.0 && self.opacity <= 1.0) {
            return Err(err(format!("opacity {} must be in (0, 1]", self.opacity)));
        }
        if !self.velocity_mps.is_finite() {
            return Err(err(format!(
                "velocity_mps {} is not finite",
                self.velocity_mps
            )));
        }
        if !(self.lifetime_s.is_finite() && self.lifetime_s > 0.0) {
            return Err(err(format!(
                "lifetime_s {} must be finite and > 0",
                self.lifetime_s
            )));
        }
        if !self.albedo.is_finite()
            || self.albedo.min_element() < 0.0
            || self.albedo.max_element() > 1.0
        {
            return Err(err(format!("albedo {} must be in [0, 1]", self.albedo)));
        }
        if let Some(h) = self.hours
            && (!h.iter().all(|x| (0.0..=24.0).contains(x)) || h[0] % 24.0 == h[1] % 24.0)
        {
            return Err(err(format!(
                "hours {h:?} must be two different hours in [0, 24]"
            )));
        }
        Ok(())
    }

    /// How much of the emitter shows at `time_s` seconds into the day (the sky's clock): 1
    /// inside its `hours`, 0 outside, linear over the fades at both ends.
    pub fn presence(&self, time_s: f64) -> f32 {
        let Some([from, to]) = self.hours else {
            return 1.0;
        };
        let hour = (time_s / 3600.0).rem_euclid(24.0) as f32;
        let length = (to - from).rem_euclid(24.0);
        let since = (hour - from).rem_euclid(24.0);
        if since > length {
            return 0.0;
        }
        let fade = length.min(2.0) * 0.5;
        (since / fade).min((length - since) / fade).clamp(0.0, 1.0)
    }

    /// Particle `i` at `time_s` seconds of the scene's clock: born at a random point of the box
    /// at an even share of the lifetime, drifting with the velocity, growing from the first
    /// size to the second, its opacity `opacity sin(pi age)` times the emitter's
    /// [`presence`](Self::presence) at that hour.
    pub fn particle(&self, i: u32, time_s: f64) -> Particle {
        let key = hash(self.seed ^ hash(i.wrapping_mul(0x9e37_79b9)));
        // Births spread evenly over a lifetime, each particle's phase jittered within its share.
        let phase = (f64::from(i) + f64::from(unit(key ^ 0x5bd1))) / f64::from(self.count);
        let cycles = time_s / f64::from(self.lifetime_s) + phase;
        let age = cycles.fract() as f32;
        // Each new life of the same index starts somewhere else.
        let life = cycles.floor() as i64 as u32;
        let k = hash(key ^ life.wrapping_mul(0x85eb_ca6b));
        let r = Vec3::new(unit(k), unit(k ^ 0x68e3_1da4), unit(k ^ 0xb529_7a4d)) * 2.0 - 1.0;
        let position =
            self.centre + r * self.half_extents + self.velocity_mps * (age * self.lifetime_s);
        Particle {
            position,
            radius_m: self.size_m[0] + (self.size_m[1] - self.size_m[0]) * age,
            opacity: self.opacity
                * (std::f32::consts::PI * age).sin().max(0.0)
                * self.presence(time_s),
        }
    }

    /// Every particle at `time_s`.
    pub fn particles_at(&self, time_s: f64) -> impl Iterator<Item = Particle> + '_ {
        (0..self.count).map(move |i| self.particle(i, time_s))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn particles_stay_in_their_box_plus_their_drift_and_fade_at_both_ends() {
        let e = ParticleEmitter {
            centre: Vec3::new(3.0, 1.0, -2.0),
            half_extents: Vec3::new(2.0, 0.5, 1.0),
            velocity_mps: Vec3::new(0.0, 0.2, 0.1),
            count: 500,
            ..Default::default()
        };
        e.validate().unwrap();
        let drift = e.velocity_mps * e.lifetime_s;
        let mut mean_opacity = 0.0;
        for p in e.particles_at(1234.5) {
            let lo = e.centre - e.half_extents - 1e-4;
            let hi = e.centre + e.half_extents + drift + 1e-4;
            assert!(
                p.position.cmpge(lo).all() && p.position.cmple(hi).all(),
                "{p:?}"
            );
            assert!(p.radius_m >= 0.5 && p.radius_m <= 1.0);
            assert!(p.opacity >= 0.0 && p.opacity <= e.opacity);
            mean_opacity += p.opacity / e.count as f32;
        }
        // Ages spread evenly over the lifetime: the mean of sin(pi age) is 2 / pi.
        let want = e.opacity * 2.0 / std::f32::consts::PI;
        assert!(
            (mean_opacity - want).abs() < 0.02 * e.opacity,
            "{mean_opacity} against {want}"
        );
    }

    #[test]
    fn the_same_moment_gives_the_same_particles_and_a_later_one_moves_them() {
        let e = ParticleEmitter {
            velocity_mps: Vec3::new(0.5, 0.0, 0.0),
            ..Default::default()
        };
        let a: Vec<_> = e.particles_at(10.0).collect();
        assert_eq!(a, e.particles_at(10.0).collect::<Vec<_>>());
        let b: Vec<_> = e.particles_at(10.5).collect();
        let moved = a
            .iter()
            .zip(&b)
            .filter(|(p, q)| p.position != q.position)
            .count();
        assert!(moved as u32 == e.count);
    }

    #[test]
    fn bad_emitters_are_refused_by_name() {
        let bad = [
            ParticleEmitter {
                count: 0,
                ..Default::default()
            },
            ParticleEmitter {
                opacity: f32::NAN,
                ..Default::default()
            },
            ParticleEmitter {
                size_m: [0.5, -1.0],
                ..Default::default()
            },
            ParticleEmitter {
                centre: Vec3::new(f32::INFINITY, 0.0, 0.0),
                ..Default::default()
            },
            ParticleEmitter {
                lifetime_s: 0.0,
                ..Default::default()
            },
            ParticleEmitter {
                albedo: Vec3::splat(1.5),
                ..Default::default()
            },
        ];
        for e in bad {
            let msg = e.validate().unwrap_err().to_string();
            assert!(msg.contains("particles `particles`"), "{msg}");
        }
    }

    #[test]
    fn an_emitter_shows_only_in_its_hours_and_fades_at_their_ends() {
        let at = |hours: Option<[f32; 2]>, h: f64| {
            ParticleEmitter {
                hours,
                ..Default::default()
            }
            .presence(h * 3600.0)
        };
        assert_eq!(at(None, 13.0), 1.0);
        // Dusk to mid-morning, through midnight: faded in by 18:30, out from 8:00 to 9:00.
        let mist = Some([17.5, 9.0]);
        for (h, want) in [
            (12.0, 0.0),
            (17.0, 0.0),
            (18.0, 0.5),
            (18.5, 1.0),
            (23.9, 1.0),
            (3.0, 1.0),
            (27.0, 1.0),
            (8.5, 0.5),
            (9.5, 0.0),
        ] {
            assert!((at(mist, h) - want).abs() < 1e-4, "{h}: {}", at(mist, h));
        }
        // A window shorter than two hours fades over half of it each way.
        assert!((at(Some([6.0, 7.0]), 6.5) - 1.0).abs() < 1e-4);
        assert!((at(Some([6.0, 7.0]), 6.25) - 0.5).abs() < 1e-4);
        let e = ParticleEmitter {
            hours: mist,
            ..Default::default()
        };
        assert!(e.particles_at(12.0 * 3600.0).all(|p| p.opacity == 0.0));
        assert!(e.particles_at(22.0 * 3600.0).any(|p| p.opacity > 0.0));
        for bad in [
            [25.0, 3.0],
            [-1.0, 3.0],
            [5.0, 5.0],
            [0.0, 24.0],
            [f32::NAN, 3.0],
        ] {
            let e = ParticleEmitter {
                hours: Some(bad),
                ..Default::default()
            };
            assert!(e.validate().is_err(), "{bad:?}");
        }
    }
}
