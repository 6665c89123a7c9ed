//! One covering tetrahedron (O, Q1, Q2, Q3) prepared for point tests: its four planes as
//! unit normals, its sign, box and octant mask (basic preprocessing, "optimizer 1" of
//! Table 4-1), and the classification of a point against it (the body of Alg. 4-1).
//!
//! Coordinates are relative to the apex O. The faces through O are stored as
//! `s · (Qi × Qj) / |Qi × Qj|`: the two tetras sharing a face through O compute the same
//! cross product with its operands swapped, which IEEE arithmetic negates exactly, so
//! they take the same "on the face" decision bit for bit — the pairing the half
//! contributions of Alg. 4-1 rely on.

use glam::DVec3;

/// Below this sine of the angle Qi O Qj a face through the apex is too thin for its
/// plane to be known within ε (f64 error ≈ 1e-16 / sin), and the tetra counts as flat.
pub const SIN_MIN: f64 = 1e-6;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u8)]
pub enum Kind {
    /// A proper tetra with sign ±1.
    Regular,
    /// Volume ~0 for this apex (apex within ε of the base plane, or nearly collinear with a
    /// base edge): a point in it is ambiguous and goes to a re-run with another apex.
    Flat,
    /// The base triangle itself has no area (smallest height ≤ ε): it contributes nothing
    /// for any apex, but a point near it may be on the boundary.
    Degenerate,
}

/// Where a point lies in a tetra it does not lie outside of.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Contact {
    /// Strictly inside: contributes 2s.
    Interior,
    /// On exactly one face through the apex: s (the face's other tetra gives the other s).
    Side,
    /// On the apex edge O–Q(j) (j = 0, 1, 2 for Q1, Q2, Q3).
    ApexEdge(u8),
    /// On all three faces through the apex: the apex itself.
    Apex,
}

/// Result of testing a point against one tetra.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Verdict {
    Outside,
    /// Inside or on the faces through O, clearly (> ε) on the apex side of the base.
    Contact(Contact),
    /// Within ε of the base plane: the caller must first check the boundary; `inward` is
    /// the signed distance from the base plane, positive on the apex side.
    NearBase {
        contact: Contact,
        inward: f64,
    },
    /// In the box of a flat tetra near its plane.
    Flat,
    /// In the box of a degenerate tetra's base triangle.
    Degenerate,
}

/// Precomputed planes of one covering tetra, relative to the apex.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TetraPlanes {
    /// Inward unit normals of the faces O Q1 Q2, O Q2 Q3, O Q3 Q1 (zero when not regular).
    pub side: [DVec3; 3],
    /// Inward unit normal of the base Q1 Q2 Q3 (for flat tetras: its unsigned normal, or
    /// zero when the whole box is the flat region).
    pub base: DVec3,
    /// `base · Q1`: the inward distance of q from the base plane is `base · q − base_offset`.
    pub base_offset: f64,
    /// Box of the tetra (of the base triangle when degenerate) grown by ε.
    pub lo: DVec3,
    pub hi: DVec3,
    /// Sign of det(Q1, Q2, Q3): +1, −1, or 0 when not regular.
    pub sign: i8,
    pub kind: Kind,
    /// Bit k set when the base triangle's box grown by ε touches octant k (see [`octant_bit`]).
    pub octants: u8,
    /// For a triangle of a planar n-gon: the sign to apply to the face-plane distance to
    /// decide "on the apex side of the base" within ε (0 otherwise: use `inward`).
    pub tie: i8,
}

/// Bit of the octant (around the apex) holding `q`: bit index x≥0 | y≥0 << 1 | z≥0 << 2.
#[inline]
pub fn octant_bit(q: DVec3) -> u8 {
    1 << ((q.x >= 0.0) as u8 | ((q.y >= 0.0) as u8) << 1 | ((q.z >= 0.0) as u8) << 2)
}

/// The octants touched by the box [lo, hi] (relative to the apex).
pub fn octant_mask(lo: DVec3, hi: DVec3) -> u8 {
    let mut mask = 0u8;
    for k in 0..8u8 {
        let side_ok = |axis: usize| if k >> axis & 1 == 1 { hi[axis] >= 0.0 } else { lo[axis] < 0.0 };
        if side_ok(0) && side_ok(1) && side_ok(2) {
            mask |= 1 << k;
        }
    }
    mask
}

