//! Bytes of a bake file: encoding and fully validating decoding (layout in the crate docs).

use crate::error::Problem;
use crate::model::{
    Bake, BakeSettings, GridTile, ProbeSh, SH_COEFFS, SceneKey, TILE_COLUMNS, TILE_PROBE_COUNT,
    TetMesh,
};
use crate::validate::{validate, validate_settings};

/// First eight bytes of every bake file.
pub const MAGIC: [u8; 8] = *b"HIKPROBE";
/// The format version this build writes and reads.
pub const FORMAT_VERSION: u32 = 1;
/// Header flag: the bake is complete (not a checkpoint).
pub const FLAG_COMPLETE: u32 = 1;
/// Bytes of the fixed header.
pub const HEADER_LEN: usize = 80;
/// Bytes of one section-table entry.
pub const SECTION_ENTRY_LEN: usize = 24;
/// Bytes of the CRC-32 trailer.
pub const CHECKSUM_LEN: usize = 4;
/// Section kind of a grid tile.
pub const SECTION_GRID_TILE: u32 = 1;
/// Section kind of a tetrahedral mesh.
pub const SECTION_TET_MESH: u32 = 2;
/// Bytes of one probe's SH data (9 + 27 f32).
pub const PROBE_SH_LEN: usize = (SH_COEFFS + 3 * SH_COEFFS) * 4;
/// Bytes of a grid-tile section.
pub const GRID_TILE_LEN: usize =
    16 + 4 * TILE_COLUMNS + PROBE_SH_LEN * TILE_PROBE_COUNT + TILE_PROBE_COUNT;
/// Bytes of a tetrahedral-mesh section's fixed part (id, tetrahedron count).
pub const TET_MESH_FIXED_LEN: usize = 8;

/// Bytes of a tetrahedral-mesh section with `probes` probes and `tets` tetrahedra.
pub fn tet_mesh_len(probes: usize, tets: usize) -> usize {
    TET_MESH_FIXED_LEN + probes * (12 + PROBE_SH_LEN + 1) + tets * 32
}

/// Encodes a bake after validating it; the result ends with its CRC-32.
pub fn encode(bake: &Bake) -> Result<Vec<u8>, Problem> {
    validate(bake)?;
    let sections = bake.tiles.len() + bake.meshes.len();
    let table_end = HEADER_LEN + sections * SECTION_ENTRY_LEN;
    let mut entries = Vec::with_capacity(sections);
    let mut offset = table_end;
    for _ in &bake.tiles {
        entries.push((SECTION_GRID_TILE, TILE_PROBE_COUNT, offset, GRID_TILE_LEN));
        offset += GRID_TILE_LEN;
    }
    for mesh in &bake.meshes {
        let len = tet_mesh_len(mesh.positions.len(), mesh.tets.len());
        entries.push((SECTION_TET_MESH, mesh.positions.len(), offset, len));
        offset += len;
    }
    let total = offset + CHECKSUM_LEN;

    let mut out = Vec::with_capacity(total);
    out.extend_from_slice(&MAGIC);
    put_u32(&mut out, FORMAT_VERSION);
    put_u32(&mut out, if bake.complete { FLAG_COMPLETE } else { 0 });
    out.extend_from_slice(&(total as u64).to_le_bytes());
    out.extend_from_slice(&bake.scene.0);
    put_u32(&mut out, bake.settings.rays_per_probe);
    put_f32(&mut out, bake.settings.grid_spacing_m);
    put_f32s(&mut out, &bake.settings.layer_heights_m);
    put_u32(&mut out, count_u32(sections, "sections")?);
    debug_assert_eq!(out.len(), HEADER_LEN);
    for (kind, count, offset, len) in entries {
        put_u32(&mut out, kind);
        put_u32(&mut out, count_u32(count, "probes in a mesh")?);
        out.extend_from_slice(&(offset as u64).to_le_bytes());
        out.extend_from_slice(&(len as u64).to_le_bytes());
    }
    for tile in &bake.tiles {
        out.extend_from_slice(&tile.tile[0].to_le_bytes());
        out.extend_from_slice(&tile.tile[1].to_le_bytes());
        put_f32s(&mut out, &tile.origin_xz);
        put_f32s(&mut out, &tile.ground_heights_m);
        put_probes(&mut out, &tile.probes);
        out.extend(tile.interior.iter().map(|&i| i as u8));
    }
    for mesh in &bake.meshes {
        put_u32(&mut out, mesh.id);
        put_u32(
            &mut out,
            count_u32(mesh.tets.len(), "tetrahedra in a mesh")?,
        );
        put_f32s(&mut out, mesh.positions.as_flattened());
        put_probes(&mut out, &mesh.probes);
        for &index in mesh.tets.as_flattened() {
            put_u32(&mut out, index);
        }
        for &index in mesh.adjacency.as_flattened() {
            put_u32(&mut out, index);
        }
        out.extend(mesh.interior.iter().map(|&i| i as u8));
    }
    let crc = crc32fast::hash(&out);
    put_u32(&mut out, crc);
    debug_assert_eq!(out.len(), total);
    Ok(out)
}

