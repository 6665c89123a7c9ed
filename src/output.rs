//! Output files that are never half-written.
//!
//! Every file texgeo writes — meshes, binvox volumes, PNG slices, point classes, reports —
//! goes through [`AtomicFile`]: the bytes go to a temporary file in the target's own
//! folder (same file system, so the final `rename` is atomic), and only a complete, flushed
//! file replaces the target. A run that fails (full disk, error halfway), is interrupted,
//! or races another run writing the same path therefore leaves either the previous good
//! file or one complete new one — never a truncated or mixed one.
//!
//! Temporary files are named `.NAME.texgeo-PID-N.tmp` (NAME shortened so the whole name
//! fits the file system's 255 bytes; the target's name is never changed). They are
//! registered while they exist: SIGINT, SIGTERM or SIGHUP removes them before the process
//! ends ([`remove_temporaries_on_signals`]), and one left by a process that was killed
//! outright (SIGKILL, a crash) is removed by the next run writing the same file, once no
//! process with its PID is alive.
//!
//! [`check_file`], [`check_dir`], [`check_extension`] and [`check_not_input`] say, before
//! any work starts, whether an output path can be written, so a long computation does not
//! end in "permission denied" or in a replaced input.
//!
//! Library code and commands both write files, so this module depends on nothing else in
//! the crate; errors carry the path and the OS error once ([`Error`]).

use std::collections::HashMap;
use std::ffi::{OsStr, OsString};
use std::fs::{File, OpenOptions};
use std::io::{BufWriter, Write};
use std::os::unix::ffi::{OsStrExt, OsStringExt};
use std::path::{Path, PathBuf};
use std::sync::Mutex;
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

    fn other(path: impl Into<PathBuf>, message: impl Into<String>) -> Error {
        Error::new(path, std::io::Error::other(message.into()))
    }
}

pub type Result<T, E = Error> = std::result::Result<T, E>;

/// Distinguishes the temporary files of one process.
static COUNTER: AtomicU64 = AtomicU64::new(0);

/// The longest file name Linux file systems take, in bytes.
const NAME_MAX: usize = 255;

/// Temporary files and folders that exist right now and must not outlive the process.
/// Held while a temporary file is created or committed, and by the signal handler until
/// the process ends, so a file is never committed after the handler removed it.
static PENDING: Mutex<Vec<Pending>> = Mutex::new(Vec::new());

struct Pending {
    path: PathBuf,
    folder: bool,
}

fn pending() -> std::sync::MutexGuard<'static, Vec<Pending>> {
    PENDING.lock().unwrap_or_else(std::sync::PoisonError::into_inner)
}

/// Registers a temporary file or folder for removal on SIGINT/SIGTERM/SIGHUP.
pub(crate) fn register(path: &Path, folder: bool) {
    pending().push(Pending { path: path.to_path_buf(), folder });
}

/// Forgets a registered temporary path (it was removed or renamed).
pub(crate) fn unregister(path: &Path) {
    let mut list = pending();
    if let Some(i) = list.iter().rposition(|p| p.path == path) {
        list.swap_remove(i);
    }
}

/// Installs, once per process, a handler that removes every registered temporary file
/// and folder when SIGINT, SIGTERM or SIGHUP arrives, then ends the process as the signal
/// would have. The handler runs on a thread of its own (not in signal context).
pub fn remove_temporaries_on_signals() -> std::io::Result<()> {
    use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
    static INSTALLED: std::sync::OnceLock<()> = std::sync::OnceLock::new();
    if INSTALLED.get().is_some() {
        return Ok(());
    }
    let mut signals = signal_hook::iterator::Signals::new([SIGINT, SIGTERM, SIGHUP])?;
    std::thread::Builder::new().name("texgeo-signals".into()).spawn(move || {
        if let Some(signal) = signals.forever().next() {
            // Kept locked: nothing is created or committed from here on.
            let list = pending();
            for p in list.iter() {
                let _ =
                    if p.folder { std::fs::remove_dir_all(&p.path) } else { std::fs::remove_file(&p.path) };
            }
            let _ = signal_hook::low_level::emulate_default_handler(signal);
            std::process::exit(128 + signal);
        }
    })?;
    let _ = INSTALLED.set(());
    Ok(())
}

