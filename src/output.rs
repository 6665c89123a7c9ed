//! Output files that are never half-written.
//!
//! Every file texgeo writes — meshes, binvox volumes, PNG slices, point classes, reports —
//! goes through [`AtomicFile`]: the bytes go to a temporary file in the target's own
//! folder (same file system, so the final `rename` is atomic), and only a complete, flushed
//! file replaces the target. A run that fails (full disk, error halfway), is interrupted,
//! or races another run writing the same path therefore leaves either the previous good
//! file or one complete new one — never a truncated or mixed one. An interrupted run may
//! leave its temporary file (`.NAME.texgeo-PID-N.tmp`) beside the target; the target is
//! untouched.
//!
//! [`check_file`] and [`check_dir`] say, before any work starts, whether an output path can
//! be written, so a long computation does not end in "permission denied".
//!
//! Library code and commands both write files, so this module depends on nothing else in
//! the crate; errors carry the path and the OS error once ([`Error`]).

use std::fs::{File, OpenOptions};
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

/// An I/O failure on an output path: `path: OS error`, printed once.
#[derive(Debug, thiserror::Error)]
#[error("{}: {error}", path.display())]
pub struct Error {
    pub path: PathBuf,
    pub error: std::io::Error,
}

impl Error {
    pub fn new(path: impl Into<PathBuf>, error: std::io::Error) -> Error {
        Error { path: path.into(), error }
    }
}

pub type Result<T, E = Error> = std::result::Result<T, E>;

/// Distinguishes the temporary files of one process.
static COUNTER: AtomicU64 = AtomicU64::new(0);

/// A file being written under a temporary name; [`AtomicFile::commit`] puts it in place.
/// Dropped without `commit` (an error or a panic on the way), it removes its temporary
/// file and leaves the target as it was.
pub struct AtomicFile {
    target: PathBuf,
    temp: PathBuf,
    out: Option<BufWriter<File>>,
    /// Renamed onto the target: nothing to clean up.
    done: bool,
}

impl AtomicFile {
    /// Starts writing `path`: creates a new temporary file beside it.
    pub fn create(path: impl AsRef<Path>) -> Result<AtomicFile> {
        let target = path.as_ref().to_path_buf();
        let name = target
            .file_name()
            .ok_or_else(|| Error::new(&target, std::io::Error::other("not a file name")))?
            .to_string_lossy()
            .into_owned();
        let n = COUNTER.fetch_add(1, Ordering::Relaxed);
        let temp = folder_of(&target).join(format!(".{name}.texgeo-{}-{n}.tmp", std::process::id()));
        let file = OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(&temp)
            .map_err(|e| Error::new(&target, e))?;
        // Replacing a file keeps its permissions.
        if let Ok(meta) = std::fs::metadata(&target) {
            let _ = file.set_permissions(meta.permissions());
        }
        Ok(AtomicFile { target, temp, out: Some(BufWriter::with_capacity(1 << 20, file)), done: false })
    }

    /// The path the file will have once committed.
    pub fn path(&self) -> &Path {
        &self.target
    }

    /// Flushes everything and renames the temporary file onto the target.
    pub fn commit(mut self) -> Result<()> {
        let out = self
            .out
            .take()
            .ok_or_else(|| Error::new(&self.target, std::io::Error::other("committed twice")))?;
        let file = out.into_inner().map_err(|e| Error::new(&self.target, e.into_error()))?;
        drop(file);
        std::fs::rename(&self.temp, &self.target).map_err(|e| Error::new(&self.target, e))?;
        self.done = true;
        Ok(())
    }

    /// Wraps an I/O error of a write into this file's [`Error`].
    pub fn error(&self, error: std::io::Error) -> Error {
        Error::new(&self.target, error)
    }

    fn writer(&mut self) -> std::io::Result<&mut BufWriter<File>> {
        self.out.as_mut().ok_or_else(|| std::io::Error::other("write after commit"))
    }
}

impl Write for AtomicFile {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.writer()?.write(buf)
    }

    fn write_all(&mut self, buf: &[u8]) -> std::io::Result<()> {
        self.writer()?.write_all(buf)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.writer()?.flush()
    }
}

impl Drop for AtomicFile {
    fn drop(&mut self) {
        if !self.done {
            drop(self.out.take());
            let _ = std::fs::remove_file(&self.temp);
        }
    }
}

