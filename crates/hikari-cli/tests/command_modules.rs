//! Each command stands alone: a module under `src/commands/` may use the shared modules
//! (`crate::args`, `crate::scene_source`, `crate::report`, ...) but never another command's
//! module. What two commands need goes into a shared module instead.

use std::path::{Path, PathBuf};

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// The command a file under `commands/` belongs to (`bench_rays` for
/// `bench_rays/measure.rs`), and how deep below `commands/` it is; `None` for `mod.rs`.
fn owner(commands: &Path, file: &Path) -> Option<(String, usize)> {
    let rel = file.strip_prefix(commands).unwrap();
    let first = rel.components().next()?.as_os_str().to_str()?.to_string();
    if first == "mod.rs" {
        return None;
    }
    let depth = rel.components().count();
    Some((first.trim_end_matches(".rs").to_string(), depth))
}

/// Every reference in `source` to a command module other than `own`: through
/// `crate::commands::`, or through `super::` paths that climb out of the command's own module.
fn foreign_references(source: &str, own: &str, depth: usize, commands: &[String]) -> Vec<String> {
    let code: String = source
        .lines()
        .map(|l| l.split("//").next().unwrap_or(""))
        .collect::<Vec<_>>()
        .join("\n");
    let mut found = Vec::new();
    // `super::` repeated `depth` times reaches `commands` itself: once from `render.rs` or
    // `bench_rays/mod.rs`, twice from `bench_rays/measure.rs`.
    let prefixes = [
        "crate::commands::".to_string(),
        "commands::".to_string(),
        "super::".repeat(depth),
    ];
    for prefix in &prefixes {
        for (at, _) in code.match_indices(prefix.as_str()) {
            // Only a prefix that starts a path (not `super::` inside `super::super::`).
            let before = code[..at].chars().last();
            if before.is_some_and(|c| c == ':' || c.is_alphanumeric() || c == '_') {
                continue;
            }
            let rest = &code[at + prefix.len()..];
            let name: String = rest
                .chars()
                .take_while(|c| c.is_alphanumeric() || *c == '_')
                .collect();
            let is_command = commands.contains(&name);
            // `super::{a, b}` groups name modules too.
            let group = rest.starts_with('{')
                && rest[1..rest.find('}').unwrap_or(rest.len())]
                    .split(',')
                    .map(|n| n.trim().split("::").next().unwrap_or(""))
                    .any(|n| n != own && commands.iter().any(|c| c == n));
            if (is_command && name != own) || group {
                found.push(format!(
                    "{prefix}{}",
                    &rest[..rest.len().min(40)].lines().next().unwrap()
                ));
            }
        }
    }
    found
}

#[test]
fn no_command_module_imports_another() {
    let commands_dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("src/commands");
    let mut files = Vec::new();
    rust_files(&commands_dir, &mut files);
    let mut commands: Vec<String> = files
        .iter()
        .filter_map(|f| owner(&commands_dir, f).map(|(c, _)| c))
        .collect();
    commands.sort();
    commands.dedup();
    // The check sees the real layout, not an empty folder.
    for c in [
        "render",
        "bench_frame",
        "bench_overhead",
        "bench_rays",
        "constants",
        "info",
    ] {
        assert!(
            commands.iter().any(|n| n == c),
            "no command module `{c}` in {commands:?}"
        );
    }
    let mut offenders = Vec::new();
    for file in &files {
        let Some((own, mut depth)) = owner(&commands_dir, file) else {
            continue;
        };
        // A folder's `mod.rs` is the module itself: its `super` is `commands`.
        if file.file_name().is_some_and(|n| n == "mod.rs") {
            depth -= 1;
        }
        let source = std::fs::read_to_string(file).unwrap();
        for r in foreign_references(&source, &own, depth, &commands) {
            offenders.push(format!("{}: {r}", file.display()));
        }
    }
    assert!(
        offenders.is_empty(),
        "command modules importing other commands:\n{}",
        offenders.join("\n")
    );
}

#[test]
fn the_check_catches_each_way_of_reaching_another_command() {
    let commands: Vec<String> = ["render", "bench_frame", "bench_rays"]
        .map(String::from)
        .to_vec();
    let bad = [
        ("use crate::commands::render::RenderArgs;", "bench_frame", 1),
        ("let x = super::render::run(a);", "bench_frame", 1),
        ("use super::{bench_frame, render};", "bench_rays", 1),
        ("use super::super::render::RenderArgs;", "bench_rays", 2),
        ("crate::commands::bench_frame::run(a)", "render", 1),
    ];
    for (line, own, depth) in bad {
        assert!(
            !foreign_references(line, own, depth, &commands).is_empty(),
            "missed `{line}` in {own}"
        );
    }
    let good = [
        ("use crate::report::Stats;", "bench_frame", 1),
        ("use super::measure::Measured;", "bench_rays", 2),
        ("use crate::commands::bench_rays::x;", "bench_rays", 1),
        ("// see super::render::run", "bench_frame", 1),
    ];
    for (line, own, depth) in good {
        assert_eq!(
            foreign_references(line, own, depth, &commands),
            Vec::<String>::new(),
            "`{line}` in {own}"
        );
    }
}
