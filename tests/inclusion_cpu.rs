//! Point-in-solid on the CPU (SPEC §3): the special cases of Alg. 4-1 on solids built so
//! points fall exactly on base triangles, faces and edges through the apex, and mesh
//! vertices; non-convex polygon faces; non-manifold, holed and hollow solids; and every
//! method against every other and the winding-number oracle on random points.

use glam::DVec3;
use texgeo::inclusion::cpu::{APEX_BALL, EdgeRule, FeitoTorres};
use texgeo::inclusion::tetragrid::GridClassifier;
use texgeo::inclusion::winding::WindingNumber;
use texgeo::inclusion::{Class, Classifier, InclusionError, Method, Options, build};
use texgeo::mesh::Mesh;
use texgeo::mesh::procedural;
use texgeo::random::Rng;

use Class::{Inside, OnBoundary, Outside};

// ---------------------------------------------------------------- test solids

/// L = [0,4]×[0,1] ∪ [0,1]×[1,3], height 1. The caps' vertex centroid (5/3, 4/3) is in the
/// notch, outside the L: each cap has two negative covering triangles.
fn l_prism() -> Mesh {
    procedural::l_prism()
}

/// A hexagonal prism (radius 1, height 1) whose top is a monkey saddle: the fan from
/// V = (0,0,1) to top corners alternately raised and lowered by `a`.
fn monkey_saddle(a: f64) -> Mesh {
    let corner = |i: u32, z: f64| {
        let f = std::f64::consts::TAU * i as f64 / 6.0;
        DVec3::new(f.cos(), f.sin(), z)
    };
    let mut p: Vec<DVec3> = (0..6).map(|i| corner(i, 0.0)).collect();
    p.extend((0..6).map(|i| corner(i, 1.0 + if i % 2 == 0 { a } else { -a })));
    p.push(DVec3::new(0.0, 0.0, 1.0));
    let mut faces = vec![(0..6u32).rev().collect::<Vec<_>>()];
    for i in 0..6u32 {
        let j = (i + 1) % 6;
        faces.push(vec![i, j, 6 + j, 6 + i]);
        faces.push(vec![12, 6 + i, 6 + j]);
    }
    Mesh::new(p, faces).unwrap()
}

/// The unit cube whose top is pushed down into a square dimple with its tip at (½,½,½).
fn dimple_cube() -> Mesh {
    let b = procedural::box_between(DVec3::ZERO, DVec3::ONE);
    let mut p = b.positions().to_vec();
    p.push(DVec3::splat(0.5));
    // Keep every face but the top (+z: 4, 5, 7, 6), replaced by a fan to the tip.
    let mut faces: Vec<Vec<u32>> = b.faces().filter(|f| f != &[4, 5, 7, 6]).map(<[u32]>::to_vec).collect();
    for (a, c) in [(4, 5), (5, 7), (7, 6), (6, 4)] {
        faces.push(vec![a, c, 8]);
    }
    Mesh::new(p, faces).unwrap()
}

/// Every model the agreement tests run on.
fn models() -> Vec<(&'static str, Mesh)> {
    vec![
        ("cube", procedural::cube()),
        ("tetrahedron", procedural::tetrahedron()),
        ("pyramid", procedural::pyramid()),
        ("sphere", procedural::sphere(8, 16)),
        ("torus", procedural::torus(1.0, 0.4, 24, 12)),
        ("knot", procedural::torus_knot()),
        ("two-cubes", procedural::two_cubes_sharing_edge()),
        ("cavity", procedural::cube_with_cavity()),
        ("l-prism", l_prism()),
        ("saddle", monkey_saddle(0.3)),
        ("dimple", dimple_cube()),
    ]
}

fn all_methods(mesh: &Mesh, options: &Options) -> Vec<Box<dyn Classifier>> {
    Method::ALL.iter().filter(|m| m.is_cpu()).map(|&m| build(m, mesh, options).unwrap()).collect()
}

