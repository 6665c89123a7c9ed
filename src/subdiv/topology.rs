//! Topology of a polygon mesh the way OpenSubdiv builds it (`Vtr::Level`), non-manifold
//! meshes included: faces, their corners ("half-edges"), edges with the faces using them,
//! and the *fans* around each vertex — what Catmull-Clark needs at the base level, and
//! what the fragment-mesh path (SPEC §5.2) asks of the coarse quad mesh.
//!
//! A half-edge is a face corner: half-edge `h` is the `h`-th entry of the mesh's CSR index
//! list and runs from that corner's vertex to the next corner's vertex of the same face.
//! Faces are counter-clockwise seen from outside, so walking "around" a vertex here is
//! counter-clockwise too.
//!
//! Edges are numbered in order of first appearance while traversing the faces, each edge
//! oriented as first traversed — OpenSubdiv's base-level numbering — with its rules for
//! what is one edge: a face corner whose two vertices are equal (a *degenerate* edge)
//! always starts a new edge; a face using the same vertex pair twice gets a second edge;
//! otherwise every face using a vertex pair uses the pair's first edge. An edge is
//! *non-manifold* when it is degenerate, repeated in a face, used by more than two faces
//! or by two faces in the same direction; a vertex is non-manifold when it has a
//! non-manifold edge, no face, or faces that do not form one fan. OpenSubdiv subdivides
//! all of these with sharp rules (see `cpu`).
//!
//! A *fan* is a maximal sequence of corners at one vertex, each next one across a
//! manifold edge (counter-clockwise): the faces around a manifold vertex form one fan,
//! closed inside the mesh and open on its boundary; a non-manifold vertex has one fan
//! per sheet. A closed fan starts at the vertex's first corner in face order, an open one
//! at the corner whose leaving edge is on its border — both where OpenSubdiv starts its
//! ordering of the vertex's edges.

use crate::mesh::Mesh;

use super::{Result, SubdivError};

/// Marks "no element" (a half-edge without twin, a vertex without fan, …).
pub const NONE: u32 = u32::MAX;

/// Set in a [`Topology::edge_flags`] entry when the corner traverses its edge against the
/// edge's orientation.
pub const REVERSED: u32 = 1;

/// A fan of corners around a vertex (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Fan {
    pub centre: u32,
    /// Its corners are `fan_corners[first..first + len]`, counter-clockwise.
    pub first: u32,
    pub len: u32,
    /// Closed fans go all the way around; open ones have a border edge at each end.
    pub closed: bool,
}

/// Polygon-mesh connectivity (see the module docs).
#[derive(Clone, Debug)]
pub struct Topology {
    /// Face `f` owns half-edges `offsets[f]..offsets[f + 1]`.
    offsets: Vec<u32>,
    /// Origin vertex of each half-edge.
    origin: Vec<u32>,
    /// Face of each half-edge.
    face: Vec<u32>,
    /// Edge of each half-edge, `edge << 1 | REVERSED?`.
    edge: Vec<u32>,
    /// The other half-edge of a manifold edge, `NONE` otherwise.
    twin: Vec<u32>,
    /// The two vertices of each edge, in the edge's orientation.
    edge_verts: Vec<[u32; 2]>,
    /// The half-edges using each edge: `edge_uses[edge_use_offsets[e]..edge_use_offsets[e + 1]]`,
    /// in face order (the first one gives the edge's orientation).
    edge_use_offsets: Vec<u32>,
    edge_uses: Vec<u32>,
    edge_non_manifold: Vec<bool>,
    vertex_non_manifold: Vec<bool>,
    /// Number of corners (faces, counted once per corner) and edge ends (a degenerate edge
    /// counts twice) at each vertex.
    vertex_corners: Vec<u32>,
    vertex_edges: Vec<u32>,
    fans: Vec<Fan>,
    fan_corners: Vec<u32>,
    /// Fan and position in it of each half-edge.
    corner_fan: Vec<u32>,
    corner_sector: Vec<u32>,
    /// First fan of each vertex (`NONE` for a vertex no face uses) and number of fans.
    vertex_fan: Vec<u32>,
    vertex_fan_count: Vec<u32>,
}

