//! The meshes of a sweep.
//!
//! A manifest is one of:
//! - a text file: one mesh per line (a path, relative to the manifest's folder, or
//!   `builtin:NAME`); blank lines and lines starting with `#` are skipped;
//! - a `.csv` file with a header: a `mesh` column and, optionally, one column per task
//!   option (`res`, `level`, `method`, …) whose non-empty cells override the sweep's
//!   options for that mesh;
//! - a folder: every `.obj`, `.off`, `.ply` and `.stl` file under it, in path order.
//!
//! A mesh that is missing or unreadable is not a manifest error: it becomes that mesh's
//! result. Two entries with the same name are an error (results are keyed by entry).

use std::path::{Path, PathBuf};
use std::str::FromStr;

use serde_json::{Map, Value};

use super::{Result, SweepError};
use crate::mesh::spec::MeshSpec;

/// One mesh to run.
#[derive(Clone, Debug, PartialEq)]
pub struct Entry {
    /// Position in the manifest (0-based).
    pub index: usize,
    /// The name results carry: the manifest's text, or the path under a folder.
    pub mesh: String,
    /// What to load: `builtin:NAME` or a path resolved against the manifest's folder.
    pub path: String,
    /// Manifest line (1-based) for messages; `None` for folders.
    pub line: Option<usize>,
    /// Per-mesh option overrides (CSV manifests).
    pub options: Map<String, Value>,
}

/// The entries of a manifest, in order.
#[derive(Clone, Debug)]
pub struct Manifest {
    pub source: PathBuf,
    pub entries: Vec<Entry>,
}

const MESH_EXTENSIONS: [&str; 4] = ["obj", "off", "ply", "stl"];

impl Manifest {
    /// Reads a manifest file or folder.
    pub fn read(path: &Path) -> Result<Manifest> {
        let meta = std::fs::metadata(path).map_err(|e| SweepError::io(path, e))?;
        let mut manifest = if meta.is_dir() {
            Manifest::folder(path)?
        } else {
            let text = std::fs::read_to_string(path).map_err(|e| SweepError::io(path, e))?;
            let base = path.parent().unwrap_or(Path::new(""));
            let csv = path.extension().is_some_and(|e| e.eq_ignore_ascii_case("csv"));
            let entries = if csv { csv_entries(path, base, &text)? } else { list_entries(base, &text) };
            Manifest { source: path.to_path_buf(), entries }
        };
        if manifest.entries.is_empty() {
            return Err(SweepError::Manifest {
                path: path.to_path_buf(),
                line: None,
                message: "no meshes listed".into(),
            });
        }
        let mut seen = std::collections::HashMap::new();
        for (i, e) in manifest.entries.iter_mut().enumerate() {
            e.index = i;
            if let Some(first) = seen.insert(e.mesh.clone(), e.line) {
                return Err(SweepError::Manifest {
                    path: path.to_path_buf(),
                    line: e.line,
                    message: format!(
                        "'{}' is listed twice{}",
                        e.mesh,
                        first.map(|l| format!(" (first on line {l})")).unwrap_or_default()
                    ),
                });
            }
        }
        Ok(manifest)
    }

    fn folder(dir: &Path) -> Result<Manifest> {
        let mut files = Vec::new();
        walk(dir, &mut files)?;
        let mut names: Vec<(String, PathBuf)> = files
            .into_iter()
            .filter_map(|p| {
                let rel = p.strip_prefix(dir).ok()?;
                let name =
                    rel.components().map(|c| c.as_os_str().to_string_lossy()).collect::<Vec<_>>().join("/");
                Some((name, p))
            })
            .collect();
        names.sort();
        let entries = names
            .into_iter()
            .map(|(mesh, p)| Entry {
                index: 0,
                mesh,
                path: p.to_string_lossy().into_owned(),
                line: None,
                options: Map::new(),
            })
            .collect();
        Ok(Manifest { source: dir.to_path_buf(), entries })
    }

