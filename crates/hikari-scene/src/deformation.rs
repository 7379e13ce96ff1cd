//! Vertex animation of a mesh in its own object space, as a function of time: plants swaying
//! in the wind and rigidly turning parts (wheels). Evaluated on the CPU by [`Mesh::deformed`],
//! deterministically (the same time gives bit-identical results), so a renderer can rebuild
//! or refit acceleration structures from it each frame.

use glam::{Quat, Vec3};

use crate::Mesh;

/// How a mesh moves over time, in its object space (the instance transform applies after).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Deformation {
    /// Bending like a plant in the wind. A vertex at height `h = y - base_y` above the base
    /// moves horizontally along `direction` by
    ///
    /// `amplitude_m * w(h) * sin(2π frequency_hz t + phase)`, with `w = 3s² - 2s³`,
    /// `s = clamp(h / height_m, 0, 1)`:
    ///
    /// nothing at and below the base, growing with height up to the full amplitude from
    /// `height_m` up. The smoothstep has zero slope at both ends, so the bent surface has no
    /// crease: it leaves the base upright (as a trunk clamped in the ground) and the part
    /// above `height_m` moves without bending. No vertex ever moves further than `amplitude_m`.
    /// `direction` is projected onto the horizontal plane and normalised (a vertical or zero
    /// direction means no motion).
    Sway {
        amplitude_m: f32,
        frequency_hz: f32,
        /// Radians.
        phase: f32,
        direction: Vec3,
        base_y: f32,
        height_m: f32,
    },
    /// Rigid rotation by `radians_per_second * t` about the line through `pivot` along
    /// `axis` (normalised here; counter-clockwise looking down the axis towards its origin, the
    /// right-hand rule). A zero axis means no motion.
    Spin {
        pivot: Vec3,
        axis: Vec3,
        radians_per_second: f32,
    },
}

impl Deformation {
    /// Checks the parameters: all finite, a positive sway height.
    pub fn check(&self) -> Result<(), String> {
        match *self {
            Deformation::Sway {
                amplitude_m,
                frequency_hz,
                phase,
                direction,
                base_y,
                height_m,
            } => {
                if !([amplitude_m, frequency_hz, phase, base_y, height_m]
                    .iter()
                    .all(|v| v.is_finite())
                    && direction.is_finite())
                {
                    return Err(format!("sway {self:?} has a non-finite parameter"));
                }
                if height_m <= 0.0 {
                    return Err(format!("sway height {height_m} m must be positive"));
                }
            }
            Deformation::Spin {
                pivot,
                axis,
                radians_per_second,
            } => {
                if !(pivot.is_finite() && axis.is_finite() && radians_per_second.is_finite()) {
                    return Err(format!("spin {self:?} has a non-finite parameter"));
                }
            }
        }
        Ok(())
    }

    /// The largest distance any vertex of `mesh` can move from its rest position at any time
    /// (for padding bounding volumes): the amplitude of a sway, the diameter of the circle
    /// swept by the vertex furthest from a spin's axis.
    pub fn max_displacement(&self, mesh: &Mesh) -> f32 {
        match *self {
            Deformation::Sway { amplitude_m, .. } => amplitude_m.abs(),
            Deformation::Spin { pivot, axis, .. } => {
                let Some(axis) = axis.try_normalize() else {
                    return 0.0;
                };
                let radius = mesh
                    .positions
                    .iter()
                    .map(|p| {
                        let d = *p - pivot;
                        (d - axis * axis.dot(d)).length()
                    })
                    .fold(0.0f32, f32::max);
                2.0 * radius
            }
        }
    }
}

