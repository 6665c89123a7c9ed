//! Sharp features and scheme options in OBJ files, as OpenSubdiv's regression shapes
//! (`regression/shapes`, read by its `shape_utils`) write them: one tag per line,
//!
//! ```text
//! t NAME nint/nfloat/nstring int… float… string…
//! ```
//!
//! with 0-based vertex and face indices (counted in the file, before texgeo drops
//! vertices no face uses). The tags that change the surface:
//!
//! | tag | arguments | meaning |
//! |---|---|---|
//! | `crease` | vertex pairs; one sharpness, or one per pair | edge sharpness |
//! | `corner` | vertices; one sharpness, or one each | vertex sharpness |
//! | `hole` | faces | holes |
//! | `interpolateboundary` | 0, 1 or 2 | boundary none, edge-and-corner, edge-only |
//! | `creasemethod` | `normal` (or `uniform`) / `chaikin` | creasing method |
//! | `smoothtriangles` | `catmark` / `smooth` | triangle weights |
//!
//! Other tags (face-varying options, hierarchical edits, …) do not change positions: they
//! are listed in [`Tagged::ignored`] with their line and otherwise ignored. A malformed
//! tag, a crease on vertices no edge joins, an index out of range or a negative sharpness
//! is an error naming file and line.

use std::collections::HashSet;
use std::io::Write;
use std::path::Path;

use crate::mesh::error::Location;
use crate::mesh::formats::{self, obj::Tags};
use crate::mesh::{Mesh, MeshError};

use super::features::{Boundary, Corner, Crease, CreaseMethod, Features, Options, Surface, Triangles};
use super::{Result, SubdivError};

/// The scheme options a file's tags set (`None`: not set by a tag).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct TaggedOptions {
    pub boundary: Option<Boundary>,
    pub crease_method: Option<CreaseMethod>,
    pub triangles: Option<Triangles>,
}

impl TaggedOptions {
    /// The tagged options over `defaults`.
    pub fn over(&self, defaults: Options) -> Options {
        Options {
            boundary: self.boundary.unwrap_or(defaults.boundary),
            crease_method: self.crease_method.unwrap_or(defaults.crease_method),
            triangles: self.triangles.unwrap_or(defaults.triangles),
        }
    }
}

/// A tag that was read but does not change the surface.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Ignored {
    pub line: usize,
    pub name: String,
    pub why: String,
}

/// A mesh file read with its tags.
#[derive(Clone, Debug, PartialEq)]
pub struct Tagged {
    pub mesh: Mesh,
    pub features: Features,
    pub options: TaggedOptions,
    pub ignored: Vec<Ignored>,
}

impl Tagged {
    /// The surface, with the tagged options over `defaults`.
    pub fn surface(self, defaults: Options) -> Surface {
        Surface { options: self.options.over(defaults), mesh: self.mesh, features: self.features }
    }
}

/// Interprets the tags the OBJ reader kept ([`crate::mesh::spec::MeshSpec::load_with_tags`])
/// on their mesh; `path` only names the file in errors.
pub fn interpret(mesh: Mesh, tags: &Tags, path: &Path) -> Result<Tagged> {
    let mut parser = Parser::new(path, &mesh, &tags.vertices);
    for tag in &tags.tags {
        parser.tag(tag.line, tag.words.iter().map(String::as_str).collect())?;
    }
    let Parser { features, options, ignored, .. } = parser;
    Ok(Tagged { mesh, features, options, ignored })
}

struct Parser<'a> {
    path: &'a Path,
    mesh: &'a Mesh,
    /// File vertex → mesh vertex (`u32::MAX`: no face uses it).
    map: &'a [u32],
    /// The mesh's edges as sorted vertex pairs.
    edges: HashSet<(u32, u32)>,
    features: Features,
    options: TaggedOptions,
    ignored: Vec<Ignored>,
}

/// One `t` line: its name and its integer, float (sharpness) and string arguments.
struct Tag<'w> {
    path: &'w Path,
    line: usize,
    name: &'w str,
    ints: Vec<u32>,
    floats: Vec<f32>,
    strings: Vec<&'w str>,
}

