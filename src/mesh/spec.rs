//! How a mesh is named — on the command line, in a sweep manifest, in a task's options —
//! and read: a file path (any bytes the system allows, not only UTF-8) or `builtin:NAME`
//! (one of [`procedural::BUILTIN_NAMES`]), placed by transform steps after `@` where a
//! command takes them ([`Placed`]). Every command and the sweep parse names here and load
//! through [`MeshSpec::load`]; an OBJ file's tags come back as data
//! ([`MeshSpec::load_with_tags`]) for subdivision to interpret.

use std::ffi::{OsStr, OsString};
use std::fmt;
use std::os::unix::ffi::OsStrExt as _;
use std::path::{Path, PathBuf};

use super::formats::{self, Format, obj::Tags};
use super::transform::Transform;
use super::{Mesh, MeshError, Result, procedural};

const BUILTIN: &str = "builtin:";

/// A mesh file or a built-in model.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum MeshSpec {
    /// `builtin:NAME`: the NAME.
    Builtin(String),
    File(PathBuf),
}

impl MeshSpec {
    /// `builtin:NAME` or a path.
    pub fn parse(s: impl AsRef<OsStr>) -> MeshSpec {
        let s = s.as_ref();
        match s.to_str().and_then(|s| s.strip_prefix(BUILTIN)) {
            Some(name) => MeshSpec::Builtin(name.to_string()),
            None => MeshSpec::File(s.into()),
        }
    }

    /// The NAME of `builtin:NAME`.
    pub fn builtin(&self) -> Option<&str> {
        match self {
            MeshSpec::Builtin(name) => Some(name),
            MeshSpec::File(_) => None,
        }
    }

    /// The file, unless it is a built-in model.
    pub fn file(&self) -> Option<&Path> {
        match self {
            MeshSpec::Builtin(_) => None,
            MeshSpec::File(path) => Some(path),
        }
    }

    /// The files among `specs` (for "never overwrite an input").
    pub fn files<'a>(specs: impl IntoIterator<Item = &'a MeshSpec>) -> Vec<&'a Path> {
        specs.into_iter().filter_map(MeshSpec::file).collect()
    }

    /// A relative file taken relative to `folder`; built-ins and absolute paths as they are.
    pub fn in_folder(self, folder: &Path) -> MeshSpec {
        match self {
            MeshSpec::File(path) => MeshSpec::File(folder.join(path)),
            builtin => builtin,
        }
    }

    /// Reads the file, or builds the built-in model.
    pub fn load(&self) -> Result<Mesh> {
        match self {
            MeshSpec::Builtin(name) => builtin(name),
            MeshSpec::File(path) => formats::read(path),
        }
    }

    /// Reads the mesh with an OBJ file's tags (`t` lines), uninterpreted; other formats and
    /// built-in models have none.
    pub fn load_with_tags(&self) -> Result<(Mesh, Tags)> {
        match self {
            MeshSpec::File(path) if Format::from_path(path)? == Format::Obj => {
                let bytes = formats::read_file(path, Format::Obj)?;
                formats::obj::read_with_tags(&bytes, path)
            }
            _ => Ok((self.load()?, Tags::default())),
        }
    }
}

/// A mesh and the steps that place it ([`Transform`]): `MESH` or `MESH@STEPS`, e.g.
/// `part.off@"rotate z 90; translate 1 0 0"` or `builtin:cube@scale 2`, as `texgeo csg`'s
/// operands, the sweep's second operands and Python's `load` name them. MESH is split at
/// the last `@` unless the whole text names an existing file (a file name with `@` in it
/// and no steps).
#[derive(Clone, Debug, PartialEq)]
pub struct Placed {
    pub spec: MeshSpec,
    /// The steps after `@` (`None`: none given).
    pub transform: Option<Transform>,
}

impl Placed {
    /// `MESH` or `MESH@STEPS`; the error says what is wrong with the steps.
    pub fn parse(s: impl AsRef<OsStr>) -> std::result::Result<Placed, String> {
        let s = s.as_ref();
        let bytes = s.as_bytes();
        match bytes.iter().rposition(|&c| c == b'@') {
            Some(at) if !Path::new(s).is_file() => {
                let steps = std::str::from_utf8(&bytes[at + 1..])
                    .map_err(|_| "the transform after '@' is not text".to_string())?;
                let transform = Transform::parse(steps)?;
                Ok(Placed {
                    spec: MeshSpec::parse(OsStr::from_bytes(&bytes[..at])),
                    transform: Some(transform),
                })
            }
            _ => Ok(Placed { spec: MeshSpec::parse(s), transform: None }),
        }
    }

    /// Reads the mesh and places it.
    pub fn load(&self) -> Result<Mesh> {
        let mesh = self.spec.load()?;
        match &self.transform {
            Some(t) => t.apply(&mesh),
            None => Ok(mesh),
        }
    }
}

/// The built-in model NAME, or an error listing the built-ins.
fn builtin(name: &str) -> Result<Mesh> {
    procedural::by_name(name).ok_or_else(|| {
        MeshError::Unsuitable(format!(
            "no built-in model '{name}' (built-ins: {})",
            procedural::BUILTIN_NAMES.join(", ")
        ))
    })
}

impl fmt::Display for MeshSpec {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            MeshSpec::Builtin(name) => write!(f, "{BUILTIN}{name}"),
            MeshSpec::File(path) => path.display().fmt(f),
        }
    }
}

// Conversions clap uses for arguments (any OS string), and code for names it builds.
impl From<OsString> for MeshSpec {
    fn from(s: OsString) -> MeshSpec {
        MeshSpec::parse(s)
    }
}

impl From<PathBuf> for MeshSpec {
    fn from(p: PathBuf) -> MeshSpec {
        MeshSpec::parse(p)
    }
}

impl From<&str> for MeshSpec {
    fn from(s: &str) -> MeshSpec {
        MeshSpec::parse(s)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_parse_and_print_back() {
        for s in ["builtin:knot", "a/b.off", "/abs/c.obj", "builtin"] {
            assert_eq!(MeshSpec::parse(s).to_string(), s);
        }
        assert_eq!(MeshSpec::parse("builtin:cube").builtin(), Some("cube"));
        assert_eq!(MeshSpec::parse("builtin:cube").file(), None);
        assert_eq!(MeshSpec::parse("x.off").file(), Some(Path::new("x.off")));
    }

    #[test]
    fn relative_files_move_into_the_folder_only() {
        let base = Path::new("/m");
        assert_eq!(MeshSpec::parse("a.off").in_folder(base), MeshSpec::parse("/m/a.off"));
        assert_eq!(MeshSpec::parse("/x/a.off").in_folder(base), MeshSpec::parse("/x/a.off"));
        assert_eq!(MeshSpec::parse("builtin:cube").in_folder(base), MeshSpec::parse("builtin:cube"));
    }

    #[test]
    fn an_unknown_builtin_names_the_known_ones() {
        let e = MeshSpec::parse("builtin:nope").load().unwrap_err().to_string();
        assert!(e.starts_with("no built-in model 'nope' (built-ins: "), "{e}");
        assert_eq!(MeshSpec::parse("builtin:cube").load().unwrap(), procedural::cube());
    }
}
