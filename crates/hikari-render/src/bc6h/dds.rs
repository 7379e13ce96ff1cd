//! DDS files of BC6H_UF16 blocks with the DX10 header (what engines and texture tools read),
//! written atomically.

use std::path::Path;

use crate::error::{RenderError, Result};

/// Writes `blocks` (one mip, one layer) as a `width` x `height` BC6H_UF16 DDS file.
pub fn write(path: &Path, blocks: &[u8], width: u32, height: u32) -> Result<()> {
    let err = |m: String| RenderError::Output {
        path: path.display().to_string(),
        message: m,
    };
    let mut dds = ddsfile::Dds::new_dxgi(ddsfile::NewDxgiParams {
        height,
        width,
        depth: None,
        format: ddsfile::DxgiFormat::BC6H_UF16,
        mipmap_levels: Some(1),
        array_layers: None,
        caps2: None,
        is_cubemap: false,
        resource_dimension: ddsfile::D3D10ResourceDimension::Texture2D,
        alpha_mode: ddsfile::AlphaMode::Unknown,
    })
    .map_err(|e| err(format!("DDS header: {e}")))?;
    if dds.data.len() != blocks.len() {
        return Err(err(format!(
            "{} bytes of blocks for a {width}x{height} BC6H image of {} bytes",
            blocks.len(),
            dds.data.len()
        )));
    }
    dds.data.copy_from_slice(blocks);
    crate::output::write_atomically(path, |tmp| {
        let mut f = std::fs::File::create(tmp).map_err(|e| err(e.to_string()))?;
        dds.write(&mut f).map_err(|e| err(e.to_string()))
    })
}