    /// The entries shard `shard` runs: every `count`-th from the `index`-th, so shards of a
    /// size-sorted manifest get similar work.
    pub fn shard(&self, shard: Shard) -> impl Iterator<Item = &Entry> {
        self.entries.iter().filter(move |e| shard.contains(e.index))
    }
}

fn walk(dir: &Path, out: &mut Vec<PathBuf>) -> Result<()> {
    for item in std::fs::read_dir(dir).map_err(|e| SweepError::io(dir, e))? {
        let path = item.map_err(|e| SweepError::io(dir, e))?.path();
        if path.is_dir() {
            walk(&path, out)?;
        } else if path
            .extension()
            .and_then(|e| e.to_str())
            .is_some_and(|e| MESH_EXTENSIONS.contains(&e.to_ascii_lowercase().as_str()))
        {
            out.push(path);
        }
    }
    Ok(())
}

fn resolve(base: &Path, mesh: &str) -> String {
    MeshSpec::parse(mesh).in_folder(base).to_string()
}

fn list_entries(base: &Path, text: &str) -> Vec<Entry> {
    text.lines()
        .enumerate()
        .filter_map(|(n, line)| {
            let mesh = line.trim();
            (!mesh.is_empty() && !mesh.starts_with('#')).then(|| Entry {
                index: 0,
                mesh: mesh.to_string(),
                path: resolve(base, mesh),
                line: Some(n + 1),
                options: Map::new(),
            })
        })
        .collect()
}

fn csv_entries(path: &Path, base: &Path, text: &str) -> Result<Vec<Entry>> {
    let err = |line: Option<usize>, message: String| SweepError::Manifest {
        path: path.to_path_buf(),
        line,
        message,
    };
    let mut reader =
        csv::ReaderBuilder::new().trim(csv::Trim::All).comment(Some(b'#')).from_reader(text.as_bytes());
    let header: Vec<String> =
        reader.headers().map_err(|e| err(Some(1), e.to_string()))?.iter().map(str::to_string).collect();
    let mesh_col = header
        .iter()
        .position(|h| h == "mesh")
        .ok_or_else(|| err(Some(1), "the header has no 'mesh' column".into()))?;
    let mut entries = Vec::new();
    for row in reader.records() {
        let row = row.map_err(|e| err(e.position().map(|p| p.line() as usize), e.to_string()))?;
        let line = row.position().map(|p| p.line() as usize);
        let mesh = row.get(mesh_col).unwrap_or("").to_string();
        if mesh.is_empty() {
            return Err(err(line, "empty 'mesh' cell".into()));
        }
        let mut options = Map::new();
        for (k, cell) in header.iter().zip(row.iter()) {
            if k != "mesh" && !cell.is_empty() {
                options.insert(k.clone(), typed_value(cell));
            }
        }
        entries.push(Entry { index: 0, path: resolve(base, &mesh), mesh, line, options });
    }
    Ok(entries)
}

/// A text option value as JSON: booleans, integers and decimals by their looks, else a
/// string (so `64` sets a number option and `gpu` a name).
pub fn typed_value(s: &str) -> Value {
    match s {
        "true" => Value::Bool(true),
        "false" => Value::Bool(false),
        _ => {
            if let Ok(u) = s.parse::<u64>() {
                Value::from(u)
            } else if let Ok(i) = s.parse::<i64>() {
                Value::from(i)
            } else if let Some(n) =
                s.parse::<f64>().ok().filter(|f| f.is_finite()).and_then(serde_json::Number::from_f64)
            {
                Value::Number(n)
            } else {
                Value::String(s.to_string())
            }
        }
    }
}

/// Shard `index` of `count` (`--shard I/N`, 0-based like `SLURM_ARRAY_TASK_ID`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Shard {
    pub index: usize,
    pub count: usize,
}

impl Shard {
    pub const WHOLE: Shard = Shard { index: 0, count: 1 };

    pub fn contains(&self, entry: usize) -> bool {
        entry % self.count == self.index
    }
}

