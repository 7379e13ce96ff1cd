//! The `village` built-in scene against the requirements of its issue, measured from the
//! generated geometry (not from the generator's own bookkeeping where avoidable).

use std::collections::HashMap;
use std::sync::OnceLock;

use glam::{Mat4, Vec2, Vec3};
use hikari_scene::village::{self, Village};
use hikari_scene::{Deformation, LightKind, Material, Mesh, Scene, builtin};

fn village() -> &'static Village {
    static V: OnceLock<Village> = OnceLock::new();
    V.get_or_init(|| village::build(village::DEFAULT_SEED))
}

fn scene() -> &'static Scene {
    &village().scene
}

fn luminance(c: Vec3) -> f32 {
    c.dot(Vec3::new(0.2126, 0.7152, 0.0722))
}

/// Instances of meshes whose name satisfies `pred`: (mesh, material, transform).
fn instances_of<'a>(
    s: &'a Scene,
    pred: impl Fn(&str) -> bool + 'a,
) -> impl Iterator<Item = (&'a Mesh, &'a Material, Mat4)> + 'a {
    s.instances
        .iter()
        .filter(move |i| pred(&s.meshes[i.mesh].name))
        .map(|i| (&s.meshes[i.mesh], &s.materials[i.material], i.transform))
}

/// Whether the whole instance (its world bounding box) is inside the room of `f`: within the
/// inner faces of its walls, above the floor, below the ceiling.
fn in_room(f: &village::Footprint, m: &Mesh, t: Mat4) -> bool {
    let (lo, hi) = m.bounds().unwrap();
    let to_local = f.transform().inverse() * t;
    (0..8).all(|k| {
        let c = Vec3::new(
            if k & 1 == 0 { lo.x } else { hi.x },
            if k & 2 == 0 { lo.y } else { hi.y },
            if k & 4 == 0 { lo.z } else { hi.z },
        );
        let l = to_local.transform_point3(c);
        l.x.abs() < f.half_size.x - 0.119
            && l.z.abs() < f.half_size.y - 0.119
            && l.y > 0.001
            && l.y < f.ceiling_height - 0.001
    })
}

fn is_wall(name: &str) -> bool {
    name.contains("wall")
}

/// The terrain mesh's triangles bucketed by the 1 m cells their xz bounds overlap, to find
/// the surface height under a point quickly.
struct Ground {
    cells: HashMap<(i32, i32), Vec<[Vec3; 3]>>,
}

impl Ground {
    fn new(s: &Scene) -> Ground {
        let (m, _, t) = instances_of(s, |n| n == "terrain")
            .next()
            .expect("a terrain");
        assert_eq!(t, Mat4::IDENTITY);
        let mut cells: HashMap<(i32, i32), Vec<[Vec3; 3]>> = HashMap::new();
        for tri in m.indices.chunks(3) {
            let v = [0, 1, 2].map(|i| m.positions[tri[i] as usize]);
            let lo = v[0].min(v[1]).min(v[2]);
            let hi = v[0].max(v[1]).max(v[2]);
            for i in lo.x.floor() as i32..=hi.x.floor() as i32 {
                for j in lo.z.floor() as i32..=hi.z.floor() as i32 {
                    cells.entry((i, j)).or_default().push(v);
                }
            }
        }
        Ground { cells }
    }

    /// Height of the surface at (x, z): the triangle under the point, interpolated
    /// barycentrically.
    fn height(&self, x: f32, z: f32) -> f32 {
        let p = Vec2::new(x, z);
        for [a, b, c] in self
            .cells
            .get(&(x.floor() as i32, z.floor() as i32))
            .into_iter()
            .flatten()
        {
            let [a2, b2, c2] = [a, b, c].map(|v| Vec2::new(v.x, v.z));
            let d = (b2 - a2).perp_dot(c2 - a2);
            let wb = (p - a2).perp_dot(c2 - a2) / d;
            let wc = (b2 - a2).perp_dot(p - a2) / d;
            let wa = 1.0 - wb - wc;
            if wa >= -1e-5 && wb >= -1e-5 && wc >= -1e-5 {
                return wa * a.y + wb * b.y + wc * c.y;
            }
        }
        panic!("no terrain under ({x}, {z})");
    }
}

fn ground() -> &'static Ground {
    static G: OnceLock<Ground> = OnceLock::new();
    G.get_or_init(|| Ground::new(scene()))
}

