//! Is a mesh a solid, and what "inside" means — one rule for every command.
//!
//! ## The rule
//!
//! A point P is **inside** a mesh iff the winding number w(P) of its faces around P is
//! at least ½. texgeo's commands only accept meshes on which w is 0 or 1 everywhere off
//! the surface — *valid solids* — and there the other rules the algorithms compute agree
//! with it exactly: Feito-Torres sums 2·w (inside iff non-zero), the voxelizers' XOR
//! accumulates the parity of w, Jordan rays count crossings (parity), and the
//! winding-number oracle measures w itself. Points within ε of the surface are
//! OnBoundary for `inclusion` ([`crate::inclusion`] states ε) and decided by the tie rule
//! for `voxelize` ([`crate::voxel::exact`]).
//!
//! A valid solid is:
//!
//! 1. **closed and consistently oriented**: every directed edge a→b is matched by a twin
//!    b→a (non-manifold edges are fine when they pair up, and when the faces around them
//!    alternate in direction in their exact order about the edge: two neighbours facing
//!    the same way make the winding number −1 or 2 beside it — a piece hanging on the edge
//!    turned inside out);
//! 2. **measurable**: its area and volume are finite in f64 (measured in the mesh's
//!    [`Frame`], then scaled back: every size whose measures fit f64 is measurable);
//! 3. **outward**: every shell (a connected component of faces) faces away from the
//!    region it bounds, so that w = 0 outside and 1 inside. An outer shell has positive
//!    volume, a shell inside it faces inwards (a cavity, negative volume), an island in
//!    the cavity faces outwards again, and so on. Two shells with the same orientation,
//!    one inside the other, give w = 2 between them; an inverted solid gives w = −1;
//! 4. **not self-intersecting**: no two faces cross (overlapping shells give w = 2 where
//!    they overlap). Detected by [`super::intersect::self_intersections`] (exact
//!    triangle–triangle tests on the faces as every command sees them: planar ones
//!    tessellated in their planes, non-planar ones as the fan from their centroid); shells that
//!    overlap are also named as such when a shell has vertices both inside and outside
//!    another.
//!
//! Anything else is refused by `inclusion`, `voxelize` and `boolean` (and skipped by
//! `sweep` with the same reason) with status 2 and the reason ([`Defect`]), unless a flag
//! changes the question:
//!
//! - `--flip-inverted`: an inverted solid (every face reversed would make it valid) is
//!   flipped and then treated as the solid it describes;
//! - `--allow-open` (`inclusion`, `voxelize`, `sweep`): **a mesh that is not a solid** —
//!   open, self-intersecting, with nested or crossing shells, inverted — is accepted, and a
//!   point is inside iff the *generalized* winding number of its faces (polygons as their
//!   covering, as for solids) is at least ½. That is the rule above, read for any mesh: on a
//!   valid solid nothing changes. On an inverted mesh w = −1 inside, so nothing is inside
//!   (`--flip-inverted` makes it the solid it describes); where two shells overlap or nest
//!   with the same orientation w = 2, inside. [`crate::inclusion::fast_winding`] evaluates
//!   it with a certified bound. Only a mesh whose area or volume overflows f64 is still
//!   refused;
//! - `--allow-self-intersections` (`boolean` only): go on with crossing faces, best effort.
//!
//! [`check`] measures everything and lists every defect (`texgeo mesh stats` prints it);
//! [`require_solid`] is the gate a command puts in front of its algorithm.

use glam::DVec3;

use super::covering::{Covering, FoldedEdge, UnbalancedEdge, compensated_sum};
use super::disjoint_sets::UnionFind;
use super::frame::Frame;
use super::{Mesh, intersect};

/// Vertices sampled per shell to find how deep it is nested.
const SAMPLES: usize = 8;
/// A winding number farther than this from an integer means the sample is (nearly) on
/// the other shell's surface: it says nothing about nesting.
const WINDING_SLACK: f64 = 0.1;

/// One shell: a connected component of faces (faces sharing a vertex are connected).
#[derive(Clone, Debug, PartialEq)]
pub struct Shell {
    /// Number of faces, and the first of them (faces of a shell need not be contiguous).
    pub faces: usize,
    pub first_face: usize,
    /// Signed volume (Alg. 3-1): positive when the shell faces outwards.
    pub volume: f64,
    /// Winding number of the *other* shells around this one (0 for a shell inside no
    /// other, 1 for a cavity's shell, …); `None` when it could not be decided (the shell
    /// touches another).
    pub depth: Option<i32>,
}

