//! Reference Catmull-Clark on the CPU (SPEC §5.1): any polygon mesh — closed or
//! open, manifold or not — with semi-sharp and infinitely sharp creases, corners, holes,
//! the three boundary modes, both creasing methods and both triangle weightings, any
//! level, positions in f64; the surface of OpenSubdiv's `CATMARK` with the same options,
//! in the same vertex and face order.
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
//! The smooth masks (the thesis' "máscaras", Ch. 2.2) are applied by scattering each face
//! point and each edge's ends into the sums the edge and vertex masks need, so no level
//! keeps vertex→edge or edge→face tables. Sharp features follow OpenSubdiv's rules
//! (`crease`): at the base level boundary and non-manifold edges become infinitely sharp,
//! and so do corners (with `EdgeAndCorner`) and non-manifold vertices (except along a
//! non-manifold crease); each sharp edge's children inherit its decayed sharpness; edge
//! points of sharp edges are midpoints, or blends with the smooth point where the crease
//! fades out. The few vertices with a sharp edge or sharpness keep a list of their sharp
//! edges in OpenSubdiv's order around the vertex (the order of its `f32` sums), which
//! every level passes on to the children.

use glam::DVec3;

use crate::mesh::Mesh;

use super::crease::{self, INFINITE, Method, Rule, SemiSharpSum};
use super::features::{Boundary, Features, Options, Surface, Triangles};
use super::topology::{NONE, REVERSED, Topology};
use super::{Result, SubdivError};

/// A refined surface: the mesh (no faces under holes; their vertices stay, as in
/// OpenSubdiv) and the refined edges that descend from sharp edges of the control mesh.
#[derive(Clone, Debug, PartialEq)]
pub struct Refined {
    pub mesh: Mesh,
    pub sharp_edges: Vec<SharpEdge>,
}

/// A refined edge lying on a sharp edge of the control mesh: what a renderer draws as a
/// crease. `sharpness` is the control edge's (≥ 10: infinitely sharp), after
/// OpenSubdiv's sharpening of boundary and non-manifold edges.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SharpEdge {
    pub vertices: [u32; 2],
    pub sharpness: f32,
    /// The control edge has one face.
    pub boundary: bool,
    /// The control edge is non-manifold (degenerate, repeated, more than two faces, or two
    /// faces in the same direction).
    pub non_manifold: bool,
}

/// Refines `mesh` `levels` times with Catmull-Clark, no sharp features, default options;
/// after one level every face is a quad. Level 0 returns a copy.
pub fn refine(mesh: &Mesh, levels: u32) -> Result<Mesh> {
    Ok(refine_parts(mesh, &Features::default(), &Options::default(), levels)?.mesh)
}

/// Refines a surface with its sharp features and options `levels` times.
pub fn refine_surface(surface: &Surface, levels: u32) -> Result<Refined> {
    refine_parts(&surface.mesh, &surface.features, &surface.options, levels)
}

fn refine_parts(mesh: &Mesh, features: &Features, options: &Options, levels: u32) -> Result<Refined> {
    let mut refiner = Refiner::new(mesh, features, options)?;
    for l in 1..=levels {
        refiner.step(l < levels)?;
    }
    refiner.finish()
}

/// A sharp control edge that refined edges descend from: (sharpness, boundary,
/// non-manifold), see [`SharpEdge`].
pub(crate) type SharpOrigin = (f32, bool, bool);

/// Level-by-level refinement, for the fragment path's CPU base level (which needs the
/// levels' topology and sharpness) and for [`refine_surface`].
pub(crate) struct Refiner {
    level: Level,
    depth: u32,
    /// The last step built no topology: nothing more can be refined.
    finished: bool,
    options: Options,
    /// The sharp edges of the base level (see [`SharpEdge`]), indexed by `edge_origin`.
    base_sharp: Vec<SharpOrigin>,
}

impl Refiner {
    pub(crate) fn new(mesh: &Mesh, features: &Features, options: &Options) -> Result<Refiner> {
        let topology = Topology::new(mesh)?;
        let (level, base_sharp) = Level::base(mesh, &topology, features, options)?;
        Ok(Refiner { level, depth: 0, finished: false, options: *options, base_sharp })
    }