/// Height of the default village's terrain surface at (x, z).
fn terrain_height(x: f32, z: f32) -> f32 {
    ground().height(x, z)
}

/// Ray against every triangle of the instances whose mesh name satisfies `pred`; nearest
/// hit distance (Möller-Trumbore, both sides).
fn ray_hit(s: &Scene, origin: Vec3, dir: Vec3, pred: impl Fn(&str) -> bool) -> Option<f32> {
    let mut best: Option<f32> = None;
    for (m, _, t) in instances_of(s, pred) {
        for tri in m.indices.chunks(3) {
            let [a, b, c] = [0, 1, 2].map(|i| t.transform_point3(m.positions[tri[i] as usize]));
            let (e1, e2) = (b - a, c - a);
            let p = dir.cross(e2);
            let det = e1.dot(p);
            if det.abs() < 1e-12 {
                continue;
            }
            let inv = 1.0 / det;
            let tv = origin - a;
            let u = tv.dot(p) * inv;
            let q = tv.cross(e1);
            let v = dir.dot(q) * inv;
            let d = e2.dot(q) * inv;
            if (0.0..=1.0).contains(&u) && v >= 0.0 && u + v <= 1.0 && d > 0.0 {
                best = Some(best.map_or(d, |b: f32| b.min(d)));
            }
        }
    }
    best
}

fn bits(s: &Scene) -> Vec<u32> {
    let mut out = Vec::new();
    let v3 = |out: &mut Vec<u32>, v: Vec3| out.extend(v.to_array().map(f32::to_bits));
    for m in &s.meshes {
        out.extend(m.name.bytes().map(u32::from));
        for p in m.positions.iter().chain(&m.normals) {
            v3(&mut out, *p);
        }
        out.extend(&m.indices);
        for t in &m.tangents {
            out.extend(t.to_array().map(f32::to_bits));
        }
        for uv in &m.uvs {
            out.extend(uv.to_array().map(f32::to_bits));
        }
        for c in m.colors.iter().flatten() {
            out.extend(c.to_array().map(f32::to_bits));
        }
        out.extend(m.interior.iter().map(|v| v.to_bits()));
        out.extend(format!("{:?}", m.deformation).bytes().map(u32::from));
    }
    for i in &s.instances {
        out.extend([i.mesh as u32, i.material as u32]);
        out.extend(i.transform.to_cols_array().map(f32::to_bits));
    }
    out.extend(
        format!("{:?}{:?}{:?}{:?}", s.materials, s.cameras, s.lights, s.sun)
            .bytes()
            .map(u32::from),
    );
    out
}

#[test]
fn same_seed_gives_a_bit_identical_scene_and_another_seed_a_different_one() {
    let a = bits(scene());
    let b = bits(&builtin::village());
    assert!(a == b, "two builds of the default seed differ");
    let other = village::build(12345);
    assert!(bits(&other.scene) != a);
    // Not only somewhere: the houses moved and the hills changed.
    assert_ne!(
        other.layout.houses[1].centre,
        village().layout.houses[1].centre
    );
    let far = (150.0, -150.0);
    assert_ne!(
        Ground::new(&other.scene).height(far.0, far.1),
        terrain_height(far.0, far.1)
    );
    assert_eq!(builtin::NAMES[0], "village");
}

#[test]
fn validates_and_stays_within_the_triangle_budget() {
    let s = scene();
    s.validate().unwrap();
    let tris = s.triangle_count();
    assert!((300_000..=1_500_000).contains(&tris), "{tris} triangles");
    // Instancing: far fewer meshes than instances, and the triangles stored are fewer than
    // the triangles drawn.
    let stored: usize = s.meshes.iter().map(|m| m.indices.len() / 3).sum();
    assert!(s.meshes.len() * 3 < s.instances.len());
    assert!(stored < tris, "{stored} stored of {tris}");
    let (lo, hi) = s.bounds().unwrap();
    assert!(hi.x - lo.x >= 390.0 && hi.z - lo.z >= 390.0, "{lo} {hi}");
    let (m, _, _) = instances_of(s, |n| n == "terrain").next().unwrap();
    let (tlo, thi) = m.bounds().unwrap();
    assert!(thi.x - tlo.x >= 390.0 && thi.z - tlo.z >= 390.0);
    // Gentle hills: some relief, no cliffs (every terrain triangle within 45° of level).
    assert!(thi.y - tlo.y > 5.0);
    for tri in m.indices.chunks(3) {
        let [a, b, c] = [0, 1, 2].map(|i| m.positions[tri[i] as usize]);
        assert!((b - a).cross(c - a).normalize().y > 0.7);
    }
    let sun = s.sun.as_ref().unwrap();
    assert_eq!(
        sun.illuminance_lux,
        hikari_scene::Sun::default().illuminance_lux
    );
}

