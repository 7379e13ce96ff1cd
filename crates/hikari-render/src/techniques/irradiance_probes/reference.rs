//! CPU twins of the probes' passes, on hikari-math's SH: the relight (`relight.wgsl`) and the
//! lookup (`lookup.wgsl`), both over the arrays of [`ProbeGpuData`].

use glam::Vec3;
use hikari_math::sh::dering::{dering, directionality_boost};
use hikari_math::sh::product::product_l2_mono;
use hikari_math::sh::{Sh, ShL2, ShL2Rgb, basis, window, zonal};

use super::gpu_data::{
    COLUMNS, MeshSlot, NO_TILE, PROBES_GRID, PROBES_INTERIOR_MASK, PROBES_PRESENT, ProbeGpuData,
    START_CELLS, TILE_SIDE,
};
use super::{RELIGHT_BOOST, RELIGHT_BOUNCE, RELIGHT_DERING, RELIGHT_SUN_BOUNCE, RelightParams};
use hikari_probes::HULL;

/// The Sloan 2017 strength that leaves a projected delta with no negative lobe (hikari-math's
/// deringing notes: a delta needs exactly 1/4).
pub const LOBE_LAMBDA: f32 = 0.25;

/// Steps of the walk through a mesh's tetrahedra before the point counts as outside it.
pub const MAX_WALK_STEPS: u32 = 256;

/// A point is inside a tetrahedron when no barycentric coordinate is below this.
pub const INSIDE_EPSILON: f32 = 1e-5;

/// Metres inside a tetrahedral mesh's bounds over which its weight rises from 0 (at the
/// bounds) to 1; the grid takes the rest ([`mesh_blend_weight`]).
pub const BLEND_MARGIN_M: f32 = 1.0;

/// Radiance SH of the sun's (or moon's) light bounced by an imaginary ground and an imaginary
/// wall facing the light, as seen by a probe whose mean bounced visibility (relative to a
/// white sky) is `mean_bounce`: each reflection's negated direction as a windowed delta,
/// weighted by the cosine at its surface, times the light's RGB irradiance. The factor 2
/// makes the ground's lobe the irradiance a Lambertian plane of albedo `2 * mean_bounce`
/// (a probe above such a plane sees it over half the sphere) reflects.
pub fn sun_bounce(to_light: Vec3, light_rgb: Vec3, mean_bounce: Vec3, scale: f32) -> ShL2Rgb {
    let l = to_light;
    let ground = Vec3::new(l.x, -l.y, l.z);
    let wall = Vec3::new(-l.x, l.y, -l.z);
    let ground_w = l.y.max(0.0);
    let wall_w = if l.y > 0.0 {
        Vec3::new(l.x, 0.0, l.z).length()
    } else {
        0.0
    };
    let strength = light_rgb * mean_bounce * (2.0 * scale);
    let yg = basis::eval_l2(ground);
    let yw = basis::eval_l2(wall);
    let lobes: ShL2 = Sh::new(std::array::from_fn(|k| ground_w * yg[k] + wall_w * yw[k]))
        .scale_bands(window::sloan2017(LOBE_LAMBDA));
    Sh::new(lobes.coeffs.map(|c| strength * c))
}

/// One probe's irradiance SH (lux per unit normal direction, RGB) relit from the sky's
/// radiance SH `sky` (nits), as `relight.wgsl` does: sky times visibility, plus bounced
/// visibility times the sky's average and the sun bounce, each convolved with the cosine lobe
/// and boosted separately, summed and deringed.
pub fn relight_probe(
    sky: &ShL2Rgb,
    visibility: &ShL2,
    bounced_visibility: &ShL2Rgb,
    p: &RelightParams,
) -> ShL2Rgb {
    let flags = p.config[1];
    let direct = product_l2_mono(sky, visibility);
    let mut bounced = ShL2Rgb::zero();
    if flags & RELIGHT_BOUNCE != 0 {
        let mean_sky = sky.coeffs[0] * basis::C0 as f32;
        bounced = Sh::new(bounced_visibility.coeffs.map(|c| c * mean_sky));
    }
    if flags & RELIGHT_SUN_BOUNCE != 0 {
        let mean_bounce = bounced_visibility.coeffs[0] * basis::C0 as f32;
        let to_light = Vec3::from_slice(&p.light_dir[..3]);
        let rgb = Vec3::from_slice(&p.light_rgb[..3]);
        let sun = sun_bounce(to_light, rgb, mean_bounce, p.light_rgb[3]);
        bounced = Sh::new(std::array::from_fn(|k| bounced.coeffs[k] + sun.coeffs[k]));
    }
    let mut direct = zonal::irradiance(&direct);
    let mut bounced = zonal::irradiance(&bounced);
    if flags & RELIGHT_BOOST != 0 {
        direct = directionality_boost(&direct, p.amounts[0]);
        bounced = directionality_boost(&bounced, p.amounts[0]);
    }
    let total: ShL2Rgb = Sh::new(std::array::from_fn(|k| {
        direct.coeffs[k] + bounced.coeffs[k]
    }));
    if flags & RELIGHT_DERING != 0 {
        dering(&total).sh
    } else {
        total
    }
}