    /// One level; without `with_topology` only the child's faces are built (a last level
    /// needs no edges), and no further step is possible.
    pub(crate) fn step(&mut self, with_topology: bool) -> Result<()> {
        if self.finished {
            return Err(SubdivError::Fragment("a level built without topology cannot be refined".into()));
        }
        self.level.check_size(self.depth + 1)?;
        self.level = self.level.refine(&self.options, self.depth == 0, with_topology);
        self.depth += 1;
        self.finished = !with_topology;
        Ok(())
    }

    pub(crate) fn level(&self) -> &Level {
        &self.level
    }

    pub(crate) fn depth(&self) -> u32 {
        self.depth
    }

    pub(crate) fn options(&self) -> &Options {
        &self.options
    }

    /// The control edge that edge `e` of the current level lies on, if it is sharp:
    /// (sharpness, boundary, non-manifold).
    pub(crate) fn edge_origin(&self, e: u32) -> Option<SharpOrigin> {
        let o = self.level.edge_origin.as_ref()?[e as usize];
        (o != NONE).then(|| self.base_sharp[o as usize])
    }

    /// The sharp edges of the current level (see [`SharpEdge`]).
    pub(crate) fn sharp_edges(&self) -> Vec<SharpEdge> {
        let mut out = Vec::new();
        let origin = self.level.edge_origin.as_deref().unwrap_or(&[]);
        for (e, &o) in origin.iter().enumerate() {
            if o != NONE {
                let (sharpness, boundary, non_manifold) = self.base_sharp[o as usize];
                let vertices = self.level.edge_verts[e];
                out.push(SharpEdge { vertices, sharpness, boundary, non_manifold });
            }
        }
        out.extend(self.level.last_sharp_edges.iter().map(|&(vertices, o)| {
            let (sharpness, boundary, non_manifold) = self.base_sharp[o as usize];
            SharpEdge { vertices, sharpness, boundary, non_manifold }
        }));
        out
    }

    pub(crate) fn finish(self) -> Result<Refined> {
        let sharp_edges = self.sharp_edges();
        Ok(Refined { mesh: self.level.into_mesh()?, sharp_edges })
    }
}

/// Faces of a level: polygons at the base, quads (4 corners each) after.
enum Faces {
    Polygons(Vec<u32>),
    Quads,
}

/// The sharpness of a level's edges and vertices, and its sharp vertices.
struct Sharp {
    edge: Vec<f32>,
    vertex: Vec<f32>,
    /// Every vertex with a sharp edge or a sharpness, with its sharp edges as
    /// `edge << 1 | end` (the vertex is `edge_verts[edge][end]`), in OpenSubdiv's order:
    /// `edges[offsets[i]..offsets[i + 1]]` for vertex `verts[i]`.
    verts: Vec<u32>,
    offsets: Vec<u32>,
    edges: Vec<u32>,
}

impl Sharp {
    fn list(&self, i: usize) -> &[u32] {
        &self.edges[self.offsets[i] as usize..self.offsets[i + 1] as usize]
    }
}

/// The sharpness the features tag: each edge's (creases), each vertex's (corners), and
/// the faces that are holes (`None`: none).
#[allow(clippy::type_complexity)]
fn tagged(topo: &Topology, features: &Features) -> Result<(Vec<f32>, Vec<f32>, Option<Vec<bool>>)> {
    let (nv, ne, nf) = (topo.num_vertices(), topo.num_edges(), topo.num_faces());
    let feature = |m: String| SubdivError::Feature(m);
    let mut edge_sharp = vec![0.0f32; ne];
    if !features.creases.is_empty() {
        // The first edge of each vertex pair (OpenSubdiv's findEdge).
        let mut first = std::collections::HashMap::with_capacity(ne);
        for (e, &[a, b]) in topo.edge_verts().iter().enumerate().rev() {
            first.insert((a.min(b), a.max(b)), e as u32);
        }
        for (i, c) in features.creases.iter().enumerate() {
            let [a, b] = c.vertices;
            check_sharpness(c.sharpness).map_err(|m| feature(format!("crease {i}: {m}")))?;
            let e = first.get(&(a.min(b), a.max(b))).ok_or_else(|| {
                feature(format!("crease {i}: vertices {a} and {b} are not joined by an edge"))
            })?;
            edge_sharp[*e as usize] = c.sharpness;
        }
    }
    let mut vertex_sharp = vec![0.0f32; nv];
    for (i, c) in features.corners.iter().enumerate() {
        check_sharpness(c.sharpness).map_err(|m| feature(format!("corner {i}: {m}")))?;
        let slot = vertex_sharp.get_mut(c.vertex as usize).ok_or_else(|| {
            feature(format!("corner {i}: vertex {} is out of range ({nv} vertices)", c.vertex))
        })?;
        *slot = c.sharpness;
    }
    let mut holes = None;
    for &f in &features.holes {
        if f as usize >= nf {
            return Err(feature(format!("hole: face {f} is out of range ({nf} faces)")));
        }
        holes.get_or_insert_with(|| vec![false; nf])[f as usize] = true;
    }
    Ok((edge_sharp, vertex_sharp, holes))
}

