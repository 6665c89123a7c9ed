//! Validation reports of the procedural models and of small broken meshes.

use std::collections::BTreeMap;

use glam::DVec3;
use texgeo::mesh::procedural::{self, BUILTIN_NAMES};
use texgeo::mesh::{Mesh, Report, validate};

/// Signed volume by the divergence theorem over fan triangles (positive = outward).
fn volume(mesh: &Mesh) -> f64 {
    let p = mesh.positions();
    mesh.faces()
        .flat_map(|f| f.windows(2).skip(1).map(move |w| (f[0], w[0], w[1])))
        .map(|(a, b, c)| p[a as usize].dot(p[b as usize].cross(p[c as usize])) / 6.0)
        .sum()
}

/// Volumes summed from many tetrahedra: equal up to rounding.
fn assert_close(got: f64, want: f64) {
    assert!((got - want).abs() <= 1e-12 * want.abs().max(1.0), "{got} != {want}");
}

fn degrees(pairs: &[(usize, usize)]) -> BTreeMap<usize, usize> {
    pairs.iter().copied().collect()
}

/// A closed, oriented, manifold model with the given counts.
fn assert_solid(r: &Report, v: usize, e: usize, f: usize, chi: i64, components: usize) {
    assert_eq!((r.vertices, r.edges, r.faces), (v, e, f), "{r}");
    assert_eq!(r.euler_characteristic, chi, "{r}");
    assert_eq!(r.components, components, "{r}");
    assert!(r.is_closed() && r.is_oriented() && r.is_manifold(), "{r}");
    assert_eq!(
        (r.boundary_edges, r.non_manifold_edges, r.misoriented_edges, r.non_manifold_vertices),
        (0, 0, 0, 0)
    );
    assert_eq!((r.degenerate_faces, r.unused_vertices), (0, 0), "{r}");
}

#[test]
fn cube() {
    let m = procedural::cube();
    let r = m.report();
    assert_solid(&r, 8, 12, 6, 2, 1);
    assert_eq!(r.face_degrees, degrees(&[(4, 6)]));
    assert_eq!(r.genus(), Some(0));
    assert_close(volume(&m), 8.0);
    assert_eq!(m.bounds(), (DVec3::splat(-1.0), DVec3::splat(1.0)));
}

#[test]
fn tetrahedron_and_pyramid() {
    let t = procedural::tetrahedron();
    let r = t.report();
    assert_solid(&r, 4, 6, 4, 2, 1);
    assert_eq!(r.face_degrees, degrees(&[(3, 4)]));
    assert!((volume(&t) - 8.0 / 3.0).abs() < 1e-12);

    let p = procedural::pyramid();
    let r = p.report();
    assert_solid(&r, 5, 8, 5, 2, 1);
    assert_eq!(r.face_degrees, degrees(&[(3, 4), (4, 1)]));
    assert!((volume(&p) - 8.0 / 3.0).abs() < 1e-12);
}

#[test]
fn sphere() {
    let m = procedural::sphere(16, 32);
    let r = m.report();
    assert_solid(&r, 2 + 15 * 32, 992, 512, 2, 1);
    assert_eq!(r.face_degrees, degrees(&[(3, 64), (4, 448)]));
    // Inscribed polyhedron: a little under 4π/3.
    let v = volume(&m);
    assert!(v > 4.0 && v < 4.0 * std::f64::consts::PI / 3.0, "{v}");
    assert!(m.positions().iter().all(|p| (p.length() - 1.0).abs() < 1e-12));
    // Smallest sphere: two caps of triangles only.
    assert_solid(&procedural::sphere(2, 3).report(), 5, 9, 6, 2, 1);
}

