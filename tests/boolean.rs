//! Boolean operations (SPEC §6): the special cases of the thesis' Fig. 6-9, each for
//! all four operations, checked for closedness, against CGAL's exact corefinement
//! (volume and area to 1e-9 relative), against the volume identity and against the
//! inclusion oracle at random points; regularized vs plain; GPU vs CPU classification.

mod common;

use common::{moved, volume};
use glam::{DAffine3, DVec3};
use texgeo::boolean::{self, Class, Evaluation, Names, Operation, Options, cgal};
use texgeo::exact::Exact;
use texgeo::exact::rounding::{Ball, quotient_exact};
use texgeo::gpu::Context;
use texgeo::inclusion::winding::WindingNumber;
use texgeo::inclusion::{self, Classifier, Method};
use texgeo::mesh::covering::Covering;
use texgeo::mesh::intersect::TriangleSoup;
use texgeo::mesh::{Mesh, procedural};
use texgeo::random::Rng;

/// Relative tolerance of volumes and areas against CGAL (exact arithmetic there; f64
/// intersection points here).
const REL: f64 = 1e-9;

/// An axis-aligned box whose quads are split along the other diagonal when `other_diagonal`.
fn boxed(lo: [f64; 3], hi: [f64; 3], other_diagonal: bool) -> Mesh {
    let m = procedural::box_between(DVec3::from(lo), DVec3::from(hi));
    if !other_diagonal {
        return m;
    }
    let faces = m.faces().map(|f| vec![f[1], f[2], f[3], f[0]]).collect();
    Mesh::new(m.positions().to_vec(), faces).unwrap()
}

fn area(m: &Mesh) -> f64 {
    if m.num_faces() == 0 { 0.0 } else { Covering::new(m).area() }
}

fn close(a: f64, b: f64, scale: f64) -> bool {
    (a - b).abs() <= REL * scale
}

fn evaluate(a: &Mesh, b: &Mesh, method: Method, ctx: Option<&Context>) -> Evaluation {
    let options = Options { method: method.into(), ..Options::default() };
    boolean::evaluate(a, b, Names::default(), &options, ctx).unwrap_or_else(|e| panic!("{e}"))
}

/// Every check of one case; returns how many operations CGAL declined.
fn check_case(name: &str, a: &Mesh, b: &Mesh) -> usize {
    let ev = evaluate(a, b, Method::Bvh, None);
    let reference = cgal::reference(a, b, None).unwrap_or_else(|e| panic!("{name}: {e}"));
    let (va, vb) = (volume(a), volume(b));
    let scale_v = va.max(vb);
    let (lo, hi) = a.bounds();
    let (lo2, hi2) = b.bounds();
    let (lo, hi) = (lo.min(lo2), hi.max(hi2));
    let scale_a = area(a).max(area(b));
    let mut results = Vec::new();
    let mut declined = 0;
    for op in Operation::ALL {
        let r = ev.result(op, true).unwrap_or_else(|e| panic!("{name} {op}: {e}"));
        let report = r.report();
        assert!(report.is_closed(), "{name} {op}: not closed: {report}");
        let (v, s) = (volume(&r), area(&r));
        assert!(v >= -REL * scale_v, "{name} {op}: negative volume {v}");
        match reference.measures(op) {
            Some((cv, cs)) => {
                assert!(close(v, cv, scale_v), "{name} {op}: volume {v} vs CGAL {cv}");
                assert!(close(s, cs, scale_a), "{name} {op}: area {s} vs CGAL {cs}");
            }
            None => declined += 1,
        }
        results.push((op, r, v));
    }
    let vol = |op: Operation| results.iter().find(|x| x.0 == op).map(|x| x.2).unwrap_or_default();
    // vol(A∪B) + vol(A∩B) = vol(A) + vol(B); vol(A−B) = vol(A) − vol(A∩B).
    let (vu, vi, vd, vs) = (
        vol(Operation::Union),
        vol(Operation::Intersection),
        vol(Operation::Difference),
        vol(Operation::SymmetricDifference),
    );
    assert!(close(vu + vi, va + vb, scale_v), "{name}: {vu} + {vi} vs {va} + {vb}");
    assert!(close(vd, va - vi, scale_v), "{name}: A−B {vd} vs {va} − {vi}");
    assert!(close(vs, vu - vi, scale_v), "{name}: A⊖B {vs} vs {vu} − {vi}");

    // Random points away from both surfaces: inside the result iff op(in A, in B).
    let wa = WindingNumber::new(a).unwrap();
    let wb = WindingNumber::new(b).unwrap();
    let soups = [TriangleSoup::new(a), TriangleSoup::new(b)];
    let pad = (hi - lo) * 0.05;
    let pts: Vec<DVec3> = Rng::new(7)
        .points_in_box(300, lo - pad, hi + pad)
        .into_iter()
        .filter(|&p| soups.iter().all(|s| distance(s, p) > 1e-6 * (hi - lo).length()))
        .collect();
    assert!(pts.len() > 100, "{name}: too few test points");
    for (op, r, _) in &results {
        let inside_result: Vec<bool> = if r.num_faces() == 0 {
            vec![false; pts.len()]
        } else {
            let w = WindingNumber::new(r).unwrap();
            pts.iter().map(|&p| w.classify(p) == inclusion::Class::Inside).collect()
        };
        for (k, &p) in pts.iter().enumerate() {
            let (ia, ib) =
                (wa.classify(p) == inclusion::Class::Inside, wb.classify(p) == inclusion::Class::Inside);
            let want = match op {
                Operation::Union => ia || ib,
                Operation::Intersection => ia && ib,
                Operation::Difference => ia && !ib,
                Operation::SymmetricDifference => ia != ib,
            };
            assert_eq!(inside_result[k], want, "{name} {op}: point {p} (in A {ia}, in B {ib})");
        }
    }
    declined
}