impl TetraPlanes {
    /// Prepares the tetra (o, q1, q2, q3) (absolute coordinates). `face_normal` is the unit
    /// normal of the covering triangle's face when that face is a planar n-gon.
    pub fn new(o: DVec3, q: [DVec3; 3], eps: f64, face_normal: Option<DVec3>) -> TetraPlanes {
        let [a, b, c] = q.map(|x| x - o);
        let (tlo, thi) = (a.min(b).min(c), a.max(b).max(c));
        let octants = octant_mask(tlo - eps, thi + eps);
        let mut t = TetraPlanes {
            side: [DVec3::ZERO; 3],
            base: DVec3::ZERO,
            base_offset: 0.0,
            lo: tlo - eps,
            hi: thi + eps,
            sign: 0,
            kind: Kind::Degenerate,
            octants,
            tie: 0,
        };
        let nbase = (b - a).cross(c - a);
        let longest = (b - a).length().max((c - b).length()).max((a - c).length());
        let nb_len = nbase.length();
        if nb_len <= eps * longest {
            return t;
        }
        let nb = nbase / nb_len;
        t.lo = tlo.min(DVec3::ZERO) - eps;
        t.hi = thi.max(DVec3::ZERO) + eps;
        let det = a.dot(b.cross(c));
        let sides = [a.cross(b), b.cross(c), c.cross(a)];
        let spans = [a.length() * b.length(), b.length() * c.length(), c.length() * a.length()];
        let thin = sides.iter().zip(spans).any(|(n, span)| n.length() <= SIN_MIN * span);
        if thin || det.abs() / nb_len <= eps {
            t.kind = Kind::Flat;
            if !thin {
                t.base = nb;
                t.base_offset = nb.dot(a);
            }
            return t;
        }
        let s = if det > 0.0 { 1.0 } else { -1.0 };
        t.kind = Kind::Regular;
        t.sign = s as i8;
        t.side = sides.map(|n| n / n.length() * s);
        t.base = -s * nb;
        t.base_offset = t.base.dot(a);
        if let Some(nf) = face_normal {
            let sigma = nb.dot(nf);
            if sigma != 0.0 {
                t.tie = (-s * sigma.signum()) as i8;
            }
        }
        t
    }

    #[inline]
    fn in_box(&self, q: DVec3) -> bool {
        q.cmpge(self.lo).all() && q.cmple(self.hi).all()
    }

    /// Classifies `q` (relative to the apex, in octant `octant` = [`octant_bit`]) against
    /// this tetra with tolerance `eps` (Alg. 4-1's loop body).
    ///
    /// A tetra reports something other than `Outside` only for points inside its grown box
    /// and octant mask; optimizers rely on this to skip it exactly where this returns
    /// `Outside`, so their sums equal the plain loop's bit for bit.
    #[inline]
    pub fn verdict(&self, q: DVec3, octant: u8, eps: f64) -> Verdict {
        if self.kind != Kind::Regular {
            return self.special_verdict(q, octant, eps);
        }
        // All four planes, then one test: which tetras a point is outside of follows no
        // pattern a branch predictor could learn, so early exits cost more than they save.
        let e0 = self.side[0].dot(q);
        let e1 = self.side[1].dot(q);
        let e2 = self.side[2].dot(q);
        let inward = self.base.dot(q) - self.base_offset;
        if e0.min(e1).min(e2).min(inward) < -eps {
            return Verdict::Outside;
        }
        if !self.in_box(q) || self.octants & octant == 0 {
            return Verdict::Outside;
        }
        let on = (e0 <= eps) as u8 | ((e1 <= eps) as u8) << 1 | ((e2 <= eps) as u8) << 2;
        let contact = match on {
            0 => Contact::Interior,
            1 | 2 | 4 => Contact::Side,
            // Faces 0 and 1 meet at O–Q2, 1 and 2 at O–Q3, 2 and 0 at O–Q1.
            3 => Contact::ApexEdge(1),
            6 => Contact::ApexEdge(2),
            5 => Contact::ApexEdge(0),
            _ => Contact::Apex,
        };
        if inward <= eps { Verdict::NearBase { contact, inward } } else { Verdict::Contact(contact) }
    }