#[test]
fn walls_are_thinner_than_15_cm_and_placed_rigidly() {
    let s = scene();
    let mut walls = 0;
    for (m, _, t) in instances_of(s, is_wall) {
        let (lo, hi) = m.bounds().unwrap();
        let thickness = (hi - lo).min_element();
        assert!(thickness < 0.15, "{} is {thickness} m thick", m.name);
        // Rigid placement: the world thickness is the object thickness.
        for col in [t.x_axis, t.y_axis, t.z_axis] {
            assert!(
                (col.truncate().length() - 1.0).abs() < 1e-5,
                "{} scaled",
                m.name
            );
        }
        walls += 1;
    }
    assert!(walls >= 8 * 4, "{walls} wall instances");
}

#[test]
fn at_least_eight_furnished_houses_with_doors_windows_and_roofs() {
    let v = village();
    let s = &v.scene;
    assert!(v.layout.houses.len() >= 8);
    let fronts: Vec<_> = instances_of(s, |n| n.contains("house front wall")).collect();
    assert_eq!(fronts.len(), v.layout.houses.len());
    // Real openings: the wall's outside face has less area than its outline by at least a
    // door (1.5 m²) and a window (1 m²); the door reaches the bottom edge, so the bottom face
    // is shorter than the wall.
    for (m, _, _) in instances_of(s, |n| {
        n.contains("house") && is_wall(n) && !n.contains("gable")
    }) {
        let (lo, hi) = m.bounds().unwrap();
        let mut outside = 0.0;
        let mut bottom = 0.0;
        for tri in m.indices.chunks(3) {
            let [a, b, c] = [0, 1, 2].map(|i| m.positions[tri[i] as usize]);
            let n = (b - a).cross(c - a);
            if n.z > 0.0 && n.normalize().z > 0.99 {
                outside += 0.5 * n.length();
            }
            if n.y < 0.0 && n.normalize().y < -0.99 && a.y == lo.y {
                bottom += 0.5 * n.length();
            }
        }
        let outline = (hi.x - lo.x) * (hi.y - lo.y);
        assert!(outline - outside > 0.5, "{}: no window-sized hole", m.name);
        if m.name.contains("front") {
            assert!(outline - outside > 2.5, "{}: no door and window", m.name);
            let full_bottom = (hi.x - lo.x) * (hi.z - lo.z);
            assert!(
                bottom < full_bottom - 0.12 * 1.5,
                "{}: the door does not reach the floor",
                m.name
            );
        }
    }
    for f in &v.layout.houses {
        // Furniture and floor inside, marked interior.
        let inside: Vec<_> = instances_of(s, |_| true)
            .filter(|(m, _, t)| in_room(f, m, *t))
            .collect();
        let names: Vec<&str> = inside.iter().map(|(m, _, _)| m.name.as_str()).collect();
        for want in ["table", "tansu", "shelves", "futon", "tatami"] {
            assert!(
                names.iter().any(|n| n.contains(want)),
                "{}: no {want} in {names:?}",
                f.name
            );
        }
        for (m, mat, _) in &inside {
            assert_eq!(mat.interior, Some(1.0), "{}", m.name);
        }
        // A roof above: a ray up from the middle of the room hits a ceiling, then a roof.
        let mid = f.centre + Vec3::Y * 1.0;
        let ceiling = ray_hit(s, mid, Vec3::Y, |n| n.contains("ceiling")).expect("a ceiling");
        let roof = ray_hit(s, mid, Vec3::Y, |n| n.contains("roof")).expect("a roof");
        assert!(ceiling < roof && ceiling < f.ceiling_height, "{}", f.name);
    }
}

