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

/// The cube [0, 2]³ with its top split into two quads at x = 1: the front and back
/// faces keep their whole top edges, and a face with no area (three corners on one line)
/// plugs each T-junction. Faces only touch there.
fn cube_with_plugged_t_junctions() -> Mesh {
    let mut p: Vec<DVec3> = (0..8)
        .map(|i| DVec3::new(f64::from(i & 1) * 2.0, f64::from(i >> 1 & 1) * 2.0, f64::from(i >> 2) * 2.0))
        .collect();
    p.extend([DVec3::new(1.0, 0.0, 2.0), DVec3::new(1.0, 2.0, 2.0)]);
    let faces = vec![
        vec![0, 4, 6, 2], // −x
        vec![1, 3, 7, 5], // +x
        vec![0, 1, 5, 4], // −y, with the whole edge 5–4
        vec![2, 6, 7, 3], // +y, with the whole edge 6–7
        vec![0, 2, 3, 1], // −z
        vec![4, 8, 9, 6], // top, x ≤ 1
        vec![8, 5, 7, 9], // top, x ≥ 1
        vec![4, 5, 8],    // plugs: no area
        vec![7, 6, 9],
    ];
    Mesh::new(p, faces).unwrap()
}

#[test]
fn faces_touching_at_a_plugged_t_junction_do_not_cross() {
    let m = cube_with_plugged_t_junctions();
    assert!(m.report().is_closed());
    assert_eq!(self_intersections(&m, 10), vec![]);
    assert!(texgeo::mesh::solidity::check(&m).defects.is_empty());
    // A real crossing next to the junction is still found: a small box through the top.
    let poked = merged(&[m, boxed([0.9, 0.4, 1.9], [1.1, 0.6, 2.1])]);
    let pairs = self_intersections(&poked, 10);
    assert!(
        !pairs.is_empty() && pairs.iter().all(|&(f, g)| f < 9 && g >= 9 && (f == 5 || f == 6)),
        "{pairs:?}"
    );
}

/// A non-planar face is the fan from its centroid in the check too. The bent box's top
/// quad reaches z = 4.5 at its centre as a fan (z = 5 as two triangles split along the
/// diagonal to the raised corner): a small box between the two crosses only the
/// diagonal split, one around z = 4.5 only the fan.
#[test]
fn non_planar_faces_are_checked_as_their_fan() {
    let bent = procedural::bent_box();
    let top = 5;
    let above_fan = merged(&[bent.clone(), boxed([1.9, 1.9, 4.6], [2.1, 2.1, 5.2])]);
    assert_eq!(self_intersections(&above_fan, 10), vec![]);
    let through_fan = merged(&[bent, boxed([1.9, 1.9, 4.3], [2.1, 2.1, 4.7])]);
    let pairs = self_intersections(&through_fan, 10);
    assert!(!pairs.is_empty() && pairs.iter().all(|&(f, g)| f == top && g >= 6), "{pairs:?}");
}

/// A non-convex face bent out of its plane whose centroid lies outside it: its fan would
/// fold through itself, so it is triangulated in its projection plane, and that surface
/// does not cross itself.
#[test]
fn a_folding_fan_is_not_used() {
    // A bracket opening to the left; its vertex centroid (1.25, 1.5) lies in the notch.
    // Tilting the notch's lower side (one end up, one down) would make the fan triangle
    // over that side cross the lower arm's.
    let bracket = |tilt: f64| {
        let xy =
            [(0.0, 0.0), (3.0, 0.0), (3.0, 3.0), (0.0, 3.0), (0.0, 2.0), (2.0, 2.0), (2.0, 1.0), (0.0, 1.0)];
        let z = [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, tilt, -tilt];
        let p: Vec<DVec3> = xy.iter().zip(z).map(|(&(x, y), z)| DVec3::new(x, y, z)).collect();
        Mesh::new(p, vec![(0..8).collect()]).unwrap()
    };
    for tilt in [0.0, 0.5] {
        let m = bracket(tilt);
        assert_eq!(texgeo::mesh::triangulate::fan_centre(m.positions(), m.face(0)), None);
        assert_eq!(self_intersections(&m, 10), vec![]);
    }
    // The bent box's top is convex: fanned.
    let bent = procedural::bent_box();
    assert_eq!(
        texgeo::mesh::triangulate::fan_centre(bent.positions(), bent.face(5)),
        Some(DVec3::new(2.0, 2.0, 4.5))
    );
}

/// `procedural::bicone(sides, 1, 1)` with its first top triangle (ring corners 0, 1 and
/// the apex) replaced by the other three faces of a tetrahedron to a point below its
/// centroid at height `z`: a dent into the solid for z above the bottom cap, a spike
/// pushed through the bottom cap for z below it.
fn dented_bicone(sides: u32, z: f64) -> Mesh {
    let b = procedural::bicone(sides, 1.0, 1.0);
    let mut positions = b.positions().to_vec();
    let apex = sides;
    let c = (positions[0] + positions[1] + positions[apex as usize]) / 3.0;
    positions.push(DVec3::new(c.x, c.y, z));
    let p = apex + 2;
    let mut faces: Vec<Vec<u32>> = b.faces().map(<[u32]>::to_vec).collect();
    assert_eq!(faces[0], vec![0, 1, apex]);
    faces[0] = vec![0, 1, p];
    faces.push(vec![1, apex, p]);
    faces.push(vec![apex, 0, p]);
    Mesh::new(positions, faces).unwrap()
}

#[test]
fn fans_slivers_and_high_valence_vertices_are_clean() {
    for (name, m) in [
        ("bicone", procedural::bicone(300, 1.0, 1.0)),
        ("needle over a fanned base", procedural::bicone(300, 100.0, 0.0)),
        ("flat lens", procedural::bicone(300, 0.01, 0.01)),
        ("cone", procedural::cone(300)),
        ("dented bicone", dented_bicone(300, 0.2)),
        ("cylinder of long slivers", procedural::sliver_cylinder(300, 10.0)),
    ] {
        assert_eq!(self_intersections(&m, 10), vec![], "{name}");
        let check = texgeo::mesh::solidity::check(&m);
        assert!(check.is_solid(), "{name}: {:?}", check.defects);
    }
}

#[test]
fn a_cap_triangle_pushed_through_the_other_cap_crosses_it() {
    let sides = 300;
    let m = dented_bicone(sides, -0.5);
    let pairs = self_intersections(&m, 1000);
    // Only the spike's faces (0 and the last two) cross, and only bottom faces.
    let spike = [0, 2 * sides as usize, 2 * sides as usize + 1];
    let bottom = sides as usize..2 * sides as usize;
    assert!(!pairs.is_empty(), "the spike through the bottom cap is not found");
    assert!(pairs.iter().all(|&(f, g)| spike.contains(&f) != spike.contains(&g)), "{pairs:?}");
    assert!(pairs.iter().all(|&(f, g)| bottom.contains(&f) || bottom.contains(&g)), "{pairs:?}");
    let check = texgeo::mesh::solidity::check(&m);
    assert!(
        check.defects.iter().any(|d| matches!(d, texgeo::mesh::solidity::Defect::SelfIntersecting { .. })),
        "{:?}",
        check.defects
    );
}
