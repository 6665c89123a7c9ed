//! Reference Catmull-Clark on the CPU (SPEC §5.1): any manifold polygon mesh, closed or
//! open, any level, f64; the same surface as OpenSubdiv's `CATMARK` with
//! `VTX_BOUNDARY_EDGE_ONLY` and `TRI_SUB_CATMARK`, in the same vertex order.
//!
//! Only the base level is built by sorting ([`Topology`]); every finer level's topology
//! is derived arithmetically from its parent's, because the numbering of child elements
//! is fixed by the parent's (OpenSubdiv's order):
//!
//! - child vertices: the parent's vertex points, then its face points, then its edge points;
//! - child faces: `n` quads per parent face of `n` sides, one per corner, in face order;
//! - child edges: one per parent face corner (face point → edge point), then two per
//!   parent edge (edge point → each end's vertex point).
//!
//! The masks (the thesis' "máscaras", Ch. 2.2) are applied by scattering each face point
//! and each edge's ends into the sums the edge and vertex masks need, so no level keeps
//! vertex→edge or edge→face tables.

use glam::DVec3;

use crate::mesh::Mesh;

use super::topology::Topology;
use super::{Result, SubdivError};

/// Refines `mesh` `levels` times with Catmull-Clark; after one level every face is a quad.
/// Level 0 returns a copy once the topology has been checked.
pub fn refine(mesh: &Mesh, levels: u32) -> Result<Mesh> {
    let topology = Topology::new(mesh)?;
    if levels == 0 {
        return Ok(mesh.clone());
    }
    let mut level = Level::base(mesh, &topology);
    for l in 1..=levels {
        level.check_size(l)?;
        level = level.refine(l < levels);
    }
    level.into_mesh()
}

/// Set in a `face_edges` entry when the face traverses the edge against its orientation.
const REVERSED: u32 = 1;

/// Faces of a level: polygons at the base, quads (4 corners each) after.
enum Faces {
    Polygons(Vec<u32>),
    Quads,
}

/// One subdivision level: positions plus the topology needed to refine it once more.
struct Level {
    positions: Vec<DVec3>,
    faces: Faces,
    /// Vertex of each face corner.
    face_verts: Vec<u32>,
    /// Edge leaving each face corner, `edge << 1 | REVERSED?`.
    face_edges: Vec<u32>,
    /// The two vertices of each edge, in the edge's orientation.
    edge_verts: Vec<[u32; 2]>,
    /// Edges with a single face.
    edge_boundary: Vec<bool>,
    has_boundary: bool,
}

impl Level {
    /// The base level, numbered as OpenSubdiv numbers it.
    fn base(mesh: &Mesh, topology: &Topology) -> Level {
        let (offsets, indices) = mesh.face_parts();
        let face_edges = (0..topology.num_half_edges() as u32)
            .map(|h| {
                let e = topology.edge(h);
                let reversed = topology.edge_half_edge(e) != h;
                (e << 1) | u32::from(reversed)
            })
            .collect();
        let edges = 0..topology.num_edges() as u32;
        let edge_boundary: Vec<bool> = edges.clone().map(|e| topology.is_boundary_edge(e)).collect();
        Level {
            positions: mesh.positions().to_vec(),
            faces: Faces::Polygons(offsets.iter().map(|&o| o as u32).collect()),
            face_verts: indices.to_vec(),
            face_edges,
            edge_verts: edges.map(|e| topology.edge_vertices(e)).collect(),
            has_boundary: edge_boundary.contains(&true),
            edge_boundary,
        }
    }

    fn num_faces(&self) -> usize {
        match &self.faces {
            Faces::Polygons(offsets) => offsets.len() - 1,
            Faces::Quads => self.face_verts.len() / 4,
        }
    }