#[test]
fn interior_mask_is_one_inside_and_zero_outside() {
    let s = scene();
    let material = |name: &str| {
        let (_, m, _) = instances_of(s, |n| n.contains(name)).next().unwrap();
        m.interior
    };
    assert_eq!(material("terrain"), Some(0.0));
    assert_eq!(material("pond water"), Some(0.0));
    // Everything standing entirely outside every building's walls is outdoors, vertex by
    // vertex.
    let v = village();
    let buildings: Vec<_> = v
        .layout
        .houses
        .iter()
        .chain([&v.layout.temple_hall])
        .collect();
    let mut outdoor = 0;
    for (m, mat, t) in instances_of(s, |_| true) {
        let (lo, hi) = m.bounds().unwrap();
        let outside = (0..8).all(|k| {
            let c = Vec3::new(
                if k & 1 == 0 { lo.x } else { hi.x },
                if k & 2 == 0 { lo.y } else { hi.y },
                if k & 4 == 0 { lo.z } else { hi.z },
            );
            buildings.iter().all(|f| {
                let l = f
                    .transform()
                    .inverse()
                    .transform_point3(t.transform_point3(c));
                l.x.abs() > f.half_size.x + 0.01 || l.z.abs() > f.half_size.y + 0.01
            })
        });
        if outside {
            for k in (0..m.positions.len()).step_by(97) {
                assert_eq!(m.interior_at(k, mat), 0.0, "{} vertex {k}", m.name);
            }
            outdoor += 1;
        }
    }
    assert!(outdoor > 300, "{outdoor} outdoor instances");
    // Walls: per vertex, 1 where the face looks into its building, 0 where it looks out.
    let (mut ones, mut zeros) = (0, 0);
    for (m, mat, tr) in instances_of(s, |n| is_wall(n) && !n.contains("gable")) {
        let t_world = |p: &Vec3| tr.transform_point3(*p);
        let t_world_vec = |n: &Vec3| tr.transform_vector3(*n);
        assert_eq!(
            mat.interior, None,
            "{}: the per-vertex mask decides",
            m.name
        );
        assert_eq!(m.interior.len(), m.positions.len());
        let centre = tr.transform_point3(m.bounds().map(|(a, b)| 0.5 * (a + b)).unwrap());
        let building = buildings
            .iter()
            .find(|f| f.contains(centre.with_y(f.centre.y + 1.0)))
            .unwrap_or_else(|| panic!("{} at {centre} is in no building", m.name));
        // In the building's frame, the room's walls have their inside faces on the inner
        // rectangle (half size less the thickness) and their outside faces on the outer one.
        let to_local = building.transform().inverse();
        let half = building.half_size;
        let t = 0.12;
        for ((p, n), mask) in m.positions.iter().zip(&m.normals).zip(&m.interior) {
            let l = to_local.transform_point3(t_world(p));
            let o = to_local.transform_vector3(t_world_vec(n));
            let on = |v: f32, plane: f32| (v.abs() - plane).abs() < 1e-3;
            let within = |v: f32, plane: f32| v.abs() <= plane + 1e-3;
            let faces_in = (o.z.abs() > 0.99 && o.z * l.z < 0.0 && on(l.z, half.y - t))
                || (o.x.abs() > 0.99 && o.x * l.x < 0.0 && on(l.x, half.x - t));
            // Outside faces, including the ends of walls at the building's corners.
            let faces_out = (o.z.abs() > 0.99
                && o.z * l.z > 0.0
                && on(l.z, half.y)
                && within(l.x, half.x))
                || (o.x.abs() > 0.99 && o.x * l.x > 0.0 && on(l.x, half.x) && within(l.z, half.y));
            if faces_in {
                assert_eq!(*mask, 1.0, "{} at {l} facing {o}", m.name);
                ones += 1;
            } else if faces_out {
                assert_eq!(*mask, 0.0, "{} at {l} facing {o}", m.name);
                zeros += 1;
            }
        }
    }
    assert!(
        ones > 100 && zeros > 100,
        "{ones} inside, {zeros} outside wall vertices"
    );
    // The furnishings of the temple hall are interior.
    let hall = &v.layout.temple_hall;
    let inside_hall: Vec<_> = instances_of(s, |_| true)
        .filter(|(m, _, t)| in_room(hall, m, *t))
        .collect();
    assert!(inside_hall.len() >= 6);
    for (m, mat, _) in inside_hall {
        assert_eq!(mat.interior, Some(1.0), "{}", m.name);
    }
}

