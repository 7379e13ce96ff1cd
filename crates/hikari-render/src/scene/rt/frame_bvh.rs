//! The CPU side of the frame's ray-tracing scene: one BLAS per scene mesh, kept up to date for
//! deforming meshes by throttled refits, and the TLAS rebuilt every frame over the instances
//! kept around the camera. Two TLAS share the BLAS list: one over every kept instance (GI
//! rays) and one without the emissive shells of point and spot lights (shadow rays, as
//! `area_lights::shadow_casters` says).

use std::time::Instant;

use glam::{Mat4, Vec3, Vec3A};
use hikari_bvh::{
    Blas, BuildOptions, BvhError, CullSettings, Frustum, Instance, RefitScheduler,
    ThrottleSettings, Tlas, TlasBuilder, cull_instances,
};
use hikari_scene::Scene;

use super::settings::SceneRtSettings;
use crate::lights::shadow_casters;
use crate::scene::bvh;

/// What one frame's update cost and did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FrameBvhStats {
    /// CPU milliseconds of the culling and of both TLAS builds.
    pub tlas_ms: f64,
    /// CPU milliseconds of the deformation (new vertex positions) and the BLAS refits.
    pub refit_ms: f64,
    /// Bytes written to the GPU this frame: both TLAS, the refitted BLAS, and the raster's
    /// deformed vertices (filled in by the GPU side).
    pub upload_bytes: u64,
    pub instances_kept: usize,
    pub instances_culled: usize,
    /// Kept instances left out of the shadow rays' TLAS (lamp shells).
    pub shadow_excluded: usize,
    pub refits_done: usize,
    /// Refits done this frame that the scheduler picked at random.
    pub random_refits: usize,
    /// CPU milliseconds of the raster's deformed vertices (0 when the time did not change).
    pub raster_ms: f64,
    /// Vertices refitted this frame.
    pub refit_vertices: usize,
    /// Deforming meshes whose BLAS still shows another time than the frame's (stale).
    pub refits_pending: usize,
}

impl FrameBvhStats {
    /// The `log::info` line and `bench frame`'s row.
    pub fn summary(&self) -> String {
        format!(
            "scene BVH: TLAS {:.3} ms ({} instances kept, {} culled, {} lamp shells out of \
             shadows), refits {:.3} ms ({} done, {} random, {} vertices, {} pending), {} bytes \
             uploaded, raster vertices {:.3} ms",
            self.tlas_ms,
            self.instances_kept,
            self.instances_culled,
            self.shadow_excluded,
            self.refit_ms,
            self.refits_done,
            self.random_refits,
            self.refit_vertices,
            self.refits_pending,
            self.upload_bytes,
            self.raster_ms
        )
    }
}

/// Positions and unit normals of a mesh at one time.
type Pose = (Vec<Vec3>, Vec<Vec3>);

/// One deforming scene mesh.
struct Animated {
    mesh: usize,
    /// The scheduler's id.
    id: usize,
    /// The time the BLAS shows (`None`: the rest pose).
    shown: Option<f32>,
}

/// This frame's result.
pub struct FrameTlases {
    /// Over every kept instance.
    pub gi: Tlas,
    /// Over the kept shadow casters.
    pub shadow: Tlas,
    /// Indices of the kept instances, ascending.
    pub kept: Vec<u32>,
    /// Scene meshes whose BLAS was refitted this frame.
    pub refitted: Vec<usize>,
    pub stats: FrameBvhStats,
}

pub struct FrameBvh {
    pub blases: Vec<Blas>,
    pub instances: Vec<Instance>,
    /// Per instance: whether it enters the shadow rays' TLAS.
    casters: Vec<bool>,
    /// The rest-pose meshes that deform (only those: the others never change).
    rest: Vec<hikari_scene::Mesh>,
    animated: Vec<Animated>,
    /// Per entry of `animated`: the last pose computed (time, positions, normals).
    poses: Vec<Option<(Option<f32>, Pose)>>,
    /// Per scene mesh: its entry in `animated`.
    animated_of_mesh: Vec<Option<usize>>,
    scheduler: RefitScheduler,
    /// The settings the scheduler was made with (a change makes a new one).
    throttle: (u32, u32, u32),
    builder: TlasBuilder,
}

fn throttle_key(s: &SceneRtSettings) -> (u32, u32, u32) {
    (
        s.refits_per_frame,
        s.random_refits_per_frame,
        s.refit_vertex_budget,
    )
}

