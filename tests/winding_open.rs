//! Meshes that are not solids, under `--allow-open`: inside iff the generalized winding
//! number is at least ½. The certified hierarchical evaluation against the winding number
//! summed directly, every CPU method and `voxelize` against it, and the commands' words.

mod common;

use common::shapes::{open_cube, union};
use common::{TempDir, assert_refused, stderr, stdout, texgeo};
use glam::DVec3;
use rayon::prelude::*;
use texgeo::inclusion::fast_winding::{FastWinding, TOLERANCES};
use texgeo::inclusion::winding::WindingNumber;
use texgeo::inclusion::{Choice, Class, Classifier, InclusionError, Method, Options, Solver, build};
use texgeo::mesh::procedural::{box_between, cube};
use texgeo::mesh::solidity::{self, flipped};
use texgeo::mesh::{Mesh, formats};
use texgeo::random::Rng;
use texgeo::voxel::Grid;

/// The upper half of the unit sphere (z ≥ 0), facing outwards, open along the equator.
fn hemisphere(n: usize) -> Mesh {
    let mut positions = vec![DVec3::Z];
    for i in 1..=n {
        let theta = std::f64::consts::FRAC_PI_2 * i as f64 / n as f64;
        for j in 0..2 * n {
            let phi = std::f64::consts::PI * j as f64 / n as f64;
            positions.push(DVec3::new(theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos()));
        }
    }
    let ring = |i: usize, j: usize| (1 + (i - 1) * 2 * n + j % (2 * n)) as u32;
    let mut faces = Vec::new();
    for j in 0..2 * n {
        faces.push(vec![0, ring(1, j), ring(1, j + 1)]);
    }
    for i in 1..n {
        for j in 0..2 * n {
            faces.push(vec![ring(i, j), ring(i + 1, j), ring(i + 1, j + 1), ring(i, j + 1)]);
        }
    }
    Mesh::new(positions, faces).unwrap()
}

/// A bumpy open sheet over [−1, 1]², like the face of a scanned head: one boundary loop.
fn patch(n: u32) -> Mesh {
    let mut positions = Vec::new();
    for j in 0..=n {
        for i in 0..=n {
            let (x, y) = (2.0 * i as f64 / n as f64 - 1.0, 2.0 * j as f64 / n as f64 - 1.0);
            positions.push(DVec3::new(x, y, 0.3 * (3.0 * x).sin() * (2.0 * y).cos() + 0.4 * (1.0 - x * x)));
        }
    }
    let v = |i: u32, j: u32| j * (n + 1) + i;
    let mut faces = Vec::new();
    for j in 0..n {
        for i in 0..n {
            faces.push(vec![v(i, j), v(i + 1, j), v(i + 1, j + 1)]);
            faces.push(vec![v(i, j), v(i + 1, j + 1), v(i, j + 1)]);
        }
    }
    Mesh::new(positions, faces).unwrap()
}

/// The meshes of the rule, by name: open, self-intersecting, nested, inverted.
fn non_solids() -> Vec<(&'static str, Mesh)> {
    vec![
        ("open cube", open_cube()),
        ("hemisphere", hemisphere(10)),
        ("patch", patch(12)),
        ("overlapping cubes", union(&[cube(), box_between(DVec3::ZERO, DVec3::splat(2.0))])),
        ("nested cubes", union(&[box_between(DVec3::splat(-2.0), DVec3::splat(2.0)), cube()])),
        ("inverted cube", flipped(&cube())),
    ]
}

/// Random points in the mesh's box grown by a fifth, and points a hair (10⁻³ … 10⁻⁸ of
/// the diagonal) off either side of random points of its faces.
fn probes(mesh: &Mesh, n: usize, seed: u64) -> Vec<DVec3> {
    let (lo, hi) = mesh.bounds();
    let d = (hi - lo).length();
    let mut rng = Rng::new(seed);
    let mut pts = rng.points_in_box(n / 2, lo - 0.2 * (hi - lo), hi + 0.2 * (hi - lo));
    let faces: Vec<&[u32]> = mesh.faces().collect();
    let pos = mesh.positions();
    for k in 0..n - n / 2 {
        let f = faces[k % faces.len()];
        let [a, b, c] = [pos[f[0] as usize], pos[f[1] as usize], pos[f[2] as usize]];
        let (u, v) = (rng.next_f64(), rng.next_f64());
        let (u, v) = if u + v > 1.0 { (1.0 - u, 1.0 - v) } else { (u, v) };
        let normal = (b - a).cross(c - a).normalize();
        let hair = d * 10f64.powi(-3 - (k % 6) as i32) * if k % 2 == 0 { 1.0 } else { -1.0 };
        pts.push(a + u * (b - a) + v * (c - a) + hair * normal);
    }
    pts
}

