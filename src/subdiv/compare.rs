//! Comparing a refined mesh with a reference (OpenSubdiv, SPEC §5.4): counts, a
//! one-to-one vertex correspondence, position errors, and faces compared as vertex cycles
//! under the correspondence. Vertex order may differ; face orientation may not.
//!
//! The correspondence is the refinement's own whenever there is one, and positions are
//! only the check (coincident but distinct vertices must not be
//! swapped):
//!
//! 1. both meshes list their vertices in the same order (the CPU reference and
//!    OpenSubdiv do): vertex i ↔ vertex i;
//! 2. both list the same number of faces of the same sizes (the GPU path emits its faces
//!    in OpenSubdiv's order and rotation, `assemble`): the corners of face i give the
//!    correspondence, if they do so consistently (one partner per vertex, both ways);
//!    vertices no face uses are matched by position among themselves;
//! 3. otherwise, a one-to-one matching by position: the reference's vertices are hashed
//!    into a grid whose cells are much larger than the tolerance, so almost every query
//!    looks in one cell — linear time, a few seconds for 5 M vertices.

use std::collections::HashMap;
use std::fmt;
use std::hash::{BuildHasherDefault, Hasher};

use glam::DVec3;

use crate::mesh::Mesh;

/// Unmatched vertex marker.
const NONE: u32 = u32::MAX;

/// The outcome of comparing `mesh` with `reference` (`subdivide --validate --json`: these
/// fields).
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Comparison {
    /// Vertex counts of mesh and reference.
    pub vertices: [usize; 2],
    /// Face counts of mesh and reference.
    pub faces: [usize; 2],
    /// Bounding-box diagonal of the reference.
    pub diagonal: f64,
    /// Largest distance accepted for a match (relative tolerance × diagonal).
    pub tolerance: f64,
    /// Vertices of the mesh matched one-to-one to reference vertices within `tolerance`.
    pub matched: usize,
    /// Largest and root-mean-square distance over the matched vertices.
    pub max_error: f64,
    pub rms_error: f64,
    /// Every vertex matched the reference vertex of the same index.
    pub same_order: bool,
    /// How the vertices were put in correspondence.
    pub matching: Matching,
    /// Faces of the mesh whose matched cycle is a reference face (up to rotation).
    pub faces_equal: usize,
    /// Faces whose matched cycle is a reference face traversed backwards.
    pub faces_reversed: usize,
    /// Faces with an unmatched vertex or no counterpart at all.
    pub faces_missing: usize,
}

/// How [`Comparison`] put the vertices in correspondence (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Matching {
    SameOrder,
    Faces,
    Positions,
}

impl Comparison {
    /// Compares `mesh` with `reference`; `relative_tolerance` is a fraction of the
    /// reference's bounding-box diagonal (1e-12 for f64 against OpenSubdiv, 1e-5 for f32).
    pub fn new(mesh: &Mesh, reference: &Mesh, relative_tolerance: f64) -> Comparison {
        let (lo, hi) = reference.bounds();
        let diagonal = (hi - lo).length();
        let tolerance = relative_tolerance * diagonal;
        let (a, b) = (mesh.positions(), reference.positions());
        let (how, matching) =
            if a.len() == b.len() && a.iter().zip(b).all(|(p, q)| p.distance(*q) <= tolerance) {
                (Matching::SameOrder, (0..a.len() as u32).collect())
            } else if let Some(m) = match_by_faces(mesh, reference, tolerance) {
                (Matching::Faces, m)
            } else {
                (Matching::Positions, match_vertices(a, b, tolerance))
            };
        let (mut matched, mut max_sq, mut sum_sq, mut partnered) = (0usize, 0.0f64, 0.0f64, 0usize);
        for (p, &m) in a.iter().zip(&matching) {
            if m != NONE {
                let d2 = p.distance_squared(b[m as usize]);
                partnered += 1;
                matched += usize::from(d2.sqrt() <= tolerance);
                max_sq = max_sq.max(d2);
                sum_sq += d2;
            }
        }
        let matched = matched;
        let same_order = mesh.num_vertices() == reference.num_vertices()
            && matching.iter().enumerate().all(|(i, &m)| m == i as u32);
        let [faces_equal, faces_reversed, faces_missing] = compare_faces(mesh, reference, &matching);
        Comparison {
            vertices: [mesh.num_vertices(), reference.num_vertices()],
            faces: [mesh.num_faces(), reference.num_faces()],
            diagonal,
            tolerance,
            matched,
            max_error: max_sq.sqrt(),
            rms_error: if partnered > 0 { (sum_sq / partnered as f64).sqrt() } else { 0.0 },
            same_order,
            matching: how,
            faces_equal,
            faces_reversed,
            faces_missing,
        }
    }

