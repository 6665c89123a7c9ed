//! Fragment meshes in sector layout (2010 thesis §3.3.1, after Shiue, Jones and Peters;
//! SPEC §5.2), extended with sharp features: the CPU base level, one fragment
//! per fan of corners around a vertex, the thesis' storage order, per-texel sharpness
//! data, and one refinement step of a fragment stream on the CPU — the stencils of
//! `glsl/subdiv/refine.frag`, in f64, so layout and rules are testable without a GPU.
//!
//! Names used throughout the subdivision code:
//!
//! - the *coarse* mesh P: an all-quad level of the surface whose vertices are the fragment
//!   centres (the input when it is all quads, else its first Catmull-Clark level, or a
//!   later one when the fragments cannot express the earlier ones, see below);
//! - the *base level* B: P refined once on the CPU. Every B quad has exactly one corner
//!   that is a vertex point of P, so the quads around each centre (its *owned region*)
//!   tile B, and every ring-1 vertex of a centre is an edge or face point of valence 4
//!   (the validity condition of SPEC §5.2);
//! - a fragment: the 2-ring of a centre c in B over one *fan* of c's corners
//!   (`topology`), in sectors. Sector s is the P face of the fan's s-th corner, between
//!   spokes s and s + 1; its vertex (a, b) lies a steps along spoke s and b steps towards
//!   spoke s + 1. (0, b) of sector s is (b, 0) of sector s + 1 and (a, −1) of sector s is
//!   (1, a) of sector s − 1. A manifold vertex has one fan; a non-manifold vertex has one
//!   fragment per sheet, each bounded by the non-manifold edges as by a boundary;
//! - an open fan (on a boundary or a non-manifold edge) of k corners has k + 1 spokes: its
//!   fragment is a half-fan whose last spoke k is stored as one extra entry per ring, so
//!   ring r has 2kr + 1 entries instead of 2kr.
//!
//! Storage order (the thesis'): the centre, then ring by ring; inside ring r, sector s
//! takes 2r consecutive entries t ∈ [0, 2r): t ≤ r → (r, t), t > r → (2r − t, r); a
//! half-fan's extra spoke entry (r, 0) comes last.
//!
//! # Sharpness data
//!
//! Inside the part of a fragment the passes evaluate, every edge is either a piece of a
//! spoke (a coarse edge at the centre) or was born inside a coarse face, and an edge born
//! inside a face is smooth for good; only the centre can have a vertex sharpness (the
//! coarse faces' other corners stay out of reach: at level j they lie on ring 2^(j+1),
//! beyond the stream's 2^j + 1). So a fragment's sharpness lives on its spokes. A
//! fragment with any sharp spoke or a sharp centre (every half-fan: its borders are
//! infinitely sharp) is *sharp*: it has a data block after all positions, one texel per
//! entry, `1 + (k + e)·R` of them at ring radius R:
//!
//! - the centre: (vertex sharpness, 0, 0, 0);
//! - entry `1 + s·R + (a − 1)`, the vertex (a, 0) of spoke s: (sharpness of the spoke
//!   segment (a−1, 0)–(a, 0), count and sum of the vertex's semi-sharp edges, 0) — the
//!   count and sum are what Chaikin's rule averages (a spoke vertex's two segments,
//!   except at the base level's ring 2, a coarse vertex, whose every edge counts).
//!
//! Sharpness only decays, so a fragment whose largest semi-sharp value is σ needs data
//! for ⌈σ⌉ levels (one more with Chaikin, whose `f32` averages may leave a last bit);
//! after that *horizon* its stream drops the data block and it runs the smooth stencil.
//! Fragments are sorted into runs of one horizon and class (valence, half-fan), horizon
//! first: at every level the runs without data come first, so the GPU pass can draw them
//! with the smooth shader variant and the rest with the sharp one (`gpu`).
//!
//! # What the fragments cannot express
//!
//! A fan of a non-manifold vertex sees only its own sheet. Its centre's rule counts the
//! sharp edges of all sheets: where the other sheets add only infinitely sharp edges and
//! the vertex is a corner for good, the centre's sharpness is set to infinity; where they
//! add semi-sharp edges (which change the centre's rule or, with Chaikin, its edges'
//! decay), the CPU refines one more level before cutting fragments, until those edges
//! have decayed — and says so ([`FragmentMesh::reasons`]).

use glam::DVec3;

use crate::mesh::Mesh;

use super::cpu::{self, Refiner, SharpEdge};
use super::crease::{self, INFINITE, Method, Rule, SemiSharpSum};
use super::topology::{NONE, Topology};
use super::{Result, SubdivError, Surface};

/// The sector structure shared by every fragment of a class: valence and half-fan flag.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Class {
    /// Boundary centres (half-fans) sort after closed ones.
    pub boundary: bool,
    /// Number of sectors (corners of the fan).
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

    /// Spokes: one per sector, one more on a half-fan.
    pub fn spokes(self) -> u32 {
        self.valence + u32::from(self.boundary)
    }

    /// Entries of a sharp fragment's data block at ring radius `radius`: the centre and
    /// `radius` vertices along each spoke.
    pub fn data_len(self, radius: u32) -> u64 {
        1 + u64::from(self.spokes()) * u64::from(radius)
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

/// Levels of sharpness data a fragment needs ([`Fragment::horizon`]) when it has an
/// infinitely sharp edge or vertex: all of them.
pub const FOREVER: u32 = u32::MAX;

/// A run of fragments of one class and horizon, consecutive in every stream.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ClassRun {
    pub class: Class,
    /// Streams `0..horizon` carry sharpness data (see the module docs).
    pub horizon: u32,
    /// Index of the run's first fragment.
    pub first: u32,
    pub count: u32,
}

