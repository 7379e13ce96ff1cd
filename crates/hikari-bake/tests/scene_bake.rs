//! The full scene bake: progress, cancellation and resumption, tetrahedral meshes from probe
//! volumes (placement, interior flags), glTF `extras` volumes.

mod common;

use std::cell::RefCell;
use std::ops::ControlFlow;

use glam::{Mat4, Vec3};
use hikari_bake::volumes::{ProbeVolume, gltf_volumes};
use hikari_bake::{
    BakeError, BakeProgress, GridBakeOptions, SceneBakeOptions, bake_scene, bake_scene_resume,
};
use hikari_probes::{Bake, HULL, SceneKey};
use hikari_scene::{Instance, Material, Mesh, Scene, shapes};

/// A 60 m ground with a closed 6 x 3 x 6 m room on it: a box of inward-facing walls (so the
/// room's inside faces are front faces) inside an outward-facing shell 20 cm thicker.
fn room_scene() -> Scene {
    let ground = common::ground(30.0, 0.0);
    let outer = shapes::cuboid(Vec3::new(-3.2, 0.0, -3.2), Vec3::new(3.2, 3.2, 3.2));
    let mut inner = shapes::cuboid(Vec3::new(-3.0, 0.01, -3.0), Vec3::new(3.0, 3.0, 3.0));
    for t in inner.indices.chunks_exact_mut(3) {
        t.swap(1, 2);
    }
    for n in &mut inner.normals {
        *n = -*n;
    }
    let meshes: Vec<Mesh> = vec![ground, outer, inner];
    Scene {
        instances: (0..3)
            .map(|i| Instance {
                mesh: i,
                material: 0,
                transform: Mat4::IDENTITY,
            })
            .collect(),
        meshes,
        materials: vec![Material::diffuse("grey", Vec3::splat(0.5))],
        ..Default::default()
    }
}

fn small_options(volumes: Vec<ProbeVolume>) -> SceneBakeOptions {
    SceneBakeOptions {
        grid: GridBakeOptions {
            rays_per_probe: 64,
            inside_test_rays: 32,
            progress_batch: 200,
            ..Default::default()
        },
        bounce_rays: 2,
        volumes,
        scene_key: SceneKey::from_u64(42),
        ..Default::default()
    }
}

/// Around the room: from 2 m outside its walls, 0.5 m to 4 m up.
fn room_volume() -> ProbeVolume {
    ProbeVolume {
        name: "room".into(),
        transform: Mat4::from_translation(Vec3::new(0.0, 2.25, 0.0))
            * Mat4::from_scale(Vec3::new(5.0, 1.75, 5.0)),
        spacing: 1.0,
    }
}

#[test]
fn progress_counts_up_to_the_total_with_an_eta() {
    let seen = RefCell::new(Vec::<BakeProgress>::new());
    let bake = bake_scene(&room_scene(), &small_options(vec![room_volume()]), &|p| {
        seen.borrow_mut().push(p)
    })
    .expect("bakes");
    let seen = seen.into_inner();
    assert!(seen.len() > 3);
    assert_eq!(seen[0].probes_done, 0);
    assert!(seen[0].eta().is_none());
    for w in seen.windows(2) {
        assert!(w[1].probes_done >= w[0].probes_done);
        assert!(w[1].elapsed >= w[0].elapsed);
    }
    let last = seen.last().unwrap();
    assert_eq!(last.probes_done, last.probes_total);
    assert_eq!(last.sections_done, last.sections_total);
    assert_eq!(last.sections_total, bake.tiles.len() + bake.meshes.len());
    // One 16 x 16 x 3 tile over the 60 m scene, plus the volume's 11 x 8 x 11 lattice.
    assert_eq!(last.probes_total, 768 + 11 * 5 * 11);
    assert!(seen[seen.len() / 2].eta().is_some());
    assert!(bake.complete);
    hikari_probes::validate(&bake).expect("valid");
}