/// The incident edges of every vertex in edge order (a degenerate edge twice), each as
/// `edge << 1 | end`: the order OpenSubdiv keeps for non-manifold vertices.
struct VertexEdges {
    offsets: Vec<u32>,
    edges: Vec<u32>,
}

impl VertexEdges {
    fn new(topo: &Topology) -> VertexEdges {
        let nv = topo.num_vertices();
        let mut offsets = vec![0u32; nv + 1];
        for &[a, b] in topo.edge_verts() {
            offsets[a as usize + 1] += 1;
            offsets[b as usize + 1] += 1;
        }
        for v in 0..nv {
            offsets[v + 1] += offsets[v];
        }
        let mut fill = offsets.clone();
        let mut edges = vec![0u32; offsets[nv] as usize];
        for (e, &[a, b]) in topo.edge_verts().iter().enumerate() {
            for (v, end) in [(a, 0), (b, 1)] {
                edges[fill[v as usize] as usize] = ((e as u32) << 1) | end;
                fill[v as usize] += 1;
            }
        }
        VertexEdges { offsets, edges }
    }

    fn of(&self, v: usize) -> &[u32] {
        &self.edges[self.offsets[v] as usize..self.offsets[v + 1] as usize]
    }
}

/// Without boundary interpolation: the faces at a boundary vertex with a boundary edge
/// not tagged infinitely sharp are holes (decided before boundary edges are sharpened).
fn boundary_holes(
    topo: &Topology,
    indices: &[u32],
    vertex_edges: &VertexEdges,
    edge_sharp: &[f32],
    holes: &mut Option<Vec<bool>>,
) {
    let (nv, nf) = (topo.num_vertices(), topo.num_faces());
    let mut excluded = vec![false; nv];
    for (v, out) in excluded.iter_mut().enumerate() {
        let manifold_interior = topo.valence(v as u32) == topo.num_vertex_faces(v as u32)
            && !topo.is_non_manifold_vertex(v as u32);
        if !manifold_interior {
            *out = vertex_edges.of(v).iter().any(|&x| {
                topo.num_edge_faces(x >> 1) < 2 && !crease::is_infinite(edge_sharp[(x >> 1) as usize])
            });
        }
    }
    for (h, &v) in indices.iter().enumerate() {
        if excluded[v as usize] {
            holes.get_or_insert_with(|| vec![false; nf])[topo.face(h as u32) as usize] = true;
        }
    }
}

