//! Catmull-Clark with fragment meshes on the GPU (SPEC §5.2–5.4) against live OpenSubdiv
//! on the named test shapes, watertightness of every output, the fragment layout on the
//! CPU, fragments spanning rows, and the limits' errors. Runs on the default device
//! (lavapipe in `tools/test`, with the validation layer on: any validation error fails
//! the submission that caused it, and so the test).

mod common;

use common::shapes;
use glam::DVec3;
use texgeo::gpu::Context;
use texgeo::mesh::{Mesh, procedural};
use texgeo::subdiv::assemble;
use texgeo::subdiv::compare::{Comparison, Matching};
use texgeo::subdiv::fragment::{self, FragmentMesh};
use texgeo::subdiv::gpu::{MAX_RUNS, Options, Packing, Subdivider};
use texgeo::subdiv::{SubdivError, Surface, cpu, osd};

/// float32 GPU positions against f64 OpenSubdiv, after up to 5 levels (SPEC §5.4).
const TOLERANCE: f64 = 1e-5;

fn ctx() -> Context {
    Context::from_env().expect("a Vulkan device (run tools/setup)")
}

/// Refines with OpenSubdiv; a missing helper fails the test, saying to run tools/setup.
fn opensubdiv(mesh: &Mesh, level: u32) -> Mesh {
    osd::refine(mesh, level).unwrap_or_else(|e| panic!("{e}"))
}

/// GPU at every level of `levels` equals OpenSubdiv (counts, positions, faces as cycles),
/// is watertight by the mesh checks (`mesh::validate`: manifold, oriented, closed — or
/// with the input's boundary, each edge split 2^level times), keeps the input's Euler
/// characteristic, and did every level past the base level as a fragment pass.
fn assert_gpu_matches_opensubdiv(
    ctx: &Context,
    sub: &mut Subdivider,
    name: &str,
    mesh: &Mesh,
    levels: std::ops::RangeInclusive<u32>,
    options: &Options,
) {
    let input = mesh.report();
    let base_levels = fragment::levels_needed(mesh);
    for level in levels {
        let run =
            sub.refine(ctx, mesh, level, options).unwrap_or_else(|e| panic!("{name} level {level}: {e}"));
        assert_eq!(run.gpu_levels, level.saturating_sub(base_levels), "{name} level {level}");
        assert_eq!(run.cpu_levels + run.gpu_levels, level, "{name} level {level}");
        let reference = opensubdiv(mesh, level);
        let c = Comparison::new(&run.mesh, &reference, TOLERANCE);
        assert!(c.is_match(), "{name} level {level} (GPU vs OpenSubdiv):\n{c}");
        let w = run.mesh.report();
        assert!(w.is_manifold() && w.is_oriented(), "{name} level {level}: {w}");
        assert_eq!(w.is_closed(), input.is_closed(), "{name} level {level}: {w}");
        assert_eq!(w.euler_characteristic, input.euler_characteristic, "{name} level {level}: {w}");
        assert_eq!(w.boundary_edges, input.boundary_edges << level, "{name} level {level}: {w}");
        assert_eq!((w.non_manifold_edges, w.degenerate_faces), (0, 0), "{name} level {level}: {w}");
    }
}

#[test]
fn cube_valence_3_matches_opensubdiv_to_level_5() {
    let ctx = ctx();
    let mut sub = Subdivider::new(&ctx).unwrap();
    let cube = shapes::cube();
    assert_gpu_matches_opensubdiv(&ctx, &mut sub, "cube", &cube, 1..=5, &Options::default());
    // The thesis' case: 8 fragments, 6·4⁵ faces at level 5.
    let run = sub.refine(&ctx, &cube, 5, &Options::default()).unwrap();
    assert_eq!((run.fragments, run.mesh.num_faces(), run.mesh.num_vertices()), (8, 6144, 6146));
    assert_eq!(run.gpu_levels, 4);
}

