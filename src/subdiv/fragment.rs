//! Fragment meshes in sector layout (2010 thesis §3.3.1, after Shiue, Jones and Peters;
//! SPEC §5.2): the CPU base level, one fragment per centre vertex, the thesis' storage
//! order, and one refinement step of a fragment stream on the CPU — the stencils of
//! `glsl/subdiv/refine.frag`, in f64, so the layout is testable without a GPU.
//!
//! Names used throughout the subdivision code:
//!
//! - the *coarse* mesh P: an all-quad mesh whose vertices are the fragment centres (the
//!   input when it is all quads, else its first Catmull-Clark level);
//! - the *base level* B: P refined once on the CPU. Every B quad has exactly one corner
//!   that is a vertex point of P, so the quads around each centre (its *owned region*)
//!   tile B, and every ring-1 vertex of a centre is an edge or face point of valence 4
//!   (the validity condition of SPEC §5.2);
//! - a fragment: the 2-ring of a centre c of valence k in B, in sectors. Sector s is the
//!   P face between spokes s and s + 1 of c; its vertex (a, b) lies a steps along spoke s
//!   and b steps towards spoke s + 1. (0, b) of sector s is (b, 0) of sector s + 1 and
//!   (a, −1) of sector s is (1, a) of sector s − 1.
//! - a boundary centre (on an open mesh's border) has k faces but k + 1 spokes: its
//!   fragment is a half-fan whose last spoke k is stored as one extra entry per ring, so
//!   ring r has 2kr + 1 entries instead of 2kr.
//!
//! Storage order (the thesis'): the centre, then ring by ring; inside ring r, sector s
//! takes 2r consecutive entries t ∈ [0, 2r): t ≤ r → (r, t), t > r → (2r − t, r); a
//! half-fan's extra spoke entry (r, 0) comes last.

use glam::DVec3;

use crate::mesh::Mesh;

use super::assemble::assemble;
use super::topology::{NONE, Topology};
use super::{Result, SubdivError, cpu};

/// The sector structure shared by every fragment of a class: valence and half-fan flag.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Class {
    /// Boundary centres (half-fans) sort after closed ones.
    pub boundary: bool,
    /// Number of sectors (faces around the centre).
    pub valence: u32,
}

impl Class {
    /// Entries before ring `r` (r ≥ 1), not counting the centre: `k·r(r−1) + e·(r−1)`.
    pub fn ring_offset(self, r: u64) -> u64 {
        let k = u64::from(self.valence);
        k * r * r.saturating_sub(1) + u64::from(self.boundary) * r.saturating_sub(1)
    }

    /// Entries of a fragment of ring radius `radius`: the centre and rings 1..=radius.
    pub fn len(self, radius: u32) -> u64 {
        1 + self.ring_offset(u64::from(radius) + 1)
    }

    /// Storage index of vertex (a, b) of sector `s`, after moving (0, b) and (a, −1) to the
    /// neighbouring sector. Half-fans address their last spoke as sector `valence`.
    pub fn index(self, s: u32, a: i64, b: i64) -> u64 {
        let k = i64::from(self.valence);
        let (mut s, mut a, mut b) = (i64::from(s), a, b);
        if b < 0 {
            // (a, −1) of sector s is (1, a) of sector s − 1.
            (s, a, b) = (if s == 0 { k - 1 } else { s - 1 }, 1, a);
        }
        if a == 0 {
            if b == 0 {
                return 0;
            }
            // (0, b) of sector s is (b, 0) of sector s + 1.
            (s, a, b) = (s + 1, b, 0);
            if s == k && !self.boundary {
                s = 0;
            }
        }
        let r = a.max(b);
        let t = if a == r { b } else { 2 * r - a };
        1 + self.ring_offset(r as u64) + (s * 2 * r + t) as u64
    }

    /// The (sector, a, b) stored at index `i`; `None` for the centre (index 0).
    pub fn coords(self, i: u64) -> Option<(u32, u32, u32)> {
        let q = i.checked_sub(1)?;
        // Largest r with ring_offset(r) ≤ q, from the quadratic, then corrected.
        let (k, e) = (self.valence as f64, f64::from(u8::from(self.boundary)));
        let d = k - e;
        let mut r = (((d + (d * d + 4.0 * k * (e + q as f64)).sqrt()) / (2.0 * k)) as u64).max(1);
        while self.ring_offset(r + 1) <= q {
            r += 1;
        }
        while r > 1 && self.ring_offset(r) > q {
            r -= 1;
        }
        let u = q - self.ring_offset(r);
        let (s, t) = (u / (2 * r), u % (2 * r));
        let (a, b) = if s == u64::from(self.valence) {
            (r, 0)
        } else if t <= r {
            (r, t)
        } else {
            (2 * r - t, r)
        };
        Some((s as u32, a as u32, b as u32))
    }
}

