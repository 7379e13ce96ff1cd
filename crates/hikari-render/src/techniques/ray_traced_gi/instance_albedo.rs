//! The albedo a GI ray takes where it hits through the BVH, per scene instance (Metro Exodus:
//! a table of the average visible albedo of each mesh-material combination).
//!
//! A BVH hit knows its instance but not its texture coordinates or vertex colours (fetching and
//! interpolating them per hit would cost more memory traffic than the trace itself), so each
//! (mesh, material) pair that some instance draws gets one colour, measured once per scene load:
//! the mesh is rendered on the CPU in its object space, orthographically from the six axis
//! directions, each view a [`VIEW_RESOLUTION`]² grid of parallel rays over the face of its
//! bounding box, through hikari-bvh's traversal of the same BLAS layout the GPU walks (both
//! windings, as the GI rays see them; cut-outs rejected by the BVH's alpha test,
//! [`SceneAlphaFilter`]). Each hit is shaded as the G-buffer shades a pixel (base colour factor
//! x interpolated vertex colour x the base colour texture, bilinear at mip 0, clamped to [0, 1];
//! metalness x the metallic-roughness texture's B) and turned into the albedo a hit reflects with,
//! [`hit_albedo`] (metals: `albedo (1 - F0) + F0` with F0 = base colour, blended by metalness).
//! The pair's albedo is the mean over all hits of the six views, each hit weighted by its
//! pixel's area (a view's pixels cover `extent_u * extent_v / N²` m²), so it is the mean over
//! the mesh's visible projected area: surfaces hidden from all six directions (the inside of a
//! closed box) do not count, a large face counts for more than a small one.
//!
//! A material's [`Material::gi_albedo`] override (scene model, glTF material `extras`) replaces
//! the measurement for every pair drawn with it, and those pairs are not rendered. A pair whose
//! mesh shows nothing (no triangles, or all cut out) falls back to the material's base colour
//! factor times its base colour texture's mean.
//!
//! Limits: the measurement is in object space, so an instance scaled non-uniformly weights its
//! faces as the unscaled mesh does; deforming meshes are measured at rest.
//!
//! Cost: `VIEW_RESOLUTION² x 6` rays per pair (6144 at 32), plus one BLAS build per mesh drawn
//! without an override; docs/ray-traced-gi.md gives the village's time.

use std::collections::HashMap;
use std::time::{Duration, Instant};

use glam::{DVec2, Vec3};
use hikari_bvh::{Blas, BuildOptions, Ray, Stack};
use hikari_scene::{Material, Scene};
use rayon::prelude::*;

use super::reference::{hit_albedo, texture_mean};
use crate::reference::textures::TwinTextures;
use crate::scene::bvh::SceneAlphaFilter;
use crate::scene::upload::alpha_cutoff;

/// Rays per side of each of the six orthographic views of a mesh.
pub const VIEW_RESOLUTION: u32 = 32;

/// What measuring a scene's table cost.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct AlbedoCost {
    /// (mesh, material) pairs drawn by the scene's instances.
    pub pairs: usize,
    /// Pairs measured (the others had an override).
    pub rendered: usize,
    /// Rays traced.
    pub rays: u64,
    /// Rays that hit the mesh and were shaded.
    pub hits: u64,
    /// Wall time of the BLAS builds.
    pub build: Duration,
    /// Wall time of the rendering.
    pub trace: Duration,
}

/// The per-instance albedo of a scene, linear Rec.709 in [0, 1].
#[derive(Clone, Debug, Default)]
pub struct InstanceAlbedo {
    /// One per scene instance, in instance order.
    pub per_instance: Vec<Vec3>,
    pub cost: AlbedoCost,
}

impl InstanceAlbedo {
    /// Measures every (mesh, material) pair of `scene`'s instances at [`VIEW_RESOLUTION`].
    pub fn for_scene(scene: &Scene) -> Self {
        Self::with_resolution(scene, VIEW_RESOLUTION)
    }

