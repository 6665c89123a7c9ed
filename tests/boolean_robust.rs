//! Robustness of the refinement (SPEC §6.4) where the two surfaces are nearly degenerate
//! to each other: intersection points closer than rounding (kept exact, as implicit
//! points), exactly coplanar faces, copies turned by tiny angles, random placements of
//! the built-in solids. Every regularized result must be closed and consistently oriented,
//! and the volumes must satisfy vol(A∪B) + vol(A∩B) = vol(A) + vol(B) and
//! vol(A−B) = vol(A) − vol(A∩B).

mod common;

use common::{moved, volume};
use glam::{DAffine3, DVec3};
use texgeo::boolean::{self, Evaluation, Names, Operation, Options, Transform, cgal};
use texgeo::inclusion::Method;
use texgeo::mesh::frame::Frame;
use texgeo::mesh::{Mesh, procedural};
use texgeo::random::Rng;
use texgeo::report::bench::boolean::turned_copy;

const REL: f64 = 1e-9;

/// All four operations closed and oriented, the volume identities; returns the evaluation
/// and the volumes of ∪, ∩, −, ⊖.
fn check(name: &str, a: &Mesh, b: &Mesh) -> (Evaluation, [f64; 4]) {
    let options = Options { method: Method::Bvh.into(), ..Options::default() };
    let ev =
        boolean::evaluate(a, b, Names::default(), &options, None).unwrap_or_else(|e| panic!("{name}: {e}"));
    let mut v = [0.0; 4];
    for (k, op) in Operation::ALL.into_iter().enumerate() {
        let r = ev.result(op, true).unwrap_or_else(|e| panic!("{name} {op}: {e}"));
        let report = r.report();
        assert!(report.is_closed(), "{name} {op}: {report}");
        v[k] = volume(&r);
    }
    let [vu, vi, vd, vs] = v;
    let (va, vb) = (volume(a), volume(b));
    let scale = va.max(vb);
    assert!((vu + vi - va - vb).abs() <= REL * scale, "{name}: {vu} + {vi} vs {va} + {vb}");
    assert!((vd - (va - vi)).abs() <= REL * scale, "{name}: A−B {vd} vs {va} − {vi}");
    assert!((vs - (vu - vi)).abs() <= REL * scale, "{name}: A⊖B {vs} vs {vu} − {vi}");
    assert!(vi >= -REL * scale && vd >= -REL * scale, "{name}: {v:?}");
    (ev, v)
}

/// The smallest sphere of `texgeo bench boolean --scaling` (1 000 triangles): its turned
/// copy's rings lie in the planes of its own rings, and a ring edge of the copy passes
/// within an ulp of a vertex, so several exactly distinct intersection points round to
/// (almost) the same place. Rounded, its cut triangles could not be re-triangulated
/// (constraints crossed); kept implicit, every order and side among them is exact.
#[test]
fn sphere_and_turned_copy_with_points_closer_than_rounding() {
    let a = procedural::sphere(11, 22);
    let b = turned_copy(&a).unwrap();
    let (ev, v) = check("sphere 11×22", &a, &b);
    assert!(ev.refinement.stats.exact_signs > 0, "{:?}", ev.refinement.stats);
    // Its quads facing ±y and those of the copy (turned about y) lie in one plane up to a
    // few ulps: exactly, the difference keeps a sliver between them thinner than f64 can
    // hold, which the output removes whole. Every result passes the full operand checks.
    let out = ev.output(Operation::Difference, true).unwrap_or_else(|e| panic!("{e}"));
    assert!(out.repair.pockets > 0, "{}", out.repair);
    for op in Operation::ALL {
        let r = ev.result(op, true).unwrap();
        let frame = Frame::of(&[&r]);
        boolean::input::check(&frame.mesh_in_ref(&r), frame, false).unwrap_or_else(|e| panic!("{op}: {e}"));
    }
    // The exact reference agrees (CGAL's exact kernel has no rounding to merge).
    let reference = cgal::reference(&a, &b, None).unwrap();
    for (k, op) in Operation::ALL.into_iter().enumerate() {
        if let Some((cv, _)) = reference.measures(op) {
            assert!((v[k] - cv).abs() <= REL * volume(&a), "{op}: {} vs CGAL {cv}", v[k]);
        }
    }
}