/// Every probe of `data` relit: 9 RGB coefficients per probe, as the `irradiance` buffer.
pub fn relight_all(data: &ProbeGpuData, sky: &ShL2Rgb, p: &RelightParams) -> Vec<ShL2Rgb> {
    relight_all_shadowed(data, sky, p, &|_| 1.0)
}

/// [`relight_all`] with the sun bounce of each probe times `cloud_shadow` at its position
/// (`relight.wgsl` reads `hikari::clouds::cloud_shadow` there; twin
/// `clouds::reference::cloud_shadow_at`).
pub fn relight_all_shadowed(
    data: &ProbeGpuData,
    sky: &ShL2Rgb,
    p: &RelightParams,
    cloud_shadow: &dyn Fn(Vec3) -> f32,
) -> Vec<ShL2Rgb> {
    (0..data.probe_count())
        .map(|i| {
            let (v, b) = data.probe_sh(i);
            let mut shadowed = *p;
            shadowed.light_rgb[3] *= cloud_shadow(Vec3::from_slice(&data.positions[i][..3]));
            relight_probe(sky, &v, &b, &shadowed)
        })
        .collect()
}

/// Barycentric coordinates of `p` in global tetrahedron `t` (vertex k's weight in entry k);
/// `None` for a degenerate tetrahedron.
pub fn barycentrics(data: &ProbeGpuData, t: u32, p: Vec3) -> Option<[f32; 4]> {
    let off = data.params.topology[1] as usize + 4 * t as usize;
    let v: [Vec3; 4] = std::array::from_fn(|k| {
        Vec3::from_slice(&data.positions[data.topology[off + k] as usize][..3])
    });
    let (a, b, c, q) = (v[0] - v[3], v[1] - v[3], v[2] - v[3], p - v[3]);
    let det = a.dot(b.cross(c));
    if det.abs() < 1e-12 {
        return None;
    }
    let b0 = q.dot(b.cross(c)) / det;
    let b1 = a.dot(q.cross(c)) / det;
    let b2 = a.dot(b.cross(q)) / det;
    Some([b0, b1, b2, 1.0 - b0 - b1 - b2])
}

/// The start-grid cell of `p` in `mesh` (x fastest), as `lookup.wgsl` computes it.
pub fn start_cell(mesh: &MeshSlot, p: Vec3) -> usize {
    let n = START_CELLS as f32;
    let c: [usize; 3] = std::array::from_fn(|a| {
        let ext = (mesh.hi[a] - mesh.lo[a]).max(1e-6);
        ((p[a] - mesh.lo[a]) / ext * n).clamp(0.0, n - 1.0) as usize
    });
    c[0] + START_CELLS * (c[1] + START_CELLS * c[2])
}

/// The tetrahedron of mesh `m` holding `p` and its barycentrics, found by walking from the
/// start grid's tetrahedron of `p`'s cell across the face opposite the most negative
/// coordinate; `None` when the walk leaves the mesh (or `p` is outside the mesh's bounds).
pub fn locate(data: &ProbeGpuData, m: usize, p: Vec3) -> Option<(u32, [f32; 4])> {
    locate_counting(data, m, p).0
}

/// [`locate`], and the steps its walk took.
pub fn locate_counting(data: &ProbeGpuData, m: usize, p: Vec3) -> (Option<(u32, [f32; 4])>, u32) {
    let mesh = &data.meshes[m];
    if mesh.tets == 0 || (0..3).any(|a| p[a] < mesh.lo[a] || p[a] > mesh.hi[a]) {
        return (None, 0);
    }
    let adj = data.params.topology[2] as usize;
    let mut t = data.topology[mesh.start_grid as usize + start_cell(mesh, p)];
    for step in 0..MAX_WALK_STEPS {
        let b = barycentrics(data, t, p).unwrap_or([-1.0, 0.0, 0.0, 0.0]);
        let (k, min) =
            b.iter().enumerate().fold(
                (0, f32::MAX),
                |acc, (k, &x)| if x < acc.1 { (k, x) } else { acc },
            );
        if min >= -INSIDE_EPSILON {
            return (Some((t, b)), step + 1);
        }
        let next = data.topology[adj + 4 * t as usize + k];
        if next == HULL {
            return (None, step + 1);
        }
        t = next;
    }
    (None, MAX_WALK_STEPS)
}

