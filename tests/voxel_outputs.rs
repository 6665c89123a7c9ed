//! Voxelization outputs and the TetraGrid: binvox round trips and rejects bad files, PNG
//! slice stacks, the Perlin aspect function, and the conservative rasterizer against an
//! exact tetra/box overlap test on random tetras.

use std::path::Path;

use glam::DVec3;
use texgeo::gpu::Context;
use texgeo::inclusion::cells::{Cells, Growth, MIN_OFFSET, SPEC_OFFSET, TetraGrid, tetra_box_overlap};
use texgeo::mesh::procedural;
use texgeo::random::Rng;
use texgeo::voxel::aspect::{self, Aspect, Material};
use texgeo::voxel::{Grid, Method, binvox, pictures, voxelize};

mod common;

use common::TempDir;

#[test]
fn binvox_round_trips_exactly() {
    for (mesh, n) in
        [(procedural::torus_knot(), 37), (procedural::cube_with_cavity(), 64), (procedural::cube(), 1)]
    {
        let r = voxelize(None, &mesh, n, Method::Scanline).unwrap();
        let bytes = binvox::to_bytes(&r.grid, &r.volume).unwrap();
        assert!(bytes.starts_with(format!("#binvox 1\ndim {n} {n} {n}\n").as_bytes()));
        let (grid, volume) = binvox::from_bytes(&bytes, Path::new("mem.binvox")).unwrap();
        assert_eq!(grid, r.grid);
        assert_eq!(volume, r.volume);
        // Through a file as well.
        let dir = TempDir::new("voxel-binvox");
        let path = dir.join("v.binvox");
        binvox::write(&path, &r.grid, &r.volume).unwrap();
        assert_eq!(binvox::read(&path).unwrap(), (r.grid, r.volume.clone()));
    }
}

#[test]
fn binvox_order_is_x_then_z_then_y() {
    // One occupied voxel at (x, y, z) = (1, 0, 0): index x·N² = 4 in a 2³ volume.
    let grid = Grid::new(2, DVec3::ZERO, 2.0).unwrap();
    let mut v = texgeo::voxel::Volume::new(2).unwrap();
    v.set(1, 0, 0, true);
    let bytes = binvox::to_bytes(&grid, &v).unwrap();
    let data = &bytes[bytes.len() - 6..];
    assert_eq!(data, &[0, 4, 1, 1, 0, 3]);
}

#[test]
fn bad_binvox_files_are_rejected_with_a_reason() {
    let good = b"#binvox 1\ndim 2 2 2\ntranslate 0 0 0\nscale 1\ndata\n\x00\x08".to_vec();
    assert!(binvox::from_bytes(&good, Path::new("g")).is_ok());
    let cases: Vec<(Vec<u8>, &str)> = vec![
        (b"hello\n".to_vec(), "binvox"),
        (b"#binvox 1\ndim 2 2 3\ndata\n".to_vec(), "cubic"),
        (b"#binvox 1\ndim 5000 5000 5000\ndata\n".to_vec(), "1024"),
        (b"#binvox 1\ndim 2 2 2\ndata\n\x00\x07".to_vec(), "cover"),
        (b"#binvox 1\ndim 2 2 2\ndata\n\x00\x09".to_vec(), "more than"),
        (b"#binvox 1\ndim 2 2 2\ndata\n\x02\x08".to_vec(), "value"),
        (b"#binvox 1\ndim 2 2 2\ndata\n\x00".to_vec(), "pairs"),
        (b"#binvox 1\ndim 2 2 2\nscale nan\ndata\n\x00\x08".to_vec(), "scale"),
        (b"#binvox 1\ndim 2 2 2\ntranslate".to_vec(), "header"),
        (b"#binvox 1\nscale 1\ndata\n".to_vec(), "dim"),
    ];
    for (bytes, expect) in cases {
        let err = binvox::from_bytes(&bytes, Path::new("bad.binvox")).unwrap_err().to_string();
        assert!(err.contains("bad.binvox") && err.contains(expect), "{err:?} should mention {expect:?}");
    }
}

#[test]
fn slice_pngs_show_the_slices() {
    let r = voxelize(None, &procedural::torus(1.0, 0.4, 24, 12), 24, Method::Cpu).unwrap();
    let dir = TempDir::new("voxel-slices");
    let files = pictures::write_slices(&r.volume, dir.path()).unwrap();
    assert_eq!(files.len(), 24);
    for (j, f) in files.iter().enumerate() {
        let img = image::open(f).unwrap().to_luma8();
        assert_eq!(img.dimensions(), (24, 24));
        for (i, k, p) in img.enumerate_pixels() {
            assert_eq!(p.0[0] == 255, r.volume.get(i as usize, j, k as usize));
        }
    }
}

