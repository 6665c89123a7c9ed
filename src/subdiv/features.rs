//! What a control mesh carries besides its faces: the sharp features (semi-sharp and
//! infinitely sharp creases on edges, corners on vertices, holes) and the scheme-wide
//! options of OpenSubdiv's `Sdc::Options` that change the surface — boundary
//! interpolation, creasing method and the weights of triangles. A [`Surface`] is the
//! three together: everything both refiners (CPU, GPU) and the OpenSubdiv helper need.

use glam::DVec3;

use crate::mesh::Mesh;

pub use super::crease::Method as CreaseMethod;

/// Boundary interpolation (OpenSubdiv's `VtxBoundaryInterpolation`). Boundary edges are
/// infinitely sharp in every mode; the modes differ at corners and at the faces along
/// the boundary.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Boundary {
    /// `VTX_BOUNDARY_NONE`: faces at a boundary vertex with an untagged boundary edge are
    /// holes (the boundary is not interpolated).
    None,
    /// `VTX_BOUNDARY_EDGE_ONLY`: boundary edges are creases, corners follow them.
    #[default]
    EdgeOnly,
    /// `VTX_BOUNDARY_EDGE_AND_CORNER`: also every vertex with one face is a sharp corner.
    EdgeAndCorner,
}

/// Weights at edges next to triangles (OpenSubdiv's `TriangleSubdivision`, Catmull-Clark
/// only). Triangles exist only in the control mesh, so this affects the first level.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Triangles {
    /// `TRI_SUB_CATMARK`: the plain Catmull-Clark masks.
    #[default]
    Catmark,
    /// `TRI_SUB_SMOOTH`: "smooth triangle" weights (face weight 0.47 for a triangle).
    Smooth,
}

/// The scheme-wide options.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Options {
    pub boundary: Boundary,
    pub crease_method: CreaseMethod,
    pub triangles: Triangles,
}

/// A crease: the edge between two vertices and its sharpness (0 smooth, ≥ 10 infinite).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Crease {
    pub vertices: [u32; 2],
    pub sharpness: f32,
}

/// A sharp (corner) vertex.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Corner {
    pub vertex: u32,
    pub sharpness: f32,
}

/// The sharp features of a control mesh, as OpenSubdiv's `Far::TopologyDescriptor` takes
/// them. Later entries for the same edge or vertex replace earlier ones.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Features {
    pub creases: Vec<Crease>,
    pub corners: Vec<Corner>,
    /// Faces that are holes: refined like the others (their neighbours do not change) but
    /// no face is emitted under them.
    pub holes: Vec<u32>,
}

impl Features {
    pub fn is_empty(&self) -> bool {
        self.creases.is_empty() && self.corners.is_empty() && self.holes.is_empty()
    }

    /// Creases of `sharpness` on the *feature edges* of `mesh`: edges with two faces whose
    /// normals differ by more than `degrees` (how a CAD model's sharp edges are usually
    /// tagged before subdivision). Boundary and non-manifold edges are sharp anyway.
    pub fn feature_edges(mesh: &Mesh, degrees: f64, sharpness: f32) -> Features {
        let normals: Vec<DVec3> = mesh
            .faces()
            .map(|f| {
                // Newell's normal: robust for non-planar polygons.
                let mut n = DVec3::ZERO;
                for (i, &a) in f.iter().enumerate() {
                    let (p, q) =
                        (mesh.positions()[a as usize], mesh.positions()[f[(i + 1) % f.len()] as usize]);
                    n += DVec3::new(
                        (p.y - q.y) * (p.z + q.z),
                        (p.z - q.z) * (p.x + q.x),
                        (p.x - q.x) * (p.y + q.y),
                    );
                }
                n.normalize_or_zero()
            })
            .collect();
        let mut uses: Vec<((u32, u32), u32)> = Vec::new();
        for (f, face) in mesh.faces().enumerate() {
            for (i, &a) in face.iter().enumerate() {
                let b = face[(i + 1) % face.len()];
                if a != b {
                    uses.push(((a.min(b), a.max(b)), f as u32));
                }
            }
        }
        uses.sort_unstable();
        let cos = degrees.to_radians().cos();
        let creases = uses
            .chunk_by(|x, y| x.0 == y.0)
            .filter_map(|g| match g {
                [(edge, f0), (_, f1)] if normals[*f0 as usize].dot(normals[*f1 as usize]) < cos => {
                    Some(Crease { vertices: [edge.0, edge.1], sharpness })
                }
                _ => None,
            })
            .collect();
        Features { creases, ..Features::default() }
    }
}

/// A control mesh with its sharp features and scheme options.
#[derive(Clone, Debug, PartialEq)]
pub struct Surface {
    pub mesh: Mesh,
    pub features: Features,
    pub options: Options,
}

impl Surface {
    /// A mesh with no sharp features and the default options (smooth, boundary edges
    /// creased): SPEC §5.1's surface.
    pub fn smooth(mesh: Mesh) -> Surface {
        Surface { mesh, features: Features::default(), options: Options::default() }
    }

    /// True when nothing differs from [`Surface::smooth`].
    pub fn is_plain(&self) -> bool {
        self.features.is_empty() && self.options == Options::default()
    }
}

impl From<Mesh> for Surface {
    fn from(mesh: Mesh) -> Surface {
        Surface::smooth(mesh)
    }
}