    /// Same counts, every vertex matched, every face equal.
    pub fn is_match(&self) -> bool {
        self.vertices[0] == self.vertices[1]
            && self.faces[0] == self.faces[1]
            && self.matched == self.vertices[0]
            && self.faces_equal == self.faces[0]
    }
}

impl fmt::Display for Comparison {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let relative = |x: f64| if self.diagonal > 0.0 { x / self.diagonal } else { x };
        writeln!(
            f,
            "{}: vertices {} vs {} (reference), faces {} vs {}",
            if self.is_match() { "match" } else { "MISMATCH" },
            self.vertices[0],
            self.vertices[1],
            self.faces[0],
            self.faces[1]
        )?;
        let how = match self.matching {
            Matching::SameOrder => ", same order",
            Matching::Faces => ", corresponding by faces",
            Matching::Positions => ", matched by position",
        };
        writeln!(
            f,
            "  vertices matched one-to-one within {:.3e} ({:.1e} × diagonal {:.6}): {} of {}{how}",
            self.tolerance,
            relative(self.tolerance),
            self.diagonal,
            self.matched,
            self.vertices[0],
        )?;
        writeln!(
            f,
            "  position error: max {:.3e} ({:.3e} × diagonal), RMS {:.3e} ({:.3e} × diagonal)",
            self.max_error,
            relative(self.max_error),
            self.rms_error,
            relative(self.rms_error)
        )?;
        write!(
            f,
            "  faces as cycles: {} equal, {} reversed, {} missing",
            self.faces_equal, self.faces_reversed, self.faces_missing
        )
    }
}

/// The correspondence given by aligned faces: corner k of face i of `mesh` ↔ corner k
/// of face i of `reference`; `None` when the face lists differ in shape or do not
/// correspond consistently. Vertices no face uses are matched by position among
/// themselves.
fn match_by_faces(mesh: &Mesh, reference: &Mesh, tolerance: f64) -> Option<Vec<u32>> {
    let ((offsets, indices), (ref_offsets, ref_indices)) = (mesh.face_parts(), reference.face_parts());
    if mesh.num_vertices() != reference.num_vertices() || offsets != ref_offsets {
        return None;
    }
    let mut forward = vec![NONE; mesh.num_vertices()];
    let mut backward = vec![NONE; reference.num_vertices()];
    for (&v, &w) in indices.iter().zip(ref_indices) {
        let (f, b) = (&mut forward[v as usize], &mut backward[w as usize]);
        if (*f != NONE && *f != w) || (*b != NONE && *b != v) {
            return None;
        }
        (*f, *b) = (w, v);
    }
    let free_a: Vec<u32> = (0..forward.len() as u32).filter(|&v| forward[v as usize] == NONE).collect();
    if !free_a.is_empty() {
        let free_b: Vec<u32> = (0..backward.len() as u32).filter(|&w| backward[w as usize] == NONE).collect();
        let pa: Vec<DVec3> = free_a.iter().map(|&v| mesh.positions()[v as usize]).collect();
        let pb: Vec<DVec3> = free_b.iter().map(|&w| reference.positions()[w as usize]).collect();
        for (&v, m) in free_a.iter().zip(match_vertices(&pa, &pb, tolerance)) {
            if m != NONE {
                forward[v as usize] = free_b[m as usize];
            }
        }
    }
    Some(forward)
}

/// For each vertex of `a`, a distinct vertex of `b` within `tolerance` (the nearest one
/// still free), or `NONE`.
fn match_vertices(a: &[DVec3], b: &[DVec3], tolerance: f64) -> Vec<u32> {
    let grid = Grid::new(b, tolerance);
    let mut taken = vec![false; b.len()];
    a.iter()
        .map(|&p| {
            let mut best = (NONE, tolerance * tolerance);
            grid.visit_near(p, tolerance, |j| {
                let d2 = p.distance_squared(b[j as usize]);
                if !taken[j as usize] && d2 <= best.1 {
                    best = (j, d2);
                }
            });
            if best.0 != NONE {
                taken[best.0 as usize] = true;
            }
            best.0
        })
        .collect()
}

