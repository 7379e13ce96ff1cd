//! Deringing as in Ghost of Tsushima (Patry 2021, after Sloan 2017): find the minimum of the
//! L2 function with one Newton step from a few good starting directions, then pick the window
//! strength by a depth-3 binary search so that the windowed function is non-negative.
//!
//! Also the directionality boost of the same talk: lerp toward the SH of a delta in the
//! direction of the linear (band-1) maximum.

use super::{Sh, ShCoeff, basis, window};
use glam::{DVec3, Vec3};

/// Scale of the window strength: the Sloan 2017 `λ` used for strength `t ∈ [0, 1)` is
/// `LAMBDA_SCALE · t / (1 − t)` (so `t = 1` keeps band 0 only). Chosen so that the depth-3
/// search grid (t = 1/8 ... 1) spans from light to strong deringing: a projected delta needs
/// `λ = 1/4` exactly, and `t = 1/2` gives `λ = 0.3`, with a little margin.
pub const LAMBDA_SCALE: f32 = 0.3;

/// Depth of the binary search over window strength (the talk's value).
pub const SEARCH_DEPTH: u32 = 3;

/// Starting directions of the minimum search besides the negated linear direction:
/// the six axes and the eight cube diagonals cover every quadratic lobe orientation well
/// enough that one Newton step lands in the right basin.
fn start_directions() -> [DVec3; 14] {
    let s = 1.0 / 3f64.sqrt();
    [
        DVec3::X,
        DVec3::NEG_X,
        DVec3::Y,
        DVec3::NEG_Y,
        DVec3::Z,
        DVec3::NEG_Z,
        DVec3::new(s, s, s),
        DVec3::new(s, s, -s),
        DVec3::new(s, -s, s),
        DVec3::new(s, -s, -s),
        DVec3::new(-s, s, s),
        DVec3::new(-s, s, -s),
        DVec3::new(-s, -s, s),
        DVec3::new(-s, -s, -s),
    ]
}

/// Value, gradient and Hessian of the polynomial extension of an L2 scalar function.
fn value_grad_hess(c: &[f64; 9], v: DVec3) -> (f64, DVec3, [[f64; 3]; 3]) {
    use basis::{C0, C1, C2, C3, C4};
    let (x, y, z) = (v.x, v.y, v.z);
    let f = C0 * c[0]
        + C1 * (c[1] * y + c[2] * z + c[3] * x)
        + C2 * (c[4] * x * y + c[5] * y * z + c[7] * x * z)
        + C3 * c[6] * (3.0 * z * z - 1.0)
        + C4 * c[8] * (x * x - y * y);
    let g = DVec3::new(
        C1 * c[3] + C2 * (c[4] * y + c[7] * z) + 2.0 * C4 * c[8] * x,
        C1 * c[1] + C2 * (c[4] * x + c[5] * z) - 2.0 * C4 * c[8] * y,
        C1 * c[2] + C2 * (c[5] * y + c[7] * x) + 6.0 * C3 * c[6] * z,
    );
    let h = [
        [2.0 * C4 * c[8], C2 * c[4], C2 * c[7]],
        [C2 * c[4], -2.0 * C4 * c[8], C2 * c[5]],
        [C2 * c[7], C2 * c[5], 6.0 * C3 * c[6]],
    ];
    (f, g, h)
}

/// One Riemannian Newton step on the unit sphere toward a minimum; returns the new direction
/// (or `v` itself when the tangent Hessian is not positive definite, i.e. not near a minimum).
fn newton_step(c: &[f64; 9], v: DVec3) -> DVec3 {
    let (_, g, h) = value_grad_hess(c, v);
    let (t1, t2) = v.any_orthonormal_pair();
    let hv = |a: DVec3| {
        DVec3::new(
            h[0][0] * a.x + h[0][1] * a.y + h[0][2] * a.z,
            h[1][0] * a.x + h[1][1] * a.y + h[1][2] * a.z,
            h[2][0] * a.x + h[2][1] * a.y + h[2][2] * a.z,
        )
    };
    // Tangent Hessian on the sphere: Pᵀ H P − (v·∇f) I.
    let vg = v.dot(g);
    let a11 = t1.dot(hv(t1)) - vg;
    let a12 = t1.dot(hv(t2));
    let a22 = t2.dot(hv(t2)) - vg;
    let det = a11 * a22 - a12 * a12;
    if !(a11 > 0.0 && det > 0.0) {
        return v;
    }
    let (g1, g2) = (t1.dot(g), t2.dot(g));
    let s1 = -(a22 * g1 - a12 * g2) / det;
    let s2 = -(-a12 * g1 + a11 * g2) / det;
    let step = t1 * s1 + t2 * s2;
    // A step longer than ~1 rad leaves the region where the quadratic model is meaningful.
    let len = step.length();
    let step = if len > 1.0 { step / len } else { step };
    (v + step).normalize_or(v)
}

