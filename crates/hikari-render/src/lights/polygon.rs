//! Which emissive surfaces are polygonal area lights, and their GPU records.
//!
//! Rule (docs/area-lights.md): every instance whose material emits (non-zero
//! `emissive_nits`) is a candidate. Its material's `area_light` flag (glTF material `extras`:
//! `{"hikari": {"area_light": true}}`) decides when it is set; without it the instance is an
//! area light when its mesh has at most [`MAX_LIGHT_TRIANGLES`] triangles, no point or spot
//! light of the scene lies inside its bounds (a lamp's glowing shell around a light is already
//! lit by that light, as the village's lanterns are), and it emits at least the setting
//! `min_flux_lm`, which the shader applies every frame ([`AreaLightGpu::radiance_flux`]).
//! A forced light may have up to [`MAX_FORCED_LIGHT_TRIANGLES`].

use bytemuck::{Pod, Zeroable};
use glam::Vec3;
use hikari_scene::Scene;

use crate::reference::textures::address;

/// Triangles of an emissive mesh that the size rule makes a light at most.
pub const MAX_LIGHT_TRIANGLES: usize = 64;
/// Triangles of a light forced by its `area_light` flag at most (each pixel integrates every
/// triangle of the lights it shades).
pub const MAX_FORCED_LIGHT_TRIANGLES: usize = 1024;
/// [`AreaLightGpu::range`] `.z` bit: emits from both faces (double-sided material).
pub const AREA_LIGHT_DOUBLE_SIDED: u32 = 1;
/// [`AreaLightGpu::range`] `.z` bit: flagged an area light, kept below `min_flux_lm`.
pub const AREA_LIGHT_FORCED: u32 = 2;

/// One polygonal light: an emissive mesh instance in world space (64 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct AreaLightGpu {
    /// xyz: area-weighted centroid, metres; w: radius of the bounding sphere about it.
    pub centroid_radius: [f32; 4],
    /// xyz: area-weighted mean of the triangles' unit normals (front faces); w: area, m².
    pub normal_area: [f32; 4],
    /// rgb: emitted radiance, nits (the emissive texture's mean folded in); a: luminous flux
    /// of the front faces, π × luminance × area, lumens.
    pub radiance_flux: [f32; 4],
    /// x: first [`AreaTriangleGpu`]; y: triangle count; z: `AREA_LIGHT_*` bits; w: for a
    /// textured emitter its material's index + 1 (the shader reads the emissive layer and
    /// wrap there), else 0.
    pub range: [u32; 4],
}

/// One world-space triangle of a light, wound so that (p1 - p0) × (p2 - p0) points out of its
/// emitting face (48 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct AreaTriangleGpu {
    /// xyz: p0; w: the light's area up to and including this triangle, as a fraction of its
    /// total (the last triangle's is 1): the CDF that picks a triangle by area.
    pub p0_cdf: [f32; 4],
    pub p1: [f32; 4],
    pub p2: [f32; 4],
}

/// Why [`PolygonLights::for_scene`] leaves out a lamp's glowing shell: a point or spot light lies
/// inside it, and that light stands for the shell's own (the village's paper lanterns).
pub const SKIPPED_LAMP_SHELL: &str = "a point or spot light lies inside it";

/// The scene's area lights.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PolygonLights {
    pub lights: Vec<AreaLightGpu>,
    pub triangles: Vec<AreaTriangleGpu>,
    /// Per triangle two `[f32; 4]`: its vertices' UVs (u0, v0, u1, v1), (u2, v2, 1 / the
    /// texture's mean luminance, 0); zero for an untextured light.
    pub uvs: Vec<[f32; 4]>,
    /// Per light, its emissive texture's luminance for the CPU twin (`None`: untextured).
    pub textures: Vec<Option<EmitterTexture>>,
    /// Emissive instances left out, with why (for logs and tests).
    pub skipped: Vec<(usize, &'static str)>,
}

