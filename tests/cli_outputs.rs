//! Outputs are never half-written: a failed, interrupted or concurrent
//! run leaves the previous good file or one complete new one; output paths are checked
//! before any work; a closed stdout does not stop the `-o` file. The full-disk cases run
//! the binary under `ulimit -f` (with SIGXFSZ ignored, so writes fail with EFBIG instead
//! of killing the process).

mod common;

use std::process::{Command, Stdio};

use common::{TempDir, assert_refused, stderr, stdout, texgeo, texgeo_in_shell};

/// 4 KiB: `ulimit -f 4` in bash (1 KiB blocks); every output below is larger.
const FULL_DISK: &str = "trap '' XFSZ; ulimit -f 4;";

/// Runs one command whose output `out` (a file in `dir`) exceeds the file-size limit:
/// it must fail with status 2 naming `out`, keep the previous contents, and leave no
/// temporary file behind.
fn check_full_disk(dir: &TempDir, out: &str, args: &[&str]) {
    let path = dir.join(out);
    std::fs::write(&path, b"previous good contents").unwrap();
    let before = dir.entries();
    let o = texgeo_in_shell(FULL_DISK, args);
    assert_refused(&o, &[out, "File too large"]);
    assert_eq!(std::fs::read(&path).unwrap(), b"previous good contents", "{args:?}");
    assert_eq!(dir.entries(), before, "{args:?}: temporary files left");
}

#[test]
fn every_writer_fails_cleanly_on_a_full_disk() {
    let dir = TempDir::new("outputs-full");
    for ext in ["obj", "off", "ply", "stl"] {
        let out = format!("knot.{ext}");
        check_full_disk(&dir, &out, &["mesh", "convert", "builtin:knot", &dir.arg(&out)]);
    }
    check_full_disk(
        &dir,
        "sub.obj",
        &["subdivide", "builtin:cube", "-l", "4", "--method", "cpu", "-o", &dir.arg("sub.obj")],
    );
    check_full_disk(
        &dir,
        "classes.txt",
        &["inclusion", "builtin:knot", "--random", "5000", "--method", "bvh", "-o", &dir.arg("classes.txt")],
    );
    check_full_disk(
        &dir,
        "knot.binvox",
        &["voxelize", "builtin:knot", "--res", "96", "--method", "scanline", "-o", &dir.arg("knot.binvox")],
    );
}

