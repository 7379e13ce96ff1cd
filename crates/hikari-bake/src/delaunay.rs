//! 3D Delaunay tetrahedralisation (Bowyer–Watson) with exact orientation and in-sphere
//! predicates from the `robust` crate (Shewchuk's adaptive predicates).
//!
//! Why our own: the Rust Delaunay crates are GPL/AGPL bindings (tritet wraps TetGen), or large
//! (`delaunay` 0.7: BSD-3-Clause, nalgebra/serde stack, a newer toolchain than ours), while
//! Bowyer–Watson over a few thousand probes is a page of code once the predicates are exact.
//!
//! Insertion scans every live tetrahedron (a cached floating-point circumsphere rejects most,
//! the exact in-sphere test decides the rest): O(n²), a fraction of a second for the bake's
//! meshes of at most a few thousand probes.
//!
//! Output convention (as `hikari_probes::TetMesh` stores it): every tetrahedron `[a, b, c, d]`
//! has positive volume, `(b - a) · ((c - a) × (d - a)) > 0`; `adjacency[t][k]` is the
//! tetrahedron across the face opposite vertex `k`, or [`hikari_probes::HULL`].

use std::collections::HashMap;

use robust::{Coord3D, insphere, orient3d};
use thiserror::Error;

#[derive(Debug, Error, Clone, PartialEq)]
pub enum DelaunayError {
    #[error("a tetrahedralisation needs at least 4 points, got {0}")]
    TooFewPoints(usize),
    #[error("point {index} is not finite: {point:?}")]
    NotFinite { index: usize, point: [f64; 3] },
    #[error(
        "point {index} duplicates an earlier point or is degenerate with its neighbours (cospherical or coplanar): jitter the input"
    )]
    Degenerate { index: usize },
    #[error("all points are coplanar: no tetrahedron has volume")]
    Flat,
}

/// Tetrahedra and their face neighbours.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Tetrahedralization {
    pub tets: Vec<[u32; 4]>,
    pub adjacency: Vec<[u32; 4]>,
}

struct Tet {
    v: [u32; 4],
    /// Circumcentre and radius in f64, and a bound on their rounding error, for a fast
    /// conservative reject; an infinite radius leaves every decision to the exact test.
    centre: [f64; 3],
    radius: f64,
}

fn coord(p: [f64; 3]) -> Coord3D<f64> {
    Coord3D {
        x: p[0],
        y: p[1],
        z: p[2],
    }
}

/// Circumcentre and radius grown by a generous bound on the rounding of the centre (the
/// condition of the 3x3 solve: `|b|²|c||d| + ...` over the determinant, times 1e-10, far above
/// f64's 1e-16), so that a point rejected by it is outside the true sphere.
fn circumsphere(p: [[f64; 3]; 4]) -> ([f64; 3], f64) {
    let a = p[0];
    let sub = |q: [f64; 3]| [q[0] - a[0], q[1] - a[1], q[2] - a[2]];
    let (b, c, d) = (sub(p[1]), sub(p[2]), sub(p[3]));
    let dot = |u: [f64; 3], v: [f64; 3]| u[0] * v[0] + u[1] * v[1] + u[2] * v[2];
    let cross = |u: [f64; 3], v: [f64; 3]| {
        [
            u[1] * v[2] - u[2] * v[1],
            u[2] * v[0] - u[0] * v[2],
            u[0] * v[1] - u[1] * v[0],
        ]
    };
    let (cd, db, bc) = (cross(c, d), cross(d, b), cross(b, c));
    let det = 2.0 * dot(b, cd);
    let (bb, cc, dd) = (dot(b, b), dot(c, c), dot(d, d));
    let o = [
        (bb * cd[0] + cc * db[0] + dd * bc[0]) / det,
        (bb * cd[1] + cc * db[1] + dd * bc[1]) / det,
        (bb * cd[2] + cc * db[2] + dd * bc[2]) / det,
    ];
    let err =
        1e-10 * (bb * (cc * dd).sqrt() + cc * (dd * bb).sqrt() + dd * (bb * cc).sqrt()) / det.abs();
    let r = dot(o, o).sqrt() + 2.0 * err;
    if !(o.iter().all(|x| x.is_finite()) && r.is_finite()) {
        // A (near-)flat tetrahedron: never reject it cheaply, let the exact test decide.
        return ([0.0; 3], f64::INFINITY);
    }
    ([o[0] + a[0], o[1] + a[1], o[2] + a[2]], r)
}