/// What keeps a mesh from being a valid solid.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum Defect {
    #[error("the surface is not closed and consistently oriented: {0}")]
    Open(UnbalancedEdge),
    #[error(
        "the {faces} faces around edge {a}–{b} do not alternate in direction about it: the winding number \
         beside it is −1 or 2 (a piece hanging on the edge faces the wrong way)",
        a = .0.a, b = .0.b, faces = .0.faces
    )]
    FoldedEdge(FoldedEdge),
    #[error("its area or volume overflows f64 (coordinates up to {largest:e}); scale the mesh down")]
    Overflow { largest: f64 },
    #[error("the solid is inverted: its faces point inwards (signed volume {volume})")]
    Inverted { volume: f64 },
    #[error(
        "shell {shell} (the shell of face {first_face}) faces inwards but lies inside no other shell: \
         the winding number is −1 inside it"
    )]
    InvertedShell { shell: usize, first_face: usize },
    #[error(
        "shell {shell} (the shell of face {first_face}) lies inside shell {outer} and faces the same way: \
         the winding number is {winding} inside it (a shell inside another must face the other way, like a cavity)"
    )]
    NestedShell { shell: usize, first_face: usize, outer: usize, winding: i32 },
    #[error(
        "the surface intersects itself: shells {a} and {b} overlap (shell {a} has vertices both inside \
         and outside shell {b}), so the winding number is not 0 or 1 where they overlap"
    )]
    CrossingShells { a: usize, b: usize },
    #[error("faces {a} and {b} cross each other (the surface intersects itself)")]
    SelfIntersecting { a: usize, b: usize },
}

impl Defect {
    /// A short, stable name of the defect (counted in sweep summaries).
    pub fn slug(&self) -> &'static str {
        match self {
            Defect::Open(_) => "not-closed",
            Defect::FoldedEdge(_) => "folded-edge",
            Defect::Overflow { .. } => "overflow",
            Defect::Inverted { .. } => "inverted",
            Defect::InvertedShell { .. } => "inverted-shell",
            Defect::NestedShell { .. } => "nested-shell",
            Defect::CrossingShells { .. } => "crossing-shells",
            Defect::SelfIntersecting { .. } => "self-intersecting",
        }
    }

    /// The command-line flag that accepts a mesh with this defect, if any.
    pub fn remedy(&self) -> Option<&'static str> {
        match self {
            Defect::Open(_) => Some("--allow-open"),
            Defect::Inverted { .. } => Some("--flip-inverted"),
            _ => None,
        }
    }
}

/// What [`check`] found.
#[derive(Clone, Debug, PartialEq)]
pub struct Solidity {
    /// Total surface area (§3.6.2).
    pub area: f64,
    /// Signed volume (Alg. 3-1) when the surface is closed and oriented.
    pub volume: Option<f64>,
    pub shells: Vec<Shell>,
    /// Every defect found, in the order of the rule's points (empty: a valid solid).
    pub defects: Vec<Defect>,
}

impl Solidity {
    pub fn is_solid(&self) -> bool {
        self.defects.is_empty()
    }

    /// Shells that face inwards inside another (cavities).
    pub fn cavities(&self) -> usize {
        self.shells.iter().filter(|s| s.volume < 0.0 && s.depth.is_some_and(|d| d > 0)).count()
    }
}

impl std::fmt::Display for Solidity {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let cavities = self.cavities();
        write!(f, "shells                 {}", self.shells.len())?;
        if cavities > 0 {
            write!(f, " ({cavities} cavit{})", if cavities == 1 { "y" } else { "ies" })?;
        }
        writeln!(f)?;
        match self.defects.first() {
            // No faces: the empty solid, inside nowhere.
            None if self.shells.is_empty() => write!(f, "solid: yes (empty)"),
            None => write!(f, "solid: yes (inside = winding number 1)"),
            Some(d) => {
                write!(f, "solid: no: {d}")?;
                for d in &self.defects[1..] {
                    write!(f, "\n       also: {d}")?;
                }
                Ok(())
            }
        }
    }
}