/// Which instances enter the frame's TLAS: every visible instance whose world box meets the
/// view frustum widened by `cull_margin_m` on every side, plus every one whose box lies within
/// `keep_radius_m` of the camera; all visible ones when culling is off. Ascending indices, and
/// how many were culled.
pub fn kept_instances(
    instances: &[Instance],
    blases: &[Blas],
    camera: Vec3,
    view_proj: &Mat4,
    s: &SceneRtSettings,
) -> (Vec<u32>, usize) {
    if !s.cull {
        let all: Vec<u32> = (0..instances.len() as u32)
            .filter(|&i| instances[i as usize].visible)
            .collect();
        let culled = instances.len() - all.len();
        return (all, culled);
    }
    let frustum = Frustum::from_view_proj(view_proj);
    let cull = CullSettings {
        margin: s.cull_margin_m,
        ..CullSettings::default()
    };
    let (mut kept, _) = cull_instances(instances, blases, camera, &frustum, &cull);
    let mut in_kept = vec![false; instances.len()];
    for &i in &kept {
        in_kept[i as usize] = true;
    }
    let cam = Vec3A::from(camera);
    for (i, inst) in instances.iter().enumerate() {
        if in_kept[i] || !inst.visible {
            continue;
        }
        let b = inst.world_bounds(blases);
        if b.is_empty() || !b.is_finite() {
            continue;
        }
        if (cam.clamp(b.min, b.max) - cam).length() <= s.keep_radius_m {
            kept.push(i as u32);
        }
    }
    kept.sort_unstable();
    let culled = instances.len() - kept.len();
    (kept, culled)
}

fn scheduler_for(s: &SceneRtSettings, animated: &[Animated], blases: &[Blas]) -> RefitScheduler {
    let mut sch = RefitScheduler::new(ThrottleSettings {
        top: s.refits_per_frame as usize,
        random: s.random_refits_per_frame as usize,
        vertex_budget: s.refit_vertex_budget as usize,
        ..ThrottleSettings::default()
    });
    for a in animated {
        let id = sch.register(blases[a.mesh].vertex_count());
        debug_assert_eq!(id, a.id);
    }
    sch
}

impl FrameBvh {
    /// Builds every BLAS of `scene` in its rest pose.
    pub fn new(scene: &Scene) -> Result<Self, BvhError> {
        let blases = bvh::blases(scene, &BuildOptions::default())?;
        let instances = bvh::instances(scene);
        let mut casters = vec![false; instances.len()];
        for i in shadow_casters(scene) {
            casters[i as usize] = true;
        }
        let mut animated = Vec::new();
        let mut rest = Vec::new();
        let mut animated_of_mesh = vec![None; scene.meshes.len()];
        for (m, mesh) in scene.meshes.iter().enumerate() {
            if mesh.deformation.is_some() {
                animated_of_mesh[m] = Some(animated.len());
                animated.push(Animated {
                    mesh: m,
                    id: animated.len(),
                    shown: None,
                });
                rest.push(mesh.clone());
            }
        }
        let defaults = SceneRtSettings::default();
        Ok(Self {
            scheduler: scheduler_for(&defaults, &animated, &blases),
            throttle: throttle_key(&defaults),
            blases,
            instances,
            casters,
            rest,
            poses: (0..animated.len()).map(|_| None).collect(),
            animated,
            animated_of_mesh,
            builder: TlasBuilder::default(),
        })
    }

