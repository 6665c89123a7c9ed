//! Candidate triangle pairs for the exact self-intersection test: every pair that could
//! meet beyond what it shares, found without looking at the pairs that cannot.
//!
//! Two triangles that meet beyond their common vertices meet at a point of an edge of one
//! of them that has no vertex of the other: with no common vertex, some edge of one meets
//! the other; with one common vertex a, the edge opposite a of one meets the other (a
//! common part that leaves a along an edge ends on the other's opposite edge or at that
//! edge's far corner). Pairs with two or three common vertices share an edge and come
//! from the edges' triangle lists. So fans cost nothing: the triangles around a vertex
//! are paired only where the edges opposite it reach.
//!
//! The (edge, triangle) pairs come from an adaptive octree over the mesh's box that holds
//! the triangles alone: a triangle enters a cell only when it may cross it (its box
//! overlaps the cell, and the cell is not strictly on one side of its plane or of the
//! planes through its edges along the axis it faces most; tested with a margin for
//! rounding, so nothing that crosses is left out). An edge crosses no cell its triangles
//! do not, so a cell's edges are those of its triangles that may cross it (the same test,
//! made in the leaves only): the edges never go down the tree themselves, which would
//! place three times as many entries at every level. A cell stops splitting when it holds
//! few triangles, when all of them belong to one face, or when all of them share a vertex
//! and none of the edges opposite it may cross the cell (no pair there counts). A cell
//! is halved only along the axes that part its triangles when some do (long slivers side
//! by side are cut across, not along). Long slivers and high-valence fans therefore sit
//! in few cells, unlike boxes in a uniform grid, whose overlaps grow with the square of
//! the fan's size.

use glam::DVec3;
use rayon::prelude::*;

/// A cell with at most this many triangles pairs them instead of splitting.
const LEAF: usize = 24;
/// Deeper cells are not split (a point where many triangles truly cross); a level may
/// halve fewer than three axes ([`Tree::parting_axes`]).
const MAX_DEPTH: u32 = 32;
/// Cells with more entries are split with their children in parallel.
const PARALLEL: usize = 4096;
/// Where a cell is halved along an axis, as a fraction of its extent: off the middle,
/// because symmetric meshes put apexes, rings and axes on their box's middle planes, and
/// every entry touching a split plane goes to both halves.
const SPLIT_AT: f64 = 0.4567;

type Box3 = (DVec3, DVec3);

struct Tree<'a> {
    positions: &'a [DVec3],
    triangles: &'a [[u32; 3]],
    face_of: &'a [u32],
    /// Entries of the tree are triangles `0..n`; [`Tree::children_crossed`] also takes
    /// edge e as `n + e`.
    n: u32,
    /// Every edge once, as (lower, higher) vertex, in order.
    edges: Vec<[u32; 2]>,
    /// Triangles of edge e: `adjacent[start[e]..start[e + 1]]`.
    start: Vec<u32>,
    adjacent: Vec<u32>,
    /// The triangles' boxes.
    boxes: Vec<Box3>,
}

/// Triangle pairs `(i, j)`, i < j, sorted and distinct, that include every pair of
/// triangles (neither in `skip`) that share an edge, and every pair where an edge of one
/// with no vertex of the other may meet the other. Triangles of one face (`face_of`) are
/// not paired through the octree (they never count); they may still come as edge pairs.
pub fn candidate_pairs(
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    face_of: &[u32],
    skip: &[bool],
) -> Vec<(u32, u32)> {
    let n = triangles.len() as u32;
    // Every edge once, with its triangles.
    let mut ends: Vec<(u64, u32)> = (0..n)
        .into_par_iter()
        .with_min_len(4096)
        .filter(|&t| !skip[t as usize])
        .flat_map_iter(|t| {
            let v = triangles[t as usize];
            (0..3).map(move |k| {
                let (a, b) = (v[k].min(v[(k + 1) % 3]), v[k].max(v[(k + 1) % 3]));
                ((a as u64) << 32 | b as u64, t)
            })
        })
        .collect();
    ends.par_sort_unstable();
    let mut tree = Tree {
        positions,
        triangles,
        face_of,
        n,
        edges: Vec::new(),
        start: vec![0],
        adjacent: Vec::with_capacity(ends.len()),
        boxes: Vec::new(),
    };
    let mut out: Vec<u64> = Vec::new();
    for run in ends.chunk_by(|x, y| x.0 == y.0) {
        let key = run[0].0;
        tree.edges.push([(key >> 32) as u32, key as u32]);
        let first = tree.adjacent.len();
        tree.adjacent.extend(run.iter().map(|&(_, t)| t));
        tree.start.push(tree.adjacent.len() as u32);
        let faces = &tree.adjacent[first..];
        for (k, &t) in faces.iter().enumerate() {
            for &u in &faces[k + 1..] {
                out.push((t.min(u) as u64) << 32 | t.max(u) as u64);
            }
        }
    }
    drop(ends);
    let hull = |v: &[u32]| {
        v.iter().fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), &i| {
            (lo.min(positions[i as usize]), hi.max(positions[i as usize]))
        })
    };
    tree.boxes = triangles.par_iter().with_min_len(4096).map(|t| hull(t)).collect();
    let entries: Vec<u32> = (0..n).filter(|&t| !skip[t as usize]).collect();
    let root = entries
        .iter()
        .map(|&x| tree.boxes[x as usize])
        .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), b| (lo.min(b.0), hi.max(b.1)));
    if !entries.is_empty() {
        tree.walk(root, entries, 0, &mut out);
    }
    out.par_sort_unstable();
    out.dedup();
    out.into_iter().map(|p| ((p >> 32) as u32, p as u32)).collect()
}