/// Measures `mesh` against the rule of the module docs and lists its defects, in the
/// mesh's [`Frame`] (scale-free); the measures are in the mesh's units.
pub fn check(mesh: &Mesh) -> Solidity {
    let frame = Frame::of(&[mesh]);
    check_in(&frame.mesh_in_ref(mesh), frame)
}

/// [`check`] of a mesh already in `frame`: its measures are reported in the input's
/// units, and it is not measurable when they overflow there.
pub fn check_in(mesh: &Mesh, frame: Frame) -> Solidity {
    let mut report = check_framed(mesh);
    let area = frame.area_out(report.area);
    let volume = report.volume.map(|v| frame.volume_out(v));
    if !area.is_finite() || volume.is_some_and(|v| !v.is_finite()) {
        let largest = mesh.positions().iter().map(|p| p.abs().max_element()).fold(0.0, f64::max);
        // Point 2 of the rule: after an open surface, before the rest.
        let at = usize::from(matches!(report.defects.first(), Some(Defect::Open(_))));
        report.defects.insert(at, Defect::Overflow { largest: frame.length_out(largest) });
    }
    report.area = area;
    report.volume = volume;
    for shell in &mut report.shells {
        shell.volume = frame.volume_out(shell.volume);
    }
    for d in &mut report.defects {
        if let Defect::Inverted { volume } = d {
            *volume = frame.volume_out(*volume);
        }
    }
    report
}

/// [`check`] in the mesh's own units.
fn check_framed(mesh: &Mesh) -> Solidity {
    let covering = Covering::new(mesh);
    let area = covering.area();
    let mut report = Solidity { area, volume: None, shells: Vec::new(), defects: Vec::new() };
    let (unbalanced, folded) = covering.edge_faults();
    if let Some(e) = unbalanced {
        report.defects.push(Defect::Open(e));
    }
    let groups = covering.shells();
    let volumes: Vec<f64> = groups.iter().map(|faces| covering.shell_measures(faces).volume).collect();
    let volume = compensated_sum(volumes.iter().copied());
    report.shells = groups
        .iter()
        .zip(&volumes)
        .map(|(faces, &v)| Shell {
            faces: faces.len(),
            first_face: faces[0] as usize,
            volume: v,
            depth: None,
        })
        .collect();
    if unbalanced.is_some() {
        return report;
    }
    report.volume = Some(volume);
    if let Some(e) = folded {
        report.defects.push(Defect::FoldedEdge(e));
    }
    nesting(mesh, &covering, &groups, &mut report);
    orientation(&mut report);
    // Exact triangle–triangle tests: faces that cross make the winding number 2 (or −1)
    // somewhere even when every shell on its own is fine.
    if let Some(&(a, b)) = intersect::self_intersections(mesh, 1).first() {
        report.defects.push(Defect::SelfIntersecting { a, b });
    }
    report
}

/// Fills each shell's depth: the winding number of the other shells around a few of its
/// vertices; vertices that disagree mean the shells overlap.
fn nesting(mesh: &Mesh, covering: &Covering, groups: &[Vec<u32>], report: &mut Solidity) {
    if groups.len() == 1 {
        report.shells[0].depth = Some(0);
        return;
    }
    let pos = mesh.positions();
    let boxes: Vec<(DVec3, DVec3)> = groups
        .iter()
        .map(|faces| {
            faces
                .iter()
                .flat_map(|&f| mesh.face(f as usize))
                .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), &v| {
                    (lo.min(pos[v as usize]), hi.max(pos[v as usize]))
                })
        })
        .collect();
    let triangles = |s: usize| groups[s].iter().flat_map(|&f| covering.face_triangles(f as usize));
    for s in 0..groups.len() {
        let mut vertices: Vec<u32> = groups[s].iter().flat_map(|&f| mesh.face(f as usize)).copied().collect();
        vertices.sort_unstable();
        vertices.dedup();
        let step = vertices.len().div_ceil(SAMPLES).max(1);
        // Per sample, the rounded winding number of every other shell (0 when outside its box).
        let mut seen: Option<Vec<i32>> = None;
        for &v in vertices.iter().step_by(step) {
            let p = pos[v as usize];
            let mut windings = vec![0i32; groups.len()];
            let mut clear = true;
            for (t, &(lo, hi)) in boxes.iter().enumerate() {
                if t == s || !(p.cmpge(lo).all() && p.cmple(hi).all()) {
                    continue;
                }
                let w = covering.winding_number(triangles(t), p);
                if (w - w.round()).abs() > WINDING_SLACK {
                    clear = false;
                    break;
                }
                windings[t] = w.round() as i32;
            }
            if !clear {
                continue;
            }
            match &seen {
                None => seen = Some(windings),
                Some(first) => {
                    if let Some(t) = (0..groups.len()).find(|&t| first[t] != windings[t]) {
                        report.defects.push(Defect::CrossingShells { a: s, b: t });
                        seen = None;
                        break;
                    }
                }
            }
        }
        report.shells[s].depth = seen.map(|w| w.iter().sum());
    }
}

