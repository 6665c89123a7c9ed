//! Output files of a reproduction: every file is written whole or not at all
//! ([`crate::output`]), and the output folder is checked writable before a run that
//! takes minutes starts.

use std::path::{Path, PathBuf};

use super::{ReproduceError, Result};

fn io(path: &Path) -> impl FnOnce(std::io::Error) -> ReproduceError + '_ {
    move |source| ReproduceError::Io { path: path.to_path_buf(), source }
}

/// Writes `bytes` to `path` atomically ([`crate::output`]): readers see the old file or
/// the whole new one.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    crate::output::write_bytes(path, bytes).map_err(from_output)
}

/// Creates `dir` (and its parents) if needed and checks a file can be created in it.
pub fn check_writable(dir: &Path) -> Result<()> {
    crate::output::check_dir(dir).map_err(from_output)
}

fn from_output(e: crate::output::Error) -> ReproduceError {
    ReproduceError::Io { path: e.path, source: e.error }
}

/// The folders of a report: `csv/`, `plots/`, `figures/` under the output folder.
#[derive(Clone, Debug)]
pub struct Layout {
    pub root: PathBuf,
}

impl Layout {
    pub const CSV: &'static str = "csv";
    pub const PLOTS: &'static str = "plots";
    pub const FIGURES: &'static str = "figures";

    /// Checks `root` writable and creates the sub-folders.
    pub fn create(root: &Path) -> Result<Layout> {
        check_writable(root)?;
        for sub in [Layout::CSV, Layout::PLOTS, Layout::FIGURES] {
            let dir = root.join(sub);
            std::fs::create_dir_all(&dir).map_err(io(&dir))?;
        }
        Ok(Layout { root: root.to_path_buf() })
    }

    /// `root/relative`, written atomically.
    pub fn write(&self, relative: &str, bytes: &[u8]) -> Result<PathBuf> {
        let path = self.root.join(relative);
        write_atomic(&path, bytes)?;
        Ok(path)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn atomic_write_replaces_whole_files_and_leaves_no_temporary() {
        let dir = std::env::temp_dir().join(format!("texgeo-files-{}", std::process::id()));
        check_writable(&dir).unwrap();
        let path = dir.join("a.txt");
        write_atomic(&path, b"first").unwrap();
        write_atomic(&path, b"second").unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"second");
        let names: Vec<_> = std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().file_name()).collect();
        assert_eq!(names, vec![std::ffi::OsString::from("a.txt")]);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn a_file_in_the_way_is_not_a_folder() {
        let file = std::env::temp_dir().join(format!("texgeo-notdir-{}", std::process::id()));
        std::fs::write(&file, b"x").unwrap();
        match check_writable(&file) {
            Err(ReproduceError::Io { path, source }) => {
                assert_eq!(path, file);
                assert!(source.to_string().contains("not a folder"), "{source}");
            }
            other => panic!("expected an I/O error on the path, got {other:?}"),
        }
        std::fs::remove_file(&file).unwrap();
    }
}
