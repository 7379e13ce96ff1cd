//! The bytes a pass moves at least: every texture level and buffer it binds, read once if it
//! reads it and written once if it writes it. A pass that reads only part of a resource (a
//! tile, a cascade) is counted as reading all of it, so the floor this gives is an upper bound
//! of the true floor; for full-screen passes, which touch every texel, it is close. With the
//! adapter's bandwidth (`hikari bench frame` measures it with a copy) it gives each pass's
//! memory floor: the time below which it cannot run.

use super::{Binding, VirtualBuffer, VirtualTexture};
use crate::pipeline::{BindingKind, PipelineInfo};

/// What one pass reads and writes, bytes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Traffic {
    pub read: u64,
    pub written: u64,
}

impl Traffic {
    pub fn total(&self) -> u64 {
        self.read + self.written
    }
}

/// Bytes of mip `level` of `v` (all its layers).
fn level_bytes(v: &VirtualTexture, level: u32) -> u64 {
    let d = &v.desc;
    let [w, h, layers] = d.size;
    let (w, h) = ((w >> level).max(1), (h >> level).max(1));
    let (bw, bh) = d.format.block_dimensions();
    let block = u64::from(d.format.block_copy_size(None).unwrap_or(4));
    u64::from(w.div_ceil(bw)) * u64::from(h.div_ceil(bh)) * u64::from(layers.max(1)) * block
}

/// The traffic of a pass of `info` with these bindings (group 0, then its sets).
pub(crate) fn of_pass(
    info: &PipelineInfo,
    bindings: &[Binding],
    set_bindings: &[Vec<Binding>],
    textures: &[VirtualTexture],
    buffers: &[VirtualBuffer],
) -> Traffic {
    let mut t = Traffic::default();
    for (slot, b) in super::bound_slots(info, bindings, set_bindings) {
        match (*b, &slot.kind) {
            (Binding::Texture(tex, level), BindingKind::SampledTexture { .. }) => {
                t.read += level_bytes(&textures[tex.0 as usize], level.unwrap_or(0));
            }
            (Binding::Texture(tex, level), BindingKind::StorageTexture { access, .. }) => {
                let bytes = level_bytes(&textures[tex.0 as usize], level.unwrap_or(0));
                if *access != wgpu::StorageTextureAccess::WriteOnly {
                    t.read += bytes;
                }
                if *access != wgpu::StorageTextureAccess::ReadOnly {
                    t.written += bytes;
                }
            }
            (Binding::Buffer(buf), BindingKind::Storage { read_only }) => {
                let bytes = buffers[buf.0 as usize].size;
                // A read-write buffer is mostly an output (or counters): written once.
                if *read_only {
                    t.read += bytes;
                } else {
                    t.written += bytes;
                }
            }
            _ => {}
        }
    }
    t
}