#[test]
fn triangles_match_opensubdiv() {
    let ctx = ctx();
    let mut sub = Subdivider::new(&ctx).unwrap();
    let options = Options::default();
    assert_gpu_matches_opensubdiv(&ctx, &mut sub, "tetrahedron", &shapes::tetrahedron(), 1..=5, &options);
    assert_gpu_matches_opensubdiv(&ctx, &mut sub, "pyramid", &shapes::pyramid(), 1..=5, &options);
}

#[test]
fn torus_all_valence_4_matches_opensubdiv() {
    let ctx = ctx();
    let mut sub = Subdivider::new(&ctx).unwrap();
    let torus = shapes::torus(8, 6);
    assert_gpu_matches_opensubdiv(&ctx, &mut sub, "torus", &torus, 1..=5, &Options::default());
}

#[test]
fn valences_3_to_8_and_ngon_match_opensubdiv() {
    let ctx = ctx();
    let mut sub = Subdivider::new(&ctx).unwrap();
    let mesh = shapes::valences();
    let run = sub.refine(&ctx, &mesh, 3, &Options::default()).unwrap();
    // Centres are the level-1 vertices: valences 3…8 (and the 7-gon's face point: 7).
    assert!(run.classes >= 6, "{} classes", run.classes);
    assert_gpu_matches_opensubdiv(&ctx, &mut sub, "valences", &mesh, 1..=5, &Options::default());
}

#[test]
fn torus_knot_1200_triangles_matches_opensubdiv() {
    let ctx = ctx();
    let mut sub = Subdivider::new(&ctx).unwrap();
    let knot = procedural::torus_knot();
    assert_eq!(knot.num_faces(), 1200);
    assert_gpu_matches_opensubdiv(&ctx, &mut sub, "torus_knot", &knot, 1..=4, &Options::default());
}

/// Open meshes run on the GPU too: border centres get half-fan fragments.
#[test]
fn open_meshes_match_opensubdiv() {
    let ctx = ctx();
    let mut sub = Subdivider::new(&ctx).unwrap();
    let options = Options::default();
    assert_gpu_matches_opensubdiv(&ctx, &mut sub, "grid", &shapes::grid(3), 1..=4, &options);
    assert_gpu_matches_opensubdiv(&ctx, &mut sub, "open_cube", &shapes::open_cube(), 1..=4, &options);
    assert!(shapes::grid(3).report().boundary_edges > 0);
}

/// The committed OpenSubdiv outputs (reference/subdiv/README.md) need no helper.
#[test]
fn matches_committed_reference_files() {
    let ctx = ctx();
    let mut sub = Subdivider::new(&ctx).unwrap();
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("reference/subdiv");
    for (name, mesh, level) in shapes::committed_references() {
        let path = dir.join(format!("{name}-level{level}.off"));
        let reference = texgeo::mesh::formats::read(&path).unwrap_or_else(|e| panic!("{e}"));
        let run = sub.refine(&ctx, &mesh, level, &Options::default()).unwrap();
        let c = Comparison::new(&run.mesh, &reference, TOLERANCE);
        assert!(c.is_match(), "{}:\n{c}", path.display());
    }
}

/// The fragment algorithm's arithmetic (layout, stencils, welding) run on the CPU in f64
/// equals the reference to 1e-12: any GPU difference is float32 rounding, not layout.
#[test]
fn fragment_layout_on_the_cpu_equals_the_reference() {
    for shape in shapes::all() {
        let levels = if shape.mesh.num_faces() > 500 { 1..=3 } else { 1..=4 };
        for level in levels {
            let surface = Surface::smooth(shape.mesh.clone());
            let ours = assemble::refine(&surface, level).unwrap_or_else(|e| panic!("{}: {e}", shape.name));
            let reference = cpu::refine(&shape.mesh, level).unwrap();
            let c = Comparison::new(&ours.mesh, &reference, 1e-12);
            assert!(c.is_match(), "{} level {level}:\n{c}", shape.name);
        }
    }
    for shape in shapes::sharp() {
        for level in 1..=shape.levels {
            let name = shape.name;
            let ours = assemble::refine(&shape.surface, level).unwrap_or_else(|e| panic!("{name}: {e}"));
            let reference = cpu::refine_surface(&shape.surface, level).unwrap();
            let c = Comparison::new(&ours.mesh, &reference.mesh, 1e-12);
            assert!(c.is_match(), "{name} level {level} ({}):\n{c}", shape.covers);
        }
    }
}

