//! Helpers shared by the integration tests: the named test shapes, one temporary folder
//! per test, and running the `texgeo` binary.

#![allow(dead_code)]

pub mod shapes;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::atomic::{AtomicUsize, Ordering};

/// A fresh, empty folder for one test, removed when dropped. Tests running in parallel
/// (threads of one process, or several test binaries) never share one.
pub struct TempDir(PathBuf);

impl TempDir {
    pub fn new(test: &str) -> TempDir {
        static COUNT: AtomicUsize = AtomicUsize::new(0);
        let n = COUNT.fetch_add(1, Ordering::Relaxed);
        let dir = std::env::temp_dir().join(format!("texgeo-{test}-{}-{n}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).expect("create a temporary folder");
        TempDir(dir)
    }

    pub fn path(&self) -> &Path {
        &self.0
    }

    /// A path inside the folder.
    pub fn join(&self, name: &str) -> PathBuf {
        self.0.join(name)
    }

    /// `name` inside the folder, as a string for command lines.
    pub fn arg(&self, name: &str) -> String {
        self.join(name).to_string_lossy().into_owned()
    }

    /// The names in the folder, sorted.
    pub fn entries(&self) -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(&self.0)
            .expect("read the temporary folder")
            .map(|e| e.expect("folder entry").file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// A path `texgeo-TEST-NAME-PID` in the temporary folder, with nothing there: for outputs
/// that outlive one helper (a report shared by the tests of a file) or that a command must
/// create itself. The caller removes what it made.
pub fn fresh_path(test: &str, name: &str) -> PathBuf {
    let path = std::env::temp_dir().join(format!("texgeo-{test}-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&path);
    let _ = std::fs::remove_file(&path);
    path
}

/// [`fresh_path`], made an empty folder.
pub fn fresh_dir(test: &str, name: &str) -> PathBuf {
    let dir = fresh_path(test, name);
    std::fs::create_dir_all(&dir).expect("create a temporary folder");
    dir
}

/// Runs the `texgeo` binary with `args`.
pub fn texgeo(args: &[&str]) -> Output {
    texgeo_env(args, &[])
}

/// Runs the `texgeo` binary with `args` and the variables `env` set.
pub fn texgeo_env(args: &[&str], env: &[(&str, &str)]) -> Output {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_texgeo"));
    cmd.args(args);
    for (k, v) in env {
        cmd.env(k, v);
    }
    cmd.output().expect("run texgeo")
}

/// Runs `texgeo` through `bash -c` with a shell prefix (e.g. `ulimit -f 1;`): the binary
/// and every argument are quoted.
pub fn texgeo_in_shell(prefix: &str, args: &[&str]) -> Output {
    let quote = |s: &str| format!("'{}'", s.replace('\'', r"'\''"));
    let mut line = format!("{prefix} exec {}", quote(env!("CARGO_BIN_EXE_texgeo")));
    for a in args {
        line.push(' ');
        line.push_str(&quote(a));
    }
    Command::new("bash").arg("-c").arg(line).output().expect("run bash")
}

pub fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// Asserts exit status 2 with exactly one error line containing every needle.
pub fn assert_refused(o: &Output, needles: &[&str]) {
    let err = stderr(o);
    assert_eq!(o.status.code(), Some(2), "status {:?}, stderr: {err}, stdout: {}", o.status, stdout(o));
    assert!(err.starts_with("texgeo: error: "), "{err}");
    assert_eq!(err.trim_end().lines().count(), 1, "one line: {err}");
    for n in needles {
        assert!(err.contains(n), "expected '{n}' in: {err}");
    }
}

/// The volume of a closed mesh (0 for the empty solid).
pub fn volume(m: &texgeo::mesh::Mesh) -> f64 {
    if m.num_faces() == 0 { 0.0 } else { texgeo::mesh::covering::Covering::new(m).volume() }
}

/// `m` with every point moved by `t`.
pub fn moved(m: &texgeo::mesh::Mesh, t: glam::DAffine3) -> texgeo::mesh::Mesh {
    m.map_positions(|p| t.transform_point3(p)).expect("a moved test mesh is a mesh")
}
