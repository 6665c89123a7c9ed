//! `build.rs` watches only files that exist: cargo reruns a build script whenever one of
//! its `rerun-if-changed` paths is missing, which would recompile every shader and the
//! whole crate on every `cargo build` and `cargo test`.

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;

#[path = "../build/git_watch.rs"]
mod git_watch;

/// The `rerun-if-changed` paths of this build's run of the build script (its `output`
/// file beside `OUT_DIR`).
fn rerun_paths() -> Vec<PathBuf> {
    let out_dir = Path::new(env!("OUT_DIR"));
    let output = out_dir.parent().expect("OUT_DIR has a parent").join("output");
    let text = std::fs::read_to_string(&output).unwrap_or_else(|e| panic!("{}: {e}", output.display()));
    text.lines()
        .filter_map(|l| {
            l.strip_prefix("cargo:rerun-if-changed=").or_else(|| l.strip_prefix("cargo::rerun-if-changed="))
        })
        .map(|p| Path::new(env!("CARGO_MANIFEST_DIR")).join(p))
        .collect()
}

#[test]
fn every_path_the_build_script_watches_exists() {
    let paths = rerun_paths();
    assert!(paths.iter().any(|p| p.ends_with("glsl")), "{paths:?}");
    for p in &paths {
        assert!(
            p.exists(),
            "{} is watched but does not exist: every build would rerun the build script",
            p.display()
        );
    }
}

#[test]
fn a_fresh_clone_without_packed_refs_watches_its_loose_branch_ref() {
    let tmp = common::TempDir::new("build-script");
    let dir = tmp.path();
    let git = |args: &[&str]| {
        let o = Command::new("git")
            .args(["-c", "user.name=t", "-c", "user.email=t@t", "-c", "init.defaultBranch=main"])
            .args(args)
            .current_dir(dir)
            .output()
            .expect("run git");
        assert!(o.status.success(), "git {args:?}: {}", String::from_utf8_lossy(&o.stderr));
        String::from_utf8_lossy(&o.stdout).trim().to_string()
    };
    git(&["init", "-q"]);
    git(&["commit", "-q", "--allow-empty", "-m", "first"]);
    let git_dir = PathBuf::from(git(&["rev-parse", "--absolute-git-dir"]));
    assert!(!git_dir.join("packed-refs").exists(), "a fresh repository has no packed refs");
    let watched = git_watch::watched(Some(&git_dir), Some(&git_dir), Some("refs/heads/main"));
    assert_eq!(watched, vec![git_dir.join("HEAD"), git_dir.join("refs/heads/main")]);
    // After `git pack-refs` the branch lives in packed-refs only.
    git(&["pack-refs", "--all"]);
    let watched = git_watch::watched(Some(&git_dir), Some(&git_dir), Some("refs/heads/main"));
    assert_eq!(watched, vec![git_dir.join("HEAD"), git_dir.join("packed-refs")]);
    // Detached, or no git at all: nothing missing either.
    assert_eq!(git_watch::watched(Some(&git_dir), Some(&git_dir), None), vec![git_dir.join("HEAD")]);
    assert!(git_watch::watched(None, None, None).is_empty());
}
