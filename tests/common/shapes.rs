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

/// The shells of `parts` in one mesh, vertices not shared.
pub fn union(parts: &[Mesh]) -> Mesh {
    let mut positions = Vec::new();
    let mut faces = Vec::new();
    for m in parts {
        let base = positions.len() as u32;
        positions.extend_from_slice(m.positions());
        faces.extend(m.faces().map(|f| f.iter().map(|&i| i + base).collect::<Vec<_>>()));
    }
    mesh(positions, faces)
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

/// Two `n × n` grids side by side whose touching borders have the same positions but
/// distinct vertices: after refinement the two borders' vertices coincide pairwise, so
/// only the refinement's own correspondence (not positions) tells them apart.
pub fn seam(n: u32) -> Mesh {
    let g = grid(n);
    let mut positions = g.positions().to_vec();
    positions.extend(g.positions().iter().map(|p| *p + DVec3::new(f64::from(n), 0.0, 0.0)));
    let o = g.num_vertices() as u32;
    let mut faces: Vec<Vec<u32>> = g.faces().map(<[u32]>::to_vec).collect();
    faces.extend(g.faces().map(|f| f.iter().map(|&v| v + o).collect::<Vec<u32>>()));
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

// ---------------------------------------------------------------------------------------
// Sharp features (issue 14): shapes of our own that cover what OpenSubdiv's regression
// suite (`regression/shapes/catmark_*`) covers — creases at sharpness 0.5 … 10 and
// infinite, chains, Chaikin, corners, holes, boundary modes, darts, valence-2 vertices,
// poles, non-manifold edges and vertices, fans, smooth triangles.

use texgeo::subdiv::features::{Corner, Crease};
use texgeo::subdiv::{Boundary, CreaseMethod, Features, Options, Surface, Triangles};

/// A surface of the sharp set: name, surface, deepest level tested, what it covers.
pub struct SharpShape {
    pub name: &'static str,
    pub surface: Surface,
    pub levels: u32,
    pub covers: &'static str,
}

/// A surface from a mesh, creases `(a, b, sharpness)`, corners `(v, sharpness)`, holes.
pub fn surface(
    mesh: Mesh,
    creases: &[(u32, u32, f32)],
    corners: &[(u32, f32)],
    holes: &[u32],
    options: Options,
) -> Surface {
    let features = Features {
        creases: creases.iter().map(|&(a, b, sharpness)| Crease { vertices: [a, b], sharpness }).collect(),
        corners: corners.iter().map(|&(vertex, sharpness)| Corner { vertex, sharpness }).collect(),
        holes: holes.to_vec(),
    };
    Surface { mesh, features, options }
}

fn with(boundary: Boundary, crease_method: CreaseMethod, triangles: Triangles) -> Options {
    Options { boundary, crease_method, triangles }
}

const EDGE_ONLY: Options = Options {
    boundary: Boundary::EdgeOnly,
    crease_method: CreaseMethod::Uniform,
    triangles: Triangles::Catmark,
};

/// The 12 edges of `cube()` (vertex bits: x 1, y 2, z 4).
pub fn cube_edges() -> Vec<(u32, u32)> {
    let mut edges = Vec::new();
    for v in 0..8u32 {
        for bit in [1, 2, 4] {
            if v & bit == 0 {
                edges.push((v, v | bit));
            }
        }
    }
    edges
}

/// Vertex (i, j) of `grid(n)`.
pub fn grid_vertex(n: u32, i: u32, j: u32) -> u32 {
    j * (n + 1) + i
}

/// A tent: a 4 × 3 grid folded along its middle row into a ridge.
pub fn tent() -> Mesh {
    let positions = (0..=3)
        .flat_map(|j| {
            (0..=4).map(move |i| {
                DVec3::new(f64::from(i), f64::from(j), if j == 1 || j == 2 { 1.0 } else { 0.0 })
            })
        })
        .collect();
    let id = |i: u32, j: u32| j * 5 + i;
    let faces = (0..3)
        .flat_map(|j| (0..4).map(move |i| vec![id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)]))
        .collect();
    mesh(positions, faces)
}

/// A cone over an `n`-gon fanned into triangles, base closed by the `n`-gon: a pole of
/// valence `n` at the apex (and the base's face point).
pub fn cone(n: u32) -> Mesh {
    let mut positions: Vec<DVec3> = (0..n)
        .map(|i| {
            let a = TAU * f64::from(i) / f64::from(n);
            DVec3::new(a.cos(), a.sin(), 0.0)
        })
        .collect();
    positions.push(DVec3::new(0.0, 0.0, 1.0));
    let mut faces: Vec<Vec<u32>> = (0..n).map(|i| vec![i, (i + 1) % n, n]).collect();
    faces.push((0..n).rev().collect());
    mesh(positions, faces)
}

/// A disk of `n` quads around a centre collapsed into it (quads `[r_i, r_i+1, c, c]`, a
/// degenerate edge each), inside a ring of `n` ordinary quads: OpenSubdiv's "quad pole".
pub fn quad_pole(n: u32) -> Mesh {
    let ring = |r: f64, z: f64| {
        (0..n).map(move |i| {
            let a = TAU * f64::from(i) / f64::from(n);
            DVec3::new(r * a.cos(), r * a.sin(), z)
        })
    };
    let mut positions: Vec<DVec3> = ring(1.0, 0.2).chain(ring(2.0, 0.0)).collect();
    positions.push(DVec3::new(0.0, 0.0, 0.4));
    let c = 2 * n;
    let mut faces: Vec<Vec<u32>> = (0..n).map(|i| vec![i, (i + 1) % n, c, c]).collect();
    faces.extend((0..n).map(|i| vec![n + i, n + (i + 1) % n, (i + 1) % n, i]));
    mesh(positions, faces)
}

/// The 3 × 3 grid with its centre quad replaced by two quads around a new vertex: an
/// interior vertex of valence 2.
pub fn valence2_interior() -> Mesh {
    let g = grid(3);
    let mut positions = g.positions().to_vec();
    let v = positions.len() as u32;
    positions.push(DVec3::new(1.5, 1.5, 0.3));
    let (a, x, b, y) =
        (grid_vertex(3, 1, 1), grid_vertex(3, 2, 1), grid_vertex(3, 2, 2), grid_vertex(3, 1, 2));
    let mut faces: Vec<Vec<u32>> = g.faces().filter(|f| f != &[a, x, b, y]).map(<[u32]>::to_vec).collect();
    faces.push(vec![v, a, x, b]);
    faces.push(vec![v, b, y, a]);
    mesh(positions, faces)
}

/// Two quads back to back on the same four vertices: closed, every vertex of valence 2.
pub fn back_to_back() -> Mesh {
    let positions = vec![
        DVec3::new(0.0, 0.0, 0.0),
        DVec3::new(1.0, 0.0, 0.1),
        DVec3::new(1.0, 1.0, 0.0),
        DVec3::new(0.0, 1.0, 0.1),
    ];
    mesh(positions, vec![vec![0, 1, 2, 3], vec![3, 2, 1, 0]])
}

/// The cube with a vertex in the middle of edge (0, 1): two pentagons meet at a vertex
/// of valence 2 that folds over the cube's edge.
pub fn valence2_ngons() -> Mesh {
    let c = cube();
    let mut positions = c.positions().to_vec();
    let m = positions.len() as u32;
    positions.push(DVec3::new(0.0, -1.0, -1.0));
    let faces = c
        .faces()
        .map(|f| {
            let mut out = Vec::new();
            for (k, &v) in f.iter().enumerate() {
                out.push(v);
                let w = f[(k + 1) % f.len()];
                if (v, w) == (0, 1) || (v, w) == (1, 0) {
                    out.push(m);
                }
            }
            out
        })
        .collect();
    mesh(positions, faces)
}

/// A book: `pages` quads on one spine edge (0, 1): an edge with `pages` faces.
pub fn book(pages: u32) -> Mesh {
    let mut positions = vec![DVec3::new(0.0, 0.0, 0.0), DVec3::new(0.0, 0.0, 1.0)];
    let mut faces = Vec::new();
    for k in 0..pages {
        let a = TAU * f64::from(k) / f64::from(pages);
        let (dx, dy) = (a.cos(), a.sin());
        let p = positions.len() as u32;
        positions.push(DVec3::new(dx, dy, 0.1 * f64::from(k % 3)));
        positions.push(DVec3::new(dx, dy, 1.0));
        faces.push(if k % 2 == 0 { vec![0, p, p + 1, 1] } else { vec![1, p + 1, p, 0] });
    }
    mesh(positions, faces)
}

/// Two quads on edge (0, 1) traversing it the same way (inconsistently oriented), and a
/// third quad continuing one of them.
pub fn same_direction() -> Mesh {
    let positions = vec![
        DVec3::new(0.0, 0.0, 0.0),
        DVec3::new(1.0, 0.0, 0.0),
        DVec3::new(1.0, 1.0, 0.0),
        DVec3::new(0.0, 1.0, 0.0),
        DVec3::new(1.0, 0.0, 1.0),
        DVec3::new(0.0, 0.0, 1.0),
        DVec3::new(1.0, 2.0, 0.2),
        DVec3::new(0.0, 2.0, 0.2),
    ];
    mesh(positions, vec![vec![0, 1, 2, 3], vec![0, 1, 4, 5], vec![3, 2, 6, 7]])
}

/// A 1 × 1 × 2 box whose middle ring is spanned by a membrane quad: the ring's edges have
/// three faces, and its vertices lie on a non-manifold crease (not sharpened).
pub fn membrane_box() -> Mesh {
    let positions = (0..3)
        .flat_map(|k| {
            [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)]
                .map(|(x, y)| DVec3::new(x, y, f64::from(k) + 0.1 * x * y))
        })
        .collect();
    let r = |k: u32, i: u32| 4 * k + i % 4;
    let mut faces = vec![vec![r(0, 0), r(0, 3), r(0, 2), r(0, 1)], vec![r(2, 0), r(2, 1), r(2, 2), r(2, 3)]];
    for k in 0..2 {
        for i in 0..4 {
            faces.push(vec![r(k, i), r(k, i + 1), r(k + 1, i + 1), r(k + 1, i)]);
        }
    }
    faces.push(vec![r(1, 0), r(1, 1), r(1, 2), r(1, 3)]);
    mesh(positions, faces)
}

