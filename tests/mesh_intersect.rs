//! Self-intersection detection (`mesh::intersect`): crossing shells, folds and
//! self-crossing polygons are found; faces that only share vertices or edges (also
//! non-manifold ones, also through duplicated vertices) are not; built-ins are clean.

use glam::DVec3;
use texgeo::mesh::intersect::{self, self_intersections};
use texgeo::mesh::{Mesh, procedural};

fn merged(parts: &[Mesh]) -> Mesh {
    // Shells stacked in one mesh WITHOUT welding: vertices at equal positions stay
    // separate, as in a file that lists each shell on its own.
    let mut positions = Vec::new();
    let mut faces = Vec::new();
    for m in parts {
        let base = positions.len() as u32;
        positions.extend_from_slice(m.positions());
        faces.extend(m.faces().map(|f| f.iter().map(|&i| i + base).collect::<Vec<u32>>()));
    }
    Mesh::new(positions, faces).unwrap()
}

fn boxed(lo: [f64; 3], hi: [f64; 3]) -> Mesh {
    procedural::box_between(DVec3::from(lo), DVec3::from(hi))
}

#[test]
fn built_ins_are_clean() {
    for name in procedural::BUILTIN_NAMES {
        let m = procedural::by_name(name).unwrap();
        assert_eq!(self_intersections(&m, 10), vec![], "builtin:{name}");
    }
}

#[test]
fn two_overlapping_cubes_in_one_file() {
    let m = merged(&[boxed([0.0; 3], [1.0; 3]), boxed([0.5; 3], [1.5; 3])]);
    let pairs = self_intersections(&m, 100);
    assert!(!pairs.is_empty());
    // Every pair has one face from each cube (faces 0..6 and 6..12), and the three faces
    // of each cube near the other's corner are involved.
    assert!(pairs.iter().all(|&(f, g)| f < 6 && g >= 6), "{pairs:?}");
    // A's faces x, y, z = 1 each cross B's two faces at 0.5 of the other axes.
    assert_eq!(pairs, vec![(1, 8), (1, 10), (3, 6), (3, 10), (5, 6), (5, 8)]);
    // The limit is honoured and deterministic.
    assert_eq!(self_intersections(&m, 2), pairs[..2].to_vec());
    assert_eq!(self_intersections(&m, 100), pairs);
}

#[test]
fn touching_only_is_not_a_self_intersection() {
    // Non-manifold edge shared by two cubes (welded built-in), and the same two cubes
    // with their shared vertices duplicated.
    let separate = merged(&[boxed([0.0; 3], [1.0; 3]), boxed([1.0, 1.0, 0.0], [2.0, 2.0, 1.0])]);
    assert_eq!(self_intersections(&separate, 10), vec![]);
    // Two cubes sharing a vertex only.
    let corner = merged(&[boxed([0.0; 3], [1.0; 3]), boxed([1.0; 3], [2.0; 3])]);
    assert_eq!(self_intersections(&corner, 10), vec![]);
    // Two tetrahedra sharing a vertex (the second turned half a turn about the vertical
    // line through it).
    let tet = procedural::tetrahedron();
    let turned = tet.map_positions(|p| DVec3::new(2.0 - p.x, 2.0 - p.y, p.z)).unwrap();
    assert_eq!(self_intersections(&merged(&[tet, turned]), 10), vec![]);
    // A cavity (nested shells, no contact).
    assert_eq!(self_intersections(&procedural::cube_with_cavity(), 10), vec![]);
}

#[test]
fn cubes_touching_at_a_face_overlap() {
    // Face to face: the two faces coincide over their whole area.
    let m = merged(&[boxed([0.0; 3], [1.0; 3]), boxed([1.0, 0.0, 0.0], [2.0, 1.0, 1.0])]);
    assert_eq!(self_intersections(&m, 10), vec![(1, 6)]);
}

#[test]
fn bow_tie_fold_shares_an_edge_but_overlaps() {
    // A closed "tent" whose last face folds back onto its neighbour: faces 0 and 1 share
    // the edge 0–1 and lie in one plane on the same side of it.
    let positions = vec![
        DVec3::new(0.0, 0.0, 0.0),
        DVec3::new(1.0, 0.0, 0.0),
        DVec3::new(0.5, 1.0, 0.0),
        DVec3::new(0.4, 2.0, 0.0),
    ];
    let fold = Mesh::new(positions.clone(), vec![vec![0, 1, 2], vec![1, 0, 3]]).unwrap();
    assert_eq!(self_intersections(&fold, 10), vec![(0, 1)]);
    // Unfolded (3 on the other side), it is fine.
    let mut open = positions;
    open[3].y = -2.0;
    let flat = Mesh::new(open, vec![vec![0, 1, 2], vec![1, 0, 3]]).unwrap();
    assert_eq!(self_intersections(&flat, 10), vec![]);
    // A fold at a shared vertex: two fans overlapping in one plane.
    let fan = Mesh::new(
        vec![
            DVec3::ZERO,
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(0.0, 1.0, 0.0),
            DVec3::new(1.0, 1.0, 0.0),
            DVec3::new(-1.0, 2.0, 0.0),
        ],
        vec![vec![0, 1, 2], vec![0, 3, 4]],
    )
    .unwrap();
    assert_eq!(self_intersections(&fan, 10), vec![(0, 1)]);
}

#[test]
fn polygon_faces_are_tessellated_not_fanned() {
    // The L-prism's caps are non-convex: a centroid fan would overlap itself.
    assert_eq!(self_intersections(&procedural::l_prism(), 10), vec![]);
    // A pentagon whose outline crosses itself is reported paired with itself.
    let bow = Mesh::new(
        vec![
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(2.0, 2.0, 0.0),
            DVec3::new(2.0, 0.0, 0.0),
            DVec3::new(0.0, 2.0, 0.0),
            DVec3::new(-1.0, 1.0, 0.0),
        ],
        vec![vec![0, 1, 2, 3, 4]],
    )
    .unwrap();
    assert_eq!(self_intersections(&bow, 10), vec![(0, 0)]);
}

#[test]
fn a_sphere_pierced_by_a_rotated_copy_of_itself() {
    let s = procedural::sphere(8, 12);
    let r = s
        .map_positions(|p| {
            let (sin, cos) = 0.3f64.sin_cos();
            DVec3::new(cos * p.x + sin * p.z, p.y, -sin * p.x + cos * p.z) + DVec3::new(0.4, 0.1, 0.0)
        })
        .unwrap();
    assert_eq!(self_intersections(&s, 10), vec![]);
    let both = merged(&[s.clone(), r]);
    let pairs = self_intersections(&both, 10_000);
    let nf = s.num_faces();
    assert!(pairs.len() > 10 && pairs.iter().all(|&(f, g)| f < nf && g >= nf));
    // Cross-check each reported pair with the plain predicate on its triangles.
    let soup = intersect::TriangleSoup::new(&both);
    for &(f, g) in pairs.iter().take(50) {
        let tf: Vec<usize> = (0..soup.triangles.len()).filter(|&t| soup.face_of[t] as usize == f).collect();
        let tg: Vec<usize> = (0..soup.triangles.len()).filter(|&t| soup.face_of[t] as usize == g).collect();
        assert!(
            tf.iter()
                .any(|&a| tg.iter().any(|&b| intersect::triangles_meet(soup.triangle(a), soup.triangle(b))))
        );
    }
}