impl ClassRun {
    /// True when stream `j` of a refinement with `levels` fragment levels carries data
    /// texels (the last stream never does: nothing reads it).
    pub fn has_data(&self, j: u32, levels: u32) -> bool {
        j < levels && j < self.horizon
    }
}

/// Where each class run starts in the stream of one level: first the positions of every
/// run, then (from an aligned texel on) the data texels of the runs that carry them, in
/// the same order.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct StreamLayout {
    pub radius: u32,
    /// Whether each run's fragments carry data texels in this stream.
    pub data: Vec<bool>,
    /// First position texel of each class run.
    pub starts: Vec<u64>,
    /// First data texel of each class run that carries data.
    pub data_starts: Vec<u64>,
    /// Texels of all positions; the data block starts at `data_start` ≥ `positions`.
    pub positions: u64,
    pub data_start: u64,
    /// Texels of the whole stream.
    pub total: u64,
}

/// A fragment: a fan of corners around a centre (a coarse vertex).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Fragment {
    pub centre: u32,
    /// The fan in the coarse topology.
    pub fan: u32,
    pub class: Class,
    /// Streams `0..horizon` carry sharpness data; 0 for a smooth fragment.
    pub horizon: u32,
    /// Index of its run in [`FragmentMesh::runs`].
    pub run: u32,
}

/// The result of cutting a surface into fragments.
pub enum Built {
    Fragments(Box<FragmentMesh>),
    /// The level is reached before fragments can be cut (below the base level, or the
    /// fragments cannot express the surface before it): refine on the CPU. The reasons
    /// say why when it is not simply below the base level.
    Cpu(Vec<String>),
}

/// The base level cut into fragment meshes (SPEC §5.2), with its base stream.
pub struct FragmentMesh {
    coarse: Topology,
    cpu_levels: u32,
    method: Method,
    reasons: Vec<String>,
    /// Sorted by horizon, class, then centre.
    fragments: Vec<Fragment>,
    runs: Vec<ClassRun>,
    /// Fragment of each fan of the coarse topology.
    fragment_of_fan: Vec<u32>,
    /// Sector of each coarse corner in its fragment (fans may be rotated, see `build`).
    sector_of: Vec<u32>,
    /// First corner of each fragment: the corner of sector 0.
    first_corner: Vec<u32>,
    /// Coarse faces that are holes.
    holes: Option<Vec<bool>>,
    /// Coarse edges lying on sharp control edges: (edge, sharpness, boundary, non-manifold).
    sharp_edges: Vec<(u32, f32, bool, bool)>,
    /// Base-level positions (B).
    base_positions: Vec<DVec3>,
    /// The base stream (ring radius 2), fragment after fragment in sorted order: the B
    /// vertex of each entry, and its data texel (sharp fragments only).
    base_vertices: Vec<u32>,
    base_data: Vec<[f32; 4]>,
    /// Coarse vertices no face uses, with their (unchanging) positions, by vertex.
    isolated: Vec<(u32, DVec3)>,
}

/// Levels the CPU must do before fragments exist: 1 for all-quad input, else 2.
pub fn levels_needed(mesh: &Mesh) -> u32 {
    if mesh.faces().all(|f| f.len() == 4) { 1 } else { 2 }
}

impl FragmentMesh {
    /// Cuts `surface` into fragments for a refinement to `level`: the CPU refines to the
    /// coarse level P and once more to the base level B (SPEC §5.2), more levels when the
    /// fragments cannot express P (see the module docs), and none at all when `level` is
    /// reached first.
    pub fn build(surface: &Surface, level: u32) -> Result<Built> {
        let mut refiner = Refiner::new(&surface.mesh, &surface.features, &surface.options)?;
        if levels_needed(&surface.mesh) == 2 && level >= 2 {
            refiner.step(true)?;
        }
        let mut reasons = Vec::new();
        loop {
            if refiner.depth() + 1 > level || !refiner.level().is_all_quads() {
                return Ok(Built::Cpu(reasons));
            }
            match FragmentMesh::cut(&mut refiner)? {
                Ok(mut mesh) => {
                    mesh.reasons = reasons;
                    return Ok(Built::Fragments(Box::new(mesh)));
                }
                Err(reason) => reasons.push(format!("CPU level {}: {reason}", refiner.depth())),
            }
        }
    }

    /// The fragments of a smooth mesh to `level` (tests and benchmarks).
    pub fn new(mesh: &Mesh, level: u32) -> Result<FragmentMesh> {
        match FragmentMesh::build(&Surface::smooth(mesh.clone()), level)? {
            Built::Fragments(f) => Ok(*f),
            Built::Cpu(_) => Err(SubdivError::Fragment(format!("level {level} is below the base level"))),
        }
    }

