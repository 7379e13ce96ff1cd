//! A scene's vertex animation played with throttled BLAS refits, and the refit BLAS checked
//! against rebuilt ones.

use std::time::Instant;

use anyhow::Context;
use glam::Vec3;

use hikari_bvh::rng::SplitMix64;
use hikari_bvh::{Blas, BuildOptions, Instance, Mesh, Ray, RefitScheduler, ThrottleSettings, Tlas};

use super::measure::{median_min, same_hit};
use super::rays::SEED;

/// Frames of a scene's vertex animation with Metro's refit throttling ([`RefitScheduler`]).
pub(super) struct AnimationReport {
    pub deforming_meshes: usize,
    pub frames: usize,
    /// Per frame, CPU milliseconds to deform the chosen meshes and refit their BLAS.
    pub refit_ms_median: f64,
    pub refits_per_frame_max: usize,
    pub vertices_per_frame_max: usize,
    /// Most deforming meshes left outdated after a frame's batch.
    pub outdated_max: usize,
    /// After the last frame: rays traced through the refit BLAS and through BLAS rebuilt from
    /// the same deformed meshes, and how many hits differ.
    pub checked: usize,
    pub mismatches: usize,
}

/// Frames played at 60 Hz for the animation report.
const ANIMATION_FRAMES: usize = 120;

pub(super) fn animate(
    scene: &hikari_scene::Scene,
    blases: &[Blas],
    instances: &[Instance],
) -> anyhow::Result<Option<AnimationReport>> {
    let deforming: Vec<usize> = (0..scene.meshes.len())
        .filter(|&m| scene.meshes[m].deformation.is_some())
        .collect();
    if deforming.is_empty() {
        return Ok(None);
    }
    let camera = scene
        .cameras
        .first()
        .map(|c| c.position)
        .unwrap_or(Vec3::ZERO);
    let mut blases = blases.to_vec();
    let mut scheduler = RefitScheduler::new(ThrottleSettings::default());
    let ids: Vec<usize> = deforming
        .iter()
        .map(|&m| scheduler.register(scene.meshes[m].positions.len()))
        .collect();
    let mut times = Vec::new();
    let (mut refits_max, mut vertices_max, mut outdated_max) = (0, 0, 0);
    for frame in 0..ANIMATION_FRAMES {
        let t = frame as f32 / 60.0;
        for (k, &m) in deforming.iter().enumerate() {
            // Priority from the nearest instance: size over distance, as the talk weighs it.
            let (lo, hi) = scene.meshes[m].bounds().unwrap_or_default();
            let radius = 0.5 * (hi - lo).length();
            let distance = scene
                .instances
                .iter()
                .filter(|i| i.mesh == m)
                .map(|i| {
                    i.transform
                        .transform_point3(0.5 * (lo + hi))
                        .distance(camera)
                })
                .fold(f32::INFINITY, f32::min);
            scheduler.touch(ids[k], true, radius, distance);
        }
        let batch = scheduler.select();
        let t0 = Instant::now();
        for &id in &batch.ids {
            let m = deforming[id];
            let (positions, _) = scene.meshes[m].deformed(t);
            blases[m]
                .refit(&positions)
                .with_context(|| format!("refitting mesh `{}`", scene.meshes[m].name))?;
        }
        times.push(t0.elapsed().as_secs_f64() * 1e3);
        refits_max = refits_max.max(batch.ids.len());
        vertices_max = vertices_max.max(batch.vertices);
        outdated_max = outdated_max.max(batch.outdated);
    }
    // Every mesh refit at the last frame's time, compared with a rebuild at that time.
    let t_last = (ANIMATION_FRAMES - 1) as f32 / 60.0;
    let mut rebuilt = blases.clone();
    for &m in &deforming {
        let (positions, _) = scene.meshes[m].deformed(t_last);
        blases[m].refit(&positions)?;
        let mesh = Mesh::new(
            positions,
            scene.meshes[m]
                .indices
                .chunks_exact(3)
                .map(|t| [t[0], t[1], t[2]])
                .collect(),
        );
        rebuilt[m] = Blas::from_mesh(&scene.meshes[m].name, &mesh, &BuildOptions::default())?;
    }
    let all: Vec<u32> = (0..instances.len() as u32).collect();
    let refit_tlas = Tlas::build(instances, &all, &blases)?;
    let rebuilt_tlas = Tlas::build(instances, &all, &rebuilt)?;
    // Rays aimed at the deforming instances, from the camera, so they test what moved.
    let mut rng = SplitMix64::new(SEED ^ 0xA11);
    let targets: Vec<Vec3> = scene
        .instances
        .iter()
        .filter(|i| deforming.contains(&i.mesh))
        .map(|i| {
            let (lo, hi) = scene.meshes[i.mesh].bounds().unwrap_or_default();
            i.transform.transform_point3(0.5 * (lo + hi))
        })
        .collect();
    let rays: Vec<Ray> = (0..4000)
        .map(|k| {
            let aim = targets[k % targets.len()]
                + (Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) - 0.5) * 4.0;
            Ray::new(camera, (aim - camera).normalize(), 0.0, f32::INFINITY)
        })
        .collect();
    let a = refit_tlas.closest_hits(&blases, &rays, 0);
    let b = rebuilt_tlas.closest_hits(&rebuilt, &rays, 0);
    let mismatches = a
        .iter()
        .zip(&b)
        .zip(&rays)
        .filter(|((x, y), r)| !same_hit(x, y, r))
        .count();
    let (median, _) = median_min(&mut times);
    Ok(Some(AnimationReport {
        deforming_meshes: deforming.len(),
        frames: ANIMATION_FRAMES,
        refit_ms_median: median,
        refits_per_frame_max: refits_max,
        vertices_per_frame_max: vertices_max,
        outdated_max,
        checked: rays.len(),
        mismatches,
    }))
}
