//! F12's file names: `hikari-YYYY-MM-DD_HH-MM-SS.png` (and `.exr`) by the local date and time,
//! with `-2`, `-3`... when that second already has one.

use std::path::{Path, PathBuf};

/// The local date and time now as `YYYY-MM-DD_HH-MM-SS`.
pub fn local_stamp() -> String {
    let now = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_secs()) as libc::time_t;
    // SAFETY: localtime_r writes only into `tm`, which lives on this stack.
    let mut tm: libc::tm = unsafe { std::mem::zeroed() };
    let ok = unsafe { !libc::localtime_r(&now, &mut tm).is_null() };
    if !ok {
        return format!("{now}");
    }
    stamp(
        tm.tm_year + 1900,
        tm.tm_mon + 1,
        tm.tm_mday,
        tm.tm_hour,
        tm.tm_min,
        tm.tm_sec,
    )
}

fn stamp(y: i32, mo: i32, d: i32, h: i32, mi: i32, s: i32) -> String {
    format!("{y:04}-{mo:02}-{d:02}_{h:02}-{mi:02}-{s:02}")
}

/// The PNG path for a screenshot taken at `stamp` in `dir`, not yet taken.
pub fn png_path(dir: &Path, stamp: &str) -> PathBuf {
    let mut n = 1;
    loop {
        let name = if n == 1 {
            format!("hikari-{stamp}.png")
        } else {
            format!("hikari-{stamp}-{n}.png")
        };
        let p = dir.join(name);
        if !p.exists() && !p.with_extension("exr").exists() {
            return p;
        }
        n += 1;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_by_date_and_time_never_overwrite() {
        assert_eq!(stamp(2024, 7, 1, 9, 5, 3), "2024-07-01_09-05-03");
        assert_eq!(local_stamp().len(), "2024-07-01_09-05-03".len());
        let dir = std::env::temp_dir().join(format!("hikari-shot-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let a = png_path(&dir, "x");
        assert_eq!(a.file_name().unwrap(), "hikari-x.png");
        std::fs::write(&a, "").unwrap();
        let b = png_path(&dir, "x");
        assert_eq!(b.file_name().unwrap(), "hikari-x-2.png");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