/// OpenSubdiv's rules: boundary and non-manifold edges infinitely sharp, then corners
/// (with corner interpolation) and non-manifold vertices not along a crease.
fn sharpen(
    topo: &Topology,
    options: &Options,
    vertex_edges: &VertexEdges,
    edge_sharp: &mut [f32],
    vertex_sharp: &mut [f32],
) {
    let one_face = |e: u32| topo.num_edge_faces(e) < 2;
    for (e, s) in edge_sharp.iter_mut().enumerate() {
        if one_face(e as u32) || topo.is_non_manifold_edge(e as u32) {
            *s = INFINITE;
        }
    }
    for (v, s) in vertex_sharp.iter_mut().enumerate() {
        let (faces, edges) = (topo.num_vertex_faces(v as u32), topo.valence(v as u32));
        let (mut boundary, mut non_manifold) = (0, 0);
        for &x in vertex_edges.of(v) {
            boundary += usize::from(one_face(x >> 1));
            non_manifold += usize::from(topo.is_non_manifold_edge(x >> 1));
        }
        let corner = faces == 1 && edges == 2;
        if corner && options.boundary == Boundary::EdgeAndCorner {
            *s = INFINITE;
        } else if topo.is_non_manifold_vertex(v as u32) {
            // Not along a non-manifold crease: two non-manifold edges, no boundary, more
            // faces than edges (the fins of a crease).
            let crease_line = non_manifold == 2 && boundary == 0 && faces > edges;
            if !crease_line {
                *s = INFINITE;
            }
        }
    }
}

impl Sharp {
    /// The sharp vertices with their sharp edges in OpenSubdiv's order: around the fan of
    /// a manifold vertex (from its start), in edge order at a non-manifold one.
    fn ordered(topo: &Topology, vertex_edges: &VertexEdges, edge: Vec<f32>, vertex: Vec<f32>) -> Sharp {
        let mut sharp = Sharp { edge, vertex, verts: Vec::new(), offsets: vec![0], edges: Vec::new() };
        let mut ordered = Vec::new();
        for v in 0..topo.num_vertices() as u32 {
            let any_edge = vertex_edges.of(v as usize).iter().any(|&x| sharp.edge[(x >> 1) as usize] > 0.0);
            if !any_edge && sharp.vertex[v as usize] <= 0.0 {
                continue;
            }
            ordered.clear();
            match topo.vertex_fans(v) {
                (Some(fan), 1) if !topo.is_non_manifold_vertex(v) => {
                    let fan = topo.fans()[fan as usize];
                    let corners = topo.fan_corners(&fan);
                    for &h in corners {
                        ordered.push((topo.edge(h) << 1) | u32::from(topo.is_reversed(h)));
                    }
                    if !fan.closed {
                        let p = topo.prev(corners[corners.len() - 1]);
                        ordered.push((topo.edge(p) << 1) | u32::from(!topo.is_reversed(p)));
                    }
                }
                _ => ordered.extend_from_slice(vertex_edges.of(v as usize)),
            }
            sharp.verts.push(v);
            sharp.edges.extend(ordered.iter().filter(|&&x| sharp.edge[(x >> 1) as usize] > 0.0));
            sharp.offsets.push(sharp.edges.len() as u32);
        }
        sharp
    }
}

/// One subdivision level: positions plus the topology and sharpness needed to refine it
/// once more.
pub(crate) struct Level {
    positions: Vec<DVec3>,
    faces: Faces,
    /// Vertex of each face corner.
    face_verts: Vec<u32>,
    /// Edge leaving each face corner, `edge << 1 | REVERSED?`.
    face_edges: Vec<u32>,
    /// The two vertices of each edge, in the edge's orientation.
    edge_verts: Vec<[u32; 2]>,
    /// `None` when every edge and vertex is smooth.
    sharp: Option<Sharp>,
    /// Hole flag of each face; `None` without holes.
    holes: Option<Vec<bool>>,
    /// The base sharp edge each edge lies on (`NONE` if none); `None` when the base has no
    /// sharp edge.
    edge_origin: Option<Vec<u32>>,
    /// A last level has no edges: the children of the parent's sharp edges, kept here.
    last_sharp_edges: Vec<([u32; 2], u32)>,
    /// Base level with smooth triangles: how many of an edge's two faces are triangles.
    edge_triangles: Option<Vec<u8>>,
}