    /// With `refiner` at the coarse level P: refines it to B and cuts B into fragments, or
    /// says (`Err(reason)`) why the fragments cannot express P — `refiner` is then at B.
    fn cut(refiner: &mut Refiner) -> Result<std::result::Result<FragmentMesh, String>> {
        let p = refiner.level();
        let coarse = p.topology();
        let holes = (0..coarse.num_faces() as u32)
            .any(|f| p.is_hole(f))
            .then(|| (0..coarse.num_faces() as u32).map(|f| p.is_hole(f)).collect());
        let sharp_edges: Vec<(u32, f32, bool, bool)> = (0..coarse.num_edges() as u32)
            .filter_map(|e| refiner.edge_origin(e).map(|(s, b, n)| (e, s, b, n)))
            .collect();
        let cpu_levels = refiner.depth() + 1;
        let method = refiner.options().crease_method;
        // B's topology is needed only for its sharpness (and for another CPU level, which
        // only sharp features can ask for).
        refiner.step(p.has_sharpness())?;
        let b = refiner.level();
        let (nv, nf) = (coarse.num_vertices() as u32, coarse.num_faces() as u32);
        // B's sharp vertices: semi-sharp sums (Chaikin) and sharp edge lists by vertex.
        let mut sharp_list: std::collections::HashMap<u32, &[u32]> = std::collections::HashMap::new();
        for (v, list) in b.sharp_vertices() {
            sharp_list.insert(v, list);
        }
        let semi = |v: u32| -> (f32, f32) {
            if method != Method::Chaikin {
                return (0.0, 0.0);
            }
            let s = sharp_list.get(&v).map_or(SemiSharpSum::default(), |list| {
                SemiSharpSum::of(list.iter().map(|&x| b.edge_sharpness(x >> 1)))
            });
            (s.count as f32, s.sum)
        };
        let isolated_flags: Vec<bool> = (0..nv).map(|v| coarse.vertex_fans(v).0.is_none()).collect();
        let coarse_ref_isolated = |v: u32| isolated_flags[v as usize];
        let (fragments, first_corner, centre_sharpness) = match fan_fragments(&coarse, b, &sharp_list, method)
        {
            Ok(f) => f,
            Err(reason) => return Ok(Err(reason)),
        };
        all_quads(&coarse)?;

        let mut mesh = FragmentMesh {
            coarse,
            cpu_levels,
            method,
            reasons: Vec::new(),
            fragments,
            runs: Vec::new(),
            fragment_of_fan: Vec::new(),
            sector_of: Vec::new(),
            first_corner,
            holes,
            sharp_edges,
            base_positions: Vec::new(),
            base_vertices: Vec::new(),
            base_data: Vec::new(),
            isolated: (0..nv)
                .filter(|&v| coarse_ref_isolated(v))
                .map(|v| (v, b.positions()[v as usize]))
                .collect(),
        };
        // Sectors in each fragment's order, then the base texels and horizons.
        mesh.sector_of = mesh.sector_order();
        let sharp = b.has_sharpness() || centre_sharpness.iter().any(|&s| s > 0.0);
        let entries: Vec<(Vec<u32>, Vec<[f32; 4]>, u32)> = (0..mesh.fragments.len())
            .map(|i| mesh.base_entries(i, b, sharp, centre_sharpness[i], nv, nf, &semi))
            .collect();
        for (frag, (_, _, horizon)) in mesh.fragments.iter_mut().zip(&entries) {
            frag.horizon = *horizon;
        }
        mesh.base_positions = b.positions().to_vec();
        mesh.sort_and_stream(entries);
        Ok(Ok(mesh))
    }

    /// Each coarse corner's sector in its fragment's order.
    fn sector_order(&self) -> Vec<u32> {
        let coarse = &self.coarse;
        let mut sector_of = vec![NONE; coarse.num_half_edges()];
        for (i, frag) in self.fragments.iter().enumerate() {
            let fan = coarse.fans()[frag.fan as usize];
            let corners = coarse.fan_corners(&fan);
            let start = corners.iter().position(|&h| h == self.first_corner[i]).unwrap_or(0);
            for (s, &h) in corners[start..].iter().chain(&corners[..start]).enumerate() {
                sector_of[h as usize] = s as u32;
            }
        }
        sector_of
    }

    /// The corners of fragment `i`, sector 0 first.
    fn corners(&self, i: usize) -> Vec<u32> {
        let fan = self.coarse.fans()[self.fragments[i].fan as usize];
        let corners = self.coarse.fan_corners(&fan);
        let start = corners.iter().position(|&h| h == self.first_corner[i]).unwrap_or(0);
        corners[start..].iter().chain(&corners[..start]).copied().collect()
    }

