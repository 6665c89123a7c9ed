//! The hierarchical generalized winding number (Barill et al. 2018, "Fast Winding Numbers
//! for Soups and Clouds") with a certified error bound per point.
//!
//! The covering triangles are grouped in a binary tree of clusters (median splits of their
//! centroids). Seen from a point P far from a cluster, its triangles' solid angles are
//! replaced by a Taylor expansion of the double-layer kernel about the cluster's centre C;
//! near clusters are opened down to their triangles, which are summed exactly
//! (Van Oosterom & Strackee). Every term comes with a bound of its error, so an evaluation
//! returns w̃ and E with |w(P) − w̃| ≤ E.
//!
//! ## The expansion and its truncation error
//!
//! 4π·w(P) = Σ_t ∫_t n_t·k(x − P) dA with k(y) = y/|y|³. With r = C − P, d = |r| and
//! x = C + u, k(r + u) = −∇_u φ(u) for φ(u) = 1/|r + u|, whose Taylor series in u is the
//! Legendre series φ = Σ_l φ_l, φ_l(u) = |u|^l P_l(cos γ) / d^{l+1} (γ the angle between u
//! and −r). Keeping φ_1..φ_3 gives the three terms of order 0, 1, 2 in u that Barill et al.
//! use; with the moments M1 = Σ∫n, M2_ij = Σ∫n_i u_j, M3_ijk = Σ∫n_i u_j u_k (exact for flat
//! triangles: ∫_t u uᵀ = A_t/12 (Σ_v v vᵀ + s sᵀ), v the corners − C, s their sum):
//!
//! - T0 = M1·r / d³
//! - T1 = tr M2 / d³ − 3 rᵀ M2 r / d⁵
//! - T2 = 15/2 · M3[r, r, r] / d⁷ − 3 Σ_k r_k Σ_i M3_iik / d⁵ − 3/2 Σ_i r_i Σ_j M3_ijj / d⁵
//!
//! The rest is −Σ_{l≥4} ∇φ_l. In spherical coordinates about the axis −r, with x = cos γ
//! and |u| = s, |∇φ_l|² = (s^{l−1}/d^{l+1})² (l² P_l(x)² + (1 − x²) P_l'(x)²). The function
//! P_l² + (1 − x²) P_l'² / (l(l+1)) has derivative 2x P_l'² / (l(l+1)) (Legendre's equation),
//! so it is largest at x = ±1, where it is 1; hence |∇φ_l(u)| ≤ √(l(l+1)) s^{l−1}/d^{l+1}
//! ≤ (l + ½) s^{l−1}/d^{l+1}. On a triangle whose corners are within m_t of C, s ≤ m_t, and
//! with ρ the cluster's radius (every corner within ρ of C) s^{l−1} ≤ m_t³ ρ^{l−4}. Summing
//! the series, with q = ρ/d < 1 and B = Σ_t A_t m_t³ (A_t the triangle's area):
//!
//! **|truncation| ≤ B / (4π d⁵) · (q / (1 − q)² + 4.5 / (1 − q))**
//!
//! in units of w (B ≤ A ρ³ for the cluster's area A; a flat disc has B = 0.4 A ρ³). A
//! cluster is used as a whole only when that bound (plus rounding) is at most the
//! evaluation's tolerance per cluster, and only when q ≤ ½.
//!
//! ## Rounding
//!
//! u = 2⁻⁵³. A far-field evaluation adds u·(64 + 4m)·A/(4πd²)·(1 + 4q + 12q²) for a cluster
//! of m triangles: |T0| ≤ A/d², |T1| ≤ 4Aq/d², |T2| ≤ 12Aq²/d², each computed in a few
//! dozen operations, and each moment sums m terms. An exact triangle term: with the corners
//! a, b, c relative to P (rounded differences), N = a·(b×c) and
//! D = |a||b||c| + (a·b)|c| + (b·c)|a| + (c·a)|b| are each within 64u·|a||b||c| of their
//! values for the exact differences (N's six products are bounded by the 1-norms,
//! ≤ 3√3 |a||b||c|; D's four terms by |a||b||c|); Ω = 2 atan2(N, D) then moves by at most
//! π·e / (R − e) with e = 128u·|a||b||c| and R ≤ |(N, D)| (the angle between two vectors
//! whose ends are e apart, one of length ≥ R − e), plus the rounding of atan2. When R ≤ 2e,
//! or (N, D) is within e of atan2's cut (N = 0, D < 0: the point is a hair from the
//! triangle itself), the triangle's term is not known (bound 1 in units of w).
//! Sums of k terms add k·u·Σ|term|; the direct evaluation sums with Neumaier's compensated
//! summation (error ≤ 2u|S| + 4k·u²·Σ|term|).

