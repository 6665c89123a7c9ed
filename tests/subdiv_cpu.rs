//! The CPU Catmull-Clark reference against OpenSubdiv (live helper and committed
//! reference files), known values, topology checks and rejected input.

mod common;

use common::shapes;
use glam::DVec3;
use texgeo::mesh::spec::MeshSpec;
use texgeo::mesh::{Mesh, procedural};
use texgeo::subdiv::compare::Comparison;
use texgeo::subdiv::topology::Topology;
use texgeo::subdiv::{SubdivError, cpu, osd};

/// f64 CPU vs f64 OpenSubdiv: the same sums in a different order (SPEC §5.1).
const TOLERANCE: f64 = 1e-12;

/// Refines with OpenSubdiv; a missing helper fails the test, saying to run tools/setup.
fn opensubdiv(mesh: &Mesh, level: u32) -> Mesh {
    osd::refine(mesh, level).unwrap_or_else(|e| panic!("{e}"))
}

fn assert_matches_opensubdiv(name: &str, mesh: &Mesh, levels: std::ops::RangeInclusive<u32>) {
    for level in levels {
        let ours = cpu::refine(mesh, level).unwrap_or_else(|e| panic!("{name} level {level}: {e}"));
        let reference = opensubdiv(mesh, level);
        let c = Comparison::new(&ours, &reference, TOLERANCE);
        assert!(c.is_match(), "{name} level {level}:\n{c}");
        assert!(c.same_order, "{name} level {level}: vertex order differs from OpenSubdiv's\n{c}");
        assert!(ours.face_parts() == reference.face_parts(), "{name} level {level}: face lists differ");
    }
}

#[test]
fn cube_level_1_known_values() {
    let refined = cpu::refine(&shapes::cube(), 1).unwrap();
    assert_eq!((refined.num_vertices(), refined.num_faces()), (26, 24));
    assert!(refined.faces().all(|f| f.len() == 4));
    let corner = refined.positions().iter().find(|p| p.x > 0.0 && p.y > 0.0 && p.z > 0.0 && p.x == p.y);
    let corner = corner.copied().unwrap_or(DVec3::NAN);
    assert!((corner - DVec3::splat(5.0 / 9.0)).length() < 1e-15, "corner (1,1,1) went to {corner}");
    // The refined input vertices come first, as in OpenSubdiv: vertex 7 is (1,1,1).
    assert!((refined.positions()[7] - DVec3::splat(5.0 / 9.0)).length() < 1e-15);
}

#[test]
fn matches_opensubdiv_closed_quads() {
    assert_matches_opensubdiv("cube", &shapes::cube(), 1..=5);
    assert_matches_opensubdiv("torus", &shapes::torus(8, 6), 1..=4);
}

#[test]
fn matches_opensubdiv_triangles() {
    assert_matches_opensubdiv("tetrahedron", &shapes::tetrahedron(), 1..=5);
    assert_matches_opensubdiv("pyramid", &shapes::pyramid(), 1..=5);
}

#[test]
fn matches_opensubdiv_valences_3_to_8_and_ngon() {
    let mesh = shapes::valences();
    let topo = Topology::new(&mesh).unwrap();
    let mut valences: Vec<usize> = (0..mesh.num_vertices() as u32).map(|v| topo.valence(v)).collect();
    valences.sort_unstable();
    valences.dedup();
    assert_eq!(valences, [3, 4, 5, 6, 7, 8]);
    assert!(mesh.faces().any(|f| f.len() == 7));
    assert_matches_opensubdiv("valences", &mesh, 1..=4);
}

#[test]
fn matches_opensubdiv_open_meshes() {
    assert_matches_opensubdiv("grid", &shapes::grid(3), 1..=4);
    assert_matches_opensubdiv("open_cube", &shapes::open_cube(), 1..=5);
}

#[test]
fn matches_opensubdiv_torus_knot_1200() {
    let knot = procedural::torus_knot();
    assert_eq!(knot.num_faces(), 1200);
    assert_matches_opensubdiv("torus_knot", &knot, 1..=3);
}

