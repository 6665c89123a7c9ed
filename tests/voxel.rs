//! Voxelization: every method gives the identical bit volume, equal to the
//! exact inclusion test at every voxel centre, on built-in solids (holed, non-manifold,
//! polygon faces, a cavity) and on solids built so voxel centres fall exactly on faces,
//! edges and vertices (the tie rule) or a hair off them (the GPU fallback bound). Runs on
//! the default device (lavapipe in tools/test) with validation when TEXGEO_VALIDATION=1.

mod common;

use glam::DVec3;
use texgeo::gpu::Context;
use texgeo::inclusion::{Class, Classifier, FeitoTorres};
use texgeo::mesh::{Mesh, procedural};
use texgeo::random::Rng;
use texgeo::voxel::{
    Grid, Method, Solid, Volume, VoxelError, Voxelizer, binvox, cpu, exact, scanline, voxelize,
};

fn gpu() -> Context {
    Context::from_env().expect("a Vulkan device (run tools/setup)")
}

/// Union of disjoint closed meshes (vertices renumbered).
fn union(parts: &[Mesh]) -> Mesh {
    let (mut p, mut f) = (Vec::new(), Vec::new());
    for m in parts {
        let base = p.len() as u32;
        p.extend_from_slice(m.positions());
        f.extend(m.faces().map(|face| face.iter().map(|&i| i + base).collect::<Vec<_>>()));
    }
    Mesh::new(p, f).unwrap()
}

fn cube_at(lo: f64, hi: f64) -> Mesh {
    procedural::box_between(DVec3::splat(lo), DVec3::splat(hi))
}

/// `inner` plus two unit cubes in opposite corners of [0, 32]³, so the grid at N = 32 has
/// h = 1 and voxel centres at exact half-integers.
fn on_lattice(inner: Mesh) -> Mesh {
    union(&[inner, cube_at(0.0, 1.0), cube_at(31.0, 32.0)])
}

/// A prism over the counter-clockwise polygon `xz` between y = y0 and y1, caps as n-gons.
fn prism(xz: &[(f64, f64)], y0: f64, y1: f64) -> Mesh {
    let n = xz.len() as u32;
    let mut p: Vec<DVec3> = xz.iter().map(|&(x, z)| DVec3::new(x, y0, z)).collect();
    p.extend(xz.iter().map(|&(x, z)| DVec3::new(x, y1, z)));
    // Counter-clockwise in (x, z) seen from +y is clockwise seen from outside the top.
    let mut f = vec![(0..n).collect::<Vec<_>>(), (n..2 * n).rev().collect()];
    for i in 0..n {
        let j = (i + 1) % n;
        f.push(vec![i, n + i, n + j, j]);
    }
    Mesh::new(p, f).unwrap()
}

/// An L-shaped prism: its caps are non-convex hexagons whose centroid fan has negative
/// covering triangles.
fn l_prism() -> Mesh {
    prism(&[(0.0, 0.0), (0.0, 4.0), (1.0, 4.0), (1.0, 1.0), (3.0, 1.0), (3.0, 0.0)], 0.0, 1.5)
}

/// `mesh` with every vertex moved onto the half-integer lattice of the N = 32 grid
/// (plus `jitter` in each coordinate): ties everywhere, or near-ties.
fn snapped(mesh: &Mesh, scale: f64, shift: f64, jitter: f64, rng: &mut Rng) -> Mesh {
    let positions = mesh
        .positions()
        .iter()
        .map(|&p| {
            let q = (p * scale + DVec3::splat(shift) - DVec3::splat(0.5)).round() + DVec3::splat(0.5);
            q + DVec3::new(
                rng.range_f64(-jitter, jitter),
                rng.range_f64(-jitter, jitter),
                rng.range_f64(-jitter, jitter),
            )
        })
        .collect();
    Mesh::new(positions, mesh.faces().map(<[u32]>::to_vec).collect()).unwrap()
}

/// Exact occupancy of every voxel centre by the ray-parity oracle.
fn exact_volume(mesh: &Mesh, n: usize) -> (Grid, Solid, Volume) {
    let grid = Grid::for_mesh(mesh, n).unwrap();
    let solid = Solid::new(mesh).unwrap();
    let mut v = Volume::new(n).unwrap();
    for j in 0..n {
        for k in 0..n {
            for i in 0..n {
                if exact::inside_by_ray(&solid.triangles, grid.centre(i, j, k)) {
                    v.set(i, j, k, true);
                }
            }
        }
    }
    (grid, solid, v)
}