/// A run of fragments of one class, consecutive in every stream.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ClassRun {
    pub class: Class,
    /// Index of the run's first fragment.
    pub first: u32,
    pub count: u32,
}

/// Where each class run starts in a stream of fragments of one ring radius.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct StreamLayout {
    pub radius: u32,
    /// First texel of each class run.
    pub starts: Vec<u64>,
    /// Texels of the whole stream.
    pub total: u64,
}

/// A fragment: the centre (a coarse vertex) and its class.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Fragment {
    pub centre: u32,
    pub class: Class,
    /// Index of its run in [`FragmentMesh::runs`].
    pub run: u32,
}

/// The CPU part of the thesis' step 1: the coarse all-quad mesh P and its refinement B.
pub struct BaseLevel {
    /// The coarse all-quad mesh P, whose vertices are the centres.
    pub coarse: Topology,
    /// Positions of the base level B = P refined once: P's vertex points, then its face
    /// points, then its edge points (OpenSubdiv's order, as `cpu::refine` numbers them).
    pub positions: Vec<DVec3>,
    /// Catmull-Clark levels the CPU did to reach B (1 for all-quad input, else 2).
    pub cpu_levels: u32,
}

impl BaseLevel {
    /// Levels the CPU must do before fragments exist: 1 for all-quad input, else 2.
    pub fn levels_needed(mesh: &Mesh) -> u32 {
        if mesh.faces().all(|f| f.len() == 4) { 1 } else { 2 }
    }

    /// One CPU level for all-quad input, two otherwise (SPEC §5.2). Rejects what
    /// Catmull-Clark cannot refine (non-manifold, inconsistently oriented, degenerate).
    pub fn new(mesh: &Mesh) -> Result<BaseLevel> {
        let cpu_levels = BaseLevel::levels_needed(mesh);
        let refined;
        let coarse_mesh = if cpu_levels == 1 {
            mesh
        } else {
            refined = cpu::refine(mesh, 1)?;
            &refined
        };
        let coarse = Topology::new(coarse_mesh)?;
        // `cpu::refine` numbers edge points by the same edge numbering `Topology` gives P.
        let positions = cpu::refine(coarse_mesh, 1)?.positions().to_vec();
        Ok(BaseLevel { coarse, positions, cpu_levels })
    }
}

/// The base level cut into fragment meshes (SPEC §5.2).
pub struct FragmentMesh {
    coarse: Topology,
    base: Vec<DVec3>,
    cpu_levels: u32,
    /// Sorted by class, then centre.
    fragments: Vec<Fragment>,
    runs: Vec<ClassRun>,
    /// Fragment of each coarse vertex (`NONE` for a vertex no face uses).
    fragment_of: Vec<u32>,
    /// For each coarse half-edge, its index among the spokes of its origin: the sector
    /// of the face it starts.
    sector_of: Vec<u32>,
}

impl FragmentMesh {
    /// The base level and the fragments around every vertex of the coarse mesh; closed
    /// and open manifold meshes (open ones get half-fan fragments on their border).
    pub fn new(mesh: &Mesh) -> Result<FragmentMesh> {
        FragmentMesh::from_base(BaseLevel::new(mesh)?)
    }

    /// The fragments around every vertex of the coarse mesh of `base`.
    pub fn from_base(base: BaseLevel) -> Result<FragmentMesh> {
        let BaseLevel { coarse, positions, cpu_levels } = base;
        let mut sector_of = vec![NONE; coarse.num_half_edges()];
        let mut fragments = Vec::new();
        for c in 0..coarse.num_vertices() as u32 {
            let k = coarse.num_vertex_faces(c) as u32;
            if k == 0 {
                continue;
            }
            for (s, h) in coarse.spokes(c).enumerate() {
                sector_of[h as usize] = s as u32;
            }
            let class = Class { boundary: coarse.is_boundary_vertex(c), valence: k };
            fragments.push(Fragment { centre: c, class, run: 0 });
        }
        let mesh = FragmentMesh {
            coarse,
            base: positions,
            cpu_levels,
            fragments,
            runs: Vec::new(),
            fragment_of: Vec::new(),
            sector_of,
        };
        mesh.check_validity()?;
        Ok(mesh.sorted())
    }

