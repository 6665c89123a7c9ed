//! `texgeo view` under a real X server (Xvfb, started here and stopped at the end) on
//! lavapipe's X11 surface, validation on under tools/test: screenshots equal offscreen
//! pictures, live levels equal `subdivide`, resize / unmap / map / close driven by real X
//! input (xdotool) and by scripts leave no validation message and no leak; without a
//! display the viewer says so and exits 2. No X server is a failure, not a skip.

use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::time::{Duration, Instant};

use texgeo::mesh::formats;
use texgeo::render::Picture;

const BIN: &str = env!("CARGO_BIN_EXE_texgeo");

/// A private X server: `Xvfb -displayfd` picks a free display number itself, so tests
/// running at the same time never collide. Killed (by its pid) on drop.
struct Xvfb {
    child: Child,
    display: String,
}

impl Xvfb {
    fn start() -> Xvfb {
        let mut child = Command::new("Xvfb")
            // -noreset: without it the server resets whenever its last client leaves, and a
            // client connecting during the reset is refused. -r: no auto-repeat, so a key whose
            // release is late on a loaded machine is still one key press (one level, not two).
            .args(["-displayfd", "1", "-screen", "0", "1024x768x24", "-nolisten", "tcp", "-noreset", "-r"])
            .stdout(Stdio::piped())
            .stderr(Stdio::null())
            .spawn()
            .expect("cannot start Xvfb (tools/setup installs Debian's xvfb); the viewer tests need a real X server");
        let mut line = String::new();
        let stdout = child.stdout.take().expect("piped stdout");
        BufReader::new(stdout).read_line(&mut line).expect("read Xvfb's display number");
        let n: u32 = match line.trim().parse() {
            Ok(n) => n,
            Err(_) => {
                let _ = child.kill();
                panic!("Xvfb did not report a display number (got {line:?})");
            }
        };
        Xvfb { child, display: format!(":{n}") }
    }
}