#[test]
fn the_bound_holds_against_direct_sums_on_a_hundred_thousand_points() {
    let mesh = hemisphere(14);
    let fw = FastWinding::new(&mesh, 0).unwrap();
    let pts = probes(&mesh, 100_000, 7);
    let (worst, mean) = pts
        .par_iter()
        .map(|&p| {
            let exact = fw.tree().direct(p);
            let mut worst: f64 = 0.0;
            for tol in TOLERANCES {
                let e = fw.tree().winding(p, tol);
                let gap = (e.w - exact.w).abs();
                assert!(gap <= e.err + exact.err, "{p}, tol {tol}: {e:?} vs direct {exact:?}");
                worst = worst.max(gap / (e.err + exact.err).max(f64::MIN_POSITIVE));
            }
            // The label agrees with the direct sum wherever that sum decides.
            if let Some(inside) = exact.decides(0.0) {
                let (class, _) = fw.classify_point(p);
                if class != Class::OnBoundary {
                    assert_eq!(class == Class::Inside, inside, "{p}: {exact:?}");
                }
            }
            (worst, fw.tree().winding(p, TOLERANCES[1]).err)
        })
        .reduce(|| (0.0, 0.0), |a, b| (a.0.max(b.0), a.1 + b.1));
    // The bound is not vacuous: the second walk's bound is small on average.
    let mean = mean / pts.len() as f64;
    assert!(mean < 0.05, "mean bound {mean}");
    assert!(worst <= 1.0, "{worst}");
}

#[test]
fn every_cpu_method_answers_by_the_winding_number_and_gpu_methods_refuse() {
    for (name, mesh) in non_solids() {
        let s = solidity::check(&mesh);
        assert!(!s.is_solid(), "{name}");
        let pts = probes(&mesh, 4000, 3);
        // The oracle: every triangle summed for every point.
        let direct = WindingNumber::with_policy(&mesh, true).unwrap();
        let fw = FastWinding::new(&mesh, 0).unwrap();
        let expected: Vec<Class> = pts.iter().map(|&p| direct.classify(p)).collect();
        let got = fw.classify_all(&pts);
        for (k, (&p, (&e, &g))) in pts.iter().zip(expected.iter().zip(&got)).enumerate() {
            let w = direct.winding_number(p);
            if (w - 0.5).abs() > 1e-9 {
                assert_eq!(g, e, "{name}: point {k} {p}, w {w}");
            }
        }
        // With enough points for the cell grid, and whatever method is asked for.
        let options = Options { allow_open: true, non_solid: true, points: 50_000, ..Options::default() };
        let cpu = Method::ALL.into_iter().filter(|m| m.is_cpu()).map(Choice::Fixed);
        for method in std::iter::once(Choice::Auto).chain(cpu) {
            let c = build(method, &mesh, &options).unwrap();
            assert_eq!(c.classify_all(&pts), got, "{name}: {method}");
        }
        for method in Method::ALL.into_iter().filter(|m| !m.is_cpu()) {
            let e = Solver::new(method, &mesh, &options, None, None).err().unwrap();
            assert!(matches!(e, InclusionError::NotForNonSolids(_)), "{name}: {method}: {e}");
        }
    }
}

#[test]
fn what_the_rule_says_for_each_kind_of_mesh() {
    let inside = |mesh: &Mesh, p: DVec3| FastWinding::new(mesh, 0).unwrap().classify(p) == Class::Inside;
    let [open, hemi, _, overlap, nested, inverted]: [Mesh; 6] =
        non_solids().into_iter().map(|(_, m)| m).collect::<Vec<_>>().try_into().unwrap();
    // w = 5/6 at the centre of a cube without its top; ½ only on the missing face's square.
    assert!(inside(&open, DVec3::ZERO) && !inside(&open, DVec3::new(0.0, 0.0, 1.1)));
    // Under a hemisphere's dome w > ½ (it and the disc it lacks wind once; the disc winds
    // less than ½ from above it); below the rim's plane w < ½.
    assert!(inside(&hemi, DVec3::new(0.0, 0.0, 0.8)) && inside(&hemi, DVec3::new(0.0, 0.0, 0.05)));
    assert!(!inside(&hemi, DVec3::new(0.0, 0.0, -0.05)));
    // Overlapping shells: w = 2 where they overlap, inside; nested the same way: inside.
    assert!(inside(&overlap, DVec3::splat(0.5)) && inside(&overlap, DVec3::splat(1.5)));
    assert!(!inside(&overlap, DVec3::new(-0.5, 1.5, 0.5)));
    assert!(inside(&nested, DVec3::ZERO) && inside(&nested, DVec3::new(1.5, 0.0, 0.0)));
    // Inverted: w = −1 inside, so outside.
    assert!(!inside(&inverted, DVec3::ZERO) && !inside(&inverted, DVec3::splat(3.0)));
    assert_eq!(FastWinding::new(&inverted, 0).unwrap().estimate(DVec3::ZERO).w.round(), -1.0);
}