    /// Every sector must be a coarse quad: then B's ring-1 vertices of every centre are
    /// edge points of edges with two quads (or boundary edges of a half-fan's end spokes)
    /// and face points of quads, all of valence 4 — the fragment condition of SPEC §5.2.
    fn check_validity(&self) -> Result<()> {
        for f in 0..self.coarse.num_faces() as u32 {
            let sides = self.coarse.face_half_edges(f).len();
            if sides != 4 {
                return Err(SubdivError::Fragment(format!(
                    "coarse face {f} has {sides} sides; fragment meshes need an all-quad coarse mesh"
                )));
            }
        }
        Ok(())
    }

    /// Orders fragments by class and records the class runs.
    fn sorted(mut self) -> FragmentMesh {
        self.fragments.sort_by_key(|f| (f.class, f.centre));
        self.fragment_of = vec![NONE; self.coarse.num_vertices()];
        for (i, f) in self.fragments.iter_mut().enumerate() {
            if self.runs.last().is_none_or(|r| r.class != f.class) {
                self.runs.push(ClassRun { class: f.class, first: i as u32, count: 0 });
            }
            let run = self.runs.len() - 1;
            self.runs[run].count += 1;
            f.run = run as u32;
            self.fragment_of[f.centre as usize] = i as u32;
        }
        self
    }

    pub fn coarse(&self) -> &Topology {
        &self.coarse
    }

    /// Base-level positions (vertex points, face points, edge points of the coarse mesh).
    pub fn base_positions(&self) -> &[DVec3] {
        &self.base
    }

    pub fn cpu_levels(&self) -> u32 {
        self.cpu_levels
    }

    pub fn fragments(&self) -> &[Fragment] {
        &self.fragments
    }

    pub fn runs(&self) -> &[ClassRun] {
        &self.runs
    }

    /// The fragment centred on coarse vertex `v`, if a face uses `v`.
    pub fn fragment_of(&self, v: u32) -> Option<u32> {
        Some(self.fragment_of[v as usize]).filter(|&f| f != NONE)
    }

    /// The sector of coarse half-edge `h` around its origin (its spoke number).
    pub fn sector_of(&self, h: u32) -> u32 {
        self.sector_of[h as usize]
    }

    /// The spoke number of edge `e` at its end `v` (`v` must be an end of `e`): a half-edge
    /// leaving `v` along `e`, or, on the border, the half-fan's extra last spoke.
    pub fn spoke_along(&self, e: u32, v: u32) -> u32 {
        let h = self.coarse.edge_half_edge(e);
        let leaving = if self.coarse.origin(h) == v { Some(h) } else { self.coarse.twin(h) };
        match leaving {
            Some(h) => self.sector_of[h as usize],
            None => self.coarse.num_vertex_faces(v) as u32,
        }
    }

    /// Where every class run starts in a stream of fragments of ring radius `radius`.
    pub fn layout(&self, radius: u32) -> StreamLayout {
        let mut starts = Vec::with_capacity(self.runs.len());
        let mut total = 0u64;
        for run in &self.runs {
            starts.push(total);
            total += u64::from(run.count) * run.class.len(radius);
        }
        StreamLayout { radius, starts, total }
    }

    /// First texel of fragment `f` in a stream with `layout`.
    pub fn fragment_start(&self, layout: &StreamLayout, f: u32) -> u64 {
        let frag = &self.fragments[f as usize];
        let run = &self.runs[frag.run as usize];
        layout.starts[frag.run as usize] + u64::from(f - run.first) * frag.class.len(layout.radius)
    }

    /// The base-level vertex at (a, b) of sector `s` of the fragment centred on `c`, for
    /// 0 ≤ a, b ≤ 2 (ring radius 2) in stored form (a ≥ 1, or the centre).
    fn base_vertex(&self, c: u32, spokes: &[u32], s: u32, a: u32, b: u32) -> u32 {
        let topo = &self.coarse;
        let (nv, nf) = (topo.num_vertices() as u32, topo.num_faces() as u32);
        let vertex_point = |v: u32| v;
        let face_point = |h: u32| nv + topo.face(h);
        let edge_point = |h: u32| nv + nf + topo.edge(h);
        if (a, b) == (0, 0) {
            return vertex_point(c);
        }
        if s as usize == spokes.len() {
            // A half-fan's last spoke: the border edge that enters c.
            let incoming = topo.prev(spokes[spokes.len() - 1]);
            return if a == 1 { edge_point(incoming) } else { vertex_point(topo.origin(incoming)) };
        }
        // The sector's coarse quad, seen from corner c: h runs c → c1, next(h) c1 → c2, and
        // next(next(h)) c2 → c3, where c3 is the end of spoke s + 1.
        let h = spokes[s as usize];
        let (h1, h2) = (topo.next(h), topo.next(topo.next(h)));
        match (a, b) {
            (1, 0) => edge_point(h),
            (1, 1) => face_point(h),
            (2, 0) => vertex_point(topo.origin(h1)),
            (2, 1) => edge_point(h1),
            (2, 2) => vertex_point(topo.origin(h2)),
            (1, 2) => edge_point(h2),
            _ => unreachable!("ring radius 2 holds only a, b ≤ 2"),
        }
    }