/// Asserts every method classifies every point in `points` as `want`.
fn expect_all(mesh: &Mesh, options: &Options, points: &[(DVec3, Class)]) {
    for c in all_methods(mesh, options) {
        for &(p, want) in points {
            assert_eq!(c.classify(p), want, "{} at {p}", c.name());
        }
    }
}

// ---------------------------------------------------------------- Alg. 4-1 special cases

#[test]
fn cube_points_on_base_triangles_faces_and_edges_through_the_apex() {
    // The thesis' setting: apex at the origin, the centre of the cube [−1,1]³.
    let cube = procedural::cube();
    let ft = FeitoTorres::with_apex(&cube, DVec3::ZERO).unwrap();

    // On a base triangle (the +x face), on a cube edge, on a corner: OnBoundary.
    for p in [DVec3::new(1.0, 0.3, 0.2), DVec3::new(1.0, 1.0, 0.3), DVec3::ONE, DVec3::new(1.0, 0.0, 0.0)] {
        let t = ft.trace(p);
        assert_eq!(t.class, OnBoundary, "{p}: {t:?}");
        assert!(t.near_base >= 1 && t.reruns == 0, "{p}: {t:?}");
    }

    // (½, 0.2, 0.2) lies on the plane through O, the +x face's centroid (1,0,0) and its corner
    // (1,1,1): the face shared by two tetras, each adding s.
    let t = ft.trace(DVec3::new(0.5, 0.2, 0.2));
    assert_eq!((t.class, t.acc, t.side, t.interior, t.reruns), (Inside, 2, 2, 0, 0), "{t:?}");

    // Strictly inside one tetra.
    let t = ft.trace(DVec3::new(0.5, 0.1, 0.2));
    assert_eq!((t.class, t.acc, t.side, t.interior), (Inside, 2, 0, 1), "{t:?}");

    // On apex edges O–(1,1,1) (a mesh vertex) and O–(1,0,0) (a face centroid), and O itself:
    // resolved by re-running with another apex.
    for p in [DVec3::splat(0.5), DVec3::new(0.5, 0.0, 0.0), DVec3::ZERO, DVec3::splat(0.1 * APEX_BALL)] {
        let t = ft.trace(p);
        assert_eq!(t.class, Inside, "{p}: {t:?}");
        assert!(t.reruns >= 1 && !t.fallback, "{p}: {t:?}");
    }
    assert!(ft.trace(DVec3::splat(0.5)).apex_edges >= 6);

    // The thesis' vertex sets get these right: every tetra of a convex fan is positive.
    let thesis = FeitoTorres::with_options(&cube, Some(DVec3::ZERO), EdgeRule::VertexSets).unwrap();
    for p in [DVec3::splat(0.5), DVec3::new(0.5, 0.0, 0.0)] {
        let t = thesis.trace(p);
        assert_eq!((t.class, t.acc, t.reruns), (Inside, 2, 0), "{p}: {t:?}");
    }
}

#[test]
fn same_special_points_for_every_method() {
    let cube = procedural::cube();
    let options = Options { apex: Some(DVec3::ZERO), ..Options::default() };
    expect_all(
        &cube,
        &options,
        &[
            (DVec3::new(1.0, 0.3, 0.2), OnBoundary),
            (DVec3::new(1.0, 1.0, 0.3), OnBoundary),
            (DVec3::new(-1.0, -1.0, -1.0), OnBoundary),
            (DVec3::new(0.5, 0.2, 0.2), Inside),
            (DVec3::splat(0.5), Inside),
            (DVec3::ZERO, Inside),
            (DVec3::new(1.0 + 1e-6, 0.0, 0.0), Outside),
            (DVec3::new(1.0 - 1e-6, 0.0, 0.0), Inside),
            (DVec3::new(1.0 + 0.5e-9, 0.0, 0.0), OnBoundary),
            (DVec3::new(f64::NAN, 0.0, 0.0), Outside),
        ],
    );
}