#[test]
fn a_full_disk_while_writing_slices_is_one_clean_error() {
    let dir = TempDir::new("outputs-slices");
    let slices = dir.join("slices");
    let o = texgeo_in_shell(
        FULL_DISK,
        &[
            "voxelize",
            "builtin:sphere",
            "--res",
            "200",
            "--method",
            "scanline",
            "-o",
            &dir.arg("s.binvox"),
            "--slices",
            slices.to_str().unwrap(),
        ],
    );
    assert_refused(&o, &["File too large"]);
    // Slices written before the failure are whole PNGs; no temporary file is left.
    for e in std::fs::read_dir(&slices).unwrap() {
        let p = e.unwrap().path();
        assert!(!p.file_name().unwrap().to_string_lossy().starts_with('.'), "{}", p.display());
        image::open(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
    }
}

#[test]
fn output_paths_are_checked_before_any_work() {
    let dir = TempDir::new("outputs-check");
    let missing = dir.arg("no/such/folder/out.binvox");
    let folder = dir.arg("folder.off");
    std::fs::create_dir(&folder).unwrap();
    // /proc accepts no new files, even for root.
    for (args, needle) in [
        (vec!["voxelize", "builtin:knot", "--res", "64", "-o", &missing], "does not exist"),
        (vec!["voxelize", "builtin:knot", "--res", "64", "-o", "/proc/texgeo.binvox"], "/proc/texgeo.binvox"),
        (
            vec![
                "voxelize",
                "builtin:knot",
                "--res",
                "64",
                "-o",
                &dir.arg("ok.binvox"),
                "--slices",
                "/proc/texgeo-slices",
            ],
            "/proc/texgeo-slices",
        ),
        (
            vec![
                "voxelize",
                "builtin:knot",
                "--res",
                "16",
                "-o",
                &dir.arg("ok.binvox"),
                "--aspect",
                "perlin",
                "--aspect-out",
                "/proc/texgeo-aspect",
            ],
            "/proc/texgeo-aspect",
        ),
        (vec!["inclusion", "builtin:knot", "--random", "100", "-o", "/proc/texgeo.txt"], "/proc/texgeo.txt"),
        (vec!["subdivide", "builtin:cube", "-l", "2", "-o", "/proc/texgeo.obj"], "/proc/texgeo.obj"),
        (vec!["mesh", "convert", "builtin:cube", "/proc/texgeo.off"], "/proc/texgeo.off"),
        (vec!["mesh", "convert", "builtin:cube", &folder], "is a folder"),
    ] {
        let o = texgeo(&args);
        assert_refused(&o, &[needle]);
        let out = stdout(&o);
        assert!(
            !out.contains("occupied") && !out.contains("points") && !out.contains("level"),
            "{args:?} worked first: {out}"
        );
    }
    assert!(!dir.join("ok.binvox").exists());
}

#[test]
fn a_closed_stdout_is_not_a_panic_and_outputs_are_still_written() {
    let dir = TempDir::new("outputs-stdout");
    let out = dir.join("knot.binvox");
    let (reader, writer) = std::io::pipe().unwrap();
    drop(reader); // like `| head` that has exited: every write to stdout fails (EPIPE)
    let o = Command::new(env!("CARGO_BIN_EXE_texgeo"))
        .args(["voxelize", "builtin:knot", "--res", "16", "--method", "cpu", "-o", out.to_str().unwrap()])
        .stdout(Stdio::from(writer))
        .stderr(Stdio::piped())
        .output()
        .unwrap();
    assert!(o.status.success(), "{:?}: {}", o.status, stderr(&o));
    assert!(!stderr(&o).contains("panicked"), "{}", stderr(&o));
    assert!(out.exists());
    let (reader, writer) = std::io::pipe().unwrap();
    drop(reader);
    let o = Command::new(env!("CARGO_BIN_EXE_texgeo"))
        .args(["mesh", "stats", "builtin:knot"])
        .stdout(Stdio::from(writer))
        .stderr(Stdio::piped())
        .output()
        .unwrap();
    assert!(o.status.success() && stderr(&o).is_empty(), "{:?}: {}", o.status, stderr(&o));
}

#[test]
fn concurrent_runs_never_mix_their_files() {
    let dir = TempDir::new("outputs-race");
    let out = dir.arg("mesh.obj");
    let mut want = Vec::new();
    for name in ["knot", "sphere"] {
        let single = dir.arg(&format!("{name}.obj"));
        assert!(texgeo(&["mesh", "convert", &format!("builtin:{name}"), &single]).status.success());
        want.push(std::fs::read(&single).unwrap());
    }
    for round in 0..5 {
        let children: Vec<_> = (0..6)
            .map(|i| {
                let model = if i % 2 == 0 { "builtin:knot" } else { "builtin:sphere" };
                Command::new(env!("CARGO_BIN_EXE_texgeo"))
                    .args(["mesh", "convert", model, &out])
                    .stdout(Stdio::null())
                    .spawn()
                    .unwrap()
            })
            .collect();
        for mut c in children {
            assert!(c.wait().unwrap().success());
        }
        let got = std::fs::read(&out).unwrap();
        assert!(want.contains(&got), "round {round}: a mixed or truncated file of {} bytes", got.len());
    }
    assert_eq!(dir.entries(), vec!["knot.obj", "mesh.obj", "sphere.obj"]);
}

/// Starts writing the sphere's `res`³ volume to `out` (streamed by the scanline method:
/// the file is being written for most of the run).
fn spawn_sphere_volume(out: &std::path::Path, res: &str) -> std::process::Child {
    Command::new(env!("CARGO_BIN_EXE_texgeo"))
        .args([
            "voxelize",
            "builtin:sphere",
            "--res",
            res,
            "--method",
            "scanline",
            "-o",
            out.to_str().unwrap(),
        ])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap()
}

#[test]
fn an_interrupted_run_leaves_the_previous_file() {
    let dir = TempDir::new("outputs-kill");
    let out = dir.join("s.binvox");
    std::fs::write(&out, b"previous good contents").unwrap();
    let mut child = spawn_sphere_volume(&out, "512");
    // Kill it as soon as it starts writing (a temporary file appears, or the target
    // changes), or when it is done.
    let started = std::time::Instant::now();
    loop {
        let writing = dir.entries().iter().any(|e| e.starts_with(".s.binvox.texgeo-"))
            || std::fs::metadata(&out).map_or(true, |m| m.len() != 22);
        if writing || child.try_wait().unwrap().is_some() || started.elapsed().as_secs() > 120 {
            break;
        }
        std::thread::sleep(std::time::Duration::from_micros(200));
    }
    let _ = child.kill();
    child.wait().unwrap();
    let bytes = std::fs::read(&out).unwrap();
    if bytes != b"previous good contents" {
        // It finished first: then the file is complete.
        let (grid, _) = texgeo::voxel::binvox::from_bytes(&bytes, &out).unwrap();
        assert_eq!(grid.n, 512);
    }
}

#[test]
fn a_closed_stderr_is_not_a_panic_and_outputs_are_still_written() {
    let dir = TempDir::new("outputs-stderr");
    let bench = dir.join("bench");
    let classes = dir.join("classes.txt");
    let volume = dir.join("knot.binvox");
    for args in [
        // `auto` names its choice on stderr; bench says which files it wrote there.
        vec!["inclusion", "builtin:knot", "--random", "100", "-o", classes.to_str().unwrap()],
        vec!["voxelize", "builtin:knot", "--res", "16", "-o", volume.to_str().unwrap()],
        vec![
            "bench",
            "xor",
            "--sizes",
            "16",
            "--triangles",
            "10",
            "--runs",
            "1",
            "-o",
            bench.to_str().unwrap(),
        ],
        vec!["mesh", "stats", "builtin:nope"],
    ] {
        // Like `texgeo … 2>&1 | head -c0`: both streams closed.
        let (reader, writer) = std::io::pipe().unwrap();
        drop(reader);
        let o = Command::new(env!("CARGO_BIN_EXE_texgeo"))
            .args(&args)
            .stdout(Stdio::from(writer.try_clone().unwrap()))
            .stderr(Stdio::from(writer))
            .status()
            .unwrap();
        let want = if args[1] == "stats" { 2 } else { 0 };
        assert_eq!(o.code(), Some(want), "{args:?}: {o}");
    }
    assert_eq!(std::fs::read(&classes).unwrap().len(), 200);
    assert!(volume.exists());
    assert!(std::fs::read_dir(&bench).unwrap().count() >= 2, "the bench tables were written");
}

#[test]
fn output_names_up_to_255_bytes_work() {
    let dir = TempDir::new("outputs-long");
    for len in [235, 250, 255] {
        let name = format!("{}.off", "n".repeat(len - 4));
        let o = texgeo(&["mesh", "convert", "builtin:cube", &dir.arg(&name)]);
        assert!(o.status.success(), "{len} bytes: {}", common::stderr(&o));
        let o = texgeo(&["mesh", "stats", &dir.arg(&name)]);
        assert!(stdout(&o).contains("faces                  6"), "{len} bytes: {}", stdout(&o));
    }
    assert!(dir.entries().iter().all(|e| !e.starts_with('.')), "{:?}", dir.entries());
}

#[test]
fn outputs_are_checked_against_what_the_command_writes_and_never_replace_an_input() {
    let dir = TempDir::new("outputs-kind");
    let knot = dir.arg("knot.off");
    assert!(texgeo(&["mesh", "convert", "builtin:knot", &knot]).status.success());
    let before = std::fs::read(&knot).unwrap();
    std::os::unix::fs::symlink(&knot, dir.join("link.off")).unwrap();
    std::fs::write(dir.join("p.txt"), "0 0 0\n").unwrap();
    for (args, needle) in [
        (
            vec!["voxelize", &knot, "--res", "8", "-o", &knot],
            "written as binvox or NumPy; name it .binvox or .npy",
        ),
        (vec!["voxelize", "builtin:knot", "--res", "8", "-o", &dir.arg("v.png")], "name it .binvox"),
        (vec!["mesh", "convert", &knot, &knot], "is an input of this run"),
        (vec!["mesh", "convert", &knot, &dir.arg("link.off")], "is an input of this run"),
        (vec!["subdivide", &knot, "-l", "1", "-o", &dir.arg("link.off")], "is an input of this run"),
        (vec!["inclusion", &knot, "--random", "5", "-o", &knot], "name it .txt, .dat, .csv, .labels or .npy"),
        (vec!["inclusion", &knot, "--points", &dir.arg("p.txt"), "-o", &dir.arg("p.txt")], "is an input"),
        (vec!["boolean", &knot, "builtin:cube", "--op", "union", "-o", &knot], "is an input of this run"),
        (vec!["render", &knot, "-o", &dir.arg("k.jpg")], "name it .png"),
    ] {
        let o = texgeo(&args);
        assert_refused(&o, &[needle]);
        assert!(stdout(&o).is_empty(), "{args:?} worked first: {}", stdout(&o));
    }
    assert_eq!(std::fs::read(&knot).unwrap(), before, "the input is untouched");
    // The viewer checks its outputs before it opens a window (no display needed to see it).
    for (args, needle) in [
        (vec!["--frames", "1", "--screenshot", "no/such/x.png"], "its folder no/such does not exist"),
        (vec!["--frames", "1", "--screenshot", "x.jpg"], "screenshots are PNG; name it .png"),
        (vec!["--save-mesh", "no/such/x.off"], "does not exist"),
        (vec!["--save-mesh", "x.xyz"], "unknown mesh format '.xyz'"),
        (vec!["--save-mesh", &knot], "is an input of this run"),
    ] {
        let mut cmd = Command::new(env!("CARGO_BIN_EXE_texgeo"));
        cmd.args(["view", &knot]).args(&args).env_remove("DISPLAY").env_remove("WAYLAND_DISPLAY");
        assert_refused(&cmd.current_dir(dir.path()).output().unwrap(), &[needle]);
    }
}

/// Waits until `dir` holds a temporary file of `target` (true), or `child` ended (false).
fn wait_for_temporary(dir: &TempDir, target: &str, child: &mut std::process::Child) -> bool {
    let prefix = format!(".{target}.texgeo-");
    let started = std::time::Instant::now();
    while started.elapsed().as_secs() < 120 {
        if dir.entries().iter().any(|e| e.starts_with(&prefix)) {
            return true;
        }
        if child.try_wait().unwrap().is_some() {
            return false;
        }
        std::thread::sleep(std::time::Duration::from_micros(200));
    }
    false
}

#[test]
fn a_signal_removes_the_temporary_file_and_the_next_run_removes_stale_ones() {
    let dir = TempDir::new("outputs-signal");
    let out = dir.join("s.binvox");
    for signal in [libc::SIGTERM, libc::SIGINT, libc::SIGHUP] {
        std::fs::write(&out, b"previous good contents").unwrap();
        let mut child = spawn_sphere_volume(&out, "1024");
        let writing = wait_for_temporary(&dir, "s.binvox", &mut child);
        // SAFETY: a plain kill(2) of the child this test started.
        unsafe { libc::kill(child.id() as libc::pid_t, signal) };
        let status = child.wait().unwrap();
        assert_eq!(dir.entries(), vec!["s.binvox"], "signal {signal}: a temporary file is left");
        let bytes = std::fs::read(&out).unwrap();
        if writing && bytes == b"previous good contents" {
            use std::os::unix::process::ExitStatusExt as _;
            assert_eq!(status.signal(), Some(signal), "ended by the signal, as without the handler");
        }
    }
    // A temporary file a killed run left (its PID is above any PID the kernel hands out)
    // goes with the next run of the same output; one of a live process stays.
    let dead = ".c.txt.texgeo-4194311-0.tmp";
    let live = format!(".c.txt.texgeo-{}-0.tmp", std::process::id());
    let other = ".d.txt.texgeo-4194311-0.tmp";
    for name in [dead, &live, other] {
        std::fs::write(dir.join(name), b"partial").unwrap();
    }
    let o = texgeo(&["inclusion", "builtin:cube", "--random", "10", "-o", &dir.arg("c.txt")]);
    assert!(o.status.success(), "{}", common::stderr(&o));
    let left = dir.entries();
    assert!(!left.contains(&dead.to_string()), "{left:?}");
    assert!(left.contains(&live) && left.contains(&other.to_string()), "{left:?}");
}