#[test]
fn the_aspect_function_colours_exactly_the_occupied_voxels() {
    let ctx = Context::from_env().expect("a Vulkan device");
    let r = voxelize(None, &procedural::torus_knot(), 40, Method::Cpu).unwrap();
    for material in Material::ALL {
        let slices = aspect::render(&ctx, &r.volume, &Aspect { material, ..Aspect::default() }).unwrap();
        assert_eq!(slices.len(), 40);
        let mut colours = std::collections::HashSet::new();
        for (j, s) in slices.iter().enumerate() {
            for k in 0..40 {
                for i in 0..40 {
                    let px = &s[(k * 40 + i) * 4..(k * 40 + i) * 4 + 4];
                    assert_eq!(px[3] == 255, r.volume.get(i, j, k), "{material:?} ({i},{j},{k})");
                    if px[3] == 0 {
                        assert_eq!(px, [0, 0, 0, 0]);
                    } else {
                        colours.insert([px[0], px[1], px[2]]);
                    }
                }
            }
        }
        // Noise, not a flat colour.
        assert!(colours.len() > 20, "{material:?}: {} colours", colours.len());
    }
}

/// Random tetras over [0, 1]³: regular ones, slivers (a vertex near the opposite face)
/// and needles (three vertices close together).
fn random_tetra(rng: &mut Rng) -> [DVec3; 4] {
    let p = |rng: &mut Rng| rng.point_in_box(DVec3::splat(0.05), DVec3::splat(0.95));
    let mut t = [p(rng), p(rng), p(rng), p(rng)];
    match rng.below(3) {
        0 => {}
        1 => t[3] = (t[0] + t[1] + t[2]) / 3.0 + DVec3::splat(rng.range_f64(-1e-3, 1e-3)),
        _ => {
            t[1] = t[0] + DVec3::splat(rng.range_f64(-2e-3, 2e-3));
            t[2] = t[0] + DVec3::new(rng.range_f64(-2e-3, 2e-3), 0.0, rng.range_f64(-2e-3, 2e-3));
        }
    }
    t
}

#[test]
fn conservative_rasterization_never_misses_a_touched_cell() {
    let mut rng = Rng::new(45);
    for n in [7usize, 16, 32] {
        let grid = Grid::new(n, DVec3::ZERO, 1.0).unwrap();
        let cells_of = Cells::new(grid.min, grid.h(), n);
        let h = grid.h();
        for _ in 0..60 {
            let t = random_tetra(&mut rng);
            for growth in [
                Growth::Diagonals(MIN_OFFSET),
                Growth::Diagonals(SPEC_OFFSET),
                Growth::CellBox { extra: 0.0 },
            ] {
                let mut cells = Vec::new();
                cells_of.rasterize(&t, growth, |c| cells.push(c as u32));
                let listed: std::collections::HashSet<u32> = cells.iter().copied().collect();
                assert_eq!(listed.len(), cells.len(), "no duplicates");
                let mut touched = 0;
                for j in 0..n {
                    for k in 0..n {
                        for i in 0..n {
                            let lo = grid.min + DVec3::new(i as f64, j as f64, k as f64) * h;
                            if tetra_box_overlap(&t, lo, lo + DVec3::splat(h)) {
                                touched += 1;
                                let c = cells_of.index([i, j, k]) as u32;
                                assert!(listed.contains(&c), "n {n} {growth:?}: cell ({i},{j},{k}) of {t:?}");
                            }
                        }
                    }
                }
                // Conservative, but not the whole grid: every listed cell is within the
                // offset (plus a cell diagonal) of the tetra's box.
                assert!(cells.len() >= touched);
                let (tlo, thi) = (
                    t.iter().fold(DVec3::INFINITY, |m, &p| m.min(p)),
                    t.iter().fold(DVec3::NEG_INFINITY, |m, &p| m.max(p)),
                );
                let offset = match growth {
                    Growth::Diagonals(d) => d,
                    Growth::CellBox { .. } => 0.5,
                };
                let reach = (offset + 1.0) * h * 3f64.sqrt();
                for &c in &cells {
                    let c = c as usize;
                    let (i, j, k) = (c % n, c / n % n, c / (n * n));
                    let centre = grid.centre(i, j, k);
                    assert!(
                        centre.cmpge(tlo - DVec3::splat(reach)).all()
                            && centre.cmple(thi + DVec3::splat(reach)).all()
                    );
                }
            }
        }
    }
}