impl Topology {
    /// Builds the topology of `mesh` with OpenSubdiv's base-level edge rules. Every mesh is
    /// accepted; non-manifold edges and vertices are tagged.
    pub fn new(mesh: &Mesh) -> Result<Topology> {
        let (offsets, origin) = mesh.face_parts();
        let n = origin.len();
        // Edge numbers carry a flag bit, hence 2^31.
        if n >= 1 << 31 || mesh.num_vertices() >= NONE as usize {
            return Err(SubdivError::TooLarge { level: 0, vertices: mesh.num_vertices() as u64 });
        }
        let offsets: Vec<u32> = offsets.iter().map(|&o| o as u32).collect();
        let face = faces_of_corners(&offsets);
        let next = |h: usize| {
            let f = face[h] as usize;
            if h + 1 == offsets[f + 1] as usize { offsets[f] as usize } else { h + 1 }
        };
        let target = |h: usize| origin[next(h)];

        // Group the corners by unordered vertex pair (degenerate corners alone), then apply
        // OpenSubdiv's rules inside each group, in face order.
        let mut keys: Vec<(u64, u32)> = (0..n)
            .map(|h| {
                let (a, b) = (origin[h], target(h));
                let key = if a == b { u64::MAX } else { (u64::from(a.min(b)) << 32) | u64::from(a.max(b)) };
                (key, h as u32)
            })
            .collect();
        keys.sort_unstable();
        // (first use, non-manifold) of each edge instance; `instance` per half-edge.
        let mut instances: Vec<(u32, bool)> = Vec::new();
        let mut instance = vec![NONE; n];
        let mut uses_of = Vec::new(); // uses of the group's first instance
        for group in keys.chunk_by(|x, y| x.0 == y.0 && x.0 != u64::MAX) {
            let (_, h0) = group[0];
            if group[0].0 == u64::MAX {
                // Degenerate: its own non-manifold edge.
                instance[h0 as usize] = instances.len() as u32;
                instances.push((h0, true));
                continue;
            }
            let first = instances.len();
            instances.push((h0, false));
            instance[h0 as usize] = first as u32;
            uses_of.clear();
            uses_of.push(h0);
            for &(_, h) in &group[1..] {
                let last_face = face[*uses_of.last().unwrap_or(&h0) as usize];
                if last_face == face[h as usize] {
                    // The same face uses the pair again: a new, non-manifold edge.
                    instances[first].1 = true;
                    instance[h as usize] = instances.len() as u32;
                    instances.push((h, true));
                    continue;
                }
                if uses_of.len() > 1 || origin[h as usize] == origin[h0 as usize] {
                    instances[first].1 = true;
                }
                uses_of.push(h);
                instance[h as usize] = first as u32;
            }
        }
        // Number edges by first use.
        let mut order: Vec<u32> = (0..instances.len() as u32).collect();
        order.sort_unstable_by_key(|&i| instances[i as usize].0);
        let mut number = vec![0u32; instances.len()];
        for (e, &i) in order.iter().enumerate() {
            number[i as usize] = e as u32;
        }
        let mut edge_verts = vec![[0u32; 2]; instances.len()];
        let mut edge_non_manifold = vec![false; instances.len()];
        for (i, &(h, non_manifold)) in instances.iter().enumerate() {
            let e = number[i] as usize;
            edge_verts[e] = [origin[h as usize], target(h as usize)];
            edge_non_manifold[e] = non_manifold;
        }
        let edge: Vec<u32> = (0..n)
            .map(|h| {
                let e = number[instance[h] as usize];
                let reversed = origin[h] != edge_verts[e as usize][0];
                (e << 1) | u32::from(reversed)
            })
            .collect();
        Ok(Topology::assemble(
            mesh.num_vertices(),
            offsets,
            origin.to_vec(),
            face,
            edge,
            edge_verts,
            Some(edge_non_manifold),
        ))
    }

    /// The topology of a refined level whose edges are already numbered (`cpu` derives
    /// them from the parent level): corners `face_verts` in faces `offsets`, each with its
    /// edge `edge << 1 | REVERSED?`. Non-manifold edges are recognised by their uses.
    pub fn from_refined(
        num_vertices: usize,
        offsets: Vec<u32>,
        face_verts: Vec<u32>,
        face_edges: Vec<u32>,
        edge_verts: Vec<[u32; 2]>,
    ) -> Topology {
        let face = faces_of_corners(&offsets);
        Topology::assemble(num_vertices, offsets, face_verts, face, face_edges, edge_verts, None)
    }