    #[cold]
    fn special_verdict(&self, q: DVec3, octant: u8, eps: f64) -> Verdict {
        if !self.in_box(q) || self.octants & octant == 0 {
            return Verdict::Outside;
        }
        match self.kind {
            Kind::Degenerate => Verdict::Degenerate,
            // A flat tetra lies within ε of its base plane; 2ε covers the rounding.
            _ if (self.base.dot(q) - self.base_offset).abs() <= 2.0 * eps => Verdict::Flat,
            _ => Verdict::Outside,
        }
    }
}

/// Relative error allowance of [`CompactPlanes`]: four f32 roundings of unit normals and
/// coordinates cost < 4e-7 × (|q|₁ + |offset|); 1e-6 leaves a factor 2.5.
const F32_MARGIN: f64 = 1e-6;

/// A tetra's four planes in f32, one cache line: a conservative prefilter for the
/// optimizers, which read tetras in scattered order. It rejects a point only when the f64
/// [`TetraPlanes::verdict`] would say `Outside` too (its margin covers the f32 error), so
/// filtering changes nothing but speed.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(C, align(64))]
pub struct CompactPlanes {
    /// The three inward side normals, then the inward base normal.
    n: [[f32; 3]; 4],
    /// Base offset lowered by its share of the margin.
    offset: f32,
}

/// A point prepared for [`CompactPlanes::rejects`].
#[derive(Clone, Copy, Debug)]
pub struct CompactPoint {
    q: [f32; 3],
    /// −(ε + margin for q): below this a plane value is surely below −ε in f64.
    limit: f32,
}

impl CompactPoint {
    pub fn new(q: DVec3, eps: f64) -> CompactPoint {
        let q1 = q.x.abs() + q.y.abs() + q.z.abs();
        CompactPoint { q: q.as_vec3().to_array(), limit: -(eps + F32_MARGIN * q1) as f32 }
    }
}

impl CompactPlanes {
    /// Regular tetras get their planes; flat and degenerate ones all zeros (never rejected).
    pub fn new(t: &TetraPlanes) -> CompactPlanes {
        if t.kind != Kind::Regular {
            return CompactPlanes::default();
        }
        let f = |v: DVec3| v.as_vec3().to_array();
        CompactPlanes {
            n: [f(t.side[0]), f(t.side[1]), f(t.side[2]), f(t.base)],
            offset: (t.base_offset - F32_MARGIN * t.base_offset.abs()) as f32,
        }
    }