/// Copies turned by angles from 1e-9 rad up, about a skew axis through the origin (so
/// every vertex moves by about the angle: points of A and B a hair apart everywhere).
#[test]
fn copies_turned_by_tiny_angles() {
    let axis = DVec3::new(1.0, 2.0, 3.0).normalize();
    for (name, m) in [("cube", procedural::cube()), ("sphere", procedural::sphere(6, 12))] {
        for angle in [1e-9, 1e-7, 1e-5, 1e-3] {
            let b = moved(&m, DAffine3::from_axis_angle(axis, angle));
            check(&format!("{name} turned {angle:e} rad"), &m, &b);
        }
    }
}

/// Random rotations and translations of the built-in solids against each other and
/// against themselves; a third of the angles tiny.
#[test]
fn random_placements_of_builtin_solids() {
    let solids: Vec<(&str, Mesh)> = vec![
        ("cube", procedural::cube()),
        ("tetrahedron", procedural::tetrahedron()),
        ("pyramid", procedural::pyramid()),
        ("sphere", procedural::sphere(6, 12)),
        ("torus", procedural::torus(1.0, 0.4, 12, 8)),
        ("l-prism", procedural::l_prism()),
        ("star", procedural::star_prism()),
    ];
    let mut rng = Rng::new(2006);
    for trial in 0..40 {
        let (na, a) = &solids[rng.below(solids.len() as u64) as usize];
        let (nb, b) = &solids[rng.below(solids.len() as u64) as usize];
        let axis = DVec3::new(rng.range_f64(-1.0, 1.0), rng.range_f64(-1.0, 1.0), rng.range_f64(-1.0, 1.0));
        let axis = if axis.length() < 1e-3 { DVec3::Z } else { axis.normalize() };
        let angle = if trial % 3 == 0 {
            10f64.powf(rng.range_f64(-9.0, -3.0))
        } else {
            rng.range_f64(0.0, std::f64::consts::PI)
        };
        let (lo, hi) = a.bounds();
        let shift = if trial % 4 == 0 {
            DVec3::ZERO
        } else {
            DVec3::new(rng.range_f64(-0.3, 0.3), rng.range_f64(-0.3, 0.3), rng.range_f64(-0.3, 0.3))
                * (hi - lo)
        };
        let t = DAffine3::from_translation(shift) * DAffine3::from_axis_angle(axis, angle);
        check(
            &format!("trial {trial}: {na} vs {nb} turned {angle:e} about {axis}, moved {shift}"),
            a,
            &moved(b, t),
        );
    }
}

/// An operand with faces whose corners are not in one plane enters as the same surface
/// `mesh stats` measures (each such face the fan from its centroid): united with a cube
/// far away, the result's volume is the sum of the two.
#[test]
fn non_planar_faces_keep_their_volume() {
    let bent = procedural::bent_box();
    let far = procedural::box_between(DVec3::splat(10.0), DVec3::splat(11.0));
    let (_, [vu, vi, vd, _]) = check("bent box and a far cube", &bent, &far);
    let va = volume(&bent);
    assert!((vu - (va + 1.0)).abs() <= 1e-15 * vu, "{vu} vs {va} + 1");
    assert!((vd - va).abs() <= 1e-15 * va, "{vd} vs {va}");
    assert_eq!(vi, 0.0);
}

/// Exact 90° turn about z: (x, y, z) → (−y, x, z), no rounding (the faces of the copy lie
/// exactly in the planes of the original's, their diagonals the other way).
fn quarter_turn(m: &Mesh) -> Mesh {
    m.map_positions(|p| DVec3::new(-p.y, p.x, p.z)).unwrap()
}

/// The full operand check every input gets (closed, oriented, no crossing faces once
/// read as f64, positive volume): a result must pass it to be used again.
fn assert_operand(name: &str, r: &Mesh) {
    if r.num_faces() == 0 {
        return;
    }
    let frame = Frame::of(&[r]);
    boolean::input::check(&frame.mesh_in_ref(r), frame, false).unwrap_or_else(|e| panic!("{name}: {e}"));
}