impl Tree<'_> {
    /// No pair of the triangles `entries` can meet in `cell` beyond what it shares: fewer
    /// than two, all of one face, or all sharing a vertex v while no edge opposite v may
    /// cross the cell (two triangles that share only v and meet beyond it meet at a point
    /// of such an edge, see the module docs).
    fn nothing_to_pair(&self, entries: &[u32], cell: Box3) -> bool {
        if entries.len() < 2 {
            return true;
        }
        let f = self.face_of[entries[0] as usize];
        if entries.iter().all(|&t| self.face_of[t as usize] == f) {
            return true;
        }
        self.triangles[entries[0] as usize].iter().any(|&v| {
            entries.iter().all(|&t| {
                let w = self.triangles[t as usize];
                w.iter()
                    .position(|&x| x == v)
                    .is_some_and(|k| !self.segment_may_cross(w[(k + 1) % 3], w[(k + 2) % 3], cell))
            })
        })
    }

    /// The segment between vertices `a` and `b` may cross the closed `cell`: no coordinate
    /// axis and no cross product of the segment with one shows them apart (as
    /// [`Tree::children_crossed`] tests an edge).
    fn segment_may_cross(&self, a: u32, b: u32, cell: Box3) -> bool {
        let (p, q) = (self.positions[a as usize], self.positions[b as usize]);
        if !(p.min(q).cmple(cell.1).all() && cell.0.cmple(p.max(q)).all()) {
            return false;
        }
        edge_axes(q - p).into_iter().all(|axis| {
            apart_children(axis, axis.abs(), p, 0.0, DVec3::ZERO, cell, cell.1, [false; 3], 1) == 0
        })
    }

    /// The children of `cell` (halved at `mid` along the axes of `split`; child c takes
    /// the upper half of axis k iff bit k of c is set) among `mask` that entry `x` may
    /// cross: no separating axis shows them apart (the triangle's normal and its edges
    /// crossed with a coordinate axis; for an edge, the edge crossed with each coordinate
    /// axis; the coordinate axes themselves gave `mask`). Fewer axes than the theorem's
    /// only keep more children.
    fn children_crossed(&self, x: u32, cell: Box3, mid: DVec3, split: [bool; 3], mut mask: u8) -> u8 {
        let p = |i: u32| self.positions[i as usize];
        let mut axes = [(DVec3::ZERO, DVec3::ZERO, DVec3::ZERO, 0.0, DVec3::ZERO); 4];
        let count = if x < self.n {
            let t = self.triangles[x as usize].map(p);
            let (e, f) = (t[1] - t[0], t[2] - t[0]);
            let size = DVec3::new(
                (e.y * f.z).abs() + (e.z * f.y).abs(),
                (e.z * f.x).abs() + (e.x * f.z).abs(),
                (e.x * f.y).abs() + (e.y * f.x).abs(),
            );
            let normal = e.cross(f);
            axes[0] = (normal, size, t[0], 0.0, DVec3::ZERO);
            // The edges crossed with the axis the triangle faces most: the separating axes
            // of its projection along that axis, which is where a sliver is thin (the
            // other six axes of the theorem rarely separate more).
            let facing = normal.abs().max_position();
            for k in 0..3 {
                let (a, r) = (t[k], t[(k + 2) % 3]);
                let (d, span) = (t[(k + 1) % 3] - a, r - a);
                let axis = edge_axes(d)[facing];
                axes[1 + k] = (axis, axis.abs(), a, axis.dot(span), span.abs());
            }
            4
        } else {
            let [a, b] = self.edges[(x - self.n) as usize].map(p);
            for (j, axis) in edge_axes(b - a).into_iter().enumerate() {
                axes[j] = (axis, axis.abs(), a, 0.0, DVec3::ZERO);
            }
            3
        };
        for &(axis, size, a, reach, span) in &axes[..count] {
            mask &= !apart_children(axis, size, a, reach, span, cell, mid, split, mask);
            if mask == 0 {
                break;
            }
        }
        mask
    }

    /// Of the axes in `split`, those that part the entries at `mid` (by their boxes: at
    /// most half of them reach both sides, and at least an eighth lie wholly on each), or
    /// all of `split` when none does. Long slivers side by side reach both halves along
    /// their length: halving across them only, the cells become columns that each hold a
    /// few of them, where cubes would cut every sliver many times.
    fn parting_axes(&self, entries: &[u32], mid: DVec3, split: [bool; 3]) -> [bool; 3] {
        let (mut below, mut above) = ([0usize; 3], [0usize; 3]);
        for &x in entries {
            let (lo, hi) = self.boxes[x as usize];
            for k in 0..3 {
                below[k] += usize::from(hi[k] < mid[k]);
                above[k] += usize::from(lo[k] > mid[k]);
            }
        }
        let m = entries.len();
        let parting: [bool; 3] = std::array::from_fn(|k| {
            split[k] && 2 * (m - below[k] - above[k]) <= m && 8 * below[k].min(above[k]) >= m
        });
        if parting.contains(&true) { parting } else { split }
    }

    fn walk(&self, cell: Box3, entries: Vec<u32>, depth: u32, out: &mut Vec<u64>) {
        if self.nothing_to_pair(&entries, cell) {
            return;
        }
        let (lo, hi) = cell;
        let mid = lo + (hi - lo) * SPLIT_AT;
        // Axes the cell can still be halved along.
        let mut split: [bool; 3] = std::array::from_fn(|k| lo[k] < mid[k] && mid[k] < hi[k]);
        if entries.len() > LEAF {
            split = self.parting_axes(&entries, mid, split);
        }
        if entries.len() <= LEAF || depth >= MAX_DEPTH || !split.contains(&true) {
            self.pair(&entries, cell, out);
            return;
        }
        let child_box = |c: usize| -> Box3 {
            let mut b = cell;
            for k in 0..3 {
                if split[k] {
                    if c >> k & 1 == 0 {
                        b.1[k] = mid[k];
                    } else {
                        b.0[k] = mid[k];
                    }
                }
            }
            b
        };
        let classify = |x: u32| -> u8 {
            let (blo, bhi) = self.boxes[x as usize];
            // The halves of each axis the entry's box reaches.
            let sides = |k: usize| -> (usize, usize) {
                if !split[k] { (0, 0) } else { (usize::from(blo[k] > mid[k]), usize::from(bhi[k] >= mid[k])) }
            };
            let [(x0, x1), (y0, y1), (z0, z1)] = [sides(0), sides(1), sides(2)];
            let mut mask = 0u8;
            for cz in z0..=z1 {
                for cy in y0..=y1 {
                    for cx in x0..=x1 {
                        mask |= 1 << (cx | cy << 1 | cz << 2);
                    }
                }
            }
            if mask.count_ones() > 1 {
                mask = self.children_crossed(x, cell, mid, split, mask);
            }
            mask
        };
        // The children each entry enters (bit c for child c), in parallel for big cells:
        // the top cells hold nearly every entry and would otherwise run on one core.
        let masks: Vec<u8> = if entries.len() > PARALLEL {
            entries.par_iter().with_min_len(1024).map(|&x| classify(x)).collect()
        } else {
            entries.iter().map(|&x| classify(x)).collect()
        };
        let mut counts = [0usize; 8];
        for &m in &masks {
            for (c, n) in counts.iter_mut().enumerate() {
                *n += usize::from(m >> c & 1);
            }
        }
        let mut children: Vec<Vec<u32>> = counts.iter().map(|&n| Vec::with_capacity(n)).collect();
        for (&x, &m) in entries.iter().zip(&masks) {
            let mut m = m;
            while m != 0 {
                children[m.trailing_zeros() as usize].push(x);
                m &= m - 1;
            }
        }
        drop(entries);
        let total: usize = children.iter().map(Vec::len).sum();
        if total > PARALLEL {
            let found: Vec<Vec<u64>> = children
                .into_par_iter()
                .enumerate()
                .map(|(c, xs)| {
                    let mut o = Vec::new();
                    if !xs.is_empty() {
                        self.walk(child_box(c), xs, depth + 1, &mut o);
                    }
                    o
                })
                .collect();
            found.into_iter().for_each(|o| out.extend(o));
        } else {
            for (c, xs) in children.into_iter().enumerate() {
                if !xs.is_empty() {
                    self.walk(child_box(c), xs, depth + 1, out);
                }
            }
        }
    }

    /// The candidate pairs of a leaf: every edge of its triangles that may cross `cell`,
    /// against every triangle of the leaf with no vertex of the edge whose box overlaps
    /// the edge's box within the cell, gives the pairs of the edge's triangles with that
    /// triangle.
    fn pair(&self, entries: &[u32], cell: Box3, out: &mut Vec<u64>) {
        let overlaps = |a: Box3, b: Box3| a.0.cmple(b.1).all() && b.0.cmple(a.1).all();
        let mut edges: Vec<[u32; 2]> = entries
            .iter()
            .flat_map(|&t| {
                let v = self.triangles[t as usize];
                (0..3).map(move |k| [v[k].min(v[(k + 1) % 3]), v[k].max(v[(k + 1) % 3])])
            })
            .collect();
        edges.sort_unstable();
        edges.dedup();
        let first = out.len();
        for [a, b] in edges {
            if !self.segment_may_cross(a, b, cell) {
                continue;
            }
            // Every edge of a triangle is listed (the triangles not skipped).
            let Ok(k) = self.edges.binary_search(&[a, b]) else { continue };
            let (p, q) = (self.positions[a as usize], self.positions[b as usize]);
            // Where the edge meets a triangle in this cell lies in both boxes and the cell.
            let edge_box = (p.min(q).max(cell.0), p.max(q).min(cell.1));
            let around = &self.adjacent[self.start[k] as usize..self.start[k + 1] as usize];
            for &u in entries {
                let tu = self.triangles[u as usize];
                if tu.contains(&a) || tu.contains(&b) || !overlaps(edge_box, self.boxes[u as usize]) {
                    continue;
                }
                let fu = self.face_of[u as usize];
                for &t in around {
                    if self.face_of[t as usize] != fu {
                        out.push((t.min(u) as u64) << 32 | t.max(u) as u64);
                    }
                }
            }
        }
        // A pair comes once per edge of either triangle that reaches the other: drop the
        // repeats here, where they are few and close, before the global sort.
        out[first..].sort_unstable();
        let mut kept = first;
        for r in first..out.len() {
            if kept == first || out[kept - 1] != out[r] {
                out[kept] = out[r];
                kept += 1;
            }
        }
        out.truncate(kept);
    }
}