    /// [`InstanceAlbedo::for_scene`] with `resolution`² rays per view (at least 1).
    pub fn with_resolution(scene: &Scene, resolution: u32) -> Self {
        let pairs = Pairs::of(scene);
        let t_build = Instant::now();
        let mut needed: Vec<usize> = pairs.rendered.iter().map(|((mesh, _), _)| *mesh).collect();
        needed.sort_unstable();
        needed.dedup();
        let blases: HashMap<usize, Blas> = needed
            .par_iter()
            .filter_map(|&m| match mesh_blas(scene, m) {
                Ok(b) => Some((m, b)),
                Err(e) => {
                    log::debug!(
                        "GI albedo: mesh `{}` has no BLAS: {e}",
                        scene.meshes[m].name
                    );
                    None
                }
            })
            .collect();
        let build = t_build.elapsed();
        pairs.measure(scene, resolution, |m| blases.get(&m), build)
    }

    /// [`InstanceAlbedo::for_scene`] through BLASes already built: `blases[m]` of scene mesh
    /// `m`, as `crate::scene::bvh::blases` builds them for the frame's BVH (same triangles,
    /// cut-out meshes marked non-opaque), which saves building them twice at scene load.
    pub fn with_blases(scene: &Scene, blases: &[Blas], resolution: u32) -> Self {
        Pairs::of(scene).measure(scene, resolution, |m| blases.get(m), Duration::ZERO)
    }
}

/// The (mesh, material) pairs of a scene's instances, each with its first instance (the alpha
/// filter is asked by instance; every instance of a pair has the same cut-out).
struct Pairs {
    all: Vec<((usize, usize), usize)>,
    /// Those without an override, to be rendered.
    rendered: Vec<((usize, usize), usize)>,
}

impl Pairs {
    fn of(scene: &Scene) -> Self {
        let mut first_instance: HashMap<(usize, usize), usize> = HashMap::new();
        for (k, inst) in scene.instances.iter().enumerate() {
            first_instance
                .entry((inst.mesh, inst.material))
                .or_insert(k);
        }
        let mut all: Vec<((usize, usize), usize)> = first_instance.into_iter().collect();
        all.sort_unstable();
        let rendered = all
            .iter()
            .copied()
            .filter(|((mesh, mat), _)| {
                scene.materials[*mat].gi_albedo.is_none() && *mesh < scene.meshes.len()
            })
            .collect();
        Self { all, rendered }
    }

    /// Renders the pairs through `blas_of(mesh)` and makes the per-instance table.
    fn measure<'b>(
        &self,
        scene: &Scene,
        resolution: u32,
        blas_of: impl Fn(usize) -> Option<&'b Blas> + Sync,
        build: Duration,
    ) -> InstanceAlbedo {
        let resolution = resolution.max(1);
        let t_trace = Instant::now();
        let filter = SceneAlphaFilter::new(scene);
        let measured: Vec<Measured> = self
            .rendered
            .par_iter()
            .map(|&(pair, instance)| {
                let Some(blas) = blas_of(pair.0) else {
                    return Measured {
                        pair,
                        albedo: None,
                        rays: 0,
                        hits: 0,
                    };
                };
                let view = MeshView {
                    scene,
                    blas,
                    filter: &filter,
                    instance,
                    mesh: pair.0,
                    material: pair.1,
                };
                let (albedo, rays, hits) = view.mean_albedo(resolution);
                Measured {
                    pair,
                    albedo,
                    rays,
                    hits,
                }
            })
            .collect();
        let trace = t_trace.elapsed();

        let mut table: HashMap<(usize, usize), Vec3> = HashMap::new();
        let mut cost = AlbedoCost {
            pairs: self.all.len(),
            rendered: self.rendered.len(),
            build,
            trace,
            ..Default::default()
        };
        for m in measured {
            cost.rays += m.rays;
            cost.hits += m.hits;
            if let Some(a) = m.albedo {
                table.insert(m.pair, a);
            }
        }
        let per_instance = scene
            .instances
            .iter()
            .map(|inst| {
                let mat = &scene.materials[inst.material];
                mat.gi_albedo
                    .or_else(|| table.get(&(inst.mesh, inst.material)).copied())
                    .unwrap_or_else(|| fallback_albedo(scene, mat))
            })
            .map(|a| {
                if a.is_finite() {
                    a.clamp(Vec3::ZERO, Vec3::ONE)
                } else {
                    Vec3::ZERO
                }
            })
            .collect();
        log::info!(
            "GI albedo: {} mesh-material pairs ({} rendered), BLASes in {:.1} ms, {} rays \
             ({} hits) in {:.1} ms",
            cost.pairs,
            cost.rendered,
            cost.build.as_secs_f64() * 1e3,
            cost.rays,
            cost.hits,
            cost.trace.as_secs_f64() * 1e3,
        );
        InstanceAlbedo { per_instance, cost }
    }
}