#[test]
fn flat_tetras_send_points_to_a_rerun() {
    // Apex inside the bar of the L, in the plane x = 1 of the arm's wall: that wall's
    // tetras are flat, and points between the apex and the wall lie in them.
    let l = l_prism();
    let apex = DVec3::new(1.0, 0.5, 0.25);
    let ft = FeitoTorres::with_apex(&l, apex).unwrap();
    let t = ft.trace(DVec3::new(1.0, 0.8, 0.375));
    assert_eq!(t.class, Inside, "{t:?}");
    assert!(t.flat >= 1 && t.reruns >= 1, "{t:?}");
    let t = ft.trace(DVec3::new(1.0, 2.0, 0.375));
    assert_eq!(t.class, OnBoundary, "{t:?}");
    let options = Options { apex: Some(apex), ..Options::default() };
    expect_all(
        &l,
        &options,
        &[
            (DVec3::new(1.0, 0.8, 0.375), Inside),
            (DVec3::new(1.0, 1.5, 0.5), OnBoundary),
            (DVec3::new(1.0, 3.0, 1.0), OnBoundary),
            (DVec3::new(1.5, 1.5, 0.5), Outside),
        ],
    );
    agree_with_oracle(&l, &options, 2_000, 11);
}

#[test]
fn mesh_vertices_edges_and_faces_are_on_the_boundary() {
    for (name, mesh) in models() {
        let mut points: Vec<DVec3> = mesh.positions().to_vec();
        for f in mesh.faces() {
            let at = |i: usize| mesh.positions()[f[i] as usize];
            // The centroid of the first three corners is on the face (the L caps' vertex
            // centroid is not: it is in the notch).
            points.push((at(0) + at(1) + at(2)) / 3.0);
            points.push((at(0) + at(1)) * 0.5);
        }
        for c in all_methods(&mesh, &Options::default()) {
            for &p in &points {
                assert_eq!(c.classify(p), OnBoundary, "{name}: {} at {p}", c.name());
            }
        }
    }
}

// ---------------------------------------------------------------- non-convex polygon faces

#[test]
fn non_convex_caps_are_covered_with_negative_triangles() {
    let l = l_prism();
    // (1.7, 1.25) is in the notch, under both a positive and a negative covering triangle
    // of the caps (coverage +1 −1 = 0): in the cap's plane it is NOT on the boundary — the
    // thesis' "P ∈ T → return" would say it is.
    expect_all(
        &l,
        &Options::default(),
        &[
            (DVec3::new(1.7, 1.25, 1.0), Outside),
            (DVec3::new(1.7, 1.25, 0.0), Outside),
            (DVec3::new(1.7, 1.25, 0.5), Outside),
            (DVec3::new(5.0 / 3.0, 4.0 / 3.0, 1.0), Outside),
            (DVec3::new(0.5, 2.0, 1.0), OnBoundary),
            (DVec3::new(3.0, 0.5, 0.0), OnBoundary),
            (DVec3::new(1.0, 2.0, 0.5), OnBoundary),
            (DVec3::new(3.0, 1.0, 0.5), OnBoundary),
            (DVec3::new(3.0, 0.5, 0.5), Inside),
            (DVec3::new(0.5, 2.5, 0.5), Inside),
            (DVec3::new(0.5, 0.5, 0.5), Inside),
        ],
    );
    // Same with the apex in the cap's plane, so the cap's tetras are flat.
    let options = Options { apex: Some(DVec3::new(0.5, 0.5, 1.0)), ..Options::default() };
    expect_all(
        &l,
        &options,
        &[
            (DVec3::new(1.7, 1.25, 1.0), Outside),
            (DVec3::new(0.5, 2.0, 1.0), OnBoundary),
            (DVec3::new(3.0, 0.5, 0.5), Inside),
        ],
    );
}