/// [`check`], every result a valid operand, and the volumes equal CGAL's where it answers.
fn check_exact(name: &str, a: &Mesh, b: &Mesh, with_cgal: bool) -> (Evaluation, [f64; 4]) {
    let (ev, v) = check(name, a, b);
    for op in Operation::ALL {
        assert_operand(&format!("{name} {op}"), &ev.result(op, true).unwrap());
    }
    if with_cgal {
        let reference = cgal::reference(a, b, None).unwrap_or_else(|e| panic!("{name}: {e}"));
        for (k, op) in Operation::ALL.into_iter().enumerate() {
            if let Some((cv, _)) = reference.measures(op) {
                assert!(
                    (v[k] - cv).abs() <= REL * volume(a).max(volume(b)),
                    "{name} {op}: {} vs CGAL {cv}",
                    v[k]
                );
            }
        }
    }
    (ev, v)
}

/// An exact 90° copy shares every face plane with the original: the coplanar overlaps
/// are resolved exactly in 2-D, and every piece is on-same (or on-opposite) with no
/// tolerance.
#[test]
fn cube_against_its_exact_quarter_turn() {
    let a = procedural::cube();
    let (ev, [vu, vi, vd, _]) = check_exact("cube", &a, &quarter_turn(&a), true);
    let v = volume(&a);
    assert!((vu - v).abs() <= REL * v && (vi - v).abs() <= REL * v && vd == 0.0, "{vu} {vi} {vd}");
    assert!(ev.refinement.stats.coplanar_pairs > 0);
}

#[test]
fn star_prism_against_its_exact_quarter_turn() {
    let a = procedural::star_prism();
    check_exact("star prism", &a, &quarter_turn(&a), true);
}

#[test]
fn l_prism_against_its_exact_quarter_turn() {
    let a = procedural::l_prism();
    check_exact("l-prism", &a, &quarter_turn(&a), true);
}

#[test]
fn copies_turned_by_1e_9_1e_6_and_1e_3_degrees() {
    let axis = DVec3::new(1.0, 2.0, 3.0).normalize();
    for (name, m) in [("cube", procedural::cube()), ("star prism", procedural::star_prism())] {
        for degrees in [1e-9f64, 1e-6, 1e-3] {
            let b = moved(&m, DAffine3::from_axis_angle(axis, degrees.to_radians()));
            check_exact(&format!("{name} turned {degrees:e}°"), &m, &b, false);
        }
    }
}

/// A ∪ A = A, A ∩ A = A, A − A = ∅ (written as a mesh without faces).
#[test]
fn a_solid_with_itself() {
    for (name, m) in [("star prism", procedural::star_prism()), ("sphere", procedural::sphere(6, 12))] {
        let (ev, [vu, vi, vd, vs]) = check_exact(name, &m, &m, false);
        let v = volume(&m);
        assert!((vu - v).abs() <= REL * v && (vi - v).abs() <= REL * v, "{name}: {vu} {vi}");
        assert_eq!((vd, vs), (0.0, 0.0), "{name}");
        assert_eq!(ev.result(Operation::Difference, true).unwrap().num_faces(), 0, "{name}");
    }
}

#[test]
fn cubes_sharing_a_face_an_edge_a_vertex() {
    let a = procedural::box_between(DVec3::ZERO, DVec3::ONE);
    for (name, lo) in [("face", DVec3::X), ("edge", DVec3::new(1.0, 1.0, 0.0)), ("vertex", DVec3::ONE)] {
        let b = procedural::box_between(lo, lo + DVec3::ONE);
        let (_, [vu, vi, vd, _]) = check_exact(&format!("cubes sharing a {name}"), &a, &b, false);
        assert_eq!((vu, vi, vd), (2.0, 0.0, 1.0), "{name}");
    }
}

/// A box standing in a bigger one with their tops in one plane, and a third box on top.
#[test]
fn stacked_boxes_with_coplanar_tops() {
    let base = procedural::box_between(DVec3::ZERO, DVec3::new(2.0, 2.0, 1.0));
    let inner = procedural::box_between(DVec3::new(0.5, 0.5, 0.25), DVec3::new(1.5, 1.5, 1.0));
    check_exact("box in a box, tops coplanar", &base, &inner, true);
    let top = procedural::box_between(DVec3::new(0.5, 0.5, 1.0), DVec3::new(1.5, 1.5, 2.0));
    let (_, [vu, vi, vd, _]) = check_exact("box on a box", &base, &top, true);
    assert_eq!((vu, vi, vd), (5.0, 0.0, 4.0));
}