impl PolygonLights {
    pub fn for_scene(scene: &Scene) -> Self {
        let mut out = Self::default();
        for (i, inst) in scene.instances.iter().enumerate() {
            let mat = &scene.materials[inst.material];
            let radiance = mat.emissive_nits * emissive_texture_mean(scene, mat);
            if radiance.max_element() <= 0.0 {
                continue;
            }
            let mesh = &scene.meshes[inst.mesh];
            let tri_count = mesh.indices.len() / 3;
            let forced = mat.area_light;
            if forced == Some(false) {
                out.skipped
                    .push((i, "its material's area_light flag is false"));
                continue;
            }
            // A lamp's shell before the size rule: the GI's instance table tells shells from
            // other skipped emitters by this reason, whatever their triangle count.
            if forced.is_none() {
                let (lo, hi) = mesh.positions.iter().fold(
                    (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)),
                    |(lo, hi), p| {
                        let p = inst.transform.transform_point3(*p);
                        (lo.min(p), hi.max(p))
                    },
                );
                if scene
                    .lights
                    .iter()
                    .any(|l| l.position.cmpge(lo).all() && l.position.cmple(hi).all())
                {
                    out.skipped.push((i, SKIPPED_LAMP_SHELL));
                    continue;
                }
            }
            let limit = if forced == Some(true) {
                MAX_FORCED_LIGHT_TRIANGLES
            } else {
                MAX_LIGHT_TRIANGLES
            };
            if tri_count == 0 || tri_count > limit {
                out.skipped.push((i, "too many triangles (or none)"));
                continue;
            }
            let tris: Vec<[Vec3; 3]> = mesh
                .indices
                .chunks_exact(3)
                .map(|t| {
                    [t[0], t[1], t[2]]
                        .map(|v| inst.transform.transform_point3(mesh.positions[v as usize]))
                })
                .collect();
            let areas: Vec<f32> = tris
                .iter()
                .map(|t| 0.5 * (t[1] - t[0]).cross(t[2] - t[0]).length())
                .collect();
            let area: f32 = areas.iter().sum();
            if area.is_nan() || area <= 0.0 || !area.is_finite() {
                out.skipped.push((i, "zero area"));
                continue;
            }
            let centroid = tris
                .iter()
                .zip(&areas)
                .map(|(t, a)| (t[0] + t[1] + t[2]) / 3.0 * *a)
                .sum::<Vec3>()
                / area;
            let normal = tris
                .iter()
                .zip(&areas)
                .map(|(t, a)| (t[1] - t[0]).cross(t[2] - t[0]).normalize_or_zero() * *a)
                .sum::<Vec3>()
                / area;
            let radius = tris
                .iter()
                .flatten()
                .map(|p| p.distance(centroid))
                .fold(0.0f32, f32::max);
            let luminance = hikari_math::color::luminance(radiance);
            let texture = EmitterTexture::of(scene, mat, mesh);
            let first = out.triangles.len() as u32;
            let mut acc = 0.0;
            for (t, a) in tris.iter().zip(&areas) {
                acc += a;
                let cdf = if out.triangles.len() as u32 + 1 == first + tri_count as u32 {
                    1.0
                } else {
                    acc / area
                };
                out.triangles.push(AreaTriangleGpu {
                    p0_cdf: t[0].extend(cdf).to_array(),
                    p1: t[1].extend(0.0).to_array(),
                    p2: t[2].extend(0.0).to_array(),
                });
            }
            for t in mesh.indices.chunks_exact(3) {
                let (uv, inv_mean) = match &texture {
                    Some(tex) => (
                        [t[0], t[1], t[2]].map(|v| mesh.uvs[v as usize]),
                        1.0 / tex.mean,
                    ),
                    None => ([glam::Vec2::ZERO; 3], 0.0),
                };
                out.uvs.push([uv[0].x, uv[0].y, uv[1].x, uv[1].y]);
                out.uvs.push([uv[2].x, uv[2].y, inv_mean, 0.0]);
            }
            let mut bits = 0;
            if mat.double_sided {
                bits |= AREA_LIGHT_DOUBLE_SIDED;
            }
            if forced == Some(true) {
                bits |= AREA_LIGHT_FORCED;
            }
            out.lights.push(AreaLightGpu {
                centroid_radius: centroid.extend(radius).to_array(),
                normal_area: normal.extend(area).to_array(),
                radiance_flux: radiance
                    .extend(std::f32::consts::PI * luminance * area)
                    .to_array(),
                range: [
                    first,
                    tri_count as u32,
                    bits,
                    if texture.is_some() {
                        inst.material as u32 + 1
                    } else {
                        0
                    },
                ],
            });
            out.textures.push(texture);
        }
        out
    }

    /// The triangles of light `i`.
    pub fn triangles_of(&self, i: usize) -> &[AreaTriangleGpu] {
        let r = self.lights[i].range;
        &self.triangles[r[0] as usize..(r[0] + r[1]) as usize]
    }
}

