//! Mesh errors: every one names where it happened (file and line or byte offset) when it
//! comes from a file.

use std::path::PathBuf;

pub type Result<T, E = MeshError> = std::result::Result<T, E>;

/// Where in a file a problem was found.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Location {
    Line(usize),
    Byte(u64),
    /// The whole file (e.g. empty, unknown extension).
    File,
}

impl std::fmt::Display for Location {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Location::Line(l) => write!(f, ":{l}"),
            Location::Byte(b) => write!(f, ": byte {b}"),
            Location::File => Ok(()),
        }
    }
}

#[derive(Debug, thiserror::Error)]
pub enum MeshError {
    /// A file could not be opened, read or written. (The I/O error is part of the message,
    /// not a separate `source`, so error chains print it once.)
    #[error("{}: {error}", path.display())]
    Io { path: PathBuf, error: std::io::Error },
    /// A file's contents are wrong: `path:line: message`.
    #[error("{}{location}: {message}", path.display())]
    Parse { path: PathBuf, location: Location, message: String },
    /// The mesh itself is not acceptable (index out of range, NaN, face with < 3 vertices).
    #[error("invalid mesh: {0}")]
    Invalid(String),
    /// An algorithm needs a property the mesh lacks (closed, manifold, …).
    #[error("{0}")]
    Unsuitable(String),
}

impl From<crate::output::Error> for MeshError {
    fn from(e: crate::output::Error) -> MeshError {
        MeshError::Io { path: e.path, error: e.error }
    }
}

impl MeshError {
    pub fn invalid(message: impl Into<String>) -> MeshError {
        MeshError::Invalid(message.into())
    }

    pub fn parse(path: impl Into<PathBuf>, location: Location, message: impl Into<String>) -> MeshError {
        MeshError::Parse { path: path.into(), location, message: message.into() }
    }
}