#[test]
fn high_valence_fragments_span_rows() {
    let ctx = ctx();
    let mut sub = Subdivider::new(&ctx).unwrap();
    let mesh = procedural::cone(40);
    let fragments = FragmentMesh::new(&mesh, 4).unwrap();
    let widest = fragments.runs().iter().map(|r| r.class.len(2)).max().unwrap();
    assert!(widest > 64 * 3, "the apex fragment ({widest} texels) should span several 64-texel rows");
    let narrow = Options { row_width: Some(64), ..Options::default() };
    assert_gpu_matches_opensubdiv(&ctx, &mut sub, "cone(40), 64-texel rows", &mesh, 2..=4, &narrow);
    assert_gpu_matches_opensubdiv(&ctx, &mut sub, "cone(40)", &mesh, 4..=4, &Options::default());
}

#[test]
fn limits_give_clear_errors() {
    let ctx = ctx();
    let mut sub = Subdivider::new(&ctx).unwrap();
    // One fragment over 2^24 texels: the cone's valence-40 apex at 12 fragment levels.
    let fragments = FragmentMesh::new(&procedural::cone(40), 14).unwrap();
    let err = Packing::new(&fragments, 12, 16384, None).unwrap_err();
    assert!(matches!(err, SubdivError::GpuLimit(_)) && err.to_string().contains("valence 40"), "{err}");
    let err = sub.refine(&ctx, &procedural::cone(40), 14, &Options::default()).unwrap_err();
    assert!(matches!(err, SubdivError::GpuLimit(_)), "{err}");
    // More texels than a texture holds.
    let err = Packing::new(&fragments, 3, 64, None).unwrap_err();
    assert!(err.to_string().contains("do not fit"), "{err}");
    // A row width that is not a power of two.
    let err = Packing::new(&fragments, 1, 16384, Some(100)).unwrap_err();
    assert!(matches!(err, SubdivError::GpuLimit(_)) && err.to_string().contains("power of two"), "{err}");
    // More distinct valences than the run table holds: bipyramids over 3…260-gons.
    let mut positions = Vec::new();
    let mut faces = Vec::new();
    for n in 3..=(MAX_RUNS as u32 + 4) {
        let o = positions.len() as u32;
        for i in 0..n {
            let a = std::f64::consts::TAU * f64::from(i) / f64::from(n);
            positions.push(DVec3::new(a.cos(), a.sin(), 3.0 * f64::from(n)));
        }
        positions.push(DVec3::new(0.0, 0.0, 3.0 * f64::from(n) + 1.0));
        positions.push(DVec3::new(0.0, 0.0, 3.0 * f64::from(n) - 1.0));
        for i in 0..n {
            faces.push(vec![o + i, o + (i + 1) % n, o + n]);
            faces.push(vec![o + (i + 1) % n, o + i, o + n + 1]);
        }
    }
    let many = Mesh::new(positions, faces).unwrap();
    let err = sub.refine(&ctx, &many, 3, &Options::default()).unwrap_err();
    assert!(matches!(err, SubdivError::GpuLimit(_)) && err.to_string().contains("classes"), "{err}");
}

/// A vertex no face uses stays where it is, as in OpenSubdiv.
#[test]
fn isolated_vertices_stay() {
    let ctx = ctx();
    let mut sub = Subdivider::new(&ctx).unwrap();
    let cube = shapes::cube();
    let mut positions = cube.positions().to_vec();
    positions.push(DVec3::new(5.0, 5.0, 5.0));
    let mesh = Mesh::new(positions, cube.faces().map(<[u32]>::to_vec).collect()).unwrap();
    assert_gpu_matches_opensubdiv(
        &ctx,
        &mut sub,
        "cube + isolated vertex",
        &mesh,
        1..=3,
        &Options::default(),
    );
}