/// An emitter's texture as the shadow rays weigh it: the linear luminance of each texel and
/// their mean. The GPU samples the scene's sRGB array, where the image may be resampled to
/// the array's layer size; the twin samples the image itself.
#[derive(Clone, Debug, PartialEq)]
pub struct EmitterTexture {
    pub width: u32,
    pub height: u32,
    pub luminance: Vec<f32>,
    pub mean: f32,
    pub wrap: [hikari_scene::Wrap; 2],
}

impl EmitterTexture {
    /// The emissive texture of `mat` on `mesh`, if it has one, the mesh has UVs for every
    /// vertex, and its mean luminance is positive.
    pub fn of(
        scene: &Scene,
        mat: &hikari_scene::Material,
        mesh: &hikari_scene::Mesh,
    ) -> Option<Self> {
        let tex = scene.textures.get(mat.emissive_texture?.texture)?;
        if mesh.uvs.len() != mesh.positions.len() || tex.width == 0 || tex.height == 0 {
            return None;
        }
        let luminance: Vec<f32> = tex
            .data
            .chunks_exact(4)
            .map(|p| {
                Vec3::new(srgb(p[0]), srgb(p[1]), srgb(p[2]))
                    .dot(Vec3::from_array(hikari_math::color::REC709_LUMA))
            })
            .collect();
        let mean = emissive_texture_mean(scene, mat)
            .dot(Vec3::from_array(hikari_math::color::REC709_LUMA));
        (mean > 0.0 && luminance.len() == (tex.width * tex.height) as usize).then_some(Self {
            width: tex.width,
            height: tex.height,
            luminance,
            mean,
            wrap: [tex.wrap_s, tex.wrap_t],
        })
    }

    /// Bilinear luminance at `uv` (texel centres at half-integers, as the GPU's sampler).
    pub fn sample(&self, uv: glam::Vec2) -> f32 {
        let (w, h) = (self.width as i64, self.height as i64);
        let x = uv.x * w as f32 - 0.5;
        let y = uv.y * h as f32 - 0.5;
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let at = |i: i64, j: i64| {
            let i = address(i, w, self.wrap[0]);
            let j = address(j, h, self.wrap[1]);
            self.luminance[(j * w + i) as usize]
        };
        let (i, j) = (x0 as i64, y0 as i64);
        let top = at(i, j) * (1.0 - fx) + at(i + 1, j) * fx;
        let bottom = at(i, j + 1) * (1.0 - fx) + at(i + 1, j + 1) * fx;
        top * (1.0 - fy) + bottom * fy
    }
}

/// Mean linear colour of the material's emissive texture (sRGB-encoded, as glTF stores it),
/// 1 without one: the analytic integration takes a textured light as uniform at its mean.
pub fn emissive_texture_mean(scene: &Scene, mat: &hikari_scene::Material) -> Vec3 {
    let Some(tex) = mat
        .emissive_texture
        .and_then(|r| scene.textures.get(r.texture))
    else {
        return Vec3::ONE;
    };
    let n = tex.data.len() / 4;
    if n == 0 {
        return Vec3::ONE;
    }
    let sum = tex
        .data
        .chunks_exact(4)
        .map(|p| Vec3::new(srgb(p[0]), srgb(p[1]), srgb(p[2])))
        .sum::<Vec3>();
    sum / n as f32
}

fn srgb(c: u8) -> f32 {
    let c = c as f32 / 255.0;
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}
