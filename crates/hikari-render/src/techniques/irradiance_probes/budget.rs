//! Which probes are relit in a frame: the talk's budget. Every grid tile and mesh on the
//! first frame after a bake is uploaded; afterwards `tiles_per_frame` grid tiles in round robin
//! (the talk: 8x8), the 3x3 tiles around the camera, and one tetrahedral mesh.

use super::gpu_data::ProbeGpuData;
use super::settings::IrradianceProbesSettings;

/// Probes relit by one workgroup of the relight pass.
pub const CHUNK: u32 = 64;

/// The tiles and meshes (indices into [`ProbeGpuData::tiles`] and `meshes`) of one frame.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FrameWork {
    pub tiles: Vec<usize>,
    pub meshes: Vec<usize>,
}

/// The work of relight number `update` (0: the first since the upload) for a camera at
/// `camera_xz` (metres).
pub fn frame_work(
    data: &ProbeGpuData,
    update: u64,
    camera_xz: [f32; 2],
    s: &IrradianceProbesSettings,
) -> FrameWork {
    let (n, m) = (data.tiles.len(), data.meshes.len());
    if update == 0 {
        return FrameWork {
            tiles: (0..n).collect(),
            meshes: (0..m).collect(),
        };
    }
    let mut chosen = vec![false; n];
    if n > 0 {
        let per = (s.tiles_per_frame as usize).clamp(1, n);
        let start = ((update as u128 * per as u128) % n as u128) as usize;
        for k in 0..per {
            chosen[(start + k) % n] = true;
        }
    }
    if s.camera_tiles {
        // The camera's tile and its 8 neighbours: centres within 1.5 tiles along each axis.
        let reach = 1.5 * data.tile_size_m;
        for (t, slot) in data.tiles.iter().enumerate() {
            let dx = (slot.centre_xz[0] - camera_xz[0]).abs();
            let dz = (slot.centre_xz[1] - camera_xz[1]).abs();
            if dx < reach && dz < reach {
                chosen[t] = true;
            }
        }
    }
    FrameWork {
        tiles: (0..n).filter(|&t| chosen[t]).collect(),
        meshes: if m > 0 {
            vec![(update % m as u64) as usize]
        } else {
            Vec::new()
        },
    }
}

/// Frames of round robin that relight every tile and mesh once.
pub fn cycle_frames(data: &ProbeGpuData, s: &IrradianceProbesSettings) -> u32 {
    let tiles = data
        .tiles
        .len()
        .div_ceil((s.tiles_per_frame as usize).max(1));
    tiles.max(data.meshes.len()) as u32
}

/// The work as chunks of at most [`CHUNK`] consecutive probes: `(first probe, count)`.
pub fn chunks(data: &ProbeGpuData, work: &FrameWork) -> Vec<[u32; 2]> {
    let mut out = Vec::new();
    for &t in &work.tiles {
        push_chunks(
            &mut out,
            data.tiles[t].first_probe,
            hikari_probes::TILE_PROBE_COUNT as u32,
        );
    }
    for &m in &work.meshes {
        push_chunks(&mut out, data.meshes[m].first_probe, data.meshes[m].probes);
    }
    out
}

/// Appends the `count` consecutive probes from `first` as chunks of at most [`CHUNK`].
pub fn push_chunks(out: &mut Vec<[u32; 2]>, first: u32, count: u32) {
    let mut at = 0;
    while at < count {
        out.push([first + at, (count - at).min(CHUNK)]);
        at += CHUNK;
    }
}