/// The temporary name of `name` for this process: `.NAME.texgeo-PID-N.tmp`, with NAME cut
/// (at a character boundary) so the whole name has at most [`NAME_MAX`] bytes.
fn temporary_name(name: &OsStr, pid: u32, n: u64) -> OsString {
    let suffix = format!(".texgeo-{pid}-{n}.tmp");
    let bytes = name.as_bytes();
    let mut keep = bytes.len().min(NAME_MAX - 1 - suffix.len());
    while keep > 0 && keep < bytes.len() && bytes[keep] & 0xc0 == 0x80 {
        keep -= 1;
    }
    let mut out = Vec::with_capacity(1 + keep + suffix.len());
    out.push(b'.');
    out.extend_from_slice(&bytes[..keep]);
    out.extend_from_slice(suffix.as_bytes());
    OsString::from_vec(out)
}

/// The target name part and the PID of a temporary name made by [`temporary_name`].
fn parse_temporary(name: &OsStr) -> Option<(&[u8], u32)> {
    let bytes = name.as_bytes().strip_prefix(b".")?.strip_suffix(b".tmp")?;
    const MARK: &[u8] = b".texgeo-";
    let at = bytes.windows(MARK.len()).rposition(|w| w == MARK)?;
    let (pid, n) = std::str::from_utf8(&bytes[at + MARK.len()..]).ok()?.split_once('-')?;
    n.parse::<u64>().ok()?;
    Some((&bytes[..at], pid.parse().ok()?))
}

/// Whether a process with this PID exists (in this PID namespace).
fn alive(pid: u32) -> bool {
    let Ok(pid) = libc::pid_t::try_from(pid) else { return false };
    // SAFETY: signal 0 only checks that the process exists and may be signalled.
    let r = unsafe { libc::kill(pid, 0) };
    r == 0 || std::io::Error::last_os_error().raw_os_error() != Some(libc::ESRCH)
}

/// Removes the temporary files of `target` that processes no longer alive left behind.
/// A folder is listed once per process (texgeo temporaries only, by name and PID); each
/// target then removes its own.
fn remove_stale(target: &Path) {
    /// Per folder: the target name (or its cut prefix), the PID and the path of each
    /// texgeo temporary file found when the folder was first listed.
    type Found = HashMap<PathBuf, Vec<(Vec<u8>, u32, PathBuf)>>;
    static FOUND: Mutex<Option<Found>> = Mutex::new(None);
    let (Some(name), folder) = (target.file_name(), folder_of(target)) else { return };
    let mut found = FOUND.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
    let listed = found.get_or_insert_with(HashMap::new).entry(folder.clone()).or_insert_with(|| {
        // Listed before this process makes its first temporary file here: one with this
        // process' PID is from an earlier process that had the same PID.
        let Ok(entries) = std::fs::read_dir(&folder) else { return Vec::new() };
        entries
            .flatten()
            .filter_map(|e| {
                let file = e.file_name();
                let (prefix, pid) = parse_temporary(&file)?;
                Some((prefix.to_vec(), pid, e.path()))
            })
            .collect()
    });
    let name = name.as_bytes();
    listed.retain(|(prefix, pid, path)| {
        let file_len = path.file_name().map_or(0, |f| f.len());
        // The whole name, or a name cut to fit NAME_MAX.
        let same = prefix == name || (name.starts_with(prefix) && file_len + 4 > NAME_MAX);
        if same && (*pid == std::process::id() || !alive(*pid)) {
            let _ = std::fs::remove_file(path);
            return false;
        }
        true
    });
}

/// A file being written under a temporary name; [`AtomicFile::commit`] puts it in place.
/// Dropped without `commit` (an error or a panic on the way), it removes its temporary
/// file and leaves the target as it was.
pub struct AtomicFile {
    target: PathBuf,
    temp: PathBuf,
    out: Option<BufWriter<File>>,
    /// Renamed onto the target: nothing to clean up.
    done: bool,
    /// Synced to the disk before the rename (survives a power loss).
    durable: bool,
}