    fn assemble(
        num_vertices: usize,
        offsets: Vec<u32>,
        origin: Vec<u32>,
        face: Vec<u32>,
        edge: Vec<u32>,
        edge_verts: Vec<[u32; 2]>,
        edge_non_manifold: Option<Vec<bool>>,
    ) -> Topology {
        let ne = edge_verts.len();
        let n = origin.len();
        // Edge uses in face order (a counting sort by edge).
        let mut edge_use_offsets = vec![0u32; ne + 1];
        for &e in &edge {
            edge_use_offsets[(e >> 1) as usize + 1] += 1;
        }
        for e in 0..ne {
            edge_use_offsets[e + 1] += edge_use_offsets[e];
        }
        let mut fill = edge_use_offsets.clone();
        let mut edge_uses = vec![0u32; n];
        for (h, &e) in edge.iter().enumerate() {
            let slot = &mut fill[(e >> 1) as usize];
            edge_uses[*slot as usize] = h as u32;
            *slot += 1;
        }
        let mut topo = Topology {
            offsets,
            origin,
            face,
            edge,
            twin: vec![NONE; n],
            edge_non_manifold: Vec::new(),
            edge_verts,
            edge_use_offsets,
            edge_uses,
            vertex_non_manifold: vec![false; num_vertices],
            vertex_corners: vec![0; num_vertices],
            vertex_edges: vec![0; num_vertices],
            fans: Vec::new(),
            fan_corners: Vec::new(),
            corner_fan: vec![NONE; n],
            corner_sector: vec![NONE; n],
            vertex_fan: vec![NONE; num_vertices],
            vertex_fan_count: vec![0; num_vertices],
        };
        topo.edge_non_manifold = match edge_non_manifold {
            Some(tags) => tags,
            None => (0..ne as u32)
                .map(|e| {
                    let uses = topo.edge_uses(e);
                    let [a, b] = topo.edge_verts[e as usize];
                    a == b
                        || uses.len() != 2
                        || topo.origin(uses[0]) == topo.origin(uses[1])
                        || topo.face(uses[0]) == topo.face(uses[1])
                })
                .collect(),
        };
        for e in 0..ne as u32 {
            if let [h0, h1] = *topo.edge_uses(e)
                && !topo.edge_non_manifold[e as usize]
            {
                topo.twin[h0 as usize] = h1;
                topo.twin[h1 as usize] = h0;
            }
        }
        for &v in &topo.origin {
            topo.vertex_corners[v as usize] += 1;
        }
        for (e, &[a, b]) in topo.edge_verts.iter().enumerate() {
            topo.vertex_edges[a as usize] += 1;
            topo.vertex_edges[b as usize] += 1;
            if topo.edge_non_manifold[e] {
                topo.vertex_non_manifold[a as usize] = true;
                topo.vertex_non_manifold[b as usize] = true;
            }
        }
        topo.build_fans();
        for v in 0..num_vertices {
            if topo.vertex_fan_count[v] != 1 {
                topo.vertex_non_manifold[v] = true;
            }
        }
        topo
    }

    /// Groups every corner into its fan (see the module docs).
    fn build_fans(&mut self) {
        for h0 in 0..self.origin.len() as u32 {
            if self.corner_fan[h0 as usize] != NONE {
                continue;
            }
            // Clockwise to the start of an open fan (or all the way round a closed one).
            let mut start = h0;
            let mut closed = false;
            while let Some(t) = self.twin(start) {
                let before = self.next(t);
                if before == h0 {
                    closed = true;
                    break;
                }
                start = before;
            }
            if closed {
                start = h0;
            }
            let fan = self.fans.len() as u32;
            let first = self.fan_corners.len() as u32;
            let mut h = start;
            let mut len = 0u32;
            loop {
                self.corner_fan[h as usize] = fan;
                self.corner_sector[h as usize] = len;
                self.fan_corners.push(h);
                len += 1;
                match self.twin(self.prev(h)) {
                    Some(t) if t != start => h = t,
                    _ => break,
                }
            }
            let centre = self.origin(h0);
            if self.vertex_fan[centre as usize] == NONE {
                self.vertex_fan[centre as usize] = fan;
            }
            self.vertex_fan_count[centre as usize] += 1;
            self.fans.push(Fan { centre, first, len, closed });
        }
    }