#[test]
fn non_convex_caps_of_a_rotated_prism() {
    // Rotated, the caps' planes are no longer axis-aligned, so points in them sit within
    // rounding of the plane, on either side depending on which triangle's normal is used:
    // the positive and negative triangles over the notch must still cancel.
    let rot = glam::DMat3::from_axis_angle(DVec3::new(1.0, 2.0, 3.0).normalize(), 0.7);
    let l = l_prism().map_positions(|p| rot * p).unwrap();
    let mut points = Vec::new();
    for i in 0..20 {
        for j in 0..20 {
            // The notch square (1,4)×(1,3) near the covering's centroid, in both cap planes.
            let (x, y) = (1.02 + 0.05 * i as f64, 1.01 + 0.05 * j as f64);
            points.push((rot * DVec3::new(x, y, 1.0), Outside));
            points.push((rot * DVec3::new(x, y, 0.0), Outside));
            points.push((rot * DVec3::new(x - 1.0, y - 1.0, 1.0), OnBoundary));
        }
    }
    expect_all(&l, &Options::default(), &points);
}

// ---------------------------------------------------------------- the vertex-set rule

/// Thesis rule, exact rule and oracle at P, the midpoint of the apex `o` and vertex `v`.
fn apex_edge_case(mesh: &Mesh, o: DVec3, v: DVec3) -> (Class, Class, Class) {
    let p = (o + v) * 0.5;
    let thesis = FeitoTorres::with_options(mesh, Some(o), EdgeRule::VertexSets).unwrap();
    let exact = FeitoTorres::with_options(mesh, Some(o), EdgeRule::Rerun).unwrap();
    let t = thesis.trace(p);
    assert!(t.apex_edges > 0 && t.reruns == 0, "P must be on the apex edge: {t:?}");
    let oracle = WindingNumber::new(mesh).unwrap().classify(p);
    (thesis.classify(p), exact.classify(p), oracle)
}

#[test]
fn vertex_set_rule_fails_at_a_non_manifold_vertex() {
    // O in the first cube, V = (1,1,0) an end of the shared edge. The first cube's fan at V
    // is all positive (winds once), the second cube's is mixed (winds zero times): the
    // exact contribution is 2, the rule adds +2 −2 = 0.
    let two = procedural::two_cubes_sharing_edge();
    let (thesis, exact, oracle) = apex_edge_case(&two, DVec3::splat(0.5), DVec3::new(1.0, 1.0, 0.0));
    assert_eq!(oracle, Inside);
    assert_eq!(exact, Inside);
    assert_eq!(thesis, Outside, "the vertex-set rule is wrong here (see inclusion::cpu docs)");
    // Every Feito-Torres variant resolves it exactly with this apex.
    let options = Options { apex: Some(DVec3::splat(0.5)), ..Options::default() };
    expect_all(
        &two,
        &options,
        &[(DVec3::new(0.75, 0.75, 0.25), Inside), (DVec3::new(1.25, 1.25, 0.25), Inside)],
    );
}

#[test]
fn vertex_set_rule_fails_at_a_saddle_vertex() {
    // Seen from O (beside and a little below the saddle point V), the fan's tetras are
    // + − + + − +, yet the link winds once around O–V: the rule adds 0 instead of 2.
    let saddle = monkey_saddle(0.3);
    let v = DVec3::new(0.0, 0.0, 1.0);
    for (psi, slope) in [(30.0f64, 0.2), (45.0, 0.2), (20.0, 0.3)] {
        let psi = psi.to_radians();
        let o = v + 0.5 * DVec3::new(psi.cos(), psi.sin(), -slope);
        let (thesis, exact, oracle) = apex_edge_case(&saddle, o, v);
        assert_eq!(oracle, Inside);
        assert_eq!(exact, Inside);
        assert_eq!(thesis, Outside, "the vertex-set rule is wrong here (see inclusion::cpu docs)");
        expect_all(&saddle, &Options { apex: Some(o), ..Options::default() }, &[((o + v) * 0.5, Inside)]);
    }
}