#[test]
fn the_overlap_test_itself_is_right_on_simple_cases() {
    let t = [DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z];
    assert!(tetra_box_overlap(&t, DVec3::splat(0.1), DVec3::splat(0.2)));
    assert!(!tetra_box_overlap(&t, DVec3::splat(0.4), DVec3::splat(0.5))); // beyond x+y+z = 1
    assert!(tetra_box_overlap(&t, DVec3::splat(0.3), DVec3::splat(0.5))); // corner (0.3)³ inside
    assert!(!tetra_box_overlap(&t, DVec3::new(-1.0, -1.0, -1.0), DVec3::splat(-0.1)));
    // Touching at a corner counts (closed sets).
    assert!(tetra_box_overlap(&t, DVec3::new(1.0, 0.0, 0.0), DVec3::new(2.0, 1.0, 1.0)));
}

#[test]
fn tetragrid_lists_every_tetra_of_a_solid_in_its_cells() {
    let mesh = procedural::torus_knot();
    let solid = texgeo::voxel::Solid::new(&mesh).unwrap();
    let grid = Grid::for_mesh(&mesh, 16).unwrap();
    let cells = Cells::new(grid.min, grid.h(), 16);
    let tetras = solid.tetras();
    for growth in
        [Growth::CellBox { extra: 0.0 }, Growth::Diagonals(MIN_OFFSET), Growth::Diagonals(SPEC_OFFSET)]
    {
        let tg = TetraGrid::of_tetras(cells, &tetras, growth).unwrap();
        let (start, ids) = tg.lists();
        assert_eq!(start.len(), 16 * 16 * 16 + 1);
        assert_eq!(*start.last().unwrap() as usize, ids.len());
        let mut rng = Rng::new(3);
        // A point inside a tetra is found in its cell's list.
        for _ in 0..2000 {
            let id = rng.below(tetras.len() as u64) as usize;
            let t = tetras[id];
            let w = [rng.next_f64(), rng.next_f64(), rng.next_f64(), rng.next_f64()];
            let s: f64 = w.iter().sum();
            let p = (t[0] * w[0] + t[1] * w[1] + t[2] * w[2] + t[3] * w[3]) / s;
            assert!(tg.tetras_at(p).binary_search(&(id as u32)).is_ok(), "tetra {id} at {p}");
        }
    }
    let size = |g| TetraGrid::of_tetras(cells, &tetras, g).unwrap().lists().1.len();
    let (tight, small, spec) = (
        size(Growth::CellBox { extra: 0.0 }),
        size(Growth::Diagonals(MIN_OFFSET)),
        size(Growth::Diagonals(SPEC_OFFSET)),
    );
    assert!(tight <= small && small < spec, "{tight} {small} {spec}");
}

#[test]
fn the_inclusion_tetragrid_uses_the_conservative_rasterizer() {
    use texgeo::inclusion::tetragrid::GridClassifier as InclusionGrid;
    use texgeo::inclusion::{Classifier, FeitoTorres};
    for mesh in
        [procedural::torus_knot(), procedural::cube_with_cavity(), procedural::two_cubes_sharing_edge()]
    {
        let reference = FeitoTorres::new(&mesh).unwrap();
        let boxes = InclusionGrid::with_cover(
            FeitoTorres::new(&mesh).unwrap(),
            16,
            texgeo::inclusion::tetragrid::box_cover,
        )
        .unwrap();
        let raster = InclusionGrid::new(FeitoTorres::new(&mesh).unwrap(), 16).unwrap();
        let (lo, hi) = mesh.bounds();
        let mut rng = Rng::new(8);
        let mut points = rng.points_in_box(4000, lo - (hi - lo) * 0.05, hi + (hi - lo) * 0.05);
        // Points on the covering's vertices, edges and faces too.
        for f in mesh.faces().take(200) {
            let p = mesh.positions();
            points.push(p[f[0] as usize]);
            points.push((p[f[0] as usize] + p[f[1] as usize]) * 0.5);
            points.push((p[f[0] as usize] + p[f[1] as usize] + p[f[2] as usize]) / 3.0);
        }
        for &p in &points {
            let expected = reference.classify(p);
            assert_eq!(raster.classify(p), expected, "{p}");
            assert_eq!(boxes.classify(p), expected, "{p}");
        }
        let (_, ids) = raster.cell_lists();
        assert!(!ids.is_empty());
    }
}