/// Distance from p to the closest triangle of `soup`.
fn distance(soup: &TriangleSoup, p: DVec3) -> f64 {
    (0..soup.triangles.len())
        .map(|t| {
            let [a, b, c] = soup.triangle(t);
            p.distance(texgeo::exact::closest_point_on_triangle(p, a, b, c))
        })
        .fold(f64::INFINITY, f64::min)
}

#[test]
fn cubes_face_to_face_with_coplanar_overlap_both_diagonals() {
    let a = boxed([0.0; 3], [1.0; 3], false);
    let b = boxed([0.5, 0.25, 0.0], [1.5, 1.25, 1.0], true);
    assert_eq!(check_case("coplanar overlap", &a, &b), 0);
    // The same with the same diagonal on both.
    let b = boxed([0.5, 0.25, 0.0], [1.5, 1.25, 1.0], false);
    assert_eq!(check_case("coplanar overlap, same diagonal", &a, &b), 0);
}

#[test]
fn cubes_touching_at_a_face_an_edge_and_a_vertex() {
    let a = boxed([0.0; 3], [1.0; 3], false);
    // Whole face, part of a face (offset), an edge, a vertex. CGAL declines unions
    // whose result is not a 2-manifold (edge and vertex contact); the other checks
    // still apply there.
    check_case("touching face", &a, &boxed([1.0, 0.0, 0.0], [2.0, 1.0, 1.0], true));
    check_case("touching part of a face", &a, &boxed([1.0, 0.5, 0.25], [2.0, 1.5, 1.25], false));
    check_case("touching along an edge", &a, &boxed([1.0, 1.0, 0.0], [2.0, 2.0, 1.0], false));
    check_case("touching at a vertex", &a, &boxed([1.0; 3], [2.0; 3], false));
}

#[test]
fn pocket_and_box_through_box() {
    let a = boxed([0.0; 3], [2.0; 3], false);
    assert_eq!(check_case("pocket", &a, &boxed([0.5, 0.5, 1.0], [1.5, 1.5, 2.0], true)), 0);
    assert_eq!(check_case("box through box", &a, &boxed([0.5, 0.5, -1.0], [1.5, 1.5, 3.0], false)), 0);
}