/// The reference's vertices bucketed in a uniform grid.
struct Grid {
    origin: DVec3,
    cell: f64,
    /// Vertex indices sorted by cell; `cells` maps a cell key to its range here.
    order: Vec<u32>,
    cells: HashMap<u64, (u32, u32), BuildHasherDefault<CellHasher>>,
}

impl Grid {
    /// Cells of about one vertex each on a surface (diagonal / √n), never smaller than
    /// four tolerances, so a query near no cell wall looks in one cell only.
    fn new(points: &[DVec3], tolerance: f64) -> Grid {
        let (lo, hi) =
            points.iter().fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), &p| (lo.min(p), hi.max(p)));
        let origin = if points.is_empty() { DVec3::ZERO } else { lo };
        let diagonal = if points.is_empty() { 0.0 } else { (hi - lo).length() };
        let mut cell = (diagonal / (points.len() as f64).sqrt()).max(4.0 * tolerance);
        if !(cell > 0.0 && cell.is_finite()) {
            cell = 1.0;
        }
        let mut keyed: Vec<(u64, u32)> = points
            .iter()
            .enumerate()
            .map(|(i, &p)| (Self::key(Self::coords(origin, cell, p)), i as u32))
            .collect();
        keyed.sort_unstable();
        let mut cells = HashMap::with_capacity_and_hasher(keyed.len(), BuildHasherDefault::default());
        let mut start = 0;
        for run in keyed.chunk_by(|x, y| x.0 == y.0) {
            cells.insert(run[0].0, (start, start + run.len() as u32));
            start += run.len() as u32;
        }
        Grid { origin, cell, order: keyed.into_iter().map(|(_, i)| i).collect(), cells }
    }

    fn coords(origin: DVec3, cell: f64, p: DVec3) -> [i64; 3] {
        ((p - origin) / cell).floor().as_i64vec3().to_array()
    }

    /// Packs cell coordinates (21 bits each, wrapping: a collision only adds candidates).
    fn key(c: [i64; 3]) -> u64 {
        let mask = (1u64 << 21) - 1;
        (c[0] as u64 & mask) | ((c[1] as u64 & mask) << 21) | ((c[2] as u64 & mask) << 42)
    }

    /// Calls `visit` with every vertex in the cells within `radius` of `p`.
    fn visit_near(&self, p: DVec3, radius: f64, mut visit: impl FnMut(u32)) {
        let lo = Self::coords(self.origin, self.cell, p - DVec3::splat(radius));
        let hi = Self::coords(self.origin, self.cell, p + DVec3::splat(radius));
        for x in lo[0]..=hi[0] {
            for y in lo[1]..=hi[1] {
                for z in lo[2]..=hi[2] {
                    if let Some(&(s, e)) = self.cells.get(&Self::key([x, y, z])) {
                        self.order[s as usize..e as usize].iter().for_each(|&j| visit(j));
                    }
                }
            }
        }
    }
}

/// Multiplicative hashing for cell keys (the default SipHash is several times slower
/// and its resistance to crafted keys is not needed here).
#[derive(Default)]
struct CellHasher(u64);

impl Hasher for CellHasher {
    fn finish(&self) -> u64 {
        self.0
    }

    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.write_u64(u64::from(b));
        }
    }

    fn write_u64(&mut self, x: u64) {
        self.0 = (self.0 ^ x).wrapping_mul(0x9e37_79b9_7f4a_7c15).rotate_left(29);
    }
}

