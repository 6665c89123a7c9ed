//! Every shader source under glsl/ also passes the reference compiler, glslangValidator
//! (build.rs compiles them with shaderc; two front ends catch more mistakes).

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;

fn sources(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap().flatten() {
        let p = entry.path();
        if p.is_dir() {
            sources(&p, out);
        } else if matches!(p.extension().and_then(|e| e.to_str()), Some("vert" | "frag")) {
            out.push(p);
        }
    }
}

#[test]
fn glslang_validator_accepts_every_shader() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut files = Vec::new();
    sources(&root.join("glsl"), &mut files);
    assert!(files.len() >= 4, "expected shaders under glsl/, found {files:?}");
    let dir = common::TempDir::new("glslang");
    let out = dir.join("shader.spv");
    for f in &files {
        let result = Command::new("glslangValidator")
            .args(["-V", "--target-env", "vulkan1.3"])
            .arg(format!("-I{}", f.parent().unwrap().display()))
            .arg(format!("-I{}", root.join("glsl/common").display()))
            .arg("-o")
            .arg(&out)
            .arg(f)
            .output()
            .expect("glslangValidator is missing: run tools/setup (package glslang-tools)");
        assert!(
            result.status.success(),
            "glslangValidator rejected {}:\n{}{}",
            f.display(),
            String::from_utf8_lossy(&result.stdout),
            String::from_utf8_lossy(&result.stderr)
        );
    }
    let _ = std::fs::remove_file(out);
}