#[test]
fn slightly_rotated_copies_give_thin_slivers() {
    let cube = procedural::cube();
    let turn = DAffine3::from_axis_angle(DVec3::new(1.0, 2.0, 3.0).normalize(), 1f64.to_radians());
    assert_eq!(check_case("cube rotated 1°", &cube, &moved(&cube, turn)), 0);
    let sphere = procedural::sphere(8, 12);
    let turn = DAffine3::from_axis_angle(DVec3::new(0.3, 1.0, 0.2).normalize(), 2f64.to_radians());
    assert_eq!(check_case("sphere rotated 2°", &sphere, &moved(&sphere, turn)), 0);
}

#[test]
fn identical_solids() {
    for (name, m) in [("cube", procedural::cube()), ("l-prism", procedural::l_prism())] {
        let ev = evaluate(&m, &m, Method::Bvh, None);
        let v = volume(&m);
        for (op, want) in [
            (Operation::Union, v),
            (Operation::Intersection, v),
            (Operation::Difference, 0.0),
            (Operation::SymmetricDifference, 0.0),
        ] {
            let r = ev.result(op, true).unwrap();
            assert!(close(volume(&r), want, v), "{name} {op}: {}", volume(&r));
            if want == 0.0 {
                assert_eq!(r.num_faces(), 0, "{name} {op}");
            } else {
                assert!(close(area(&r), area(&m), area(&m)), "{name} {op}");
            }
        }
        // Every triangle is on the other, facing the same way.
        assert!(ev.classification.a.iter().chain(&ev.classification.b).all(|&c| c == Class::OnSame));
    }
}

#[test]
fn non_manifold_and_polygon_operands() {
    // Two cubes sharing an edge (not manifold) minus a bar through the shared edge; the
    // L-prism's non-convex caps cut by a box. CGAL cannot read the non-manifold solid:
    // the volume identity and the oracle check it.
    let two = procedural::two_cubes_sharing_edge();
    let bar = boxed([0.5, 0.5, 0.25], [1.5, 1.5, 0.75], false);
    let ev = evaluate(&two, &bar, Method::Bvh, None);
    let d = ev.result(Operation::Difference, true).unwrap();
    let i = ev.result(Operation::Intersection, true).unwrap();
    assert!(close(volume(&d), 2.0 - volume(&i), 2.0));
    // The bar holds a quarter of each cube's corner column: 2 × 0.5 × 0.5 × 0.5.
    assert!(close(volume(&i), 0.25, 1.0), "{}", volume(&i));
    let l = procedural::l_prism();
    assert_eq!(check_case("l-prism minus box", &l, &boxed([0.5, 0.5, 0.5], [2.0, 2.0, 2.0], false)), 0);
}

#[test]
fn regularized_and_plain_differ_exactly_where_faces_coincide() {
    let a = boxed([0.0; 3], [1.0; 3], false);
    for (name, b) in [
        ("touching", boxed([1.0, 0.0, 0.0], [2.0, 1.0, 1.0], true)),
        ("pocket", boxed([0.25, 0.25, 0.5], [0.75, 0.75, 1.0], false)),
        ("overlap", boxed([0.5, 0.25, 0.0], [1.5, 1.25, 1.0], true)),
    ] {
        let ev = evaluate(&a, &b, Method::Bvh, None);
        let on_opposite = ev.classification.a.iter().filter(|&&c| c == Class::OnOpposite).count();
        for op in Operation::ALL {
            let reg = ev.result(op, true).unwrap();
            let plain = ev.result(op, false).unwrap();
            let diff = reg.num_faces().abs_diff(plain.num_faces());
            let expected = match op {
                Operation::Intersection | Operation::Difference => on_opposite,
                _ => 0,
            };
            assert_eq!(diff, expected, "{name} {op}");
        }
        if name == "touching" {
            assert!(on_opposite > 0);
            // ∩: the plain result is the shared face alone (open, no volume).
            let plain = ev.result(Operation::Intersection, false).unwrap();
            assert!(plain.num_faces() > 0 && !plain.report().is_closed());
        }
    }
}