/// The volume [`scanline::x_planes`] streams, gathered plane by plane.
fn streamed(solid: &Solid, grid: &Grid) -> Result<Volume, std::io::Error> {
    let mut v = Volume::new(grid.n).unwrap();
    let mut x0 = 0;
    let occupied = scanline::x_planes(solid, grid, |planes| {
        for p in 0..planes.len() {
            for k in 0..grid.n {
                for (w, &bits) in planes.row(p, k).iter().enumerate() {
                    for b in (0..64).filter(|b| bits >> b & 1 == 1) {
                        v.set(x0 + p, 64 * w + b, k, true);
                    }
                }
            }
        }
        x0 += planes.len();
        Ok(())
    })?;
    assert_eq!(x0, grid.n, "every plane once");
    assert_eq!(occupied, v.count(), "the count of occupied voxels");
    Ok(v)
}

/// Runs every method, and the scanline streamed in x planes, and checks each against
/// `expected`.
fn all_methods_equal(v: &mut Voxelizer, name: &str, mesh: &Mesh, n: usize, expected: &Volume) {
    let grid = Grid::for_mesh(mesh, n).unwrap();
    let solid = Solid::new(mesh).unwrap();
    let planes = streamed(&solid, &grid).unwrap_or_else(|e| panic!("{name} {n}³ x planes: {e}"));
    let diff = planes.differences(expected, 5).unwrap();
    assert!(diff.is_empty(), "{name} {n}³ x planes: voxels differ, e.g. {diff:?}");
    for m in Method::ALL {
        let r = v.run(&solid, &grid, m).unwrap_or_else(|e| panic!("{name} {n}³ {m}: {e}"));
        let diff = r.volume.differences(expected, 5).unwrap();
        assert!(
            diff.is_empty(),
            "{name} {n}³ {m}: {} voxels differ, e.g. {diff:?}",
            r.volume.count_differences(expected).unwrap()
        );
    }
}

#[test]
fn every_method_matches_the_exact_test_on_builtin_solids() {
    let mut v = Voxelizer::new(Some(gpu()));
    let models: Vec<(&str, Mesh)> = vec![
        ("cube", procedural::cube()),
        ("pyramid", procedural::pyramid()),
        ("sphere", procedural::sphere(12, 24)),
        ("torus", procedural::torus(1.0, 0.4, 24, 12)),
        ("knot", procedural::torus_knot()),
        ("two-cubes", procedural::two_cubes_sharing_edge()),
        ("cavity", procedural::cube_with_cavity()),
        ("l-prism", l_prism()),
    ];
    for (name, mesh) in &models {
        // Every voxel against the brute-force exact oracle at 32³.
        let (_, _, expected) = exact_volume(mesh, 32);
        assert!(expected.count() > 0, "{name}");
        all_methods_equal(&mut v, name, mesh, 32, &expected);
        // Larger grids: every method against the exact scanline.
        for n in [64, 128] {
            let expected = voxelize(None, mesh, n, Method::Scanline).unwrap().volume;
            all_methods_equal(&mut v, name, mesh, n, &expected);
        }
    }
}

#[test]
fn parallel_rasterizers_and_encoder_give_the_same_bits_for_any_thread_count() {
    let dir = common::TempDir::new("voxel-threads");
    let in_pool = |threads: usize, work: &(dyn Fn() -> (Volume, Volume, Vec<u8>, Vec<u8>) + Sync)| {
        rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap().install(work)
    };
    for (name, mesh) in [("knot", procedural::torus_knot()), ("cavity", procedural::cube_with_cavity())] {
        // Sizes below, at and above one slab per slice, and rows of 1, 2 and 3 words;
        // one, several and a partial last batch of x planes.
        for n in [1, 7, 16, 64, 130, 150] {
            let grid = Grid::for_mesh(&mesh, n).unwrap();
            let solid = Solid::new(&mesh).unwrap();
            let file = dir.join(&format!("{name}-{n}.binvox"));
            let run = || {
                let s = scanline::voxelize(&solid, &grid).unwrap();
                let c = cpu::voxelize(&solid, &grid).unwrap().0;
                let bytes = binvox::to_bytes(&grid, &s).unwrap();
                let streamed = binvox::write_scanline(&file, &grid, &solid).unwrap();
                assert!(!streamed.whole_volume && streamed.occupied == s.count(), "{name} {n}³ {streamed:?}");
                (s, c, bytes, std::fs::read(&file).unwrap())
            };
            let one = in_pool(1, &run);
            assert_eq!(one.0, one.1, "{name} {n}³: cpu and scanline differ");
            assert!(one.3 == one.2, "{name} {n}³: the streamed file differs from the whole volume's");
            for threads in [2, 3, 5] {
                let many = in_pool(threads, &run);
                assert_eq!(many.0, one.0, "{name} {n}³ scanline, {threads} threads");
                assert_eq!(many.1, one.1, "{name} {n}³ cpu, {threads} threads");
                assert!(many.2 == one.2, "{name} {n}³ binvox bytes, {threads} threads");
                assert!(many.3 == one.3, "{name} {n}³ streamed binvox bytes, {threads} threads");
            }
        }
    }
}

