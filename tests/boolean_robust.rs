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

/// A coarse torus' symmetric difference X with its copy turned 1e-6° about a skew axis,
/// ⊖ the torus again (exactly the copy, but for X's rounding): the repair's snaps and
/// collapses around the slivers leave closed pieces folded over edges of the rest, inside
/// the solid facing out or outside it facing in (the winding number 2 or −1 in them), that
/// no collapse, ulp move or drop of a piece of no volume removes. They lie doubled over
/// the rest: the repair drops them (`Repair::doubled_pieces`), which keeps the solid's
/// points. The result re-reads as an operand and holds the copy's volume.
#[test]
fn a_micro_turned_torus_symmetric_difference_against_the_torus_drops_doubled_pieces() {
    let a = procedural::torus(1.0, 0.4, 10, 3);
    let b = Transform::parse("rotate 1 2 3 0.000001").unwrap().apply(&a).unwrap();
    let options = Options::default();
    let evaluate = |x: &Mesh, y: &Mesh| boolean::evaluate(x, y, Names::default(), &options, None).unwrap();
    let x = evaluate(&a, &b).result(Operation::SymmetricDifference, true).unwrap();
    let r = evaluate(&x, &a)
        .output(Operation::SymmetricDifference, true)
        .unwrap_or_else(|e| panic!("X ⊖ A: {e}"));
    assert!(r.repair.folded_edges > 0 && r.repair.doubled_pieces > 0, "X ⊖ A: {}", r.repair);
    assert_operand("X ⊖ A", &r.mesh);
    let v = volume(&b);
    assert!((volume(&r.mesh) - v).abs() <= REL * v, "X ⊖ A: {} vs {v}", volume(&r.mesh));
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

/// A cut-out of fandisk_large's A ⊖ B (B turned 1e-6° about (1, 2, 3) about the centre of
/// its box), then ⊖ A, as rounding and the repair's other steps leave it: its 113 triangles
/// around the place, in the evaluation's frame (ids from 29 on are intersection points;
/// `UNCUT` lists the uncut input triangles). A face of A passes within rounding of a
/// vertex of A ⊖ B, its plane cuts the edges at that vertex at points 5.7e-13 to 2.4e-9
/// from it, and the outline of the sheet there crosses itself among them: no snap, split,
/// collapse, ulp move, sheet rebuild or merge of one point removes the crossings. The sheet
/// rebuilt with those points merged onto its corners first does
/// (`Repair::merged_sheets`): no two faces cross, and every directed edge stays balanced
/// (the cut-out's open outline is kept).
#[test]
fn a_sheet_whose_outline_crosses_itself_among_points_a_hair_apart_is_rebuilt() {
    use texgeo::boolean::output;
    use texgeo::mesh::intersect::{TriangleSoup, soup_self_intersections_near};
    const POINTS: [[f64; 3]; 48] = [
        [0.14890320599079132, 0.9298924803733826, -0.16396556794643402],
        [0.1449929177761078, 0.9303357005119324, -0.16404375433921814],
        [0.14744649827480316, 0.9252976775169373, -0.16315512359142303],
        [0.1429605484008789, 0.9242953658103943, -0.16297848522663116],
        [0.1422790139913559, 0.9275281429290771, -0.1635485142469406],
        [0.13932886719703674, 0.9255092144012451, -0.16319246590137482],
        [0.1404217928647995, 0.9221389293670654, -0.16259831190109253],
        [0.1426743018261154, 0.9256531422693179, -0.163217899190621],
        [0.14267390016961698, 0.9256550459486818, -0.1632182348625297],
        [0.14195618241121916, 0.9246310639692601, -0.16303766305086154],
        [0.14195561789325536, 0.9246312525284497, -0.16303769629060458],
        [0.14035442300024606, 0.9223466796770421, -0.16263493660092673],
        [0.14538860371565931, 0.9295232246778129, -0.16390044594051564],
        [0.1453884339906828, 0.9295235725797467, -0.16390050730513134],
        [0.14359222994049142, 0.9269613134849454, -0.16344854165584985],
        [0.1435915160596315, 0.9269616215221271, -0.16344859598484526],
        [0.14035395887199828, 0.9223481101411256, -0.16263518878016736],
        [0.15263880752545225, 0.9250644449368837, -0.1631139667250583],
        [0.1520218993995953, 0.9284171465949792, -0.163705095768224],
        [0.14491151241917527, 0.9216102960565311, -0.16250512012386176],
        [0.14499291732632177, 0.9303357008042272, -0.1640437543841527],
        [0.14890320554793704, 0.9298924807200324, -0.1639655680299158],
        [0.14744649790380826, 0.9252976778394219, -0.1631551236827478],
        [0.1395738716526812, 0.9294992687475732, -0.16389621794051878],
        [0.13932886682273327, 0.9255092146103077, -0.16319246591598202],
        [0.14227901358547837, 0.9275281431810841, -0.16354851427965278],
        [0.14995637502044873, 0.9233184460385039, -0.16280591500281735],
        [0.15023469895856348, 0.920163810610421, -0.1622495056611507],
        [0.14042179254320197, 0.9221389295886506, -0.16259831194161684],
        [0.14267423900104748, 0.925653440033168, -0.16321795169471479],
        [0.1424068410354913, 0.9252724731709164, -0.16315077093947064],
        [0.14267471869753234, 0.9256537363672431, -0.1632180039354804],
        [0.1434590049533151, 0.9267725838610812, -0.16341526692571245],
        [0.1426743019238075, 0.9256531418059266, -0.16321789910891216],
        [0.1423178442571001, 0.9251475467210578, -0.16312874104082925],
        [0.1426739001699431, 0.9256550459491462, -0.16321823486261158],
        [0.14359147824645274, 0.926961567680671, -0.16344858649210828],
        [0.1426738978159212, 0.9256550458460692, -0.16321823484439768],
        [0.1419560497802105, 0.924631108270411, -0.16303767086039272],
        [0.1419561818336564, 0.9246310641623039, -0.16303766308489184],
        [0.14079317688223522, 0.9229726904216543, -0.1627452994169252],
        [0.14437502650166384, 0.9280777043494348, -0.16364546566181426],
        [0.14447083338028188, 0.9282146285824628, -0.1636696181945001],
        [0.14367281850999625, 0.9270775382788692, -0.16346904293851627],
        [0.14538843460629627, 0.929523571315686, -0.16390050708217024],
        [0.14359222883659042, 0.9269613139614273, -0.1634485417398877],
        [0.14195561976546123, 0.9246312519026859, -0.16303769618029318],
        [0.14538860447886762, 0.9295232231106905, -0.16390044566409906],
    ];
    #[rustfmt::skip]
    const TRIANGLES: [[u32; 3]; 113] = [
        [29, 8, 4], [9, 38, 3], [8, 34, 5], [34, 5, 10], [9, 30, 8], [7, 30, 29], [29, 8, 30],
        [5, 4, 8], [9, 38, 34], [10, 38, 34], [34, 8, 9], [30, 9, 3], [6, 3, 11], [10, 5, 40],
        [40, 11, 3], [2, 12, 0], [13, 4, 43], [13, 12, 42], [14, 41, 42], [41, 42, 12], [4, 13, 1],
        [15, 43, 14], [13, 43, 42], [42, 14, 43], [12, 2, 41], [15, 32, 3], [3, 7, 32], [4, 15, 32],
        [15, 3, 2], [19, 3, 22], [23, 25, 24], [19, 22, 26], [17, 26, 22], [23, 20, 25], [18, 22, 21],
        [17, 22, 18], [24, 25, 37], [8, 35, 37], [35, 37, 25], [3, 9, 8], [8, 37, 9], [24, 37, 39],
        [39, 9, 37], [10, 39, 38], [9, 39, 38], [39, 10, 24], [11, 40, 9], [38, 9, 40], [38, 40, 46],
        [9, 3, 11], [16, 24, 10], [40, 16, 10], [3, 28, 11], [47, 22, 44], [21, 22, 47], [28, 3, 19],
        [20, 13, 25], [14, 42, 22], [13, 42, 44], [44, 22, 42], [25, 42, 45], [42, 25, 13], [45, 14, 42],
        [8, 29, 33], [33, 3, 8], [45, 15, 25], [14, 22, 3], [29, 35, 32], [15, 36, 32], [36, 32, 35],
        [35, 8, 29], [29, 32, 7], [3, 33, 7], [31, 14, 3], [14, 31, 32], [32, 15, 14], [36, 35, 25],
        [25, 15, 36], [19, 26, 27], [46, 5, 34], [33, 30, 7], [4, 37, 35], [34, 39, 37], [29, 30, 33],
        [34, 4, 5], [37, 30, 39], [4, 35, 29], [37, 29, 30], [4, 34, 37], [35, 29, 37], [38, 46, 34],
        [30, 3, 39], [3, 38, 39], [39, 34, 38], [5, 46, 40], [40, 3, 6], [2, 0, 47], [43, 45, 42],
        [2, 42, 41], [1, 44, 42], [42, 2, 47], [42, 41, 45], [42, 4, 1], [42, 43, 4], [44, 42, 47],
        [43, 15, 45], [14, 45, 41], [4, 36, 15], [2, 32, 36], [32, 2, 3], [31, 3, 32], [36, 15, 2],
        [4, 32, 36],
    ];
    const UNCUT: [usize; 12] = [7, 15, 20, 30, 31, 32, 33, 34, 35, 50, 56, 78];
    let points: Vec<DVec3> = POINTS.iter().map(|&p| DVec3::from_array(p)).collect();
    let changed: Vec<bool> = (0..TRIANGLES.len()).map(|t| !UNCUT.contains(&t)).collect();
    let done = output::finish(&points, 29, &TRIANGLES, &changed, 0.4758988369256002)
        .unwrap_or_else(|e| panic!("{e}"));
    assert!(done.repair.crossings > 0 && done.repair.merged_sheets > 0, "{}", done.repair);
    let soup = TriangleSoup {
        positions: done.positions.clone(),
        face_of: (0..done.triangles.len() as u32).collect(),
        triangles: done.triangles.clone(),
        failed: Vec::new(),
    };
    let crossing = soup_self_intersections_near(&soup, &vec![true; done.triangles.len()], usize::MAX);
    assert!(crossing.is_empty(), "{crossing:?}");
    // The directed edges left unbalanced (the cut-out's outline), before and after.
    let outline = |positions: &[DVec3], triangles: &[[u32; 3]]| {
        let mut balance: std::collections::BTreeMap<[[u64; 3]; 2], i32> = Default::default();
        for t in triangles {
            for k in 0..3 {
                let (p, q) = (t[k] as usize, t[(k + 1) % 3] as usize);
                let key = |v: usize| positions[v].to_array().map(f64::to_bits);
                let (a, b) = (key(p), key(q));
                *balance.entry(if a < b { [a, b] } else { [b, a] }).or_default() +=
                    if a < b { 1 } else { -1 };
            }
        }
        balance.retain(|_, b| *b != 0);
        balance
    };
    assert_eq!(outline(&done.positions, &done.triangles), outline(&points, &TRIANGLES));
}