#[test]
fn voxelize_labels_every_centre_as_inclusion_does() {
    for (name, mesh) in non_solids() {
        for n in [13, 24] {
            let grid = Grid::for_mesh(&mesh, n).unwrap();
            let fw = FastWinding::new(&mesh, 0).unwrap();
            let volume = fw.voxelize(&grid).unwrap();
            // inclusion with its cell grid (many points) and without.
            let cells = FastWinding::new(&mesh, 50_000).unwrap();
            let centres: Vec<[usize; 3]> =
                (0..n).flat_map(|j| (0..n).flat_map(move |k| (0..n).map(move |i| [i, j, k]))).collect();
            let pts: Vec<DVec3> = centres.iter().map(|&[i, j, k]| grid.centre(i, j, k)).collect();
            for classes in [cells.classify_all(&pts), fw.classify_all(&pts)] {
                for (&[i, j, k], &c) in centres.iter().zip(&classes) {
                    assert_eq!(volume.get(i, j, k), c == Class::Inside, "{name} n {n} ({i},{j},{k}): {c:?}");
                }
            }
        }
    }
}

#[test]
fn voxelize_gives_the_same_bits_for_any_thread_count() {
    // The slabs are taller with fewer threads; the rows do not depend on them.
    for (name, mesh) in non_solids() {
        let fw = FastWinding::new(&mesh, 0).unwrap();
        for n in [7, 33, 70] {
            let grid = Grid::for_mesh(&mesh, n).unwrap();
            let in_pool = |threads: usize| {
                let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
                pool.install(|| fw.voxelize(&grid).unwrap())
            };
            let one = in_pool(1);
            for threads in [2, 3, 5] {
                assert_eq!(in_pool(threads), one, "{name} {n}³, {threads} threads");
            }
        }
    }
}

fn save(dir: &TempDir, name: &str, mesh: &Mesh) -> String {
    let path = dir.join(name);
    formats::write(&path, mesh).unwrap();
    path.to_string_lossy().into_owned()
}

#[test]
fn commands_take_non_solids_with_the_flag_and_say_what_they_do() {
    let dir = TempDir::new("winding-open");
    let open = save(&dir, "open.off", &open_cube());
    let o = texgeo(&["mesh", "stats", &open]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stdout(&o)
            .contains("open: 4 boundary edges in 1 loop; inside by winding number ≥ ½ with --allow-open"),
        "{}",
        stdout(&o)
    );
    let overlap = save(&dir, "overlap.off", &non_solids()[3].1);
    let inverted = save(&dir, "inverted.off", &flipped(&cube()));
    for (mesh, words) in [
        (&overlap, &["not a solid", "overlap", "at least ½"][..]),
        (&inverted, &["not a solid", "inverted", "−1", "--flip-inverted"][..]),
    ] {
        let o = texgeo(&["inclusion", mesh, "--random", "300", "--allow-open"]);
        assert!(o.status.success(), "{}", stderr(&o));
        let err = stderr(&o);
        assert_eq!(err.matches("warning").count(), 1, "{err}");
        for w in words {
            assert!(err.contains(w), "expected '{w}' in {err}");
        }
        // voxelize: the same warning; the GPU methods refuse.
        let out = dir.arg("v.binvox");
        let o = texgeo(&["voxelize", mesh, "--res", "16", "--allow-open", "-o", &out]);
        assert!(o.status.success(), "{}", stderr(&o));
        assert_eq!(stderr(&o).matches("warning").count(), 1, "{}", stderr(&o));
        let o = texgeo(&["voxelize", mesh, "--res", "16", "--allow-open", "--method", "zoned", "-o", &out]);
        assert_refused(&o, &["solids only", "--allow-open"]);
        // Without the flag: refused, and the flag is named.
        let o = texgeo(&["voxelize", mesh, "--res", "16", "-o", &out]);
        assert_refused(&o, &["not a solid", "--allow-open"]);
    }
    // On a solid the flag changes nothing, byte for byte.
    let (a, b) = (dir.arg("a.binvox"), dir.arg("b.binvox"));
    for method in ["auto", "cpu", "scanline"] {
        let o = texgeo(&["voxelize", "builtin:torus", "--res", "24", "--method", method, "-o", &a]);
        assert!(o.status.success(), "{}", stderr(&o));
        let o = texgeo(&[
            "voxelize",
            "builtin:torus",
            "--res",
            "24",
            "--method",
            method,
            "--allow-open",
            "-o",
            &b,
        ]);
        assert!(o.status.success() && !stderr(&o).contains("warning"), "{}", stderr(&o));
        assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap(), "{method}");
    }
}