/// The direction `d` crossed with each coordinate axis (exactly, from `d`).
fn edge_axes(d: DVec3) -> [DVec3; 3] {
    [DVec3::new(0.0, d.z, -d.y), DVec3::new(-d.z, 0.0, d.x), DVec3::new(d.y, -d.x, 0.0)]
}

/// Along `axis`, which children of `cell` (halved at `mid` along the axes of `split`, as
/// in [`Tree::children_crossed`]; bit c for child c, among those of `mask`) and an object that projects
/// (relative to its point `a`) onto the interval between 0 and `reach` (`reach` =
/// axis · (r − a) for the object's point r with |r − a| = `span`) are apart by more than
/// the rounding can explain, given that each component of `axis` is within a few ulps of
/// its exact value relative to `size` (a bound on its terms). Differences of f64 are
/// correctly rounded, so every error is relative to a term (or an underflowed product,
/// absolutely tiny); overflow never gives "apart".
#[allow(clippy::too_many_arguments)]
#[inline]
fn apart_children(
    axis: DVec3,
    size: DVec3,
    a: DVec3,
    reach: f64,
    span: DVec3,
    (lo, hi): Box3,
    mid: DVec3,
    split: [bool; 3],
    mask: u8,
) -> u8 {
    let (u, m, v) = (lo - a, mid - a, hi - a);
    let (pu, pm, pv) = (axis * u, axis * m, axis * v);
    // Each component's term over the lower (or whole) and the upper half: (min, max).
    let half: [[(f64, f64); 2]; 3] = std::array::from_fn(|k| {
        let low = if split[k] { pm[k] } else { pv[k] };
        [(pu[k].min(low), pu[k].max(low)), (pm[k].min(pv[k]), pm[k].max(pv[k]))]
    });
    let w = u.abs().max(v.abs()).max(span);
    let tol = 1e-12 * (size * w).element_sum() + 1e-300 * (w.element_sum() + 1.0);
    let (below, above) = (reach.min(0.0) - tol, reach.max(0.0) + tol);
    let mut apart = 0u8;
    let mut left = mask;
    while left != 0 {
        let c = left.trailing_zeros() as usize;
        left &= left - 1;
        let [x, y, z] = std::array::from_fn(|k| half[k][c >> k & 1]);
        if x.0 + y.0 + z.0 > above || x.1 + y.1 + z.1 < below {
            apart |= 1 << c;
        }
    }
    apart
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn apart_only_when_strictly_aside() {
        let cell = (DVec3::ZERO, DVec3::ONE);
        let whole = [false; 3];
        let apart = |a: DVec3, reach: f64, span: DVec3| {
            apart_children(DVec3::ONE, DVec3::ONE, a, reach, span, cell, DVec3::splat(0.5), whole, 1) & 1 == 1
        };
        let none = DVec3::ZERO;
        // The plane x + y + z = 3 touches the corner (1, 1, 1): not apart.
        assert!(!apart(DVec3::new(3.0, 0.0, 0.0), 0.0, none));
        assert!(apart(DVec3::new(3.001, 0.0, 0.0), 0.0, none));
        assert!(apart(DVec3::new(-0.001, 0.0, 0.0), 0.0, none));
        assert!(!apart(DVec3::new(1.5, 0.0, 0.0), 0.0, none));
        // An interval reaching back to the box.
        let r = DVec3::new(-1.0, 0.0, 0.0);
        assert!(!apart(DVec3::new(4.0, 0.0, 0.0), DVec3::ONE.dot(r), r.abs()));
        assert!(apart(DVec3::new(4.001, 0.0, 0.0), DVec3::ONE.dot(r), r.abs()));
        // Halved: the plane x + y + z = 1.4 misses the upper octant [0.5, 1]³ only.
        let halves = apart_children(
            DVec3::ONE,
            DVec3::ONE,
            DVec3::new(1.4, 0.0, 0.0),
            0.0,
            none,
            cell,
            DVec3::splat(0.5),
            [true; 3],
            0xff,
        );
        assert_eq!(halves, 1 << 7);
        // Far beyond f64's range the products overflow: no decision.
        let big = DVec3::splat(1e300);
        assert_eq!(apart_children(big, big, big, 0.0, none, cell, DVec3::splat(0.5), [true; 3], 0xff), 0);
    }

    #[test]
    fn triangles_enter_only_cells_they_cross() {
        // One long sliver from the origin to (1, 1, 0) and (1, 0.99, 0).
        let positions = [DVec3::ZERO, DVec3::new(1.0, 1.0, 0.0), DVec3::new(1.0, 0.99, 0.0)];
        let pairs = candidate_pairs(&positions, &[[0, 1, 2]], &[0], &[false]);
        assert!(pairs.is_empty());
        let tree = Tree {
            positions: &positions,
            triangles: &[[0, 1, 2]],
            face_of: &[0],
            n: 1,
            edges: vec![[0, 1]],
            start: vec![0, 1],
            adjacent: vec![0],
            boxes: Vec::new(),
        };
        // The cell [0.4, 0.8] × [0.35, 0.75] × [−0.2, 0.2] (inside the sliver's box),
        // halved: the sliver and its long edge cross every child but the two with x in
        // the upper half and y in the lower (bit 0 set, bit 1 clear).
        let cell = (DVec3::new(0.4, 0.35, -0.2), DVec3::new(0.8, 0.75, 0.2));
        let mid = DVec3::new(0.6, 0.55, 0.0);
        let crossed: u8 = !(1 << 1 | 1 << 5);
        assert_eq!(tree.children_crossed(0, cell, mid, [true; 3], 0xff), crossed);
        assert_eq!(tree.children_crossed(1, cell, mid, [true; 3], 0xff), crossed);
        // Children that only touch its corner (1, 1, 0) stay.
        let corner = (DVec3::new(1.0, 1.0, -0.2), DVec3::new(1.4, 1.4, 0.2));
        let at = 1 | 1 << 4;
        assert_eq!(tree.children_crossed(0, corner, DVec3::new(1.2, 1.2, 0.0), [true; 3], at), at);
    }
}