/// Decodes and fully validates a bake file's bytes, which must belong to scene `expected`.
/// Complete and incomplete bakes are both returned; check [`Bake::complete`].
pub fn decode(bytes: &[u8], expected: &SceneKey) -> Result<Bake, Problem> {
    let actual = bytes.len() as u64;
    if bytes.len() < HEADER_LEN + CHECKSUM_LEN {
        // Too short even for a header: say "not a bake" when the magic is already wrong.
        if bytes.len() >= MAGIC.len() && bytes[..MAGIC.len()] != MAGIC {
            return Err(bad_magic(bytes));
        }
        return Err(Problem::Truncated {
            expected: (HEADER_LEN + CHECKSUM_LEN) as u64,
            actual,
        });
    }
    if bytes[..MAGIC.len()] != MAGIC {
        return Err(bad_magic(bytes));
    }
    let mut header = Reader::new(&bytes[MAGIC.len()..HEADER_LEN]);
    let version = header.u32()?;
    if version != FORMAT_VERSION {
        return Err(Problem::UnsupportedVersion {
            found: version,
            supported: FORMAT_VERSION,
        });
    }
    let flags = header.u32()?;
    let total = header.u64()?;
    if actual < total {
        return Err(Problem::Truncated {
            expected: total,
            actual,
        });
    }
    if actual > total {
        return Err(Problem::TrailingBytes {
            expected: total,
            actual,
        });
    }
    let body = &bytes[..bytes.len() - CHECKSUM_LEN];
    let stored = u32::from_le_bytes(take4(&bytes[body.len()..]));
    let computed = crc32fast::hash(body);
    if stored != computed {
        return Err(Problem::ChecksumMismatch { stored, computed });
    }
    if flags & !FLAG_COMPLETE != 0 {
        return Err(Problem::UnknownFlags(flags & !FLAG_COMPLETE));
    }
    let scene = SceneKey(header.array()?);
    if scene != *expected {
        return Err(Problem::OtherScene {
            expected: *expected,
            found: scene,
        });
    }
    let settings = BakeSettings {
        rays_per_probe: header.u32()?,
        grid_spacing_m: header.f32()?,
        layer_heights_m: [header.f32()?, header.f32()?, header.f32()?],
    };
    validate_settings(&settings)?;
    let sections = header.u32()? as usize;

    let table_len = sections
        .checked_mul(SECTION_ENTRY_LEN)
        .filter(|len| HEADER_LEN + len <= body.len())
        .ok_or_else(|| Problem::InconsistentCounts {
            section: 0,
            what: format!("{sections} sections do not fit in {} bytes", body.len()),
        })?;
    let mut table = Reader::new(&body[HEADER_LEN..HEADER_LEN + table_len]);
    let mut bake = Bake {
        scene,
        settings,
        complete: flags & FLAG_COMPLETE != 0,
        tiles: Vec::new(),
        meshes: Vec::new(),
    };
    let mut expected_offset = (HEADER_LEN + table_len) as u64;
    for section in 0..sections {
        let kind = table.u32()?;
        let count = table.u32()? as usize;
        let offset = table.u64()?;
        let len = table.u64()?;
        if offset != expected_offset {
            return Err(Problem::SectionTable {
                section,
                what: format!(
                    "starts at byte {offset}, expected {expected_offset} (sections are back to back)"
                ),
            });
        }
        let end = offset
            .checked_add(len)
            .filter(|&end| end <= body.len() as u64)
            .ok_or_else(|| Problem::InconsistentCounts {
                section,
                what: format!(
                    "{len} bytes from byte {offset} run past the payload's end at {}",
                    body.len()
                ),
            })?;
        let payload = &body[offset as usize..end as usize];
        expected_offset = end;
        match kind {
            SECTION_GRID_TILE => {
                if !bake.meshes.is_empty() {
                    return Err(Problem::SectionTable {
                        section,
                        what: "grid tile after a tetrahedral mesh (tiles come first)".into(),
                    });
                }
                bake.tiles.push(decode_tile(section, count, payload)?);
            }
            SECTION_TET_MESH => bake.meshes.push(decode_mesh(section, count, payload)?),
            other => {
                return Err(Problem::SectionTable {
                    section,
                    what: format!("unknown section kind {other}"),
                });
            }
        }
    }
    if expected_offset != body.len() as u64 {
        return Err(Problem::InconsistentCounts {
            section: sections,
            what: format!(
                "sections end at byte {expected_offset}, the checksum starts at {}",
                body.len()
            ),
        });
    }
    validate(&bake)?;
    Ok(bake)
}