#[test]
fn vertex_set_rule_holds_for_convex_and_folded_but_unwound_fans() {
    // Convex fan (a cube corner seen from the centre) and mixed fans whose link does not
    // wind around the apex edge (k = 0): the L's reflex corner seen from inside its bar,
    // the dimple's tip seen from its side. The rule's +2 −2 = 0 is right there.
    let cases = [
        (procedural::cube(), DVec3::new(0.1, -0.2, 0.3), DVec3::ONE),
        (l_prism(), DVec3::new(2.5, 0.5, 0.5), DVec3::new(1.0, 1.0, 0.0)),
        (l_prism(), DVec3::new(0.5, 2.25, 0.75), DVec3::new(1.0, 1.0, 1.0)),
        (dimple_cube(), DVec3::new(0.1, 0.45, 0.3), DVec3::splat(0.5)),
    ];
    for (mesh, o, v) in cases {
        let (thesis, exact, oracle) = apex_edge_case(&mesh, o, v);
        assert_eq!((thesis, exact), (oracle, oracle), "o {o} v {v}");
        assert_eq!(oracle, Inside);
    }
}

// ---------------------------------------------------------------- topology

#[test]
fn two_cubes_sharing_an_edge() {
    let two = procedural::two_cubes_sharing_edge();
    expect_all(
        &two,
        &Options::default(),
        &[
            (DVec3::new(1.0, 1.0, 0.5), OnBoundary),
            (DVec3::new(1.0, 1.0, 0.0), OnBoundary),
            (DVec3::new(1.001, 1.001, 0.5), Inside),
            (DVec3::new(0.999, 0.999, 0.5), Inside),
            (DVec3::new(0.999, 1.001, 0.5), Outside),
            (DVec3::new(1.001, 0.999, 0.5), Outside),
            (DVec3::new(1.5, 0.5, 0.5), Outside),
        ],
    );
}

#[test]
fn torus_hole_and_cavity() {
    let torus = procedural::torus(1.0, 0.4, 24, 12);
    expect_all(
        &torus,
        &Options::default(),
        &[
            (DVec3::ZERO, Outside),
            (DVec3::new(0.0, 0.0, 0.3), Outside),
            (DVec3::new(1.0, 0.0, 0.0), Inside),
            (DVec3::new(0.0, -1.0, 0.2), Inside),
            (DVec3::new(1.4, 0.0, 0.0), OnBoundary),
        ],
    );
    let cavity = procedural::cube_with_cavity();
    expect_all(
        &cavity,
        &Options::default(),
        &[
            (DVec3::ZERO, Outside),
            (DVec3::new(0.5, -0.3, 0.9), Outside),
            (DVec3::new(1.5, 0.0, 0.0), Inside),
            (DVec3::new(-1.5, 1.9, -1.2), Inside),
            (DVec3::new(1.0, 0.0, 0.0), OnBoundary),
            (DVec3::new(1.0, 0.5, -1.0), OnBoundary),
            (DVec3::new(2.0, 0.5, -1.0), OnBoundary),
        ],
    );
}

#[test]
fn open_or_inconsistent_meshes_are_rejected() {
    let cube = procedural::cube();
    let mut faces: Vec<Vec<u32>> = cube.faces().map(<[u32]>::to_vec).collect();
    let open = Mesh::new(cube.positions().to_vec(), faces[1..].to_vec()).unwrap();
    faces[3].reverse();
    let flipped = Mesh::new(cube.positions().to_vec(), faces).unwrap();
    for mesh in [open, flipped] {
        for m in Method::ALL.into_iter().filter(|m| m.is_cpu()) {
            let e = build(m, &mesh, &Options::default()).err().unwrap();
            assert!(matches!(e, InclusionError::NotClosed { .. }), "{m}: {e}");
            assert!(e.to_string().contains("not closed"), "{e}");
        }
    }
    let o = Options { tetragrid_resolution: 65, ..Options::default() };
    assert!(matches!(build(Method::TetraGrid, &procedural::cube(), &o), Err(InclusionError::Resolution(65))));
}