#[test]
fn gpu_and_cpu_classification_give_identical_outputs() {
    let ctx = Context::from_env().expect("a Vulkan device (run tools/setup)");
    let knot = procedural::torus_knot();
    let turned = moved(
        &knot,
        DAffine3::from_axis_angle(DVec3::Y, 10f64.to_radians()) * DAffine3::from_translation(DVec3::X * 0.05),
    );
    let gpu = evaluate(&knot, &turned, Method::Gpu, Some(&ctx));
    let cpu = evaluate(&knot, &turned, Method::Cpu, None);
    assert_eq!(gpu.classification.a, cpu.classification.a);
    assert_eq!(gpu.classification.b, cpu.classification.b);
    for op in Operation::ALL {
        assert_eq!(gpu.result(op, true).unwrap(), cpu.result(op, true).unwrap(), "{op}");
    }
    // Grouping saves point tests and changes nothing.
    let plain = boolean::evaluate(
        &knot,
        &turned,
        Names::default(),
        &Options { method: Method::Cpu.into(), grouping: boolean::Grouping::Plain, ..Options::default() },
        None,
    )
    .unwrap();
    assert_eq!(plain.classification.a, cpu.classification.a);
    assert_eq!(plain.classification.b, cpu.classification.b);
    let (g, p) = (cpu.classification.stats, plain.classification.stats);
    assert!(g.point_tests < p.point_tests / 2, "{g:?} vs {p:?}");
    assert!(p.saved_share() == 0.0 && g.saved_share() > 0.5);
}

#[test]
fn bad_operands_are_refused_with_the_reason() {
    let cube = procedural::cube();
    let open =
        Mesh::new(cube.positions().to_vec(), cube.faces().skip(1).map(<[u32]>::to_vec).collect()).unwrap();
    let inverted = Mesh::new(
        cube.positions().to_vec(),
        cube.faces().map(|f| f.iter().rev().copied().collect()).collect(),
    )
    .unwrap();
    let names = Names { a: "first.off", b: "second.off" };
    for (bad, want) in [(&open, "not closed"), (&inverted, "inverted")] {
        let e = boolean::evaluate(
            &cube,
            bad,
            names,
            &Options { method: Method::Bvh.into(), ..Options::default() },
            None,
        )
        .err()
        .unwrap()
        .to_string();
        assert!(e.contains("second.off") && e.contains(want), "{e}");
    }
}

#[test]
fn the_empty_solid_is_an_operand_and_a_result() {
    let empty = Mesh::new(Vec::new(), Vec::new()).unwrap();
    let cube = procedural::cube();
    let (v, s) = (volume(&cube), area(&cube));
    // A op ∅ and ∅ op A: (A ∪ ∅, A ∩ ∅, A − ∅, A ⊖ ∅) = (A, ∅, A, A), (∅ − A) = ∅.
    for (a, b, a_is_cube) in [(&cube, &empty, true), (&empty, &cube, false), (&empty, &empty, false)] {
        let ev = evaluate(a, b, Method::Octants, None);
        for op in Operation::ALL {
            let r = ev.result(op, true).unwrap_or_else(|e| panic!("{op}: {e}"));
            let b_is_cube = !a_is_cube && b.num_faces() > 0;
            let want = match op {
                Operation::Union | Operation::SymmetricDifference => a_is_cube || b_is_cube,
                Operation::Intersection => false,
                Operation::Difference => a_is_cube,
            };
            if want {
                assert!(r.report().is_closed(), "{op}");
                assert!(close(volume(&r), v, v) && close(area(&r), s, s), "{op}: {}", volume(&r));
            } else {
                assert_eq!(r.num_faces(), 0, "{op}");
            }
        }
    }
}