    pub fn num_vertices(&self) -> usize {
        self.vertex_corners.len()
    }

    pub fn num_faces(&self) -> usize {
        self.offsets.len() - 1
    }

    pub fn num_edges(&self) -> usize {
        self.edge_verts.len()
    }

    pub fn num_half_edges(&self) -> usize {
        self.origin.len()
    }

    /// CSR face offsets, as the mesh had them.
    pub fn face_offsets(&self) -> &[u32] {
        &self.offsets
    }

    /// The vertex of every corner, face after face.
    pub fn face_verts(&self) -> &[u32] {
        &self.origin
    }

    /// The edge of every corner, `edge << 1 | REVERSED?`.
    pub fn edge_flags(&self) -> &[u32] {
        &self.edge
    }

    /// The two vertices of every edge, in its orientation.
    pub fn edge_verts(&self) -> &[[u32; 2]] {
        &self.edge_verts
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
        self.edge[h as usize] >> 1
    }

    /// True when half-edge `h` runs against its edge's orientation.
    pub fn is_reversed(&self, h: u32) -> bool {
        self.edge[h as usize] & REVERSED != 0
    }

    /// The other half-edge of a manifold edge; `None` on the border of a fan (boundary or
    /// non-manifold edge).
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
        self.edge_verts[e as usize]
    }

    /// The half-edge that first traversed edge `e`.
    pub fn edge_half_edge(&self, e: u32) -> u32 {
        self.edge_uses[self.edge_use_offsets[e as usize] as usize]
    }

    /// The half-edges using edge `e`, in face order.
    pub fn edge_uses(&self, e: u32) -> &[u32] {
        &self.edge_uses
            [self.edge_use_offsets[e as usize] as usize..self.edge_use_offsets[e as usize + 1] as usize]
    }

    /// Number of faces using edge `e` (a face using it twice counts twice).
    pub fn num_edge_faces(&self, e: u32) -> usize {
        (self.edge_use_offsets[e as usize + 1] - self.edge_use_offsets[e as usize]) as usize
    }

    pub fn is_boundary_edge(&self, e: u32) -> bool {
        self.num_edge_faces(e) < 2
    }

    pub fn is_non_manifold_edge(&self, e: u32) -> bool {
        self.edge_non_manifold[e as usize]
    }

    pub fn is_non_manifold_vertex(&self, v: u32) -> bool {
        self.vertex_non_manifold[v as usize]
    }

    /// True when `v` lies on the boundary (has a boundary edge).
    pub fn is_boundary_vertex(&self, v: u32) -> bool {
        self.vertex_fan_count[v as usize] == 1 && !self.fans[self.vertex_fan[v as usize] as usize].closed
    }

    /// Number of edges at `v` (a degenerate edge counts twice; 0 when isolated).
    pub fn valence(&self, v: u32) -> usize {
        self.vertex_edges[v as usize] as usize
    }

    /// Number of face corners at `v`.
    pub fn num_vertex_faces(&self, v: u32) -> usize {
        self.vertex_corners[v as usize] as usize
    }

    pub fn fans(&self) -> &[Fan] {
        &self.fans
    }

    /// The corners of a fan, counter-clockwise.
    pub fn fan_corners(&self, fan: &Fan) -> &[u32] {
        &self.fan_corners[fan.first as usize..(fan.first + fan.len) as usize]
    }

    /// The fan of half-edge `h`'s corner and the corner's position in it.
    pub fn corner_fan(&self, h: u32) -> (u32, u32) {
        (self.corner_fan[h as usize], self.corner_sector[h as usize])
    }

    /// The first fan of `v` (`None` for a vertex no face uses) and how many it has.
    pub fn vertex_fans(&self, v: u32) -> (Option<u32>, u32) {
        let f = self.vertex_fan[v as usize];
        ((f != NONE).then_some(f), self.vertex_fan_count[v as usize])
    }

    /// The half-edges leaving `v`, counter-clockwise, along its first fan; on the boundary
    /// the first is the boundary edge with the mesh on its left. One per face of the fan.
    pub fn spokes(&self, v: u32) -> impl Iterator<Item = u32> + '_ {
        let (fan, _) = self.vertex_fans(v);
        fan.into_iter().flat_map(move |f| self.fan_corners(&self.fans[f as usize]).iter().copied())
    }

    /// The faces around `v` along its first fan, counter-clockwise (face `i` lies between
    /// ring vertices `i` and `i + 1` of [`Topology::one_ring`]).
    pub fn faces_around(&self, v: u32) -> impl Iterator<Item = u32> + '_ {
        self.spokes(v).map(|h| self.face(h))
    }

    /// The neighbours of `v` along the edges of its first fan, counter-clockwise; on the
    /// boundary the first and last are the two boundary neighbours.
    pub fn one_ring(&self, v: u32) -> impl Iterator<Item = u32> + '_ {
        let last = self.vertex_fans(v).0.and_then(|f| {
            let fan = &self.fans[f as usize];
            (!fan.closed).then(|| {
                let corners = self.fan_corners(fan);
                self.origin(self.prev(corners[corners.len() - 1]))
            })
        });
        self.spokes(v).map(|h| self.target(h)).chain(last)
    }
}

