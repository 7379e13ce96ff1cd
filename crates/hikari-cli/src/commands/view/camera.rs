//! The fly camera: W/A/S/D move forward, left, back and right, Q/E down and up, Shift five
//! times faster, the wheel scales the speed, a drag with the right button looks around.

use glam::Vec3;
use hikari_scene::Camera;

use super::keys::Held;

/// Shift's speed-up.
pub const FAST: f32 = 5.0;
/// Each wheel notch multiplies the speed by this (down: divides).
pub const WHEEL_STEP: f32 = 1.25;
/// The speed's limits in metres a second.
pub const SPEED_RANGE: (f32, f32) = (0.05, 500.0);
/// Radians the view turns for each pixel the mouse moves.
pub const LOOK_RADIANS_PER_PX: f32 = 0.004;
/// How far up or down the view may look, short of straight (where yaw is undefined).
const MAX_PITCH: f32 = 89.0_f32 * std::f32::consts::PI / 180.0;

/// A camera that flies: a position, a heading (yaw about +Y) and a pitch.
#[derive(Clone, Debug)]
pub struct FlyCamera {
    pub position: Vec3,
    /// Radians about +Y; 0 looks along +Z.
    pub yaw: f32,
    /// Radians above the horizon.
    pub pitch: f32,
    /// Metres a second.
    pub speed: f32,
    /// The camera's lens and name, kept from the camera it started from.
    base: Camera,
}

impl FlyCamera {
    /// Starts at `camera`'s position, looking where it looks; `speed` in metres a second.
    pub fn new(camera: &Camera, speed: f32) -> Self {
        let f = camera.forward();
        Self {
            position: camera.position,
            yaw: f.x.atan2(f.z),
            pitch: f.y.clamp(-1.0, 1.0).asin().clamp(-MAX_PITCH, MAX_PITCH),
            speed: speed.clamp(SPEED_RANGE.0, SPEED_RANGE.1),
            base: camera.clone(),
        }
    }

    /// A speed that suits a scene of this size: crossing its bounds in about 10 s.
    pub fn speed_for(bounds: Option<(Vec3, Vec3)>) -> f32 {
        let size = bounds.map_or(10.0, |(lo, hi)| (hi - lo).length());
        (size / 10.0).clamp(0.5, 50.0)
    }

    pub fn forward(&self) -> Vec3 {
        let (sy, cy) = self.yaw.sin_cos();
        let (sp, cp) = self.pitch.sin_cos();
        Vec3::new(cp * sy, sp, cp * cy)
    }

    /// The horizontal direction to the right of the view.
    pub fn right(&self) -> Vec3 {
        let (sy, cy) = self.yaw.sin_cos();
        Vec3::new(-cy, 0.0, sy)
    }

    /// The camera to render.
    pub fn camera(&self) -> Camera {
        Camera {
            position: self.position,
            target: self.position + self.forward(),
            up: Vec3::Y,
            ..self.base.clone()
        }
    }

    /// Moves for `dt` seconds with the keys `held`; whether the camera moved.
    pub fn step(&mut self, held: &Held, fast: bool, dt: f32) -> bool {
        let [right, up, forward] = held.axes();
        if (right, up, forward) == (0.0, 0.0, 0.0) || dt.is_nan() || dt <= 0.0 {
            return false;
        }
        let dir = self.forward() * forward + self.right() * right + Vec3::Y * up;
        let Some(dir) = dir.try_normalize() else {
            return false;
        };
        let speed = self.speed * if fast { FAST } else { 1.0 };
        // A stalled frame (a CPU driver, a probe bake) must not throw the camera far away.
        self.position += dir * speed * dt.min(0.25);
        true
    }

    /// Turns the view by a mouse motion of `dx`, `dy` pixels (right and down positive);
    /// whether it turned.
    pub fn look(&mut self, dx: f32, dy: f32) -> bool {
        if dx == 0.0 && dy == 0.0 || !dx.is_finite() || !dy.is_finite() {
            return false;
        }
        self.yaw -= dx * LOOK_RADIANS_PER_PX;
        self.yaw = (self.yaw + std::f32::consts::PI).rem_euclid(std::f32::consts::TAU)
            - std::f32::consts::PI;
        self.pitch = (self.pitch - dy * LOOK_RADIANS_PER_PX).clamp(-MAX_PITCH, MAX_PITCH);
        true
    }