impl AtomicFile {
    /// Starts writing `path`: creates a new temporary file beside it (and removes the
    /// temporary files of `path` that dead processes left).
    pub fn create(path: impl AsRef<Path>) -> Result<AtomicFile> {
        let target = path.as_ref().to_path_buf();
        let name = target.file_name().ok_or_else(|| Error::other(&target, "not a file name"))?.to_owned();
        remove_stale(&target);
        let folder = folder_of(&target);
        let (temp, file) = loop {
            let n = COUNTER.fetch_add(1, Ordering::Relaxed);
            let temp = folder.join(temporary_name(&name, std::process::id(), n));
            // Registered before it exists, under the lock the signal handler takes.
            let mut list = pending();
            match OpenOptions::new().write(true).create_new(true).open(&temp) {
                Ok(file) => {
                    list.push(Pending { path: temp.clone(), folder: false });
                    break (temp, file);
                }
                Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => continue,
                Err(e) => return Err(Error::new(&target, e)),
            }
        };
        // Replacing a file keeps its permissions.
        if let Ok(meta) = std::fs::metadata(&target) {
            let _ = file.set_permissions(meta.permissions());
        }
        Ok(AtomicFile {
            target,
            temp,
            out: Some(BufWriter::with_capacity(1 << 20, file)),
            done: false,
            durable: false,
        })
    }

    /// Also syncs the file to the disk before it replaces the target, so a power loss
    /// leaves the old or the new file (records a resumed run relies on).
    pub fn durable(mut self) -> AtomicFile {
        self.durable = true;
        self
    }

    /// The path the file will have once committed.
    pub fn path(&self) -> &Path {
        &self.target
    }

