//! Half-edge topology of a manifold polygon mesh: what Catmull-Clark needs at the base
//! level, and what the fragment-mesh path (SPEC §5.2) asks of the refined quad mesh —
//! vertex valence, the one-ring in order, the faces around a vertex in order.
//!
//! A half-edge is a face corner: half-edge `h` is the `h`-th entry of the mesh's CSR
//! index list and runs from that corner's vertex to the next corner's vertex of the same
//! face. Faces are counter-clockwise seen from outside, so walking "around" a vertex
//! here is counter-clockwise seen from outside too.
//!
//! Edges are numbered in order of first appearance while traversing the faces, each edge
//! oriented as first traversed: the numbering OpenSubdiv gives its base-level edges, so
//! edge points come out in OpenSubdiv's order.

use crate::mesh::Mesh;

use super::{Result, SubdivError};

/// Marks "no half-edge" (a boundary half-edge's twin, an isolated vertex's spoke).
pub const NONE: u32 = u32::MAX;

/// Half-edge connectivity of a manifold mesh (closed or with boundary).
#[derive(Clone, Debug)]
pub struct Topology {
    /// Face `f` owns half-edges `offsets[f]..offsets[f + 1]`.
    offsets: Vec<u32>,
    /// Origin vertex of each half-edge.
    origin: Vec<u32>,
    /// Face of each half-edge.
    face: Vec<u32>,
    /// Opposite half-edge, or `NONE` on the boundary.
    twin: Vec<u32>,
    /// Edge of each half-edge.
    edge: Vec<u32>,
    /// The half-edge that first traversed each edge (it gives the edge's orientation).
    edge_half: Vec<u32>,
    /// First spoke (outgoing half-edge) of each vertex: the boundary one for a boundary
    /// vertex, so that walking counter-clockwise from it visits every face; `NONE` for an
    /// isolated vertex.
    spoke: Vec<u32>,
    /// Number of faces around each vertex.
    vertex_faces: Vec<u32>,
}

impl Topology {
    /// Builds the half-edges of `mesh`, rejecting what Catmull-Clark (and OpenSubdiv's
    /// smooth rules) cannot handle: degenerate faces, edges with more than two faces,
    /// inconsistently oriented neighbours and vertices whose faces form several fans.
    /// Vertices used by no face are allowed (they stay where they are when refined).
    pub fn new(mesh: &Mesh) -> Result<Topology> {
        let (offsets, origin) = mesh.face_parts();
        let n = origin.len();
        // Edge numbers carry a flag bit during refinement, hence 2^31.
        if n >= 1 << 31 || mesh.num_vertices() >= NONE as usize {
            return Err(SubdivError::TooLarge { level: 0, vertices: mesh.num_vertices() as u64 });
        }
        check_degenerate_faces(mesh)?;

        let offsets: Vec<u32> = offsets.iter().map(|&o| o as u32).collect();
        let mut face = Vec::with_capacity(n);
        for (f, w) in offsets.windows(2).enumerate() {
            face.extend(std::iter::repeat_n(f as u32, (w[1] - w[0]) as usize));
        }
        let mut topo = Topology {
            offsets,
            origin: origin.to_vec(),
            face,
            twin: vec![NONE; n],
            edge: vec![NONE; n],
            edge_half: Vec::new(),
            spoke: vec![NONE; mesh.num_vertices()],
            vertex_faces: vec![0; mesh.num_vertices()],
        };
        topo.pair_half_edges()?;
        topo.number_edges();
        topo.find_spokes()?;
        Ok(topo)
    }

    /// Pairs half-edges into edges by sorting their undirected keys (the only sort; after
    /// the base level child topology is derived arithmetically).
    fn pair_half_edges(&mut self) -> Result<()> {
        let mut keys: Vec<(u64, u32)> = (0..self.origin.len() as u32)
            .map(|h| {
                let (a, b) = (self.origin(h), self.target(h));
                ((u64::from(a.min(b)) << 32) | u64::from(a.max(b)), h)
            })
            .collect();
        keys.sort_unstable();
        for group in keys.chunk_by(|x, y| x.0 == y.0) {
            match *group {
                [_] => {}
                [(_, h0), (_, h1)] => {
                    if self.origin(h0) == self.origin(h1) {
                        return Err(SubdivError::Inconsistent {
                            a: self.origin(h0),
                            b: self.target(h0),
                            f0: self.face(h0) as usize,
                            f1: self.face(h1) as usize,
                        });
                    }
                    self.twin[h0 as usize] = h1;
                    self.twin[h1 as usize] = h0;
                }
                _ => {
                    let (a, b) = ((group[0].0 >> 32) as u32, group[0].0 as u32);
                    return Err(SubdivError::NonManifoldEdge { a, b, faces: group.len() });
                }
            }
        }
        Ok(())
    }

    /// Numbers edges by first appearance in face order (OpenSubdiv's base-level order).
    fn number_edges(&mut self) {
        for h in 0..self.origin.len() as u32 {
            let t = self.twin[h as usize];
            if t != NONE && t < h {
                self.edge[h as usize] = self.edge[t as usize];
            } else {
                self.edge[h as usize] = self.edge_half.len() as u32;
                self.edge_half.push(h);
            }
        }
    }

    /// Chooses each vertex's first spoke and checks that its faces form one fan.
    fn find_spokes(&mut self) -> Result<()> {
        let mut boundary_spokes = vec![0u32; self.spoke.len()];
        for h in 0..self.origin.len() as u32 {
            let v = self.origin(h) as usize;
            self.vertex_faces[v] += 1;
            if self.twin[h as usize] == NONE {
                boundary_spokes[v] += 1;
                self.spoke[v] = h;
            } else if self.spoke[v] == NONE {
                self.spoke[v] = h;
            }
        }
        for v in 0..self.spoke.len() as u32 {
            let faces = self.vertex_faces[v as usize];
            let fan = if boundary_spokes[v as usize] > 1 { 0 } else { self.spokes(v).count() as u32 };
            if fan != faces {
                return Err(SubdivError::NonManifoldVertex { vertex: v, faces: faces as usize });
            }
        }
        Ok(())
    }