#[test]
fn torus_is_genus_one_with_valence_four() {
    let m = procedural::torus(1.0, 0.4, 32, 16);
    let r = m.report();
    assert_solid(&r, 512, 1024, 512, 0, 1);
    assert_eq!(r.face_degrees, degrees(&[(4, 512)]));
    assert_eq!(r.genus(), Some(1));
    let mut valence = vec![0; m.num_vertices()];
    for f in m.faces() {
        for &i in f {
            valence[i as usize] += 1;
        }
    }
    assert!(valence.iter().all(|&v| v == 4));
    let exact = 2.0 * std::f64::consts::PI.powi(2) * 1.0 * 0.4 * 0.4;
    assert!((volume(&m) - exact).abs() < 0.05 * exact);
}

#[test]
fn torus_knot_like_the_thesis() {
    let m = procedural::torus_knot();
    let r = m.report();
    assert_solid(&r, 600, 1800, 1200, 0, 1);
    assert_eq!(r.face_degrees, degrees(&[(3, 1200)]));
    assert_eq!(r.genus(), Some(1));
    // Tube of radius 0.4 around a curve about 31.9 long: volume close to π·0.4²·31.9.
    let v = volume(&m);
    let tube = std::f64::consts::PI * 0.16 * 31.9;
    assert!(v > 0.85 * tube && v < tube, "{v} vs {tube}");
}

#[test]
fn two_cubes_sharing_an_edge_are_closed_but_not_manifold() {
    let m = procedural::two_cubes_sharing_edge();
    let r = m.report();
    assert_eq!((r.vertices, r.edges, r.faces), (14, 23, 12));
    assert_eq!(r.euler_characteristic, 3);
    assert!(r.is_closed() && r.is_oriented());
    assert!(!r.is_manifold());
    assert_eq!(r.non_manifold_edges, 1);
    assert_eq!(r.non_manifold_vertices, 2);
    assert_eq!(r.components, 1);
    assert_eq!(r.genus(), None);
    assert_close(volume(&m), 2.0);
}

#[test]
fn cube_with_cavity() {
    let m = procedural::cube_with_cavity();
    let r = m.report();
    assert_solid(&r, 16, 24, 12, 4, 2);
    assert_eq!(r.genus(), Some(0));
    assert_close(volume(&m), 64.0 - 8.0);
}

#[test]
fn box_between() {
    let m = procedural::box_between(DVec3::new(1.0, 2.0, 3.0), DVec3::new(2.0, 4.0, 7.0));
    assert_solid(&m.report(), 8, 12, 6, 2, 1);
    assert_close(volume(&m), 8.0);
}

#[test]
fn every_builtin_has_positive_volume_and_unit_scale() {
    for name in BUILTIN_NAMES {
        let m = procedural::by_name(name).unwrap_or_else(|| panic!("{name} is listed but unknown"));
        let r = m.report();
        assert!(r.is_closed() && r.is_oriented(), "{name}: {r}");
        assert_eq!(r.degenerate_faces, 0, "{name}");
        assert!(volume(&m) > 0.0, "{name} is inside out");
    }
    assert!(procedural::by_name("teapot").is_none());
}

/// The cube with its faces replaced by `faces`.
fn cube_with(faces: Vec<Vec<u32>>) -> Mesh {
    Mesh::new(procedural::cube().positions().to_vec(), faces).unwrap()
}

fn cube_faces() -> Vec<Vec<u32>> {
    procedural::cube().faces().map(<[u32]>::to_vec).collect()
}

#[test]
fn a_hole_makes_the_mesh_open() {
    let mut faces = cube_faces();
    faces.pop();
    let r = cube_with(faces).report();
    assert_eq!(r.boundary_edges, 4);
    assert_eq!(r.misoriented_edges, 0);
    assert!(!r.is_closed());
    assert!(r.is_oriented() && r.is_manifold(), "{r}");
    assert_eq!(r.euler_characteristic, 1);
    assert_eq!(r.genus(), None);
}

#[test]
fn a_flipped_face_is_misoriented() {
    let mut faces = cube_faces();
    faces[2].reverse();
    let r = cube_with(faces).report();
    assert_eq!(r.misoriented_edges, 4);
    assert_eq!(r.boundary_edges, 0);
    assert!(!r.is_oriented() && !r.is_closed());
    assert!(r.is_manifold());
    assert_eq!(r.euler_characteristic, 2);
}