use std::f64::consts::PI;

use glam::DVec3;

use crate::mesh::covering::Covering;

/// Unit roundoff of f64.
const U: f64 = f64::EPSILON * 0.5;
/// Triangles per leaf cluster.
const LEAF: usize = 8;
/// Clusters are expanded only when q = ρ/d is at most this.
const MAX_Q: f64 = 0.5;
const FOUR_PI: f64 = 4.0 * PI;
/// Below this many triangles a subtree is built on the calling thread.
const PARALLEL_BUILD: usize = 4096;

/// A winding number and a bound of its error: |w(P) − w| ≤ err.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Estimate {
    pub w: f64,
    pub err: f64,
}

impl Estimate {
    /// Whether the estimate decides w ≥ ½ (with `margin` to spare): `Some(inside)`.
    pub fn decides(&self, margin: f64) -> Option<bool> {
        if self.w - self.err >= 0.5 + margin {
            Some(true)
        } else if self.w + self.err < 0.5 - margin {
            Some(false)
        } else {
            None
        }
    }
}

/// One cluster: bounds, expansion centre and radius, unsigned area and moments.
#[derive(Clone, Debug)]
struct Node {
    lo: DVec3,
    hi: DVec3,
    centre: DVec3,
    radius: f64,
    area: f64,
    /// B = Σ_t A_t m_t³ of the truncation bound.
    b3: f64,
    /// Number of triangles (for the rounding bound).
    count: u32,
    m1: DVec3,
    /// M2_ij, row-major.
    m2: [f64; 9],
    /// M3_i(jk) for jk in xx, yy, zz, xy, xz, yz, i-major.
    m3: [f64; 18],
    /// Triangles `first..first + count` of the tree's order when a leaf.
    first: u32,
    /// Children (`u32::MAX` for a leaf).
    left: u32,
    right: u32,
}

/// The cluster tree of a covering, ready for evaluations from any thread.
#[derive(Clone, Debug)]
pub struct Tree {
    nodes: Vec<Node>,
    /// Triangle corners in leaf order.
    tris: Vec<[DVec3; 3]>,
    /// The covering triangle of each entry of `tris`.
    index: Vec<u32>,
}

/// Per triangle while building: corners, centroid, vector area.
#[derive(Clone, Copy)]
struct Item {
    corners: [DVec3; 3],
    centroid: DVec3,
    area: DVec3,
    index: u32,
}

impl Tree {
    /// Builds the tree of the covering's triangles (in parallel above a few thousand).
    pub fn new(covering: &Covering) -> Tree {
        Tree::from_triangles((0..covering.triangles.len()).map(|t| covering.triangle(t)))
    }

    /// The tree of `triangles` (indices in the order given).
    pub fn from_triangles(triangles: impl Iterator<Item = [DVec3; 3]>) -> Tree {
        let mut items: Vec<Item> = triangles
            .enumerate()
            .map(|(t, [a, b, c])| Item {
                corners: [a, b, c],
                centroid: (a + b + c) / 3.0,
                area: 0.5 * (b - a).cross(c - a),
                index: t as u32,
            })
            .collect();
        let mut nodes = Vec::new();
        if !items.is_empty() {
            nodes = build(&mut items, 0);
        }
        let tris = items.iter().map(|i| i.corners).collect();
        let index = items.iter().map(|i| i.index).collect();
        Tree { nodes, tris, index }
    }

    /// Heap bytes held.
    pub fn bytes(&self) -> usize {
        self.nodes.capacity() * std::mem::size_of::<Node>()
            + self.tris.capacity() * std::mem::size_of::<[DVec3; 3]>()
            + self.index.capacity() * 4
    }

    /// Number of triangles.
    pub fn len(&self) -> usize {
        self.tris.len()
    }

    pub fn is_empty(&self) -> bool {
        self.tris.is_empty()
    }

    /// The covering triangles (their indices) whose bounding box grown by `grow` holds a
    /// point of the box `lo..hi`, passed to `f` until it returns true; true if it did.
    pub fn any_near(&self, lo: DVec3, hi: DVec3, grow: f64, mut f: impl FnMut(usize) -> bool) -> bool {
        let (lo, hi) = (lo - grow, hi + grow);
        let overlaps = |a: DVec3, b: DVec3| a.cmple(hi).all() && b.cmpge(lo).all();
        let mut stack = Stack::new();
        if self.nodes.is_empty() {
            return false;
        }
        stack.push(0);
        while let Some(i) = stack.pop() {
            let n = &self.nodes[i as usize];
            if !overlaps(n.lo, n.hi) {
                continue;
            }
            if n.left == u32::MAX {
                for t in n.first as usize..(n.first + n.count) as usize {
                    let [a, b, c] = self.tris[t];
                    if overlaps(a.min(b).min(c), a.max(b).max(c)) && f(self.index[t] as usize) {
                        return true;
                    }
                }
            } else {
                stack.push(n.left);
                stack.push(n.right);
            }
        }
        false
    }