    /// The base-level stream (ring radius 2), fragment after fragment, mapped by `texel`.
    pub fn base_stream<T>(&self, texel: impl Fn(DVec3) -> T) -> Vec<T> {
        let layout = self.layout(2);
        let mut out = Vec::with_capacity(layout.total as usize);
        let mut spokes = Vec::new();
        for frag in &self.fragments {
            spokes.clear();
            spokes.extend(self.coarse.spokes(frag.centre));
            let c = frag.centre;
            let mut push = |s: u32, a: u32, b: u32| {
                out.push(texel(self.base[self.base_vertex(c, &spokes, s, a, b) as usize]));
            };
            // The storage order: centre, then ring by ring, sector by sector (t ≤ r → (r, t),
            // t > r → (2r − t, r)), a half-fan's last spoke at the end of each ring.
            push(0, 0, 0);
            for r in 1..=2 {
                for s in 0..frag.class.valence {
                    for t in 0..2 * r {
                        if t <= r { push(s, r, t) } else { push(s, 2 * r - t, r) }
                    }
                }
                if frag.class.boundary {
                    push(frag.class.valence, r, 0);
                }
            }
        }
        out
    }

    /// One Catmull-Clark level of every fragment on the CPU, in f64: reads a stream of ring
    /// radius `r_in`, writes one of radius `r_out` ≤ 2·r_in − 1. The same stencils and
    /// addressing as the GPU pass (`glsl/subdiv/refine.frag`).
    pub fn refine_stream(&self, input: &[DVec3], r_in: u32, r_out: u32) -> Vec<DVec3> {
        let (lin, lout) = (self.layout(r_in), self.layout(r_out));
        let mut out = vec![DVec3::ZERO; lout.total as usize];
        for f in 0..self.fragments.len() as u32 {
            let class = self.fragments[f as usize].class;
            let (base_in, base_out) = (self.fragment_start(&lin, f), self.fragment_start(&lout, f));
            let fetch = |s: u32, a: i64, b: i64| input[(base_in + class.index(s, a, b)) as usize];
            for i in 0..class.len(r_out) {
                out[(base_out + i) as usize] = stencil(class, i, fetch);
            }
        }
        out
    }
}

/// Ring radius of the stream after each fragment level: 2 at the base level, 2^j + 1
/// after j levels (2R − 1 from R), except the last, which keeps only its 2^j owned rings.
pub fn radii(levels: u32) -> Vec<u32> {
    (0..=levels)
        .map(|j| match j {
            0 => 2,
            j if j == levels => 1 << j,
            j => (1 << j) + 1,
        })
        .collect()
}

/// The whole fragment-mesh algorithm on the CPU in f64 (base level, [`FragmentMesh::
/// refine_stream`] per level, assembly): the GPU path's arithmetic without a GPU, to
/// test the layout, stencils and welding exactly. Levels below the base level are
/// refined by [`cpu::refine`].
pub fn refine(mesh: &Mesh, level: u32) -> Result<Mesh> {
    let needed = BaseLevel::levels_needed(mesh);
    if level < needed {
        return cpu::refine(mesh, level);
    }
    let fragments = FragmentMesh::new(mesh)?;
    let levels = level - needed;
    let radii = radii(levels);
    let mut stream = fragments.base_stream(|p| p);
    for pair in radii.windows(2) {
        stream = fragments.refine_stream(&stream, pair[0], pair[1]);
    }
    assemble(&fragments, &stream, radii[levels as usize], levels, |p| *p)
}

