//! The geometry `bench rays` traces: issue 5's terrain, or a scene as `hikari render` loads it,
//! turned into BLAS (timed) and instances.

use std::time::Instant;

use anyhow::{Context, ensure};
use glam::Affine3A;

use hikari_bvh::{Blas, BuildOptions, Instance, Mesh};

use super::animation::{AnimationReport, animate};
use super::rays::{RaySource, TERRAIN_SIDE};
use crate::scene_source;

/// The geometry traced: BLAS list, instances, and how rays are generated for it.
pub(super) struct BenchScene {
    pub description: String,
    pub blases: Vec<Blas>,
    pub instances: Vec<Instance>,
    /// Wall-clock milliseconds to build all BLAS, per repetition.
    pub blas_build_ms: Vec<f64>,
    pub rays: RaySource,
    /// The scene's deforming meshes played for a while with throttled refits.
    pub animation: Option<AnimationReport>,
}

/// Builds the BLAS list (three times, for the build time) and the ray source for `name`.
pub(super) fn load(name: &str) -> anyhow::Result<BenchScene> {
    let options = BuildOptions::default();
    let mut blas_build_ms = Vec::new();
    if name == "terrain" {
        let mesh = Mesh::terrain(TERRAIN_SIDE);
        let mut blas = None;
        for _ in 0..3 {
            let t0 = Instant::now();
            let b =
                Blas::from_mesh("terrain", &mesh, &options).context("building the terrain BLAS")?;
            blas_build_ms.push(t0.elapsed().as_secs_f64() * 1e3);
            blas = Some(b);
        }
        return Ok(BenchScene {
            description: format!(
                "issue 5 terrain, {TERRAIN_SIDE}x{TERRAIN_SIDE} vertices, {} triangles",
                mesh.indices.len()
            ),
            blases: blas.into_iter().collect(),
            instances: vec![Instance::new(Affine3A::IDENTITY, 0)],
            blas_build_ms,
            rays: RaySource::Terrain(mesh),
            animation: None,
        });
    }
    let scene = scene_source::load_scene(name)?;
    scene
        .validate()
        .with_context(|| format!("scene `{name}`"))?;
    let meshes = hikari_render::scene::bvh::meshes(&scene);
    let mut blases = Vec::new();
    for _ in 0..3 {
        let t0 = Instant::now();
        blases = meshes
            .iter()
            .zip(&scene.meshes)
            .map(|(m, sm)| {
                Blas::from_mesh(&sm.name, m, &options)
                    .with_context(|| format!("building the BLAS of mesh `{}`", sm.name))
            })
            .collect::<anyhow::Result<_>>()?;
        blas_build_ms.push(t0.elapsed().as_secs_f64() * 1e3);
    }
    let instances = hikari_render::scene::bvh::instances(&scene);
    let mut triangles = Vec::new();
    let mut cdf = Vec::new();
    let mut area = 0.0f64;
    for inst in &scene.instances {
        let m = &scene.meshes[inst.mesh];
        for t in m.indices.chunks_exact(3) {
            let p = [t[0], t[1], t[2]]
                .map(|i| inst.transform.transform_point3(m.positions[i as usize]));
            let a = 0.5 * (p[1] - p[0]).cross(p[2] - p[0]).length() as f64;
            if !(a > 0.0 && a.is_finite()) {
                continue;
            }
            area += a;
            triangles.push(p);
            cdf.push(area);
        }
    }
    ensure!(
        !triangles.is_empty(),
        "scene `{name}` has no triangle with an area to start rays from"
    );
    let animation = animate(&scene, &blases, &instances)?;
    let (camera, _) = scene_source::first_or_framing_camera(&scene, "bench")?;
    Ok(BenchScene {
        description: format!(
            "{} meshes, {} instances, {} world triangles ({:.0} m^2), camera `{}`",
            scene.meshes.len(),
            scene.instances.len(),
            triangles.len(),
            area,
            camera.name
        ),
        blases,
        instances,
        blas_build_ms,
        animation,
        rays: RaySource::Surfaces {
            triangles,
            cdf,
            camera,
        },
    })
}