fn decode_tile(section: usize, count: usize, payload: &[u8]) -> Result<GridTile, Problem> {
    if count != TILE_PROBE_COUNT || payload.len() != GRID_TILE_LEN {
        return Err(Problem::InconsistentCounts {
            section,
            what: format!(
                "grid tile of {count} probes in {} bytes, expected {TILE_PROBE_COUNT} in {GRID_TILE_LEN}",
                payload.len()
            ),
        });
    }
    let mut r = Reader::new(payload);
    let tile = [r.i32()?, r.i32()?];
    let origin_xz = [r.f32()?, r.f32()?];
    let ground_heights_m = r.f32s(TILE_COLUMNS)?;
    let probes = r.probes(TILE_PROBE_COUNT)?;
    let interior = r.flags(section, TILE_PROBE_COUNT)?;
    Ok(GridTile {
        tile,
        origin_xz,
        ground_heights_m,
        probes,
        interior,
    })
}

fn decode_mesh(section: usize, count: usize, payload: &[u8]) -> Result<TetMesh, Problem> {
    let mut r = Reader::new(payload);
    let (id, tets) = match (r.u32(), r.u32()) {
        (Ok(id), Ok(tets)) => (id, tets as usize),
        _ => {
            return Err(Problem::InconsistentCounts {
                section,
                what: format!("tetrahedral mesh section of {} bytes", payload.len()),
            });
        }
    };
    // Compared in u128 so that huge counts from a corrupt file cannot overflow.
    let expected = TET_MESH_FIXED_LEN as u128
        + count as u128 * (12 + PROBE_SH_LEN + 1) as u128
        + tets as u128 * 32;
    if expected != payload.len() as u128 {
        return Err(Problem::InconsistentCounts {
            section,
            what: format!(
                "tetrahedral mesh of {count} probes and {tets} tetrahedra needs {expected} bytes, section has {}",
                payload.len()
            ),
        });
    }
    let positions = r.f32s(3 * count)?;
    let probes = r.probes(count)?;
    let tet_indices = r.u32s(4 * tets)?;
    let adjacency = r.u32s(4 * tets)?;
    let interior = r.flags(section, count)?;
    Ok(TetMesh {
        id,
        positions: positions
            .chunks_exact(3)
            .map(|c| [c[0], c[1], c[2]])
            .collect(),
        probes,
        interior,
        tets: quads(&tet_indices),
        adjacency: quads(&adjacency),
    })
}

