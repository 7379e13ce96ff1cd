//! CPU twins of the reflection probes: cube texel directions and faces, the probe box, the
//! talk's horizon occlusion and roughness parallax compensation, the GGX prefilter as the
//! integral it estimates, and the lookup's nesting.

use glam::{DMat3, DVec3, Mat4, Vec3, Vec4};

use super::ReflectionProbeGpu;

/// The fraction of the GGX lobe's energy the talk's reflection cone holds.
pub const CONE_ENERGY: f32 = 0.95;

/// Unit direction through the centre of texel (x, y) of `face` (n texels a side), in the
/// Vulkan / D3D cube map order (+X, -X, +Y, -Y, +Z, -Z).
pub fn texel_direction(face: usize, x: u32, y: u32, n: u32) -> Vec3 {
    let s = (x as f32 + 0.5) / n as f32 * 2.0 - 1.0;
    let t = (y as f32 + 0.5) / n as f32 * 2.0 - 1.0;
    let d = match face {
        0 => Vec3::new(1.0, -t, -s),
        1 => Vec3::new(-1.0, -t, s),
        2 => Vec3::new(s, 1.0, t),
        3 => Vec3::new(s, -1.0, -t),
        4 => Vec3::new(s, -t, 1.0),
        _ => Vec3::new(-s, -t, -1.0),
    };
    d.normalize()
}

/// The face a direction falls on and its [0, 1]^2 coordinates there.
pub fn face_uv(d: Vec3) -> (usize, [f32; 2]) {
    let a = d.abs();
    let (face, sc, tc, ma) = if a.x >= a.y && a.x >= a.z {
        if d.x > 0.0 {
            (0, -d.z, -d.y, a.x)
        } else {
            (1, d.z, -d.y, a.x)
        }
    } else if a.y >= a.z {
        if d.y > 0.0 {
            (2, d.x, d.z, a.y)
        } else {
            (3, d.x, -d.z, a.y)
        }
    } else if d.z > 0.0 {
        (4, d.x, -d.y, a.z)
    } else {
        (5, -d.x, -d.y, a.z)
    };
    let m = ma.max(1e-30);
    (face, [sc / m * 0.5 + 0.5, tc / m * 0.5 + 0.5])
}

fn to_box(p: &ReflectionProbeGpu) -> Mat4 {
    Mat4::from_cols_array_2d(&p.to_box)
}

/// Where a ray from x along d leaves the probe's box, as a multiple of d; 0 outside it.
pub fn box_exit(p: &ReflectionProbeGpu, x: Vec3, d: Vec3) -> f32 {
    let m = to_box(p);
    let o = m.transform_point3(x);
    let dl = m.transform_vector3(d);
    if o.abs().max_element() > 1.0 {
        return 0.0;
    }
    let mut t = f32::INFINITY;
    for k in 0..3 {
        if dl[k].abs() >= 1e-30 {
            t = t.min((dl[k].signum() - o[k]) / dl[k]);
        }
    }
    t.max(0.0)
}

/// The probe's weight at x: 1 deeper than its blend distance inside every face, linear to 0
/// at the faces, 0 outside and for a probe that is not resident.
pub fn box_weight(p: &ReflectionProbeGpu, x: Vec3) -> f32 {
    if p.half_m[3] <= 0.0 {
        return 0.0;
    }
    let o = to_box(p).transform_point3(x);
    let half = Vec3::from_slice(&p.half_m[..3]);
    let inside = (Vec3::ONE - o.abs()) * half;
    let m = inside.min_element();
    if m < 0.0 {
        0.0
    } else if p.capture[3] <= 0.0 {
        1.0
    } else {
        (m / p.capture[3]).clamp(0.0, 1.0)
    }
}

/// tan of the half-angle of the cone holding [`CONE_ENERGY`] of a GGX lobe of `alpha` (the
/// talk: tan theta_c = alpha sqrt(u / (1 - u))).
pub fn cone_tan(alpha: f32) -> f32 {
    alpha * (CONE_ENERGY / (1.0 - CONE_ENERGY)).sqrt()
}