#[test]
fn voxels_agree_with_feito_torres_and_the_tetra_oracle() {
    for (name, mesh) in
        [("knot", procedural::torus_knot()), ("cavity", procedural::cube_with_cavity()), ("l", l_prism())]
    {
        let n = 32;
        let r = voxelize(None, &mesh, n, Method::Cpu).unwrap();
        let ft = FeitoTorres::new(&mesh).unwrap();
        let solid = Solid::new(&mesh).unwrap();
        let (mut checked, mut boundary) = (0, 0);
        for j in 0..n {
            for k in 0..n {
                for i in 0..n {
                    let p = r.grid.centre(i, j, k);
                    let got = r.volume.get(i, j, k);
                    match ft.classify(p) {
                        Class::Inside => assert!(got, "{name} ({i},{j},{k}) inside"),
                        Class::Outside => assert!(!got, "{name} ({i},{j},{k}) outside"),
                        Class::OnBoundary => boundary += 1,
                    }
                    if (i + j + k) % 7 == 0 {
                        assert_eq!(
                            exact::inside_by_tetras(&solid.triangles, solid.apex, p),
                            got,
                            "{name} ({i},{j},{k})"
                        );
                    }
                    checked += 1;
                }
            }
        }
        assert_eq!(checked, n * n * n);
        assert!(boundary < checked / 100, "{name}: {boundary} centres on the boundary");
    }
}

#[test]
fn the_tie_rule_on_a_box_with_faces_on_centre_planes() {
    // Faces at x = 2.5, 9.5; y = 2.5, 7.5; z = 3.5, 20.5: voxel centres lie on all six.
    let inner = procedural::box_between(DVec3::new(2.5, 2.5, 3.5), DVec3::new(9.5, 7.5, 20.5));
    let mesh = on_lattice(inner);
    let (grid, _, expected) = exact_volume(&mesh, 32);
    assert_eq!(grid.h(), 1.0);
    // Half-open in every axis: centres on the low faces are in, on the high faces out.
    let mut rule = Volume::new(32).unwrap();
    for j in 2..7 {
        for k in 3..20 {
            rule.xor_span(j, k, 2, 9);
        }
    }
    rule.set(0, 0, 0, true);
    rule.set(31, 31, 31, true);
    assert_eq!(expected, rule, "the exact oracle follows the documented rule");
    let mut v = Voxelizer::new(Some(gpu()));
    all_methods_equal(&mut v, "box on centre planes", &mesh, 32, &rule);
    // With exactly representable coordinates the raw rasterizers already follow the rule:
    // the CPU's half-open spans, and the GPU's top-left rule (x right, z down).
    v.fallback = false;
    let solid = Solid::new(&mesh).unwrap();
    for m in [Method::Cpu, Method::Fgpu, Method::Pgpu, Method::Zoned] {
        let raw = v.run(&solid, &grid, m).unwrap();
        assert_eq!(raw.volume, rule, "raw {m}");
    }
}

#[test]
fn the_tie_rule_on_slanted_faces_edges_and_vertices() {
    // Octahedra centred on a voxel corner with half-integer radius: their faces, edges and
    // vertices pass through voxel centres.
    let mut v = Voxelizer::new(Some(gpu()));
    for (o, r) in [(16.0, 10.5), (15.0, 6.5), (16.0, 3.5)] {
        let mesh = on_lattice(procedural::octahedron(DVec3::splat(o), r));
        let (_, solid, expected) = exact_volume(&mesh, 32);
        // Cross-check the ray oracle with the tetra oracle on every centre.
        let grid = Grid::for_mesh(&mesh, 32).unwrap();
        for j in 0..32 {
            for k in 0..32 {
                for i in 0..32 {
                    let p = grid.centre(i, j, k);
                    assert_eq!(
                        exact::inside_by_tetras(&solid.triangles, solid.apex, p),
                        expected.get(i, j, k),
                        "({i},{j},{k})"
                    );
                }
            }
        }
        all_methods_equal(&mut v, &format!("octahedron {o} {r}"), &mesh, 32, &expected);
    }
}

#[test]
fn lattice_snapped_and_jittered_solids() {
    // Vertices exactly on voxel centres (ties on every vertex, many edges and faces), and
    // then a hair off them: 1e-9 (below any rasterizer's resolution), 1e-4 and 3e-3 voxels
    // (inside the GPU's fallback bound), 0.05 (outside it).
    let mut v = Voxelizer::new(Some(gpu()));
    let mut rng = Rng::new(4);
    let shapes =
        [("sphere", procedural::sphere(8, 12), 11.0), ("torus", procedural::torus(1.0, 0.45, 12, 8), 9.0)];
    for (name, shape, scale) in &shapes {
        for jitter in [0.0, 1e-9, 1e-4, 3e-3, 0.05] {
            let mesh = on_lattice(snapped(shape, *scale, 16.0, jitter, &mut rng));
            let (_, _, expected) = exact_volume(&mesh, 32);
            all_methods_equal(&mut v, &format!("{name} snapped, jitter {jitter}"), &mesh, 32, &expected);
        }
    }
}