fn quads(values: &[u32]) -> Vec<[u32; 4]> {
    values
        .chunks_exact(4)
        .map(|c| [c[0], c[1], c[2], c[3]])
        .collect()
}

fn bad_magic(bytes: &[u8]) -> Problem {
    let mut found = [0u8; 8];
    found.copy_from_slice(&bytes[..8]);
    Problem::BadMagic { found }
}

fn take4(bytes: &[u8]) -> [u8; 4] {
    let mut out = [0u8; 4];
    out.copy_from_slice(&bytes[..4]);
    out
}

fn count_u32(count: usize, what: &str) -> Result<u32, Problem> {
    u32::try_from(count).map_err(|_| Problem::InconsistentCounts {
        section: 0,
        what: format!("{count} {what} do not fit the format's 32-bit counts"),
    })
}

fn put_u32(out: &mut Vec<u8>, v: u32) {
    out.extend_from_slice(&v.to_le_bytes());
}

fn put_f32(out: &mut Vec<u8>, v: f32) {
    out.extend_from_slice(&v.to_le_bytes());
}

fn put_f32s(out: &mut Vec<u8>, values: &[f32]) {
    for &v in values {
        put_f32(out, v);
    }
}

fn put_probes(out: &mut Vec<u8>, probes: &[ProbeSh]) {
    for probe in probes {
        put_f32s(out, &probe.sky_visibility);
        put_f32s(out, probe.bounced_sky_visibility.as_flattened());
    }
}

/// Little-endian reads from a slice whose length was checked against the counts beforehand;
/// running short anyway is reported, not a panic.
struct Reader<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl<'a> Reader<'a> {
    fn new(bytes: &'a [u8]) -> Self {
        Self { bytes, at: 0 }
    }

    fn array<const N: usize>(&mut self) -> Result<[u8; N], Problem> {
        let end = self.at.checked_add(N).filter(|&e| e <= self.bytes.len());
        let Some(end) = end else {
            return Err(Problem::InconsistentCounts {
                section: 0,
                what: format!("read past the end of a {}-byte block", self.bytes.len()),
            });
        };
        let mut out = [0u8; N];
        out.copy_from_slice(&self.bytes[self.at..end]);
        self.at = end;
        Ok(out)
    }

    fn u32(&mut self) -> Result<u32, Problem> {
        Ok(u32::from_le_bytes(self.array()?))
    }

    fn i32(&mut self) -> Result<i32, Problem> {
        Ok(i32::from_le_bytes(self.array()?))
    }

    fn u64(&mut self) -> Result<u64, Problem> {
        Ok(u64::from_le_bytes(self.array()?))
    }

    fn f32(&mut self) -> Result<f32, Problem> {
        Ok(f32::from_le_bytes(self.array()?))
    }

    fn f32s(&mut self, n: usize) -> Result<Vec<f32>, Problem> {
        (0..n).map(|_| self.f32()).collect()
    }

    fn u32s(&mut self, n: usize) -> Result<Vec<u32>, Problem> {
        (0..n).map(|_| self.u32()).collect()
    }

    fn probes(&mut self, n: usize) -> Result<Vec<ProbeSh>, Problem> {
        (0..n)
            .map(|_| {
                let mut probe = ProbeSh::default();
                for c in &mut probe.sky_visibility {
                    *c = self.f32()?;
                }
                for c in probe.bounced_sky_visibility.as_flattened_mut() {
                    *c = self.f32()?;
                }
                Ok(probe)
            })
            .collect()
    }

    fn flags(&mut self, section: usize, n: usize) -> Result<Vec<bool>, Problem> {
        (0..n)
            .map(|probe| match self.array::<1>()?[0] {
                0 => Ok(false),
                1 => Ok(true),
                value => Err(Problem::BadInteriorFlag {
                    section,
                    probe,
                    value,
                }),
            })
            .collect()
    }
}