/// A cube with a pyramid on each face (the corpus' star: 14 vertices, 24 triangles).
fn spiked_cube() -> Mesh {
    let h = 0.125;
    let mut positions: Vec<DVec3> = [(-h, -h), (-h, h), (h, h), (h, -h)]
        .iter()
        .map(|&(x, y)| DVec3::new(x, y, -h))
        .chain([(-h, -h), (-h, h), (h, h), (h, -h)].iter().map(|&(x, y)| DVec3::new(x, y, h)))
        .collect();
    positions
        .extend([DVec3::X, DVec3::Y, DVec3::NEG_X, DVec3::NEG_Y, DVec3::Z, DVec3::NEG_Z].map(|p| 0.5 * p));
    let faces = [
        [0, 1, 13],
        [1, 2, 13],
        [2, 3, 13],
        [3, 0, 13],
        [3, 2, 8],
        [7, 3, 8],
        [6, 7, 8],
        [2, 6, 8],
        [7, 6, 12],
        [4, 7, 12],
        [5, 4, 12],
        [6, 5, 12],
        [4, 5, 10],
        [5, 1, 10],
        [1, 0, 10],
        [0, 4, 10],
        [5, 6, 9],
        [6, 2, 9],
        [2, 1, 9],
        [1, 5, 9],
        [7, 4, 11],
        [3, 7, 11],
        [0, 3, 11],
        [4, 0, 11],
    ];
    Mesh::new(positions, faces.iter().map(|f| f.to_vec()).collect()).unwrap()
}

/// Mirrored in x and turned 30° about z in floating point: the copy's spikes along ±z
/// keep the apexes, and an edge of one spike passes within an ulp of the other's, so
/// exactly distinct intersection points on the two faces at that edge round to one point
/// and their sub-ulp slivers to one triangle twice, oppositely oriented.
#[test]
fn spiked_cube_against_its_mirror_image_turned_30_degrees() {
    let a = spiked_cube();
    let (s, c) = 30f64.to_radians().sin_cos();
    let positions = a
        .positions()
        .iter()
        .map(|p| {
            let x = 0.0 - p.x;
            DVec3::new(x * c + p.y * -s, x * s + p.y * c, p.z)
        })
        .collect();
    let faces = (0..a.num_faces()).map(|f| a.face(f).iter().rev().copied().collect()).collect();
    let b = Mesh::new(positions, faces).unwrap();
    check_exact("spiked cube, mirrored and turned 30°", &a, &b, true);
}

/// A sphere against its copy turned by an exact quarter about z: the turned vertices are
/// those of the sphere up to an ulp (cos and sin rounded), so the difference is slivers
/// thinner than f64 between faces a few ulps apart; snapped together they cancel.
#[test]
fn sphere_against_its_exact_quarter_turn() {
    let a = procedural::sphere(16, 32);
    let (_, [vu, vi, vd, vs]) = check_exact("sphere 16×32", &a, &quarter_turn(&a), false);
    let v = volume(&a);
    assert!((vu - v).abs() <= REL * v && (vi - v).abs() <= REL * v, "{vu} {vi}");
    assert!(vd <= REL * v && vs <= REL * v, "{vd} {vs}");
}

/// S = A − B, then S against B and against A, every operation: each result must be a
/// valid operand (the full check, as when its file is read back) and the volumes must add
/// up. S's corners that were intersection points are now input vertices within an ulp of
/// B's faces and edges, and S carries B's faces reversed with those corners among theirs.
fn reuse_difference(name: &str, a: &Mesh, b: &Mesh) {
    let (ev, _) = check_exact(&format!("{name}: A − B"), a, b, false);
    let s = ev.result(Operation::Difference, true).unwrap();
    assert!(volume(&s) > 0.0, "{name}: {}", volume(&s));
    check_exact(&format!("{name}: (A − B) against B"), &s, b, false);
    check_exact(&format!("{name}: (A − B) against A"), &s, a, false);
}