    /// The base entries of fragment `i` (ring radius 2, storage order): each entry's B
    /// vertex, its data texel (only for a sharp fragment) and the fragment's horizon. With
    /// `sharp` false the base level has no sharpness at all and no data is made.
    #[allow(clippy::too_many_arguments)]
    fn base_entries(
        &self,
        i: usize,
        b: &cpu::Level,
        sharp: bool,
        centre_sharpness: f32,
        nv: u32,
        nf: u32,
        semi: &dyn Fn(u32) -> (f32, f32),
    ) -> (Vec<u32>, Vec<[f32; 4]>, u32) {
        let topo = &self.coarse;
        let frag = self.fragments[i];
        let corners = self.corners(i);
        let k = frag.class.valence;
        let nc = topo.num_half_edges() as u32;
        let vertex_point = |v: u32| v;
        let face_point = |h: u32| nv + topo.face(h);
        let edge_point = |h: u32| nv + nf + topo.edge(h);
        let half_at_origin = |h: u32| nc + 2 * topo.edge(h) + u32::from(topo.is_reversed(h));
        let half_at_target = |h: u32| nc + 2 * topo.edge(h) + u32::from(!topo.is_reversed(h));
        let last_in = if frag.class.boundary { topo.prev(corners[k as usize - 1]) } else { NONE };
        // B vertex and the B edges −a, +a, −b, +b of entry (s, a, b) (`None`: an edge inside
        // a coarse face, always smooth, or one outside the fan, never read).
        let entry = |s: u32, a: u32, bb: u32| -> (u32, [Option<u32>; 4]) {
            if (a, bb) == (0, 0) {
                return (vertex_point(frag.centre), [None; 4]);
            }
            let (ho, ht) = (|h: u32| Some(half_at_origin(h)), |h: u32| Some(half_at_target(h)));
            if s == k {
                // A half-fan's last spoke: the border edge p that enters the centre.
                let p = last_in;
                return if a == 1 {
                    (edge_point(p), [ht(p), ho(p), None, None])
                } else {
                    (vertex_point(topo.origin(p)), [ho(p), None, None, None])
                };
            }
            // The sector's coarse quad, seen from the centre: h runs c → c1, h1 c1 → c2,
            // h2 c2 → c3, where c3 is the end of spoke s + 1.
            let h = corners[s as usize];
            let (h1, h2) = (topo.next(h), topo.next(topo.next(h)));
            match (a, bb) {
                (1, 0) => (edge_point(h), [ho(h), ht(h), None, None]),
                (1, 1) => (face_point(h), [None; 4]),
                (2, 0) => (vertex_point(topo.origin(h1)), [ht(h), None, None, ho(h1)]),
                (2, 1) => (edge_point(h1), [None, None, ho(h1), ht(h1)]),
                (2, 2) => (vertex_point(topo.origin(h2)), [ho(h2), None, ht(h1), None]),
                (1, 2) => (edge_point(h2), [ht(h2), ho(h2), None, None]),
                _ => unreachable!("ring radius 2 holds only a, b ≤ 2"),
            }
        };
        let len = frag.class.len(2) as usize;
        let mut vertices = Vec::with_capacity(len);
        let mut data = Vec::with_capacity(if sharp { frag.class.data_len(2) as usize } else { 0 });
        let (mut largest, mut infinite) = (0.0f32, false);
        let mut note = |s: f32| {
            if crease::is_infinite(s) {
                infinite = true;
            } else {
                largest = largest.max(s);
            }
        };
        vertices.push(entry(0, 0, 0).0);
        for r in 1..=2 {
            for s in 0..k {
                for t in 0..2 * r {
                    vertices.push(if t <= r { entry(s, r, t).0 } else { entry(s, 2 * r - t, r).0 });
                }
            }
            if frag.class.boundary {
                vertices.push(entry(k, r, 0).0);
            }
        }
        if sharp {
            note(centre_sharpness);
            data.push([centre_sharpness, 0.0, 0.0, 0.0]);
            for s in 0..frag.class.spokes() {
                for a in 1..=2 {
                    let (v, edges) = entry(s, a, 0);
                    let segment = edges[0].map_or(0.0, |e| b.edge_sharpness(e));
                    note(segment);
                    let (count, sum) = semi(v);
                    data.push([segment, count, sum, 0.0]);
                }
            }
        }
        let horizon = if infinite {
            FOREVER
        } else if largest <= 0.0 {
            0
        } else {
            // One more level with Chaikin: its f32 averages may leave a last bit.
            largest.ceil() as u32 + u32::from(self.method == Method::Chaikin)
        };
        if horizon == 0 {
            data.clear();
        }
        (vertices, data, horizon)
    }

    /// Orders fragments by horizon and class, records the runs and lays out the base stream.
    fn sort_and_stream(&mut self, entries: Vec<(Vec<u32>, Vec<[f32; 4]>, u32)>) {
        let mut order: Vec<usize> = (0..self.fragments.len()).collect();
        order.sort_by_key(|&i| {
            let f = &self.fragments[i];
            (f.horizon, f.class, f.centre, f.fan)
        });
        self.fragments = order.iter().map(|&i| self.fragments[i]).collect();
        self.first_corner = order.iter().map(|&i| self.first_corner[i]).collect();
        self.fragment_of_fan = vec![NONE; self.coarse.fans().len()];
        for (i, f) in self.fragments.iter_mut().enumerate() {
            if self.runs.last().is_none_or(|r| r.class != f.class || r.horizon != f.horizon) {
                self.runs.push(ClassRun { class: f.class, horizon: f.horizon, first: i as u32, count: 0 });
            }
            let run = self.runs.len() - 1;
            self.runs[run].count += 1;
            f.run = run as u32;
            self.fragment_of_fan[f.fan as usize] = i as u32;
        }
        self.base_vertices = Vec::with_capacity(entries.iter().map(|e| e.0.len()).sum());
        self.base_data = Vec::with_capacity(entries.iter().map(|e| e.1.len()).sum());
        for &i in &order {
            self.base_vertices.extend_from_slice(&entries[i].0);
            self.base_data.extend_from_slice(&entries[i].1);
        }
    }

    pub fn coarse(&self) -> &Topology {
        &self.coarse
    }

    /// Catmull-Clark levels the CPU did to reach the base level.
    pub fn cpu_levels(&self) -> u32 {
        self.cpu_levels
    }

    /// Why the CPU did more levels than the minimum (empty when it did not).
    pub fn reasons(&self) -> &[String] {
        &self.reasons
    }