/// The albedo of a pair that shows nothing: base colour factor x base colour texture mean.
pub fn fallback_albedo(scene: &Scene, mat: &Material) -> Vec3 {
    let tex = mat
        .base_color_texture
        .and_then(|r| scene.textures.get(r.texture))
        .filter(|t| texture_is_sound(t))
        .map_or(Vec3::ONE, texture_mean);
    hit_albedo(mat.base_color * tex, mat.metalness)
}

fn texture_is_sound(t: &hikari_scene::Texture) -> bool {
    t.width > 0 && t.height > 0 && t.data.len() as u64 == t.width as u64 * t.height as u64 * 4
}

/// A BLAS of one scene mesh in object space; every triangle marked non-opaque when some
/// instance draws the mesh with a cut-out material, as the frame's BVH does.
fn mesh_blas(scene: &Scene, m: usize) -> Result<Blas, hikari_bvh::BvhError> {
    let mesh = &scene.meshes[m];
    let indices: Vec<[u32; 3]> = mesh
        .indices
        .chunks_exact(3)
        .map(|t| [t[0], t[1], t[2]])
        .collect();
    let cut = scene
        .instances
        .iter()
        .any(|i| i.mesh == m && alpha_cutoff(&scene.materials[i.material]) > 0.0);
    // The current rayon pool: small meshes build side by side, a large one (the terrain)
    // spreads over the threads the others leave.
    let options = BuildOptions::default();
    if cut {
        let marks = vec![true; indices.len()];
        Blas::build_with_opacity(&mesh.name, &mesh.positions, &indices, &marks, &options)
    } else {
        Blas::build(&mesh.name, &mesh.positions, &indices, &options)
    }
}

/// What rendering one (mesh, material) pair gave: its mean albedo (`None`: nothing seen), the
/// rays traced and the hits.
struct Measured {
    pair: (usize, usize),
    albedo: Option<Vec3>,
    rays: u64,
    hits: u64,
}

/// One (mesh, material) pair being rendered.
struct MeshView<'a> {
    scene: &'a Scene,
    blas: &'a Blas,
    filter: &'a SceneAlphaFilter<'a>,
    /// The pair's representative instance, for the alpha filter.
    instance: usize,
    mesh: usize,
    material: usize,
}