/// A thin result used again against the solids that made it: the star prism minus its
/// copy turned 1e-6° about a skew axis through its centre (as `--transform-b` turns it)
/// is slivers, whose faces meet B's at creases of ~1e-8 rad and whose corners lie a few
/// 1e-9 from B's vertices; S − A is empty up to specks that carry no volume.
#[test]
fn a_sliver_difference_reused_against_the_solids_that_made_it() {
    let a = procedural::star_prism();
    let turn = Transform::parse("translate 0 0 -0.5; rotate 1 2 3 1e-6; translate 0 0 0.5").unwrap();
    reuse_difference("star prism, B turned 1e-6°", &a, &turn.apply(&a).unwrap());
}

/// The sphere minus its copy turned 10° about a skew axis and shifted (as `--transform-b`
/// places it), used again against the copy and against the sphere. The difference carries
/// the copy's faces reversed with corners rounded a hair off their planes: where both
/// layers are kept the exact result holds a sheet between them, whose outline has corners
/// in line within an ulp (rebuilt with its cover counted by winding numbers, after splits
/// at those corners and snaps of corners a few ulps apart: `Repair::sheets`); where both
/// go, S ∩ B, what is left is such sheets
/// only (dropped whole: they carry no volume). Every result re-reads as an operand.
#[test]
fn a_turned_difference_reused_against_its_cutter() {
    let a = procedural::sphere(16, 32);
    let turn = Transform::parse("rotate 1 2 3 10; translate 0.01 0.02 0.005").unwrap();
    let b = turn.apply(&a).unwrap();
    let options = Options::default();
    let evaluate = |x: &Mesh, y: &Mesh| boolean::evaluate(x, y, Names::default(), &options, None).unwrap();
    let s = evaluate(&a, &b).result(Operation::Difference, true).unwrap();
    let against_b = evaluate(&s, &b);
    let union = against_b.output(Operation::Union, true).unwrap_or_else(|e| panic!("S ∪ B: {e}"));
    assert!(union.repair.sheets > 0, "{}", union.repair);
    assert_operand("S ∪ B", &union.mesh);
    let inter = against_b.result(Operation::Intersection, true).unwrap_or_else(|e| panic!("S ∩ B: {e}"));
    assert!(volume(&inter).abs() <= 1e-12, "S ∩ B: {}", volume(&inter));
    assert_operand("S ∩ B", &inter);
    for op in [Operation::Difference, Operation::SymmetricDifference] {
        let r = against_b.result(op, true).unwrap_or_else(|e| panic!("S {op} B: {e}"));
        assert_operand(&format!("S {op} B"), &r);
    }
    let against_a = evaluate(&s, &a);
    for op in Operation::ALL {
        let r = against_a.result(op, true).unwrap_or_else(|e| panic!("S {op} A: {e}"));
        assert_operand(&format!("S {op} A"), &r);
    }
}

/// The sphere minus its copy turned 1e-6° about a skew axis (as `--transform-b` turns it),
/// intersected with the copy: exactly, what is left is sheets between S's faces and the
/// copy's a hair apart. Where a sheet's outline must be split at corners in line within an
/// ulp, the splits cut the triangles of the sheet beside it (across a crease of the
/// outline), which then cross: the two are rebuilt together (`Repair::joined_sheets`).
/// The result carries no volume and re-reads as an operand.
#[test]
fn a_micro_turned_difference_intersected_with_its_cutter() {
    let a = procedural::sphere(16, 32);
    let b = Transform::parse("rotate 1 2 3 0.000001").unwrap().apply(&a).unwrap();
    let options = Options::default();
    let evaluate = |x: &Mesh, y: &Mesh| boolean::evaluate(x, y, Names::default(), &options, None).unwrap();
    let s = evaluate(&a, &b).result(Operation::Difference, true).unwrap();
    assert!(volume(&s) > 0.0, "{}", volume(&s));
    let inter =
        evaluate(&s, &b).output(Operation::Intersection, true).unwrap_or_else(|e| panic!("S ∩ B: {e}"));
    assert!(inter.repair.joined_sheets > 0, "{}", inter.repair);
    assert!(volume(&inter.mesh).abs() <= 1e-12, "S ∩ B: {}", volume(&inter.mesh));
    assert_operand("S ∩ B", &inter.mesh);
}