    pub fn crease_method(&self) -> Method {
        self.method
    }

    pub fn fragments(&self) -> &[Fragment] {
        &self.fragments
    }

    pub fn runs(&self) -> &[ClassRun] {
        &self.runs
    }

    /// Fragments that carry sharpness data at the base level.
    pub fn sharp_fragments(&self) -> usize {
        self.fragments.iter().filter(|f| f.horizon > 0).count()
    }

    /// The fragment of a fan of vertex `v`, if a face uses `v`.
    pub fn fragment_of(&self, v: u32) -> Option<u32> {
        self.coarse.vertex_fans(v).0.map(|fan| self.fragment_of_fan[fan as usize])
    }

    /// The fragment and sector of coarse corner `h`.
    pub fn corner_sector(&self, h: u32) -> (u32, u32) {
        let (fan, _) = self.coarse.corner_fan(h);
        (self.fragment_of_fan[fan as usize], self.sector_of[h as usize])
    }

    /// A fragment and its spoke along coarse edge `e` at its `end` (0: the edge's first
    /// vertex, 1: its second).
    pub fn spoke_along(&self, e: u32, end: usize) -> (u32, u32) {
        let h = self.coarse.edge_half_edge(e);
        // The corner at h's origin leaves along e; at the other end the edge enters the
        // face's next corner, whose spoke along it is the one after its own.
        let leaving_end = usize::from(self.coarse.is_reversed(h));
        if end == leaving_end {
            return self.corner_sector(h);
        }
        let (f, s) = self.corner_sector(self.coarse.next(h));
        let class = self.fragments[f as usize].class;
        (f, if class.boundary { s + 1 } else { (s + 1) % class.valence })
    }

    /// The position of a coarse vertex no face uses (it never moves).
    pub fn isolated_position(&self, v: u32) -> DVec3 {
        match self.isolated.binary_search_by_key(&v, |&(w, _)| w) {
            Ok(i) => self.isolated[i].1,
            Err(_) => DVec3::ZERO,
        }
    }

    pub fn is_hole(&self, f: u32) -> bool {
        self.holes.as_ref().is_some_and(|h| h[f as usize])
    }

    /// Coarse edges on sharp control edges: (edge, sharpness, boundary, non-manifold).
    pub fn coarse_sharp_edges(&self) -> &[(u32, f32, bool, bool)] {
        &self.sharp_edges
    }

    /// Where every class run starts in stream `j` of a refinement with `levels` fragment
    /// levels (ring radius [`radii`]`(levels)[j]`), the data block starting at a multiple
    /// of `align` texels (a texture row, so that it can be drawn on its own).
    pub fn layout(&self, j: u32, levels: u32, align: u64) -> StreamLayout {
        let radius = radii(levels)[j as usize];
        let mut starts = Vec::with_capacity(self.runs.len());
        let mut data = Vec::with_capacity(self.runs.len());
        let mut positions = 0u64;
        for run in &self.runs {
            starts.push(positions);
            data.push(run.has_data(j, levels));
            positions += u64::from(run.count) * run.class.len(radius);
        }
        let data_start =
            if data.contains(&true) { positions.div_ceil(align.max(1)) * align.max(1) } else { positions };
        let mut data_starts = Vec::with_capacity(self.runs.len());
        let mut total = data_start;
        for (run, &has) in self.runs.iter().zip(&data) {
            data_starts.push(total);
            if has {
                total += u64::from(run.count) * run.class.data_len(radius);
            }
        }
        StreamLayout { radius, data, starts, data_starts, positions, data_start, total }
    }

    /// First position texel of fragment `f` in a stream with `layout`.
    pub fn fragment_start(&self, layout: &StreamLayout, f: u32) -> u64 {
        let frag = &self.fragments[f as usize];
        let run = &self.runs[frag.run as usize];
        layout.starts[frag.run as usize] + u64::from(f - run.first) * frag.class.len(layout.radius)
    }

    /// First data texel of fragment `f` in a stream with `layout` (its run must carry data).
    pub fn fragment_data_start(&self, layout: &StreamLayout, f: u32) -> u64 {
        let frag = &self.fragments[f as usize];
        let run = &self.runs[frag.run as usize];
        layout.data_starts[frag.run as usize] + u64::from(f - run.first) * frag.class.data_len(layout.radius)
    }

    /// The base-level stream (ring radius 2) of a refinement with `levels` fragment levels
    /// and data aligned to `align` texels, mapped texel by texel: positions by `position`,
    /// data texels (and the padding before them, as zeros) by `data`.
    pub fn base_stream<T>(
        &self,
        levels: u32,
        align: u64,
        position: impl Fn(DVec3) -> T,
        data: impl Fn([f32; 4]) -> T,
    ) -> Vec<T> {
        let layout = self.layout(0, levels, align);
        let mut out = Vec::with_capacity(layout.total as usize);
        out.extend(self.base_vertices.iter().map(|&v| position(self.base_positions[v as usize])));
        out.extend((layout.positions..layout.data_start).map(|_| data([0.0; 4])));
        let mut datum = 0usize;
        for (r, run) in self.runs.iter().enumerate() {
            if run.horizon == 0 {
                continue;
            }
            let len = (u64::from(run.count) * run.class.data_len(2)) as usize;
            if layout.data[r] {
                out.extend(self.base_data[datum..datum + len].iter().map(|&d| data(d)));
            }
            datum += len;
        }
        out
    }

