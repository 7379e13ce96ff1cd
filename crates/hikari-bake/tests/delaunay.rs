//! The Delaunay tetrahedralisation and the adjacency walk, checked by brute force in f64
//! arithmetic of their own (not the `robust` predicates the tetrahedraliser uses):
//! - every tetrahedron has positive volume, and no input point lies strictly inside any
//!   tetrahedron's circumsphere (the empty-sphere property);
//! - neighbours are mutual and share exactly the face opposite the vertex named;
//! - the tetrahedra fill the convex hull: their volumes add up to the hull's (a cube's
//!   corners are among the points), and every random point inside the hull is found, by the
//!   walk and by brute force, in a tetrahedron whose barycentrics reproduce it.

use hikari_bake::delaunay::{DelaunayError, tetrahedralize};
use hikari_math::sampling::rng::SplitMix64;
use hikari_probes::locate::{Location, barycentrics, locate, locate_brute_force};
use hikari_probes::{HULL, ProbeSh, TetMesh};

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
fn volume(p: [[f64; 3]; 4]) -> f64 {
    dot(sub(p[1], p[0]), cross(sub(p[2], p[0]), sub(p[3], p[0]))) / 6.0
}

/// Circumcentre by solving the 3x3 system `2 (q_k - q_0) · c = |q_k|² - |q_0|²` (Cramer).
fn circumsphere(p: [[f64; 3]; 4]) -> ([f64; 3], f64) {
    let rows = [1, 2, 3].map(|k| sub(p[k], p[0]));
    let rhs = [1, 2, 3].map(|k| 0.5 * (dot(p[k], p[k]) - dot(p[0], p[0])));
    let det3 = |a: [f64; 3], b: [f64; 3], c: [f64; 3]| dot(a, cross(b, c));
    let col = |k: usize| [rows[0][k], rows[1][k], rows[2][k]];
    let d = det3(col(0), col(1), col(2));
    let c = [
        det3(rhs, col(1), col(2)) / d,
        det3(col(0), rhs, col(2)) / d,
        det3(col(0), col(1), rhs) / d,
    ];
    let r = sub(p[0], c);
    (c, dot(r, r))
}

fn random_points(n: usize, seed: u64, with_cube_corners: bool) -> Vec<[f64; 3]> {
    let mut rng = SplitMix64::new(seed);
    let mut pts = Vec::new();
    if with_cube_corners {
        for k in 0..8 {
            // Corners of [0, 10]³, nudged by < 1 µm: exactly cospherical corners are the
            // degenerate input the tetrahedraliser refuses.
            let c = [(k & 1) as f64, ((k >> 1) & 1) as f64, ((k >> 2) & 1) as f64];
            pts.push(c.map(|x| 10.0 * x + 1e-7 * (rng.next_f64() - 0.5)));
        }
    }
    while pts.len() < n {
        pts.push([0, 1, 2].map(|_| 0.1 + 9.8 * rng.next_f64()));
    }
    pts
}

fn mesh_of(points: &[[f64; 3]]) -> TetMesh {
    let t = tetrahedralize(points).expect("tetrahedralises");
    TetMesh {
        id: 0,
        positions: points.iter().map(|p| p.map(|x| x as f32)).collect(),
        probes: vec![ProbeSh::default(); points.len()],
        interior: vec![false; points.len()],
        tets: t.tets,
        adjacency: t.adjacency,
    }
}