impl Drop for Xvfb {
    fn drop(&mut self) {
        // SIGTERM first, so the server removes its socket and lock file.
        let _ = Command::new("kill").arg(self.child.id().to_string()).status();
        let start = Instant::now();
        while self.child.try_wait().ok().flatten().is_none() && start.elapsed() < Duration::from_secs(5) {
            std::thread::sleep(Duration::from_millis(20));
        }
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

fn temp(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("texgeo-view-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Runs `texgeo` to completion within `limit`, killing it past the limit (a failure).
fn run_with_limit(mut cmd: Command, limit: Duration) -> Output {
    let mut child = cmd.stdout(Stdio::piped()).stderr(Stdio::piped()).spawn().expect("run texgeo");
    let start = Instant::now();
    loop {
        if child.try_wait().unwrap().is_some() {
            return child.wait_with_output().unwrap();
        }
        if start.elapsed() > limit {
            let _ = child.kill();
            let out = child.wait_with_output().unwrap();
            panic!(
                "texgeo did not finish within {limit:?}\nstdout: {}\nstderr: {}",
                String::from_utf8_lossy(&out.stdout),
                String::from_utf8_lossy(&out.stderr)
            );
        }
        std::thread::sleep(Duration::from_millis(50));
    }
}

fn view(x: &Xvfb, args: &[&str], dir: &Path) -> Output {
    let mut cmd = Command::new(BIN);
    cmd.arg("view").args(args).env("DISPLAY", &x.display).env_remove("WAYLAND_DISPLAY").current_dir(dir);
    run_with_limit(cmd, Duration::from_secs(120))
}

fn texgeo(args: &[&str]) -> Output {
    let mut cmd = Command::new(BIN);
    cmd.args(args);
    run_with_limit(cmd, Duration::from_secs(120))
}

/// Exit 0, and nothing on stderr about validation or leaks.
fn clean(o: &Output, what: &str) -> String {
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{what}: {}\n{err}", o.status);
    let lower = err.to_lowercase();
    assert!(!lower.contains("validation") && !lower.contains("leak"), "{what}: {err}");
    String::from_utf8_lossy(&o.stdout).into_owned()
}

#[test]
fn screenshots_equal_offscreen_pictures() {
    let x = Xvfb::start();
    let dir = temp("equal");
    let binvox = dir.join("knot.binvox");
    clean(&texgeo(&["voxelize", "builtin:knot", "--res", "32", "-o", binvox.to_str().unwrap()]), "voxelize");
    for (name, model) in [
        ("binvox", vec![binvox.to_str().unwrap()]),
        ("two meshes", vec!["builtin:torus", "builtin:sphere", "--wireframe"]),
        ("knot", vec!["builtin:knot", "--wireframe"]),
        ("voxels", vec!["builtin:torus", "--voxels", "--res", "24", "--aspect", "perlin"]),
        ("valence", vec!["builtin:cube", "--level", "2", "--valence", "--shading", "smooth", "--yaw", "-60"]),
        ("boolean", vec!["builtin:torus", "--boolean", "builtin:knot", "--op", "intersection"]),
    ] {
        let shot = dir.join(format!("{name}-view.png"));
        let picture = dir.join(format!("{name}-render.png"));
        let mut args = model.clone();
        args.extend(["--size", "320x240", "--frames", "3", "--screenshot", shot.to_str().unwrap()]);
        clean(&view(&x, &args, &dir), name);
        let mut args = vec!["render"];
        args.extend(&model);
        args.extend(["--size", "320x240", "-o", picture.to_str().unwrap()]);
        clean(&texgeo(&args), name);
        let (a, b) = (Picture::load_png(&shot).unwrap(), Picture::load_png(&picture).unwrap());
        assert_eq!((a.width, a.height), (320, 240), "{name}: the window's size");
        // The window shows the offscreen picture copied onto the swapchain image; allow one
        // level of rounding per channel should a driver convert on the way.
        assert_eq!(a.pixels_differing(&b, 1), Some(0), "{name}: screenshot vs texgeo render");
        assert!(
            a.rgba.chunks_exact(4).filter(|p| p[..3] != [24, 26, 32]).count() > 5000,
            "{name}: empty picture"
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn live_levels_equal_subdivide() {
    let x = Xvfb::start();
    let dir = temp("levels");
    let shown = dir.join("shown.obj");
    let reference = dir.join("reference.obj");
    for (start, script, level) in [("1", "+,+", "3"), ("3", "-,-,+", "2")] {
        let o = view(
            &x,
            &[
                "builtin:knot",
                "--level",
                start,
                "--script",
                script,
                "--frames",
                "1",
                "--save-mesh",
                shown.to_str().unwrap(),
            ],
            &dir,
        );
        let out = clean(&o, script);
        assert!(out.contains(&format!("level {level}: ")), "{out}");
        clean(
            &texgeo(&["subdivide", "builtin:knot", "-l", level, "-o", reference.to_str().unwrap()]),
            "subdivide",
        );
        let (a, b) = (formats::read(&shown).unwrap(), formats::read(&reference).unwrap());
        assert_eq!(a.num_faces(), b.num_faces());
        assert_eq!(a.positions(), b.positions(), "level {level} on screen vs texgeo subdivide");
        assert!(a.faces().eq(b.faces()));
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn scripted_resize_hide_show_and_minimize() {
    let x = Xvfb::start();
    let dir = temp("script");
    let shot = dir.join("last.png");
    let script = "size:400x300,wait:4,hide,wait:3,show,wait:3,minimize,wait:2,restore,size:200x150,wait:4,orbit:30:10,zoom:0.8,pan:0.05:0,w,f,v,s";
    let o = view(
        &x,
        &[
            "builtin:cube",
            "--level",
            "2",
            "--size",
            "300x200",
            "--script",
            script,
            "--frames",
            "2",
            "--screenshot",
            shot.to_str().unwrap(),
        ],
        &dir,
    );
    let out = clean(&o, "script");
    assert!(out.contains("wrote texgeo-view-001.png"), "{out}");
    let p = Picture::load_png(&shot).unwrap();
    assert_eq!((p.width, p.height), (200, 150), "the last resize took effect");
    assert!(dir.join("texgeo-view-001.png").exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Polls `f` every 50 ms until it returns Some or `limit` passes.
fn wait_for<T>(limit: Duration, what: &str, mut f: impl FnMut() -> Option<T>) -> T {
    let start = Instant::now();
    loop {
        if let Some(v) = f() {
            return v;
        }
        if start.elapsed() > limit {
            let dir = temp("xdotool");
            let read = |n: &str| std::fs::read_to_string(dir.join(n)).unwrap_or_default();
            panic!(
                "timed out waiting for {what}\nviewer stdout: {}\nviewer stderr: {}",
                read("stdout.txt"),
                read("stderr.txt")
            );
        }
        std::thread::sleep(Duration::from_millis(50));
    }
}

#[test]
fn real_x_input_resizes_orbits_unmaps_and_closes() {
    let x = Xvfb::start();
    let dir = temp("xdotool");
    let (out_path, err_path) = (dir.join("stdout.txt"), dir.join("stderr.txt"));
    let mut viewer = Command::new(BIN)
        .args(["view", "builtin:cube", "--size", "300x200"])
        .env("DISPLAY", &x.display)
        .env_remove("WAYLAND_DISPLAY")
        .current_dir(&dir)
        .stdout(std::fs::File::create(&out_path).unwrap())
        .stderr(std::fs::File::create(&err_path).unwrap())
        .spawn()
        .unwrap();
    let xdo = |args: &[&str]| {
        let o = Command::new("xdotool")
            .args(args)
            .env("DISPLAY", &x.display)
            .output()
            .expect("cannot run xdotool (tools/setup installs it)");
        String::from_utf8_lossy(&o.stdout).trim().to_string()
    };
    let stdout = || std::fs::read_to_string(&out_path).unwrap_or_default();
    let limit = Duration::from_secs(60);
    let wid = wait_for(limit, "the viewer's window", || {
        let w = xdo(&["search", "--name", "texgeo view"]);
        (!w.is_empty()).then(|| w.lines().next().unwrap_or_default().to_string())
    });
    // The title gets its counts and fps once a frame was presented: the window is mapped.
    wait_for(limit, "the first frame", || xdo(&["getwindowname", &wid]).contains("fps").then_some(()));
    xdo(&["windowsize", &wid, "500", "400"]);
    // Keys typed through XTEST go to the focused window.
    let focus = |wid: &str| {
        wait_for(limit, "the window to take the focus", || {
            xdo(&["windowfocus", "--sync", wid]);
            (xdo(&["getwindowfocus"]) == wid).then_some(())
        });
        xdo(&["mousemove", "--window", wid, "100", "100"]);
    };
    focus(&wid);
    // `=` is the unshifted `+`: no modifier for xdotool to press and release around it.
    xdo(&["key", "equal"]);
    wait_for(limit, "level 1", || stdout().contains("level 1: 26 vertices, 24 faces").then_some(()));
    xdo(&["key", "equal"]);
    wait_for(limit, "level 2", || stdout().contains("level 2: 98 vertices, 96 faces").then_some(()));
    let title = wait_for(limit, "the title to show level 2", || {
        let t = xdo(&["getwindowname", &wid]);
        t.contains("level 2").then_some(t)
    });
    assert!(title.contains("98 vertices, 96 faces") && title.contains("fps"), "{title}");
    xdo(&["mousedown", "1", "mousemove_relative", "40", "15", "mouseup", "1"]);
    xdo(&["click", "--repeat", "2", "4"]); // wheel: zoom in
    xdo(&["windowunmap", "--sync", &wid]);
    xdo(&["windowmap", "--sync", &wid]);
    focus(&wid);
    xdo(&["key", "s"]);
    wait_for(limit, "the screenshot", || stdout().contains("wrote texgeo-view-001.png").then_some(()));
    xdo(&["key", "q"]);
    let status = wait_for(limit, "the viewer to close", || viewer.try_wait().unwrap());
    let err = std::fs::read_to_string(&err_path).unwrap();
    assert!(status.success(), "{status}: {err}");
    assert!(!err.to_lowercase().contains("validation") && !err.to_lowercase().contains("leak"), "{err}");
    let p = Picture::load_png(dir.join("texgeo-view-001.png")).unwrap();
    assert_eq!((p.width, p.height), (500, 400), "the window was resized to 500×400");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn without_a_display_the_viewer_exits_2_and_points_to_pictures() {
    let unused = Xvfb::start(); // only to know a display number nobody listens on after it stops
    let gone = unused.display.clone();
    drop(unused);
    for display in [None, Some(gone.as_str())] {
        let mut cmd = Command::new(BIN);
        cmd.args(["view", "builtin:cube", "--frames", "1"]).env_remove("WAYLAND_DISPLAY");
        match display {
            Some(d) => cmd.env("DISPLAY", d),
            None => cmd.env_remove("DISPLAY"),
        };
        let o = run_with_limit(cmd, Duration::from_secs(60));
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{display:?}: {err}");
        assert!(err.starts_with("texgeo: error: no display"), "{err}");
        assert!(err.contains("texgeo render") && err.contains("texgeo reproduce"), "{err}");
        assert_eq!(err.trim_end().lines().count(), 1, "one message: {err}");
    }
}

#[test]
fn every_script_step_takes_effect_in_first_position() {
    let x = Xvfb::start();
    let dir = temp("first");
    let size = ["--size", "160x120"];
    // The last of two frames, with `script` from the first frame on.
    let shot = |name: &str, model: &[&str], script: &str| -> (Picture, String) {
        let png = dir.join(format!("{name}.png"));
        let mut args = model.to_vec();
        args.extend(size);
        args.extend(["--frames", "2", "--screenshot", png.to_str().unwrap()]);
        if !script.is_empty() {
            args.extend(["--script", script]);
        }
        let out = clean(&view(&x, &args, &dir), name);
        (Picture::load_png(&png).unwrap(), out)
    };
    let render = |name: &str, model: &[&str]| -> Picture {
        let png = dir.join(format!("{name}-render.png"));
        let mut args = vec!["render"];
        args.extend(model);
        args.extend(size);
        args.extend(["-o", png.to_str().unwrap()]);
        clean(&texgeo(&args), name);
        Picture::load_png(&png).unwrap()
    };
    let same = |a: &Picture, b: &Picture| a.pixels_differing(b, 1) == Some(0);
    // Camera steps before the first frame: the camera they turn is the first one. (An
    // L-shaped prism: no turn by 90° looks the same.)
    let prism = ["builtin:l-prism"];
    let (plain, _) = shot("plain-prism", &prism, "");
    assert!(same(&plain, &render("plain-prism", &prism)));
    let (orbit, _) = shot("orbit", &prism, "orbit:90:0");
    let turned = render("orbit", &["builtin:l-prism", "--yaw", "125"]);
    assert!(orbit.pixels_differing(&turned, 8).is_some_and(|d| d < 100), "orbit:90:0 = --yaw 125");
    assert!(!same(&orbit, &plain), "orbit:90:0 first turns the camera");
    for (name, script, back) in
        [("zoom", "zoom:0.5", "zoom:0.5,zoom:2"), ("pan", "pan:0.2:0", "pan:0.2:0,pan:-0.2:0")]
    {
        let (moved, _) = shot(name, &prism, script);
        assert!(!same(&moved, &plain), "{script} alone changes the picture");
        let (undone, _) = shot(&format!("{name}-back"), &prism, back);
        assert!(undone.pixels_differing(&plain, 8).is_some_and(|d| d < 100), "{back} comes back");
    }
    let cube = ["builtin:cube"];
    let (plain, _) = shot("plain", &cube, "");
    // Keys first: the same picture as the option they toggle.
    for (key, option) in [
        ("v", &["--valence"][..]),
        ("w", &["--wireframe"]),
        ("f", &["--shading", "smooth"]),
        ("+", &["--level", "1"]),
    ] {
        let (got, _) = shot(&format!("key-{key}"), &cube, key);
        let mut model = cube.to_vec();
        model.extend(option);
        assert!(same(&got, &render(&format!("key-{key}"), &model)), "'{key}' first = {option:?}");
    }
    let (reset, _) = shot("key-r", &cube, "r");
    assert!(same(&reset, &plain), "'r' first keeps the initial view");
    let (saved, out) = shot("key-s", &cube, "s");
    assert!(out.contains("wrote texgeo-view-001.png"), "{out}");
    assert!(same(&Picture::load_png(dir.join("texgeo-view-001.png")).unwrap(), &saved));
    let voxels = ["builtin:cube", "--voxels", "--res", "8", "--aspect", "perlin"];
    let (aspect, _) = shot("aspect", &voxels, "");
    let (flat, _) = shot("key-p", &voxels, "p");
    assert!(!same(&aspect, &flat), "'p' first turns the aspect colours off");
    // Window steps first.
    let (resized, _) = shot("size", &cube, "size:200x150,wait:3");
    assert_eq!((resized.width, resized.height), (200, 150));
    for script in ["hide,wait:2,show", "minimize,wait:2,restore", "wait:3"] {
        let (p, _) = shot("window", &cube, script);
        assert!(same(&p, &plain), "{script}");
    }
    // --save-mesh names its file once.
    let saved = dir.join("saved.obj");
    let out = clean(
        &view(&x, &["builtin:cube", "--frames", "1", "--save-mesh", saved.to_str().unwrap()], &dir),
        "save-mesh",
    );
    assert_eq!(out.matches("saved.obj").count(), 1, "{out}");
    std::fs::remove_dir_all(&dir).unwrap();
}
