//! What a new user meets in the first minutes: mistakes refused with a message that says what
//! to do, before the GPU starts; help texts that agree with README's table; the files the
//! commands write by default ignored by git; `./x render` writing where it was called.

mod common;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;

use common::{hikari, text, tmp};

/// The repository's root.
fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// Runs `hikari args` with an adapter name that matches no adapter: a check that comes before
/// the GPU starts fails with its own message; one that comes after would name the adapter.
/// Returns the output, which must be a clean failure.
fn fails_before_the_gpu(args: &[&str]) -> String {
    let o = Command::new(env!("CARGO_BIN_EXE_hikari"))
        .args(args)
        .env("WGPU_ADAPTER_NAME", "no-such-gpu-anywhere")
        .env_remove("HIKARI_PROGRESS")
        .output()
        .expect("run hikari");
    let t = text(&o);
    assert!(!o.status.success(), "{args:?} should fail: {t}");
    assert!(!t.contains("panicked"), "{args:?} panicked: {t}");
    assert!(
        !t.contains("no-such-gpu-anywhere"),
        "{args:?} started the GPU before refusing: {t}"
    );
    t
}

fn assert_says(args: &[&str], needles: &[&str]) {
    let t = fails_before_the_gpu(args);
    for n in needles {
        assert!(t.contains(n), "{args:?}: expected `{n}` in: {t}");
    }
}

#[test]
fn an_image_size_of_zero_is_refused_before_the_gpu_starts() {
    let dir = tmp("size");
    let out = dir.join("x.png");
    let o = out.to_str().unwrap();
    assert_says(
        &["render", "--width", "0", "-o", o],
        &["--width 0", "width must be at least 1"],
    );
    assert_says(
        &["render", "--height", "0", "-o", o],
        &["--height 0", "height must be at least 1"],
    );
    let config = dir.join("zero.toml");
    std::fs::write(&config, "width = 0\n").unwrap();
    assert_says(
        &["render", "--config", config.to_str().unwrap(), "-o", o],
        &["`width = 0`", "width must be at least 1"],
    );
    assert_says(
        &["compare", "--width", "0", "-o", o],
        &["width must be at least 1"],
    );
    assert!(!out.exists());
}

#[test]
fn settings_errors_name_the_table_the_key_and_the_type() {
    let t = fails_before_the_gpu(&["render", "--set", "nonexistent.key=1"]);
    assert!(
        t.contains("`nonexistent` is not a settings table") && t.contains("sun_shadows"),
        "{t}"
    );
    assert!(!t.contains("`settings` is ?") && !t.contains("is ?"), "{t}");
    assert_says(
        &["render", "--set", "taa.enabled=maybe"],
        &["`taa.enabled`", "\"maybe\"", "a boolean, true or false"],
    );
    assert_says(
        &["render", "--set", "sun_shadows.cascade=2"],
        &[
            "`sun_shadows.cascade` is not a setting of `sun_shadows`",
            "did you mean `cascades`?",
        ],
    );
    assert_says(
        &["render", "--set", "sunshadows.cascades=2"],
        &["did you mean `sun_shadows`?"],
    );
    assert_says(
        &["render", "--set", "tonemap.lut=3"],
        &["`tonemap.lut` is 3", "a string"],
    );
    let dir = tmp("settings");
    let config = dir.join("typo.toml");
    std::fs::write(&config, "[exposure]\nev10 = 3.0\n").unwrap();
    assert_says(
        &["render", "--config", config.to_str().unwrap()],
        &["`exposure.ev10`", "did you mean `ev100`?"],
    );
}

#[test]
fn a_scene_that_is_a_folder_or_a_misspelling_says_so() {
    let dir = tmp("scene");
    assert_says(
        &["render", "--scene", dir.to_str().unwrap()],
        &["is a folder", ".gltf or .glb"],
    );
    assert_says(
        &["render", "--scene", "vilage"],
        &[
            "unknown scene `vilage`",
            "did you mean `village`?",
            "cutout",
        ],
    );
    assert_says(&["bake", "--scene", "Cornel"], &["did you mean `cornell`?"]);
    let obj = dir.join("model.obj");
    std::fs::write(&obj, "v 0 0 0\n").unwrap();
    assert_says(
        &["render", "--scene", obj.to_str().unwrap()],
        &["glTF", ".gltf or .glb"],
    );
}

