//! The user's cache folder: small files that spare a later run work it would redo — the
//! verdict of the solid check for a mesh already checked ([`crate::mesh::solidity`]), the
//! Vulkan pipeline cache of a device (`crate::gpu`).
//!
//! Where: `$TEXGEO_CACHE_DIR` if set, else `$XDG_CACHE_HOME/texgeo`, else
//! `$HOME/.cache/texgeo` (the XDG base directory rule); `TEXGEO_CACHE=off` turns caching off.
//! Each kind of entry lives in its own versioned folder (`solidity-v1`, `pipelines-v2`):
//! a texgeo whose rules change bumps the version and never reads the old entries.
//!
//! An entry is one file named by the hex of its 32-byte key:
//! `texgeo cache 1\n`, the key, the payload's length (u64 LE), the payload's BLAKE3 hash,
//! the payload. A file that does not parse, names another key, has another length or a
//! payload whose hash differs (truncated, corrupt, written by something else) is ignored
//! as if absent. Entries are written like every texgeo output ([`crate::output`]): a
//! temporary file in the same folder renamed into place, so concurrent runs each leave one
//! complete entry and a reader sees the old or the new file, never a mix. The cache is an
//! optimisation only: a failure to read or write it changes no answer and is not an error.

use std::io::Write as _;
use std::path::{Path, PathBuf};

const MAGIC: &[u8] = b"texgeo cache 1\n";

/// A 32-byte cache key (a BLAKE3 hash of everything the entry depends on).
pub type Key = [u8; 32];

/// One kind of entry in one folder.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Store {
    dir: PathBuf,
}

/// The cache root from the environment, `None` when caching is off or no folder is known.
pub fn root() -> Option<PathBuf> {
    let var = |k: &str| std::env::var_os(k).filter(|v| !v.is_empty());
    if var("TEXGEO_CACHE").is_some_and(|v| v == "off" || v == "0") {
        return None;
    }
    if let Some(d) = var("TEXGEO_CACHE_DIR") {
        return Some(PathBuf::from(d));
    }
    if let Some(d) = var("XDG_CACHE_HOME").map(PathBuf::from).filter(|d| d.is_absolute()) {
        return Some(d.join("texgeo"));
    }
    var("HOME").map(|h| PathBuf::from(h).join(".cache").join("texgeo"))
}

impl Store {
    /// The store for entries of `kind` (e.g. `solidity-v1`) under the environment's root.
    pub fn open(kind: &str) -> Option<Store> {
        root().map(|r| Store::at(r.join(kind)))
    }

    /// A store in an explicit folder (tests).
    pub fn at(dir: impl Into<PathBuf>) -> Store {
        Store { dir: dir.into() }
    }

    pub fn dir(&self) -> &Path {
        &self.dir
    }

    fn path(&self, key: &Key) -> PathBuf {
        self.dir.join(hex(key))
    }

    /// The payload stored under `key`, if a complete, intact entry exists.
    pub fn get(&self, key: &Key) -> Option<Vec<u8>> {
        let bytes = std::fs::read(self.path(key)).ok()?;
        decode(&bytes, key).map(<[u8]>::to_vec)
    }

    /// Stores `payload` under `key` (atomically; failures are ignored: see the module docs).
    pub fn put(&self, key: &Key, payload: &[u8]) {
        if std::fs::create_dir_all(&self.dir).is_err() {
            return;
        }
        let _ = crate::output::write_with(self.path(key), |w| {
            w.write_all(MAGIC)?;
            w.write_all(key)?;
            w.write_all(&(payload.len() as u64).to_le_bytes())?;
            w.write_all(blake3::hash(payload).as_bytes())?;
            w.write_all(payload)
        });
    }
}

/// The payload of an entry file, if it is intact and holds `key`.
fn decode<'a>(bytes: &'a [u8], key: &Key) -> Option<&'a [u8]> {
    let rest = bytes.strip_prefix(MAGIC)?;
    let (stored_key, rest) = rest.split_at_checked(32)?;
    let (len, rest) = rest.split_at_checked(8)?;
    let (hash, payload) = rest.split_at_checked(32)?;
    let len = u64::from_le_bytes(len.try_into().ok()?);
    (stored_key == key && len == payload.len() as u64 && blake3::hash(payload).as_bytes() == hash)
        .then_some(payload)
}

/// A BLAKE3 hasher fed through a buffer, for keys over many small values.
pub struct KeyHasher {
    hasher: blake3::Hasher,
    buf: Vec<u8>,
}

impl KeyHasher {
    /// A hasher whose keys differ from every other kind's: `domain` names what is hashed and
    /// the version of the rules that use it.
    pub fn new(domain: &str) -> KeyHasher {
        let mut h = KeyHasher { hasher: blake3::Hasher::new(), buf: Vec::with_capacity(1 << 16) };
        h.bytes(domain.as_bytes());
        h
    }

    /// Adds a length-prefixed byte string.
    pub fn bytes(&mut self, b: &[u8]) {
        self.u64(b.len() as u64);
        self.flush();
        self.hasher.update(b);
    }

    pub fn u64(&mut self, v: u64) {
        self.buf.extend_from_slice(&v.to_le_bytes());
        if self.buf.len() >= 1 << 16 {
            self.flush();
        }
    }

    pub fn f64(&mut self, v: f64) {
        self.u64(v.to_bits());
    }

    fn flush(&mut self) {
        self.hasher.update(&self.buf);
        self.buf.clear();
    }

    pub fn finish(mut self) -> Key {
        self.flush();
        *self.hasher.finalize().as_bytes()
    }
}

fn hex(key: &Key) -> String {
    key.iter().map(|b| format!("{b:02x}")).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn entries_round_trip_and_damage_reads_as_absent() {
        let dir = std::env::temp_dir().join(format!("texgeo-cache-test-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        let store = Store::at(dir.join("kind-v1"));
        let key = *blake3::hash(b"a key").as_bytes();
        assert_eq!(store.get(&key), None);
        store.put(&key, b"payload bytes");
        assert_eq!(store.get(&key).as_deref(), Some(&b"payload bytes"[..]));
        // Another key never reads this entry, even if the file is copied over.
        let other = *blake3::hash(b"another key").as_bytes();
        std::fs::copy(store.path(&key), store.path(&other)).unwrap();
        assert_eq!(store.get(&other), None);
        // Truncated, flipped or extended files read as absent.
        let good = std::fs::read(store.path(&key)).unwrap();
        for bad in [
            good[..good.len() - 1].to_vec(),
            good.iter().enumerate().map(|(i, &b)| if i == good.len() - 3 { b ^ 1 } else { b }).collect(),
            [good.clone(), b"x".to_vec()].concat(),
            b"garbage".to_vec(),
            Vec::new(),
        ] {
            std::fs::write(store.path(&key), &bad).unwrap();
            assert_eq!(store.get(&key), None);
        }
        // A store whose folder cannot be made is silently skipped.
        let blocked = Store::at(dir.join("kind-v1").join(hex(&key)).join("sub"));
        blocked.put(&key, b"x");
        assert_eq!(blocked.get(&key), None);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