#[test]
fn cameras_exist_above_ground_and_inside_their_buildings_clear_of_walls() {
    let v = village();
    let s = &v.scene;
    for name in [
        "exterior_wide",
        "courtyard",
        "house_interior",
        "temple_interior",
        "night_street",
    ] {
        let c = s.camera(name).unwrap();
        let ground = terrain_height(c.position.x, c.position.z);
        assert!(
            c.position.y > ground + 1.0,
            "{name} at {} over ground {ground}",
            c.position
        );
        // Clear of every wall's solid (its object-space box, grown by the near plane).
        for (m, _, t) in instances_of(s, is_wall) {
            let (lo, hi) = m.bounds().unwrap();
            let l = t.inverse().transform_point3(c.position);
            let grown = Vec3::splat(c.near);
            assert!(
                l.cmplt(lo - grown).any() || l.cmpgt(hi + grown).any(),
                "{name} is inside {}",
                m.name
            );
        }
    }
    assert!(s.cameras.len() >= 5);
    let house = s.camera("house_interior").unwrap();
    assert!(v.layout.houses.iter().any(|f| f.contains(house.position)));
    assert!(
        v.layout
            .temple_hall
            .contains(s.camera("temple_interior").unwrap().position)
    );
    // Inside means under a ceiling, with walls all round (rays along the floor in eight
    // directions hit a wall, door and window openings aside: at least six of eight).
    for name in ["house_interior", "temple_interior"] {
        let c = s.camera(name).unwrap();
        assert!(
            ray_hit(s, c.position, Vec3::Y, |n| n.contains("ceiling")).is_some_and(|d| d < 4.0)
        );
        let low = c.position - Vec3::Y * 0.6;
        let walled = (0..8)
            .filter(|k| {
                let a = *k as f32 * std::f32::consts::FRAC_PI_4;
                ray_hit(s, low, Vec3::new(a.cos(), 0.0, a.sin()), is_wall).is_some_and(|d| d < 15.0)
            })
            .count();
        assert!(
            walled >= 6,
            "{name}: only {walled} of 8 directions hit walls"
        );
    }
    // The outdoor cameras are outside every building.
    for name in ["exterior_wide", "courtyard", "night_street"] {
        let p = s.camera(name).unwrap().position;
        assert!(
            !v.layout
                .houses
                .iter()
                .chain([&v.layout.temple_hall])
                .any(|f| f.contains(p))
        );
    }
}

#[test]
fn lanterns_glow_and_lights_are_point_and_spot() {
    let s = scene();
    let papers: Vec<_> = instances_of(s, |n| n == "lantern paper").collect();
    let street: Vec<_> = papers
        .iter()
        .filter(|(_, m, _)| m.interior == Some(0.0))
        .collect();
    assert!(street.len() >= 20, "{} outdoor lanterns", street.len());
    let centre_of = |(mesh, _, t): &&(&Mesh, &Material, Mat4)| {
        let (lo, hi) = mesh.bounds().unwrap();
        t.transform_point3(0.5 * (lo + hi))
    };
    let points: Vec<_> = s
        .lights
        .iter()
        .filter(|l| l.kind == LightKind::Point)
        .collect();
    let mut glowing = 0;
    for p in &street {
        let (_, m, _) = p;
        let nits = luminance(m.emissive_nits);
        let centre = centre_of(p);
        let light_inside = points.iter().any(|l| centre.distance(l.position) < 0.05);
        // A glowing paper has its light inside and a dark one none: the street's light is
        // sampled as lights, never only found by GI rays (docs/ray-traced-gi.md).
        assert_eq!(nits > 0.0, light_inside, "lantern at {centre}: {nits} nits");
        if nits > 0.0 {
            glowing += 1;
            // 2000 to 5000 nits, up to rounding of the colour's luminance.
            assert!((1999.0..=5000.0).contains(&nits), "{nits} nits");
            assert!(m.emissive_nits.x > m.emissive_nits.z, "warm");
        }
    }
    assert!(glowing >= 5, "{glowing} lit lanterns");
    let spots: Vec<_> = s
        .lights
        .iter()
        .filter(|l| matches!(l.kind, LightKind::Spot { .. }))
        .collect();
    assert!(!spots.is_empty());
    let hall = &village().layout.temple_hall;
    for l in &spots {
        assert!(l.position.distance(hall.centre) < 12.0 && l.direction.y < -0.5);
    }
    // Every light is above the ground (the houses' floor lamps stand on floors raised above it).
    for l in &s.lights {
        assert!(
            l.position.y > terrain_height(l.position.x, l.position.z) + 0.3,
            "{}",
            l.name
        );
    }
}

