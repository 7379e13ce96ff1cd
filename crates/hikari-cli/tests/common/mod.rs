//! What the CLI's test files share: running the binary, a scratch folder, its output as text.

use std::path::PathBuf;
use std::process::{Command, Output};

/// `hikari args`, as a script runs it: stderr is a pipe, so no progress is drawn (whatever
/// `HIKARI_PROGRESS` the test's own environment has).
pub fn hikari(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_hikari"))
        .args(args)
        .env_remove("HIKARI_PROGRESS")
        .output()
        .expect("run hikari")
}

/// A scratch folder for this test process (each test binary has its own process id).
pub fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("hikari-cli-test-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

pub fn text(o: &Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}