/// Mesh `m`'s barycentric weights of its probes at `p` (negative ones as 0); `None` where the
/// mesh does not hold `p`.
pub fn mesh_weights(data: &ProbeGpuData, m: usize, p: Vec3) -> Option<Vec<(u32, f32)>> {
    let (t, b) = locate(data, m, p)?;
    let off = data.params.topology[1] as usize + 4 * t as usize;
    Some(
        (0..4)
            .map(|k| (data.topology[off + k], b[k].max(0.0)))
            .collect(),
    )
}

/// The weight of a mesh's own probes at `p` inside its bounds: the distance to the nearest
/// face of the bounds over [`BLEND_MARGIN_M`], clamped to 1; the grid gets the rest, so the
/// light is continuous where the mesh ends.
pub fn mesh_blend_weight(mesh: &MeshSlot, p: Vec3) -> f32 {
    let d = (0..3)
        .map(|a| (p[a] - mesh.lo[a]).min(mesh.hi[a] - p[a]))
        .fold(f32::MAX, f32::min);
    (d / BLEND_MARGIN_M).clamp(0.0, 1.0)
}

/// Probe weights by the interior mask `mask`: each weight times `mask` for interior probes and
/// `1 - mask` for exterior ones, renormalised; the weights as given (normalised) when that
/// leaves nothing.
pub fn masked_weights(weights: &[(u32, f32)], data: &ProbeGpuData, mask: f32) -> Vec<(u32, f32)> {
    let masked: Vec<(u32, f32)> = weights
        .iter()
        .map(|&(p, w)| {
            (
                p,
                w * if data.interior(p as usize) {
                    mask
                } else {
                    1.0 - mask
                },
            )
        })
        .collect();
    let sum: f32 = masked.iter().map(|x| x.1).sum();
    if sum > 1e-6 {
        return masked.into_iter().map(|(p, w)| (p, w / sum)).collect();
    }
    let sum: f32 = weights.iter().map(|x| x.1).sum();
    weights
        .iter()
        .map(|&(p, w)| (p, w / sum.max(1e-12)))
        .collect()
}

/// The grid's trilinear weights at `p`: bilinear over the four columns around it, and along
/// each column linear between the two layers around `p`'s height (clamped to the lowest and
/// highest). Columns of missing tiles drop out.
pub fn grid_weights(data: &ProbeGpuData, p: Vec3) -> Vec<(u32, f32)> {
    let prm = &data.params;
    if prm.grid_size[3] & PROBES_GRID == 0 {
        return Vec::new();
    }
    let cols = [prm.grid_size[0] as f32, prm.grid_size[1] as f32];
    let g = [
        (p.x - prm.grid[0]) / prm.grid[2],
        (p.z - prm.grid[1]) / prm.grid[2],
    ];
    let mut i0 = [0u32; 2];
    let mut f = [0.0f32; 2];
    for a in 0..2 {
        let gc = g[a].clamp(0.0, cols[a] - 1.0);
        i0[a] = gc.floor().min((cols[a] - 2.0).max(0.0)) as u32;
        f[a] = (gc - i0[a] as f32).clamp(0.0, 1.0);
    }
    let mut out = Vec::new();
    for c in 0..4u32 {
        let ci = [i0[0] + (c & 1), i0[1] + (c >> 1)];
        if ci[0] >= prm.grid_size[0] || ci[1] >= prm.grid_size[1] {
            continue;
        }
        let wx = if c & 1 == 1 { f[0] } else { 1.0 - f[0] };
        let wz = if c >> 1 == 1 { f[1] } else { 1.0 - f[1] };
        let side = TILE_SIDE as u32;
        let tile = data.topology[((ci[1] / side) * prm.grid_size[2] + ci[0] / side) as usize];
        if tile == NO_TILE {
            continue;
        }
        let col = tile + (ci[1] % side) * side + ci[0] % side;
        let h = |layer: u32| data.positions[(col + layer * COLUMNS as u32) as usize][1];
        let upper = u32::from(p.y > h(1));
        let (ha, hb) = (h(upper), h(upper + 1));
        let t = ((p.y - ha) / (hb - ha).max(1e-4)).clamp(0.0, 1.0);
        let base = col + upper * COLUMNS as u32;
        out.push((base, wx * wz * (1.0 - t)));
        out.push((base + COLUMNS as u32, wx * wz * t));
    }
    out
}

/// The parts of the lookup at `p`: the first mesh holding `p` (its barycentric weights, and
/// its blend weight: [`mesh_blend_weight`], 1 when there is no grid) and the grid's weights
/// where the mesh leaves the grid a share (or holds nothing).
pub struct LookupParts {
    pub mesh: Vec<(u32, f32)>,
    pub mesh_weight: f32,
    pub grid: Vec<(u32, f32)>,
}