    /// Scales the speed by wheel `notches` (up positive).
    pub fn wheel(&mut self, notches: f32) {
        if notches.is_finite() {
            self.speed =
                (self.speed * WHEEL_STEP.powf(notches)).clamp(SPEED_RANGE.0, SPEED_RANGE.1);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::keys::Move;
    use super::*;

    fn looking_along_z() -> FlyCamera {
        let c = Camera {
            position: Vec3::new(1.0, 2.0, 3.0),
            target: Vec3::new(1.0, 2.0, 4.0),
            ..Camera::default()
        };
        FlyCamera::new(&c, 2.0)
    }

    fn held(moves: &[Move]) -> Held {
        let mut h = Held::default();
        for &m in moves {
            h.set(m, true);
        }
        h
    }

    #[test]
    fn starts_where_the_camera_is_and_looks_where_it_looks() {
        let c = Camera {
            position: Vec3::new(1.0, 2.0, 3.0),
            target: Vec3::new(4.0, 0.0, -1.0),
            ..Camera::default()
        };
        let fly = FlyCamera::new(&c, 1.0);
        let back = fly.camera();
        assert!((back.position - c.position).length() < 1e-6);
        assert!((back.forward() - c.forward()).length() < 1e-5);
        assert_eq!((back.vfov_deg, back.near), (c.vfov_deg, c.near));
        back.validate().unwrap();
    }

    #[test]
    fn wasd_qe_move_along_the_view_and_shift_is_five_times_faster() {
        let dt = 0.1;
        for (keys, want) in [
            (vec![Move::Forward], Vec3::Z),
            (vec![Move::Back], -Vec3::Z),
            (vec![Move::Left], Vec3::X),
            (vec![Move::Right], -Vec3::X),
            (vec![Move::Up], Vec3::Y),
            (vec![Move::Down], -Vec3::Y),
        ] {
            let mut fly = looking_along_z();
            let start = fly.position;
            assert!(fly.step(&held(&keys), false, dt));
            let moved = fly.position - start;
            assert!((moved - want * 0.2).length() < 1e-5, "{keys:?}: {moved}");
            let mut fast = looking_along_z();
            fast.step(&held(&keys), true, dt);
            assert!(((fast.position - start) - want * 1.0).length() < 1e-5);
        }
        // Opposite keys cancel; nothing held is no move.
        let mut fly = looking_along_z();
        assert!(!fly.step(&held(&[Move::Forward, Move::Back]), false, dt));
        assert!(!fly.step(&Held::default(), false, dt));
        // Diagonals are not faster.
        fly.step(&held(&[Move::Forward, Move::Right]), false, 0.25);
        assert!(((fly.position - Vec3::new(1.0, 2.0, 3.0)).length() - 0.5).abs() < 1e-5);
    }

    #[test]
    fn a_stalled_frame_moves_at_most_a_quarter_second() {
        let mut fly = looking_along_z();
        fly.step(&held(&[Move::Forward]), false, 30.0);
        assert!((fly.position.z - 3.5).abs() < 1e-5);
    }

    #[test]
    fn dragging_right_turns_right_and_up_looks_up_short_of_straight_up() {
        let mut fly = looking_along_z();
        let right = fly.right();
        assert!(fly.look(100.0, 0.0));
        assert!(fly.forward().dot(right) > 0.3, "{}", fly.forward());
        let mut fly = looking_along_z();
        fly.look(0.0, -100.0);
        assert!(fly.forward().y > 0.3);
        fly.look(0.0, -1e6);
        assert!(fly.pitch < std::f32::consts::FRAC_PI_2);
        fly.camera().validate().unwrap();
        assert!(!fly.look(0.0, 0.0));
        assert!(!fly.look(f32::NAN, 1.0));
    }

    #[test]
    fn the_wheel_scales_the_speed_within_its_limits() {
        let mut fly = looking_along_z();
        fly.wheel(1.0);
        assert!((fly.speed - 2.5).abs() < 1e-5);
        fly.wheel(-2.0);
        assert!((fly.speed - 1.6).abs() < 1e-5);
        fly.wheel(1000.0);
        assert_eq!(fly.speed, SPEED_RANGE.1);
        fly.wheel(-1e4);
        assert_eq!(fly.speed, SPEED_RANGE.0);
    }
}