/// Checks every shell's orientation against its depth (point 3 of the rule).
fn orientation(report: &mut Solidity) {
    let sign = |v: f64| {
        if v > 0.0 {
            1
        } else if v < 0.0 {
            -1
        } else {
            0
        }
    };
    let valid = |d: i32, s: i32| (0..=1).contains(&d) && (0..=1).contains(&(d + s));
    let shells = &report.shells;
    let decided = || shells.iter().filter_map(|sh| sh.depth.map(|d| (d, sign(sh.volume))));
    if decided().all(|(d, s)| valid(d, s)) {
        return;
    }
    if decided().all(|(d, s)| valid(-d, -s)) {
        let volume = report.volume.unwrap_or(0.0);
        report.defects.push(Defect::Inverted { volume });
        return;
    }
    let mut found = Vec::new();
    for (i, sh) in shells.iter().enumerate() {
        let (Some(d), s) = (sh.depth, sign(sh.volume)) else { continue };
        if valid(d, s) {
            continue;
        }
        if d == 0 {
            found.push(Defect::InvertedShell { shell: i, first_face: sh.first_face });
        } else {
            // The innermost shell around it with a non-zero winding: the one deepest itself.
            let outer = shells
                .iter()
                .enumerate()
                .filter(|&(j, o)| j != i && o.depth.is_some_and(|od| od < d) && sign(o.volume) != 0)
                .max_by_key(|(_, o)| o.depth)
                .map_or(0, |(j, _)| j);
            found.push(Defect::NestedShell { shell: i, first_face: sh.first_face, outer, winding: d + s });
        }
    }
    report.defects.extend(found);
}

/// The boundary curve of a mesh that is not closed: its edges whose directed uses do not
/// cancel (counted once each), and the loops they form (components sharing a vertex).
pub fn boundary_loops(mesh: &Mesh) -> (usize, usize) {
    let mut uses: Vec<(u32, u32, i32)> = mesh
        .faces()
        .flat_map(|f| (0..f.len()).map(move |i| (f[i], f[(i + 1) % f.len()])))
        .map(|(a, b)| if a < b { (a, b, 1) } else { (b, a, -1) })
        .collect();
    uses.sort_unstable_by_key(|&(a, b, _)| (a, b));
    let mut sets = UnionFind::new(mesh.num_vertices());
    let mut ends = Vec::new();
    for run in uses.chunk_by(|x, y| (x.0, x.1) == (y.0, y.1)) {
        if run.iter().map(|x| x.2).sum::<i32>() != 0 {
            sets.union(run[0].0, run[0].1);
            ends.push(run[0].0);
        }
    }
    let mut roots: Vec<u32> = ends.iter().map(|&v| sets.find(v)).collect();
    roots.sort_unstable();
    roots.dedup();
    (ends.len(), roots.len())
}

/// What `--allow-open` makes of a mesh with this defect: the rule, and what it means here.
pub fn allow_open_note(defect: &Defect) -> &'static str {
    match defect {
        Defect::Overflow { .. } => "refused even with --allow-open",
        Defect::Inverted { .. } | Defect::InvertedShell { .. } => {
            "inside by winding number ≥ ½ with --allow-open: the winding number is −1 inside an \
             inverted shell, so none of it is inside (--flip-inverted reverses the faces of an inverted solid)"
        }
        Defect::NestedShell { .. } | Defect::CrossingShells { .. } | Defect::SelfIntersecting { .. } => {
            "inside by winding number ≥ ½ with --allow-open (where shells overlap or nest the same way, \
             w = 2: inside)"
        }
        Defect::Open(_) => "inside by winding number ≥ ½ with --allow-open",
        Defect::FoldedEdge(_) => {
            "inside by winding number ≥ ½ with --allow-open (beside the edge w is −1, outside, or 2, inside)"
        }
    }
}