/// Counts `mesh` faces whose cycle under `matching` is a reference face (each reference
/// face used once), is one reversed, or is neither: `[equal, reversed, missing]`.
fn compare_faces(mesh: &Mesh, reference: &Mesh, matching: &[u32]) -> [usize; 3] {
    let (offsets, indices) = mesh.face_parts();
    let (ref_offsets, ref_indices) = reference.face_parts();
    let identity = matching.iter().enumerate().all(|(i, &m)| m == i as u32);
    if identity && offsets == ref_offsets && indices == ref_indices {
        return [mesh.num_faces(), 0, 0];
    }
    // Reference faces bucketed by their smallest vertex (a rotation-invariant key).
    let mut first = vec![0u32; reference.num_vertices() + 1];
    for face in reference.faces() {
        first[min_vertex(face) as usize + 1] += 1;
    }
    for v in 0..reference.num_vertices() {
        first[v + 1] += first[v];
    }
    let mut bucket = vec![0u32; reference.num_faces()];
    let mut fill = first.clone();
    for (f, face) in reference.faces().enumerate() {
        let slot = &mut fill[min_vertex(face) as usize];
        bucket[*slot as usize] = f as u32;
        *slot += 1;
    }
    let mut used = vec![false; reference.num_faces()];
    let mut cycle = Vec::new();
    let mut counts = [0usize; 3];
    for face in mesh.faces() {
        cycle.clear();
        cycle.extend(face.iter().map(|&v| matching.get(v as usize).copied().unwrap_or(NONE)));
        if cycle.contains(&NONE) {
            counts[2] += 1;
            continue;
        }
        let m = min_vertex(&cycle) as usize;
        let candidates = &bucket[first[m] as usize..first[m + 1] as usize];
        let find = |cycle: &[u32], used: &[bool]| {
            candidates
                .iter()
                .copied()
                .find(|&g| !used[g as usize] && same_cycle(cycle, reference.face(g as usize)))
        };
        if let Some(g) = find(&cycle, &used) {
            used[g as usize] = true;
            counts[0] += 1;
        } else {
            cycle.reverse();
            match find(&cycle, &used) {
                Some(g) => {
                    used[g as usize] = true;
                    counts[1] += 1;
                }
                None => counts[2] += 1,
            }
        }
    }
    counts
}

fn min_vertex(face: &[u32]) -> u32 {
    face.iter().copied().min().unwrap_or(NONE)
}

/// True when `b` is `a` rotated.
fn same_cycle(a: &[u32], b: &[u32]) -> bool {
    if a.len() != b.len() {
        return false;
    }
    let Some(shift) = b.iter().position(|&v| v == a[0]) else { return false };
    a.iter().enumerate().all(|(i, &v)| b[(i + shift) % b.len()] == v)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cycles_equal_up_to_rotation_only() {
        assert!(same_cycle(&[1, 2, 3, 4], &[3, 4, 1, 2]));
        assert!(!same_cycle(&[1, 2, 3, 4], &[4, 3, 2, 1]));
        assert!(!same_cycle(&[1, 2, 3], &[1, 2, 3, 4]));
    }

    #[test]
    fn matches_a_permuted_perturbed_mesh() {
        let positions = vec![
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(1.0, 1.0, 0.0),
            DVec3::new(0.0, 1.0, 0.0),
            DVec3::new(0.5, 0.5, 1.0),
        ];
        let faces = vec![vec![0, 3, 2, 1], vec![0, 1, 4], vec![1, 2, 4], vec![2, 3, 4], vec![3, 0, 4]];
        let reference = Mesh::new(positions.clone(), faces.clone()).unwrap();
        // Reverse the vertex order, nudge positions, rotate one face.
        let perm = |v: u32| 4 - v;
        let moved: Vec<DVec3> = positions.iter().rev().map(|&p| p + DVec3::splat(1e-9)).collect();
        let mut moved_faces: Vec<Vec<u32>> =
            faces.iter().map(|f| f.iter().map(|&v| perm(v)).collect()).collect();
        moved_faces[1].rotate_left(1);
        let mesh = Mesh::new(moved, moved_faces.clone()).unwrap();
        let c = Comparison::new(&mesh, &reference, 1e-8);
        assert!(c.is_match(), "{c}");
        assert!(!c.same_order);
        assert!((c.max_error - 3f64.sqrt() * 1e-9).abs() < 1e-15);

        moved_faces[2].reverse();
        let flipped = Mesh::new(mesh.positions().to_vec(), moved_faces).unwrap();
        let c = Comparison::new(&flipped, &reference, 1e-8);
        assert_eq!((c.faces_equal, c.faces_reversed, c.faces_missing), (4, 1, 0), "{c}");
        assert!(!c.is_match());

        let c = Comparison::new(&mesh, &reference, 1e-12);
        assert_eq!(c.matched, 0, "{c}");
        assert_eq!(c.faces_missing, 5);
    }
}