impl<'w> Tag<'w> {
    /// `NAME nint/nfloat/nstring ARGS…`: the counts must match the arguments, the
    /// integers be indices and the floats sharpnesses.
    fn parse(path: &'w Path, line: usize, words: &[&'w str]) -> Result<Tag<'w>> {
        let err = |m: String| -> SubdivError { MeshError::parse(path, Location::Line(line), m).into() };
        let [name, counts, args @ ..] = words else {
            return Err(err("a tag needs a name and 'nint/nfloat/nstring' counts".into()));
        };
        let counts: Vec<usize> = counts.split('/').map(|c| c.parse().unwrap_or(usize::MAX)).collect();
        let &[nint, nfloat, nstring] = counts.as_slice() else {
            return Err(err(format!(
                "tag '{name}': expected 'nint/nfloat/nstring' counts, found '{}'",
                words[1]
            )));
        };
        if [nint, nfloat, nstring].contains(&usize::MAX) || nint + nfloat + nstring != args.len() {
            return Err(err(format!(
                "tag '{name}': '{}' does not match its {} arguments",
                words[1],
                args.len()
            )));
        }
        let ints: Vec<u32> = args[..nint]
            .iter()
            .map(|a| a.parse::<u32>().map_err(|_| err(format!("tag '{name}': '{a}' is not an index"))))
            .collect::<Result<_>>()?;
        let floats: Vec<f32> = args[nint..nint + nfloat]
            .iter()
            .map(|a| match a.parse::<f32>() {
                Ok(s) if s.is_finite() && s >= 0.0 => Ok(s),
                _ => Err(err(format!("tag '{name}': '{a}' is not a sharpness (a finite number ≥ 0)"))),
            })
            .collect::<Result<_>>()?;
        let strings = args[nint + nfloat..].to_vec();
        Ok(Tag { path, line, name, ints, floats, strings })
    }

    fn error(&self, message: String) -> SubdivError {
        MeshError::parse(self.path, Location::Line(self.line), message).into()
    }

    /// The sharpness of item `i` of `items`: one for all items or one each.
    fn sharpness(&self, i: usize, items: usize) -> Result<f32> {
        let name = self.name;
        match self.floats.len() {
            1 => Ok(self.floats[0]),
            n if n == items => Ok(self.floats[i]),
            n => Err(self
                .error(format!("tag '{name}': {n} sharpness values for {items} items (give 1 or {items})"))),
        }
    }

    /// The one integer argument (`what` it means).
    fn one_int(&self, what: &str) -> Result<u32> {
        match self.ints.as_slice() {
            [i] if self.floats.is_empty() && self.strings.is_empty() => Ok(*i),
            _ => Err(self.error(format!("tag '{}' takes one integer ({what})", self.name))),
        }
    }

    /// The one string argument (`what` it may be).
    fn one_string(&self, what: &str) -> Result<&'w str> {
        match self.strings.as_slice() {
            [s] if self.ints.is_empty() && self.floats.is_empty() => Ok(*s),
            _ => Err(self.error(format!("tag '{}' takes one string ({what})", self.name))),
        }
    }
}

