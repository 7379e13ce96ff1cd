//! Checks of the numbers a renderer takes from a camera, the sun and punctual lights, so that
//! no NaN, infinity or degenerate frame reaches the GPU. [`crate::Scene::validate`] runs them
//! for everything in a scene; renderers run them again on cameras and lights they are handed
//! directly (a camera moved by a user, a sun computed for a time of day). Each error names the
//! object and the field.

use glam::Vec3;

use crate::{Camera, Light, LightKind, SceneError, Sun};

/// How far a "unit" direction's length may be from 1: loose enough for directions normalised
/// in f32 and written to a file with a few digits, tight enough to catch an unnormalised one.
pub const UNIT_TOLERANCE: f32 = 1e-3;

fn is_unit(v: Vec3) -> bool {
    v.is_finite() && (v.length() - 1.0).abs() <= UNIT_TOLERANCE
}

fn colour_ok(c: Vec3) -> bool {
    c.is_finite() && c.min_element() >= 0.0
}

impl Camera {
    /// Checks the camera: finite `position` and `target` at a distance whose direction can be
    /// normalised, `vfov_deg` in (0, 180), `near` positive and finite, `up` finite and not
    /// parallel to the view direction.
    pub fn validate(&self) -> Result<(), SceneError> {
        let err = |what: String| SceneError::Camera {
            camera: self.name.clone(),
            what,
        };
        if !self.position.is_finite() {
            return Err(err(format!("position {} is not finite", self.position)));
        }
        if !self.target.is_finite() {
            return Err(err(format!("target {} is not finite", self.target)));
        }
        let view = self.target - self.position;
        let Some(forward) = view.try_normalize() else {
            return Err(err(format!(
                "target {} and position {} give no view direction (equal, or too close or too far apart to normalise)",
                self.target, self.position
            )));
        };
        if !(self.vfov_deg > 0.0 && self.vfov_deg < 180.0) {
            return Err(err(format!(
                "vfov_deg {} is outside (0, 180) degrees",
                self.vfov_deg
            )));
        }
        if !(self.near > 0.0 && self.near.is_finite()) {
            return Err(err(format!(
                "near {} m must be positive and finite",
                self.near
            )));
        }
        if !self.up.is_finite() || self.up.cross(forward).try_normalize().is_none() {
            return Err(err(format!(
                "up {} is zero, not finite or parallel to the view direction",
                self.up
            )));
        }
        Ok(())
    }

    /// [`Camera::validate`] and the image's `aspect` (width / height), which must be positive
    /// and finite, as [`Camera::projection`] needs.
    pub fn validate_projection(&self, aspect: f32) -> Result<(), SceneError> {
        self.validate()?;
        if !(aspect > 0.0 && aspect.is_finite()) {
            return Err(SceneError::Camera {
                camera: self.name.clone(),
                what: format!("aspect ratio {aspect} must be positive and finite"),
            });
        }
        Ok(())
    }
}

impl Sun {
    /// Checks the sun: `direction` a finite unit vector (within [`UNIT_TOLERANCE`]),
    /// `illuminance_lux` finite and non-negative, `color` finite and non-negative.
    pub fn validate(&self) -> Result<(), SceneError> {
        if !is_unit(self.direction) {
            return Err(SceneError::Sun(format!(
                "direction {} is not a finite unit vector",
                self.direction
            )));
        }
        if !(self.illuminance_lux >= 0.0 && self.illuminance_lux.is_finite()) {
            return Err(SceneError::Sun(format!(
                "illuminance_lux {} must be finite and non-negative",
                self.illuminance_lux
            )));
        }
        if !colour_ok(self.color) {
            return Err(SceneError::Sun(format!(
                "color {} must be finite and non-negative",
                self.color
            )));
        }
        Ok(())
    }
}