    /// One Catmull-Clark level of every fragment on the CPU, in f64 (sharpness in f32):
    /// reads stream `j` of a refinement with `levels` fragment levels, writes stream j + 1.
    /// The same stencils and addressing as the GPU pass (`glsl/subdiv/refine.frag`).
    pub fn refine_stream(&self, input: &[[f64; 4]], j: u32, levels: u32) -> Vec<[f64; 4]> {
        let (lin, lout) = (self.layout(j, levels, 1), self.layout(j + 1, levels, 1));
        let mut out = vec![[0.0; 4]; lout.total as usize];
        for f in 0..self.fragments.len() as u32 {
            let frag = self.fragments[f as usize];
            let r = frag.run as usize;
            let view = View {
                class: frag.class,
                input,
                base: self.fragment_start(&lin, f),
                data_base: if lin.data[r] { self.fragment_data_start(&lin, f) } else { 0 },
                radius: lin.radius,
                data: lin.data[r],
                method: self.method,
            };
            let base_out = self.fragment_start(&lout, f);
            for i in 0..frag.class.len(lout.radius) {
                let p = if view.data {
                    sharp_stencil(&view, i)
                } else {
                    stencil(frag.class, i, |s, a, b| view.p(s, a, b))
                };
                out[(base_out + i) as usize] = [p.x, p.y, p.z, 1.0];
            }
            if lout.data[r] {
                let data_out = self.fragment_data_start(&lout, f);
                for i in 0..frag.class.data_len(lout.radius) {
                    out[(data_out + i) as usize] = sharp_data(&view, i, lout.radius).map(f64::from);
                }
            }
        }
        out
    }
}

/// Ring radius of the stream after each fragment level: 2 at the base level, 2^j + 1
/// after j levels (2R − 1 from R), except the last, which keeps only its 2^j owned rings.
pub fn radii(levels: u32) -> Vec<u32> {
    let levels = levels.min(30);
    (0..=levels)
        .map(|j| match j {
            0 => 2,
            j if j == levels => 1 << j,
            j => (1 << j) + 1,
        })
        .collect()
}

/// A fragment of the input stream: positions and (when `data`) its spokes' sharpness.
struct View<'a> {
    class: Class,
    input: &'a [[f64; 4]],
    /// First position and first data texel of the fragment, and its ring radius.
    base: u64,
    data_base: u64,
    radius: u32,
    data: bool,
    method: Method,
}

impl View<'_> {
    fn p(&self, s: u32, a: i64, b: i64) -> DVec3 {
        let t = self.input[(self.base + self.class.index(s, a, b)) as usize];
        DVec3::new(t[0], t[1], t[2])
    }

    fn datum(&self, i: u64) -> [f32; 4] {
        self.input[(self.data_base + i) as usize].map(|x| x as f32)
    }

    /// Sharpness of the centre.
    fn centre_sharpness(&self) -> f32 {
        self.datum(0)[0]
    }

    /// The data of vertex (a, 0) of spoke s (a ≥ 1): segment (a−1)–a and semi-sharp sum.
    fn spoke(&self, s: u32, a: i64) -> ([f32; 4], SemiSharpSum) {
        let d = self.datum(1 + u64::from(s) * u64::from(self.radius) + (a as u64 - 1));
        (d, SemiSharpSum { count: d[1] as u32, sum: d[2] })
    }

    /// Sharpness of the spoke segment (a−1, 0)–(a, 0) of spoke s.
    fn segment(&self, s: u32, a: i64) -> f32 {
        self.spoke(s, a).0[0]
    }

    /// The spokes at the centre: (sharpness, ring-1 neighbour), in sector order.
    fn spokes(&self) -> impl Iterator<Item = (f32, DVec3)> + '_ {
        (0..self.class.spokes()).map(move |s| (self.segment(s, 1), self.p(s, 1, 0)))
    }

    /// Semi-sharp sum at vertex (a, 0) of spoke s (the centre for a = 0).
    fn semi(&self, s: u32, a: i64) -> SemiSharpSum {
        if a == 0 { SemiSharpSum::of(self.spokes().map(|(e, _)| e)) } else { self.spoke(s, a).1 }
    }

    /// Child sharpness of a segment of sharpness `e` at its end (a, 0) of spoke s.
    fn child(&self, e: f32, s: u32, a: i64) -> f32 {
        match self.method {
            Method::Uniform => crease::decrement(e),
            // Every vertex of a fragment has at least two edges.
            Method::Chaikin => crease::chaikin(e, self.semi(s, a), 2),
        }
    }
}

