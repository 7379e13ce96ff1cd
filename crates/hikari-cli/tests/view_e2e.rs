//! `hikari view` end to end, as a person would use it: the viewer runs under a virtual X
//! server (Xvfb) on the CPU Vulkan driver in a 320x180 window, driven by real X input events
//! (xdotool), and the window is captured (xwd) between them. Holding W moves the view, a
//! right-button drag turns it, `T` (a technique's switch) and `]` (the clock) change the
//! image, `V` shows a debug view and Shift+V goes back, F12 writes a PNG and an EXR, Esc
//! exits with status 0 and `--screenshot` is written. `./x test` installs Xvfb, xdotool and
//! xwd (x11-apps); this test fails, not skips, without them.
//!
//! A fault switch makes the surface lost once and the GPU run out of memory after a settings
//! change: the viewer makes a new surface, goes back to the settings before, and goes on.
//!
//! Also: without a display, `hikari view` says which variables are unset and how to get one.

use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::mpsc::Receiver;
use std::time::{Duration, Instant};

/// A scratch folder for this test process.
fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("hikari-view-test-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

const W: u32 = 320;
const H: u32 = 180;

fn tool(name: &str) -> PathBuf {
    for dir in std::env::var("PATH").unwrap_or_default().split(':') {
        let p = Path::new(dir).join(name);
        if p.is_file() {
            return p;
        }
    }
    panic!(
        "`{name}` is not installed: the viewer's end-to-end test needs Xvfb, xdotool and xwd. \
         `./x setup` installs them (apt-get install xvfb xdotool x11-apps)"
    );
}

/// A virtual X server on a free display number, stopped on drop.
struct Xvfb {
    child: Child,
    display: String,
}

impl Xvfb {
    fn start() -> Xvfb {
        let xvfb = tool("Xvfb");
        for n in 90 + std::process::id() % 50..200 {
            if Path::new(&format!("/tmp/.X11-unix/X{n}")).exists()
                || Path::new(&format!("/tmp/.X{n}-lock")).exists()
            {
                continue;
            }
            let display = format!(":{n}");
            let mut child = Command::new(&xvfb)
                .args([&display, "-screen", "0", "640x480x24", "-nolisten", "tcp"])
                .stdout(Stdio::null())
                .stderr(Stdio::null())
                .spawn()
                .expect("start Xvfb");
            let t = Instant::now();
            while t.elapsed() < Duration::from_secs(10) {
                if Path::new(&format!("/tmp/.X11-unix/X{n}")).exists() {
                    return Xvfb { child, display };
                }
                if child.try_wait().unwrap().is_some() {
                    break;
                }
                std::thread::sleep(Duration::from_millis(50));
            }
            let _ = child.kill();
            let _ = child.wait();
        }
        panic!("could not start Xvfb on any display :90 to :199");
    }
}

impl Drop for Xvfb {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// The viewer, its log lines, killed on drop if still running.
struct Viewer {
    child: Child,
    log: Receiver<String>,
    lines: Vec<String>,
    display: String,
    window: String,
    /// The last frame the viewer logged as shown.
    frame: u64,
}

impl Viewer {
    /// Waits until `n` more frames have been shown (the input before them taken in).
    fn frames(&mut self, n: u64) {
        let want = self.frame + n;
        while self.frame < want {
            self.wait_log(" shown", Duration::from_secs(120));
        }
    }

    fn xdotool(&self, args: &[&str]) {
        let st = Command::new(tool("xdotool"))
            .env("DISPLAY", &self.display)
            .args(args)
            .status()
            .expect("xdotool");
        assert!(st.success(), "xdotool {args:?} failed");
    }

    /// A key pressed and released, through XTEST as a keyboard would (events sent to a
    /// window with `--window` are synthetic, and winit's XInput2 ignores them).
    fn key(&self, key: &str) {
        self.xdotool(&["key", key]);
    }

    /// Waits for a log line containing `what`.
    fn wait_log(&mut self, what: &str, limit: Duration) {
        let t = Instant::now();
        while t.elapsed() < limit {
            if let Ok(l) = self.log.recv_timeout(Duration::from_millis(200)) {
                let found = l.contains(what);
                if let Some(n) = l
                    .split("frame ")
                    .nth(1)
                    .and_then(|r| r.strip_suffix(" shown"))
                    .and_then(|n| n.parse().ok())
                {
                    self.frame = n;
                } else {
                    self.lines.push(l);
                }
                if found {
                    return;
                }
            }
            if let Some(st) = self.child.try_wait().unwrap() {
                panic!("the viewer exited ({st}) early:\n{}", self.lines.join("\n"));
            }
        }
        panic!("no `{what}` after {limit:?}:\n{}", self.lines.join("\n"));
    }

    /// The window as the X server shows it, RGB.
    fn capture(&self) -> Vec<[u8; 3]> {
        let out = Command::new(tool("xwd"))
            .env("DISPLAY", &self.display)
            .args(["-silent", "-id", &self.window])
            .output()
            .expect("xwd");
        assert!(out.status.success(), "xwd failed");
        let (w, h, px) = parse_xwd(&out.stdout);
        assert_eq!((w, h), (W, H), "the window's size");
        px
    }

    /// Frames go by (`n`, for the temporal passes to settle), then captures.
    fn settle_and_capture(&mut self, n: u64) -> Vec<[u8; 3]> {
        self.frames(n);
        self.capture()
    }
}

impl Drop for Viewer {
    fn drop(&mut self) {
        if self.child.try_wait().ok().flatten().is_none() {
            let _ = self.child.kill();
            let _ = self.child.wait();
        }
    }
}

/// An XWD image (ZPixmap, 24 or 32 bits a pixel, true colour) as (width, height, RGB).
fn parse_xwd(b: &[u8]) -> (u32, u32, Vec<[u8; 3]>) {
    let u = |i: usize| u32::from_be_bytes(b[i * 4..i * 4 + 4].try_into().unwrap());
    let (header, width, height) = (u(0) as usize, u(4), u(5));
    let (byte_order, bpp, bpl, ncolors) = (u(7), u(11) as usize, u(12) as usize, u(19) as usize);
    let (rmask, gmask, bmask) = (u(15), u(16), u(17));
    assert!(bpp == 32 || bpp == 24, "xwd: {bpp} bits a pixel");
    let data = &b[header + ncolors * 12..];
    let shift = |m: u32| m.trailing_zeros();
    let mut px = Vec::with_capacity((width * height) as usize);
    for y in 0..height as usize {
        for x in 0..width as usize {
            let o = y * bpl + x * bpp / 8;
            let mut v = [0u8; 4];
            v[..bpp / 8].copy_from_slice(&data[o..o + bpp / 8]);
            let p = if byte_order == 0 {
                u32::from_le_bytes(v)
            } else {
                u32::from_be_bytes(v) >> (32 - bpp)
            };
            let c = |m: u32| ((p & m) >> shift(m)) as u8;
            px.push([c(rmask), c(gmask), c(bmask)]);
        }
    }
    (width, height, px)
}

/// Mean absolute difference of two captures, 0 to 255.
fn diff(a: &[[u8; 3]], b: &[[u8; 3]]) -> f64 {
    let sum: u64 = a
        .iter()
        .zip(b)
        .flat_map(|(p, q)| (0..3).map(move |i| p[i].abs_diff(q[i]) as u64))
        .sum();
    sum as f64 / (a.len() * 3) as f64
}

fn start_viewer(x: &Xvfb, dir: &Path) -> Viewer {
    let mut child = Command::new(env!("CARGO_BIN_EXE_hikari"))
        .current_dir(dir)
        .env("DISPLAY", &x.display)
        .env_remove("WAYLAND_DISPLAY")
        .env("XDG_CACHE_HOME", dir.join("cache"))
        .env("RUST_LOG", "hikari::commands::view=info")
        // The surface is taken for lost at the 8th paint, and the GPU for out of memory after
        // the second settings change: the viewer must make a new surface and go back.
        .env("HIKARI_VIEW_FAULT", "surface-lost@8,oom@change-2")
        .args([
            "view",
            "--scene",
            "boxes",
            "--time",
            "10:00",
            "--preset",
            "low",
            "--width",
            &W.to_string(),
            "--height",
            &H.to_string(),
            "--screenshot",
            "last.png",
            "--print-frames",
        ])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("start hikari view");
    let (tx, rx) = std::sync::mpsc::channel();
    let err = child.stderr.take().unwrap();
    let out = child.stdout.take().unwrap();
    let tx2 = tx.clone();
    std::thread::spawn(move || {
        for l in BufReader::new(err).lines().map_while(Result::ok) {
            let _ = tx.send(l);
        }
    });
    std::thread::spawn(move || {
        for l in BufReader::new(out).lines().map_while(Result::ok) {
            let _ = tx2.send(l);
        }
    });
    let mut v = Viewer {
        child,
        log: rx,
        lines: Vec::new(),
        display: x.display.clone(),
        window: String::new(),
        frame: 0,
    };
    v.wait_log("ready in", Duration::from_secs(240));
    v.frames(1);
    let found = Command::new(tool("xdotool"))
        .env("DISPLAY", &x.display)
        .args(["search", "--name", "hikari view"])
        .output()
        .expect("xdotool search");
    v.window = String::from_utf8_lossy(&found.stdout)
        .lines()
        .next()
        .expect("the viewer's window")
        .trim()
        .to_string();
    // Keyboard focus: there is no window manager to give it.
    v.xdotool(&["windowfocus", "--sync", &v.window]);
    v
}

#[test]
fn the_viewer_is_driven_by_keys_and_mouse_and_exits_on_esc() {
    let x = Xvfb::start();
    let dir = tmp("view-e2e");
    let mut v = start_viewer(&x, &dir);
    let settle = 4;

    // F1 hides the panel: the window shows the frame alone.
    v.key("F1");
    let a = v.settle_and_capture(settle);
    let a2 = v.settle_and_capture(2);
    let noise = diff(&a, &a2);
    let changed = |what: &str, before: &[[u8; 3]], after: &[[u8; 3]], lines: &[String]| {
        let d = diff(before, after);
        eprintln!("{what}: mean difference {d:.2} (a still view: {noise:.2})");
        assert!(
            d > (4.0 * noise).max(2.0),
            "{what} did not change the image: {d:.2} against {noise:.2} still\n{}",
            lines.join("\n")
        );
    };

    // Holding W moves the view.
    v.xdotool(&["keydown", "w"]);
    v.frames(3);
    v.xdotool(&["keyup", "w"]);
    let b = v.settle_and_capture(settle);
    changed("holding W", &a2, &b, &v.lines);

    // Dragging with the right button looks around.
    v.xdotool(&["mousemove", "--window", &v.window, "160", "90"]);
    v.xdotool(&["mousedown", "3"]);
    for _ in 0..6 {
        v.xdotool(&["mousemove_relative", "--", "20", "0"]);
        std::thread::sleep(Duration::from_millis(150));
    }
    v.xdotool(&["mouseup", "3"]);
    let c = v.settle_and_capture(settle);
    changed("a right-button drag", &b, &c, &v.lines);

    // T: ray-traced GI off, a technique's switch.
    let c2 = v.capture();
    v.key("t");
    v.wait_log("ray-traced GI off", Duration::from_secs(30));
    let d = v.settle_and_capture(settle);
    changed("T (ray-traced GI off)", &c2, &d, &v.lines);

    // T again, with the GPU out of memory after it (the fault switch): the viewer goes back
    // to the settings before it, GI off, and goes on.
    v.key("t");
    v.wait_log(
        "went back to the settings before the last change",
        Duration::from_secs(60),
    );
    v.frames(2);
    // Back means GI off: the next T turns it on.
    v.key("t");
    v.wait_log("ray-traced GI on", Duration::from_secs(30));
    v.key("t");
    v.wait_log("ray-traced GI off", Duration::from_secs(30));
    let d = v.settle_and_capture(settle);
    // The surface lost at the 8th paint was made anew, and frames went on.
    if !v
        .lines
        .iter()
        .any(|l| l.contains("surface was lost; made a new one"))
    {
        v.wait_log("surface was lost; made a new one", Duration::from_secs(10));
    }

    // ]: the clock 30 minutes on, four times: the light changes.
    for _ in 0..4 {
        v.key("bracketright");
    }
    let e = v.settle_and_capture(settle);
    changed("] (the clock two hours on)", &d, &e, &v.lines);

    // V: a debug view; Shift+V back to the final image.
    v.key("v");
    let f = v.settle_and_capture(settle);
    changed("V (a debug view)", &e, &f, &v.lines);
    v.key("shift+v");
    let g = v.settle_and_capture(settle);
    changed("Shift+V (back from the debug view)", &f, &g, &v.lines);
    assert!(
        diff(&g, &e) < diff(&f, &e),
        "Shift+V should show the final image again"
    );

    // F12: a PNG and a linear EXR named by date and time.
    v.key("F12");
    let t = Instant::now();
    let shot = loop {
        let pngs: Vec<PathBuf> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| {
                let n = p.file_name().unwrap().to_string_lossy();
                n.starts_with("hikari-20") && n.ends_with(".png")
            })
            .collect();
        if let Some(p) = pngs.first() {
            break p.clone();
        }
        assert!(t.elapsed() < Duration::from_secs(60), "F12 wrote nothing");
        std::thread::sleep(Duration::from_millis(200));
    };
    std::thread::sleep(Duration::from_millis(500));
    assert!(shot.with_extension("exr").is_file(), "F12's EXR");
    let img = image::open(&shot).unwrap();
    assert_eq!((img.width(), img.height()), (W, H));

    // Esc exits with status 0, writing --screenshot.
    v.key("Escape");
    let t = Instant::now();
    let status = loop {
        if let Some(st) = v.child.try_wait().unwrap() {
            break st;
        }
        assert!(t.elapsed() < Duration::from_secs(60), "Esc did not exit");
        std::thread::sleep(Duration::from_millis(100));
    };
    while let Ok(l) = v.log.recv_timeout(Duration::from_millis(200)) {
        v.lines.push(l);
    }
    assert!(
        status.success(),
        "exit status {status}:\n{}",
        v.lines.join("\n")
    );
    let last = image::open(dir.join("last.png")).expect("--screenshot last.png");
    assert_eq!((last.width(), last.height()), (W, H));
}

#[test]
fn without_a_display_the_viewer_says_what_is_missing() {
    let out = Command::new(env!("CARGO_BIN_EXE_hikari"))
        .env_remove("DISPLAY")
        .env_remove("WAYLAND_DISPLAY")
        .args(["view", "--scene", "boxes"])
        .output()
        .expect("run hikari");
    let text = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(!text.contains("panicked"), "{text}");
    assert!(
        text.contains("DISPLAY") && text.contains("WAYLAND_DISPLAY") && text.contains("Xvfb"),
        "{text}"
    );
}