#[test]
fn empty_circumspheres_positive_volumes_mutual_adjacency() {
    for (seed, n) in [(1u64, 50usize), (2, 300), (3, 600)] {
        let pts = random_points(n, seed, seed == 2);
        let t = tetrahedralize(&pts).expect("tetrahedralises");
        assert!(t.tets.len() > n, "{} tets for {n} points", t.tets.len());
        for (i, tet) in t.tets.iter().enumerate() {
            let p = tet.map(|v| pts[v as usize]);
            assert!(volume(p) > 0.0, "tet {i} {tet:?} has volume {}", volume(p));
            let (c, r2) = circumsphere(p);
            for (j, q) in pts.iter().enumerate() {
                if tet.contains(&(j as u32)) {
                    continue;
                }
                let d = sub(*q, c);
                assert!(
                    dot(d, d) >= r2 * (1.0 - 1e-9),
                    "seed {seed}: point {j} inside the circumsphere of tet {i}"
                );
            }
        }
        for (i, nb) in t.adjacency.iter().enumerate() {
            for (k, &across) in nb.iter().enumerate() {
                if across == HULL {
                    continue;
                }
                let other = t.tets[across as usize];
                let face: Vec<u32> = (0..4).filter(|&j| j != k).map(|j| t.tets[i][j]).collect();
                assert!(face.iter().all(|v| other.contains(v)), "tet {i} face {k}");
                assert!(!other.contains(&t.tets[i][k]));
                let back = t.adjacency[nb[k] as usize];
                assert!(
                    back.contains(&(i as u32)),
                    "tet {i} -> {} not mutual",
                    nb[k]
                );
            }
        }
    }
}

#[test]
fn tetrahedra_fill_the_hull_and_every_point_inside_is_located() {
    let pts = random_points(400, 11, true);
    let mesh = mesh_of(&pts);
    let total: f64 = mesh
        .tets
        .iter()
        .map(|t| volume(t.map(|v| pts[v as usize])))
        .sum();
    assert!(
        (total - 1000.0).abs() < 1e-3,
        "tetrahedra fill {total} of 1000 m³"
    );
    let mut rng = SplitMix64::new(99);
    let mut last = 0;
    for _ in 0..2000 {
        let p = [0, 1, 2].map(|_| (0.01 + 9.98 * rng.next_f64()) as f32);
        let walk = locate(&mesh, p, last, 1e-5);
        let brute = locate_brute_force(&mesh, p, 1e-5);
        let Location::Inside { tet, weights } = walk else {
            panic!("{p:?} is inside the hull but the walk left it");
        };
        assert!(matches!(brute, Location::Inside { .. }));
        last = tet;
        let v = mesh.tets[tet as usize];
        let mut back = [0.0f64; 3];
        for k in 0..4 {
            for (b, x) in back.iter_mut().zip(mesh.positions[v[k] as usize]) {
                *b += f64::from(weights[k]) * f64::from(x);
            }
        }
        for c in 0..3 {
            assert!(
                (back[c] - f64::from(p[c])).abs() < 1e-4,
                "{p:?} vs {back:?}"
            );
        }
        let w = barycentrics(&mesh, tet as usize, p).unwrap();
        assert!(w.iter().all(|&x| x >= -1e-5));
    }
    for p in [[-0.5f32, 5.0, 5.0], [5.0, 10.5, 5.0], [20.0, 20.0, 20.0]] {
        assert_eq!(locate(&mesh, p, 0, 1e-5), Location::Outside, "{p:?}");
        assert_eq!(locate_brute_force(&mesh, p, 1e-5), Location::Outside);
    }
    assert_eq!(
        locate(&mesh, [f32::NAN, 0.0, 0.0], 0, 1e-5),
        Location::Outside
    );
}

#[test]
fn bad_input_is_an_error() {
    assert_eq!(
        tetrahedralize(&[[0.0; 3]; 3]),
        Err(DelaunayError::TooFewPoints(3))
    );
    let mut pts = random_points(20, 5, false);
    pts[7] = [f64::NAN, 0.0, 0.0];
    assert!(matches!(
        tetrahedralize(&pts),
        Err(DelaunayError::NotFinite { index: 7, .. })
    ));
    let mut pts = random_points(20, 5, false);
    pts[12] = pts[3];
    assert_eq!(
        tetrahedralize(&pts),
        Err(DelaunayError::Degenerate { index: 12 })
    );
    let flat: Vec<[f64; 3]> = random_points(20, 6, false)
        .into_iter()
        .map(|p| [p[0], 1.0, p[2]])
        .collect();
    assert!(tetrahedralize(&flat).is_err());
}
