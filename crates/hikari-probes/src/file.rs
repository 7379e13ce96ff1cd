//! Reading and atomically writing bake files, and the checkpoints that make a bake resumable.

use std::io::Write;
use std::path::{Path, PathBuf};

use crate::error::{BakeFileError, Problem};
use crate::format::{decode, encode};
use crate::model::{Bake, BakeSettings, SceneKey};

/// Reads a complete bake of scene `expected` for rendering: any problem, including an
/// unfinished checkpoint ([`Problem::Incomplete`]), is an error naming the file.
pub fn read_bake(path: &Path, expected: &SceneKey) -> Result<Bake, BakeFileError> {
    let bake = read_any(path, expected)?;
    if !bake.complete {
        return Err(Problem::Incomplete {
            tiles: bake.tiles.len(),
            meshes: bake.meshes.len(),
        }
        .at(path));
    }
    Ok(bake)
}

/// Reads a bake of scene `expected`, complete or not.
pub fn read_any(path: &Path, expected: &SceneKey) -> Result<Bake, BakeFileError> {
    let bytes = std::fs::read(path).map_err(|e| Problem::from_io(&e).at(path))?;
    decode(&bytes, expected).map_err(|p| p.at(path))
}

/// Validates and writes a bake atomically: into a temporary file in the same directory,
/// flushed to disk, then renamed over `path`, so a reader sees the old file or the new one,
/// never a part.
pub fn write_bake(path: &Path, bake: &Bake) -> Result<(), BakeFileError> {
    let bytes = encode(bake).map_err(|p| p.at(path))?;
    write_atomically(path, &bytes).map_err(|e| Problem::Io(e.to_string()).at(path))
}

fn write_atomically(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let name = path.file_name().ok_or_else(|| {
        std::io::Error::new(std::io::ErrorKind::InvalidInput, "path names no file")
    })?;
    // Unique per process and call, so concurrent writers never share a temporary file.
    static WRITES: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
    let call = WRITES.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let mut temp_name = std::ffi::OsString::from(".");
    temp_name.push(name);
    temp_name.push(format!(".tmp{}-{call}", std::process::id()));
    let temp = dir.join(temp_name);
    let result = (|| {
        let mut file = std::fs::File::create(&temp)?;
        file.write_all(bytes)?;
        file.sync_all()?;
        std::fs::rename(&temp, path)
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&temp);
    }
    result
}

/// Where the checkpoints of a bake headed for `path` live: `path` with `.partial` appended.
pub fn partial_path(path: &Path) -> PathBuf {
    let mut name = path.as_os_str().to_os_string();
    name.push(".partial");
    PathBuf::from(name)
}

/// Where a bake starts from: the tiles and meshes of an earlier interrupted run, or nothing.
#[derive(Debug)]
pub struct Resumed {
    /// Incomplete; holds the checkpoint's tiles and meshes when one was usable.
    pub bake: Bake,
    /// Why a checkpoint that exists was not used (corrupt, other scene, other settings, other
    /// format version), for a warning; `None` when there was none or it was used.
    pub discarded: Option<BakeFileError>,
}

/// Starts or resumes the bake headed for `path`: loads `partial_path(path)` when it holds a
/// valid checkpoint of the same scene and settings, else starts empty.
pub fn resume(path: &Path, scene: SceneKey, settings: BakeSettings) -> Resumed {
    let partial = partial_path(path);
    let fresh = Bake::new(scene, settings);
    match read_any(&partial, &scene) {
        Ok(mut bake) if bake.settings == settings => {
            bake.complete = false;
            Resumed {
                bake,
                discarded: None,
            }
        }
        Ok(bake) => Resumed {
            bake: fresh,
            discarded: Some(
                Problem::OtherSettings(format!(
                    "checkpoint has {:?}, this bake uses {:?}",
                    bake.settings, settings
                ))
                .at(&partial),
            ),
        },
        Err(err) if err.problem == Problem::Missing => Resumed {
            bake: fresh,
            discarded: None,
        },
        Err(err) => Resumed {
            bake: fresh,
            discarded: Some(err),
        },
    }
}

/// Saves the tiles and meshes done so far as a checkpoint (atomically, at
/// `partial_path(path)`, marked incomplete). Cost: the whole checkpoint is rewritten, so call
/// it every few seconds of baking, not after every probe.
pub fn save_checkpoint(path: &Path, bake: &Bake) -> Result<(), BakeFileError> {
    let mut checkpoint = bake.clone();
    checkpoint.complete = false;
    write_bake(&partial_path(path), &checkpoint)
}

/// Writes the finished bake to `path` marked complete and removes its checkpoint.
pub fn finish(path: &Path, mut bake: Bake) -> Result<Bake, BakeFileError> {
    bake.complete = true;
    write_bake(path, &bake)?;
    let partial = partial_path(path);
    match std::fs::remove_file(&partial) {
        Ok(()) => Ok(bake),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(bake),
        Err(e) => Err(Problem::Io(e.to_string()).at(partial)),
    }
}