#[test]
fn a_sweep_with_the_flag_records_non_solids_with_their_defect() {
    let dir = TempDir::new("winding-sweep");
    let meshes = dir.join("meshes");
    std::fs::create_dir_all(&meshes).unwrap();
    for (name, mesh) in non_solids().into_iter().take(4) {
        formats::write(meshes.join(format!("{}.off", name.replace(' ', "-"))), &mesh).unwrap();
    }
    let out = dir.arg("out");
    let m = meshes.to_string_lossy().into_owned();
    let o = texgeo(&[
        "sweep",
        &m,
        "--task",
        "inclusion",
        "--method",
        "cpu",
        "--points",
        "300",
        "--allow-open",
        "-o",
        &out,
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let csv = std::fs::read_to_string(dir.join("out").join("sweep.csv")).unwrap();
    assert!(csv.lines().next().unwrap().contains("check_non_solid"), "{csv}");
    assert_eq!(csv.lines().filter(|l| l.contains(",ok,")).count(), 4, "{csv}");
    assert!(
        csv.contains("not-closed") && (csv.contains("self-intersecting") || csv.contains("crossing-shells")),
        "{csv}"
    );
}

#[test]
fn voxelize_closes_every_hole_and_keeps_centres_on_faces_empty() {
    // A tube open at both ends (two loops of its boundary), two open cubes whose holes face
    // each other, and an open cube on grids whose centres lie on its faces, edges and rim.
    let tube = {
        let m = 12;
        let ring = |z: f64| {
            (0..m).map(move |i| {
                let a = std::f64::consts::TAU * i as f64 / m as f64;
                DVec3::new(a.cos(), a.sin(), z)
            })
        };
        let positions = ring(-1.0).chain(ring(1.0)).collect();
        let faces = (0..m).map(|i| vec![i, (i + 1) % m, m + (i + 1) % m, m + i]).collect();
        Mesh::new(positions, faces).unwrap()
    };
    let facing = {
        let a = open_cube();
        let turned: Vec<DVec3> =
            a.positions().iter().map(|p| DVec3::new(p.x + 0.5, p.y, 3.5 - p.z)).collect();
        let b = Mesh::new(turned, a.faces().map(|f| f.iter().rev().copied().collect()).collect()).unwrap();
        union(&[a, b])
    };
    let fitted = |n: usize, h: f64| Grid::new(n, DVec3::splat(-(n as f64) * h / 2.0), n as f64 * h).unwrap();
    let cases = [
        ("tube", tube.clone(), Grid::for_mesh(&tube, 20).unwrap()),
        ("facing cubes", facing.clone(), Grid::for_mesh(&facing, 23).unwrap()),
        ("open cube on centres", open_cube(), fitted(5, 1.0)),
        ("open cube on half centres", open_cube(), fitted(9, 0.5)),
    ];
    for (name, mesh, grid) in cases {
        let fw = FastWinding::new(&mesh, 0).unwrap();
        let volume = fw.voxelize(&grid).unwrap();
        let n = grid.n;
        let mut on_faces = 0;
        for (i, j, k) in (0..n).flat_map(|j| (0..n).flat_map(move |k| (0..n).map(move |i| (i, j, k)))) {
            let (class, _) = fw.classify_point(grid.centre(i, j, k));
            on_faces += (class == Class::OnBoundary) as usize;
            assert_eq!(volume.get(i, j, k), class == Class::Inside, "{name} ({i},{j},{k}): {class:?}");
        }
        if name.contains("centres") {
            assert!(on_faces > 0, "{name}: no centre on a face");
        }
    }
}