#[test]
fn polished_and_brushed_metal_and_a_dark_glossy_pond() {
    let s = scene();
    let metals: Vec<_> = instances_of(s, |_| true)
        .filter(|(_, m, _)| m.metalness == 1.0 && m.roughness <= 0.3)
        .collect();
    assert!(metals.iter().any(|(mesh, _, _)| mesh.name.contains("bell")));
    let (mesh, mat, _) = instances_of(s, |_| true)
        .find(|(_, m, _)| m.anisotropy.is_some_and(|a| a.strength > 0.5))
        .expect("an anisotropic material in use");
    assert_eq!(mat.metalness, 1.0);
    assert_eq!(mesh.tangents.len(), mesh.positions.len());
    for (t, n) in mesh.tangents.iter().zip(&mesh.normals) {
        assert!((t.truncate().length() - 1.0).abs() < 1e-4 && t.truncate().dot(*n).abs() < 1e-4);
        assert!(t.w.abs() == 1.0);
    }
    let (_, water, _) = instances_of(s, |n| n == "pond water").next().unwrap();
    assert!(water.roughness <= 0.1 && water.base_color.max_element() < 0.1);
    // The pond fills a depression: the ground under its middle is well below the water and
    // the ground beyond its shore is above it.
    let v = village();
    let (c, r) = (v.layout.pond_centre, v.layout.pond_shore_radius);
    assert!(terrain_height(c.x, c.z) < c.y - 1.0);
    for k in 0..8 {
        let a = k as f32 * std::f32::consts::FRAC_PI_4;
        let p = c + 1.5 * r * Vec3::new(a.cos(), 0.0, a.sin());
        assert!(terrain_height(p.x, p.z) > c.y, "shore at {p}");
    }
}

#[test]
fn trees_sway_and_the_wheel_turns_without_hitting_the_ground() {
    let s = scene();
    let mut sway = 0;
    let mut spin = None;
    for inst in &s.instances {
        match s.meshes[inst.mesh].deformation {
            Some(Deformation::Sway { .. }) => sway += 1,
            Some(Deformation::Spin { .. }) => spin = Some(inst),
            None => {}
        }
    }
    assert!(sway >= 40, "{sway} swaying instances");
    let wheel = spin.expect("a spinning mesh");
    let mesh = &s.meshes[wheel.mesh];
    let rest = &mesh.positions;
    let mut max_moved = 0.0f32;
    for k in 0..24 {
        let (p, n) = mesh.deformed(k as f32 * 0.37);
        for (a, b) in p.iter().zip(rest) {
            max_moved = max_moved.max(a.distance(*b));
        }
        assert!(n.iter().all(|n| (n.length() - 1.0).abs() < 1e-4));
        // Every part of the wheel stays above the pond bed (sampled every tenth vertex).
        for q in p.iter().step_by(10) {
            let w = wheel.transform.transform_point3(*q);
            assert!(
                w.y > terrain_height(w.x, w.z) + 0.05,
                "wheel at {w} is in the ground"
            );
        }
    }
    assert!(max_moved > 1.0, "{max_moved}");
    // Trees keep their feet: the vertices at the base do not move.
    let (tree, _, _) = instances_of(s, |n| n.contains("wood")).next().unwrap();
    let (p, _) = tree.deformed(1.3);
    for (a, b) in p.iter().zip(&tree.positions) {
        if b.y <= 0.0 {
            assert_eq!(a, b);
        }
    }
}