/// `texgeo subdivide`: writes the mesh, `--validate` passes against OpenSubdiv, tags and
/// options are applied, non-manifold input is subdivided, and a bad tag is a clear error
/// (file and line) with exit status 2.
#[test]
fn subdivide_command() {
    let exe = env!("CARGO_BIN_EXE_texgeo");
    let dir = common::TempDir::new("subdivide");
    let out = dir.join("out.off");
    let texgeo = |args: &[&str]| std::process::Command::new(exe).args(args).output().unwrap();
    let run = texgeo(&["subdivide", "builtin:pyramid", "-l", "3", "--validate", "-o", out.to_str().unwrap()]);
    let stdout = String::from_utf8_lossy(&run.stdout);
    assert!(run.status.success(), "{stdout}{}", String::from_utf8_lossy(&run.stderr));
    assert!(stdout.contains("validation passed") && stdout.contains("position error: max"), "{stdout}");
    let written = texgeo::mesh::formats::read(&out).unwrap();
    let reference = cpu::refine(&texgeo::mesh::procedural::pyramid(), 3).unwrap();
    assert_eq!(
        (written.num_vertices(), written.num_faces()),
        (reference.num_vertices(), reference.num_faces())
    );
    assert!(written.report().is_closed());

    // Non-manifold input: OpenSubdiv's sharp rules, on the GPU.
    let run = texgeo(&["subdivide", "builtin:two-cubes", "-l", "3", "--validate"]);
    let stdout = String::from_utf8_lossy(&run.stdout);
    assert!(run.status.success() && stdout.contains("validation passed"), "{stdout}");

    // Tags: a crease, a corner, Chaikin, an ignored tag; options override tags.
    let cube = dir.join("cube.obj");
    let mut text = Vec::new();
    texgeo::mesh::formats::obj::write(&mut text, &shapes::cube()).unwrap();
    let mut text = String::from_utf8(text).unwrap();
    text.push_str(
        "t crease 2/1/0 0 1 2.5\nt corner 1/1/0 7 1.5\nt creasemethod 0/0/1 chaikin\nt vertexedit 1/0/0 3\n",
    );
    std::fs::write(&cube, &text).unwrap();
    for method in ["gpu", "cpu"] {
        let run = texgeo(&["subdivide", cube.to_str().unwrap(), "-l", "3", "--method", method, "--validate"]);
        let stdout = String::from_utf8_lossy(&run.stdout);
        assert!(run.status.success() && stdout.contains("validation passed"), "{method}: {stdout}");
        assert!(stdout.contains("1 crease edge(s)") && stdout.contains("creasing chaikin"), "{stdout}");
        assert!(stdout.contains("tag 'vertexedit' ignored"), "{stdout}");
    }
    let run =
        texgeo(&["subdivide", cube.to_str().unwrap(), "-l", "2", "--crease-method", "uniform", "--validate"]);
    let stdout = String::from_utf8_lossy(&run.stdout);
    assert!(run.status.success() && stdout.contains("creasing uniform"), "{stdout}");

    // A crease on vertices no edge joins: file and line, exit status 2.
    text.push_str("t crease 2/1/0 0 7 1\n");
    std::fs::write(&cube, &text).unwrap();
    let run = texgeo(&["subdivide", cube.to_str().unwrap(), "-l", "2"]);
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert_eq!(run.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("cube.obj:20") && stderr.contains("not joined by an edge"), "{stderr}");
}