impl Level {
    /// The base level, numbered as OpenSubdiv numbers it, with the features applied and
    /// sharpened by OpenSubdiv's rules. Also returns the sharp base edges' (sharpness,
    /// boundary, non-manifold).
    fn base(
        mesh: &Mesh,
        topo: &Topology,
        features: &Features,
        options: &Options,
    ) -> Result<(Level, Vec<SharpOrigin>)> {
        let (offsets, indices) = mesh.face_parts();
        let (mut edge_sharp, mut vertex_sharp, mut holes) = tagged(topo, features)?;
        let vertex_edges = VertexEdges::new(topo);
        if options.boundary == Boundary::None {
            boundary_holes(topo, indices, &vertex_edges, &edge_sharp, &mut holes);
        }
        sharpen(topo, options, &vertex_edges, &mut edge_sharp, &mut vertex_sharp);
        let sharp = Sharp::ordered(topo, &vertex_edges, edge_sharp, vertex_sharp);
        let ne = topo.num_edges();
        let mut base_sharp = Vec::new();
        let mut edge_origin = vec![NONE; ne];
        for (e, origin) in edge_origin.iter_mut().enumerate() {
            let s = sharp.edge[e];
            if s > 0.0 {
                *origin = base_sharp.len() as u32;
                base_sharp.push((s, topo.num_edge_faces(e as u32) < 2, topo.is_non_manifold_edge(e as u32)));
            }
        }
        let edge_triangles = (options.triangles == Triangles::Smooth).then(|| {
            (0..ne as u32)
                .map(|e| match *topo.edge_uses(e) {
                    [h0, h1] => {
                        let tri = |h: u32| u8::from(topo.face_half_edges(topo.face(h)).len() == 3);
                        tri(h0) + tri(h1)
                    }
                    _ => 0,
                })
                .collect()
        });
        let has_sharp = !sharp.verts.is_empty();
        let level = Level {
            positions: mesh.positions().to_vec(),
            faces: Faces::Polygons(offsets.iter().map(|&o| o as u32).collect()),
            face_verts: indices.to_vec(),
            face_edges: topo.edge_flags().to_vec(),
            edge_verts: topo.edge_verts().to_vec(),
            sharp: has_sharp.then_some(sharp),
            holes,
            edge_origin: (!base_sharp.is_empty()).then_some(edge_origin),
            last_sharp_edges: Vec::new(),
            edge_triangles,
        };
        Ok((level, base_sharp))
    }

    pub(crate) fn positions(&self) -> &[DVec3] {
        &self.positions
    }

    pub(crate) fn num_faces(&self) -> usize {
        match &self.faces {
            Faces::Polygons(offsets) => offsets.len() - 1,
            Faces::Quads => self.face_verts.len() / 4,
        }
    }

    /// CSR offsets of the faces.
    pub(crate) fn face_offsets(&self) -> Vec<u32> {
        match &self.faces {
            Faces::Polygons(offsets) => offsets.clone(),
            Faces::Quads => (0..=self.face_verts.len() as u32).step_by(4).collect(),
        }
    }

    pub(crate) fn is_all_quads(&self) -> bool {
        match &self.faces {
            Faces::Polygons(offsets) => offsets.windows(2).all(|w| w[1] - w[0] == 4),
            Faces::Quads => true,
        }
    }

    /// The topology of this level (fans, twins), with the level's own edge numbering.
    pub(crate) fn topology(&self) -> Topology {
        Topology::from_refined(
            self.positions.len(),
            self.face_offsets(),
            self.face_verts.clone(),
            self.face_edges.clone(),
            self.edge_verts.clone(),
        )
    }

    pub(crate) fn edge_sharpness(&self, e: u32) -> f32 {
        self.sharp.as_ref().map_or(0.0, |s| s.edge[e as usize])
    }

    pub(crate) fn vertex_sharpness(&self, v: u32) -> f32 {
        self.sharp.as_ref().map_or(0.0, |s| s.vertex[v as usize])
    }