    /// Fails when the child level would overflow the 32-bit indices (edges carry a flag bit).
    fn check_size(&self, level: u32) -> Result<()> {
        let vertices = (self.positions.len() + self.num_faces() + self.edge_verts.len()) as u64;
        let edges = (self.face_verts.len() + 2 * self.edge_verts.len()) as u64;
        let corners = 4 * self.face_verts.len() as u64;
        if vertices >= u64::from(u32::MAX) || edges >= 1 << 31 || corners >= u64::from(u32::MAX) {
            return Err(SubdivError::TooLarge { level, vertices });
        }
        // The child level (positions, quads with their edges, edge ends) and the output
        // mesh built from it, checked before anything is allocated.
        let bytes = 48 * vertices + 64 * (corners / 4) + 9 * edges;
        crate::host::check_available(bytes).map_err(|(need_mib, have_mib)| SubdivError::Memory {
            level,
            need_mib,
            have_mib,
        })
    }

    /// One Catmull-Clark step. Without `with_topology` only the child's faces are built
    /// (the last level needs no edges).
    fn refine(&self, with_topology: bool) -> Level {
        let mut child = Child::new(self, with_topology);
        match &self.faces {
            Faces::Polygons(offsets) => {
                child.face_pass(self, |f| offsets[f] as usize..offsets[f + 1] as usize)
            }
            Faces::Quads => child.face_pass(self, |f| 4 * f..4 * f + 4),
        }
        child.edge_pass(self);
        child.vertex_pass(self);
        child.level
    }

    fn into_mesh(self) -> Result<Mesh> {
        let offsets = match self.faces {
            Faces::Polygons(offsets) => offsets.into_iter().map(|o| o as usize).collect(),
            Faces::Quads => (0..=self.face_verts.len()).step_by(4).collect(),
        };
        Ok(Mesh::from_parts(self.positions, offsets, self.face_verts)?)
    }
}

/// A child level under construction, with the per-parent-vertex sums of the vertex mask.
struct Child {
    level: Level,
    with_topology: bool,
    /// First child index of face points and of edge points.
    face_point0: u32,
    edge_point0: u32,
    /// First child index of the edges halving parent edges (= number of parent corners).
    edge_edge0: u32,
    /// Number of edges at each parent vertex; `ON_BOUNDARY` marks boundary vertices.
    valence: Vec<u32>,
    /// Sum of each boundary vertex's two boundary neighbours.
    boundary_sum: Vec<DVec3>,
}

const ON_BOUNDARY: u32 = 1 << 31;

impl Child {
    fn new(parent: &Level, with_topology: bool) -> Child {
        let (nv, nf, ne, nc) =
            (parent.positions.len(), parent.num_faces(), parent.edge_verts.len(), parent.face_verts.len());
        let (faces, edges) = if with_topology { (4 * nc, nc + 2 * ne) } else { (4 * nc, 0) };
        Child {
            level: Level {
                positions: vec![DVec3::ZERO; nv + nf + ne],
                faces: Faces::Quads,
                face_verts: Vec::with_capacity(faces),
                face_edges: Vec::with_capacity(if with_topology { faces } else { 0 }),
                edge_verts: Vec::with_capacity(edges),
                edge_boundary: Vec::with_capacity(edges),
                has_boundary: parent.has_boundary,
            },
            with_topology,
            face_point0: nv as u32,
            edge_point0: (nv + nf) as u32,
            edge_edge0: nc as u32,
            valence: vec![0; nv],
            boundary_sum: if parent.has_boundary { vec![DVec3::ZERO; nv] } else { Vec::new() },
        }
    }

    /// Face points; scatters each into its corners' vertex sums and its edges' sums; builds
    /// the child quads (and the face-point edges). Quad parents get OpenSubdiv's
    /// rotation: the child quad at corner `j` has the vertex point in position `j`.
    fn face_pass(&mut self, parent: &Level, corners: impl Fn(usize) -> std::ops::Range<usize>) {
        let pos = &parent.positions;
        let nv = parent.positions.len();
        for f in 0..parent.num_faces() {
            let out = &mut self.level.positions;
            let range = corners(f);
            let verts = &parent.face_verts[range.clone()];
            let edges = &parent.face_edges[range.clone()];
            let sum: DVec3 = verts.iter().map(|&v| pos[v as usize]).sum();
            let face_point = sum * (1.0 / verts.len() as f64);
            out[nv + f] = face_point;
            for (&v, &e) in verts.iter().zip(edges) {
                out[v as usize] += face_point;
                out[(self.edge_point0 + (e >> 1)) as usize] += face_point;
            }
            self.child_faces(f as u32, range.start as u32, verts, edges);
        }
    }