/// `mesh` with every face reversed (inside and outside swapped).
pub fn flipped(mesh: &Mesh) -> Mesh {
    let (offsets, indices) = mesh.face_parts();
    let mut reversed = indices.to_vec();
    for w in offsets.windows(2) {
        reversed[w[0]..w[1]].reverse();
    }
    Mesh::from_parts(mesh.positions().to_vec(), offsets.to_vec(), reversed)
        .unwrap_or_else(|e| unreachable!("reversing faces keeps a mesh valid: {e}"))
}

/// What a command may accept besides valid solids (the flags of the module docs).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Policy {
    /// `--allow-open`: accept a mesh that is not a solid (open, self-intersecting, nested,
    /// inverted): inside iff its generalized winding number is at least ½.
    pub allow_open: bool,
    /// `--flip-inverted`: reverse every face of an inverted solid.
    pub flip_inverted: bool,
    /// `boolean --allow-self-intersections`: go on with faces that cross (best effort).
    pub allow_self_intersections: bool,
}

/// The first defect of `solidity` that `policy` does not excuse (an inverted solid is
/// excused when the policy flips it; [`require_solid`] then checks the flipped mesh).
pub fn first_refusal(solidity: &Solidity, policy: Policy) -> Option<&Defect> {
    solidity.defects.iter().find(|d| match d {
        Defect::Overflow { .. } => true,
        _ if policy.allow_open => false,
        Defect::Inverted { .. } => !policy.flip_inverted,
        Defect::SelfIntersecting { .. } | Defect::CrossingShells { .. } => !policy.allow_self_intersections,
        _ => true,
    })
}

/// A mesh a command may work on.
#[derive(Clone, Debug)]
pub struct Accepted {
    /// The mesh to use: the input, or its [`flipped`] copy, in [`Accepted::frame`].
    pub mesh: Mesh,
    /// The scale the command works at: query points enter it, reported positions and
    /// measures leave it ([`Frame`]).
    pub frame: Frame,
    pub solidity: Solidity,
    /// The faces were reversed (`--flip-inverted`).
    pub flipped: bool,
    /// Not a solid, accepted under `--allow-open`: its first defect. Points are then
    /// inside iff the generalized winding number is at least ½.
    pub non_solid: Option<Defect>,
}

/// Why [`require_solid`] refused a mesh: the first defect the policy does not excuse.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("not a solid: {defect}")]
pub struct NotSolid {
    pub defect: Defect,
}

/// The gate in front of every command that needs a solid: `mesh` if it is a valid solid
/// (or flipped, or open, as `policy` allows), else the reason it is not.
///
/// A mesh found to be a valid solid is remembered in the user's cache ([`crate::cache`],
/// keyed by a BLAKE3 hash of its exact contents and of [`RULES`]): the same mesh read again
/// is let through without repeating [`check`]. Only valid solids are remembered, so a
/// mesh is refused, with the same reason, exactly when [`check`] refuses it.
pub fn require_solid(mesh: Mesh, policy: Policy) -> Result<Accepted, NotSolid> {
    let memory = Memory::of(&mesh);
    if let Some(solidity) = memory.recall() {
        let frame = Frame::of(&[&mesh]);
        return Ok(Accepted { mesh: frame.mesh_in(mesh), frame, solidity, flipped: false, non_solid: None });
    }
    let accepted = require_solid_uncached(mesh, policy)?;
    if !accepted.flipped {
        memory.remember(&accepted.solidity);
    }
    Ok(accepted)
}

/// The user's cache entry for one mesh's verdict (exactly these positions and faces): the
/// memory [`require_solid`] keeps, for callers that check in their own frame (the
/// Booleans' operands). Empty when caching is off.
pub struct Memory {
    entry: Option<(crate::cache::Store, crate::cache::Key)>,
}

impl Memory {
    pub fn of(mesh: &Mesh) -> Memory {
        Memory { entry: crate::cache::Store::open(CACHE_KIND).map(|store| (store, verdict_key(mesh))) }
    }