impl<'a> Parser<'a> {
    fn new(path: &'a Path, mesh: &'a Mesh, map: &'a [u32]) -> Parser<'a> {
        Parser {
            path,
            mesh,
            map,
            edges: HashSet::new(),
            features: Features::default(),
            options: TaggedOptions::default(),
            ignored: Vec::new(),
        }
    }

    fn error(&self, line: usize, message: String) -> SubdivError {
        MeshError::parse(self.path, Location::Line(line), message).into()
    }

    fn tag(&mut self, line: usize, words: Vec<&str>) -> Result<()> {
        let tag = Tag::parse(self.path, line, &words)?;
        let err = |m: String| tag.error(m);
        match tag.name {
            "crease" => self.crease(&tag)?,
            "corner" => self.corner(&tag)?,
            "hole" => self.hole(&tag)?,
            "interpolateboundary" => {
                self.options.boundary =
                    Some(match tag.one_int("0 none, 1 edge-and-corner, 2 edge-only")? {
                        0 => Boundary::None,
                        1 => Boundary::EdgeAndCorner,
                        2 => Boundary::EdgeOnly,
                        n => return Err(err(format!("tag 'interpolateboundary': {n} is not 0, 1 or 2"))),
                    });
            }
            "creasemethod" => {
                self.options.crease_method = Some(match tag.one_string("normal or chaikin")? {
                    "normal" | "uniform" => CreaseMethod::Uniform,
                    "chaikin" => CreaseMethod::Chaikin,
                    s => return Err(err(format!("tag 'creasemethod': '{s}' is not normal or chaikin"))),
                });
            }
            "smoothtriangles" => {
                self.options.triangles = Some(match tag.one_string("catmark or smooth")? {
                    "catmark" => Triangles::Catmark,
                    "smooth" => Triangles::Smooth,
                    s => return Err(err(format!("tag 'smoothtriangles': '{s}' is not catmark or smooth"))),
                });
            }
            other => self.ignored.push(Ignored {
                line,
                name: other.to_string(),
                why: "does not change vertex positions".into(),
            }),
        }
        Ok(())
    }

    /// `t crease 2n/1/0 a b …`: each vertex pair an edge of the mesh.
    fn crease(&mut self, tag: &Tag) -> Result<()> {
        let ints = &tag.ints;
        if ints.is_empty() || ints.len() % 2 != 0 {
            return Err(tag.error("tag 'crease' takes vertex pairs".into()));
        }
        if self.edges.is_empty() {
            self.edges = mesh_edges(self.mesh);
        }
        let pairs = ints.len() / 2;
        for i in 0..pairs {
            let [a, b] = [self.vertex(tag.line, ints[2 * i])?, self.vertex(tag.line, ints[2 * i + 1])?];
            let (Some(a), Some(b)) = (a, b) else {
                return Err(tag.error(format!(
                    "tag 'crease': vertices {} and {} are not joined by an edge (no face uses one of them)",
                    ints[2 * i],
                    ints[2 * i + 1]
                )));
            };
            if !self.edges.contains(&(a.min(b), a.max(b))) {
                return Err(tag.error(format!(
                    "tag 'crease': vertices {} and {} are not joined by an edge",
                    ints[2 * i],
                    ints[2 * i + 1]
                )));
            }
            let sharpness = tag.sharpness(i, pairs)?;
            self.features.creases.push(Crease { vertices: [a, b], sharpness });
        }
        Ok(())
    }

    /// `t corner n/1/0 v …`: a vertex no face uses is ignored (the mesh drops it).
    fn corner(&mut self, tag: &Tag) -> Result<()> {
        if tag.ints.is_empty() {
            return Err(tag.error("tag 'corner' takes vertices".into()));
        }
        for (i, &v) in tag.ints.iter().enumerate() {
            let sharpness = tag.sharpness(i, tag.ints.len())?;
            match self.vertex(tag.line, v)? {
                Some(vertex) => self.features.corners.push(Corner { vertex, sharpness }),
                None => self.ignored.push(Ignored {
                    line: tag.line,
                    name: "corner".into(),
                    why: format!("vertex {v} is used by no face (texgeo drops it)"),
                }),
            }
        }
        Ok(())
    }

    /// `t hole n/0/0 f …`: faces of the mesh.
    fn hole(&mut self, tag: &Tag) -> Result<()> {
        if !tag.floats.is_empty() || !tag.strings.is_empty() {
            return Err(tag.error("tag 'hole' takes only face indices".into()));
        }
        for &f in &tag.ints {
            if f as usize >= self.mesh.num_faces() {
                return Err(tag.error(format!(
                    "tag 'hole': face {f} is out of range ({} faces)",
                    self.mesh.num_faces()
                )));
            }
            self.features.holes.push(f);
        }
        Ok(())
    }

    /// The mesh vertex of file vertex `v`: `None` when no face uses it.
    fn vertex(&self, line: usize, v: u32) -> Result<Option<u32>> {
        match self.map.get(v as usize) {
            None => Err(self.error(
                line,
                format!(
                    "vertex {v} is out of range ({} vertices in the file; tags count from 0)",
                    self.map.len()
                ),
            )),
            Some(&m) => Ok((m != u32::MAX).then_some(m)),
        }
    }
}

/// The edges of `mesh` as sorted vertex pairs.
fn mesh_edges(mesh: &Mesh) -> HashSet<(u32, u32)> {
    let mut edges = HashSet::new();
    for face in mesh.faces() {
        for (i, &a) in face.iter().enumerate() {
            let b = face[(i + 1) % face.len()];
            edges.insert((a.min(b), a.max(b)));
        }
    }
    edges
}

/// Writes `surface` as OBJ with its features and options as tags (one tag per crease,
/// corner and hole; sharpness with the shortest decimals that read back to the same `f32`).
pub fn write_obj(out: &mut impl Write, surface: &Surface) -> std::io::Result<()> {
    let mut w = std::io::BufWriter::new(out);
    formats::obj::write(&mut w, &surface.mesh)?;
    let Surface { features, options, .. } = surface;
    for c in &features.creases {
        writeln!(w, "t crease 2/1/0 {} {} {}", c.vertices[0], c.vertices[1], c.sharpness)?;
    }
    for c in &features.corners {
        writeln!(w, "t corner 1/1/0 {} {}", c.vertex, c.sharpness)?;
    }
    if !features.holes.is_empty() {
        write!(w, "t hole {}/0/0", features.holes.len())?;
        for f in &features.holes {
            write!(w, " {f}")?;
        }
        writeln!(w)?;
    }
    let boundary = match options.boundary {
        Boundary::None => 0,
        Boundary::EdgeAndCorner => 1,
        Boundary::EdgeOnly => 2,
    };
    writeln!(w, "t interpolateboundary 1/0/0 {boundary}")?;
    let method = match options.crease_method {
        CreaseMethod::Uniform => "normal",
        CreaseMethod::Chaikin => "chaikin",
    };
    writeln!(w, "t creasemethod 0/0/1 {method}")?;
    let triangles = match options.triangles {
        Triangles::Catmark => "catmark",
        Triangles::Smooth => "smooth",
    };
    writeln!(w, "t smoothtriangles 0/0/1 {triangles}")?;
    w.flush()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn read(text: &str) -> Result<Tagged> {
        let path = Path::new("test.obj");
        let (mesh, tags) = formats::obj::read_with_tags(text.as_bytes(), path)?;
        interpret(mesh, &tags, path)
    }

    const SQUARE: &str = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 5 5 5\nf 1 2 3 4\n";

    #[test]
    fn reads_the_regression_shape_tags() {
        let t = read(&format!(
            "{SQUARE}t crease 2/1/0 0 1 2.5\nt corner 2/1/0 2 3 10\nt hole 1/0/0 0\n\
             t interpolateboundary 1/0/0 1\nt creasemethod 0/0/1 chaikin\nt smoothtriangles 0/0/1 smooth\n\
             t facevaryinginterpolateboundary 1/0/0 1\n"
        ))
        .unwrap();
        assert_eq!(t.features.creases, [Crease { vertices: [0, 1], sharpness: 2.5 }]);
        assert_eq!(t.features.corners.len(), 2);
        assert_eq!(t.features.holes, [0]);
        assert_eq!(t.options.boundary, Some(Boundary::EdgeAndCorner));
        assert_eq!(t.options.crease_method, Some(CreaseMethod::Chaikin));
        assert_eq!(t.options.triangles, Some(Triangles::Smooth));
        assert_eq!(t.ignored.len(), 1);
        assert_eq!((t.ignored[0].line, t.ignored[0].name.as_str()), (13, "facevaryinginterpolateboundary"));
        // Round trip through the writer.
        let surface = t.surface(Options::default());
        let mut out = Vec::new();
        write_obj(&mut out, &surface).unwrap();
        let again = read(std::str::from_utf8(&out).unwrap()).unwrap().surface(Options::default());
        assert_eq!(again, surface);
    }

    #[test]
    fn bad_tags_name_the_line() {
        for (tag, want) in [
            ("t crease 2/1/0 0 2 1", "not joined by an edge"),
            ("t crease 2/1/0 0 9 1", "out of range"),
            ("t crease 3/1/0 0 1 2 1", "vertex pairs"),
            ("t crease 2/1/0 0 1 -1", "not a sharpness"),
            ("t corner 2/2/0 0 1 1", "does not match"),
            ("t hole 1/0/0 3", "out of range"),
            ("t interpolateboundary 1/0/0 7", "not 0, 1 or 2"),
            ("t creasemethod 0/0/1 fancy", "not normal or chaikin"),
            ("t crease", "counts"),
            ("t crease 2-1-0 0 1 1", "counts"),
        ] {
            let err = read(&format!("{SQUARE}{tag}\n")).unwrap_err().to_string();
            assert!(err.contains("test.obj:7") && err.contains(want), "{tag}: {err}");
        }
    }
}