#[test]
fn degenerate_faces() {
    // A repeated index, a collinear triangle, and a fine triangle.
    let positions = vec![
        DVec3::new(0.0, 0.0, 0.0),
        DVec3::new(1.0, 0.0, 0.0),
        DVec3::new(2.0, 0.0, 0.0),
        DVec3::new(0.0, 1.0, 0.0),
    ];
    let m = Mesh::new(positions, vec![vec![0, 1, 0, 3], vec![0, 1, 2], vec![0, 1, 3]]).unwrap();
    let r = m.report();
    assert_eq!(r.degenerate_faces, 2);
    // A repeated index far apart in a large face.
    let n = 12u32;
    let ring: Vec<DVec3> = (0..n)
        .map(|i| {
            let t = f64::from(i) * std::f64::consts::TAU / f64::from(n);
            DVec3::new(t.cos(), t.sin(), 0.0)
        })
        .collect();
    let mut face: Vec<u32> = (0..n).collect();
    face.push(5);
    let r = Mesh::new(ring, vec![face]).unwrap().report();
    assert_eq!(r.degenerate_faces, 1);
}

#[test]
fn huge_coordinates_do_not_overflow_the_area_test() {
    let big = f64::MAX / 2.0;
    let positions = vec![DVec3::new(-big, -big, 0.0), DVec3::new(big, -big, 0.0), DVec3::new(0.0, big, 0.0)];
    let r = Mesh::new(positions.clone(), vec![vec![0, 1, 2]]).unwrap().report();
    assert_eq!(r.degenerate_faces, 0);
    let flat = vec![positions[0], positions[1], DVec3::new(0.0, -big, 0.0)];
    assert_eq!(Mesh::new(flat, vec![vec![0, 1, 2]]).unwrap().report().degenerate_faces, 1);
}

#[test]
fn two_tetrahedra_touching_at_a_vertex() {
    let t = procedural::tetrahedron();
    let mut positions = t.positions().to_vec();
    // Second copy mirrored through vertex 0, sharing it.
    let apex = positions[0];
    positions.extend(t.positions()[1..].iter().map(|&p| 2.0 * apex - p));
    let mut faces: Vec<Vec<u32>> = t.faces().map(<[u32]>::to_vec).collect();
    // Point reflection keeps orientation; vertex i (i > 0) of the copy is 3 + i.
    faces.extend(t.faces().map(|f| f.iter().map(|&i| if i == 0 { 0 } else { 3 + i }).collect()));
    let r = Mesh::new(positions, faces).unwrap().report();
    assert_eq!(r.non_manifold_vertices, 1);
    assert_eq!(r.non_manifold_edges, 0);
    assert!(r.is_closed() && r.is_oriented() && !r.is_manifold(), "{r}");
    assert_eq!(r.components, 1);
    assert_eq!(r.euler_characteristic, 3);
}

#[test]
fn unused_vertices_do_not_count() {
    let mut positions = procedural::cube().positions().to_vec();
    positions.push(DVec3::splat(5.0));
    let r = Mesh::new(positions, cube_faces()).unwrap().report();
    assert_eq!(r.unused_vertices, 1);
    assert_eq!(r.vertices, 9);
    assert_eq!(r.euler_characteristic, 2);
    assert_eq!(r.components, 1);
}

#[test]
fn display_summarizes() {
    let text = procedural::two_cubes_sharing_edge().report().to_string();
    for want in ["vertices", "14", "23", "1 non-manifold", "closed: yes", "oriented: yes", "manifold: no"] {
        assert!(text.contains(want), "missing '{want}' in:\n{text}");
    }
    let text = procedural::torus_knot().report().to_string();
    assert!(text.contains("1200×3-gon") && text.contains("genus 1"), "{text}");
    assert_eq!(validate::report(&procedural::cube()), procedural::cube().report());
}