    /// Scene meshes that deform.
    pub fn animated_meshes(&self) -> impl Iterator<Item = usize> + '_ {
        self.animated.iter().map(|a| a.mesh)
    }

    /// The time the BLAS of scene mesh `mesh` shows (`None`: the rest pose, or a mesh that
    /// does not deform).
    pub fn shown_time(&self, mesh: usize) -> Option<f32> {
        self.animated_of_mesh
            .get(mesh)
            .copied()
            .flatten()
            .and_then(|a| self.animated[a].shown)
    }

    /// Positions and unit normals of deforming scene mesh `mesh` at `time` (`None`: the rest
    /// pose). The last pose asked for is kept per mesh, so the refit and the raster of one
    /// frame deform each mesh once.
    pub fn pose_at(&mut self, mesh: usize, time: Option<f32>) -> Option<&Pose> {
        let a = self.animated_of_mesh.get(mesh).copied().flatten()?;
        let fresh = matches!(&self.poses[a], Some((t, _)) if *t == time);
        if !fresh {
            let rest = &self.rest[a];
            let pose = match time {
                None => (rest.positions.clone(), rest.normals.clone()),
                Some(t) => rest.deformed(t),
            };
            self.poses[a] = Some((time, pose));
        }
        self.poses[a].as_ref().map(|(_, p)| p)
    }

    /// One frame: culls around `camera` (world position) seen through `view_proj`, touches
    /// every deforming mesh whose BLAS shows another time than `s.time_s`, refits what the
    /// scheduler picks, and builds both TLAS. Culling reads the BLAS boxes before this frame's
    /// refits: they lag by at most the deformation's reach, which the margin covers.
    pub fn update(
        &mut self,
        camera: Vec3,
        view_proj: &Mat4,
        s: &SceneRtSettings,
    ) -> Result<FrameTlases, BvhError> {
        let start = Instant::now();
        let (kept, culled) = kept_instances(&self.instances, &self.blases, camera, view_proj, s);
        let cull_s = start.elapsed().as_secs_f64();

        let refit_start = Instant::now();
        if throttle_key(s) != self.throttle {
            self.scheduler = scheduler_for(s, &self.animated, &self.blases);
            self.throttle = throttle_key(s);
        }
        let target = s.time_s;
        let stale: Vec<usize> = (0..self.animated.len())
            .filter(|&a| self.animated[a].shown != target)
            .collect();
        let mut refitted = Vec::new();
        let mut batch = hikari_bvh::RefitBatch::default();
        if !stale.is_empty() {
            // Per stale mesh: whether a kept instance draws it, and its nearest instance's
            // bounding-sphere radius and distance (the scheduler's priority terms).
            let mut visible = vec![false; self.animated.len()];
            let mut nearest = vec![(f32::INFINITY, 0.0f32); self.animated.len()];
            let mut is_kept = vec![false; self.instances.len()];
            for &i in &kept {
                is_kept[i as usize] = true;
            }
            let cam = Vec3A::from(camera);
            for (i, inst) in self.instances.iter().enumerate() {
                let Some(a) = self
                    .animated_of_mesh
                    .get(inst.blas as usize)
                    .copied()
                    .flatten()
                else {
                    continue;
                };
                visible[a] |= is_kept[i];
                let b = inst.world_bounds(&self.blases);
                if b.is_empty() || !b.is_finite() {
                    continue;
                }
                let d = (cam.clamp(b.min, b.max) - cam).length();
                if d < nearest[a].0 {
                    nearest[a] = (d, 0.5 * (b.max - b.min).length());
                }
            }
            for &a in &stale {
                let (d, r) = nearest[a];
                let d = if d.is_finite() { d + r } else { f32::MAX };
                self.scheduler.touch(self.animated[a].id, visible[a], r, d);
            }
            batch = self.scheduler.select();
            for &id in &batch.ids {
                // Ids are registered in the order of `animated`.
                let a = id;
                let mesh = self.animated[a].mesh;
                if self.animated[a].shown == target {
                    continue;
                }
                let Some((positions, _)) = self.pose_at(mesh, target) else {
                    continue;
                };
                let positions = positions.clone();
                self.blases[mesh].refit(&positions)?;
                self.animated[a].shown = target;
                refitted.push(mesh);
            }
        }
        let refit_ms = refit_start.elapsed().as_secs_f64() * 1e3;

        let tlas_start = Instant::now();
        let gi = self.builder.build(&self.instances, &kept, &self.blases)?;
        let casters: Vec<u32> = kept
            .iter()
            .copied()
            .filter(|&i| self.casters[i as usize])
            .collect();
        let shadow = self
            .builder
            .build(&self.instances, &casters, &self.blases)?;
        let tlas_ms = (cull_s + tlas_start.elapsed().as_secs_f64()) * 1e3;

        let tlas_bytes = |t: &Tlas| t.gpu_bytes() as u64;
        let blas_bytes: u64 = refitted
            .iter()
            .map(|&m| self.blases[m].gpu_bytes() as u64)
            .sum();
        let stats = FrameBvhStats {
            tlas_ms,
            refit_ms,
            upload_bytes: tlas_bytes(&gi) + tlas_bytes(&shadow) + blas_bytes,
            instances_kept: kept.len(),
            instances_culled: culled,
            shadow_excluded: kept.len() - casters.len(),
            raster_ms: 0.0,
            refits_done: refitted.len(),
            random_refits: batch.random_picks.min(refitted.len()),
            refit_vertices: refitted
                .iter()
                .map(|&m| self.blases[m].vertex_count())
                .sum(),
            refits_pending: self.animated.iter().filter(|a| a.shown != target).count(),
        };
        Ok(FrameTlases {
            gi,
            shadow,
            kept,
            refitted,
            stats,
        })
    }
}