/// Every command that writes an image writes it under its own extension or refuses: never PNG
/// bytes under a .jpg name.
#[test]
fn images_are_refused_under_another_formats_name() {
    let dir = tmp("names");
    let p = |name: &str| dir.join(name).to_str().unwrap().to_string();
    let (jpg, png, exr, txt) = (p("x.jpg"), p("x.png"), p("x.exr"), p("x.txt"));
    let noext = p("noext");
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (vec!["render", "-o", &jpg], "ending in .png"),
        (vec!["render", "-o", &noext], "ending in .png"),
        (vec!["render", "-o", &png, "--exr", &png], "ending in .exr"),
        (vec!["compare", "-o", &jpg], "ending in .png"),
        (vec!["compare", "--exr-a", &png], "ending in .exr"),
        (vec!["compare", "--exr-b", &jpg], "ending in .exr"),
        (vec!["view", "--screenshot", &jpg], "ending in .png"),
        (vec!["sky", "-o", &png], "ending in .exr"),
        (
            vec!["lut", "apply", "grade.cube", "in.png", "-o", &jpg],
            "ending in .png",
        ),
        (
            vec!["lut", "extract", "in.png", "-o", &txt],
            "ending in .cube",
        ),
        (vec!["render", "-o", &exr], "ending in .png"),
    ];
    for (args, needle) in &cases {
        assert_says(args, &[needle]);
    }
    let written: Vec<_> = std::fs::read_dir(&dir).unwrap().collect();
    assert!(written.is_empty(), "something was written: {written:?}");
}

/// `hikari <command> --help`.
fn help(command: &[&str]) -> String {
    let mut args = command.to_vec();
    args.push("--help");
    let o = hikari(&args);
    assert!(o.status.success(), "{command:?} --help: {}", text(&o));
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// Every command, as its words after `hikari`.
fn commands() -> Vec<Vec<String>> {
    let top = help(&[]);
    let mut out = Vec::new();
    let names = |h: &str| -> Vec<String> {
        h.split("Commands:")
            .nth(1)
            .unwrap_or("")
            .split("Options:")
            .next()
            .unwrap_or("")
            .lines()
            .filter_map(|l| l.split_whitespace().next())
            .filter(|w| *w != "help")
            .map(String::from)
            .collect()
    };
    for name in names(&top) {
        let sub = help(&[&name]);
        if sub.contains("Commands:") {
            for inner in names(&sub) {
                out.push(vec![name.clone(), inner]);
            }
        } else {
            out.push(vec![name]);
        }
    }
    out
}

/// Each option of a help text by its long name (`--width`, `--output`) with its text, up to
/// the next option; the text starts with the short name where there is one (`-o, --output`).
fn options(help: &str) -> BTreeMap<String, String> {
    let mut out = BTreeMap::new();
    let mut current: Option<String> = None;
    let section = help.split("Options:").nth(1).unwrap_or("");
    for line in section.lines() {
        let l = line.trim_start();
        // Options start at most 6 columns in; a value's list (`- auto: ...`) further.
        if l.starts_with('-') && line.len() - l.len() <= 6 {
            let flag = l
                .split([' ', ',', '<', '['])
                .find(|w| w.starts_with("--"))
                .unwrap_or_else(|| panic!("an option without a long name: {l}"))
                .to_string();
            out.insert(flag.clone(), l.to_string());
            current = Some(flag);
        } else if let Some(f) = &current {
            let text = out.get_mut(f).unwrap();
            text.push(' ');
            text.push_str(l);
        }
    }
    out.remove("--help");
    out.remove("--version");
    out
}

/// The option `flag` names (`-o` or `--output`) in `offered`: its long name and text.
fn find<'a>(offered: &'a BTreeMap<String, String>, flag: &str) -> Option<(&'a String, &'a String)> {
    if flag.starts_with("--") {
        return offered.get_key_value(flag);
    }
    offered
        .iter()
        .find(|(_, t)| t.starts_with(&format!("{flag},")))
}

#[test]
fn every_scene_flag_names_every_built_in_scene() {
    let mut seen = 0;
    for command in commands() {
        let c: Vec<&str> = command.iter().map(String::as_str).collect();
        let h = help(&c);
        if let Some(scene) = options(&h).get("--scene") {
            seen += 1;
            for name in hikari_scene::builtin::NAMES {
                assert!(scene.contains(name), "{c:?} --scene lacks {name}: {scene}");
            }
        }
    }
    assert!(seen >= 8, "only {seen} commands take --scene");
}