/// The vertex mask at a sharp vertex: `edges` are (sharpness, neighbour) in the vertex's
/// order, `smooth` its smooth point, `semi` its semi-sharp sum (Chaikin).
fn vertex_rule(
    view: &View,
    p: DVec3,
    vs: f32,
    edges: &[(f32, DVec3)],
    smooth: DVec3,
    semi: SemiSharpSum,
) -> DVec3 {
    let sharp = edges.iter().filter(|e| e.0 > 0.0).count();
    let p_rule = Rule::of(vs, sharp);
    if p_rule.is_smooth() {
        return smooth;
    }
    let child: Vec<f32> = edges
        .iter()
        .map(|&(e, _)| match view.method {
            Method::Uniform => crease::decrement(e),
            Method::Chaikin => crease::chaikin(e, semi, 2),
        })
        .collect();
    let cvs = crease::decrement(vs);
    let c_rule = Rule::of(cvs, child.iter().filter(|&&c| c > 0.0).count());
    let mask = |rule: Rule, use_child: bool| match rule {
        Rule::Smooth | Rule::Dart => smooth,
        Rule::Crease => {
            let ends: DVec3 = edges
                .iter()
                .zip(&child)
                .filter(|(e, c)| if use_child { **c > 0.0 } else { e.0 > 0.0 })
                .map(|(e, _)| e.1)
                .sum();
            p * 0.75 + ends * 0.125
        }
        Rule::Corner => p,
    };
    if c_rule == p_rule {
        return mask(p_rule, false);
    }
    let w = f64::from(crease::fractional_weight(
        view.method,
        vs,
        cvs,
        edges.iter().zip(&child).map(|(e, &c)| (e.0, c)),
    ));
    mask(p_rule, false) * w + mask(c_rule, true) * (1.0 - w)
}

/// The position of output entry `i` of a sharp fragment: the smooth stencil, replaced by
/// OpenSubdiv's crease and corner rules at the centre and along the spokes (elsewhere
/// every edge is smooth, see the module docs).
fn sharp_stencil(view: &View, i: u64) -> DVec3 {
    let class = view.class;
    let smooth = stencil(class, i, |s, a, b| view.p(s, a, b));
    let Some((s, a, b)) = class.coords(i) else {
        let edges: Vec<(f32, DVec3)> = view.spokes().collect();
        return vertex_rule(view, view.p(0, 0, 0), view.centre_sharpness(), &edges, smooth, view.semi(0, 0));
    };
    if b != 0 {
        return smooth;
    }
    let a = i64::from(a);
    let x = a / 2;
    if a % 2 == 0 {
        // Vertex point of (x, 0): its spoke segments; the edges across the spoke are smooth.
        let edges =
            [(view.segment(s, x), view.p(s, x - 1, 0)), (view.segment(s, x + 1), view.p(s, x + 1, 0))];
        vertex_rule(view, view.p(s, x, 0), 0.0, &edges, smooth, view.semi(s, x))
    } else {
        // Edge point of the segment (x, 0)–(x + 1, 0): the midpoint while both halves stay
        // sharp, else midpoint and smooth point blended by the segment's sharpness.
        let e = view.segment(s, x + 1);
        if e <= 0.0 {
            return smooth;
        }
        let mid = (view.p(s, x, 0) + view.p(s, x + 1, 0)) * 0.5;
        if view.child(e, s, x) > 0.0 && view.child(e, s, x + 1) > 0.0 {
            return mid;
        }
        let w = f64::from(e);
        mid * w + smooth * (1.0 - w)
    }
}

/// Data texel `i` of a sharp fragment's data block at output ring radius `radius` (see
/// the module docs).
fn sharp_data(view: &View, i: u64, radius: u32) -> [f32; 4] {
    if i == 0 {
        return [crease::decrement(view.centre_sharpness()), 0.0, 0.0, 0.0];
    }
    let s = ((i - 1) / u64::from(radius)) as u32;
    let a = ((i - 1) % u64::from(radius)) as i64 + 1;
    // The output segment (a−1, a): half of the parent segment ⌈a/2⌉ at the parent vertex
    // a/2 (a even) or (a−1)/2 (a odd); the next one (a, a+1) likewise.
    let half = |a: i64| {
        let parent = view.segment(s, (a + 1) / 2);
        let end = if a % 2 == 0 { a / 2 } else { (a - 1) / 2 };
        view.child(parent, s, end)
    };
    let segment = half(a);
    if view.method != Method::Chaikin {
        return [segment, 0.0, 0.0, 0.0];
    }
    // The new vertex's semi-sharp edges: its two segments.
    let next = {
        let parent = view.segment(s, a / 2 + 1);
        let end = if a % 2 == 0 { a / 2 } else { (a + 1) / 2 };
        view.child(parent, s, end)
    };
    let semi = SemiSharpSum::of([segment, next]);
    [segment, semi.count as f32, semi.sum, 0.0]
}

