//! Point location in a tetrahedral mesh by walking its adjacency (Cupisz 2012: start from the
//! last tetrahedron found, step across the face whose barycentric coordinate is most negative).
//! The renderer's GPU walk twins this; tools and tests use it on the CPU.

use crate::model::{HULL, TetMesh};

/// Where a point lies in a mesh.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Location {
    /// Inside (or on) tetrahedron `tet`, with barycentric weights of its four vertices (sum 1).
    Inside { tet: u32, weights: [f32; 4] },
    /// Outside the mesh: the walk left through a hull face (a Delaunay mesh is convex, so the
    /// point is outside its hull), or the mesh has no tetrahedra.
    Outside,
}

/// Barycentric weights of `p` in tetrahedron `tet` (in f64); `None` for a flat tetrahedron or
/// an index out of range.
pub fn barycentrics(mesh: &TetMesh, tet: usize, p: [f32; 3]) -> Option<[f64; 4]> {
    let v = mesh.tets.get(tet)?;
    let mut q = [[0.0f64; 3]; 4];
    for (k, &i) in v.iter().enumerate() {
        q[k] = mesh.positions.get(i as usize)?.map(f64::from);
    }
    let p = p.map(f64::from);
    let sub = |a: [f64; 3], b: [f64; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    let det = |a: [f64; 3], b: [f64; 3], c: [f64; 3]| {
        a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
            + a[2] * (b[0] * c[1] - b[1] * c[0])
    };
    let (e1, e2, e3, ep) = (
        sub(q[1], q[0]),
        sub(q[2], q[0]),
        sub(q[3], q[0]),
        sub(p, q[0]),
    );
    let vol = det(e1, e2, e3);
    if vol.abs() < 1e-18 {
        return None;
    }
    let w1 = det(ep, e2, e3) / vol;
    let w2 = det(e1, ep, e3) / vol;
    let w3 = det(e1, e2, ep) / vol;
    Some([1.0 - w1 - w2 - w3, w1, w2, w3])
}

/// Walks from tetrahedron `start` (clamped into range) to the one holding `p`. Gives up after
/// as many steps as there are tetrahedra (a walk can cycle only through rounding) and then
/// scans every tetrahedron. `tolerance` is how far below zero a weight may be and still count
/// as inside (1e-5 is a good value).
pub fn locate(mesh: &TetMesh, p: [f32; 3], start: u32, tolerance: f64) -> Location {
    let n = mesh.tets.len();
    if n == 0 || !p.iter().all(|x| x.is_finite()) {
        return Location::Outside;
    }
    let mut t = (start as usize).min(n - 1);
    for _ in 0..n {
        let Some(w) = barycentrics(mesh, t, p) else {
            break;
        };
        let (k, min) =
            w.iter().enumerate().fold(
                (0, f64::INFINITY),
                |acc, (k, &x)| if x < acc.1 { (k, x) } else { acc },
            );
        if min >= -tolerance {
            return inside(t, w);
        }
        match mesh.adjacency.get(t).map(|a| a[k]) {
            Some(HULL) => return Location::Outside,
            Some(next) if (next as usize) < n => t = next as usize,
            _ => break,
        }
    }
    locate_brute_force(mesh, p, tolerance)
}

/// The first tetrahedron holding `p`, by testing every one.
pub fn locate_brute_force(mesh: &TetMesh, p: [f32; 3], tolerance: f64) -> Location {
    for t in 0..mesh.tets.len() {
        if let Some(w) = barycentrics(mesh, t, p)
            && w.iter().all(|&x| x >= -tolerance)
        {
            return inside(t, w);
        }
    }
    Location::Outside
}

fn inside(t: usize, w: [f64; 4]) -> Location {
    let w = w.map(|x| x.max(0.0));
    let sum: f64 = w.iter().sum::<f64>().max(1e-30);
    Location::Inside {
        tet: t as u32,
        weights: w.map(|x| (x / sum) as f32),
    }
}