    /// The sharp vertices with their sharp edges (`edge << 1 | end`), in OpenSubdiv's order.
    pub(crate) fn sharp_vertices(&self) -> impl Iterator<Item = (u32, &[u32])> + '_ {
        self.sharp.iter().flat_map(|s| (0..s.verts.len()).map(move |i| (s.verts[i], s.list(i))))
    }

    /// True when an edge or vertex is sharp (boundaries included).
    pub(crate) fn has_sharpness(&self) -> bool {
        self.sharp.is_some()
    }

    pub(crate) fn is_hole(&self, f: u32) -> bool {
        self.holes.as_ref().is_some_and(|h| h[f as usize])
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

    /// One Catmull-Clark step. Without `with_topology` only the child's faces are built.
    fn refine(&self, options: &Options, base: bool, with_topology: bool) -> Level {
        let mut child = Child::new(self, options, base, with_topology);
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
        let (offsets, indices) = match (self.faces, self.holes) {
            (Faces::Polygons(offsets), None) => {
                (offsets.into_iter().map(|o| o as usize).collect(), self.face_verts)
            }
            (Faces::Quads, None) => ((0..=self.face_verts.len()).step_by(4).collect(), self.face_verts),
            (faces, Some(holes)) => {
                let offsets: Vec<usize> = match faces {
                    Faces::Polygons(o) => o.into_iter().map(|o| o as usize).collect(),
                    Faces::Quads => (0..=self.face_verts.len()).step_by(4).collect(),
                };
                let mut kept_offsets = vec![0];
                let mut kept = Vec::new();
                for (f, w) in offsets.windows(2).enumerate() {
                    if !holes[f] {
                        kept.extend_from_slice(&self.face_verts[w[0]..w[1]]);
                        kept_offsets.push(kept.len());
                    }
                }
                (kept_offsets, kept)
            }
        };
        Ok(Mesh::from_parts(self.positions, offsets, indices)?)
    }
}

/// A sharpness value a feature may have: finite and not negative.
fn check_sharpness(s: f32) -> std::result::Result<(), String> {
    if s.is_finite() && s >= 0.0 {
        Ok(())
    } else {
        Err(format!("sharpness {s} is not a finite number ≥ 0"))
    }
}

/// A child level under construction, with the per-parent-vertex sums of the vertex mask.
struct Child {
    level: Level,
    with_topology: bool,
    method: Method,
    /// Smooth-triangle weights apply (base level with `Triangles::Smooth`).
    smooth_triangles: bool,
    /// First child index of face points and of edge points.
    face_point0: u32,
    edge_point0: u32,
    /// First child index of the edges halving parent edges (= number of parent corners).
    edge_edge0: u32,
    /// Number of edges at each parent vertex.
    valence: Vec<u32>,
    /// Chaikin only: each parent sharp vertex's semi-sharp sum, by vertex (`around_of`).
    around: Vec<SemiSharpSum>,
    around_of: Vec<u32>,
    /// Child sharpness of both halves of each parent edge (sharp parents only).
    halves: Vec<[f32; 2]>,
}

impl Child {
    fn new(parent: &Level, options: &Options, base: bool, with_topology: bool) -> Child {
        let (nv, nf, ne, nc) =
            (parent.positions.len(), parent.num_faces(), parent.edge_verts.len(), parent.face_verts.len());
        let (faces, edges) = if with_topology { (4 * nc, nc + 2 * ne) } else { (4 * nc, 0) };
        let mut child = Child {
            level: Level {
                positions: vec![DVec3::ZERO; nv + nf + ne],
                faces: Faces::Quads,
                face_verts: Vec::with_capacity(faces),
                face_edges: Vec::with_capacity(if with_topology { faces } else { 0 }),
                edge_verts: Vec::with_capacity(edges),
                sharp: None,
                holes: parent.holes.as_ref().map(|_| Vec::with_capacity(nc)),
                edge_origin: parent
                    .edge_origin
                    .as_ref()
                    .filter(|_| with_topology)
                    .map(|_| Vec::with_capacity(edges)),
                last_sharp_edges: Vec::new(),
                edge_triangles: None,
            },
            with_topology,
            method: options.crease_method,
            smooth_triangles: base && options.triangles == Triangles::Smooth,
            face_point0: nv as u32,
            edge_point0: (nv + nf) as u32,
            edge_edge0: nc as u32,
            valence: vec![0; nv],
            around: Vec::new(),
            around_of: Vec::new(),
            halves: Vec::new(),
        };
        if let Some(sharp) = &parent.sharp {
            for &[a, b] in &parent.edge_verts {
                child.valence[a as usize] += 1;
                child.valence[b as usize] += 1;
            }
            if child.method == Method::Chaikin {
                child.around_of = vec![NONE; nv];
                for (i, &v) in sharp.verts.iter().enumerate() {
                    child.around_of[v as usize] = i as u32;
                    child
                        .around
                        .push(SemiSharpSum::of(sharp.list(i).iter().map(|&x| sharp.edge[(x >> 1) as usize])));
                }
            }
            child.halves = vec![[0.0; 2]; ne];
        }
        child
    }

