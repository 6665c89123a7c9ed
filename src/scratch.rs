//! A private temporary folder for the files a helper process reads and writes (the
//! OpenSubdiv and CGAL helpers), removed with everything in it when dropped — or when
//! SIGINT, SIGTERM or SIGHUP ends the process ([`crate::output`] keeps the list).

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

/// The helper binary `name` (built by `tools/setup`): the file `$ENV` names, else
/// `target/tools/NAME` of this checkout, else `tools/NAME` in an ancestor of the running
/// executable. `Err`: the path it should be at (`$ENV`'s, or this checkout's).
pub fn helper(env: &str, name: &str) -> Result<PathBuf, PathBuf> {
    if let Some(path) = std::env::var_os(env) {
        let path = PathBuf::from(path);
        return if path.is_file() { Ok(path) } else { Err(path) };
    }
    let default = Path::new(env!("CARGO_MANIFEST_DIR")).join("target/tools").join(name);
    if default.is_file() {
        return Ok(default);
    }
    let beside_exe = std::env::current_exe().ok().and_then(|exe| {
        exe.ancestors().map(|dir| dir.join("tools").join(name)).find(|candidate| candidate.is_file())
    });
    beside_exe.ok_or(default)
}

/// A fresh folder `texgeo-PREFIX-PID-N` in the system's temporary folder.
#[derive(Debug)]
pub struct ScratchDir {
    path: PathBuf,
}

impl ScratchDir {
    /// Creates the folder; the error names it.
    pub fn new(prefix: &str) -> crate::output::Result<ScratchDir> {
        // One per call, also across threads of this process.
        static COUNTER: AtomicU64 = AtomicU64::new(0);
        let n = COUNTER.fetch_add(1, Ordering::Relaxed);
        let path = std::env::temp_dir().join(format!("texgeo-{prefix}-{}-{n}", std::process::id()));
        crate::output::register(&path, true);
        if let Err(e) = std::fs::create_dir_all(&path) {
            crate::output::unregister(&path);
            return Err(crate::output::Error::new(&path, e));
        }
        Ok(ScratchDir { path })
    }

    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The path of `name` inside the folder.
    pub fn join(&self, name: &str) -> PathBuf {
        self.path.join(name)
    }
}

impl Drop for ScratchDir {
    fn drop(&mut self) {
        // Best effort: a leftover folder in the temp dir is harmless.
        let _ = std::fs::remove_dir_all(&self.path);
        crate::output::unregister(&self.path);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn folders_are_distinct_and_removed() {
        let (a, b) = (ScratchDir::new("t").unwrap(), ScratchDir::new("t").unwrap());
        assert_ne!(a.path(), b.path());
        std::fs::write(a.join("f"), b"x").unwrap();
        let p = a.path().to_path_buf();
        drop(a);
        assert!(!p.exists() && b.path().is_dir());
    }
}