#[test]
fn a_sliver_difference_is_repaired_into_a_valid_operand() {
    // The thin slivers of a sphere minus its copy turned 1e-6°: rounded to f64, some of
    // their faces cross; the output check collapses the short edges there.
    let sphere = procedural::sphere(16, 32);
    let turned = moved(&sphere, DAffine3::from_axis_angle(DVec3::X, 1e-6f64.to_radians()));
    let ev = evaluate(&sphere, &turned, Method::Octants, None);
    let out = ev.output(Operation::Difference, true).unwrap_or_else(|e| panic!("{e}"));
    assert!(out.repair.crossings > 0 && out.repair.collapsed_edges > 0, "{}", out.repair);
    // A valid operand: the full check every operand gets (crossings, nesting, no area, volume).
    let frame = texgeo::mesh::frame::Frame::of(&[&out.mesh]);
    boolean::input::check(&frame.mesh_in_ref(&out.mesh), frame, false).unwrap_or_else(|e| panic!("{e}"));
    assert!(texgeo::mesh::solidity::check(&out.mesh).is_solid());
    // The repair moves points by at most 1e-7 × the diagonal, which changes the slivers'
    // own volume by a fraction of a percent and the solids' by far less than the 1e-9
    // every volume is checked to: against the selected triangles' (the unchecked,
    // non-regularized selection is the same here).
    let selected = ev.result(Operation::Difference, false).unwrap();
    let (got, want) = (volume(&out.mesh), volume(&selected));
    assert!(out.repair.moved <= 1e-7 * 2.0 * 3f64.sqrt(), "{}", out.repair);
    assert!((got - want).abs() <= REL * volume(&sphere), "{got} vs {want}: {}", out.repair);
    assert!((got - want).abs() <= 1e-2 * want, "{got} vs {want}: {}", out.repair);
    // And as an operand again: within a box around it, the slivers are what they were.
    let around = boxed([-3.0; 3], [3.0; 3], false);
    let again = evaluate(&out.mesh, &around, Method::Octants, None);
    let r = again.result(Operation::Intersection, true).unwrap_or_else(|e| panic!("{e}"));
    assert!(close(volume(&r), got, got), "{} vs {got}", volume(&r));
}

#[test]
fn point_tests_answer_for_the_triangles_that_are_cut() {
    // The L-prism with one top corner raised: its top is a non-planar hexagon whose
    // centroid lies outside it, so its triangles are made in its projection plane, while
    // the covering (centroid fan) passes above them over the long arm. A small box in
    // that gap is outside the triangles, inside the covering: the Boolean cuts and keeps
    // the triangles, so its point tests must answer for them.
    let l = procedural::l_prism();
    let mut p = l.positions().to_vec();
    p[7].z = 3.0; // (4, 0, 1) → (4, 0, 3)
    let raised = Mesh::new(p, l.faces().map(<[u32]>::to_vec).collect()).unwrap();
    let soup = TriangleSoup::new(&raised);
    let corner = DVec3::new(3.0, 0.45, 2.15);
    assert_eq!(boolean::classify::exact_parity(corner, &soup), Some(false));
    let cut_surface = texgeo::mesh::triangulate::triangulated(&raised);
    let a = boxed([3.0, 0.45, 2.15], [3.2, 0.5, 2.28], false);
    let covering = WindingNumber::new(&raised).unwrap();
    assert!(a.positions().iter().all(|&p| covering.classify(p) == inclusion::Class::Inside));
    for method in [Method::Octants, Method::Bvh, Method::Winding] {
        let ev = evaluate(&raised, &a, method, None);
        let union = ev.result(Operation::Union, true).unwrap();
        assert!(union.report().is_closed(), "{method:?}");
        assert!(
            close(volume(&union), volume(&cut_surface) + volume(&a), 1.0),
            "{method:?}: {}",
            volume(&union)
        );
        assert_eq!(ev.result(Operation::Intersection, true).unwrap().num_faces(), 0, "{method:?}");
    }
}

/// A prism over the quadrilateral `corners` (counter-clockwise seen from +z) between z = −1
/// and z = 1, in outward triangles.
fn prism(corners: [[f64; 2]; 4]) -> Mesh {
    let positions = [-1.0, 1.0].iter().flat_map(|&z| corners.map(|[x, y]| DVec3::new(x, y, z))).collect();
    let mut faces = vec![vec![0, 2, 1], vec![0, 3, 2], vec![4, 5, 6], vec![4, 6, 7]];
    for i in 0..4u32 {
        let j = (i + 1) % 4;
        faces.push(vec![i, j, j + 4]);
        faces.push(vec![i, j + 4, i + 4]);
    }
    Mesh::new(positions, faces).unwrap()
}

