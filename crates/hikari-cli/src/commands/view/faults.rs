//! The viewer's fault switch, for tests and for trying its recovery by hand:
//! `HIKARI_VIEW_FAULT=surface-lost@N,oom@change-M` pretends the window's surface was lost at
//! paint N, and that the GPU ran out of memory on the M-th settings change (the frame after
//! it fails as a real out-of-memory would; the viewer goes back to the settings before it).

const VAR: &str = "HIKARI_VIEW_FAULT";

fn parts() -> Vec<String> {
    std::env::var(VAR)
        .unwrap_or_default()
        .split(',')
        .map(|s| s.trim().to_string())
        .filter(|s| !s.is_empty())
        .collect()
}

fn number_after(prefix: &str) -> Option<u64> {
    parts().iter().find_map(|p| {
        let n = p.strip_prefix(prefix)?;
        match n.parse() {
            Ok(n) => Some(n),
            Err(_) => {
                log::warn!("{VAR}: `{p}` is not {prefix}N; ignored");
                None
            }
        }
    })
}

/// The paint at which the surface is taken for lost.
pub fn surface_lost_at() -> Option<u64> {
    number_after("surface-lost@")
}

/// The settings change after which the GPU is taken to have run out of memory.
pub fn oom_on_change() -> Option<u64> {
    number_after("oom@change-")
}