    /// The verdict of an earlier [`check`] that found the mesh a valid solid, if any.
    pub fn recall(&self) -> Option<Solidity> {
        let (store, key) = self.entry.as_ref()?;
        store.get(key).and_then(|b| decode_solid(&b))
    }

    /// Remembers `solidity`, the result of [`check`] on the mesh in its units, if it says
    /// the mesh is a valid solid (only valid solids are remembered).
    pub fn remember(&self, solidity: &Solidity) {
        if let Some((store, key)) = &self.entry {
            if solidity.is_solid() {
                store.put(key, &encode_solid(solidity));
            }
        }
    }
}

/// Names the rules of this module in every cached verdict's key: change it whenever what
/// counts as a solid (or what [`check`] measures) changes, and old verdicts are not used.
pub const RULES: &str = "texgeo solidity rules 3 (closed, alternating at non-manifold edges, measurable, outward, not self-intersecting; in the mesh's frame)";
const CACHE_KIND: &str = "solidity-v3";

/// The cache key of `mesh`: its positions (bit for bit) and faces, under [`RULES`].
pub fn verdict_key(mesh: &Mesh) -> crate::cache::Key {
    let mut h = crate::cache::KeyHasher::new(RULES);
    h.u64(mesh.num_vertices() as u64);
    for p in mesh.positions() {
        for c in p.to_array() {
            h.f64(c);
        }
    }
    let (offsets, indices) = mesh.face_parts();
    h.u64(offsets.len() as u64);
    for &o in offsets {
        h.u64(o as u64);
    }
    for &i in indices {
        h.u64(i as u64);
    }
    h.finish()
}

/// A valid solid's measures: area, volume, then per shell faces, first face, volume, depth.
fn encode_solid(s: &Solidity) -> Vec<u8> {
    let mut out = Vec::with_capacity(24 + 28 * s.shells.len());
    out.extend_from_slice(&s.area.to_le_bytes());
    out.extend_from_slice(&s.volume.unwrap_or(f64::NAN).to_le_bytes());
    out.extend_from_slice(&(s.shells.len() as u64).to_le_bytes());
    for sh in &s.shells {
        out.extend_from_slice(&(sh.faces as u64).to_le_bytes());
        out.extend_from_slice(&(sh.first_face as u64).to_le_bytes());
        out.extend_from_slice(&sh.volume.to_le_bytes());
        out.extend_from_slice(&sh.depth.unwrap_or(i32::MIN).to_le_bytes());
    }
    out
}

fn decode_solid(b: &[u8]) -> Option<Solidity> {
    let mut rest = b;
    let mut take = |n: usize| -> Option<u64> {
        let (head, tail) = rest.split_at_checked(n)?;
        rest = tail;
        let mut v = [0u8; 8];
        v[..n].copy_from_slice(head);
        Some(u64::from_le_bytes(v))
    };
    let area = f64::from_bits(take(8)?);
    let volume = f64::from_bits(take(8)?);
    let count = take(8)? as usize;
    let mut shells = Vec::with_capacity(count.min(b.len() / 28));
    for _ in 0..count {
        let faces = take(8)? as usize;
        let first_face = take(8)? as usize;
        let volume = f64::from_bits(take(8)?);
        let depth = take(4)? as u32 as i32;
        shells.push(Shell { faces, first_face, volume, depth: (depth != i32::MIN).then_some(depth) });
    }
    (take(1).is_none() && !volume.is_nan()).then_some(Solidity {
        area,
        volume: Some(volume),
        shells,
        defects: Vec::new(),
    })
}