#[test]
fn commands_offer_only_flags_that_do_something_and_say_what_they_print() {
    let sky = options(&help(&["sky"]));
    for f in ["--no-sun", "--no-sky", "--scene", "--camera"] {
        assert!(!sky.contains_key(f), "sky offers {f}");
    }
    let probes_help = help(&["probes"]);
    let probes = options(&probes_help);
    for f in [
        "--width",
        "--height",
        "--camera",
        "--ev100",
        "--white",
        "--no-dither",
        "--no-sun",
    ] {
        assert!(!probes.contains_key(f), "probes offers {f}");
    }
    for f in ["--scene", "--bake", "--at", "--time", "--set", "--json"] {
        assert!(probes.contains_key(f), "probes lacks {f}");
    }
    assert!(
        probes_help.contains("Count a scene's baked probes") && probes_help.contains("--at"),
        "{probes_help}"
    );
    let timelapse = options(&help(&["timelapse"]));
    assert!(!timelapse.contains_key("--time"), "timelapse offers --time");
    assert!(timelapse.contains_key("--from") && timelapse.contains_key("--date"));
    assert_says(
        &[
            "timelapse",
            "--from",
            "6:00",
            "--to",
            "7:00",
            "--count",
            "2",
            "--time",
            "6:00",
        ],
        &["--time 6:00", "--from"],
    );
    let bench = options(&help(&["bench", "probes"]));
    assert!(bench["--width"].contains("[default: 3840]"), "{bench:?}");
    assert!(bench["--height"].contains("[default: 2160]"), "{bench:?}");
    let info = help(&["info"]);
    assert!(info.contains("can run hikari"), "{info}");
}

/// The rows of README's command table: each command's words and the signature in its first
/// cell (a row may hold two commands: `hikari lut extract ...` / `hikari lut apply ...`).
fn readme_rows() -> Vec<(Vec<String>, String)> {
    let readme = std::fs::read_to_string(root().join("README.md")).unwrap();
    let mut rows = Vec::new();
    for line in readme.lines().filter(|l| l.starts_with("| `hikari ")) {
        let cell = line[2..].split(" | ").next().unwrap().replace("\\|", "|");
        for sig in cell.split("` / `") {
            let sig = sig.trim_matches('`').to_string();
            let words: Vec<String> = sig
                .split_whitespace()
                .skip(1)
                .take_while(|w| {
                    w.starts_with(|c: char| c.is_ascii_lowercase())
                        && w.chars()
                            .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '_')
                })
                .map(String::from)
                .collect();
            rows.push((words, sig));
        }
    }
    rows
}

/// The flags a README signature names: `--name` and `-o`.
fn readme_flags(sig: &str) -> Vec<String> {
    let mut out = Vec::new();
    for w in sig.split(|c: char| c.is_whitespace() || c == '[' || c == ']' || c == '|' || c == '/')
    {
        let w = w.trim_end_matches([',', '.', ')']);
        if (w.starts_with("--") && w.len() > 2) || w == "-o" || w == "-q" {
            out.push(w.to_string());
        }
    }
    out
}

/// `[--flag VALUE]` pairs of a README signature whose value is a default (lowercase letters,
/// digits, dots, no alternatives), e.g. `--width 1280`, `-o hikari.png`.
fn readme_defaults(sig: &str) -> Vec<(String, String)> {
    let mut out = Vec::new();
    for group in sig.split('[').skip(1) {
        let group = group.split(']').next().unwrap_or("");
        let mut words = group.split_whitespace();
        let (Some(flag), Some(value), None) = (words.next(), words.next(), words.next()) else {
            continue;
        };
        let is_default = value
            .chars()
            .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '.' || c == '/')
            && !value.is_empty();
        if flag.starts_with('-') && is_default {
            out.push((flag.to_string(), value.trim_end_matches('/').to_string()));
        }
    }
    out
}