/// Estimated minimum of a scalar L2 function over the sphere: `(direction, value)`.
/// One Newton step from the negated band-1 direction and from 14 fixed directions (the talk's
/// "one Newton step"), then one more step from the best of those, which brings the typical
/// error from ~1e-2 to ~1e-4 of the coefficient scale for the cost of one extra step.
pub fn find_minimum(sh: &Sh<f32, 9>) -> (Vec3, f32) {
    let c = sh.coeffs.map(f64::from);
    let lin = DVec3::new(c[3], c[1], c[2]);
    let mut best = (DVec3::Z, f64::INFINITY);
    let mut try_start = |v: DVec3| {
        for d in [v, newton_step(&c, v)] {
            let (f, _, _) = value_grad_hess(&c, d);
            if f < best.1 {
                best = (d, f);
            }
        }
    };
    if let Some(n) = (-lin).try_normalize() {
        try_start(n);
    }
    for v in start_directions() {
        try_start(v);
    }
    let refined = newton_step(&c, best.0);
    let (f, _, _) = value_grad_hess(&c, refined);
    if f < best.1 {
        best = (refined, f);
    }
    (best.0.as_vec3(), best.1 as f32)
}

/// Window factors for deringing strength `t ∈ [0, 1]` (0: none, 1: band 0 only).
pub fn dering_window(t: f32) -> [f32; 3] {
    if t >= 1.0 {
        [1.0, 0.0, 0.0]
    } else {
        window::sloan2017(LAMBDA_SCALE * t.max(0.0) / (1.0 - t.max(0.0)))
    }
}

/// Smallest strength on the depth-[`SEARCH_DEPTH`] grid for which `ok(window)` holds,
/// assuming `ok` is monotone in strength. Strength 0 is returned when no windowing is needed.
fn search_strength(mut ok: impl FnMut([f32; 3]) -> bool) -> f32 {
    if ok(dering_window(0.0)) {
        return 0.0;
    }
    let (mut lo, mut hi) = (0.0f32, 1.0f32);
    for _ in 0..SEARCH_DEPTH {
        let mid = 0.5 * (lo + hi);
        if ok(dering_window(mid)) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    hi
}

/// Deringing result: the windowed SH and the strength used.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Deringed<T: ShCoeff> {
    /// The windowed coefficients (non-negative everywhere up to the minimum search accuracy).
    pub sh: Sh<T, 9>,
    /// Window strength in [0, 1] (see [`dering_window`]).
    pub strength: f32,
}

/// Deringing of any L2 SH (scalar or RGB): one window strength for all channels, so hue is
/// kept; the smallest strength of the depth-3 grid that makes every channel's estimated
/// minimum non-negative. A function with a negative mean (band 0 < 0) cannot be made
/// non-negative by windowing and is returned as zero with strength 1.
pub fn dering<T: ShCoeff>(sh: &Sh<T, 9>) -> Deringed<T> {
    if (0..T::CHANNELS).any(|k| sh.coeffs[0].channel(k) < 0.0) {
        return Deringed {
            sh: Sh::zero(),
            strength: 1.0,
        };
    }
    let non_negative = |w: [f32; 3]| {
        let s = sh.scale_bands(w);
        (0..T::CHANNELS).all(|k| find_minimum(&s.channel(k)).1 >= 0.0)
    };
    let strength = search_strength(non_negative);
    Deringed {
        sh: sh.scale_bands(dering_window(strength)),
        strength,
    }
}

/// Rec.709 luminance weights, used to pick one direction for RGB SH.
const LUMA: Vec3 = Vec3::from_array(crate::color::REC709_LUMA);

/// Direction of the maximum of the linear (band 0 + 1) part, `normalize(c₃, c₁, c₂)`; for RGB,
/// of the Rec.709 luminance. `None` when the band-1 part is zero.
pub fn linear_max_direction<T: ShCoeff, const N: usize>(sh: &Sh<T, N>) -> Option<Vec3> {
    let [x, y, z] = sh.linear_vector();
    let lum = |t: T| {
        if T::CHANNELS == 1 {
            t.channel(0)
        } else {
            (0..3).map(|k| t.channel(k) * LUMA[k]).sum()
        }
    };
    Vec3::new(lum(x), lum(y), lum(z)).try_normalize()
}

/// Directionality boost (Patry 2021): `lerp(sh, delta, amount)` where `delta` is the SH of a
/// delta function in the linear-maximum direction with the same band-0 coefficient (so the
/// average is unchanged). The talk used `amount = 0.25`. Unchanged when there is no direction.
pub fn directionality_boost<T: ShCoeff, const N: usize>(sh: &Sh<T, N>, amount: f32) -> Sh<T, N> {
    let Some(d) = linear_max_direction(sh) else {
        return *sh;
    };
    let weight = sh.coeffs[0] * (1.0 / basis::C0 as f32);
    sh.lerp(&Sh::delta(d, weight), amount)
}
