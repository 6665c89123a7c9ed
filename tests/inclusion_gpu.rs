//! The GPU inclusion methods (`gpu`, `cpu+gpu`, `gpu+tetragrid`) equal the exact CPU test
//! point for point, including points built to hit the flagged cases that fall back to the
//! CPU (on faces, edges and vertices of the surface, at the apex, on apex edges).

use glam::DVec3;
use texgeo::gpu::Context;
use texgeo::inclusion::gpu::{GpuInclusion, GpuOptions, Phase2};
use texgeo::inclusion::gpu_grid::GpuGridInclusion;
use texgeo::inclusion::tetragrid::GridClassifier;
use texgeo::inclusion::winding::WindingNumber;
use texgeo::inclusion::{Class, Classifier, FeitoTorres};
use texgeo::mesh::{Mesh, procedural};
use texgeo::random::Rng;

fn ctx() -> Context {
    Context::from_env().expect("a Vulkan device (run tools/setup)")
}

fn grid(mesh: &Mesh) -> GridClassifier {
    GridClassifier::new(FeitoTorres::new(mesh).unwrap(), 16).unwrap()
}

/// Random points in the grown bounding box plus points on the surface and at the apex.
fn query_points(mesh: &Mesh, n: usize, seed: u64) -> Vec<DVec3> {
    let (lo, hi) = mesh.bounds();
    let pad = (hi - lo) * 0.1;
    let mut rng = Rng::new(seed);
    let mut pts = rng.points_in_box(n, lo - pad, hi + pad);
    pts.extend_from_slice(mesh.positions());
    for f in mesh.faces() {
        let c = f.iter().map(|&i| mesh.positions()[i as usize]).sum::<DVec3>() / f.len() as f64;
        pts.push(c);
        let (a, b) = (mesh.positions()[f[0] as usize], mesh.positions()[f[1] as usize]);
        pts.push((a + b) * 0.5);
    }
    let ft = FeitoTorres::new(mesh).unwrap();
    let o = ft.apex();
    pts.push(o);
    // On apex edges: between the apex and covering vertices.
    for t in 0..ft.tetras().len().min(50) {
        let q = ft.tetra_vertices(t)[0];
        pts.push(o + (q - o) * 0.5);
    }
    pts
}

fn check(mesh: &Mesh, name: &str, pts: &[DVec3]) {
    let ctx = ctx();
    let exact = grid(mesh);
    let want = exact.classify_all(pts);
    // The independent oracle agrees with the exact test the GPU falls back to.
    let oracle = WindingNumber::new(mesh).unwrap().classify_all(pts);
    let off: Vec<_> = (0..pts.len())
        .filter(|&i| oracle[i] != want[i])
        .take(3)
        .map(|i| (pts[i], want[i], oracle[i]))
        .collect();
    assert!(off.is_empty(), "{name}: exact test vs winding number: {off:?}");
    for (options, label) in [
        (GpuOptions::default(), "gpu"),
        (GpuOptions { batch: 1, groups_per_draw: 2, phase2: Phase2::Gpu }, "gpu, thesis layout"),
        (GpuOptions { batch: 7, groups_per_draw: 3, phase2: Phase2::Host }, "cpu+gpu"),
    ] {
        let mut gpu = GpuInclusion::new(&ctx, grid(mesh), options).unwrap();
        let got = gpu.classify_all(pts).unwrap();
        let bad: Vec<_> = (0..pts.len()).filter(|&i| got[i] != want[i]).take(5).collect();
        assert!(
            bad.is_empty(),
            "{name} {label}: points {:?} gpu {:?} cpu {:?}",
            bad.iter().map(|&i| pts[i]).collect::<Vec<_>>(),
            bad.iter().map(|&i| got[i]).collect::<Vec<_>>(),
            bad.iter().map(|&i| want[i]).collect::<Vec<_>>()
        );
        assert!(gpu.stats().flagged > 0, "{name} {label}: surface points must be flagged");
        assert!(gpu.stats().flagged < pts.len(), "{name} {label}: not everything may fall back");
    }
    for batch in [1, 16] {
        let mut gpu = GpuGridInclusion::new(&ctx, grid(mesh), batch).unwrap();
        let got = gpu.classify_all(pts).unwrap();
        let bad: Vec<_> = (0..pts.len()).filter(|&i| got[i] != want[i]).take(5).collect();
        assert!(
            bad.is_empty(),
            "{name} gpu+tetragrid batch {batch}: {:?}",
            bad.iter().map(|&i| (pts[i], got[i], want[i])).collect::<Vec<_>>()
        );
        assert!(gpu.stats().flagged > 0);
    }
    assert!(want.contains(&Class::Inside) && want.contains(&Class::Outside), "{name}: a weak test set");
}

#[test]
fn gpu_equals_cpu_on_builtin_models() {
    for name in ["cube", "tetrahedron", "pyramid", "sphere", "torus", "knot", "two-cubes", "cavity"] {
        let mesh = procedural::by_name(name).unwrap();
        check(&mesh, name, &query_points(&mesh, 10_000, 11));
    }
}

#[test]
fn gpu_equals_cpu_on_polygon_faces() {
    // An L-shaped prism with non-convex 6-gon caps: negative covering triangles.
    let mesh = procedural::l_prism();
    check(&mesh, "L-prism", &query_points(&mesh, 3000, 5));
}

#[test]
fn many_points_span_several_submissions() {
    let mesh = procedural::by_name("knot").unwrap();
    let pts = query_points(&mesh, 5000, 3);
    let ctx = ctx();
    let want = grid(&mesh).classify_all(&pts);
    let mut gpu =
        GpuInclusion::new(&ctx, grid(&mesh), GpuOptions { groups_per_draw: 4, ..Default::default() })
            .unwrap();
    assert_eq!(gpu.classify_all(&pts).unwrap(), want);
    assert!(gpu.stats().draws > 10);
}

#[test]
fn flat_tetras_fall_back_to_the_cpu() {
    // The apex on the cube's x = 1 face plane: that face's tetrahedra are flat.
    let mesh = procedural::cube();
    let apex = DVec3::new(1.0, 0.3, -0.2);
    let grid = || {
        let ft = FeitoTorres::with_options(&mesh, Some(apex), texgeo::inclusion::EdgeRule::Rerun).unwrap();
        GridClassifier::new(ft, 8).unwrap()
    };
    let mut pts = query_points(&mesh, 2000, 9);
    // Points in the flat tetrahedra's plane, inside and outside the face.
    let mut rng = Rng::new(2);
    for _ in 0..200 {
        pts.push(DVec3::new(1.0, rng.range_f64(-1.5, 1.5), rng.range_f64(-1.5, 1.5)));
    }
    let want = grid().classify_all(&pts);
    let ctx = ctx();
    let mut gpu = GpuInclusion::new(&ctx, grid(), GpuOptions::default()).unwrap();
    assert_eq!(gpu.classify_all(&pts).unwrap(), want);
    let on_face = pts[pts.len() - 200..].iter().filter(|p| p.y.abs() <= 1.0 && p.z.abs() <= 1.0).count();
    assert!(
        on_face > 50 && gpu.stats().flagged >= on_face,
        "points in the flat tetrahedra's plane are flagged"
    );
    let mut gpu = GpuGridInclusion::new(&ctx, grid(), 4).unwrap();
    assert_eq!(gpu.classify_all(&pts).unwrap(), want);
}
