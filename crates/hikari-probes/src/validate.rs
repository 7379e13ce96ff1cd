//! Checks a bake's consistency; run on every bake written and every bake read, so that NaN,
//! bad indices and mismatched lengths never reach a file or the renderer.
//!
//! Sections are numbered as in the file: tiles first, then meshes.

use std::collections::HashSet;

use crate::error::Problem;
use crate::model::{
    Bake, BakeSettings, GridTile, HULL, ProbeSh, TILE_COLUMNS, TILE_PROBE_COUNT, TetMesh,
};

/// Checks settings, counts, indices, adjacency and finiteness of a whole bake.
pub fn validate(bake: &Bake) -> Result<(), Problem> {
    validate_settings(&bake.settings)?;
    let mut tiles_seen = HashSet::new();
    for (section, tile) in bake.tiles.iter().enumerate() {
        validate_tile(section, tile)?;
        if !tiles_seen.insert(tile.tile) {
            return Err(Problem::DuplicateTile {
                section,
                tile: tile.tile,
            });
        }
    }
    let mut meshes_seen = HashSet::new();
    for (k, mesh) in bake.meshes.iter().enumerate() {
        let section = bake.tiles.len() + k;
        validate_mesh(section, mesh)?;
        if !meshes_seen.insert(mesh.id) {
            return Err(Problem::DuplicateMesh {
                section,
                id: mesh.id,
            });
        }
    }
    Ok(())
}

pub(crate) fn validate_settings(settings: &BakeSettings) -> Result<(), Problem> {
    if settings.rays_per_probe == 0 {
        return Err(Problem::InvalidSettings("zero rays per probe".into()));
    }
    let spacing = settings.grid_spacing_m;
    if !(spacing.is_finite() && spacing > 0.0) {
        return Err(Problem::InvalidSettings(format!(
            "grid spacing {spacing} m is not a positive finite length"
        )));
    }
    if let Some(h) = settings.layer_heights_m.iter().find(|h| !h.is_finite()) {
        return Err(Problem::InvalidSettings(format!(
            "layer height {h} m is not finite"
        )));
    }
    Ok(())
}

fn counts(section: usize, what: &str, found: usize, expected: usize) -> Result<(), Problem> {
    if found == expected {
        Ok(())
    } else {
        Err(Problem::InconsistentCounts {
            section,
            what: format!("{found} {what}, expected {expected}"),
        })
    }
}

fn finite(
    section: usize,
    what: &'static str,
    element: usize,
    values: &[f32],
) -> Result<(), Problem> {
    if values.iter().all(|v| v.is_finite()) {
        Ok(())
    } else {
        Err(Problem::NonFinite {
            section,
            what,
            element,
        })
    }
}

fn validate_probes(section: usize, probes: &[ProbeSh]) -> Result<(), Problem> {
    for (p, probe) in probes.iter().enumerate() {
        finite(section, "sky visibility of probe", p, &probe.sky_visibility)?;
        finite(
            section,
            "bounced sky visibility of probe",
            p,
            probe.bounced_sky_visibility.as_flattened(),
        )?;
    }
    Ok(())
}

fn validate_tile(section: usize, tile: &GridTile) -> Result<(), Problem> {
    counts(
        section,
        "ground heights",
        tile.ground_heights_m.len(),
        TILE_COLUMNS,
    )?;
    counts(section, "probes", tile.probes.len(), TILE_PROBE_COUNT)?;
    counts(
        section,
        "interior flags",
        tile.interior.len(),
        TILE_PROBE_COUNT,
    )?;
    finite(section, "tile origin", 0, &tile.origin_xz)?;
    for (c, h) in tile.ground_heights_m.iter().enumerate() {
        finite(
            section,
            "ground height of column",
            c,
            std::slice::from_ref(h),
        )?;
    }
    validate_probes(section, &tile.probes)
}

fn validate_mesh(section: usize, mesh: &TetMesh) -> Result<(), Problem> {
    let n = mesh.positions.len();
    counts(section, "probes for positions", mesh.probes.len(), n)?;
    counts(
        section,
        "interior flags for positions",
        mesh.interior.len(),
        n,
    )?;
    counts(
        section,
        "adjacency entries for tetrahedra",
        mesh.adjacency.len(),
        mesh.tets.len(),
    )?;
    for (p, pos) in mesh.positions.iter().enumerate() {
        finite(section, "position of probe", p, pos)?;
    }
    validate_probes(section, &mesh.probes)?;
    for (t, tet) in mesh.tets.iter().enumerate() {
        for &v in tet {
            if v as usize >= n {
                return Err(Problem::IndexOutOfRange {
                    section,
                    what: "vertex of tetrahedron",
                    element: t,
                    index: v,
                    limit: n,
                });
            }
        }
        let distinct = (0..4).all(|a| (a + 1..4).all(|b| tet[a] != tet[b]));
        if !distinct {
            return Err(Problem::DegenerateTet {
                section,
                tet: t,
                vertices: *tet,
            });
        }
    }
    let m = mesh.tets.len();
    for (t, neighbours) in mesh.adjacency.iter().enumerate() {
        for &nb in neighbours {
            if nb == HULL {
                continue;
            }
            let Some(back) = mesh.adjacency.get(nb as usize) else {
                return Err(Problem::IndexOutOfRange {
                    section,
                    what: "neighbour of tetrahedron",
                    element: t,
                    index: nb,
                    limit: m,
                });
            };
            // A walk through the mesh steps to a neighbour and must be able to step back;
            // a one-sided or self link would make it loop or leave the mesh.
            if nb as usize == t || !back.contains(&(t as u32)) {
                return Err(Problem::AdjacencyNotMutual {
                    section,
                    tet: t,
                    neighbour: nb,
                });
            }
        }
    }
    Ok(())
}