impl Light {
    /// Checks the light: finite `position`; `direction` finite (a unit vector for spots);
    /// `intensity_cd` finite and non-negative; `color` finite and non-negative; `range`
    /// positive and finite when given; `radius_m` finite and non-negative when given; spot
    /// cones 0 <= inner < outer <= pi/2.
    pub fn validate(&self) -> Result<(), SceneError> {
        let err = |what: String| SceneError::Light {
            light: self.name.clone(),
            what,
        };
        if !self.position.is_finite() {
            return Err(err(format!("position {} is not finite", self.position)));
        }
        if !self.direction.is_finite() {
            return Err(err(format!("direction {} is not finite", self.direction)));
        }
        if !(self.intensity_cd >= 0.0 && self.intensity_cd.is_finite()) {
            return Err(err(format!(
                "intensity_cd {} must be finite and non-negative",
                self.intensity_cd
            )));
        }
        if !colour_ok(self.color) {
            return Err(err(format!(
                "color {} must be finite and non-negative",
                self.color
            )));
        }
        if let Some(r) = self.range
            && !(r > 0.0 && r.is_finite())
        {
            return Err(err(format!(
                "range {r} m must be positive and finite (None means unlimited)"
            )));
        }
        if let Some(r) = self.radius_m
            && !(r >= 0.0 && r.is_finite())
        {
            return Err(err(format!(
                "radius_m {r} must be finite and non-negative (None means the renderer's setting)"
            )));
        }
        if let LightKind::Spot {
            inner_cone,
            outer_cone,
        } = self.kind
        {
            if !is_unit(self.direction) {
                return Err(err(format!(
                    "spot direction {} is not a unit vector",
                    self.direction
                )));
            }
            if !(0.0 <= inner_cone
                && inner_cone < outer_cone
                && outer_cone <= std::f32::consts::FRAC_PI_2 + 1e-6)
            {
                return Err(err(format!(
                    "cone angles inner_cone {inner_cone} and outer_cone {outer_cone} rad must satisfy 0 <= inner < outer <= pi/2"
                )));
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn camera_err(c: Camera) -> String {
        c.validate().unwrap_err().to_string()
    }

    #[test]
    fn the_defaults_pass() {
        Camera::default().validate().unwrap();
        Camera::default().validate_projection(16.0 / 9.0).unwrap();
        Sun::default().validate().unwrap();
        Light::point("p", Vec3::ONE, 10.0, Vec3::ONE)
            .validate()
            .unwrap();
        Light::spot("s", Vec3::ONE, Vec3::NEG_Y, 10.0, 0.2, 0.4, Vec3::ONE)
            .validate()
            .unwrap();
    }

    #[test]
    fn cameras_with_bad_numbers_are_rejected_naming_the_field() {
        let c = Camera::default;
        let cases: Vec<(Camera, &str)> = vec![
            (
                Camera {
                    position: Vec3::new(f32::NAN, 0.0, 0.0),
                    ..c()
                },
                "position [NaN, 0, 0]",
            ),
            (
                Camera {
                    target: Vec3::splat(f32::INFINITY),
                    ..c()
                },
                "target [inf",
            ),
            (
                Camera {
                    target: c().position,
                    ..c()
                },
                "no view direction",
            ),
            // Finite ends whose difference overflows f32.
            (
                Camera {
                    position: Vec3::new(-3e38, 0.0, 0.0),
                    target: Vec3::new(3e38, 0.0, 0.0),
                    ..c()
                },
                "no view direction",
            ),
            (
                Camera {
                    vfov_deg: f32::NAN,
                    ..c()
                },
                "vfov_deg NaN",
            ),
            (
                Camera {
                    vfov_deg: 0.0,
                    ..c()
                },
                "vfov_deg 0",
            ),
            (
                Camera {
                    vfov_deg: 180.0,
                    ..c()
                },
                "vfov_deg 180",
            ),
            (Camera { near: 0.0, ..c() }, "near 0"),
            (Camera { near: -1.0, ..c() }, "near -1"),
            (
                Camera {
                    near: f32::INFINITY,
                    ..c()
                },
                "near inf",
            ),
            (
                Camera {
                    up: Vec3::ZERO,
                    ..c()
                },
                "up [0, 0, 0]",
            ),
            (
                Camera {
                    up: Vec3::new(0.0, f32::NAN, 0.0),
                    ..c()
                },
                "up [0, NaN, 0]",
            ),
        ];
        for (camera, wanted) in cases {
            let e = camera_err(camera);
            assert!(e.starts_with("camera `main`: "), "{e}");
            assert!(e.contains(wanted), "`{e}` lacks `{wanted}`");
        }
        // Up parallel to the view direction.
        let mut cam = c();
        cam.up = cam.target - cam.position;
        assert!(camera_err(cam).contains("parallel"));
        for aspect in [0.0, -1.0, f32::NAN, f32::INFINITY] {
            let e = c().validate_projection(aspect).unwrap_err().to_string();
            assert!(e.contains("aspect ratio"), "{e}");
        }
    }

    #[test]
    fn suns_with_bad_numbers_are_rejected_naming_the_field() {
        let s = Sun::default;
        let cases: Vec<(Sun, &str)> = vec![
            (
                Sun {
                    direction: Vec3::ZERO,
                    ..s()
                },
                "direction [0, 0, 0]",
            ),
            (
                Sun {
                    direction: Vec3::new(0.0, 2.0, 0.0),
                    ..s()
                },
                "direction [0, 2, 0]",
            ),
            (
                Sun {
                    direction: Vec3::new(f32::NAN, 1.0, 0.0),
                    ..s()
                },
                "direction [NaN",
            ),
            (
                Sun {
                    illuminance_lux: -1.0,
                    ..s()
                },
                "illuminance_lux -1",
            ),
            (
                Sun {
                    illuminance_lux: f32::INFINITY,
                    ..s()
                },
                "illuminance_lux inf",
            ),
            (
                Sun {
                    illuminance_lux: f32::NAN,
                    ..s()
                },
                "illuminance_lux NaN",
            ),
            (
                Sun {
                    color: Vec3::new(1.0, -0.5, 1.0),
                    ..s()
                },
                "color [1, -0.5, 1]",
            ),
        ];
        for (sun, wanted) in cases {
            let e = sun.validate().unwrap_err().to_string();
            assert!(e.starts_with("sun: "), "{e}");
            assert!(e.contains(wanted), "`{e}` lacks `{wanted}`");
        }
    }

    #[test]
    fn lights_with_bad_numbers_are_rejected_naming_the_field() {
        let p = || Light::point("lamp", Vec3::ONE, 10.0, Vec3::ONE);
        let s = || Light::spot("lamp", Vec3::ONE, Vec3::NEG_Y, 10.0, 0.2, 0.4, Vec3::ONE);
        let spot = |inner_cone, outer_cone| Light {
            kind: LightKind::Spot {
                inner_cone,
                outer_cone,
            },
            ..s()
        };
        let cases: Vec<(Light, &str)> = vec![
            (
                Light {
                    position: Vec3::splat(f32::NAN),
                    ..p()
                },
                "position [NaN",
            ),
            (
                Light {
                    direction: Vec3::splat(f32::NEG_INFINITY),
                    ..p()
                },
                "direction [-inf",
            ),
            (
                Light {
                    intensity_cd: -2.0,
                    ..p()
                },
                "intensity_cd -2",
            ),
            (
                Light {
                    intensity_cd: f32::NAN,
                    ..s()
                },
                "intensity_cd NaN",
            ),
            (
                Light {
                    color: Vec3::new(f32::INFINITY, 0.0, 0.0),
                    ..p()
                },
                "color [inf",
            ),
            (
                Light {
                    range: Some(0.0),
                    ..p()
                },
                "range 0",
            ),
            (
                Light {
                    range: Some(f32::NAN),
                    ..p()
                },
                "range NaN",
            ),
            (
                Light {
                    range: Some(f32::INFINITY),
                    ..p()
                },
                "range inf",
            ),
            (
                Light {
                    radius_m: Some(-0.1),
                    ..p()
                },
                "radius_m -0.1",
            ),
            (
                Light {
                    radius_m: Some(f32::NAN),
                    ..s()
                },
                "radius_m NaN",
            ),
            (
                Light {
                    direction: Vec3::ZERO,
                    ..s()
                },
                "spot direction [0, 0, 0]",
            ),
            (spot(0.4, 0.4), "inner_cone 0.4 and outer_cone 0.4"),
            (spot(-0.1, 0.4), "inner_cone -0.1"),
            (spot(0.1, 2.0), "outer_cone 2"),
            (spot(f32::NAN, 0.4), "inner_cone NaN"),
        ];
        for (light, wanted) in cases {
            let e = light.validate().unwrap_err().to_string();
            assert!(e.starts_with("light `lamp`: "), "{e}");
            assert!(e.contains(wanted), "`{e}` lacks `{wanted}`");
        }
        // A point light's direction is unused, so any finite one is fine.
        Light {
            direction: Vec3::ZERO,
            ..p()
        }
        .validate()
        .unwrap();
    }
}
