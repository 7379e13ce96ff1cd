//! The village's tetrahedral meshes against the village's own layout (its building
//! footprints, which the bake does not read to classify): probes inside a house or the temple
//! hall are interior, probes in the open are exterior; no mesh probe is left inside geometry.

use glam::Vec3;
use hikari_bake::volumes::village_volumes;
use hikari_bake::{GridBakeOptions, SceneBakeOptions, bake_scene};
use hikari_probes::SceneKey;
use hikari_scene::village::{DEFAULT_SEED, Footprint, build};

/// Inside the footprint's walls by at least `margin` metres, between floor and ceiling.
fn well_inside(f: &Footprint, p: Vec3, margin: f32) -> bool {
    let l = f.transform().inverse().transform_point3(p);
    l.x.abs() < f.half_size.x - margin
        && l.z.abs() < f.half_size.y - margin
        && l.y > margin
        && l.y < f.ceiling_height - margin
}

/// Outside the footprint grown by `margin` metres.
fn well_outside(f: &Footprint, p: Vec3, margin: f32) -> bool {
    let l = f.transform().inverse().transform_point3(p);
    l.x.abs() > f.half_size.x + margin || l.z.abs() > f.half_size.y + margin
}

#[test]
fn village_mesh_probes_are_classified_by_where_they_stand() {
    let village = build(DEFAULT_SEED);
    let buildings: Vec<Footprint> = village
        .layout
        .houses
        .iter()
        .cloned()
        .chain([village.layout.temple_hall.clone()])
        .collect();
    let options = SceneBakeOptions {
        grid: GridBakeOptions {
            rays_per_probe: 128,
            ..Default::default()
        },
        bounce_rays: 0,
        volumes: village_volumes(&village.layout),
        scene_key: SceneKey::from_u64(1),
        ..Default::default()
    };
    let bake = bake_scene(&village.scene, &options, &|_| {}).expect("bakes");
    assert_eq!(bake.meshes.len(), 12);
    let (mut inside, mut inside_interior) = (0, 0);
    let (mut outside, mut outside_interior) = (0, 0);
    for mesh in &bake.meshes {
        assert!(mesh.tets.len() > mesh.positions.len(), "mesh {}", mesh.id);
        for (p, &interior) in mesh.positions.iter().zip(&mesh.interior) {
            let p = Vec3::from_array(*p);
            if buildings.iter().any(|f| well_inside(f, p, 0.3)) {
                inside += 1;
                inside_interior += usize::from(interior);
            } else if buildings.iter().all(|f| well_outside(f, p, 1.5)) {
                outside += 1;
                outside_interior += usize::from(interior);
            }
        }
    }
    println!(
        "inside buildings: {inside_interior}/{inside} interior; in the open: {outside_interior}/{outside} interior"
    );
    assert!(
        inside > 300 && outside > 1000,
        "{inside} inside, {outside} outside"
    );
    assert!(inside_interior as f32 >= 0.95 * inside as f32);
    assert!((outside_interior as f32) <= 0.02 * outside as f32);
}
