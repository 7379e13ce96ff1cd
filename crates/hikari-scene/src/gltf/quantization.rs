//! Which component types each vertex attribute may have: core glTF 2.0, widened by
//! KHR_mesh_quantization (docs/gltf.md). Integer data is dequantized by the loader's accessor
//! reader with the spec's formulas (normalized signed byte `max(c / 127, -1)`, unsigned byte
//! `c / 255`, signed short `max(c / 32767, -1)`, unsigned short `c / 65535`; not normalized:
//! the integer's value); the node transform that usually undoes a position quantization is
//! applied like any other.

use gltf::accessor::DataType;

/// The extension's name.
pub const EXTENSION: &str = "KHR_mesh_quantization";

/// The component types an attribute may be stored as.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Storage {
    /// POSITION: float; with KHR_mesh_quantization also (unsigned) byte or short, normalized
    /// or not.
    Position,
    /// NORMAL and TANGENT: float; with KHR_mesh_quantization also normalized byte or short.
    Direction,
    /// TEXCOORD_n: float or normalized unsigned byte or short; with KHR_mesh_quantization also
    /// signed and non-normalized byte or short.
    TexCoord,
    /// COLOR_n and hikari's own scalar attributes: float or normalized unsigned byte or
    /// short, as core glTF has it for colours; KHR_mesh_quantization does not widen them.
    Unorm,
}

/// How `ty` (normalized or not) may be used for an attribute stored as `storage`: `None` if
/// not at all, `Some(false)` in core glTF, `Some(true)` only through KHR_mesh_quantization.
pub fn allowed(storage: Storage, ty: DataType, normalized: bool) -> Option<bool> {
    use DataType::*;
    let core_unorm = normalized && matches!(ty, U8 | U16);
    match (storage, ty) {
        (_, F32) => Some(false),
        (_, U32) => None,
        (Storage::Position, _) => Some(true),
        (Storage::Direction, I8 | I16) if normalized => Some(true),
        (Storage::Direction, _) => None,
        (Storage::TexCoord, _) => Some(!core_unorm),
        (Storage::Unorm, _) => core_unorm.then_some(false),
    }
}

/// The types `storage` allows, for messages; `quantized`: with KHR_mesh_quantization.
pub fn describe(storage: Storage, quantized: bool) -> &'static str {
    match (storage, quantized) {
        (Storage::Position | Storage::Direction, false) => "float",
        (Storage::Position, true) => {
            "float, byte, unsigned byte, short or unsigned short (normalized or not; KHR_mesh_quantization)"
        }
        (Storage::Direction, true) => "float or normalized byte or short (KHR_mesh_quantization)",
        (Storage::TexCoord, true) => {
            "float, byte, unsigned byte, short or unsigned short (normalized or not; KHR_mesh_quantization)"
        }
        (Storage::TexCoord | Storage::Unorm, _) => "float or normalized u8/u16",
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use DataType::*;

    /// The extension's attribute table, written out: (storage, type, normalized, allowed).
    #[test]
    fn the_table_of_the_extension() {
        let all = [I8, U8, I16, U16, U32, F32];
        for ty in all {
            for norm in [false, true] {
                let float = ty == F32;
                let small = matches!(ty, I8 | U8 | I16 | U16);
                assert_eq!(
                    allowed(Storage::Position, ty, norm).is_some(),
                    float || small
                );
                assert_eq!(
                    allowed(Storage::Direction, ty, norm).is_some(),
                    float || (norm && matches!(ty, I8 | I16))
                );
                assert_eq!(
                    allowed(Storage::TexCoord, ty, norm).is_some(),
                    float || small
                );
                assert_eq!(
                    allowed(Storage::TexCoord, ty, norm) == Some(false),
                    float || (norm && matches!(ty, U8 | U16))
                );
            }
        }
    }
}