// ---------------------------------------------------------------- agreement

/// Every method against the winding-number oracle on `n` random points in the bounding
/// box grown by 10% (points classified OnBoundary by one method must be by all).
fn agree_with_oracle(mesh: &Mesh, options: &Options, n: usize, seed: u64) -> [usize; 3] {
    let (lo, hi) = mesh.bounds();
    let pad = (hi - lo) * 0.1;
    let points = Rng::new(seed).points_in_box(n, lo - pad, hi + pad);
    let oracle = WindingNumber::new(mesh).unwrap().classify_all(&points);
    for c in all_methods(mesh, options) {
        let got = c.classify_all(&points);
        for (i, (g, w)) in got.iter().zip(&oracle).enumerate() {
            assert_eq!(g, w, "{} disagrees with the oracle at {}", c.name(), points[i]);
        }
    }
    let mut counts = [0; 3];
    oracle.iter().for_each(|&c| counts[c as usize] += 1);
    counts
}

#[test]
fn all_methods_agree_with_the_oracle_on_random_points() {
    for (i, (name, mesh)) in models().into_iter().enumerate() {
        let [out, inside, _] = agree_with_oracle(&mesh, &Options::default(), 10_000, 1000 + i as u64);
        assert!(out > 500 && inside > 500, "{name}: {out} outside, {inside} inside");
    }
}

/// Points on covering triangles, on their edges and at their corners, moved off by 0,
/// ±ε/2, ±3ε or ±1000ε along the normal or a random direction: the tolerance zone where
/// the methods' decisions are the hardest to keep consistent.
fn near_surface_points(mesh: &Mesh, n: usize, seed: u64) -> Vec<DVec3> {
    let surface = texgeo::inclusion::Surface::new(mesh).unwrap();
    let (cov, eps) = (surface.covering(), surface.eps());
    let mut rng = Rng::new(seed);
    (0..n)
        .map(|_| {
            let [a, b, c] = cov.triangle(rng.below(cov.triangles.len() as u64) as usize);
            let (mut u, mut v) = (rng.next_f64(), rng.next_f64());
            match rng.below(4) {
                0 => u = 0.0,
                1 => (u, v) = (0.0, 0.0),
                _ => {}
            }
            if u + v > 1.0 {
                (u, v) = (1.0 - u, 1.0 - v);
            }
            let x = a + (b - a) * u + (c - a) * v;
            let off = [0.0, 0.5, -0.5, 3.0, -3.0, 1e3, -1e3][rng.below(7) as usize] * eps;
            let dir = if rng.below(2) == 0 {
                (b - a).cross(c - a).normalize_or_zero()
            } else {
                rng.point_in_box(DVec3::NEG_ONE, DVec3::ONE).normalize_or_zero()
            };
            x + dir * off
        })
        .collect()
}

#[test]
fn all_methods_agree_near_the_surface() {
    let rot = glam::DMat3::from_axis_angle(DVec3::new(1.0, 2.0, 3.0).normalize(), 0.7);
    let models = [
        l_prism().map_positions(|p| rot * p).unwrap(),
        procedural::two_cubes_sharing_edge(),
        procedural::torus_knot(),
        procedural::pyramid(),
        monkey_saddle(0.3),
    ];
    for (i, mesh) in models.iter().enumerate() {
        let points = near_surface_points(mesh, 1500, 50 + i as u64);
        let oracle = WindingNumber::new(mesh).unwrap().classify_all(&points);
        assert!(oracle.contains(&OnBoundary) && oracle.contains(&Inside) && oracle.contains(&Outside));
        // The default apex, and the apex on a mesh vertex (many flat tetras).
        for apex in [None, Some(mesh.positions()[0])] {
            for c in all_methods(mesh, &Options { apex, ..Options::default() }) {
                let got = c.classify_all(&points);
                for (k, (g, w)) in got.iter().zip(&oracle).enumerate() {
                    assert_eq!(g, w, "model {i}, apex {apex:?}: {} at {}", c.name(), points[k]);
                }
            }
        }
    }
}