#[test]
fn mesh_probes_are_out_of_the_walls_classified_and_tetrahedralised() {
    let bake =
        bake_scene(&room_scene(), &small_options(vec![room_volume()]), &|_| {}).expect("bakes");
    let mesh = &bake.meshes[0];
    let lattice = 11 * 5 * 11;
    assert!(mesh.positions.len() <= lattice);
    // The lattice's x and z = ±3 columns fall in the 20 cm walls (between x = 3.0 and 3.2 the
    // point is inside the shell and outside the room): moved out or dropped, none left there.
    for p in &mesh.positions {
        let inside_wall = |c: f32| (3.0..3.2).contains(&c.abs());
        let within = |c: f32| c.abs() < 3.2;
        let in_x_wall = inside_wall(p[0]) && within(p[2]) && p[1] < 3.2;
        let in_z_wall = inside_wall(p[2]) && within(p[0]) && p[1] < 3.2;
        assert!(!(in_x_wall || in_z_wall), "probe at {p:?} is inside a wall");
    }
    // Interior: inside the room (away from its walls) every probe; outside it, none.
    let mut inside = 0;
    for (p, &interior) in mesh.positions.iter().zip(&mesh.interior) {
        let in_room = p[0].abs() < 2.9 && p[2].abs() < 2.9 && p[1] > 0.1 && p[1] < 2.9;
        let outside = p[0].abs() > 3.3 || p[2].abs() > 3.3 || p[1] > 3.3;
        if in_room {
            inside += 1;
            assert!(interior, "probe at {p:?} in the room is not interior");
            assert!(
                mesh.probes[mesh.positions.iter().position(|q| q == p).unwrap()]
                    .sky_visibility
                    .iter()
                    .all(|&c| c == 0.0)
            );
        }
        if outside {
            assert!(!interior, "probe at {p:?} outside the room is interior");
        }
    }
    assert!(inside > 50, "{inside} probes in the room");
    assert!(!mesh.tets.is_empty());
    assert_eq!(mesh.tets.len(), mesh.adjacency.len());
    assert!(mesh.adjacency.iter().flatten().any(|&a| a == HULL));
}

#[test]
fn a_cancelled_bake_resumes_to_the_same_result() {
    let scene = room_scene();
    let options = small_options(vec![room_volume()]);
    let full = bake_scene(&scene, &options, &|_| {}).expect("bakes");
    let mut saved: Option<Bake> = None;
    let result = bake_scene_resume(
        &scene,
        &options,
        Bake::new(
            options.scene_key,
            hikari_bake::scene_bake::bake_settings(&options),
        ),
        &|_| {},
        &mut |b| {
            saved = Some(b.clone());
            ControlFlow::Break(())
        },
    );
    assert!(matches!(result, Err(BakeError::Cancelled)));
    let partial = saved.expect("a checkpoint before cancelling");
    assert_eq!(partial.tiles.len(), 1);
    assert!(partial.meshes.is_empty());
    // Through the file format, as the CLI would.
    let bytes = hikari_probes::encode(&partial).expect("encodes");
    let partial = hikari_probes::decode(&bytes, &options.scene_key).expect("decodes");
    let resumed = bake_scene_resume(&scene, &options, partial, &|_| {}, &mut |_| {
        ControlFlow::Continue(())
    })
    .expect("resumes");
    // Not assert_eq!: a bake's Debug is megabytes.
    assert!(resumed.tiles == full.tiles, "tiles differ");
    assert!(resumed.meshes == full.meshes, "meshes differ");
    assert!(resumed == full, "bakes differ");
    // Another scene key is refused.
    let other = Bake::new(
        SceneKey::from_u64(7),
        hikari_bake::scene_bake::bake_settings(&options),
    );
    assert!(matches!(
        bake_scene_resume(&scene, &options, other, &|_| {}, &mut |_| {
            ControlFlow::Continue(())
        }),
        Err(BakeError::Scene(_))
    ));
}

#[test]
fn bad_volumes_and_options_are_named() {
    let mut v = room_volume();
    v.spacing = 0.01;
    let e = bake_scene(&room_scene(), &small_options(vec![v]), &|_| {}).unwrap_err();
    assert!(e.to_string().contains("`room`"), "{e}");
    let mut v = room_volume();
    v.transform.x_axis.x = f32::NAN;
    assert!(bake_scene(&room_scene(), &small_options(vec![v]), &|_| {}).is_err());
    let mut o = small_options(vec![]);
    o.grid.probes_per_tile = 8;
    assert!(matches!(
        bake_scene(&room_scene(), &o, &|_| {}),
        Err(BakeError::BadOption {
            option: "probes_per_tile",
            ..
        })
    ));
}