/// Writes `path` atomically with `fill`, which writes the whole contents.
pub fn write_with(
    path: impl AsRef<Path>,
    fill: impl FnOnce(&mut AtomicFile) -> std::io::Result<()>,
) -> Result<()> {
    let mut file = AtomicFile::create(path)?;
    fill(&mut file).map_err(|e| file.error(e))?;
    file.commit()
}

/// Writes `bytes` to `path` atomically.
pub fn write_bytes(path: impl AsRef<Path>, bytes: &[u8]) -> Result<()> {
    write_with(path, |w| w.write_all(bytes))
}

/// Writes an 8-bit image (grey, RGB or RGBA) as a PNG file atomically.
pub fn write_png<P>(path: impl AsRef<Path>, image: &image::ImageBuffer<P, Vec<u8>>) -> Result<()>
where
    P: image::PixelWithColorType<Subpixel = u8>,
{
    use image::ImageEncoder as _;
    write_with(path, |w| {
        image::codecs::png::PngEncoder::new(w)
            .write_image(image.as_raw(), image.width(), image.height(), P::COLOR_TYPE)
            .map_err(|e| match e {
                image::ImageError::IoError(e) => e,
                other => std::io::Error::other(other),
            })
    })
}

/// The folder a file path lives in (`.` for a bare name).
fn folder_of(path: &Path) -> PathBuf {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

/// Checks, before any work, that `path` can be written as a file: it is not a folder, its
/// folder exists, and a new file can be created there (by creating and removing one).
pub fn check_file(path: impl AsRef<Path>) -> Result<()> {
    let path = path.as_ref();
    if path.is_dir() {
        return Err(Error::new(path, std::io::Error::other("is a folder, not a file")));
    }
    let folder = folder_of(path);
    if !folder.is_dir() {
        let why = if folder.exists() { "is not a folder" } else { "does not exist" };
        return Err(Error::new(
            path,
            std::io::Error::other(format!("its folder {} {why}", folder.display())),
        ));
    }
    probe(&folder).map_err(|e| Error::new(path, e))
}

/// Creates the folder `dir` (and its parents) if needed and checks that files can be
/// created in it.
pub fn check_dir(dir: impl AsRef<Path>) -> Result<()> {
    let dir = dir.as_ref();
    if dir.exists() && !dir.is_dir() {
        return Err(Error::new(dir, std::io::Error::other("exists and is not a folder")));
    }
    std::fs::create_dir_all(dir).map_err(|e| Error::new(dir, e))?;
    probe(dir).map_err(|e| Error::new(dir, e))
}

/// Creates and removes a temporary file in `folder`.
fn probe(folder: &Path) -> std::io::Result<()> {
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    let temp = folder.join(format!(".texgeo-probe-{}-{n}.tmp", std::process::id()));
    OpenOptions::new().write(true).create_new(true).open(&temp)?;
    std::fs::remove_file(&temp)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn folder(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("texgeo-output-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    fn entries(d: &Path) -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(d)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    }

    #[test]
    fn commit_replaces_and_a_failure_keeps_the_old_file() {
        let d = folder("commit");
        let p = d.join("out.txt");
        write_bytes(&p, b"first").unwrap();
        assert_eq!(std::fs::read(&p).unwrap(), b"first");
        let e = write_with(&p, |w| {
            w.write_all(b"half of the second")?;
            Err(std::io::Error::other("disk full"))
        })
        .unwrap_err();
        assert_eq!(e.to_string(), format!("{}: disk full", p.display()));
        assert_eq!(std::fs::read(&p).unwrap(), b"first");
        // Dropped without commit: the temporary file is gone too.
        let mut f = AtomicFile::create(&p).unwrap();
        f.write_all(b"never committed").unwrap();
        drop(f);
        assert_eq!(entries(&d), vec!["out.txt"]);
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn checks_name_the_problem_before_work() {
        let d = folder("check");
        assert!(check_file(d.join("a.off")).is_ok());
        let e = check_file(&d).unwrap_err().to_string();
        assert!(e.ends_with("is a folder, not a file"), "{e}");
        let e = check_file(d.join("missing/a.off")).unwrap_err().to_string();
        assert!(e.contains("missing") && e.ends_with("does not exist"), "{e}");
        let sub = d.join("slices/deep");
        check_dir(&sub).unwrap();
        assert!(sub.is_dir());
        std::fs::write(d.join("file"), b"x").unwrap();
        let e = check_dir(d.join("file")).unwrap_err().to_string();
        assert!(e.ends_with("exists and is not a folder"), "{e}");
        assert_eq!(entries(&d), vec!["file", "slices"]);
        std::fs::remove_dir_all(&d).unwrap();
    }
}