    /// True when `p` is certainly outside the tetra (by more than ε).
    #[inline]
    pub fn rejects(&self, p: &CompactPoint) -> bool {
        let d = |n: &[f32; 3]| n[0] * p.q[0] + n[1] * p.q[1] + n[2] * p.q[2];
        let e = d(&self.n[0]).min(d(&self.n[1])).min(d(&self.n[2])).min(d(&self.n[3]) - self.offset);
        e < p.limit
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const EPS: f64 = 1e-9;

    fn unit() -> TetraPlanes {
        // O at the origin, base x + y + z = 1: a positive tetra.
        TetraPlanes::new(DVec3::ZERO, [DVec3::X, DVec3::Y, DVec3::Z], EPS, None)
    }

    fn v(q: DVec3) -> Verdict {
        unit().verdict(q, octant_bit(q), EPS)
    }

    #[test]
    fn contacts_of_the_unit_tetra() {
        assert_eq!(unit().sign, 1);
        assert_eq!(v(DVec3::splat(0.2)), Verdict::Contact(Contact::Interior));
        assert_eq!(v(DVec3::new(0.2, 0.3, 0.0)), Verdict::Contact(Contact::Side));
        // O–Q1 is the x axis; O–Q3 the z axis.
        assert_eq!(v(DVec3::new(0.5, 0.0, 0.0)), Verdict::Contact(Contact::ApexEdge(0)));
        assert_eq!(v(DVec3::new(0.0, 0.0, 0.5)), Verdict::Contact(Contact::ApexEdge(2)));
        assert_eq!(v(DVec3::ZERO), Verdict::Contact(Contact::Apex));
        assert!(matches!(v(DVec3::splat(1.0 / 3.0)), Verdict::NearBase { contact: Contact::Interior, .. }));
        assert_eq!(v(DVec3::splat(0.4)), Verdict::Outside);
        assert_eq!(v(DVec3::new(-0.1, 0.2, 0.2)), Verdict::Outside);
        // Within ε of a face counts as on it; beyond, not.
        assert_eq!(v(DVec3::new(0.2, 0.3, -0.5 * EPS)), Verdict::Contact(Contact::Side));
        assert_eq!(v(DVec3::new(0.2, 0.3, -2.0 * EPS)), Verdict::Outside);
    }

    #[test]
    fn twins_share_their_face_exactly() {
        let o = DVec3::new(0.1, 0.2, 0.3);
        let (a, b) = (DVec3::new(1.3, 0.7, -0.2), DVec3::new(-0.4, 1.1, 0.9));
        let t1 = TetraPlanes::new(o, [a, b, DVec3::new(0.5, 0.5, 2.0)], EPS, None);
        let t2 = TetraPlanes::new(o, [b, a, DVec3::new(0.5, -2.0, 0.1)], EPS, None);
        assert_eq!(t1.kind, Kind::Regular);
        assert_eq!(t2.kind, Kind::Regular);
        assert_eq!(t1.side[0] * t1.sign as f64, -(t2.side[0] * t2.sign as f64));
    }

    #[test]
    fn flat_and_degenerate() {
        // Apex in the base plane x + y − z = 1, away from the edge lines.
        let f = TetraPlanes::new(DVec3::new(0.8, 0.6, 0.4), [DVec3::X, DVec3::Y, DVec3::ONE], EPS, None);
        assert_eq!(f.kind, Kind::Flat);
        assert_eq!(f.sign, 0);
        let q = DVec3::new(0.1, 0.2, 0.3);
        assert_eq!(f.verdict(q, octant_bit(q), EPS), Verdict::Flat);
        let q = DVec3::new(0.1, 0.2, 0.4);
        assert_eq!(f.verdict(q, octant_bit(q), EPS), Verdict::Outside);
        let d = TetraPlanes::new(DVec3::ZERO, [DVec3::X, DVec3::X * 2.0, DVec3::X * 3.0], EPS, None);
        assert_eq!(d.kind, Kind::Degenerate);
        let q = DVec3::new(1.5, 0.0, 0.0);
        assert_eq!(d.verdict(q, octant_bit(q), EPS), Verdict::Degenerate);
        let q = DVec3::new(0.5, 0.0, 0.0);
        assert_eq!(d.verdict(q, octant_bit(q), EPS), Verdict::Outside);
    }

    #[test]
    fn compact_planes_only_reject_what_the_verdict_rejects() {
        let mut rng = crate::random::Rng::new(4);
        let o = DVec3::new(0.3, -0.2, 0.1);
        for _ in 0..200 {
            let q = [0; 3].map(|_| rng.point_in_box(DVec3::splat(-1.0), DVec3::splat(1.0)));
            let t = TetraPlanes::new(o, q, EPS, None);
            let c = CompactPlanes::new(&t);
            for _ in 0..200 {
                // Points spread out, and points within a few ε of a face.
                let mut p = rng.point_in_box(DVec3::splat(-1.2), DVec3::splat(1.2));
                if rng.below(2) == 0 && t.kind == Kind::Regular {
                    let k = rng.below(3) as usize;
                    p = o + t.side[k] * (t.side[k].dot(o - p) + rng.range_f64(-3.0, 3.0) * EPS) + (p - o);
                }
                let qp = p - o;
                if c.rejects(&CompactPoint::new(qp, EPS)) {
                    assert_eq!(t.verdict(qp, octant_bit(qp), EPS), Verdict::Outside);
                }
            }
        }
        assert_eq!(std::mem::size_of::<CompactPlanes>(), 64);
    }

    #[test]
    fn octant_masks() {
        assert_eq!(octant_mask(DVec3::splat(1.0), DVec3::splat(2.0)), 1 << 7);
        assert_eq!(octant_mask(DVec3::splat(-2.0), DVec3::splat(-1.0)), 1);
        assert_eq!(octant_mask(DVec3::new(-1.0, 1.0, 1.0), DVec3::splat(2.0)), (1 << 7) | (1 << 6));
        assert_eq!(octant_bit(DVec3::new(-1.0, 2.0, 0.0)), 1 << 6);
    }
}
