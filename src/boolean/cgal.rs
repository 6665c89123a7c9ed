//! CGAL as the independent reference (SPEC §6.4): runs the helper
//! `tools/cgal-boolean.cpp` (CGAL 5.5 `Polygon_mesh_processing::corefine_and_compute_*`
//! with the exact-constructions kernel; built by `tools/setup` into
//! `target/tools/cgal-boolean`) on both operands written to temporary OFF files, and
//! reads the volume, area and size of each result back.
//!
//! CGAL computes union, intersection and the two differences; the symmetric difference
//! is (A − B) ∪ (B − A), whose parts have disjoint interiors: its volume is the sum of
//! the differences'. Its area follows from all four: with the surfaces of A and B split
//! into out/in/on-same/on-opposite parts, ∪ + ∩ + (A − B) + (B − A) − A − B counts each
//! out and in part once and each on part zero times, which is the regularized A ⊖ B.
//! CGAL declines results that would not be a 2-manifold (e.g. the union of cubes
//! touching along an edge): those come back as `None` with its reason.

use std::path::{Path, PathBuf};
use std::process::Command;

use super::Operation;
use crate::mesh::{Mesh, formats};
use crate::scratch::ScratchDir;

/// Environment variable naming the helper binary, overriding the default location.
pub const HELPER_ENV: &str = "TEXGEO_CGAL_BOOLEAN";

#[derive(Debug, thiserror::Error)]
pub enum CgalError {
    #[error("the CGAL helper is not built at {} (run tools/setup)", path.display())]
    HelperMissing { path: PathBuf },
    #[error("{}: {source}", path.display())]
    Io { path: PathBuf, source: std::io::Error },
    #[error("writing an operand for CGAL: {0}")]
    Mesh(#[from] crate::mesh::MeshError),
    #[error("CGAL helper {}: {message}", path.display())]
    Helper { path: PathBuf, message: String },
}

pub type Result<T, E = CgalError> = std::result::Result<T, E>;

impl From<crate::output::Error> for CgalError {
    fn from(e: crate::output::Error) -> CgalError {
        CgalError::Io { path: e.path, source: e.error }
    }
}

/// The helper binary: `$TEXGEO_CGAL_BOOLEAN`, else `target/tools/cgal-boolean` of this
/// checkout, else `tools/cgal-boolean` in an ancestor of the running executable.
pub fn helper_path() -> Result<PathBuf> {
    crate::scratch::helper(HELPER_ENV, "cgal-boolean").map_err(|path| CgalError::HelperMissing { path })
}

/// One operation as CGAL computed it.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Outcome {
    /// `None` when CGAL declined, with its reason in `declined`.
    pub volume: Option<f64>,
    pub area: Option<f64>,
    pub vertices: usize,
    pub faces: usize,
    pub declined: Option<String>,
    /// Corefinement time alone (inputs copied outside the clock), with `repeat`.
    pub min_seconds: Option<f64>,
    pub median_seconds: Option<f64>,
}

/// What CGAL says about all operations of one pair.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Reference {
    /// The operands as CGAL measures them.
    pub a: Outcome,
    pub b: Outcome,
    pub union: Outcome,
    pub intersection: Outcome,
    pub difference: Outcome,
    /// B − A.
    pub reverse_difference: Outcome,
}

impl Reference {
    /// (volume, area) of `op`, or `None` when CGAL declined it (or a part of it).
    pub fn measures(&self, op: Operation) -> Option<(f64, f64)> {
        let get = |o: &Outcome| Some((o.volume?, o.area?));
        match op {
            Operation::Union => get(&self.union),
            Operation::Intersection => get(&self.intersection),
            Operation::Difference => get(&self.difference),
            Operation::SymmetricDifference => {
                let (v1, a1) = get(&self.difference)?;
                let (v2, a2) = get(&self.reverse_difference)?;
                let (_, au) = get(&self.union)?;
                let (_, ai) = get(&self.intersection)?;
                let (_, aa) = get(&self.a)?;
                let (_, ab) = get(&self.b)?;
                Some((v1 + v2, au + ai + a1 + a2 - aa - ab))
            }
        }
    }

    /// Median corefinement seconds of `op` (symmetric difference: both differences).
    pub fn median_seconds(&self, op: Operation) -> Option<f64> {
        match op {
            Operation::Union => self.union.median_seconds,
            Operation::Intersection => self.intersection.median_seconds,
            Operation::Difference => self.difference.median_seconds,
            Operation::SymmetricDifference => {
                Some(self.difference.median_seconds? + self.reverse_difference.median_seconds?)
            }
        }
    }
}