    fn child_faces(&mut self, f: u32, first_corner: u32, verts: &[u32], edges: &[u32]) {
        let n = verts.len();
        let face_point = self.face_point0 + f;
        for j in 0..n {
            let jp = if j == 0 { n - 1 } else { j - 1 };
            let (e, ep) = (edges[j], edges[jp]);
            // The quad at corner j: vertex point, next edge point, face point, previous edge point.
            let quad = [verts[j], self.edge_point0 + (e >> 1), face_point, self.edge_point0 + (ep >> 1)];
            let rot = if n == 4 { j } else { 0 };
            self.level.face_verts.extend_from_slice(&rotate(quad, rot));
            if self.with_topology {
                // Edges of that quad, each flagged by how the quad traverses it: the
                // edge-point edges run edge point → vertex point, the face-point edges
                // face point → edge point.
                let half = |e: u32, k: u32| self.edge_edge0 + 2 * (e >> 1) + k;
                let quad_edges = [
                    (half(e, e & REVERSED) << 1) | REVERSED,
                    ((first_corner + j as u32) << 1) | REVERSED,
                    (first_corner + jp as u32) << 1,
                    half(ep, 1 - (ep & REVERSED)) << 1,
                ];
                self.level.face_edges.extend_from_slice(&rotate(quad_edges, rot));
            }
        }
        if self.with_topology {
            for &e in edges {
                self.level.edge_verts.push([face_point, self.edge_point0 + (e >> 1)]);
                self.level.edge_boundary.push(false);
            }
        }
    }

    /// Edge points (the face sums are in place), and the neighbour sums of the vertex mask.
    fn edge_pass(&mut self, parent: &Level) {
        let pos = &parent.positions;
        let out = &mut self.level.positions;
        for (e, (&[a, b], &boundary)) in parent.edge_verts.iter().zip(&parent.edge_boundary).enumerate() {
            let (pa, pb) = (pos[a as usize], pos[b as usize]);
            let edge_point = &mut out[self.edge_point0 as usize + e];
            if boundary {
                *edge_point = (pa + pb) * 0.5;
                self.boundary_sum[a as usize] += pb;
                self.boundary_sum[b as usize] += pa;
                self.valence[a as usize] = (self.valence[a as usize] + 1) | ON_BOUNDARY;
                self.valence[b as usize] = (self.valence[b as usize] + 1) | ON_BOUNDARY;
            } else {
                *edge_point = (pa + pb + *edge_point) * 0.25;
                out[a as usize] += pb;
                out[b as usize] += pa;
                self.valence[a as usize] += 1;
                self.valence[b as usize] += 1;
            }
            if self.with_topology {
                let edge_point = self.edge_point0 + e as u32;
                self.level.edge_verts.extend_from_slice(&[[edge_point, a], [edge_point, b]]);
                self.level.edge_boundary.extend_from_slice(&[boundary, boundary]);
            }
        }
    }

    /// Vertex points: `((n−2)/n)·V + (Σ neighbours + Σ face points)/n²` inside,
    /// `¾·V + ⅛·(prev + next)` on the boundary (corners included: `VTX_BOUNDARY_EDGE_ONLY`).
    fn vertex_pass(&mut self, parent: &Level) {
        let out = &mut self.level.positions;
        for (v, (&p, &valence)) in parent.positions.iter().zip(&self.valence).enumerate() {
            out[v] = if valence & ON_BOUNDARY != 0 {
                p * 0.75 + self.boundary_sum[v] * 0.125
            } else if valence == 0 {
                p // a vertex no face uses stays put, as in OpenSubdiv
            } else {
                let n = f64::from(valence);
                p * ((n - 2.0) / n) + out[v] * (1.0 / (n * n))
            };
        }
    }
}

/// Entry `i` of `cycle` moved to position `(i + rot) % 4`.
fn rotate(cycle: [u32; 4], rot: usize) -> [u32; 4] {
    std::array::from_fn(|i| cycle[(i + 4 - rot) % 4])
}