/// README's table and the help texts agree: every command has a row, every flag a row names
/// exists, every flag a command offers is in its row (or in `render`'s, for rows that say
/// "same ... as render"), and every default a row writes (`[--width 1280]`) is the help's.
#[test]
fn the_help_texts_agree_with_readmes_table() {
    let rows = readme_rows();
    let render_sig = rows
        .iter()
        .find(|(w, _)| w == &["render"])
        .map(|(_, s)| s.clone())
        .expect("README has a render row");
    let mut failures = Vec::new();
    let all = commands();
    for (words, _) in &rows {
        if !all.contains(words) {
            failures.push(format!(
                "README names `hikari {}`, which is no command",
                words.join(" ")
            ));
        }
    }
    for command in &all {
        let c: Vec<&str> = command.iter().map(String::as_str).collect();
        let Some((_, sig)) = rows.iter().find(|(w, _)| w == command) else {
            failures.push(format!(
                "README's table has no row for `hikari {}`",
                c.join(" ")
            ));
            continue;
        };
        let offered = options(&help(&c));
        // Each flag the row names, by its long name.
        let long = |sig: &str| -> Vec<String> {
            readme_flags(sig)
                .iter()
                .filter_map(|f| find(&offered, f).map(|(l, _)| l.clone()))
                .collect()
        };
        for f in readme_flags(sig) {
            if find(&offered, &f).is_none() {
                failures.push(format!("README: `hikari {}` has no {f}", c.join(" ")));
            }
        }
        let named = long(sig);
        let render_named = long(&render_sig);
        let as_render = sig.contains("as render");
        for f in offered.keys() {
            if !(named.contains(f) || (as_render && render_named.contains(f))) {
                failures.push(format!(
                    "README's row for `hikari {}` lacks {f}",
                    c.join(" ")
                ));
            }
        }
        for (flag, value) in readme_defaults(sig) {
            let Some((_, text)) = find(&offered, &flag) else {
                continue;
            };
            let said = text.split("[default: ").nth(1).map(|d| {
                d.split([']', ';'])
                    .next()
                    .unwrap_or("")
                    .trim_end_matches('/')
            });
            if said != Some(value.as_str()) {
                failures.push(format!(
                    "`hikari {}`: README's default for {flag} is {value}, the help's {said:?}",
                    c.join(" ")
                ));
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// What the commands write where they run, by default, is ignored by git wherever in the
/// repository they run: the default names as the help texts give them.
#[test]
fn the_repositorys_gitignore_covers_what_the_commands_write_by_default() {
    let default_of = |c: &[&str]| -> String {
        let o = options(&help(c));
        let t = &o["--output"];
        t.split("[default: ")
            .nth(1)
            .and_then(|d| d.split(']').next())
            .unwrap_or_else(|| panic!("{c:?}: no default output: {t}"))
            .to_string()
    };
    let png = default_of(&["render"]);
    let mut names = vec![
        png.clone(),
        Path::new(&png).with_extension("exr").display().to_string(),
        default_of(&["compare"]),
        default_of(&["sky"]),
        format!("{}/frame_0000.png", default_of(&["timelapse"])),
        // `hikari view`'s F12 screenshots.
        "hikari-2024-07-21_12-00-00.png".into(),
        "hikari-2024-07-21_12-00-00-2.exr".into(),
    ];
    assert_eq!(names.len(), 7);
    names.extend(names.clone().iter().map(|n| format!("docs/{n}")));
    for name in &names {
        let o = Command::new("git")
            .args(["check-ignore", "--no-index", "-q", name])
            .current_dir(root())
            .output()
            .expect("git runs");
        assert!(
            o.status.code() == Some(0),
            "{name} is not ignored by .gitignore: {}",
            text(&o)
        );
    }
    // Nothing the repository holds is ignored by those patterns.
    let o = Command::new("git")
        .args(["ls-files", "-ci", "--exclude-standard"])
        .current_dir(root())
        .output()
        .expect("git runs");
    assert!(o.stdout.is_empty(), "tracked but ignored: {}", text(&o));
}

/// `./x render` runs `hikari render` in the folder it was called from (its files land there,
/// relative paths mean what the caller meant), with the options as given. `CARGO` stands in
/// for cargo, recording where and how it was run.
#[test]
fn x_render_runs_in_the_callers_folder() {
    let dir = tmp("x-render");
    let here = dir.join("my renders");
    std::fs::create_dir_all(&here).unwrap();
    let log = dir.join("cargo.log");
    let fake = dir.join("fake-cargo");
    std::fs::write(
        &fake,
        format!(
            "#!/bin/sh\npwd > '{}'\nfor a in \"$@\"; do echo \"$a\" >> '{}'; done\n",
            log.display(),
            log.display()
        ),
    )
    .unwrap();
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        std::fs::set_permissions(&fake, std::fs::Permissions::from_mode(0o755)).unwrap();
    }
    let x = root().join("x").canonicalize().unwrap();
    let o = Command::new("bash")
        .arg(&x)
        .args(["render", "--width", "64", "-o", "a b.png"])
        .current_dir(&here)
        .env("CARGO", &fake)
        .output()
        .expect("run ./x");
    assert!(o.status.success(), "{}", text(&o));
    let logged = std::fs::read_to_string(&log).unwrap();
    let lines: Vec<&str> = logged.lines().collect();
    assert_eq!(
        Path::new(lines[0]).canonicalize().unwrap(),
        here.canonicalize().unwrap(),
        "./x render ran in {} instead of the caller's folder",
        lines[0]
    );
    let manifest = root().join("Cargo.toml").canonicalize().unwrap();
    let args = &lines[1..];
    let at = args
        .iter()
        .position(|a| *a == "--manifest-path")
        .expect(&logged);
    assert_eq!(Path::new(args[at + 1]).canonicalize().unwrap(), manifest);
    let tail: Vec<&str> = args.iter().skip_while(|a| **a != "--").copied().collect();
    assert_eq!(
        tail,
        ["--", "render", "--width", "64", "-o", "a b.png"],
        "{logged}"
    );
}

/// `hikari info` says whether hikari can run on the adapter.
#[test]
fn info_says_whether_hikari_can_run_here() {
    let o = hikari(&["info"]);
    let t = text(&o);
    assert!(o.status.success(), "{t}");
    assert!(
        t.contains("hikari:   can run on this adapter (64-bit integer atomics present)"),
        "{t}"
    );
}
