//! The crate's layering, held by a scan of its sources: a technique imports only techniques
//! that run before it in `frame.rs`, and the modules below the techniques (the scene's GPU
//! side, the lights, the shared twins, the view) import none. The engine below them all is a
//! crate of its own (`hikari-gpu`), so the compiler holds that layer.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

fn src() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("src")
}

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

/// The file's code without its comments (line comments and doc comments).
fn code(path: &Path) -> String {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .map(|l| l.split("//").next().unwrap_or(""))
        .collect::<Vec<_>>()
        .join("\n")
}

fn techniques() -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(src().join("techniques"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.is_dir())
        .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

fn frame_order() -> Vec<String> {
    hikari_render::techniques::FRAME_ORDER
        .map(String::from)
        .to_vec()
}

/// Where `frame.rs` first records technique `t`: `t.<name>` then, past white space and
/// `.as_ref()` / `.unwrap()`, a call of `.record`.
fn recorded_at(frame: &str, t: &str) -> Option<usize> {
    let compact: String = frame.split_whitespace().collect();
    let needle = format!("t.{t}");
    compact.match_indices(&needle).find_map(|(i, _)| {
        let mut rest = &compact[i + needle.len()..];
        while let Some(r) = rest
            .strip_prefix(".as_ref()")
            .or_else(|| rest.strip_prefix(".unwrap()"))
        {
            rest = r;
        }
        rest.starts_with(".record").then_some(i)
    })
}

#[test]
fn frame_rs_records_the_techniques_in_frame_order() {
    let frame = code(&src().join("frame.rs"));
    let order = frame_order();
    let mut techniques = techniques();
    let mut listed = order.clone();
    techniques.sort();
    listed.sort();
    assert_eq!(
        techniques, listed,
        "FRAME_ORDER must list every technique folder once"
    );
    let at: Vec<(String, usize)> = order
        .iter()
        .filter_map(|t| recorded_at(&frame, t).map(|i| (t.clone(), i)))
        .collect();
    assert!(
        at.len() >= 15,
        "frame.rs records too few techniques: {at:?}"
    );
    for pair in at.windows(2) {
        assert!(
            pair[0].1 < pair[1].1,
            "frame.rs records `{}` before `{}`, against FRAME_ORDER",
            pair[1].0,
            pair[0].0
        );
    }
}

/// The techniques `text` names through a path: `techniques::x`, `techniques::{x, y}`, and,
/// in a technique's own files, `super::x` from its `mod.rs` or `super::super::x` below it.
fn named_techniques(text: &str, own_mod_rs: bool, all: &[String]) -> BTreeSet<String> {
    let mut found = BTreeSet::new();
    let mut prefixes = vec!["techniques::".to_string(), "super::super::".to_string()];
    if own_mod_rs {
        prefixes.push("super::".to_string());
    }
    for prefix in &prefixes {
        for (i, _) in text.match_indices(prefix.as_str()) {
            let rest = &text[i + prefix.len()..];
            let names: Vec<&str> = if let Some(group) = rest.strip_prefix('{') {
                let group = &group[..group.find('}').unwrap_or(group.len())];
                group
                    .split(',')
                    .map(|n| n.trim().split("::").next().unwrap_or("").trim())
                    .collect()
            } else {
                vec![
                    rest.split(|c: char| !(c.is_alphanumeric() || c == '_'))
                        .next()
                        .unwrap(),
                ]
            };
            found.extend(
                names
                    .into_iter()
                    .filter(|n| all.iter().any(|t| t == n))
                    .map(String::from),
            );
        }
    }
    found
}

#[test]
fn a_technique_imports_only_techniques_that_run_before_it() {
    let order = frame_order();
    let all = techniques();
    assert!(order.len() > 10);
    let mut violations = Vec::new();
    for (rank, t) in order.iter().enumerate() {
        let mut files = Vec::new();
        rust_files(&src().join("techniques").join(t), &mut files);
        for file in files {
            let own_mod_rs = file.file_name().is_some_and(|n| n == "mod.rs")
                && file.parent().is_some_and(|d| d.ends_with(t));
            for used in named_techniques(&code(&file), own_mod_rs, &all) {
                let used_rank = order.iter().position(|o| *o == used).unwrap();
                if used_rank > rank {
                    violations.push(format!(
                        "{} imports `{used}`, which runs after `{t}`",
                        file.strip_prefix(src()).unwrap().display()
                    ));
                }
            }
        }
    }
    assert!(violations.is_empty(), "{}", violations.join("\n"));
}

#[test]
fn modules_below_the_techniques_import_none() {
    let all = techniques();
    let mut files = Vec::new();
    for dir in ["scene", "lights", "reference", "checks"] {
        rust_files(&src().join(dir), &mut files);
    }
    for file in [
        "view.rs",
        "brdf_tables.rs",
        "output.rs",
        "shader.rs",
        "error.rs",
    ] {
        files.push(src().join(file));
    }
    assert!(files.len() > 15, "the scan found too few files: {files:?}");
    let violations: Vec<String> = files
        .iter()
        .filter_map(|f| {
            let used = named_techniques(&code(f), false, &all);
            (!used.is_empty()).then(|| {
                format!(
                    "{} imports {used:?}",
                    f.strip_prefix(src()).unwrap().display()
                )
            })
        })
        .collect();
    assert!(violations.is_empty(), "{}", violations.join("\n"));
}

#[test]
fn the_scan_sees_an_import() {
    let all = techniques();
    let text = "use crate::techniques::{haze::reference::x, gbuffer};\nuse super::sky::Y;";
    assert_eq!(
        named_techniques(text, true, &all),
        ["gbuffer", "haze", "sky"].map(String::from).into()
    );
    assert_eq!(
        named_techniques(text, false, &all),
        ["gbuffer", "haze"].map(String::from).into()
    );
}

#[test]
fn techniques_keep_no_state_of_their_own() {
    // A technique's state lives in the renderer's frame state (`frame::TechniqueStates`),
    // advanced with a shown frame: no interior mutability and no process-wide statics here.
    let mut files = Vec::new();
    rust_files(&src().join("techniques"), &mut files);
    let forbidden = [
        "Mutex<", "RwLock<", "RefCell<", "Cell<", "Atomic", "static ",
    ];
    let mut found = Vec::new();
    for file in &files {
        for (i, line) in code(file).lines().enumerate() {
            for f in forbidden {
                if line.contains(f) && !line.contains("&'static") && !line.contains("'static str") {
                    found.push(format!(
                        "{}:{}: {}",
                        file.strip_prefix(src()).unwrap().display(),
                        i + 1,
                        line.trim()
                    ));
                }
            }
        }
    }
    assert!(files.len() > 40, "the scan found too few files");
    assert!(found.is_empty(), "{}", found.join("\n"));
}