#[test]
fn golden_trees_ring_the_courtyard_and_leaves_lie_on_it() {
    let v = village();
    let s = &v.scene;
    let c = v.layout.courtyard_centre;
    let r = v.layout.courtyard_radius;
    let golden: Vec<Vec3> = instances_of(s, |n| n.contains("foliage"))
        .filter(|(_, m, _)| {
            m.name.contains("ginkgo") && m.base_color.x > 0.6 && m.base_color.z < 0.2
        })
        .map(|(_, _, t)| t.transform_point3(Vec3::ZERO))
        .filter(|p| (p.distance(c.with_y(p.y)) - r).abs() < 6.0)
        .collect();
    assert!(
        golden.len() >= 12,
        "{} golden trees around the courtyard",
        golden.len()
    );
    // All round it: each quarter except the south entrance has some.
    for (dx, dz) in [(1.0, 0.0), (-1.0, 0.0), (0.0, 1.0)] {
        assert!(
            golden
                .iter()
                .any(|p| (*p - c).normalize().dot(Vec3::new(dx, 0.0, dz)) > 0.8)
        );
    }
    let (leaves, mat, t) = instances_of(s, |n| n == "fallen leaves").next().unwrap();
    assert!(mat.double_sided && mat.base_color.x > 0.6 && mat.base_color.z < 0.2);
    assert!(leaves.indices.len() / 6 >= 1000);
    for p in leaves.positions.iter().step_by(37) {
        let w = t.transform_point3(*p);
        assert!(w.distance(c.with_y(w.y)) < r + 2.0);
        let ground = terrain_height(w.x, w.z);
        assert!(
            w.y > ground + 0.001 && w.y < ground + 0.05,
            "leaf at {w}, ground {ground}"
        );
    }
    // The temple: raised floor, pillars, an interior.
    let hall = &v.layout.temple_hall;
    assert!(hall.centre.y > c.y + 1.0);
    assert!(instances_of(s, |n| n.contains("pillar")).count() >= 10);
}

#[test]
fn report_stats() {
    let s = scene();
    let vertex_bytes = |m: &Mesh| {
        m.positions.len() * 24
            + m.tangents.len() * 16
            + m.uvs.len() * 8
            + m.colors.as_ref().map_or(0, |c| c.len() * 16)
            + m.interior.len() * 4
            + m.indices.len() * 4
    };
    let bytes: usize = s.meshes.iter().map(vertex_bytes).sum();
    let stored: usize = s.meshes.iter().map(|m| m.indices.len() / 3).sum();
    println!(
        "village: {} triangles drawn ({} stored in {} meshes), {} instances, {} materials, {} lights, mesh data {:.1} MiB",
        s.triangle_count(),
        stored,
        s.meshes.len(),
        s.instances.len(),
        s.materials.len(),
        s.lights.len(),
        bytes as f64 / (1024.0 * 1024.0)
    );
    let mut by_part: Vec<(&str, usize, usize)> = Vec::new();
    for i in &s.instances {
        let name = s.meshes[i.mesh].name.as_str();
        let part = [
            "terrain",
            "house",
            "temple",
            "bell",
            "ginkgo",
            "broadleaf",
            "cedar",
            "lantern",
            "fallen",
            "wheel",
        ]
        .into_iter()
        .find(|p| name.contains(p))
        .unwrap_or("furniture and other");
        let tris = s.meshes[i.mesh].indices.len() / 3;
        match by_part.iter_mut().find(|(p, _, _)| *p == part) {
            Some(e) => {
                e.1 += tris;
                e.2 += 1;
            }
            None => by_part.push((part, tris, 1)),
        }
    }
    for (part, tris, n) in by_part {
        println!("  {part}: {tris} triangles in {n} instances");
    }
    for c in &s.cameras {
        println!("camera {}: {} -> {}", c.name, c.position, c.target);
    }
}

/// Every glowing surface of the village (lanterns, andon lamps) has a point light inside its
/// bounds: the light it casts is sampled as a light, never left to one GI ray a pixel to find
/// (the night's white speckle, docs/ray-traced-gi.md), and its paper is that light's shell.
#[test]
fn every_glowing_surface_has_its_light_inside() {
    let s = scene();
    let mut glowing = 0;
    for i in &s.instances {
        let m = &s.materials[i.material];
        if luminance(m.emissive_nits) <= 0.0 {
            continue;
        }
        glowing += 1;
        let (lo, hi) = s.meshes[i.mesh].bounds().unwrap();
        let corners = (0..8).map(|k| {
            i.transform.transform_point3(Vec3::new(
                if k & 1 == 0 { lo.x } else { hi.x },
                if k & 2 == 0 { lo.y } else { hi.y },
                if k & 4 == 0 { lo.z } else { hi.z },
            ))
        });
        let (wlo, whi) = corners.fold((Vec3::MAX, Vec3::MIN), |(a, b), c| (a.min(c), b.max(c)));
        let inside = s.lights.iter().any(|l| {
            l.kind == LightKind::Point && l.position.cmpge(wlo).all() && l.position.cmple(whi).all()
        });
        assert!(
            inside,
            "{} ({}) glows without a light inside",
            s.meshes[i.mesh].name, m.name
        );
    }
    assert!(glowing >= 20, "{glowing} glowing instances");
}
