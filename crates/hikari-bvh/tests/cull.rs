//! Instance culling never drops an instance that a ray starting inside the view frustum can hit
//! within the frustum margin; hidden and tiny distant instances are dropped.

use hikari_bvh::reference as common;

use glam::{Affine3A, Mat4, Quat, Vec3, Vec4};
use hikari_bvh::reference::closest_hit_instances;
use hikari_bvh::rng::SplitMix64;
use hikari_bvh::{
    Blas, BuildOptions, CullSettings, Frustum, Instance, Mesh, Ray, Tlas, cull_instances,
};

fn camera() -> (Vec3, Mat4) {
    let eye = Vec3::new(0.0, 5.0, -20.0);
    let view = Mat4::look_at_rh(eye, Vec3::new(0.0, 0.0, 10.0), Vec3::Y);
    let proj = Mat4::perspective_rh(60f32.to_radians(), 16.0 / 9.0, 0.1, 30.0);
    (eye, proj * view)
}

fn point_in_frustum(rng: &mut SplitMix64, inv_view_proj: &Mat4) -> Vec3 {
    let ndc = Vec4::new(
        rng.range(-1.0, 1.0),
        rng.range(-1.0, 1.0),
        rng.range(0.0, 1.0),
        1.0,
    );
    let p = *inv_view_proj * ndc;
    p.truncate() / p.w
}

#[test]
fn culling_keeps_every_instance_a_short_ray_from_the_frustum_can_hit() {
    let meshes = vec![Mesh::random_soup(1, 40, 2.5, 3.0)];
    let blases = vec![Blas::from_mesh("rock", &meshes[0], &BuildOptions::default()).unwrap()];
    let mut rng = SplitMix64::new(2);
    // Instances everywhere around the camera, many of them outside the view.
    let mut instances: Vec<Instance> = (0..150)
        .map(|_| {
            let t = Vec3::new(
                rng.range(-35.0, 35.0),
                rng.range(-15.0, 25.0),
                rng.range(-35.0, 25.0),
            );
            let rot = Quat::from_axis_angle(common::random_dir(&mut rng), rng.range(0.0, 6.0));
            Instance::new(Affine3A::from_rotation_translation(rot, t), 0)
        })
        .collect();
    for inst in instances.iter_mut().step_by(10) {
        inst.visible = false;
    }
    let (eye, view_proj) = camera();
    let frustum = Frustum::from_view_proj(&view_proj);
    let settings = CullSettings {
        margin: 8.0,
        ..Default::default()
    };
    let (kept, stats) = cull_instances(&instances, &blases, eye, &frustum, &settings);
    assert_eq!(stats.hidden, 15);
    assert!(stats.outside_frustum > 20, "{stats:?}");
    assert_eq!(stats.survived, kept.len());
    let visible: Vec<u32> = (0..instances.len() as u32)
        .filter(|&i| instances[i as usize].visible)
        .collect();
    let tlas = Tlas::build(&instances, &kept, &blases).unwrap();

    let inv = view_proj.inverse();
    let mut hits = 0;
    for _ in 0..800 {
        let o = point_in_frustum(&mut rng, &inv);
        assert!(frustum.expanded(1e-3).contains_point(o));
        let d = common::random_dir(&mut rng);
        let ray = Ray::new(o, d, 0.0, settings.margin);
        if let Some(h) = closest_hit_instances(&meshes, &instances, Some(&visible), &ray) {
            hits += 1;
            assert!(
                kept.contains(&h.instance),
                "instance {} was culled but is hit by {ray:?}",
                h.instance
            );
            let got = tlas
                .closest_hit(&blases, &ray)
                .expect("the culled TLAS hits too");
            common::same_hit(Some(got), Some(h)).unwrap();
        }
    }
    assert!(hits > 30, "the test should produce hits ({hits})");
}

#[test]
fn contribution_culling_drops_small_distant_instances_only() {
    let mesh = Mesh::random_soup(3, 20, 0.5, 0.5);
    let blases = vec![Blas::from_mesh("pebble", &mesh, &BuildOptions::default()).unwrap()];
    let (eye, view_proj) = camera();
    let frustum = Frustum::from_view_proj(&view_proj);
    let near = Instance::new(Affine3A::from_translation(Vec3::new(0.0, 3.0, -14.0)), 0);
    let far = Instance::new(Affine3A::from_translation(Vec3::new(0.0, 0.0, 8.0)), 0);
    let big_far = Instance::new(
        Affine3A::from_scale_rotation_translation(
            Vec3::splat(20.0),
            Quat::IDENTITY,
            Vec3::new(0.0, 0.0, 8.0),
        ),
        0,
    );
    let settings = CullSettings {
        margin: 2.0,
        min_angular_size: 0.1,
        contribution_min_distance: 5.0,
    };
    let (kept, stats) = cull_instances(&[near, far, big_far], &blases, eye, &frustum, &settings);
    assert_eq!(kept, vec![0, 2]);
    assert_eq!(stats.too_small, 1);
}

#[test]
fn frustum_planes_point_inward() {
    let (eye, view_proj) = camera();
    let f = Frustum::from_view_proj(&view_proj);
    assert!(f.contains_point(Vec3::new(0.0, 2.0, 0.0)));
    assert!(!f.contains_point(eye - Vec3::Z)); // behind the camera
    assert!(!f.contains_point(Vec3::new(0.0, 0.0, 20.0))); // past the far plane
    assert!(f.expanded(20.0).contains_point(Vec3::new(0.0, 0.0, 20.0)));
}