/// Issue 12, item 7: meshes with coincident but distinct vertices. Two grids side by side
/// with duplicated border vertices refine to pairs of vertices at the same positions; the
/// comparison takes the refinement's own correspondence (faces in OpenSubdiv's order), so
/// the GPU result matches OpenSubdiv — a matching by position could swap the pairs.
#[test]
fn coincident_vertices_match_by_the_refinement() {
    let ctx = ctx();
    let mut sub = Subdivider::new(&ctx).unwrap();
    let seam = shapes::seam(3);
    for level in 1..=3 {
        let run = sub.refine(&ctx, &seam, level, &Options::default()).unwrap();
        let reference = opensubdiv(&seam, level);
        let c = Comparison::new(&run.mesh, &reference, TOLERANCE);
        assert!(c.is_match(), "seam level {level}:\n{c}");
        assert_eq!(c.matching, Matching::Faces, "seam level {level}:\n{c}");
    }
    // And through the command line.
    let dir = common::TempDir::new("seam");
    let file = dir.join("seam.off");
    texgeo::mesh::formats::write(&file, &seam).unwrap();
    let run = std::process::Command::new(env!("CARGO_BIN_EXE_texgeo"))
        .args(["subdivide", file.to_str().unwrap(), "-l", "3", "--validate"])
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&run.stdout);
    assert!(run.status.success() && stdout.contains("corresponding by faces"), "{stdout}");
}

/// Every shape of the sharp set on the GPU equals OpenSubdiv (1e-5 × diagonal), faces in
/// OpenSubdiv's order (the comparison corresponds vertices through them), and ran its
/// levels past the base level as fragment passes — except where the fragments cannot
/// express the surface and the run says why.
#[test]
fn sharp_features_match_opensubdiv() {
    let ctx = ctx();
    let mut sub = Subdivider::new(&ctx).unwrap();
    let mut gpu_levels = 0;
    let mut sharp_fragments = 0;
    for shape in shapes::sharp() {
        let name = shape.name;
        for level in 1..=shape.levels {
            let run = sub
                .refine_surface(&ctx, &shape.surface, level, &Options::default())
                .unwrap_or_else(|e| panic!("{name} level {level}: {e}"));
            let reference = opensubdiv_surface(&shape.surface, level);
            let c = Comparison::new(&run.mesh, &reference, TOLERANCE);
            assert!(c.is_match(), "{name} level {level} ({}), GPU vs OpenSubdiv:\n{c}", shape.covers);
            assert_ne!(
                c.matching,
                Matching::Positions,
                "{name} level {level}: faces not in OpenSubdiv's order\n{c}"
            );
            let base = fragment::levels_needed(&shape.surface.mesh);
            assert_eq!(run.cpu_levels + run.gpu_levels, level, "{name} level {level}");
            if run.cpu_reasons.is_empty() {
                assert_eq!(run.gpu_levels, level.saturating_sub(base), "{name} level {level}");
            } else {
                assert!(
                    run.gpu_levels < level.saturating_sub(base).max(1),
                    "{name} level {level}: {:?}",
                    run.cpu_reasons
                );
            }
            gpu_levels += run.gpu_levels;
            sharp_fragments += run.sharp_fragments;
        }
    }
    assert!(
        gpu_levels > 150 && sharp_fragments > 1000,
        "{gpu_levels} GPU levels, {sharp_fragments} sharp fragments"
    );
}

/// Semi-sharp edges meeting a non-manifold crease outside a fragment's fan decay on the
/// CPU first; the run says so.
#[test]
fn inexpressible_features_go_to_the_cpu_and_say_so() {
    let ctx = ctx();
    let mut sub = Subdivider::new(&ctx).unwrap();
    let shape = shapes::sharp().into_iter().find(|s| s.name == "membrane_box_creased").unwrap();
    let run = sub.refine_surface(&ctx, &shape.surface, 4, &Options::default()).unwrap();
    assert_eq!((run.cpu_levels, run.gpu_levels), (2, 2), "{:?}", run.cpu_reasons);
    assert!(run.cpu_reasons.iter().any(|r| r.contains("non-manifold vertex")), "{:?}", run.cpu_reasons);
    // With an infinitely sharp edge there too, the vertex is a corner for good: no extra level.
    let shape = shapes::sharp().into_iter().find(|s| s.name == "membrane_box_corner").unwrap();
    let run = sub.refine_surface(&ctx, &shape.surface, 4, &Options::default()).unwrap();
    assert_eq!((run.cpu_levels, run.gpu_levels), (1, 3), "{:?}", run.cpu_reasons);
}