pub fn lookup_parts(data: &ProbeGpuData, p: Vec3) -> LookupParts {
    let has_grid = data.params.grid_size[3] & PROBES_GRID != 0;
    for m in 0..data.meshes.len() {
        if let Some(mesh) = mesh_weights(data, m, p) {
            let a = if has_grid {
                mesh_blend_weight(&data.meshes[m], p)
            } else {
                1.0
            };
            let grid = if a < 1.0 {
                grid_weights(data, p)
            } else {
                Vec::new()
            };
            let a = if grid.iter().map(|x| x.1).sum::<f32>() > 0.0 {
                a
            } else {
                1.0
            };
            return LookupParts {
                mesh,
                mesh_weight: a,
                grid,
            };
        }
    }
    LookupParts {
        mesh: Vec::new(),
        mesh_weight: 0.0,
        grid: grid_weights(data, p),
    }
}

/// The probes and (unmasked, unnormalised) weights that light a point at `p`: the mesh's times
/// its blend weight and the grid's times the rest; empty where no probe covers it.
pub fn lookup_weights(data: &ProbeGpuData, p: Vec3) -> Vec<(u32, f32)> {
    let parts = lookup_parts(data, p);
    let a = parts.mesh_weight;
    let mut out: Vec<(u32, f32)> = parts.mesh.into_iter().map(|(k, w)| (k, w * a)).collect();
    out.extend(parts.grid.into_iter().map(|(k, w)| (k, w * (1.0 - a))));
    out
}

/// The weights the lookup uses at `p` with interior mask `mask`: the mesh's and the grid's
/// each masked and renormalised ([`masked_weights`]) on their own, then blended (so the blend
/// stays continuous however the mask weighs either side); empty where no probe covers `p`.
pub fn blended_weights(data: &ProbeGpuData, p: Vec3, mask: f32) -> Vec<(u32, f32)> {
    let parts = lookup_parts(data, p);
    let a = parts.mesh_weight;
    let total = |w: &[(u32, f32)]| w.iter().map(|x| x.1).sum::<f32>();
    let mut out = Vec::new();
    if a > 0.0 && total(&parts.mesh) > 0.0 {
        out.extend(
            masked_weights(&parts.mesh, data, mask)
                .into_iter()
                .map(|(k, w)| (k, w * a)),
        );
    }
    if a < 1.0 && total(&parts.grid) > 0.0 {
        out.extend(
            masked_weights(&parts.grid, data, mask)
                .into_iter()
                .map(|(k, w)| (k, w * (1.0 - a))),
        );
    }
    out
}

/// The irradiance at `p` averaged over every normal (each probe's constant term, weighted as
/// [`irradiance_at`] weighs it), lux, clamped at 0 and times `params.grid.w`; `None` where no
/// probe covers `p`: what the lookup gives with n = 0.
pub fn average_irradiance_at(
    data: &ProbeGpuData,
    params: &super::gpu_data::ProbeLookupParams,
    irradiance: &[ShL2Rgb],
    p: Vec3,
    mask: f32,
) -> Option<Vec3> {
    let y00 = 0.5 / std::f32::consts::PI.sqrt();
    weighted_sum(data, params, p, mask, |k| {
        irradiance[k as usize].coeffs[0] * y00
    })
}

/// `Σ w_k value(k)` over the probes that light `p` with interior mask `mask` (the frame's
/// flags decide whether the mask counts), clamped at 0 and times `params.grid.w`; `None`
/// without probes or where none covers `p`.
fn weighted_sum(
    data: &ProbeGpuData,
    params: &super::gpu_data::ProbeLookupParams,
    p: Vec3,
    mask: f32,
    value: impl Fn(u32) -> Vec3,
) -> Option<Vec3> {
    if params.grid_size[3] & PROBES_PRESENT == 0 {
        return None;
    }
    let mask = if params.grid_size[3] & PROBES_INTERIOR_MASK != 0 {
        mask
    } else {
        0.5
    };
    let w = blended_weights(data, p, mask);
    if w.iter().map(|x| x.1).sum::<f32>() <= 0.0 {
        return None;
    }
    let e: Vec3 = w.iter().map(|&(k, wk)| value(k) * wk).sum();
    Some(e.max(Vec3::ZERO) * params.grid[3])
}

/// Irradiance at `p` on a surface with normal `n` and interior mask `mask` from the relit
/// probes (`irradiance`, one SH per probe), lux, clamped at 0 and times `params.grid.w`;
/// `None` where no probe covers `p`. `params` carries the frame's flags and scale.
pub fn irradiance_at(
    data: &ProbeGpuData,
    params: &super::gpu_data::ProbeLookupParams,
    irradiance: &[ShL2Rgb],
    p: Vec3,
    n: Vec3,
    mask: f32,
) -> Option<Vec3> {
    weighted_sum(data, params, p, mask, |k| irradiance[k as usize].eval(n))
}