/// The knot minus its copy turned 1e-6° about a skew axis, united with the copy: along an
/// edge of the knot, needles of S (A's edge and the cut a few 1e-9 beside it) lie along
/// needles of the copy's faces, and a vertex of A and its turned copy 2e-8 apart share no
/// edge. No snap, collapse, ulp move or sheet removes the crossing there; merging the two
/// vertices does (`Repair::merged`). The result re-reads as an operand and holds the
/// volume of A ∪ B.
#[test]
fn a_micro_turned_knot_difference_united_with_its_cutter() {
    let a = procedural::torus_knot();
    let b = Transform::parse("rotate 1 2 3 0.000001").unwrap().apply(&a).unwrap();
    let options = Options::default();
    let evaluate = |x: &Mesh, y: &Mesh| boolean::evaluate(x, y, Names::default(), &options, None).unwrap();
    let ab = evaluate(&a, &b);
    let s = ab.result(Operation::Difference, true).unwrap();
    let v_union = volume(&ab.result(Operation::Union, true).unwrap());
    let r = evaluate(&s, &b).output(Operation::Union, true).unwrap_or_else(|e| panic!("S ∪ B: {e}"));
    assert!(r.repair.merged > 0, "S ∪ B: {}", r.repair);
    assert!((volume(&r.mesh) - v_union).abs() <= REL * v_union, "S ∪ B: {} vs {v_union}", volume(&r.mesh));
    assert_operand("S ∪ B", &r.mesh);
}

/// The knot's symmetric difference with its copy turned 1e-6° about a skew axis, united
/// with the knot: X carries faces of the knot reversed with corners rounded a hair off
/// their planes, and where a face of the knot and its reversed copy share an edge, the
/// corners across it lie 1e-9 apart and the sheet between them cannot be rebuilt (a corner
/// of one lies off the plane by more than a flat region's thickness). Once rounded, such
/// sheets and slivers are closed pieces of no volume hanging on the rest by edges of four
/// faces, and many of them face the wrong way about those edges (folded edges): the repair
/// drops them (`Repair::dropped_pieces`). The result re-reads as an operand (the order of
/// faces about every such edge included) and holds the volume of A ∪ B.
#[test]
fn a_micro_turned_knot_symmetric_difference_united_with_the_knot() {
    let a = procedural::torus_knot();
    let b = Transform::parse("rotate 1 2 3 0.000001").unwrap().apply(&a).unwrap();
    let options = Options::default();
    let evaluate = |x: &Mesh, y: &Mesh| boolean::evaluate(x, y, Names::default(), &options, None).unwrap();
    let ab = evaluate(&a, &b);
    let x = ab.result(Operation::SymmetricDifference, true).unwrap();
    let v_union = volume(&ab.result(Operation::Union, true).unwrap());
    let r = evaluate(&x, &a).output(Operation::Union, true).unwrap_or_else(|e| panic!("X ∪ A: {e}"));
    assert!(r.repair.folded_edges > 0 && r.repair.dropped_pieces > 0, "X ∪ A: {}", r.repair);
    assert!((volume(&r.mesh) - v_union).abs() <= REL * v_union, "X ∪ A: {} vs {v_union}", volume(&r.mesh));
    assert_operand("X ∪ A", &r.mesh);
}

/// The knot's A ⊖ B (B turned 1e-6°) minus A: rounding the result turns tiny closed pieces
/// hanging on an edge of four faces inside out (the winding number −1 in them) without
/// making faces cross. The repair counts such folded edges as defects and drops the pieces
/// of no volume on them (`Repair::dropped_pieces`): the result re-reads as an operand (the
/// order of faces about every edge of more than two included) and holds the volume of
/// X − (X ∩ A).
#[test]
fn a_micro_turned_knot_symmetric_difference_minus_the_knot_is_repaired() {
    let a = procedural::torus_knot();
    let b = Transform::parse("rotate 1 2 3 0.000001").unwrap().apply(&a).unwrap();
    let options = Options::default();
    let evaluate = |x: &Mesh, y: &Mesh| boolean::evaluate(x, y, Names::default(), &options, None).unwrap();
    let x = evaluate(&a, &b).result(Operation::SymmetricDifference, true).unwrap();
    let xa = evaluate(&x, &a);
    let r = xa.output(Operation::Difference, true).unwrap_or_else(|e| panic!("X − A: {e}"));
    assert!(r.repair.folded_edges > 0 && r.repair.dropped_pieces > 0, "X − A: {}", r.repair);
    assert_operand("X − A", &r.mesh);
    let expected = volume(&x) - volume(&xa.result(Operation::Intersection, true).unwrap());
    let scale = volume(&x).max(volume(&a));
    assert!((volume(&r.mesh) - expected).abs() <= REL * scale, "X − A: {} vs {expected}", volume(&r.mesh));
}