/// Two pyramids touching at their apex (a closed bowtie) and, apart, two squares touching
/// at a corner (an open one): non-manifold vertices whose edges are all manifold.
pub fn bowties() -> Mesh {
    let p = pyramid();
    let mut positions = p.positions().to_vec();
    let apex = 4u32;
    positions.extend(p.positions()[..4].iter().map(|q| DVec3::new(q.x, q.y, 3.0 - q.z)));
    let mut faces: Vec<Vec<u32>> = p.faces().map(<[u32]>::to_vec).collect();
    let mirror = |v: u32| if v == apex { apex } else { 5 + v };
    faces.extend(p.faces().map(|f| f.iter().rev().map(|&v| mirror(v)).collect::<Vec<u32>>()));
    let o = positions.len() as u32;
    for (x, y) in [(3.0, 0.0), (4.0, 0.0), (4.0, 1.0), (3.0, 1.0), (5.0, 1.0), (5.0, 2.0), (4.0, 2.0)] {
        positions.push(DVec3::new(x, y, 0.0));
    }
    faces.push(vec![o, o + 1, o + 2, o + 3]);
    faces.push(vec![o + 2, o + 4, o + 5, o + 6]);
    mesh(positions, faces)
}

/// Quads around one vertex in three separate sheets, one of them a fan of three quads
/// whose middle edges also carry a fin: a non-manifold vertex with several fans.
pub fn fan() -> Mesh {
    let c = DVec3::ZERO;
    let mut positions = vec![c];
    let mut faces = Vec::new();
    let quad = |a: DVec3, b: DVec3, d: DVec3, positions: &mut Vec<DVec3>| {
        let o = positions.len() as u32;
        positions.extend([a, b, d]);
        (o, o + 1, o + 2)
    };
    // Sheet 1: a fan of three quads sharing edges 0–s1 and 0–s2.
    let s: Vec<u32> = (0..4)
        .map(|k| {
            let a = 0.5 * f64::from(k);
            positions.push(DVec3::new(a.cos(), a.sin(), 0.0));
            positions.len() as u32 - 1
        })
        .collect();
    for k in 0..3 {
        let a = 0.5 * k as f64 + 0.25;
        positions.push(DVec3::new(1.4 * a.cos(), 1.4 * a.sin(), 0.2));
        let m = positions.len() as u32 - 1;
        faces.push(vec![0, s[k], m, s[k + 1]]);
    }
    // A fin on edge 0–s1.
    positions.push(DVec3::new(0.5, 0.5, 1.0));
    let fin = positions.len() as u32 - 1;
    positions.push(DVec3::new(0.0, 0.0, 1.0));
    faces.push(vec![0, s[1], fin, fin + 1]);
    // Sheets 2 and 3: single quads touching only at the vertex.
    for (dir, z) in [(DVec3::new(-1.0, 0.0, 0.0), 0.3), (DVec3::new(0.0, -1.0, 0.0), -0.3)] {
        let side = DVec3::new(dir.y, -dir.x, 0.0);
        let (a, b, d) = quad(dir, dir + side + DVec3::new(0.0, 0.0, z), side, &mut positions);
        faces.push(vec![0, a, b, d]);
    }
    mesh(positions, faces)
}