/// [`require_solid`] without the cache: always runs [`check`].
pub fn require_solid_uncached(mesh: Mesh, policy: Policy) -> Result<Accepted, NotSolid> {
    let frame = Frame::of(&[&mesh]);
    let mesh = frame.mesh_in(mesh);
    let solidity = check_in(&mesh, frame);
    if let Some(d) = first_refusal(&solidity, policy) {
        return Err(NotSolid { defect: d.clone() });
    }
    if policy.flip_inverted && solidity.defects.iter().any(|d| matches!(d, Defect::Inverted { .. })) {
        let mesh = flipped(&mesh);
        let solidity = check_in(&mesh, frame);
        return match first_refusal(&solidity, Policy { flip_inverted: false, ..policy }) {
            None => {
                let non_solid = solidity.defects.first().cloned();
                Ok(Accepted { mesh, frame, solidity, flipped: true, non_solid })
            }
            Some(d) => Err(NotSolid { defect: d.clone() }),
        };
    }
    let non_solid = solidity.defects.first().cloned();
    Ok(Accepted { mesh, frame, solidity, flipped: false, non_solid })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::procedural::{self, box_between};

    fn union(parts: &[Mesh]) -> Mesh {
        let mut positions = Vec::new();
        let mut faces = Vec::new();
        for m in parts {
            let base = positions.len() as u32;
            positions.extend_from_slice(m.positions());
            faces.extend(m.faces().map(|f| f.iter().map(|&i| i + base).collect::<Vec<_>>()));
        }
        Mesh::new(positions, faces).unwrap()
    }

    #[test]
    fn built_ins_are_solids() {
        for name in procedural::BUILTIN_NAMES {
            let m = procedural::by_name(name).unwrap();
            let s = check(&m);
            assert!(s.is_solid(), "{name}: {:?}", s.defects);
        }
        let cavity = check(&procedural::cube_with_cavity());
        assert_eq!(cavity.shells.len(), 2);
        assert_eq!(cavity.cavities(), 1);
        assert!((cavity.volume.unwrap() - 56.0).abs() < 1e-12);
    }

    #[test]
    fn inverted_and_nested_shells() {
        let cube = procedural::cube();
        let inverted = check(&flipped(&cube));
        assert!(
            matches!(inverted.defects[..], [Defect::Inverted { volume }] if (volume + 8.0).abs() < 1e-12)
        );
        let flipped_cavity = check(&flipped(&procedural::cube_with_cavity()));
        assert!(
            matches!(flipped_cavity.defects[..], [Defect::Inverted { .. }]),
            "{:?}",
            flipped_cavity.defects
        );

        // A shell inside a shell, both facing out: w = 2 inside the inner one.
        let nested = union(&[box_between(DVec3::splat(-2.0), DVec3::splat(2.0)), cube.clone()]);
        let s = check(&nested);
        assert_eq!(s.defects, vec![Defect::NestedShell { shell: 1, first_face: 6, outer: 0, winding: 2 }]);
        // An inward shell next to a good one.
        let beside = union(&[cube.clone(), flipped(&box_between(DVec3::splat(3.0), DVec3::splat(4.0)))]);
        assert_eq!(check(&beside).defects, vec![Defect::InvertedShell { shell: 1, first_face: 6 }]);
        // An island inside a cavity is fine; inside it another outward box is not.
        let island =
            union(&[procedural::cube_with_cavity(), box_between(DVec3::splat(-0.5), DVec3::splat(0.5))]);
        assert!(check(&island).is_solid(), "{:?}", check(&island).defects);
        // Two overlapping cubes: some vertices of each lie inside the other.
        let overlap = union(&[cube.clone(), box_between(DVec3::splat(0.0), DVec3::splat(2.0))]);
        assert!(matches!(check(&overlap).defects[..], [Defect::CrossingShells { .. }, ..]));
    }

    /// The cube with a tetrahedron on its edge between its first face's first two corners,
    /// outside it or inside it, facing out or in.
    fn cube_with_tetra_on_an_edge(outside: bool, outward: bool) -> Mesh {
        let cube = procedural::cube();
        let mut positions = cube.positions().to_vec();
        let mut faces: Vec<Vec<u32>> = cube.faces().map(<[u32]>::to_vec).collect();
        let (a, b) = (faces[0][0], faces[0][1]);
        let (pa, pb) = (positions[a as usize], positions[b as usize]);
        let m = (pa + pb) / 2.0;
        // The cube's outward normals at the edge: the axes where the midpoint is on a side.
        let axes: Vec<DVec3> = (0..3)
            .filter(|&i| m[i].abs() == 1.0)
            .map(|i| DVec3::from_array(std::array::from_fn(|j| if j == i { m[i] } else { 0.0 })))
            .collect();
        let (n1, n2) = (axes[0], axes[1]);
        let d = if outside { n1 + n2 } else { -(n1 + n2) };
        let (mut p, mut q) = (m + 0.4 * d + 0.1 * (n1 - n2), m + 0.4 * d - 0.1 * (n1 - n2));
        if (pb - pa).dot((p - pa).cross(q - pa)) < 0.0 {
            std::mem::swap(&mut p, &mut q);
        }
        let (ip, iq) = (positions.len() as u32, positions.len() as u32 + 1);
        positions.extend([p, q]);
        // Tetra (a, b, p, q) of positive volume, faces outward.
        let mut tetra = vec![vec![a, ip, b], vec![a, b, iq], vec![b, ip, iq], vec![a, iq, ip]];
        if !outward {
            for f in &mut tetra {
                f.reverse();
            }
        }
        faces.extend(tetra);
        Mesh::new(positions, faces).unwrap()
    }

    #[test]
    fn faces_around_a_non_manifold_edge_alternate() {
        // Outside facing out (w = 1 in it) and inside facing in (a cavity, w = 0): solids.
        for (outside, outward) in [(true, true), (false, false)] {
            let s = check(&cube_with_tetra_on_an_edge(outside, outward));
            assert!(s.is_solid(), "outside {outside}, outward {outward}: {:?}", s.defects);
        }
        // Outside facing in (w = −1 in it) and inside facing out (w = 2): the faces about the
        // shared edge do not alternate.
        for (outside, outward) in [(true, false), (false, true)] {
            let s = check(&cube_with_tetra_on_an_edge(outside, outward));
            assert!(
                matches!(s.defects.first(), Some(Defect::FoldedEdge(FoldedEdge { faces: 4, .. }))),
                "outside {outside}, outward {outward}: {:?}",
                s.defects
            );
        }
    }

    #[test]
    fn any_size_is_checked_in_its_frame() {
        let cube = procedural::cube();
        // 2⁻³⁰⁰: products of coordinates are 2⁻⁹⁰⁰, yet the checks run at unit size.
        let tiny = cube.map_positions(|p| p * 2f64.powi(-300)).unwrap();
        let s = check(&tiny);
        assert!(s.is_solid(), "{:?}", s.defects);
        assert_eq!(s.volume, Some(8.0 * 2f64.powi(-900)));
        let ok = require_solid(tiny, Policy::default()).unwrap();
        assert_eq!((ok.frame.exponent(), &ok.mesh), (300, &cube));
        // 10⁻¹⁴⁰: the volume underflows f64, the verdict does not.
        let s = check(&cube.map_positions(|p| p * 1e-140).unwrap());
        assert!(s.is_solid(), "{:?}", s.defects);
        // 10⁸⁰: volume 8·10²⁴⁰, finite.
        let s = check(&cube.map_positions(|p| p * 1e80).unwrap());
        assert!(s.is_solid(), "{:?}", s.defects);
        let want = 8.0 * 1e80f64.powi(3);
        assert!((s.volume.unwrap() - want).abs() <= 1e-14 * want, "{:?}", s.volume);
    }

    #[test]
    fn require_solid_follows_the_policy() {
        let inverted = flipped(&procedural::cube());
        let e = require_solid(inverted.clone(), Policy::default()).unwrap_err();
        assert_eq!(e.defect.remedy(), Some("--flip-inverted"));
        assert!(e.to_string().starts_with("not a solid: the solid is inverted"), "{e}");
        let ok = require_solid(inverted, Policy { flip_inverted: true, ..Policy::default() }).unwrap();
        assert!(ok.flipped && (ok.solidity.volume.unwrap() - 8.0).abs() < 1e-12);
        let cube = procedural::cube();
        let open = Mesh::new(cube.positions().to_vec(), cube.faces().skip(1).map(<[u32]>::to_vec).collect())
            .unwrap();
        assert!(matches!(
            require_solid(open.clone(), Policy::default()).unwrap_err().defect,
            Defect::Open(_)
        ));
        assert!(matches!(
            require_solid(open, Policy { allow_open: true, ..Policy::default() }).unwrap().non_solid,
            Some(Defect::Open(_))
        ));
        let huge = cube.map_positions(|p| p * 1e120).unwrap();
        let e = require_solid(huge, Policy::default()).unwrap_err();
        assert!(matches!(e.defect, Defect::Overflow { .. }), "{e}");
    }
}