/// The committed OpenSubdiv outputs (reference/subdiv/README.md) need no helper.
#[test]
fn matches_committed_reference_files() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("reference/subdiv");
    for (name, mesh, level) in shapes::committed_references() {
        let input = texgeo::mesh::formats::read(dir.join(format!("{name}.off"))).unwrap();
        assert_eq!(input, mesh, "reference/subdiv/{name}.off is not the test shape {name}");
        let path = dir.join(format!("{name}-level{level}.off"));
        let reference = texgeo::mesh::formats::read(&path).unwrap_or_else(|e| panic!("{e}"));
        let ours = cpu::refine(&mesh, level).unwrap();
        let c = Comparison::new(&ours, &reference, TOLERANCE);
        assert!(c.is_match() && c.same_order, "{}:\n{c}", path.display());
        assert!(ours.face_parts() == reference.face_parts(), "{}: face lists differ", path.display());
    }
}

/// The committed OpenSubdiv outputs of sharp shapes (OBJ inputs with tags): reading the
/// tags gives the test shape back, and the CPU reference equals OpenSubdiv's output.
#[test]
fn matches_committed_sharp_references() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("reference/subdiv");
    for (name, level) in shapes::committed_sharp_references() {
        let shape = shapes::sharp().into_iter().find(|s| s.name == name).unwrap();
        let path = dir.join(format!("{name}.obj"));
        let (mesh, tags) = MeshSpec::File(path.clone()).load_with_tags().unwrap();
        let input = texgeo::subdiv::tags::interpret(mesh, &tags, &path).unwrap();
        let surface = input.surface(Default::default());
        assert_eq!(surface, shape.surface, "reference/subdiv/{name}.obj is not the test shape {name}");
        let path = dir.join(format!("{name}-level{level}.off"));
        let reference = texgeo::mesh::formats::read(&path).unwrap_or_else(|e| panic!("{e}"));
        let ours = cpu::refine_surface(&surface, level).unwrap();
        let c = Comparison::new(&ours.mesh, &reference, TOLERANCE);
        assert!(c.is_match() && c.same_order, "{}:\n{c}", path.display());
    }
}

/// V − E + F of every refined level equals the input's (closed and open meshes).
#[test]
fn euler_characteristic_is_preserved() {
    let euler = |mesh: &Mesh| {
        let topo = Topology::new(mesh).unwrap();
        mesh.num_vertices() as i64 - topo.num_edges() as i64 + mesh.num_faces() as i64
    };
    for shape in shapes::all() {
        let expected = euler(&shape.mesh);
        for level in 1..=3 {
            let refined = cpu::refine(&shape.mesh, level).unwrap();
            assert_eq!(euler(&refined), expected, "{} level {level}", shape.name);
        }
    }
    assert_eq!(euler(&shapes::torus(8, 6)), 0);
    assert_eq!(euler(&shapes::valences()), 2);
    assert_eq!(euler(&shapes::grid(3)), 1);
}

/// One-rings and face fans come out in order: face i lies between ring vertices i and i+1.
#[test]
fn one_rings_are_ordered() {
    for shape in shapes::all() {
        let refined = cpu::refine(&shape.mesh, 1).unwrap();
        let topo = Topology::new(&refined).unwrap();
        for v in 0..refined.num_vertices() as u32 {
            let ring: Vec<u32> = topo.one_ring(v).collect();
            let faces: Vec<u32> = topo.faces_around(v).collect();
            assert_eq!(ring.len(), topo.valence(v), "{} vertex {v}", shape.name);
            let closed = !topo.is_boundary_vertex(v);
            assert_eq!(faces.len(), ring.len() - usize::from(!closed));
            for (i, &f) in faces.iter().enumerate() {
                let face = refined.face(f as usize);
                let k = face.iter().position(|&x| x == v).unwrap();
                // Counter-clockwise around v: the face runs v → ring[i], and ring[i+1] → v.
                assert_eq!(face[(k + 1) % 4], ring[i], "{} vertex {v}", shape.name);
                assert_eq!(face[(k + 3) % 4], ring[(i + 1) % ring.len()], "{} vertex {v}", shape.name);
            }
        }
        // Original vertices keep their valence; face points get their face's size.
        let base = Topology::new(&shape.mesh).unwrap();
        for v in 0..shape.mesh.num_vertices() as u32 {
            assert_eq!(topo.valence(v), base.valence(v));
        }
        for (f, face) in shape.mesh.faces().enumerate() {
            assert_eq!(topo.valence((shape.mesh.num_vertices() + f) as u32), face.len());
        }
    }
}