    /// Whether some triangle may meet the box `lo..hi` (conservative: false means none
    /// does). Boxes of triangles first, then the triangle's plane against the box.
    pub fn may_meet_box(&self, lo: DVec3, hi: DVec3) -> bool {
        let (c, half) = ((lo + hi) * 0.5, (hi - lo) * 0.5);
        let mut hit = false;
        let (nodes, tris) = (&self.nodes, &self.tris);
        let mut stack = Stack::new();
        if nodes.is_empty() {
            return false;
        }
        stack.push(0);
        let overlaps = |a: DVec3, b: DVec3| a.cmple(hi).all() && b.cmpge(lo).all();
        while let Some(i) = stack.pop() {
            let n = &nodes[i as usize];
            if !overlaps(n.lo, n.hi) {
                continue;
            }
            if n.left != u32::MAX {
                stack.push(n.left);
                stack.push(n.right);
                continue;
            }
            for &[a, b, cc] in &tris[n.first as usize..(n.first + n.count) as usize] {
                if !overlaps(a.min(b).min(cc), a.max(b).max(cc)) {
                    continue;
                }
                let nrm = (b - a).cross(cc - a);
                let s = nrm.dot(c - a).abs();
                let reach = nrm.abs().dot(half);
                // Generous slack for the rounding of both sides: only ever says "may meet".
                let slack = 1e-9 * (nrm.abs().dot((c - a).abs()) + reach);
                if s <= reach + slack {
                    hit = true;
                    break;
                }
            }
            if hit {
                break;
            }
        }
        hit
    }

    /// w(P) with a certified bound: clusters whose error bound is at most `tol` are taken
    /// as their expansion, the others opened, leaves summed exactly.
    pub fn winding(&self, p: DVec3, tol: f64) -> Estimate {
        let (mut w, mut err, mut abs, mut terms) = (0.0, 0.0, 0.0, 0usize);
        let mut stack = Stack::new();
        if self.nodes.is_empty() {
            return Estimate::default();
        }
        stack.push(0);
        while let Some(i) = stack.pop() {
            let n = &self.nodes[i as usize];
            let r = n.centre - p;
            let d2 = r.length_squared();
            if d2 > 4.0 * n.radius * n.radius {
                let d = d2.sqrt();
                if let Some(bound) = far_bound(n, d) {
                    if bound <= tol {
                        let t = far_field(n, r, d);
                        w += t;
                        abs += t.abs();
                        err += bound;
                        terms += 1;
                        continue;
                    }
                }
            }
            if n.left == u32::MAX {
                for t in n.first as usize..(n.first + n.count) as usize {
                    let [a, b, c] = self.tris[t];
                    let (omega, e) = solid_angle_bounded(a - p, b - p, c - p);
                    w += omega / FOUR_PI;
                    abs += (omega / FOUR_PI).abs();
                    err += e;
                    terms += 1;
                }
            } else {
                stack.push(n.left);
                stack.push(n.right);
            }
        }
        Estimate { w, err: err + (terms as f64 + 2.0) * U * abs }
    }

    /// w(P) summed over every triangle exactly, with compensated (Neumaier) summation.
    pub fn direct(&self, p: DVec3) -> Estimate {
        let (mut sum, mut comp, mut abs, mut err) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
        for &[a, b, c] in &self.tris {
            let (omega, e) = solid_angle_bounded(a - p, b - p, c - p);
            let x = omega / FOUR_PI;
            let t = sum + x;
            comp += if sum.abs() >= x.abs() { (sum - t) + x } else { (x - t) + sum };
            sum = t;
            abs += x.abs();
            err += e;
        }
        let w = sum + comp;
        let k = self.tris.len() as f64;
        Estimate { w, err: err + 2.0 * U * w.abs() + 4.0 * k * U * U * abs + 4.0 * U * err }
    }
}