#[test]
fn interior_edges_cancel_when_the_apex_is_a_voxel_centre() {
    // Any apex gives the same voxels. With the apex on a voxel centre and every mesh
    // vertex on the lattice, many tetra edges and faces inside the solid pass exactly
    // through voxel centres, far from the surface where no fallback applies: only
    // bit-identical shared cross-section edges get those centres right.
    let mut v = Voxelizer::new(Some(gpu()));
    let mut rng = Rng::new(9);
    for (name, shape, scale) in [
        ("sphere", procedural::sphere(10, 16), 12.0),
        ("knot", procedural::torus_knot(), 4.0),
        ("cube", procedural::cube(), 11.0),
    ] {
        let mesh = on_lattice(snapped(&shape, scale, 16.0, 0.0, &mut rng));
        let (grid, mut solid, expected) = exact_volume(&mesh, 32);
        for apex in [DVec3::splat(16.5), DVec3::new(15.5, 16.5, 17.5)] {
            solid.apex = apex;
            for m in Method::ALL {
                let r = v.run(&solid, &grid, m).unwrap();
                let diff = r.volume.differences(&expected, 5).unwrap();
                assert!(diff.is_empty(), "{name} apex {apex} {m}: {diff:?}");
            }
        }
    }
}

#[test]
fn near_surface_centres_are_fixed_and_counted() {
    // A sphere whose surface passes within 1e-6 voxels of many centres: the GPU methods
    // must send them to the exact fallback.
    let mut v = Voxelizer::new(Some(gpu()));
    let mesh = procedural::sphere(24, 48);
    let grid = Grid::for_mesh(&mesh, 64).unwrap();
    let solid = Solid::new(&mesh).unwrap();
    let reference = v.run(&solid, &grid, Method::Scanline).unwrap().volume;
    for m in [Method::Pgpu, Method::Fang] {
        let r = v.run(&solid, &grid, m).unwrap();
        assert_eq!(r.volume, reference, "{m}");
        assert!(r.band.candidates > 0 && r.band.tolerance > 0.0, "{m}: {:?}", r.band);
        assert!(r.band.changed <= r.band.candidates);
    }
}

#[test]
fn bad_requests_get_clear_errors() {
    let cube = procedural::cube();
    assert!(matches!(voxelize(None, &cube, 0, Method::Cpu), Err(VoxelError::Resolution { .. })));
    let err = voxelize(None, &cube, 100_000, Method::Cpu).unwrap_err();
    assert!(err.to_string().contains("1024"), "{err}");
    // An open box (top face missing).
    let b = procedural::box_between(DVec3::ZERO, DVec3::ONE);
    let open = Mesh::new(b.positions().to_vec(), b.faces().skip(1).map(<[u32]>::to_vec).collect()).unwrap();
    let err = voxelize(None, &open, 16, Method::Cpu).unwrap_err();
    assert!(matches!(err, VoxelError::Mesh(_)) && err.to_string().contains("closed"), "{err}");
    // A flat mesh has no volume to voxelize but is still handled.
    let gpu_needed = voxelize(None, &cube, 16, Method::Pgpu).unwrap_err();
    assert!(gpu_needed.to_string().contains("Vulkan"), "{gpu_needed}");
}

#[test]
fn an_odd_row_falls_back_to_the_whole_volume() {
    // A covering with a hole (built directly: `Solid::new` refuses open meshes) leaves
    // rows that meet it once. The x planes notice at the end, and the file written
    // instead is the whole volume's, never a half-checked one.
    let cube = procedural::cube();
    let grid = Grid::for_mesh(&cube, 24).unwrap();
    let mut solid = Solid::new(&cube).unwrap();
    solid.triangles.remove(0);
    let err = streamed(&solid, &grid).unwrap_err();
    assert!(err.get_ref().is_some_and(|e| e.is::<scanline::OddRow>()), "{err}");
    let dir = common::TempDir::new("voxel-odd-row");
    let file = dir.join("open.binvox");
    let written = binvox::write_scanline(&file, &grid, &solid).unwrap();
    assert!(written.whole_volume);
    let whole = scanline::voxelize(&solid, &grid).unwrap();
    assert_eq!(written.occupied, whole.count());
    assert!(std::fs::read(&file).unwrap() == binvox::to_bytes(&grid, &whole).unwrap());
    assert_eq!(dir.entries(), ["open.binvox"], "no temporary file left");
}