#[test]
fn empty_mesh() {
    let r = Mesh::new(vec![], vec![]).unwrap().report();
    assert_eq!((r.vertices, r.faces, r.edges, r.components, r.euler_characteristic), (0, 0, 0, 0, 0));
    assert!(r.is_closed());
}

/// The report of random small meshes (repeated indices, shared edges, stray vertices)
/// against a slow, obvious recount.
#[test]
fn random_meshes_match_a_naive_recount() {
    use std::collections::{BTreeMap, BTreeSet};
    use texgeo::random::Rng;
    let mut rng = Rng::new(42);
    for _ in 0..300 {
        let nv = 3 + rng.below(10) as usize;
        let positions: Vec<DVec3> =
            (0..nv).map(|_| DVec3::new(rng.next_f64(), rng.next_f64(), rng.next_f64())).collect();
        let faces: Vec<Vec<u32>> = (0..1 + rng.below(14))
            .map(|_| (0..3 + rng.below(3)).map(|_| rng.below(nv as u64) as u32).collect())
            .collect();
        let r = Mesh::new(positions, faces.clone()).unwrap().report();

        // Half-edge counts per undirected edge.
        let mut half: BTreeMap<(u32, u32), [u32; 2]> = BTreeMap::new();
        for f in &faces {
            for k in 0..f.len() {
                let (a, b) = (f[k], f[(k + 1) % f.len()]);
                if a != b {
                    half.entry((a.min(b), a.max(b))).or_default()[usize::from(a > b)] += 1;
                }
            }
        }
        let boundary = half.values().filter(|c| c[0] + c[1] == 1).count();
        let non_manifold = half.values().filter(|c| c[0] + c[1] > 2).count();
        let misoriented = half.values().filter(|c| c[0] + c[1] >= 2 && c[0] != c[1]).count();
        assert_eq!((r.edges, r.boundary_edges), (half.len(), boundary));
        assert_eq!((r.non_manifold_edges, r.misoriented_edges), (non_manifold, misoriented));

        // Fans: corners at v linked when they share a neighbour across an edge side.
        let mut bad_vertices = 0;
        for v in 0..nv as u32 {
            let mut sides: Vec<BTreeSet<u32>> = Vec::new();
            for f in &faces {
                for k in 0..f.len() {
                    if f[k] == v {
                        let n = f.len();
                        let set: BTreeSet<u32> =
                            [f[(k + n - 1) % n], f[(k + 1) % n]].into_iter().filter(|&w| w != v).collect();
                        sides.push(set);
                    }
                }
            }
            let mut group: Vec<usize> = (0..sides.len()).collect();
            let mut changed = true;
            while changed {
                changed = false;
                for i in 0..sides.len() {
                    for j in 0..sides.len() {
                        if group[i] < group[j] && !sides[i].is_disjoint(&sides[j]) {
                            group[j] = group[i];
                            changed = true;
                        }
                    }
                }
            }
            let fans = group.iter().collect::<BTreeSet<_>>().len();
            let on_bad_edge = half.iter().any(|(&(a, b), c)| (a == v || b == v) && c[0] + c[1] > 2);
            if fans > 1 || on_bad_edge {
                bad_vertices += 1;
            }
        }
        assert_eq!(r.non_manifold_vertices, bad_vertices, "{faces:?}");

        let used: BTreeSet<u32> = faces.iter().flatten().copied().collect();
        assert_eq!(r.unused_vertices, nv - used.len());
        assert_eq!(r.euler_characteristic, used.len() as i64 - half.len() as i64 + faces.len() as i64);
        assert_eq!(r.face_degrees.values().sum::<usize>(), faces.len());
        let repeats = faces.iter().filter(|f| f.iter().collect::<BTreeSet<_>>().len() < f.len()).count();
        assert!(r.degenerate_faces >= repeats);
    }
}