/// What OpenSubdiv tags and subdivides with sharp rules is accepted (fins, bowties,
/// inconsistently oriented neighbours, degenerate faces), and the result equals
/// OpenSubdiv's; features that do not fit the mesh are clear errors.
#[test]
fn non_manifold_input_is_subdivided_as_opensubdiv_does() {
    let p = |x: f64, y: f64, z: f64| DVec3::new(x, y, z);
    // Three triangles on one edge.
    let fin = Mesh::new(
        vec![p(0., 0., 0.), p(1., 0., 0.), p(0., 1., 0.), p(0., -1., 0.), p(0., 0., 1.)],
        vec![vec![0, 1, 2], vec![1, 0, 3], vec![0, 1, 4]],
    )
    .unwrap();
    assert_matches_opensubdiv("fin", &fin, 1..=3);
    // A flipped face of a cube, and a face using a vertex twice.
    let cube = shapes::cube();
    let mut faces: Vec<Vec<u32>> = cube.faces().map(<[u32]>::to_vec).collect();
    faces[2].reverse();
    assert_matches_opensubdiv("flipped face", &Mesh::new(cube.positions().to_vec(), faces).unwrap(), 1..=3);
    let degenerate = Mesh::new(
        vec![p(0., 0., 0.), p(1., 0., 0.), p(0., 1., 0.), p(1., 1., 0.)],
        vec![vec![0, 1, 0, 2], vec![1, 3, 2, 0]],
    )
    .unwrap();
    assert_matches_opensubdiv("repeated vertex", &degenerate, 1..=3);
    assert_matches_opensubdiv("two cubes on an edge", &procedural::two_cubes_sharing_edge(), 1..=3);

    let bad = |creases: &[(u32, u32, f32)], corners: &[(u32, f32)], holes: &[u32]| {
        let s = shapes::surface(shapes::cube(), creases, corners, holes, Default::default());
        cpu::refine_surface(&s, 1).unwrap_err().to_string()
    };
    assert!(bad(&[(0, 7, 1.0)], &[], &[]).contains("not joined by an edge"));
    assert!(bad(&[(0, 1, -1.0)], &[], &[]).contains("sharpness"));
    assert!(bad(&[], &[(8, 1.0)], &[]).contains("out of range"));
    assert!(bad(&[], &[], &[6]).contains("out of range"));
}

/// A vertex no face uses stays where it is and keeps its place, as in OpenSubdiv.
#[test]
fn isolated_vertices_stay() {
    let cube = shapes::cube();
    let mut positions = cube.positions().to_vec();
    positions.push(DVec3::new(5.0, 5.0, 5.0));
    let mesh = Mesh::new(positions, cube.faces().map(<[u32]>::to_vec).collect()).unwrap();
    let refined = cpu::refine(&mesh, 2).unwrap();
    assert_eq!(refined.positions()[8], DVec3::new(5.0, 5.0, 5.0));
    assert_matches_opensubdiv("cube + isolated vertex", &mesh, 1..=2);
}

#[test]
fn missing_helper_error_says_to_run_setup() {
    let e = SubdivError::HelperMissing { path: "target/tools/osd-refine".into() };
    assert!(e.to_string().contains("run tools/setup"), "{e}");
}

/// Every shape of the sharp set (creases, corners, holes, boundary modes, Chaikin, smooth
/// triangles, non-manifold topology) equals OpenSubdiv with the same tags and options:
/// same vertex order, same faces, positions to 1e-12.
#[test]
fn sharp_features_match_opensubdiv() {
    for shape in shapes::sharp() {
        for level in 1..=shape.levels {
            let name = shape.name;
            let ours = cpu::refine_surface(&shape.surface, level)
                .unwrap_or_else(|e| panic!("{name} level {level}: {e}"));
            let reference =
                osd::refine_surface(&shape.surface, level).unwrap_or_else(|e| panic!("{name}: {e}"));
            let c = Comparison::new(&ours.mesh, &reference, TOLERANCE);
            assert!(c.is_match() && c.same_order, "{name} level {level} ({}):\n{c}", shape.covers);
            assert!(
                ours.mesh.face_parts() == reference.face_parts(),
                "{name} level {level}: face lists differ"
            );
        }
    }
}