/// Builds the subtree of `items` (reordered in place) with node indices from `base`.
fn build(items: &mut [Item], base: u32) -> Vec<Node> {
    let mut node = cluster(items);
    if items.len() <= LEAF {
        node.first = 0;
        return vec![node];
    }
    let (clo, chi) = items
        .iter()
        .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(l, h), i| (l.min(i.centroid), h.max(i.centroid)));
    let e = chi - clo;
    let axis = if e.x >= e.y && e.x >= e.z {
        0
    } else if e.y >= e.z {
        1
    } else {
        2
    };
    let mid = items.len() / 2;
    let parallel = items.len() > PARALLEL_BUILD;
    items.select_nth_unstable_by(mid, |a, b| a.centroid[axis].total_cmp(&b.centroid[axis]));
    let (l, r) = items.split_at_mut(mid);
    let (left, right) = if parallel {
        rayon::join(|| build(l, base + 1), || build(r, 0))
    } else {
        (build(l, base + 1), build(r, 0))
    };
    let right_base = base + 1 + left.len() as u32;
    node.left = base + 1;
    node.right = right_base;
    let mut out = Vec::with_capacity(1 + left.len() + right.len());
    out.push(node);
    out.extend(left);
    // The right subtree was numbered from 0: shift its links (and its leaves' triangles).
    let shift_tris = mid as u32;
    out.extend(right.into_iter().map(|mut n| {
        if n.left != u32::MAX {
            n.left += right_base;
            n.right += right_base;
        }
        n.first += shift_tris;
        n
    }));
    // The left subtree's leaves are already relative to this node's first triangle.
    out
}