/// The committed OpenSubdiv outputs of sharp shapes (`reference/subdiv/<name>.obj` with
/// tags, `<name>-level<level>.off`): shape name, level.
pub fn committed_sharp_references() -> Vec<(&'static str, u32)> {
    vec![
        ("cube_creases", 2),
        ("torus_chaikin", 2),
        ("grid_holes", 2),
        ("grid_boundary_none", 2),
        ("membrane_box", 2),
        ("quad_pole8", 2),
        ("tetrahedron_smooth", 2),
    ]
}

/// The sharp set.
pub fn sharp() -> Vec<SharpShape> {
    let e = EDGE_ONLY;
    let chaikin = with(Boundary::EdgeOnly, CreaseMethod::Chaikin, Triangles::Catmark);
    let all_cube = |s: f32| cube_edges().iter().map(|&(a, b)| (a, b, s)).collect::<Vec<_>>();
    let torus_ring = |values: &[f32]| {
        // Torus(8, 6) vertex (i, j) is i·6 + j: the ring j = 0 around u.
        (0..8u32).map(|i| (i * 6, ((i + 1) % 8) * 6, values[i as usize % values.len()])).collect::<Vec<_>>()
    };
    let g = |i, j| grid_vertex(4, i, j);
    let t = |i: u32, j: u32| j * 5 + i;
    vec![
        SharpShape {
            name: "cube_creases",
            surface: surface(cube(), &[(4, 5, 0.5), (5, 7, 1.0), (7, 6, 2.5), (6, 4, 10.0)], &[], &[], e),
            levels: 4,
            covers: "creases of sharpness 0.5, 1, 2.5, infinite around a face; crease vertices",
        },
        SharpShape {
            name: "cube_semisharp",
            surface: surface(cube(), &all_cube(2.3), &[], &[], e),
            levels: 4,
            covers: "every edge 2.3: corners of three semi-sharp edges fading to smooth",
        },
        SharpShape {
            name: "cube_infinite",
            surface: surface(cube(), &all_cube(10.0), &[], &[], e),
            levels: 4,
            covers: "every edge infinitely sharp",
        },
        SharpShape {
            name: "cube_junctions",
            surface: surface(
                cube(),
                &[(0, 1, 0.3), (0, 2, 0.6), (0, 4, 0.45), (3, 7, 1.3), (5, 7, 1.6), (6, 7, 1.45)],
                &[(7, 0.8)],
                &[],
                e,
            ),
            levels: 4,
            covers: "three semi-sharp edges decaying together at a vertex (f32 sums in OpenSubdiv's order), a corner of 0.8",
        },
        SharpShape {
            name: "cube_corners",
            surface: surface(cube(), &[], &[(0, 0.5), (3, 2.5), (5, 10.0), (6, 1.7)], &[], e),
            levels: 4,
            covers: "semi-sharp and infinite corners",
        },
        SharpShape {
            name: "cube_dart",
            surface: surface(cube(), &[(0, 1, 10.0), (2, 3, 1.5)], &[], &[], e),
            levels: 4,
            covers: "darts: single crease edges ending at smooth vertices",
        },
        SharpShape {
            name: "cube_chaikin",
            surface: surface(
                cube(),
                &[(0, 1, 2.7), (1, 3, 1.1), (3, 2, 3.9), (2, 0, 0.6), (0, 4, 2.2)],
                &[],
                &[],
                chaikin,
            ),
            levels: 4,
            covers: "Chaikin creasing along a loop and into a junction",
        },
        SharpShape {
            name: "tent_creases",
            surface: surface(
                tent(),
                &[
                    (t(0, 1), t(1, 1), 2.0),
                    (t(1, 1), t(2, 1), 2.0),
                    (t(2, 1), t(3, 1), 0.5),
                    (t(3, 1), t(4, 1), 10.0),
                ],
                &[],
                &[],
                e,
            ),
            levels: 4,
            covers: "a tent: ridge creases meeting the boundary (corner rule there)",
        },
        SharpShape {
            name: "tent_corner",
            surface: surface(
                tent(),
                &[
                    (t(0, 2), t(1, 2), 10.0),
                    (t(1, 2), t(2, 2), 10.0),
                    (t(2, 2), t(3, 2), 10.0),
                    (t(3, 2), t(4, 2), 10.0),
                ],
                &[(t(2, 2), 3.0)],
                &[],
                with(Boundary::EdgeAndCorner, CreaseMethod::Uniform, Triangles::Catmark),
            ),
            levels: 4,
            covers: "infinite ridge with a semi-sharp corner on it; boundary edge-and-corner",
        },
        SharpShape {
            name: "torus_creases",
            surface: {
                let mut creases = torus_ring(&[1.5]);
                // A chain across the ring along v at i = 2: ends are darts, the crossing a corner.
                creases.extend([(12, 13, 4.0), (13, 14, 4.0), (17, 12, 4.0)]);
                surface(torus(8, 6), &creases, &[], &[], e)
            },
            levels: 4,
            covers: "a torus with a closed crease loop and a chain crossing it",
        },
        SharpShape {
            name: "torus_chaikin",
            surface: {
                let mut creases = torus_ring(&[0.5, 1.7, 2.3, 3.9, 1.2, 0.8, 2.6, 10.0]);
                creases.extend([(12, 13, 2.9), (17, 12, 1.3)]);
                surface(torus(8, 6), &creases, &[], &[], chaikin)
            },
            levels: 4,
            covers: "Chaikin along a loop of varying sharpness, four semi-sharp edges at a vertex",
        },
        SharpShape {
            name: "grid_holes",
            surface: surface(grid(4), &[(g(0, 2), g(1, 2), 2.0)], &[], &[5, 6, 10, 0, 2], e),
            levels: 4,
            covers: "holes: single, adjacent, at a boundary corner and edge",
        },
        SharpShape {
            name: "cube_hole",
            surface: surface(cube(), &[(4, 5, 3.0)], &[], &[5], e),
            levels: 4,
            covers: "a hole in a closed mesh next to a crease",
        },
        SharpShape {
            name: "grid_boundary_none",
            surface: surface(
                grid(4),
                &[
                    (g(0, 0), g(1, 0), 10.0),
                    (g(1, 0), g(2, 0), 10.0),
                    (g(2, 0), g(3, 0), 10.0),
                    (g(4, 3), g(4, 4), 10.0),
                ],
                &[],
                &[],
                with(Boundary::None, CreaseMethod::Uniform, Triangles::Catmark),
            ),
            levels: 4,
            covers: "boundary none: boundary faces dropped except where boundary edges are tagged infinite",
        },
        SharpShape {
            name: "grid_edge_and_corner",
            surface: surface(
                grid(3),
                &[(grid_vertex(3, 1, 1), grid_vertex(3, 2, 1), 1.5)],
                &[],
                &[],
                with(Boundary::EdgeAndCorner, CreaseMethod::Uniform, Triangles::Catmark),
            ),
            levels: 4,
            covers: "boundary edge-and-corner: valence-2 corners stay",
        },
        SharpShape {
            name: "grid_edge_only",
            surface: surface(grid(3), &[(grid_vertex(3, 0, 1), grid_vertex(3, 1, 1), 10.0)], &[], &[], e),
            levels: 4,
            covers: "boundary edge-only; an infinite crease running into the boundary",
        },
        SharpShape {
            name: "valence2_interior",
            surface: surface(valence2_interior(), &[], &[], &[], e),
            levels: 4,
            covers: "an interior vertex of valence 2",
        },
        SharpShape {
            name: "valence2_crease",
            surface: surface(valence2_interior(), &[(16, 5, 2.0), (16, 10, 2.0)], &[], &[], e),
            levels: 4,
            covers: "a crease through an interior vertex of valence 2",
        },
        SharpShape {
            name: "valence2_back_to_back",
            surface: surface(back_to_back(), &[], &[], &[], e),
            levels: 4,
            covers: "two quads back to back: every vertex of valence 2",
        },
        SharpShape {
            name: "valence2_ngons",
            surface: surface(valence2_ngons(), &[(8, 1, 1.5)], &[], &[], e),
            levels: 4,
            covers: "a valence-2 vertex folded over an edge between pentagons, half creased",
        },
        SharpShape {
            name: "pole8",
            surface: surface(cone(8), &[], &[], &[], e),
            levels: 4,
            covers: "a pole of valence 8",
        },
        SharpShape {
            name: "pole64",
            surface: surface(cone(64), &[(0, 1, 2.0)], &[], &[], e),
            levels: 3,
            covers: "a pole of valence 64",
        },
        SharpShape {
            name: "pole360",
            surface: surface(cone(360), &[], &[], &[], e),
            levels: 3,
            covers: "a pole of valence 360",
        },
        SharpShape {
            name: "quad_pole8",
            surface: surface(quad_pole(8), &[], &[], &[], e),
            levels: 4,
            covers: "a pole of degenerate quads (non-manifold degenerate edges), valence 8",
        },
        SharpShape {
            name: "quad_pole64",
            surface: surface(quad_pole(64), &[], &[], &[], e),
            levels: 3,
            covers: "a pole of degenerate quads, valence 64",
        },
        SharpShape {
            name: "quad_pole360",
            surface: surface(quad_pole(360), &[], &[], &[], e),
            levels: 3,
            covers: "a pole of degenerate quads, valence 360",
        },
        SharpShape {
            name: "fin",
            surface: surface(book(3), &[], &[], &[], e),
            levels: 4,
            covers: "an edge with three faces",
        },
        SharpShape {
            name: "book",
            surface: surface(
                book(8),
                &[(0, 2, 1.5)],
                &[],
                &[],
                with(Boundary::EdgeAndCorner, CreaseMethod::Uniform, Triangles::Catmark),
            ),
            levels: 4,
            covers: "an edge with eight faces",
        },
        SharpShape {
            name: "same_direction",
            surface: surface(same_direction(), &[], &[], &[], e),
            levels: 4,
            covers: "two faces traversing an edge the same way",
        },
        SharpShape {
            name: "membrane_box",
            surface: surface(membrane_box(), &[], &[], &[], e),
            levels: 4,
            covers: "a non-manifold crease: a ring of three-face edges, vertices not sharpened",
        },
        SharpShape {
            name: "membrane_box_creased",
            surface: surface(membrane_box(), &[(4, 8, 1.5)], &[], &[], e),
            levels: 4,
            covers: "a semi-sharp edge meeting a non-manifold crease (decays on the CPU first)",
        },
        SharpShape {
            name: "membrane_box_corner",
            surface: surface(membrane_box(), &[(4, 8, 1.5), (0, 4, 10.0)], &[], &[], e),
            levels: 4,
            covers: "semi-sharp and infinite edges at a non-manifold crease vertex: a corner for good",
        },
        SharpShape {
            name: "repeated_vertex",
            surface: surface(
                mesh(
                    vec![
                        DVec3::new(0.0, 0.0, 0.0),
                        DVec3::new(1.0, 0.0, 0.0),
                        DVec3::new(0.0, 1.0, 0.0),
                        DVec3::new(1.0, 1.0, 0.3),
                        DVec3::new(2.0, 0.5, 0.2),
                    ],
                    vec![vec![0, 1, 0, 2], vec![1, 3, 2, 0], vec![1, 4, 3]],
                ),
                &[(1, 3, 1.5)],
                &[],
                &[],
                e,
            ),
            levels: 4,
            covers: "a face using a vertex twice (repeated, non-manifold edges)",
        },
        SharpShape {
            name: "bowties",
            surface: surface(bowties(), &[], &[], &[], e),
            levels: 4,
            covers: "closed and open bowtie vertices",
        },
        SharpShape {
            name: "fan",
            surface: surface(fan(), &[(0, 3, 2.0)], &[], &[], e),
            levels: 4,
            covers: "a fan: sheets around one vertex, a fin",
        },
        SharpShape {
            name: "tetrahedron_smooth",
            surface: surface(
                tetrahedron(),
                &[],
                &[],
                &[],
                with(Boundary::EdgeOnly, CreaseMethod::Uniform, Triangles::Smooth),
            ),
            levels: 4,
            covers: "smooth triangles",
        },
        SharpShape {
            name: "pyramid_smooth_creased",
            surface: surface(
                pyramid(),
                &[(0, 1, 3.0), (1, 4, 0.7)],
                &[(4, 1.2)],
                &[],
                with(Boundary::EdgeOnly, CreaseMethod::Uniform, Triangles::Smooth),
            ),
            levels: 4,
            covers: "smooth triangles with creases and a corner",
        },
        SharpShape {
            name: "valences_creased",
            surface: surface(
                valences(),
                &[(0, 1, 2.0), (1, 2, 2.0), (7, 14, 10.0), (8, 14, 0.9)],
                &[],
                &[3],
                e,
            ),
            levels: 4,
            covers: "n-gons and every valence 3…8 with creases and a hole",
        },
        SharpShape {
            name: "bare_vertices",
            surface: {
                let gm = grid(2);
                let mut positions = gm.positions().to_vec();
                positions.extend([DVec3::new(5.0, 0.0, 0.0), DVec3::new(5.0, 1.0, 1.0)]);
                surface(mesh(positions, gm.faces().map(<[u32]>::to_vec).collect()), &[], &[(9, 2.0)], &[], e)
            },
            levels: 4,
            covers: "vertices no face uses, one tagged as a corner",
        },
    ]
}