    /// Flushes everything and renames the temporary file onto the target.
    pub fn commit(mut self) -> Result<()> {
        let out = self.out.take().ok_or_else(|| Error::other(&self.target, "committed twice"))?;
        let file = out.into_inner().map_err(|e| Error::new(&self.target, e.into_error()))?;
        if self.durable {
            file.sync_all().map_err(|e| Error::new(&self.target, e))?;
        }
        drop(file);
        let mut list = pending();
        std::fs::rename(&self.temp, &self.target).map_err(|e| Error::new(&self.target, e))?;
        if let Some(i) = list.iter().rposition(|p| p.path == self.temp) {
            list.swap_remove(i);
        }
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
            unregister(&self.temp);
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

/// Writes `bytes` to `path` atomically and synced to the disk ([`AtomicFile::durable`]).
pub fn write_bytes_durable(path: impl AsRef<Path>, bytes: &[u8]) -> Result<()> {
    let mut file = AtomicFile::create(path)?.durable();
    file.write_all(bytes).map_err(|e| file.error(e))?;
    file.commit()
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
        return Err(Error::other(path, "is a folder, not a file"));
    }
    let folder = folder_of(path);
    if !folder.is_dir() {
        let why = if folder.exists() { "is not a folder" } else { "does not exist" };
        return Err(Error::other(path, format!("its folder {} {why}", folder.display())));
    }
    probe(&folder).map_err(|e| Error::new(path, e))
}

/// Checks that `path` ends in one of `extensions` (without the dot, matched ignoring
/// case): `what` says what the command writes there ("the volume is binvox").
pub fn check_extension(path: impl AsRef<Path>, extensions: &[&str], what: &str) -> Result<()> {
    let path = path.as_ref();
    let ext = path.extension().and_then(OsStr::to_str).map(str::to_ascii_lowercase);
    if ext.as_deref().is_some_and(|e| extensions.contains(&e)) {
        return Ok(());
    }
    let names: Vec<String> = extensions.iter().map(|e| format!(".{e}")).collect();
    let names = match names.as_slice() {
        [one] => one.clone(),
        [rest @ .., last] => format!("{} or {last}", rest.join(", ")),
        [] => String::new(),
    };
    Err(Error::other(path, format!("{what}; name it {names}")))
}

/// Checks that writing `path` would not replace one of `inputs`, the files the same run
/// reads (the same file under any name, links included).
pub fn check_not_input(path: impl AsRef<Path>, inputs: &[&Path]) -> Result<()> {
    use std::os::unix::fs::MetadataExt as _;
    let path = path.as_ref();
    let Ok(out) = std::fs::metadata(path) else { return Ok(()) };
    for input in inputs {
        if let Ok(m) = std::fs::metadata(input)
            && (m.dev(), m.ino()) == (out.dev(), out.ino())
        {
            return Err(Error::other(
                path,
                format!("is an input of this run ({}); writing it would replace it", input.display()),
            ));
        }
    }
    Ok(())
}

/// [`check_file`] and [`check_not_input`]: what every command runs on each output path
/// before any work (after checking the extension against what it writes there).
pub fn check_output(path: impl AsRef<Path>, inputs: &[&Path]) -> Result<()> {
    check_file(&path)?;
    check_not_input(path, inputs)
}

/// Creates the folder `dir` (and its parents) if needed and checks that files can be
/// created in it.
pub fn check_dir(dir: impl AsRef<Path>) -> Result<()> {
    let dir = dir.as_ref();
    if dir.exists() && !dir.is_dir() {
        return Err(Error::other(dir, "exists and is not a folder"));
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
        write_bytes_durable(&p, b"durable").unwrap();
        assert_eq!(std::fs::read(&p).unwrap(), b"durable");
        assert!(pending().iter().all(|t| !t.path.starts_with(&d)), "nothing stays registered");
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
        assert!(check_extension(d.join("v.BinVox"), &["binvox"], "x").is_ok());
        let e = check_extension(d.join("v.off"), &["txt", "npy"], "classes are text or NumPy").unwrap_err();
        assert!(e.to_string().ends_with("v.off: classes are text or NumPy; name it .txt or .npy"), "{e}");
        // The same file under another name is an input; a new file is not.
        std::os::unix::fs::symlink(d.join("file"), d.join("link")).unwrap();
        let e = check_not_input(d.join("link"), &[&d.join("file")]).unwrap_err().to_string();
        assert!(e.contains("is an input of this run"), "{e}");
        assert!(check_not_input(d.join("new"), &[&d.join("file")]).is_ok());
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn temporary_names_fit_and_stale_ones_of_dead_processes_go() {
        for len in [1, 200, 230, 240, 255] {
            let name = OsString::from("é".repeat(len / 2) + &"x".repeat(len % 2));
            let t = temporary_name(&name, 4_194_303, u64::MAX);
            assert!(t.len() <= NAME_MAX, "{len}: {} bytes", t.len());
            assert!(t.to_str().is_some(), "cut at a character boundary");
            let (prefix, pid) = parse_temporary(&t).unwrap();
            assert!(name.as_bytes().starts_with(prefix) && pid == 4_194_303);
        }
        let d = folder("stale");
        let long = "n".repeat(250);
        // pid_max is at most 2^22: a PID above it never runs.
        let dead = 4_194_304 + 7;
        let mine = std::process::id();
        let parent = std::os::unix::process::parent_id();
        for (target, pid) in [("a.txt", dead), ("a.txt", parent), ("b.txt", dead), (long.as_str(), dead)] {
            std::fs::write(d.join(temporary_name(OsStr::new(target), pid, 3)), b"partial").unwrap();
        }
        write_bytes(d.join("a.txt"), b"a").unwrap();
        write_bytes(d.join(&long), b"long").unwrap();
        let left = entries(&d);
        let expect_live = temporary_name(OsStr::new("a.txt"), parent, 3).to_string_lossy().into_owned();
        let expect_b = temporary_name(OsStr::new("b.txt"), dead, 3).to_string_lossy().into_owned();
        assert_eq!(left, {
            let mut v = vec![expect_live, expect_b, "a.txt".to_string(), long.clone()];
            v.sort();
            v
        });
        assert_ne!(mine, dead);
        std::fs::remove_dir_all(&d).unwrap();
    }
}