/// The smooth Catmull-Clark stencil (the thesis' masks, Ch. 2.2) of output entry `i` of a
/// closed fragment of `class`, reading the previous level through `p(s, a, b)`: both
/// output coordinates even → vertex point, one odd → edge point, both odd → face point.
/// (Half-fans always carry sharpness data; their border entries get the crease rules in
/// [`sharp_stencil`], which only reads this value where it applies.)
pub fn stencil(class: Class, i: u64, p: impl Fn(u32, i64, i64) -> DVec3) -> DVec3 {
    let k = class.valence;
    let Some((s, a, b)) = class.coords(i) else {
        if class.boundary {
            return p(0, 0, 0);
        }
        let c = p(0, 0, 0);
        let (mut edges, mut diagonals) = (DVec3::ZERO, DVec3::ZERO);
        for s in 0..k {
            edges += p(s, 1, 0);
            diagonals += p(s, 1, 1);
        }
        let n = f64::from(k);
        return c * (1.0 - 7.0 / (4.0 * n)) + edges * (1.5 / (n * n)) + diagonals * (0.25 / (n * n));
    };
    let (a, b) = (i64::from(a), i64::from(b));
    if class.boundary && b == 0 && (s == 0 || s == k) {
        // A half-fan's border: never smooth (its edges are infinitely sharp).
        return p(s, a / 2, 0);
    }
    match (a % 2, b % 2) {
        (0, 0) => {
            let (a, b) = (a / 2, b / 2);
            let edges = p(s, a + 1, b) + p(s, a - 1, b) + p(s, a, b + 1) + p(s, a, b - 1);
            let diagonals = p(s, a + 1, b + 1) + p(s, a - 1, b + 1) + p(s, a + 1, b - 1) + p(s, a - 1, b - 1);
            (36.0 * p(s, a, b) + 6.0 * edges + diagonals) / 64.0
        }
        (1, 0) => {
            let (a, b) = (a / 2, b / 2);
            let ends = p(s, a, b) + p(s, a + 1, b);
            let sides = p(s, a, b + 1) + p(s, a + 1, b + 1) + p(s, a, b - 1) + p(s, a + 1, b - 1);
            (6.0 * ends + sides) / 16.0
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

/// The refined edges of a fragment refinement that lie on sharp control edges (see
/// [`SharpEdge`]): every coarse sharp edge split into `g` segments, with the assembled
/// mesh's vertex numbering (`assemble`).
pub fn sharp_edges(fragments: &FragmentMesh, levels: u32) -> Vec<SharpEdge> {
    let g = 2u32 << levels;
    let nv = fragments.coarse.num_vertices() as u32;
    let mut out = Vec::new();
    for &(e, sharpness, boundary, non_manifold) in fragments.coarse_sharp_edges() {
        let [v0, v1] = fragments.coarse.edge_vertices(e);
        let point = |t: u32| match t {
            0 => v0,
            t if t == g => v1,
            t => nv + e * (g - 1) + t - 1,
        };
        for t in 0..g {
            out.push(SharpEdge { vertices: [point(t), point(t + 1)], sharpness, boundary, non_manifold });
        }
    }
    out
}

/// One fragment per fan of `coarse`, with the corner its sector 0 starts at and its
/// centre's sharpness at B (`b`; `sharp_list`: its sharp vertices' sharp edges).
/// `Err(reason)` when the sharp edges around a non-manifold vertex are not all in one of
/// its fans (and semi-sharp ones must decay on the CPU first).
#[allow(clippy::type_complexity)]
fn fan_fragments(
    coarse: &Topology,
    b: &cpu::Level,
    sharp_list: &std::collections::HashMap<u32, &[u32]>,
    method: Method,
) -> std::result::Result<(Vec<Fragment>, Vec<u32>, Vec<f32>), String> {
    let nc = coarse.num_half_edges() as u32;
    // The B half of coarse corner h's leaving edge at its origin / at its target.
    let half_at_origin = |h: u32| nc + 2 * coarse.edge(h) + u32::from(coarse.is_reversed(h));
    let half_at_target = |h: u32| nc + 2 * coarse.edge(h) + u32::from(!coarse.is_reversed(h));
    let mut fragments = Vec::new();
    let mut first_corner = Vec::new();
    let mut centre_sharpness = Vec::new();
    let mut spokes_at = Vec::new();
    for (f, fan) in coarse.fans().iter().enumerate() {
        let c = fan.centre;
        let corners = coarse.fan_corners(fan);
        // The B halves of the fan's spokes at the centre.
        spokes_at.clear();
        spokes_at.extend(corners.iter().map(|&h| half_at_origin(h)));
        if !fan.closed {
            spokes_at.push(half_at_target(coarse.prev(corners[corners.len() - 1])));
        }
        let list: &[u32] = sharp_list.get(&c).copied().unwrap_or(&[]);
        let mut vs = b.vertex_sharpness(c);
        let outside: Vec<f32> = list
            .iter()
            .filter(|&&x| !spokes_at.contains(&(x >> 1)))
            .map(|&x| b.edge_sharpness(x >> 1))
            .collect();
        if !outside.is_empty() {
            let infinite = list.iter().filter(|&&x| crease::is_infinite(b.edge_sharpness(x >> 1))).count();
            let corner_for_good = crease::is_infinite(vs) || infinite >= 3;
            let semi_outside = outside.iter().any(|&s| crease::is_semi_sharp(s));
            if corner_for_good && (method == Method::Uniform || !semi_outside) {
                vs = INFINITE;
            } else {
                return Err(format!(
                    "the sharp edges around non-manifold vertex {c} are not all in one of its fans \
                     (semi-sharp ones decay on the CPU first)"
                ));
            }
        }
        // A closed fan starts at the first sharp edge of the centre's list: its f32 sums
        // then run in OpenSubdiv's order.
        let mut start = 0;
        if fan.closed
            && let Some(&x) = list.first()
        {
            start = spokes_at.iter().position(|&h| h == x >> 1).unwrap_or(0);
        }
        let class = Class { boundary: !fan.closed, valence: corners.len() as u32 };
        fragments.push(Fragment { centre: c, fan: f as u32, class, horizon: 0, run: 0 });
        first_corner.push(corners[start]);
        centre_sharpness.push(vs);
    }
    Ok((fragments, first_corner, centre_sharpness))
}

/// Fragment meshes need an all-quad coarse mesh.
fn all_quads(coarse: &Topology) -> Result<()> {
    for f in 0..coarse.num_faces() as u32 {
        let sides = coarse.face_half_edges(f).len();
        if sides != 4 {
            return Err(SubdivError::Fragment(format!(
                "coarse face {f} has {sides} sides; fragment meshes need an all-quad coarse mesh"
            )));
        }
    }
    Ok(())
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