/// The Catmull-Clark stencil (the thesis' masks, Ch. 2.2) of output entry `i` of a
/// fragment of `class`, reading the previous level through `p(s, a, b)`: both output
/// coordinates even → vertex point, one odd → edge point, both odd → face point.
pub fn stencil(class: Class, i: u64, p: impl Fn(u32, i64, i64) -> DVec3) -> DVec3 {
    let k = class.valence;
    let Some((s, a, b)) = class.coords(i) else {
        // The centre: valence-k rule, or the boundary rule on a half-fan.
        let c = p(0, 0, 0);
        if class.boundary {
            return 0.75 * c + 0.125 * (p(0, 1, 0) + p(k, 1, 0));
        }
        let (mut edges, mut diagonals) = (DVec3::ZERO, DVec3::ZERO);
        for s in 0..k {
            edges += p(s, 1, 0);
            diagonals += p(s, 1, 1);
        }
        let n = f64::from(k);
        return c * (1.0 - 7.0 / (4.0 * n)) + edges * (1.5 / (n * n)) + diagonals * (0.25 / (n * n));
    };
    let (a, b) = (i64::from(a), i64::from(b));
    let on_border = class.boundary && b == 0 && (s == 0 || s == k);
    match (a % 2, b % 2) {
        (0, 0) => {
            let (a, b) = (a / 2, b / 2);
            if on_border {
                0.75 * p(s, a, 0) + 0.125 * (p(s, a - 1, 0) + p(s, a + 1, 0))
            } else {
                let edges = p(s, a + 1, b) + p(s, a - 1, b) + p(s, a, b + 1) + p(s, a, b - 1);
                let diagonals =
                    p(s, a + 1, b + 1) + p(s, a - 1, b + 1) + p(s, a + 1, b - 1) + p(s, a - 1, b - 1);
                (36.0 * p(s, a, b) + 6.0 * edges + diagonals) / 64.0
            }
        }
        (1, 0) => {
            let (a, b) = (a / 2, b / 2);
            let ends = p(s, a, b) + p(s, a + 1, b);
            if on_border {
                0.5 * ends
            } else {
                let sides = p(s, a, b + 1) + p(s, a + 1, b + 1) + p(s, a, b - 1) + p(s, a + 1, b - 1);
                (6.0 * ends + sides) / 16.0
            }
        }
        (0, 1) => {
            let (a, b) = (a / 2, b / 2);
            let ends = p(s, a, b) + p(s, a, b + 1);
            let sides = p(s, a + 1, b) + p(s, a + 1, b + 1) + p(s, a - 1, b) + p(s, a - 1, b + 1);
            (6.0 * ends + sides) / 16.0
        }
        _ => {
            let (a, b) = (a / 2, b / 2);
            (p(s, a, b) + p(s, a + 1, b) + p(s, a + 1, b + 1) + p(s, a, b + 1)) * 0.25
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn storage_order_is_the_theses() {
        let c = Class { boundary: false, valence: 5 };
        // Ring r starts at 1 + k·r(r−1) and has 2kr entries.
        assert_eq!(c.index(0, 1, 0), 1);
        assert_eq!(c.index(0, 2, 0), 1 + 10);
        assert_eq!(c.len(2), 1 + 5 * 2 * 3);
        // Sector s of ring 2: (2,0) (2,1) (2,2) (1,2).
        let ring2: Vec<_> = (0..4).map(|t| c.coords(11 + 4 + t).unwrap()).collect();
        assert_eq!(ring2, [(1, 2, 0), (1, 2, 1), (1, 2, 2), (1, 1, 2)]);
        // (0, b) of sector s is (b, 0) of sector s + 1; (a, −1) is (1, a) of sector s − 1.
        assert_eq!(c.index(4, 0, 2), c.index(0, 2, 0));
        assert_eq!(c.index(0, 2, -1), c.index(4, 1, 2));
        assert_eq!(c.index(0, 0, -1), c.index(4, 1, 0));
        // A half-fan's last spoke is one extra entry per ring.
        let h = Class { boundary: true, valence: 2 };
        assert_eq!(h.len(1), 1 + 2 * 2 + 1);
        assert_eq!(h.index(1, 0, 1), 5);
        assert_eq!(h.coords(5), Some((2, 1, 0)));
        assert_eq!(h.index(0, 1, 0), 1);
        assert_eq!(h.index(0, 2, 0), 6);
    }

    #[test]
    fn coords_and_index_agree() {
        for boundary in [false, true] {
            for valence in [1, 2, 3, 4, 7, 40] {
                if !boundary && valence < 2 {
                    continue;
                }
                let c = Class { boundary, valence };
                for i in 0..c.len(33) {
                    match c.coords(i) {
                        None => assert_eq!(i, 0),
                        Some((s, a, b)) => {
                            assert!(a >= 1 && (s < valence || b == 0), "{c:?} {i}");
                            assert_eq!(c.index(s, a.into(), b.into()), i, "{c:?} ({s}, {a}, {b})");
                        }
                    }
                }
            }
        }
    }
}