impl FromStr for Shard {
    type Err = String;

    fn from_str(s: &str) -> std::result::Result<Shard, String> {
        let bad = || format!("shard '{s}' is not I/N with 0 <= I < N (e.g. 0/4)");
        let (i, n) = s.split_once('/').ok_or_else(bad)?;
        let index: usize = i.trim().parse().map_err(|_| bad())?;
        let count: usize = n.trim().parse().map_err(|_| bad())?;
        if count == 0 || index >= count {
            return Err(bad());
        }
        Ok(Shard { index, count })
    }
}

impl std::fmt::Display for Shard {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn temp(name: &str, text: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("texgeo-manifest-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join(name);
        std::fs::write(&p, text).unwrap();
        p
    }

    #[test]
    fn lists_csv_and_errors() {
        let m = Manifest::read(&temp("list.txt", "# meshes\nbuiltin:cube\n\n  a/b.off \n")).unwrap();
        let names: Vec<_> = m.entries.iter().map(|e| (e.index, e.mesh.as_str(), e.line)).collect();
        assert_eq!(names, [(0, "builtin:cube", Some(2)), (1, "a/b.off", Some(4))]);
        assert!(m.entries[1].path.ends_with("a/b.off") && Path::new(&m.entries[1].path).is_absolute());

        let m =
            Manifest::read(&temp("m.csv", "mesh,res,method\nbuiltin:cube,32,\nbuiltin:knot,,cpu\n")).unwrap();
        assert_eq!(m.entries[0].options.get("res"), Some(&Value::from(32u64)));
        assert!(!m.entries[0].options.contains_key("method"));
        assert_eq!(m.entries[1].options.get("method"), Some(&Value::from("cpu")));
        assert_eq!(m.entries[1].line, Some(3));

        let e = Manifest::read(&temp("dup.txt", "builtin:cube\nbuiltin:knot\nbuiltin:cube\n")).unwrap_err();
        assert!(
            e.to_string().ends_with("dup.txt:3: 'builtin:cube' is listed twice (first on line 1)"),
            "{e}"
        );
        let e = Manifest::read(&temp("nomesh.csv", "path,res\nx.off,3\n")).unwrap_err();
        assert!(e.to_string().ends_with("nomesh.csv:1: the header has no 'mesh' column"), "{e}");
        let e = Manifest::read(&temp("empty.txt", "# nothing\n")).unwrap_err();
        assert!(e.to_string().ends_with("empty.txt: no meshes listed"), "{e}");
    }

    #[test]
    fn a_folder_lists_its_mesh_files_in_path_order() {
        let dir = temp("folder.txt", "").with_file_name("folder");
        std::fs::create_dir_all(dir.join("sub")).unwrap();
        for f in ["b.off", "a.STL", "notes.txt", "sub/c.ply"] {
            std::fs::write(dir.join(f), "").unwrap();
        }
        let m = Manifest::read(&dir).unwrap();
        let names: Vec<_> = m.entries.iter().map(|e| (e.index, e.mesh.as_str())).collect();
        assert_eq!(names, [(0, "a.STL"), (1, "b.off"), (2, "sub/c.ply")]);
        assert!(m.entries[2].path.ends_with("folder/sub/c.ply"));
    }

    #[test]
    fn shards_partition_the_entries() {
        assert_eq!("1/4".parse::<Shard>(), Ok(Shard { index: 1, count: 4 }));
        for bad in ["4/4", "1", "a/2", "0/0"] {
            assert!(bad.parse::<Shard>().is_err(), "{bad}");
        }
        let m =
            Manifest::read(&temp("many.txt", &(0..10).map(|i| format!("m{i}.off\n")).collect::<String>()))
                .unwrap();
        let mut all: Vec<usize> = (0..3)
            .flat_map(|i| m.shard(Shard { index: i, count: 3 }).map(|e| e.index).collect::<Vec<_>>())
            .collect();
        all.sort();
        assert_eq!(all, (0..10).collect::<Vec<_>>());
    }
}
