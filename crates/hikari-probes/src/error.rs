//! What can be wrong with a bake file or a bake about to be written.

use std::path::PathBuf;

use crate::model::SceneKey;

/// A problem with a bake file, naming the file.
#[derive(Debug, thiserror::Error)]
#[error("bake file {}: {problem}", path.display())]
pub struct BakeFileError {
    /// The file read or written (for a checkpoint, the `.partial` file).
    pub path: PathBuf,
    /// What is wrong.
    pub problem: Problem,
}

/// What is wrong with a bake, each kind distinct so callers can choose to rebake (for example
/// on [`Problem::Missing`], [`Problem::OtherScene`] or [`Problem::UnsupportedVersion`]).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Problem {
    /// There is no such file.
    #[error("does not exist")]
    Missing,
    /// Reading, writing or renaming failed.
    #[error("I/O error: {0}")]
    Io(String),
    /// Shorter than its header says (or than a header).
    #[error("truncated: {actual} bytes, expected {expected}")]
    Truncated { expected: u64, actual: u64 },
    /// Longer than its header says.
    #[error("{actual} bytes where the header says {expected}: trailing bytes")]
    TrailingBytes { expected: u64, actual: u64 },
    /// Not a hikari probe bake.
    #[error("not a hikari probe bake (magic bytes {found:02x?})")]
    BadMagic { found: [u8; 8] },
    /// Written by another version of the format.
    #[error("format version {found}, this build reads version {supported}")]
    UnsupportedVersion { found: u32, supported: u32 },
    /// Header flag bits this version does not define.
    #[error("unknown header flags {0:#010x}")]
    UnknownFlags(u32),
    /// The CRC-32 trailer does not match the contents: the file is corrupt.
    #[error("checksum mismatch: stored {stored:#010x}, computed {computed:#010x} (corrupt file)")]
    ChecksumMismatch { stored: u32, computed: u32 },
    /// Baked for different scene content.
    #[error("baked for scene {found}, expected scene {expected}")]
    OtherScene { expected: SceneKey, found: SceneKey },
    /// A checkpoint of an unfinished bake where a complete one is needed.
    #[error("incomplete bake ({tiles} tiles, {meshes} meshes so far)")]
    Incomplete { tiles: usize, meshes: usize },
    /// Recorded with other bake settings than the ones asked for (when resuming).
    #[error("baked with other settings: {0}")]
    OtherSettings(String),
    /// A bake setting is unusable (zero rays, non-positive spacing, ...).
    #[error("invalid bake settings: {0}")]
    InvalidSettings(String),
    /// The section table is malformed (unknown kind, sections not back to back).
    #[error("section {section}: {what}")]
    SectionTable { section: usize, what: String },
    /// Lengths or counts that disagree with each other.
    #[error("section {section}: inconsistent counts: {what}")]
    InconsistentCounts { section: usize, what: String },
    /// An index past the end of what it indexes.
    #[error("section {section}: {what} {element}: index {index} out of range (limit {limit})")]
    IndexOutOfRange {
        section: usize,
        what: &'static str,
        element: usize,
        index: u32,
        limit: usize,
    },
    /// A tetrahedron that repeats a vertex.
    #[error("section {section}: tetrahedron {tet} repeats a vertex {vertices:?}")]
    DegenerateTet {
        section: usize,
        tet: usize,
        vertices: [u32; 4],
    },
    /// Tetrahedron `tet` names `neighbour` as adjacent, but not the other way round (or names
    /// itself).
    #[error(
        "section {section}: tetrahedron {tet} lists {neighbour} as neighbour, which does not list it back"
    )]
    AdjacencyNotMutual {
        section: usize,
        tet: usize,
        neighbour: u32,
    },
    /// NaN or infinity where a finite number must be.
    #[error("section {section}: {what} {element} is not finite")]
    NonFinite {
        section: usize,
        what: &'static str,
        element: usize,
    },
    /// An interior flag byte other than 0 or 1.
    #[error("section {section}: interior flag of probe {probe} is {value}, not 0 or 1")]
    BadInteriorFlag {
        section: usize,
        probe: usize,
        value: u8,
    },
    /// Two tiles with the same tile coordinates.
    #[error("section {section}: tile {tile:?} appears twice")]
    DuplicateTile { section: usize, tile: [i32; 2] },
    /// Two meshes with the same id.
    #[error("section {section}: mesh id {id} appears twice")]
    DuplicateMesh { section: usize, id: u32 },
}

impl Problem {
    /// Attaches the file's path.
    pub fn at(self, path: impl Into<PathBuf>) -> BakeFileError {
        BakeFileError {
            path: path.into(),
            problem: self,
        }
    }

    pub(crate) fn from_io(err: &std::io::Error) -> Self {
        if err.kind() == std::io::ErrorKind::NotFound {
            Problem::Missing
        } else {
            Problem::Io(err.to_string())
        }
    }
}