/// The volume of a mesh of triangles with f64 vertices, certified (double-double).
fn certified_volume(m: &Mesh) -> texgeo::exact::volume::Volume {
    let tris: Vec<[u32; 3]> = m.faces().map(|f| [f[0], f[1], f[2]]).collect();
    let p = m.positions();
    texgeo::exact::volume::signed_volume(&tris, |i| (p[i as usize].to_array().map(Ball::of), false))
}

#[test]
fn a_sliver_difference_reports_the_exact_volume_before_rounding() {
    // The cube [−1, 1]³ minus its copy turned 1e-6° about z, the copy's corners (a, b),
    // (−b, a), (−a, −b), (b, −a) being exact quarter turns of each other (a square prism,
    // whatever a and b round to). A − B is four thin prisms along A's vertical edges, each
    // over the triangle that B's side line cuts off A's corner, with legs N/(a + b) and
    // N/(b − a), N = 2b − a² − b²: the volume is 4·N²/(b² − a²), taken here exactly.
    let t = 1e-6f64.to_radians();
    let (a, b) = (t.cos() - t.sin(), t.cos() + t.sin());
    let cube = prism([[1.0, 1.0], [-1.0, 1.0], [-1.0, -1.0], [1.0, -1.0]]);
    let turned = prism([[a, b], [-b, a], [-a, -b], [b, -a]]);
    let (ea, eb) = (Exact::from_f64(a), Exact::from_f64(b));
    let (aa, bb) = (&ea * &ea, &eb * &eb);
    let n = &(&(&eb + &eb) - &aa) - &bb;
    let want = quotient_exact(&(&(&n * &n) * &Exact::from_f64(4.0)), &(&bb - &aa));
    assert!(want > 6e-8 && want < 8e-8, "{want}");
    let half_ulp = want * f64::EPSILON / 2.0;

    let ev = evaluate(&cube, &turned, Method::Octants, None);
    let out = ev.output(Operation::Difference, true).unwrap_or_else(|e| panic!("{e}"));
    let v = ev.exact_volume(Operation::Difference, true);
    // Within its certified bound (and the reference's rounding) of the exact value, and
    // that bound far below 1e-12 relative.
    assert!((v.value - want).abs() <= v.error + half_ulp, "{v:?} vs {want}");
    assert!(v.error <= 1e-15 * want, "{v:?}");
    // Rounding alone wrote this file (no repair): its volume, measured exactly, lies within
    // the stated rounding bound of the exact one.
    assert!(out.repair.is_clean(), "{}", out.repair);
    let written = certified_volume(&out.mesh);
    assert!(
        (written.value - want).abs() <= v.rounding + written.error + half_ulp,
        "{written:?} vs {want}: {v:?}"
    );
    assert!(v.rounding < 1e-6 * want, "{v:?}");

    // The corpus' case: the same cube (in triangles, so that both tools read the same
    // solids: a turned quad is not planar) turned 1e-6° about (1, 2, 3), against CGAL's
    // exact corefinement (its exact volume converted to f64).
    let turned = moved(&cube, DAffine3::from_axis_angle(DVec3::new(1.0, 2.0, 3.0).normalize(), t));
    let reference = cgal::reference(&cube, &turned, None).unwrap_or_else(|e| panic!("{e}"));
    let ev = evaluate(&cube, &turned, Method::Octants, None);
    for op in [Operation::Difference, Operation::SymmetricDifference] {
        let (cv, _) = reference.measures(op).unwrap_or_else(|| panic!("CGAL declined {op}"));
        let v = ev.exact_volume(op, true);
        assert!((v.value - cv).abs() <= 1e-12 * cv, "{op}: {v:?} vs CGAL {cv}");
    }
}