/// OpenSubdiv's refinement of a surface; a missing helper fails the test.
fn opensubdiv_surface(surface: &Surface, level: u32) -> Mesh {
    osd::refine_surface(surface, level).unwrap_or_else(|e| panic!("{e}"))
}

/// The sharp shader variants also compute smooth fragments exactly as the smooth one:
/// drawing every run with them (what a GPU that skips untaken branches would do) gives
/// the same surfaces.
#[test]
fn single_shader_draws_everything_the_same() {
    let ctx = ctx();
    let mut sub = Subdivider::new(&ctx).unwrap();
    let single = Options { single_shader: true, ..Options::default() };
    for name in ["cube_creases", "torus_chaikin", "grid_holes"] {
        let shape = shapes::sharp().into_iter().find(|s| s.name == name).unwrap();
        let split = sub.refine_surface(&ctx, &shape.surface, 3, &Options::default()).unwrap();
        let one = sub.refine_surface(&ctx, &shape.surface, 3, &single).unwrap();
        let c = Comparison::new(&one.mesh, &split.mesh, 1e-9);
        assert!(c.is_match() && c.same_order, "{name}:\n{c}");
    }
    let torus = shapes::torus(8, 6);
    let split = sub.refine(&ctx, &torus, 4, &Options::default()).unwrap();
    let one = sub.refine(&ctx, &torus, 4, &single).unwrap();
    assert!(Comparison::new(&one.mesh, &split.mesh, 1e-9).same_order);
}

/// The refined edges on sharp control edges (what a picture draws as creases) are the
/// same on the GPU path and the CPU reference: each lies on a tagged crease, a boundary or
/// a non-manifold edge, and their ends coincide.
#[test]
fn sharp_edges_for_pictures() {
    let ctx = ctx();
    let mut sub = Subdivider::new(&ctx).unwrap();
    for name in ["cube_creases", "tent_creases", "fin"] {
        let shape = shapes::sharp().into_iter().find(|s| s.name == name).unwrap();
        let cpu = cpu::refine_surface(&shape.surface, 3).unwrap();
        let gpu = sub.refine_surface(&ctx, &shape.surface, 3, &Options::default()).unwrap();
        assert_eq!(gpu.sharp_edges.len(), cpu.sharp_edges.len(), "{name}");
        assert!(!cpu.sharp_edges.is_empty(), "{name}");
        let (lo, hi) = cpu.mesh.bounds();
        let tolerance = TOLERANCE * (hi - lo).length();
        let ends = |mesh: &Mesh, e: &texgeo::subdiv::cpu::SharpEdge| {
            e.vertices.map(|v| mesh.positions()[v as usize])
        };
        for g in &gpu.sharp_edges {
            let [a, b] = ends(&gpu.mesh, g);
            let found = cpu.sharp_edges.iter().any(|c| {
                let [p, q] = ends(&cpu.mesh, c);
                let same = |x: DVec3, y: DVec3| x.distance(y) <= tolerance;
                c.sharpness == g.sharpness && ((same(a, p) && same(b, q)) || (same(a, q) && same(b, p)))
            });
            assert!(found, "{name}: GPU sharp edge {g:?} has no CPU counterpart");
        }
        if name == "cube_creases" {
            // The four tagged top edges, split 2^3 times each, with their sharpness.
            let tagged: Vec<f32> = cpu.sharp_edges.iter().map(|e| e.sharpness).collect();
            assert_eq!(tagged.len(), 4 * 8);
            assert!(cpu.sharp_edges.iter().all(|e| !e.boundary && !e.non_manifold));
            assert_eq!(tagged.iter().filter(|&&s| s == 10.0).count(), 8);
        }
        if name == "fin" {
            assert!(
                cpu.sharp_edges.iter().any(|e| e.non_manifold) && cpu.sharp_edges.iter().any(|e| e.boundary)
            );
        }
    }
}