    /// Child sharpness of edge `e` (sharpness `s`) at its vertex `v`.
    fn child_sharpness(&self, s: f32, v: u32) -> f32 {
        match self.method {
            Method::Uniform => crease::decrement(s),
            Method::Chaikin => {
                let around = match self.around_of.get(v as usize) {
                    Some(&i) if i != NONE => self.around[i as usize],
                    _ => SemiSharpSum::default(),
                };
                crease::chaikin(s, around, self.valence[v as usize])
            }
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
            if let (Some(holes), Some(parent_holes)) = (&mut self.level.holes, &parent.holes) {
                holes.extend(std::iter::repeat_n(parent_holes[f], verts.len()));
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
            }
            if let Some(origin) = &mut self.level.edge_origin {
                origin.extend(std::iter::repeat_n(NONE, n));
            }
        }
    }

    /// Edge points (the face sums are in place) and the neighbour sums of the vertex mask.
    /// A sharp edge's point is the midpoint while both children stay sharp, else the
    /// midpoint and the smooth point blended by the edge's sharpness.
    fn edge_pass(&mut self, parent: &Level) {
        let pos = &parent.positions;
        let sharp = parent.sharp.as_ref();
        for (e, &[a, b]) in parent.edge_verts.iter().enumerate() {
            let (pa, pb) = (pos[a as usize], pos[b as usize]);
            let face_sum = self.level.positions[self.edge_point0 as usize + e];
            let smooth = match &parent.edge_triangles {
                Some(triangles) if self.smooth_triangles && triangles[e] > 0 => {
                    // OpenSubdiv's smooth-triangle weights (Hbr's order of operations).
                    let (w0, w1) = if triangles[e] == 2 { (0.47, 0.47) } else { (0.47, 0.25) };
                    let face_weight = 0.5 * (w0 + w1);
                    let vertex_weight = 0.5 * (1.0 - 2.0 * face_weight);
                    (pa + pb) * vertex_weight + face_sum * face_weight
                }
                _ => (pa + pb + face_sum) * 0.25,
            };
            let s = sharp.map_or(0.0, |sh| sh.edge[e]);
            let point = if s > 0.0 {
                let halves = [self.child_sharpness(s, a), self.child_sharpness(s, b)];
                self.halves[e] = halves;
                let mid = (pa + pb) * 0.5;
                if halves[0] > 0.0 && halves[1] > 0.0 {
                    mid
                } else {
                    let w = f64::from(s);
                    mid * w + smooth * (1.0 - w)
                }
            } else {
                smooth
            };
            let out = &mut self.level.positions;
            out[self.edge_point0 as usize + e] = point;
            out[a as usize] += pb;
            out[b as usize] += pa;
            if sharp.is_none() {
                self.valence[a as usize] += 1;
                self.valence[b as usize] += 1;
            }
            let edge_point = self.edge_point0 + e as u32;
            if self.with_topology {
                self.level.edge_verts.extend_from_slice(&[[edge_point, a], [edge_point, b]]);
                if let Some(origin) = &mut self.level.edge_origin {
                    let o = parent.edge_origin.as_ref().map_or(NONE, |p| p[e]);
                    origin.extend_from_slice(&[o, o]);
                }
            } else if let Some(origin) = &parent.edge_origin
                && origin[e] != NONE
            {
                self.level.last_sharp_edges.push(([edge_point, a], origin[e]));
                self.level.last_sharp_edges.push(([edge_point, b], origin[e]));
            }
        }
    }