#[test]
fn agreement_with_the_apex_on_a_vertex_or_outside() {
    // The thesis' origin apex on a corner of the cube [0,1]³ (three faces' tetras flat), and
    // apexes outside the solid (the torus' hole, beyond the knot).
    agree_with_oracle(
        &procedural::box_between(DVec3::ZERO, DVec3::ONE),
        &Options { apex: Some(DVec3::ZERO), ..Options::default() },
        3_000,
        7,
    );
    agree_with_oracle(
        &procedural::torus(1.0, 0.4, 24, 12),
        &Options { apex: Some(DVec3::ZERO), ..Options::default() },
        3_000,
        8,
    );
    agree_with_oracle(
        &procedural::torus_knot(),
        &Options { apex: Some(DVec3::new(3.5, 0.0, 0.0)), ..Options::default() },
        3_000,
        9,
    );
}

#[test]
fn tetragrid_resolutions_and_cells() {
    let knot = procedural::torus_knot();
    let (lo, hi) = knot.bounds();
    let points = Rng::new(5).points_in_box(2_000, lo, hi);
    let cpu = FeitoTorres::new(&knot).unwrap();
    let want = cpu.classify_all(&points);
    let mut bytes = 0;
    for n in [2, 5, 32, 64] {
        let grid = GridClassifier::new(FeitoTorres::new(&knot).unwrap(), n).unwrap();
        assert_eq!(grid.classify_all(&points), want, "n = {n}");
        // Every tetra that does not answer Outside for p is listed in p's cell.
        let eps = cpu.surface().eps();
        for &p in points.iter().take(200) {
            let q = p - cpu.apex();
            let bit = texgeo::inclusion::tetra::octant_bit(q);
            let listed = grid.cell_tetras(grid.cell_of(p).unwrap());
            for (t, tp) in cpu.tetras().iter().enumerate() {
                if tp.verdict(q, bit, eps) != texgeo::inclusion::tetra::Verdict::Outside {
                    assert!(listed.binary_search(&(t as u32)).is_ok(), "n = {n}: tetra {t} missing for {p}");
                }
            }
        }
        assert_eq!(grid.cell_of(hi + (hi - lo)), None);
        let b = grid.index_stats().bytes;
        assert!(b > bytes, "memory must grow with n");
        bytes = b;
    }
}

#[test]
fn gpu_upload_arrays_match_the_covering() {
    let sphere = procedural::sphere(8, 16);
    let ft = FeitoTorres::new(&sphere).unwrap();
    let (q, sign) = ft.flat_arrays();
    assert_eq!(q.len(), 9 * sign.len());
    assert_eq!(sign.len(), ft.surface().covering().triangles.len());
    // Σ s·|V| over the tetras is the volume (Alg. 3-1 from the uploaded data, in f32).
    let vol: f64 = q
        .chunks(9)
        .zip(&sign)
        .map(|(c, &s)| {
            let v = |i: usize| DVec3::new(c[i] as f64, c[i + 1] as f64, c[i + 2] as f64);
            s as f64 * v(0).dot(v(3).cross(v(6))).abs() / 6.0
        })
        .sum();
    let want = ft.surface().covering().volume();
    assert!((vol - want).abs() < 1e-5 * want, "{vol} vs {want}");
    for c in all_methods(&sphere, &Options::default()) {
        assert!(c.build_stats().bytes > 0, "{}", c.name());
    }
}

#[test]
fn an_empty_mesh_holds_nothing() {
    let empty = Mesh::new(Vec::new(), Vec::new()).unwrap();
    for c in all_methods(&empty, &Options::default()) {
        assert_eq!(c.classify_all(&[DVec3::ZERO, DVec3::ONE]), vec![Outside, Outside], "{}", c.name());
    }
}

// ---------------------------------------------------------------- voxel space, auto, threads