fn smoothstep(e0: f32, e1: f32, x: f32) -> f32 {
    let t = ((x - e0) / (e1 - e0)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// The talk's horizon occlusion: the fraction of the reflection cone around r (GGX `alpha`)
/// lost below the surface of vertex normal nv because the mapped normal nm tilts.
pub fn horizon_occlusion(nm: Vec3, nv: Vec3, r: Vec3, alpha: f32) -> f32 {
    let plane = nv.cross(r);
    if plane.length_squared() < 1e-12 {
        return 0.0;
    }
    let b = plane.normalize();
    let np = nm - b * nm.dot(b);
    if np.length_squared() < 1e-12 {
        return 0.0;
    }
    let np = np.normalize();
    let theta_p = np.dot(nv).clamp(-1.0, 1.0).acos();
    let theta_r = r.dot(nv).clamp(-1.0, 1.0).acos();
    let theta_c = cone_tan(alpha).atan();
    let theta_o = (theta_r + theta_c - std::f32::consts::FRAC_PI_2).min(2.0 * theta_p);
    if theta_c < 1e-6 {
        return if theta_o > 0.0 { CONE_ENERGY } else { 0.0 };
    }
    CONE_ENERGY * smoothstep(0.0, 2.0 * theta_c, theta_o)
}

/// The talk's roughness parallax compensation: alpha_c = alpha_e d_e / d_c.
pub fn compensated_alpha(alpha: f32, d_eye: f32, d_capture: f32) -> f32 {
    (alpha * d_eye / d_capture.max(1e-4)).clamp(0.0, 1.0)
}

/// The GGX-prefiltered radiance a probe's level of GGX `alpha` holds in direction `n`: the
/// integral the filtered importance sampling estimates (normal = view = reflection),
///   int env(l) D(h) (n.l) dl / int D(h) (n.l) dl over the hemisphere about n,
/// by quadrature over the half vector's polar angle (`steps` x 4 `steps` cells, f64).
pub fn prefilter_integral(env: impl Fn(Vec3) -> Vec3, n: Vec3, alpha: f64, steps: usize) -> Vec3 {
    let n = n.as_dvec3().normalize();
    let up = if n.z.abs() < 0.999 {
        DVec3::Z
    } else {
        DVec3::X
    };
    let t = up.cross(n).normalize();
    let frame = DMat3::from_cols(t, n.cross(t), n);
    let a2 = alpha * alpha;
    let (mut sum, mut weight) = (DVec3::ZERO, 0.0);
    let pi = std::f64::consts::PI;
    // Substituting the GGX CDF u = tan^2 / (a^2 + tan^2) for the half vector's angle spreads
    // the cells evenly over the lobe: D(h) cos(h) dw_h is then du dphi / (2 pi).
    for i in 0..steps {
        let u = (i as f64 + 0.5) / steps as f64;
        let cos_h = ((1.0 - u) / (1.0 + (a2 - 1.0) * u)).sqrt();
        let sin_h = (1.0 - cos_h * cos_h).max(0.0).sqrt();
        for j in 0..4 * steps {
            let phi = 2.0 * pi * (j as f64 + 0.5) / (4 * steps) as f64;
            let h = frame * DVec3::new(sin_h * phi.cos(), sin_h * phi.sin(), cos_h);
            let l = 2.0 * cos_h * h - n;
            let n_dot_l = n.dot(l);
            if n_dot_l <= 0.0 {
                continue;
            }
            // dl = 4 (v.h) dh: with v = n the Jacobian's cos_h cancels D's cos_h; the weight
            // of a cell is (n.l) (its D cos_h dh share is uniform).
            let w = n_dot_l;
            sum += env(l.as_vec3()).as_dvec3() * w;
            weight += w;
        }
    }
    (sum / weight.max(1e-300)).as_vec3()
}

/// Twin of `rp_box_light_irradiance`: the irradiance (lux) one point or spot light gives x of
/// normal n, unshadowed, if it lies inside the probe's box, else 0. `cutoff_lux`: the frame's
/// punctual-light cut-off, which shortens the light's range.
pub fn box_light_irradiance(
    p: &ReflectionProbeGpu,
    light: &crate::scene::upload::LightGpu,
    cutoff_lux: f32,
    x: Vec3,
    n: Vec3,
) -> Vec3 {
    use crate::lights::reference::light_attenuation;
    let at = Vec3::from_slice(&light.position_range[..3]);
    if to_box(p).transform_point3(at).abs().max_element() > 1.0 {
        return Vec3::ZERO;
    }
    let to_light = at - x;
    let d2 = to_light.length_squared().max(1e-8);
    let l = to_light / d2.sqrt();
    Vec3::from_slice(&light.intensity[..3])
        * (light_attenuation(cutoff_lux, light, l, d2) * n.dot(l).max(0.0))
}

/// Twin of the relight's capture light: the luminance of the irradiance at the capture point
/// as an L1 function of the normal (mean, x, y, z slopes) from `e_luma(normal)` along the six
/// axes, whose mean is an L2 SH's band 0 exactly.
pub fn capture_light(e_luma: impl Fn(Vec3) -> f32) -> Vec4 {
    let [xp, xn, yp, yn, zp, zn] =
        [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z].map(&e_luma);
    Vec4::new(
        (xp + xn + yp + yn + zp + zn) / 6.0,
        0.5 * (xp - xn),
        0.5 * (yp - yn),
        0.5 * (zp - zn),
    )
}

/// One probe as the lookup sees it.
pub struct LookupProbe<'a> {
    pub gpu: ReflectionProbeGpu,
    /// Luminance of the irradiance at its capture point: mean, x, y, z slopes ([`capture_light`]).
    pub capture_light: Vec4,
    /// Luminance of the irradiance the lights inside its box give the surface, unshadowed
    /// ([`box_light_irradiance`]), which the normalisation adds to the surface's ambient.
    pub lights_luma: f32,
    /// Its prefiltered radiance along a direction at a level of detail.
    pub sample: &'a dyn Fn(Vec3, f32) -> Vec3,
}

/// Switches and values of the lookup (`LookupParams`).
pub struct LookupOptions {
    pub levels: u32,
    pub horizon: bool,
    pub parallax_roughness: bool,
    pub normalize: bool,
    pub max_normalization: f32,
}

/// Twin of `reflection_probe_radiance`: rgb, and the probes' coverage in w. `e_luma`: the
/// luminance of the surface's ambient irradiance.
#[allow(clippy::too_many_arguments)]
pub fn lookup(
    probes: &[LookupProbe<'_>],
    o: &LookupOptions,
    x: Vec3,
    nm: Vec3,
    nv: Vec3,
    v: Vec3,
    roughness: f32,
    e_luma: f32,
) -> Vec4 {
    let r = (2.0 * nm.dot(v)) * nm - v;
    let alpha = roughness * roughness;
    let levels = (o.levels.max(1) - 1) as f32;
    let mut sum = Vec3::ZERO;
    let mut covered = 0.0;
    for p in probes {
        let w = box_weight(&p.gpu, x);
        if w <= 0.0 {
            continue;
        }
        let t = box_exit(&p.gpu, x, r);
        let dir = x + r * t - Vec3::from_slice(&p.gpu.capture[..3]);
        let a = if o.parallax_roughness {
            compensated_alpha(alpha, t, dir.length())
        } else {
            alpha
        };
        let mut c = (p.sample)(dir, a.sqrt() * levels);
        if o.normalize {
            let l = p.capture_light;
            let at_capture = l.x + Vec3::new(l.y, l.z, l.w).dot(nm);
            c *= ((e_luma + p.lights_luma) / at_capture.max(1e-6)).clamp(0.0, o.max_normalization);
        }
        let take = (1.0 - covered) * w;
        sum += c * take;
        covered += take;
        if covered >= 0.999 {
            break;
        }
    }
    if o.horizon {
        sum *= 1.0 - horizon_occlusion(nm, nv, r, alpha);
    }
    sum.extend(covered)
}

/// One captured texel: albedo (a: interior mask), octahedral normal and distance (0: sky),
/// emission.
#[derive(Clone, Copy, Debug)]
pub struct CaptureTexel {
    pub albedo: Vec4,
    pub normal_depth: Vec4,
    pub emission: Vec3,
}

/// Twin of `relight.wgsl`'s `cube_map_shadow`: the fraction of the PCF footprint (2r x 2r
/// texels, clamped to the face) round the direction of the sun ray's exit from the box in
/// which the capture point sees sky. `depth(layer, x, y)`: the captured distance.
pub fn cube_map_shadow(
    p: &ReflectionProbeGpu,
    probe: usize,
    n: u32,
    radius: i32,
    depth: CapturedDepth<'_>,
    x: Vec3,
    l: Vec3,
) -> f32 {
    let t = box_exit(p, x, l);
    if t <= 0.0 {
        return 1.0;
    }
    let q = x + l * t - Vec3::from_slice(&p.capture[..3]);
    let (face, uv) = face_uv(q);
    let cx = (uv[0] * n as f32 - 0.5).floor() as i32;
    let cy = (uv[1] * n as f32 - 0.5).floor() as i32;
    let (mut lit, mut total) = (0.0, 0.0);
    let lo = 1 - radius.max(1);
    for j in lo..=radius {
        for i in lo..=radius {
            let tx = (cx + i).clamp(0, n as i32 - 1);
            let ty = (cy + j).clamp(0, n as i32 - 1);
            if depth(probe * 6 + face, tx, ty) <= 0.0 {
                lit += 1.0;
            }
            total += 1.0;
        }
    }
    lit / total
}

/// The captured distance of texel (x, y) of a layer (probe * 6 + face).
pub type CapturedDepth<'a> = &'a dyn Fn(usize, i32, i32) -> f32;

/// What lights a relit texel (`RelightParams`, as functions of position and normal).
pub struct RelightLight<'a> {
    /// Unit vector towards the sun or moon and its RGB illuminance, lux.
    pub sun: Option<(Vec3, Vec3)>,
    /// The cube-map shadow's PCF radius, `None` with shadow tracing off, and the captured
    /// distances it reads.
    pub shadow: Option<(i32, CapturedDepth<'a>)>,
    /// Irradiance from the probes or the sky at (position, normal, interior mask), lux.
    pub ambient: &'a dyn Fn(Vec3, Vec3, f32) -> Vec3,
    /// Irradiance from the point and spot lights inside the box, lux.
    pub lights: &'a dyn Fn(Vec3, Vec3) -> Vec3,
    /// The sky's radiance towards a direction, clouds included, no sun disk.
    pub sky: &'a dyn Fn(Vec3) -> Vec3,
    /// The clouds' shadow at a position.
    pub cloud_shadow: &'a dyn Fn(Vec3) -> f32,
}

/// Twin of `relight.wgsl`: the radiance of texel (x, y) of `face` of probe `probe`.
pub fn relight_texel(
    p: &ReflectionProbeGpu,
    probe: usize,
    face: usize,
    [x, y]: [u32; 2],
    n: u32,
    t: &CaptureTexel,
    light: &RelightLight<'_>,
) -> Vec3 {
    let dir = texel_direction(face, x, y, n);
    let d = t.normal_depth.z;
    if d <= 0.0 {
        return (light.sky)(dir);
    }
    let pos = Vec3::from_slice(&p.capture[..3]) + dir * d;
    let nrm =
        crate::reference::octahedral::decode(glam::Vec2::new(t.normal_depth.x, t.normal_depth.y));
    let mut e = (light.ambient)(pos, nrm, t.albedo.w);
    if let Some((l, lux)) = light.sun {
        let cos_l = nrm.dot(l).max(0.0);
        if cos_l > 0.0 {
            let mut vis = (light.cloud_shadow)(pos);
            if let Some((radius, depth)) = light.shadow {
                vis *= cube_map_shadow(p, probe, n, radius, depth, pos, l);
            }
            e += lux * (cos_l * vis);
        }
    }
    e += (light.lights)(pos, nrm);
    t.albedo.truncate() / std::f32::consts::PI * e + t.emission
}