/// Runs CGAL on every operation of A and B; with `repeat`, times each one.
pub fn reference(a: &Mesh, b: &Mesh, repeat: Option<u32>) -> Result<Reference> {
    let out = run(a, b, "all", repeat, None)?;
    let mut r = Reference::default();
    for (name, outcome) in out {
        match name.as_str() {
            "a" => r.a = outcome,
            "b" => r.b = outcome,
            "union" => r.union = outcome,
            "intersection" => r.intersection = outcome,
            "difference" => r.difference = outcome,
            "reverse-difference" => r.reverse_difference = outcome,
            _ => {}
        }
    }
    Ok(r)
}

/// CGAL's result mesh of `op` (union, intersection or difference), or its reason to decline.
pub fn result_mesh(a: &Mesh, b: &Mesh, op: Operation) -> Result<std::result::Result<Mesh, String>> {
    let dir = ScratchDir::new("cgal")?;
    let out = dir.join("result.off");
    let name = match op {
        Operation::Union => "union",
        Operation::Intersection => "intersection",
        Operation::Difference => "difference",
        Operation::SymmetricDifference => {
            return Ok(Err("CGAL has no symmetric difference".to_string()));
        }
    };
    let res = run(a, b, name, None, Some(&out))?;
    match res.into_iter().next() {
        Some((_, o)) if o.declined.is_none() => Ok(Ok(formats::read(&out)?)),
        Some((_, o)) => Ok(Err(o.declined.unwrap_or_default())),
        None => Err(CgalError::Helper { path: helper_path()?, message: "no result line".into() }),
    }
}

fn run(
    a: &Mesh,
    b: &Mesh,
    op: &str,
    repeat: Option<u32>,
    output: Option<&Path>,
) -> Result<Vec<(String, Outcome)>> {
    let helper = helper_path()?;
    let dir = ScratchDir::new("cgal")?;
    let (pa, pb) = (dir.join("a.off"), dir.join("b.off"));
    formats::write(&pa, a)?;
    formats::write(&pb, b)?;
    let mut command = Command::new(&helper);
    command.arg(&pa).arg(&pb).arg("--op").arg(op);
    if let Some(n) = repeat {
        command.arg("--repeat").arg(n.max(1).to_string());
    }
    if let Some(out) = output {
        command.arg("-o").arg(out);
    }
    let result = command.output().map_err(|source| CgalError::Io { path: helper.clone(), source })?;
    if !result.status.success() {
        let stderr = String::from_utf8_lossy(&result.stderr);
        return Err(CgalError::Helper {
            path: helper,
            message: format!("{}: {}", result.status, stderr.trim()),
        });
    }
    Ok(parse(&String::from_utf8_lossy(&result.stdout)))
}

/// Reads the helper's `op=NAME key=value …` lines.
fn parse(stdout: &str) -> Vec<(String, Outcome)> {
    let mut out: Vec<(String, Outcome)> = Vec::new();
    for line in stdout.lines() {
        let mut fields = std::collections::HashMap::new();
        let mut reason = None;
        for tok in line.split_whitespace() {
            if let Some((k, v)) = tok.split_once('=') {
                if k == "reason" {
                    reason = Some(line[line.find("reason=").unwrap_or(0) + 7..].to_string());
                    break;
                }
                fields.insert(k, v);
            }
        }
        let Some(&name) = fields.get("op") else { continue };
        let num = |k: &str| fields.get(k).and_then(|v| v.parse::<f64>().ok());
        let idx = match out.iter().position(|(n, _)| n == name) {
            Some(i) => i,
            None => {
                out.push((name.to_string(), Outcome::default()));
                out.len() - 1
            }
        };
        let o = &mut out[idx].1;
        match fields.get("ok") {
            Some(&"1") => {
                o.volume = num("volume");
                o.area = num("area");
                o.vertices = num("vertices").unwrap_or(0.0) as usize;
                o.faces = num("faces").unwrap_or(0.0) as usize;
            }
            Some(_) => o.declined = Some(reason.unwrap_or_else(|| "declined".to_string())),
            None => {
                o.min_seconds = num("min_seconds");
                o.median_seconds = num("median_seconds");
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_result_and_timing_lines() {
        let out = parse(
            "op=union ok=1 volume=1.5 area=9 vertices=12 faces=20\n\
             op=union min_seconds=0.25 median_seconds=0.5\n\
             op=intersection ok=0 reason=corefinement-declined\n",
        );
        assert_eq!(out.len(), 2);
        assert_eq!(out[0].1.volume, Some(1.5));
        assert_eq!(out[0].1.faces, 20);
        assert_eq!(out[0].1.median_seconds, Some(0.5));
        assert_eq!(out[1].1.declined.as_deref(), Some("corefinement-declined"));
    }
}