    pub fn num_vertices(&self) -> usize {
        self.spoke.len()
    }

    pub fn num_faces(&self) -> usize {
        self.offsets.len() - 1
    }

    pub fn num_edges(&self) -> usize {
        self.edge_half.len()
    }

    pub fn num_half_edges(&self) -> usize {
        self.origin.len()
    }

    /// The half-edges of face `f` (its corners), in order.
    pub fn face_half_edges(&self, f: u32) -> std::ops::Range<u32> {
        self.offsets[f as usize]..self.offsets[f as usize + 1]
    }

    pub fn origin(&self, h: u32) -> u32 {
        self.origin[h as usize]
    }

    pub fn target(&self, h: u32) -> u32 {
        self.origin[self.next(h) as usize]
    }

    pub fn face(&self, h: u32) -> u32 {
        self.face[h as usize]
    }

    pub fn edge(&self, h: u32) -> u32 {
        self.edge[h as usize]
    }

    /// The opposite half-edge, `None` on the boundary.
    pub fn twin(&self, h: u32) -> Option<u32> {
        Some(self.twin[h as usize]).filter(|&t| t != NONE)
    }

    /// The next half-edge around the same face.
    pub fn next(&self, h: u32) -> u32 {
        let end = self.offsets[self.face(h) as usize + 1];
        if h + 1 == end { self.offsets[self.face(h) as usize] } else { h + 1 }
    }

    /// The previous half-edge around the same face.
    pub fn prev(&self, h: u32) -> u32 {
        let start = self.offsets[self.face(h) as usize];
        if h == start { self.offsets[self.face(h) as usize + 1] - 1 } else { h - 1 }
    }

    /// The vertices of edge `e`, in the direction it was first traversed.
    pub fn edge_vertices(&self, e: u32) -> [u32; 2] {
        let h = self.edge_half[e as usize];
        [self.origin(h), self.target(h)]
    }

    /// The half-edge that first traversed edge `e`.
    pub fn edge_half_edge(&self, e: u32) -> u32 {
        self.edge_half[e as usize]
    }

    pub fn is_boundary_edge(&self, e: u32) -> bool {
        self.twin[self.edge_half[e as usize] as usize] == NONE
    }

    /// True when `v` lies on the boundary (has a boundary edge).
    pub fn is_boundary_vertex(&self, v: u32) -> bool {
        let h = self.spoke[v as usize];
        h != NONE && self.twin[h as usize] == NONE
    }

    /// Number of edges at `v` (faces + 1 on the boundary, 0 when isolated).
    pub fn valence(&self, v: u32) -> usize {
        self.vertex_faces[v as usize] as usize + usize::from(self.is_boundary_vertex(v))
    }

    /// Number of faces around `v`.
    pub fn num_vertex_faces(&self, v: u32) -> usize {
        self.vertex_faces[v as usize] as usize
    }

    /// The half-edges leaving `v`, counter-clockwise; on the boundary the first is the
    /// boundary edge with the mesh on its left. One per face around `v`.
    pub fn spokes(&self, v: u32) -> Spokes<'_> {
        let first = self.spoke[v as usize];
        Spokes { topo: self, first, next: first }
    }

    /// The faces around `v`, counter-clockwise (face `i` lies between ring vertices `i`
    /// and `i + 1` of [`Topology::one_ring`]).
    pub fn faces_around(&self, v: u32) -> impl Iterator<Item = u32> + '_ {
        self.spokes(v).map(|h| self.face(h))
    }

    /// The neighbours of `v` along edges, counter-clockwise; `valence(v)` of them. On the
    /// boundary the first and last are the two boundary neighbours.
    pub fn one_ring(&self, v: u32) -> impl Iterator<Item = u32> + '_ {
        let last = self.is_boundary_vertex(v).then(|| {
            // The last spoke's face closes the fan: its edge into `v` is the other boundary edge.
            let last_spoke = self.spokes(v).last().unwrap_or(NONE);
            self.origin(self.prev(last_spoke))
        });
        self.spokes(v).map(|h| self.target(h)).chain(last)
    }
}

/// The spokes of a vertex, counter-clockwise: `h → twin(prev(h))`.
#[derive(Clone, Debug)]
pub struct Spokes<'a> {
    topo: &'a Topology,
    first: u32,
    next: u32,
}

impl Iterator for Spokes<'_> {
    type Item = u32;

    fn next(&mut self) -> Option<u32> {
        let h = self.next;
        if h == NONE {
            return None;
        }
        let t = self.topo.twin[self.topo.prev(h) as usize];
        self.next = if t == self.first { NONE } else { t };
        Some(h)
    }
}

/// Rejects faces that use a vertex twice.
fn check_degenerate_faces(mesh: &Mesh) -> Result<()> {
    let mut sorted = Vec::new();
    for (f, face) in mesh.faces().enumerate() {
        let repeated = if face.len() <= 8 {
            (1..face.len()).find_map(|i| face[..i].contains(&face[i]).then_some(face[i]))
        } else {
            sorted.clear();
            sorted.extend_from_slice(face);
            sorted.sort_unstable();
            sorted.windows(2).find_map(|w| (w[0] == w[1]).then_some(w[0]))
        };
        if let Some(vertex) = repeated {
            return Err(SubdivError::DegenerateFace { face: f, vertex });
        }
    }
    Ok(())
}