impl MeshView<'_> {
    /// The area-weighted mean albedo over the six views, the rays traced and the hits; `None`
    /// when nothing was hit.
    fn mean_albedo(&self, n: u32) -> (Option<Vec3>, u64, u64) {
        let Some((lo, hi)) = self.scene.meshes[self.mesh].bounds() else {
            return (None, 0, 0);
        };
        let extent = hi - lo;
        // Rays start this far outside the box so that faces lying on it are hit.
        let margin = (extent.length() * 1e-2).max(1e-3);
        let mut stack = Stack::default();
        let (mut sum, mut weight) = (glam::DVec3::ZERO, 0.0f64);
        let (mut rays, mut hits) = (0u64, 0u64);
        for axis in 0..3 {
            let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
            let pixel_area = extent[u] as f64 * extent[v] as f64 / (n as f64 * n as f64);
            // A view of a mesh flat along it sees only its edge: no area.
            if pixel_area <= 0.0 {
                continue;
            }
            for side in [1.0f32, -1.0] {
                let mut dir = Vec3::ZERO;
                dir[axis] = -side;
                let mut origin = Vec3::ZERO;
                origin[axis] = if side > 0.0 {
                    hi[axis] + margin
                } else {
                    lo[axis] - margin
                };
                let t_max = extent[axis] + 2.0 * margin;
                for j in 0..n {
                    for i in 0..n {
                        origin[u] = lo[u] + (i as f32 + 0.5) / n as f32 * extent[u];
                        origin[v] = lo[v] + (j as f32 + 0.5) / n as f32 * extent[v];
                        rays += 1;
                        let ray = Ray::new(origin, dir, 0.0, t_max);
                        if let Some(a) = self.trace(&ray, &mut stack) {
                            hits += 1;
                            sum += a.as_dvec3() * pixel_area;
                            weight += pixel_area;
                        }
                    }
                }
            }
        }
        let mean = (weight > 0.0).then(|| (sum / weight).as_vec3());
        (mean, rays, hits)
    }

    /// The albedo at the closest hit of `ray`, cut-outs rejected.
    fn trace(&self, ray: &Ray, stack: &mut Stack) -> Option<Vec3> {
        let instance = self.instance as u32;
        // The unfiltered traversal is compiled once in hikari-bvh (optimised even in debug
        // builds); the filtered one is generic over the filter and built here.
        let opaque = alpha_cutoff(&self.scene.materials[self.material]) <= 0.0;
        let hit = if opaque {
            self.blas.intersect_with(ray, stack)
        } else {
            hikari_bvh::traverse::closest_hit_blas_filtered(
                &self.blas.nodes,
                &self.blas.triangles,
                ray,
                instance,
                stack,
                |_, p, u, v| self.filter.accept(instance, p, u, v),
            )
        }?;
        self.albedo_at(hit.primitive as usize, hit.u, hit.v)
    }

    /// The albedo a hit on triangle `primitive` at weights `u` (second vertex), `v` (third)
    /// reflects with, from the material as the G-buffer reads it; `None` for a triangle the
    /// mesh does not have (a BLAS of another mesh given to [`InstanceAlbedo::with_blases`]).
    fn albedo_at(&self, primitive: usize, u: f32, v: f32) -> Option<Vec3> {
        let mesh = &self.scene.meshes[self.mesh];
        let mat = &self.scene.materials[self.material];
        let w = [1.0 - u - v, u, v];
        let tri = mesh.indices.get(primitive * 3..primitive * 3 + 3)?;
        let mut color = Vec3::ZERO;
        let mut uv = DVec2::ZERO;
        for (k, &i) in tri.iter().enumerate() {
            let c = mesh
                .colors
                .as_ref()
                .and_then(|c| c.get(i as usize))
                .map_or(Vec3::ONE, |c| c.truncate());
            color += c * w[k];
            uv += mesh
                .uvs
                .get(i as usize)
                .copied()
                .unwrap_or_default()
                .as_dvec2()
                * w[k] as f64;
        }
        let textures = TwinTextures { scene: self.scene };
        let sample = |r: Option<hikari_scene::TextureRef>, srgb: bool| {
            r.filter(|r| {
                self.scene
                    .textures
                    .get(r.texture)
                    .is_some_and(texture_is_sound)
            })
            .map_or(glam::DVec4::ONE, |r| textures.sample(r.texture, uv, srgb))
            .as_vec4()
        };
        let base = (mat.base_color * color * sample(mat.base_color_texture, true).truncate())
            .clamp(Vec3::ZERO, Vec3::ONE);
        let metalness = mat.metalness * sample(mat.metallic_roughness_texture, false).z;
        Some(hit_albedo(base, metalness))
    }
}