impl Mesh {
    /// Positions and unit normals at time `time_s` (seconds) of the mesh's
    /// [`Mesh::deformation`]; the rest pose (a copy) without one.
    ///
    /// Sway normals are the exact transformed normals of the deformation (by the inverse
    /// transpose of its Jacobian `I + a ⊗ ∇w`, which is `I - ∇w ⊗ a` because the motion `a` is
    /// horizontal and `∇w` vertical); spin normals are rotated with the positions.
    pub fn deformed(&self, time_s: f32) -> (Vec<glam::Vec3>, Vec<glam::Vec3>) {
        match self.deformation {
            None => (self.positions.clone(), self.normals.clone()),
            Some(Deformation::Sway {
                amplitude_m,
                frequency_hz,
                phase,
                direction,
                base_y,
                height_m,
            }) => {
                let Some(dir) = direction.with_y(0.0).try_normalize() else {
                    return (self.positions.clone(), self.normals.clone());
                };
                // Phase in f64: at large times f32 would lose the fraction of the cycle.
                let cycle = (frequency_hz as f64 * time_s as f64).fract();
                let swing =
                    amplitude_m * (std::f64::consts::TAU * cycle + phase as f64).sin() as f32;
                let h = height_m.max(f32::MIN_POSITIVE);
                let positions = self
                    .positions
                    .iter()
                    .map(|p| {
                        let s = ((p.y - base_y) / h).clamp(0.0, 1.0);
                        *p + dir * (swing * s * s * (3.0 - 2.0 * s))
                    })
                    .collect();
                let normals = self
                    .positions
                    .iter()
                    .zip(&self.normals)
                    .map(|(p, n)| {
                        let s = (p.y - base_y) / h;
                        // dw/dy; zero where w is clamped.
                        let dw = if (0.0..1.0).contains(&s) {
                            6.0 * s * (1.0 - s) / h
                        } else {
                            0.0
                        };
                        (*n - Vec3::Y * (dw * swing * dir.dot(*n))).normalize_or(*n)
                    })
                    .collect();
                (positions, normals)
            }
            Some(Deformation::Spin {
                pivot,
                axis,
                radians_per_second,
            }) => {
                let Some(axis) = axis.try_normalize() else {
                    return (self.positions.clone(), self.normals.clone());
                };
                // The angle reduced to one turn in f64, so long runs do not lose precision.
                let angle = (radians_per_second as f64 * time_s as f64)
                    .rem_euclid(std::f64::consts::TAU) as f32;
                let q = Quat::from_axis_angle(axis, angle);
                let positions = self
                    .positions
                    .iter()
                    .map(|p| pivot + q * (*p - pivot))
                    .collect();
                let normals = self
                    .normals
                    .iter()
                    .map(|n| (q * *n).normalize_or(*n))
                    .collect();
                (positions, normals)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shapes;
    use std::f32::consts::{PI, TAU};

    /// A tall, finely divided column: a wall 0.5 m wide, 8 m high, cut into 10 cm rows by
    /// stacking walls.
    fn column() -> Mesh {
        let mut m = Mesh::default();
        for k in 0..80 {
            let w = shapes::wall(0.5, 0.1, 0.2, &[]).unwrap();
            shapes::append(
                &mut m,
                &w,
                glam::Mat4::from_translation(Vec3::new(-0.25, k as f32 * 0.1, 0.0)),
            );
        }
        m
    }

    fn sway(amplitude_m: f32) -> Deformation {
        Deformation::Sway {
            amplitude_m,
            frequency_hz: 0.3,
            phase: 0.4,
            direction: Vec3::new(1.0, 0.5, 1.0),
            base_y: 0.5,
            height_m: 6.0,
        }
    }

    #[test]
    fn no_deformation_is_the_rest_pose() {
        let m = column();
        let (p, n) = m.deformed(3.7);
        assert_eq!((p, n), (m.positions.clone(), m.normals.clone()));
    }

    #[test]
    fn sway_is_zero_at_the_base_bounded_by_the_amplitude_and_full_at_the_top() {
        let mut m = column();
        m.deformation = Some(sway(0.3));
        let dir = Vec3::new(1.0, 0.0, 1.0).normalize();
        let mut reached = 0.0f32;
        for k in 0..50 {
            let t = k as f32 * 0.137;
            let (p, _) = m.deformed(t);
            let swing = 0.3 * (TAU * 0.3 * t + 0.4).sin();
            for (rest, moved) in m.positions.iter().zip(&p) {
                let d = *moved - *rest;
                assert!(d.length() <= 0.3 + 1e-6);
                assert_eq!(d.y, 0.0, "sway is horizontal");
                if rest.y <= 0.5 {
                    assert_eq!(d, Vec3::ZERO, "below the base at {rest}");
                }
                // Independent evaluation of the documented formula.
                let s = ((rest.y - 0.5) / 6.0).clamp(0.0, 1.0);
                assert!((d - dir * swing * (3.0 * s * s - 2.0 * s * s * s)).length() < 1e-5);
                reached = reached.max(d.length());
            }
        }
        // The top (y = 8 > base + height) reaches nearly the full amplitude at some sample.
        assert!(reached > 0.29, "{reached}");
        // Periodic: one period later the same pose (up to rounding of the position update).
        let (a, _) = m.deformed(1.0);
        let (b, _) = m.deformed(1.0 + 1.0 / 0.3);
        for (a, b) in a.iter().zip(&b) {
            assert!(a.distance(*b) < 1e-5);
        }
    }

    #[test]
    fn sway_normals_are_unit_and_perpendicular_to_the_deformed_surface() {
        let mut m = column();
        // A large amplitude so a wrong normal would show.
        m.deformation = Some(sway(2.0));
        let (p, n) = m.deformed(0.9);
        for nn in &n {
            assert!((nn.length() - 1.0).abs() < 1e-5);
        }
        // Each triangle's deformed geometric normal against its vertices' normals; the
        // triangles are small (10 cm) so the curvature within one is slight.
        let mut worst = 1.0f32;
        for t in m.indices.chunks(3) {
            let [a, b, c] = [0, 1, 2].map(|i| p[t[i] as usize]);
            let g = (b - a).cross(c - a).normalize();
            for i in t {
                worst = worst.min(g.dot(n[*i as usize]));
            }
        }
        assert!(worst > 0.999, "{worst}");
        // And they did change: the side faces tilt.
        assert!(n.iter().zip(&m.normals).any(|(a, b)| a.dot(*b) < 0.99));
    }

    #[test]
    fn spin_returns_to_rest_after_a_turn_and_moves_rigidly() {
        let mut m = shapes::frustum(1.0, 1.0, 0.5, 16).unwrap();
        let pivot = Vec3::new(0.0, 0.25, 0.0);
        let omega = 0.7;
        m.deformation = Some(Deformation::Spin {
            pivot,
            axis: Vec3::new(2.0, 0.0, 0.0),
            radians_per_second: omega,
        });
        let (p, n) = m.deformed(TAU / omega);
        for ((a, b), (na, nb)) in p.iter().zip(&m.positions).zip(n.iter().zip(&m.normals)) {
            assert!(a.distance(*b) < 1e-5, "{a} vs {b}");
            assert!(na.distance(*nb) < 1e-5);
        }
        // Half a turn about x through the pivot maps (x, y, z) to (x, 2 py - y, -z).
        let (p, n) = m.deformed(PI / omega);
        for ((a, b), (na, nb)) in p.iter().zip(&m.positions).zip(n.iter().zip(&m.normals)) {
            let want = Vec3::new(b.x, 2.0 * pivot.y - b.y, -b.z);
            assert!(a.distance(want) < 1e-5, "{a} vs {want}");
            assert!(na.distance(Vec3::new(nb.x, -nb.y, -nb.z)) < 1e-5);
            assert!((na.length() - 1.0).abs() < 1e-5);
        }
        // The bound: twice the largest distance from the axis.
        let bound = m.deformation.unwrap().max_displacement(&m);
        assert!(
            (bound - 2.0 * (1.0f32 + 0.25 * 0.25).sqrt()).abs() < 1e-5,
            "{bound}"
        );
        // Deterministic, bit for bit.
        assert_eq!(m.deformed(12.345), m.deformed(12.345));
    }

    #[test]
    fn check_rejects_bad_parameters() {
        assert!(sway(0.1).check().is_ok());
        let bad = Deformation::Sway {
            amplitude_m: 0.1,
            frequency_hz: 1.0,
            phase: 0.0,
            direction: Vec3::X,
            base_y: 0.0,
            height_m: 0.0,
        };
        assert!(bad.check().unwrap_err().contains("height"));
        let bad = Deformation::Spin {
            pivot: Vec3::NAN,
            axis: Vec3::X,
            radians_per_second: 1.0,
        };
        assert!(bad.check().is_err());
    }
}