    /// Vertex points: `((n−2)/n)·V + (Σ neighbours + Σ face points)/n²` at smooth vertices;
    /// the crease or corner masks, and their blends, at sharp ones.
    fn vertex_pass(&mut self, parent: &Level) {
        let out = &mut self.level.positions;
        for (v, (&p, &valence)) in parent.positions.iter().zip(&self.valence).enumerate() {
            out[v] = if valence == 0 {
                p // a vertex no face uses stays put, as in OpenSubdiv
            } else {
                let n = f64::from(valence);
                p * ((n - 2.0) / n) + out[v] * (1.0 / (n * n))
            };
        }
        let Some(sharp) = &parent.sharp else { return };
        let method = self.method;
        let mut child_sharp = self.with_topology.then(|| Sharp {
            edge: vec![0.0; self.level.edge_verts.len()],
            vertex: vec![0.0; self.level.positions.len()],
            verts: Vec::new(),
            offsets: vec![0],
            edges: Vec::new(),
        });
        let mut child_s = Vec::new();
        for (i, &v) in sharp.verts.iter().enumerate() {
            let list = sharp.list(i);
            let p = parent.positions[v as usize];
            let vs = sharp.vertex[v as usize];
            let cvs = crease::decrement(vs);
            child_s.clear();
            child_s.extend(list.iter().map(|&x| self.halves[(x >> 1) as usize][(x & 1) as usize]));
            let neighbour = |x: u32| {
                parent.positions[parent.edge_verts[(x >> 1) as usize][(1 - (x & 1)) as usize] as usize]
            };
            let smooth = self.level.positions[v as usize];
            let p_rule = Rule::of(vs, list.len());
            let c_rule = Rule::of(cvs, child_s.iter().filter(|&&s| s > 0.0).count());
            let crease_mask = |which: &dyn Fn(usize) -> bool| {
                let ends: DVec3 = (0..list.len()).filter(|&k| which(k)).map(|k| neighbour(list[k])).sum();
                p * 0.75 + ends * 0.125
            };
            let mask = |rule: Rule, child: bool| match rule {
                Rule::Smooth | Rule::Dart => smooth,
                Rule::Crease => crease_mask(&|k| !child || child_s[k] > 0.0),
                Rule::Corner => p,
            };
            let point = if p_rule.is_smooth() {
                smooth
            } else if c_rule == p_rule {
                mask(p_rule, false)
            } else {
                let pairs = list.iter().zip(&child_s).map(|(&x, &c)| (sharp.edge[(x >> 1) as usize], c));
                let w = f64::from(crease::fractional_weight(method, vs, cvs, pairs));
                mask(p_rule, false) * w + mask(c_rule, true) * (1.0 - w)
            };
            self.level.positions[v as usize] = point;
            if let Some(cs) = &mut child_sharp {
                // The vertex point keeps the halves of its edges that stay sharp, in order.
                let before = cs.edges.len();
                for (&x, &c) in list.iter().zip(&child_s) {
                    if c > 0.0 {
                        let half = self.edge_edge0 + 2 * (x >> 1) + (x & 1);
                        cs.edges.push((half << 1) | 1);
                    }
                }
                cs.vertex[v as usize] = cvs;
                if cs.edges.len() > before || cvs > 0.0 {
                    cs.verts.push(v);
                    cs.offsets.push(cs.edges.len() as u32);
                }
            }
        }
        if let Some(mut cs) = child_sharp {
            // Edge points of sharp edges: their two halves, while sharp.
            for (e, &s) in sharp.edge.iter().enumerate() {
                if s <= 0.0 {
                    continue;
                }
                let halves = self.halves[e];
                let first = self.edge_edge0 + 2 * e as u32;
                for (k, &c) in halves.iter().enumerate() {
                    cs.edge[(first + k as u32) as usize] = c;
                }
                if halves.iter().any(|&c| c > 0.0) {
                    cs.verts.push(self.edge_point0 + e as u32);
                    for (k, &c) in halves.iter().enumerate() {
                        if c > 0.0 {
                            cs.edges.push((first + k as u32) << 1);
                        }
                    }
                    cs.offsets.push(cs.edges.len() as u32);
                }
            }
            if !cs.verts.is_empty() {
                self.level.sharp = Some(cs);
            }
        }
    }
}

/// Entry `i` of `cycle` moved to position `(i + rot) % 4`.
fn rotate(cycle: [u32; 4], rot: usize) -> [u32; 4] {
    std::array::from_fn(|i| cycle[(i + 4 - rot) % 4])
}