/// The face of every corner, from CSR offsets.
fn faces_of_corners(offsets: &[u32]) -> Vec<u32> {
    let mut face = Vec::with_capacity(offsets.last().copied().unwrap_or(0) as usize);
    for (f, w) in offsets.windows(2).enumerate() {
        face.extend(std::iter::repeat_n(f as u32, (w[1] - w[0]) as usize));
    }
    face
}

#[cfg(test)]
mod tests {
    use glam::DVec3;

    use super::*;

    fn mesh(faces: Vec<Vec<u32>>) -> Mesh {
        let n = faces.iter().flatten().max().map_or(0, |&m| m + 1);
        Mesh::new((0..n).map(|i| DVec3::new(f64::from(i), 0.0, 0.0)).collect(), faces).unwrap()
    }

    #[test]
    fn edges_numbered_by_first_use() {
        let t = Topology::new(&mesh(vec![vec![0, 1, 2, 3], vec![1, 4, 5, 2]])).unwrap();
        assert_eq!(t.num_edges(), 7);
        assert_eq!(t.edge_vertices(0), [0, 1]);
        assert_eq!(t.edge_vertices(1), [1, 2]);
        assert_eq!(t.edge(7), 1);
        assert!(t.is_reversed(7)); // face 1 traverses 2 → 1 against edge 1 (1 → 2)
        assert!(!t.is_non_manifold_edge(1));
        assert_eq!(t.twin(1), Some(7));
        assert!(t.is_boundary_vertex(0) && !t.is_non_manifold_vertex(0));
    }

    #[test]
    fn non_manifold_rules() {
        // Three faces on edge (0, 1): one non-manifold edge, both ends non-manifold.
        let fin = Topology::new(&mesh(vec![vec![0, 1, 2], vec![1, 0, 3], vec![0, 1, 4]])).unwrap();
        assert_eq!(fin.num_edges(), 7);
        assert!(fin.is_non_manifold_edge(0));
        assert_eq!(fin.edge_uses(0).len(), 3);
        assert!(fin.is_non_manifold_vertex(0) && fin.is_non_manifold_vertex(1));
        assert!(!fin.is_non_manifold_vertex(2));
        // Each face at vertex 0 is its own open fan.
        assert_eq!(fin.vertex_fans(0).1, 3);
        // A degenerate quad (2, 2): its own non-manifold edge every time.
        let pole = Topology::new(&mesh(vec![vec![0, 1, 2, 2], vec![1, 3, 2, 2]])).unwrap();
        let degenerate: Vec<u32> =
            (0..pole.num_edges() as u32).filter(|&e| pole.edge_vertices(e) == [2, 2]).collect();
        assert_eq!(degenerate.len(), 2);
        assert!(degenerate.iter().all(|&e| pole.is_non_manifold_edge(e)));
        // Two faces in the same direction.
        let flipped = Topology::new(&mesh(vec![vec![0, 1, 2], vec![0, 1, 3]])).unwrap();
        assert!(flipped.is_non_manifold_edge(0));
        // A bowtie vertex: manifold edges, two fans.
        let bowtie = Topology::new(&mesh(vec![vec![0, 1, 2], vec![0, 3, 4]])).unwrap();
        assert!((0..bowtie.num_edges() as u32).all(|e| !bowtie.is_non_manifold_edge(e)));
        assert!(bowtie.is_non_manifold_vertex(0) && !bowtie.is_non_manifold_vertex(1));
    }
}