/// Delaunay tetrahedralisation of `points`. Degenerate input (duplicates, four or more
/// cospherical points sharing an empty sphere, coplanar sets) is refused rather than
/// triangulated with flat tetrahedra: jitter regular lattices by a small fraction of their
/// spacing first.
pub fn tetrahedralize(points: &[[f64; 3]]) -> Result<Tetrahedralization, DelaunayError> {
    let n = points.len();
    if n < 4 {
        return Err(DelaunayError::TooFewPoints(n));
    }
    if let Some((index, &point)) = points
        .iter()
        .enumerate()
        .find(|(_, p)| !p.iter().all(|x| x.is_finite()))
    {
        return Err(DelaunayError::NotFinite { index, point });
    }
    let mut lo = points[0];
    let mut hi = points[0];
    for p in points {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let centre = [0.0, 1.0, 2.0].map(|k: f64| 0.5 * (lo[k as usize] + hi[k as usize]));
    let extent = (0..3).map(|k| hi[k] - lo[k]).fold(1e-3, f64::max);
    // The super-tetrahedron's vertices far enough out that the hull faces of nearly coplanar
    // probe layers are still made (a face planar within ε over L needs ~L²/ε); exact predicates
    // keep the arithmetic right at this scale.
    let far = 1e6 * extent;
    let mut verts: Vec<[f64; 3]> = points.to_vec();
    for s in [
        [1.0, 1.0, 1.0],
        [1.0, -1.0, -1.0],
        [-1.0, 1.0, -1.0],
        [-1.0, -1.0, 1.0],
    ] {
        verts.push([
            centre[0] + far * s[0],
            centre[1] + far * s[1],
            centre[2] + far * s[2],
        ]);
    }
    let s = n as u32;
    let make = |v: [u32; 4], verts: &[[f64; 3]]| {
        if v.iter().any(|&i| i >= s) {
            // Vertices a million extents out: the f64 sphere is too coarse to reject with.
            return Tet {
                v,
                centre: [0.0; 3],
                radius: f64::INFINITY,
            };
        }
        let (centre, radius) = circumsphere(v.map(|i| verts[i as usize]));
        Tet { v, centre, radius }
    };
    let positive = |v: [u32; 4], verts: &[[f64; 3]]| {
        let [a, b, c, d] = v.map(|i| coord(verts[i as usize]));
        orient3d(a, b, c, d) > 0.0
    };
    let mut first = [s, s + 1, s + 2, s + 3];
    if !positive(first, &verts) {
        first.swap(0, 1);
    }
    let mut tets = vec![make(first, &verts)];

    let mut cavity: Vec<[u32; 4]> = Vec::new();
    let mut faces: HashMap<[u32; 3], (u32, [u32; 4], usize)> = HashMap::new();
    let mut boundary: Vec<([u32; 3], [u32; 4], usize)> = Vec::new();
    for (index, p) in points.iter().enumerate() {
        let pc = coord(*p);
        cavity.clear();
        let mut k = 0;
        while k < tets.len() {
            let t = &tets[k];
            let d2 = (0..3).map(|i| (p[i] - t.centre[i]).powi(2)).sum::<f64>();
            // NaN distances (never expected) fall through to the exact test.
            let maybe = d2.sqrt() <= t.radius || d2.is_nan();
            let inside = maybe && {
                let [a, b, c, d] = t.v.map(|i| coord(verts[i as usize]));
                insphere(a, b, c, d, pc) > 0.0
            };
            if inside {
                cavity.push(t.v);
                tets.swap_remove(k);
            } else {
                k += 1;
            }
        }
        if cavity.is_empty() {
            return Err(DelaunayError::Degenerate { index });
        }
        faces.clear();
        for v in &cavity {
            for skip in 0..4 {
                let mut key = [0u32; 3];
                let mut m = 0;
                for (j, &x) in v.iter().enumerate() {
                    if j != skip {
                        key[m] = x;
                        m += 1;
                    }
                }
                key.sort_unstable();
                faces
                    .entry(key)
                    .and_modify(|e| e.0 += 1)
                    .or_insert((1, *v, skip));
            }
        }
        // In face order, not the hash map's (seeded per map), so that a bake is reproducible.
        boundary.clear();
        boundary.extend(
            faces
                .iter()
                .filter(|(_, e)| e.0 == 1)
                .map(|(k, e)| (*k, e.1, e.2)),
        );
        boundary.sort_unstable_by_key(|b| b.0);
        for &(_, v, skip) in &boundary {
            // The cavity is star-shaped from p, so p stands on the same side of this face as
            // the vertex it replaces and the orientation is kept.
            let mut nv = v;
            nv[skip] = index as u32;
            if !positive(nv, &verts) {
                return Err(DelaunayError::Degenerate { index });
            }
            tets.push(make(nv, &verts));
        }
    }

    let out: Vec<[u32; 4]> = tets
        .iter()
        .filter(|t| t.v.iter().all(|&i| i < s))
        // robust's positive orientation is our negative volume: swap two vertices.
        .map(|t| [t.v[1], t.v[0], t.v[2], t.v[3]])
        .collect();
    if out.is_empty() {
        return Err(DelaunayError::Flat);
    }
    let adjacency = adjacency_of(&out);
    Ok(Tetrahedralization {
        tets: out,
        adjacency,
    })
}

/// Neighbour across the face opposite each vertex, or `u32::MAX` on the hull.
pub fn adjacency_of(tets: &[[u32; 4]]) -> Vec<[u32; 4]> {
    let mut adjacency = vec![[u32::MAX; 4]; tets.len()];
    let mut open: HashMap<[u32; 3], (u32, usize)> = HashMap::with_capacity(tets.len() * 2);
    for (t, v) in tets.iter().enumerate() {
        for skip in 0..4 {
            let mut key = [0u32; 3];
            let mut m = 0;
            for (j, &x) in v.iter().enumerate() {
                if j != skip {
                    key[m] = x;
                    m += 1;
                }
            }
            key.sort_unstable();
            if let Some((other, other_skip)) = open.remove(&key) {
                adjacency[t][skip] = other;
                adjacency[other as usize][other_skip] = t as u32;
            } else {
                open.insert(key, (t as u32, skip));
            }
        }
    }
    adjacency
}