/// The cluster of `items`: bounds, centre, radius, area and moments (`first` relative to
/// the start of `items`, fixed up by the caller).
fn cluster(items: &[Item]) -> Node {
    let (mut lo, mut hi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
    let (mut area, mut weighted) = (0.0, DVec3::ZERO);
    for i in items {
        for v in i.corners {
            lo = lo.min(v);
            hi = hi.max(v);
        }
        let a = i.area.length();
        area += a;
        weighted += a * i.centroid;
    }
    let centre = if area > 0.0 && (weighted / area).is_finite() { weighted / area } else { (lo + hi) * 0.5 };
    let radius2 =
        items.iter().flat_map(|i| i.corners).map(|v| (v - centre).length_squared()).fold(0.0, f64::max);
    // Every corner within ρ of C, with room for the rounding of the distances.
    let radius = radius2.sqrt() * (1.0 + 8.0 * U);
    let (mut m1, mut m2, mut m3) = (DVec3::ZERO, [0.0; 9], [0.0; 18]);
    let b3 = items
        .iter()
        .map(|i| {
            let m2 = i.corners.iter().map(|&v| (v - centre).length_squared()).fold(0.0, f64::max);
            let m = m2.sqrt() * (1.0 + 8.0 * U);
            i.area.length() * m * m * m
        })
        .sum::<f64>()
        * (1.0 + 4.0 * U * items.len() as f64);
    for it in items {
        let n = it.area;
        m1 += n;
        let g = it.centroid - centre;
        for i in 0..3 {
            for j in 0..3 {
                m2[3 * i + j] += n[i] * g[j];
            }
        }
        let [a, b, c] = it.corners.map(|v| v - centre);
        let s = a + b + c;
        let second = |j: usize, k: usize| (a[j] * a[k] + b[j] * b[k] + c[j] * c[k] + s[j] * s[k]) / 12.0;
        let sym = [second(0, 0), second(1, 1), second(2, 2), second(0, 1), second(0, 2), second(1, 2)];
        for i in 0..3 {
            for (jk, v) in sym.iter().enumerate() {
                m3[6 * i + jk] += n[i] * v;
            }
        }
    }
    Node {
        lo,
        hi,
        centre,
        radius,
        area,
        b3,
        count: items.len() as u32,
        m1,
        m2,
        m3,
        first: 0,
        left: u32::MAX,
        right: u32::MAX,
    }
}

/// The bound of a cluster's expansion error (truncation + rounding) seen from distance
/// `d` of its centre, in units of w; `None` when q = ρ/d is over [`MAX_Q`].
#[inline]
fn far_bound(n: &Node, d: f64) -> Option<f64> {
    // A lower bound of the true distance (d is rounded).
    let d = d * (1.0 - 4.0 * U);
    let q = n.radius / d;
    if q > MAX_Q {
        return None;
    }
    let scale = n.area / (FOUR_PI * d * d);
    let one_q = 1.0 - q;
    let d5 = d * d * d * d * d;
    let truncation = n.b3 / (FOUR_PI * d5) * (q / (one_q * one_q) + 4.5 / one_q);
    let rounding = scale * U * (64.0 + 4.0 * n.count as f64) * (1.0 + 4.0 * q + 12.0 * q * q);
    // The bound itself is computed in f64: a relative margin covers it.
    Some((truncation + rounding) * (1.0 + 32.0 * U))
}

/// T0 + T1 + T2 of the module docs, divided by 4π.
#[inline]
fn far_field(n: &Node, r: DVec3, d: f64) -> f64 {
    let d2 = d * d;
    let inv3 = 1.0 / (d2 * d);
    let inv5 = inv3 / d2;
    let inv7 = inv5 / d2;
    let t0 = n.m1.dot(r) * inv3;
    let m2 = &n.m2;
    let tr = m2[0] + m2[4] + m2[8];
    let m2r = DVec3::new(
        m2[0] * r.x + m2[1] * r.y + m2[2] * r.z,
        m2[3] * r.x + m2[4] * r.y + m2[5] * r.z,
        m2[6] * r.x + m2[7] * r.y + m2[8] * r.z,
    );
    let t1 = tr * inv3 - 3.0 * r.dot(m2r) * inv5;
    let m3 = &n.m3;
    // Per i: the symmetric matrix S_i = M3_i.. as (xx, yy, zz, xy, xz, yz).
    let quad = |s: &[f64]| {
        s[0] * r.x * r.x
            + s[1] * r.y * r.y
            + s[2] * r.z * r.z
            + 2.0 * (s[3] * r.x * r.y + s[4] * r.x * r.z + s[5] * r.y * r.z)
    };
    let (sx, sy, sz) = (&m3[0..6], &m3[6..12], &m3[12..18]);
    let cubic = r.x * quad(sx) + r.y * quad(sy) + r.z * quad(sz);
    // Σ_k r_k Σ_i M3_iik: row i of S_i, dotted with r.
    let row = |s: &[f64], i: usize| match i {
        0 => DVec3::new(s[0], s[3], s[4]),
        1 => DVec3::new(s[3], s[1], s[5]),
        _ => DVec3::new(s[4], s[5], s[2]),
    };
    let contracted = (row(sx, 0) + row(sy, 1) + row(sz, 2)).dot(r);
    let traces = DVec3::new(sx[0] + sx[1] + sx[2], sy[0] + sy[1] + sy[2], sz[0] + sz[1] + sz[2]).dot(r);
    let t2 = 7.5 * cubic * inv7 - 3.0 * contracted * inv5 - 1.5 * traces * inv5;
    (t0 + t1 + t2) / FOUR_PI
}

/// Signed solid angle of the triangle with corners `a, b, c` relative to the viewer (as
/// [`crate::mesh::covering::solid_angle`]) and a bound of its error in units of w
/// (module docs; 1 when it cannot be bounded).
#[inline]
pub fn solid_angle_bounded(a: DVec3, b: DVec3, c: DVec3) -> (f64, f64) {
    let (la, lb, lc) = (a.length(), b.length(), c.length());
    let prod = la * lb * lc;
    let num = a.dot(b.cross(c));
    let den = prod + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb;
    let omega = 2.0 * num.atan2(den);
    let e = 128.0 * U * prod;
    // A lower bound of |(num, den)|, without the cost of hypot.
    let r = num.abs().max(den.abs()) * (1.0 - 4.0 * U);
    // Within e of atan2's cut (num = 0, den < 0) the angle may be off by 2π: unknown.
    let cut = num.abs() <= e && den < e;
    let err = if r > 2.0 * e && !cut { (PI * e / (r - e) + 16.0 * U) / FOUR_PI } else { 1.0 };
    (omega, err)
}

/// A fixed stack for tree walks (depth ≤ log₂ of the triangles, two entries per level).
struct Stack {
    items: [u32; 128],
    len: usize,
}

impl Stack {
    fn new() -> Stack {
        Stack { items: [0; 128], len: 0 }
    }

    #[inline]
    fn push(&mut self, i: u32) {
        self.items[self.len] = i;
        self.len += 1;
    }

    #[inline]
    fn pop(&mut self) -> Option<u32> {
        self.len = self.len.checked_sub(1)?;
        Some(self.items[self.len])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::procedural;
    use crate::random::Rng;

    #[test]
    fn far_field_matches_direct_sums_within_the_bound() {
        let mesh = procedural::by_name("torus").unwrap();
        let tree = Tree::new(&Covering::new(&mesh));
        let mut rng = Rng::new(9);
        for _ in 0..500 {
            let p = rng.point_in_box(DVec3::splat(-3.0), DVec3::splat(3.0));
            let exact = tree.direct(p);
            for tol in [1e-2, 1e-4, 1e-7] {
                let e = tree.winding(p, tol);
                assert!((e.w - exact.w).abs() <= e.err + exact.err, "{p} {tol}: {e:?} vs {exact:?}");
            }
        }
    }
}