/// A difference used again against the solid that cut it, B shifted by half the width:
/// corners of A − B that were intersection points on B's edges lie an ulp beside them.
#[test]
fn a_half_shifted_difference_reused_against_the_solids_that_made_it() {
    let a = procedural::sphere(16, 32);
    let (lo, hi) = a.bounds();
    assert_eq!(hi.x - lo.x, 2.0);
    let shift = Transform::parse("translate 1 0 0").unwrap();
    reuse_difference("sphere, B shifted by half", &a, &shift.apply(&a).unwrap());
}

/// A result far smaller than the operands is a result, not what rounding left of a sliver:
/// a cube 1e-8 the size of the other, straddling its face or beside it, is kept whole by
/// every operation (its corners, rounded at coordinates near 1, are good to ~1e-8 of its
/// size, hence the volume's tolerance).
#[test]
fn a_tiny_solid_is_kept_whole() {
    let a = procedural::cube();
    let s = 1e-8;
    let small =
        |centre: DVec3| moved(&a, DAffine3::from_translation(centre) * DAffine3::from_scale(DVec3::splat(s)));
    let v_small = 8.0 * s * s * s;
    // Straddling the face x = 1: half of it inside.
    let (ev, [_, vi, ..]) = check_exact("tiny straddling", &a, &small(DVec3::new(1.0, 0.1, 0.2)), false);
    assert!(ev.result(Operation::Intersection, true).unwrap().num_faces() > 0, "A ∩ B dropped");
    assert!((vi - v_small / 2.0).abs() <= 1e-6 * v_small, "A ∩ B {vi} vs {}", v_small / 2.0);
    // Beside it: A ∪ B keeps both shells (more faces than A − B, which is A alone).
    let b = small(DVec3::new(1.0 + 3.0 * s, 0.1, 0.2));
    let (ev, [_, vi, ..]) = check_exact("tiny beside", &a, &b, false);
    assert_eq!(vi, 0.0);
    let faces = |op| ev.result(op, true).unwrap().num_faces();
    assert!(faces(Operation::Union) > faces(Operation::Difference), "B dropped from A ∪ B");
}

/// A thin result used again inside one expression stays exact: `(a ^ b) ^ b` is a and
/// `(a ^ b) & b` is b − a, for a UV sphere and its copy turned 1e-6° about a skew axis.
/// The symmetric difference is slivers thinner than f64 can hold; rounded and used again
/// (one operation at a time) these fail to give a valid solid, but as the next operand
/// of an expression they are not rounded at all, and only the end result is.
#[test]
fn an_expression_keeps_a_sliver_result_exact_for_the_next_operation() {
    use texgeo::boolean::expr::{self, Expr, Operand};
    let turn = Transform::parse("rotate 1 2 3 1e-6").unwrap();
    for (rings, text) in [(6, "(a ^ b) ^ b"), (8, "(a ^ b) & b")] {
        let a = procedural::sphere(rings, 2 * rings);
        let b = turn.apply(&a).unwrap();
        let name = format!("sphere {rings}×{}: {text}", 2 * rings);
        let operands = [("a", &a), ("b", &b)].map(|(n, m)| Operand {
            name: n.to_string(),
            label: n.to_string(),
            mesh: m.clone(),
        });
        let mut repairs = Vec::new();
        let r = expr::evaluate(&Expr::parse(text).unwrap(), &operands, &Options::default(), None, |s| {
            repairs.push(s.repair.is_some())
        })
        .unwrap_or_else(|e| panic!("{name}: {e}"));
        // Only the last operation's result is rounded (and checked, and repaired).
        assert_eq!(repairs, [false, true], "{name}");
        assert_operand(&name, &r);
        // b − a exactly, before any rounding.
        let want = if text.ends_with("^ b") {
            volume(&a)
        } else {
            let ev = boolean::evaluate(&b, &a, Names::default(), &Options::default(), None).unwrap();
            ev.exact_volume(Operation::Difference, true).value
        };
        assert!((volume(&r) - want).abs() <= REL * volume(&a), "{name}: {} vs {want}", volume(&r));
    }
}