#[test]
fn gltf_extras_mark_probe_volumes() {
    let dir = std::env::temp_dir().join(format!("hikari-bake-gltf-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("marked.gltf");
    // Node 0 (translated by x = 10) holds node 1 (an empty scaled by 2, marked with a spacing)
    // and node 2 (a mesh bounded by [-1, 0, -3]..[1, 4, 3], marked true); node 3 is unmarked.
    let json = r#"{
      "asset": {"version": "2.0"},
      "scene": 0,
      "scenes": [{"nodes": [0, 3]}],
      "nodes": [
        {"translation": [10, 0, 0], "children": [1, 2]},
        {"name": "hall", "scale": [2, 2, 2], "extras": {"hikari": {"probe_volume": {"spacing": 0.5}}}},
        {"name": "shed", "mesh": 0, "extras": {"hikari": {"probe_volume": true}}},
        {"name": "tree", "extras": {"other": 1}}
      ],
      "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
      "accessors": [{"componentType": 5126, "count": 3, "type": "VEC3",
                     "min": [-1, 0, -3], "max": [1, 4, 3]}]
    }"#;
    std::fs::write(&path, json).unwrap();
    let mut v = gltf_volumes(&path).expect("reads");
    v.sort_by(|a, b| a.name.cmp(&b.name));
    assert_eq!(v.len(), 2);
    assert_eq!(v[0].name, "hall");
    assert_eq!(v[0].spacing, 0.5);
    let corner = v[0].transform.transform_point3(Vec3::ONE);
    assert!(
        (corner - Vec3::new(12.0, 2.0, 2.0)).length() < 1e-5,
        "{corner}"
    );
    assert_eq!(v[1].name, "shed");
    assert_eq!(v[1].spacing, hikari_bake::volumes::DEFAULT_VOLUME_SPACING);
    let lo = v[1].transform.transform_point3(-Vec3::ONE);
    let hi = v[1].transform.transform_point3(Vec3::ONE);
    assert!((lo - Vec3::new(9.0, 0.0, -3.0)).length() < 1e-5, "{lo}");
    assert!((hi - Vec3::new(11.0, 4.0, 3.0)).length() < 1e-5, "{hi}");

    let bad = dir.join("bad.gltf");
    std::fs::write(
        &bad,
        r#"{"scenes": [{"nodes": [0]}], "nodes": [{"extras": {"hikari": {"probe_volume": {"spacing": -1}}}}]}"#,
    )
    .unwrap();
    let e = gltf_volumes(&bad).unwrap_err().to_string();
    assert!(e.contains("bad.gltf") && e.contains("spacing"), "{e}");
    let e = gltf_volumes(&dir.join("missing.gltf"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("missing.gltf"), "{e}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn bake_to_file_checkpoints_on_cancel_and_resumes() {
    use hikari_bake::bake_to_file;
    use std::sync::atomic::{AtomicBool, Ordering};
    use std::time::Duration;
    let dir = std::env::temp_dir().join(format!("hikari-bake-file-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("room.hikprobe");
    let scene = room_scene();
    let options = small_options(vec![room_volume()]);
    let cancel = AtomicBool::new(false);
    // Cancel as soon as the first probes are done: the bake stops after its first section.
    let e = bake_to_file(
        &scene,
        &options,
        &path,
        &|p| {
            if p.probes_done > 0 {
                cancel.store(true, Ordering::Relaxed);
            }
        },
        &cancel,
        Duration::from_secs(3600),
    )
    .unwrap_err();
    assert!(matches!(e, BakeError::Cancelled));
    assert!(!path.exists());
    let partial = hikari_probes::partial_path(&path);
    assert!(partial.exists());
    let rays = RefCell::new(0u64);
    let done = bake_to_file(
        &scene,
        &options,
        &path,
        &|p| *rays.borrow_mut() = p.rays_traced,
        &AtomicBool::new(false),
        Duration::ZERO,
    )
    .expect("resumes");
    assert_eq!(done.resumed_sections, 1);
    assert!(done.discarded_checkpoint.is_none());
    assert!(!partial.exists());
    // Only the mesh was traced in the second run: its probes' rays and inside tests.
    let mesh = &done.bake.meshes[0];
    assert!(*rays.borrow() >= mesh.probes.len() as u64 * 64);
    let read = hikari_probes::read_bake(&path, &options.scene_key).expect("reads");
    let full = bake_scene(&scene, &options, &|_| {}).expect("bakes");
    assert!(
        read == full,
        "the resumed file differs from an uninterrupted bake"
    );
    std::fs::remove_dir_all(&dir).ok();
}