/// Points spread over the box, near the surface, and on mesh vertices.
fn mixed_points(mesh: &Mesh, seed: u64) -> Vec<DVec3> {
    let (lo, hi) = mesh.bounds();
    let pad = (hi - lo) * 0.1;
    let mut pts = Rng::new(seed).points_in_box(1500, lo - pad, hi + pad);
    pts.extend(near_surface_points(mesh, 1500, seed + 1));
    pts.extend_from_slice(mesh.positions());
    pts
}

#[test]
fn voxel_space_at_any_resolution_and_auto_label_as_cpu() {
    let rot = glam::DMat3::from_axis_angle(DVec3::new(1.0, 2.0, 3.0).normalize(), 0.7);
    let mut solids = models();
    solids.push(("rotated l-prism", l_prism().map_positions(|p| rot * p).unwrap()));
    for (k, (name, mesh)) in solids.into_iter().enumerate() {
        // At the origin and translated far from it (the grid's cells are then few ulps
        // wide relative to the coordinates).
        for shift in [DVec3::ZERO, DVec3::new(1e7, -3e6, 5e5) + 0.25] {
            let mesh = mesh.map_positions(|p| p + shift).unwrap();
            let pts = mixed_points(&mesh, 300 + k as u64);
            let want = build(Method::Cpu, &mesh, &Options::default()).unwrap().classify_all(&pts);
            for n in [2, 3, 5, 16, 61] {
                let options = Options { voxel_space_resolution: Some(n), ..Options::default() };
                let got = build(Method::VoxelSpace, &mesh, &options).unwrap().classify_all(&pts);
                for (i, (g, w)) in got.iter().zip(&want).enumerate() {
                    assert_eq!(g, w, "{name} + {shift}, voxel-space {n}³, at {}", pts[i]);
                }
            }
            for points in [0, 1_000, 1_000_000] {
                let options = Options { points, ..Options::default() };
                let got = build(texgeo::inclusion::Choice::Auto, &mesh, &options).unwrap().classify_all(&pts);
                assert_eq!(got, want, "{name} + {shift}: auto for {points} points");
            }
        }
    }
}

#[test]
fn the_labels_do_not_depend_on_the_number_of_threads() {
    let mesh = procedural::torus_knot();
    let pts = mixed_points(&mesh, 77);
    for m in Method::ALL.into_iter().filter(|m| m.is_cpu()) {
        let c = build(m, &mesh, &Options { points: pts.len(), ..Options::default() }).unwrap();
        let runs: Vec<Vec<Class>> = [1, 2, 3]
            .into_iter()
            .map(|threads| {
                let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
                pool.install(|| c.classify_all(&pts))
            })
            .collect();
        assert!(runs.iter().all(|r| *r == runs[0]), "{m}");
        let one_by_one: Vec<Class> = pts.iter().map(|&p| c.classify(p)).collect();
        assert_eq!(runs[0], one_by_one, "{m}");
    }
}

/// The solver streams a point source block by block with the answers of one call on all
/// the points, and says when the source is done.
#[test]
fn a_solver_streams_what_it_answers_at_once() {
    use texgeo::inclusion::points::PointReader;
    use texgeo::inclusion::solver::Solver;
    let mesh = procedural::torus_knot();
    let (lo, hi) = mesh.bounds();
    let points = Rng::new(3).points_in_box(500, lo, hi);
    for method in [Method::Cpu, Method::Octants] {
        let mut solver = Solver::new(method, &mesh, &Options::default(), None, None).unwrap();
        let whole = solver.classify_all(&points).unwrap();
        let mut source = PointReader::from_points(points.clone(), "points");
        let mut streamed = Vec::new();
        while let Some(parts) = solver.classify_next(&mut source).unwrap() {
            streamed.extend(parts.into_iter().flatten());
        }
        assert_eq!(streamed, whole, "{method}");
        assert_eq!(solver.name(), method.name());
    }
}
