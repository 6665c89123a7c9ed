//! The named test-shape set for subdivision (in the spirit of OpenSubdiv's
//! `regression/shapes`): small meshes that each exercise one case of the masks —
//! valence 3, triangles, all-regular, every valence 3…8 with an n-gon, boundaries and
//! corners, and a thesis-sized torus knot. CPU, GPU and reference tests share them.

#![allow(dead_code)]

use std::f64::consts::TAU;

use glam::DVec3;
use texgeo::mesh::{Mesh, procedural};

/// A shape of the set: its name (used in file names and messages) and mesh.
pub struct Shape {
    pub name: &'static str,
    pub mesh: Mesh,
}

fn mesh(positions: Vec<DVec3>, faces: Vec<Vec<u32>>) -> Mesh {
    Mesh::new(positions, faces).expect("test shapes are valid meshes")
}

/// Cube [−1,1]³, six quads: every vertex has valence 3 (the built-in model).
pub fn cube() -> Mesh {
    procedural::cube()
}

/// Cube without its top face: an open mesh, boundary vertices of valence 3.
pub fn open_cube() -> Mesh {
    let cube = cube();
    let faces = cube.faces().filter(|f| f != &[4, 5, 7, 6]).map(<[u32]>::to_vec).collect();
    mesh(cube.positions().to_vec(), faces)
}

/// Regular tetrahedron: four triangles, valence 3 (the built-in model).
pub fn tetrahedron() -> Mesh {
    procedural::tetrahedron()
}

/// Square pyramid: four triangles and a quad, apex valence 4, base valence 3 (the
/// built-in model).
pub fn pyramid() -> Mesh {
    procedural::pyramid()
}

/// Torus of `nu × nv` quads (major radius 2, minor 0.6): every vertex regular (valence 4).
pub fn torus(nu: u32, nv: u32) -> Mesh {
    procedural::torus(2.0, 0.6, nu as usize, nv as usize)
}

/// A closed mesh with vertices of every valence 3…8 and a heptagonal face: a heptagonal
/// prism (bottom kept as one 7-gon, top fanned to an apex of valence 7) whose side
/// strips are fanned to centres of valence 6 and 8, one side quad split by a diagonal.
pub fn valences() -> Mesh {
    let ring = |z: f64| {
        (0..7).map(move |i| {
            let a = TAU * f64::from(i) / 7.0;
            DVec3::new(a.cos(), a.sin(), z)
        })
    };
    let mut positions: Vec<DVec3> = ring(0.0).chain(ring(1.0)).collect(); // b_i = i, t_i = 7 + i
    let (b, t) = (|i: u32| i % 7, |i: u32| 7 + i % 7);
    let mut faces = vec![(0..7).rev().map(b).collect::<Vec<u32>>()]; // the 7-gon, seen from below
    positions.push(DVec3::new(0.0, 0.0, 1.5)); // apex A = 14
    faces.extend((0..7).map(|i| vec![t(i), t(i + 1), 14]));
    // Fans over side strips: quads 0–1 around S (valence 6), quads 4–6 around S' (valence 8).
    let fan = |cycle: Vec<u32>, positions: &mut Vec<DVec3>, faces: &mut Vec<Vec<u32>>| {
        let centre = cycle.iter().map(|&v| positions[v as usize]).sum::<DVec3>() / cycle.len() as f64;
        let centre = centre + DVec3::new(centre.x, centre.y, 0.0) * 0.3;
        let c = positions.len() as u32;
        positions.push(centre);
        for k in 0..cycle.len() {
            faces.push(vec![cycle[k], cycle[(k + 1) % cycle.len()], c]);
        }
    };
    fan(vec![b(0), b(1), b(2), t(2), t(1), t(0)], &mut positions, &mut faces);
    fan(vec![b(4), b(5), b(6), b(7), t(7), t(6), t(5), t(4)], &mut positions, &mut faces);
    faces.push(vec![b(2), b(3), t(3)]);
    faces.push(vec![b(2), t(3), t(2)]);
    faces.push(vec![b(3), b(4), t(4), t(3)]);
    mesh(positions, faces)
}

/// An `n × n` grid of quads in the plane: open, with corners of valence 2.
pub fn grid(n: u32) -> Mesh {
    let positions = (0..=n)
        .flat_map(|j| {
            (0..=n).map(move |i| DVec3::new(f64::from(i), f64::from(j), 0.1 * f64::from(i * j % 3)))
        })
        .collect();
    let id = |i: u32, j: u32| j * (n + 1) + i;
    let faces = (0..n)
        .flat_map(|j| (0..n).map(move |i| vec![id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)]))
        .collect();
    mesh(positions, faces)
}

/// The built-in (2,3) torus-knot tube with `2 · along · around` triangles: 75 × 8 is the
/// 1200-triangle `builtin:knot` (the thesis' "Torusknot"), 400 × 8 the 6400 of CGAL's
/// knot1.off.
pub fn torus_knot(along: usize, around: usize) -> Mesh {
    procedural::torus_knot_tube(along, around)
}

/// The committed OpenSubdiv outputs (`reference/subdiv/<name>-level<level>.off`, see its
/// README): shape name, shape, level.
pub fn committed_references() -> Vec<(&'static str, Mesh, u32)> {
    vec![
        ("cube", cube(), 1),
        ("cube", cube(), 2),
        ("tetrahedron", tetrahedron(), 1),
        ("open_cube", open_cube(), 1),
        ("grid", grid(3), 2),
        ("valences", valences(), 2),
    ]
}

/// The named set, small enough for every level the tests use.
pub fn all() -> Vec<Shape> {
    vec![
        Shape { name: "cube", mesh: cube() },
        Shape { name: "tetrahedron", mesh: tetrahedron() },
        Shape { name: "pyramid", mesh: pyramid() },
        Shape { name: "torus", mesh: torus(8, 6) },
        Shape { name: "valences", mesh: valences() },
        Shape { name: "grid", mesh: grid(3) },
        Shape { name: "open_cube", mesh: open_cube() },
        Shape { name: "torus_knot", mesh: procedural::torus_knot() },
    ]
}
