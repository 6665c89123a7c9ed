//! Catmull-Clark fragment passes (2010 thesis): the smooth shader, the sharp variants
//! (semi-sharp and infinite creases, uniform and Chaikin creasing, corners), boundaries
//! and high valences whose fragments span several texture rows, against the CPU
//! reference refinement to the float32 tolerance. Every case must run at least one level
//! as fragment passes on the GPU.

use glam::DVec3;

use super::{Check, Needs, Step, Stop};
use crate::gpu::Context;
use crate::mesh::{Mesh, procedural};
use crate::subdiv::compare::Comparison;
use crate::subdiv::features::Corner;
use crate::subdiv::gpu::{Options, Subdivider};
use crate::subdiv::{Boundary, CreaseMethod, Features, Surface, cpu};

/// float32 GPU positions against the f64 reference, relative to the bounding-box diagonal.
const TOLERANCE: f64 = 1e-5;

pub(super) fn checks() -> Vec<Check> {
    let needs = Needs { texture: 256, ..Needs::default() };
    vec![
        Check {
            name: "subdiv-smooth",
            what: "smooth fragment passes: quads (valence 3, 4), triangles, n-gons; to level 3",
            needs,
            run: smooth,
        },
        Check {
            name: "subdiv-creases",
            what: "sharp fragment passes: creases 0.5, 1, 2.5, infinite; uniform and Chaikin creasing",
            needs,
            run: creases,
        },
        Check {
            name: "subdiv-corners",
            what: "sharp fragment passes: semi-sharp and infinitely sharp corners",
            needs,
            run: corners,
        },
        Check {
            name: "subdiv-boundary",
            what: "half-fan fragments at boundaries: edge-only and edge-and-corner interpolation",
            needs,
            run: boundary,
        },
        Check {
            name: "subdiv-valence",
            what: "high valences (8, 40): fragments spanning several 64-texel rows",
            needs,
            run: valence,
        },
    ]
}

/// Refines `surface` on the GPU and with the CPU reference at `level` and compares.
fn same_surface(
    ctx: &Context,
    sub: &mut Subdivider,
    case: &str,
    surface: &Surface,
    level: u32,
    options: &Options,
) -> Step {
    let run = sub.refine_surface(ctx, surface, level, options)?;
    let case = format!("{case}, level {level}");
    if run.gpu_levels == 0 {
        return Err(Stop::error(format!(
            "{case}: no level ran as fragment passes on the GPU ({})",
            if run.cpu_reasons.is_empty() {
                "no reason given".to_string()
            } else {
                run.cpu_reasons.join("; ")
            }
        )));
    }
    let reference = cpu::refine_surface(surface, level)?.mesh;
    let c = Comparison::new(&run.mesh, &reference, TOLERANCE);
    if c.is_match() {
        return Ok(());
    }
    if c.vertices[0] != c.vertices[1] || c.faces[0] != c.faces[1] {
        return Err(Stop::mismatch(
            format!("{case}: vertices, faces"),
            (c.vertices[1], c.faces[1]),
            (c.vertices[0], c.faces[0]),
        ));
    }
    // Both list their faces in the same order: the first corner too far from its
    // reference position is the first mismatch.
    for (f, (g, r)) in run.mesh.faces().zip(reference.faces()).enumerate() {
        for (corner, (&a, &b)) in g.iter().zip(r).enumerate() {
            let (got, want) = (run.mesh.positions()[a as usize], reference.positions()[b as usize]);
            if got.distance(want) > c.tolerance {
                return Err(Stop::mismatch(
                    format!("{case}: face {f}, corner {corner} (tolerance {:.2e})", c.tolerance),
                    want.to_array(),
                    got.to_array(),
                ));
            }
        }
    }
    let summary = c.to_string();
    Err(Stop::error(format!("{case}: {}", summary.lines().next().unwrap_or("the meshes differ"))))
}

/// Every case runs in one subdivider, as the commands reuse theirs.
fn each(ctx: &Context, cases: Vec<(String, Surface, u32, Options)>) -> Step {
    let mut sub = Subdivider::new(ctx)?;
    for (case, surface, level, options) in cases {
        same_surface(ctx, &mut sub, &case, &surface, level, &options)?;
    }
    Ok(())
}

fn smooth(ctx: &Context) -> Step {
    let d = Options::default();
    each(
        ctx,
        vec![
            ("cube".into(), Surface::smooth(procedural::cube()), 3, d),
            ("torus".into(), Surface::smooth(procedural::torus(1.0, 0.4, 8, 6)), 2, d),
            ("pyramid".into(), Surface::smooth(procedural::pyramid()), 3, d),
            ("tetrahedron".into(), Surface::smooth(procedural::tetrahedron()), 3, d),
            ("L-prism (hexagons)".into(), Surface::smooth(procedural::l_prism()), 3, d),
        ],
    )
}

/// The cube with its 12 edges creased in turn at 0.5, 1, 2.5 and infinitely sharp.
fn creased_cube(method: CreaseMethod) -> Surface {
    let cube = procedural::cube();
    let mut features = Features::feature_edges(&cube, 30.0, 10.0);
    for (e, crease) in features.creases.iter_mut().enumerate() {
        crease.sharpness = [0.5, 1.0, 2.5, 10.0][e % 4];
    }
    let mut surface = Surface { mesh: cube, features, options: Default::default() };
    surface.options.crease_method = method;
    surface
}

fn creases(ctx: &Context) -> Step {
    let d = Options::default();
    // One semi-sharp crease loop on the torus: sharp fragments among smooth ones.
    let torus = procedural::torus(1.0, 0.4, 8, 6);
    let mut ring = Features::feature_edges(&torus, 0.0, 1.5);
    ring.creases.truncate(6);
    each(
        ctx,
        vec![
            ("cube, creases".into(), creased_cube(CreaseMethod::Uniform), 3, d),
            ("cube, Chaikin creasing".into(), creased_cube(CreaseMethod::Chaikin), 3, d),
            (
                "torus, semi-sharp edges".into(),
                Surface { mesh: torus, features: ring, options: Default::default() },
                3,
                d,
            ),
            (
                "cube, creases, one shader for every run".into(),
                creased_cube(CreaseMethod::Uniform),
                3,
                Options { single_shader: true, ..d },
            ),
        ],
    )
}

fn corners(ctx: &Context) -> Step {
    let corners = [(0, 0.5), (3, 2.5), (5, 10.0), (6, 1.7)]
        .map(|(vertex, sharpness)| Corner { vertex, sharpness })
        .to_vec();
    let surface = Surface {
        mesh: procedural::cube(),
        features: Features { corners, ..Features::default() },
        options: Default::default(),
    };
    each(ctx, vec![("cube, corners".into(), surface, 3, Options::default())])
}

/// An `n`×`n` grid of unit quads in the plane z = 0, gently curved.
fn grid(n: u32) -> Result<Mesh, Stop> {
    let positions = (0..=n)
        .flat_map(|j| {
            (0..=n).map(move |i| {
                let (x, y) = (f64::from(i), f64::from(j));
                DVec3::new(x, y, 0.1 * (x * y).sin())
            })
        })
        .collect();
    let v = |i: u32, j: u32| j * (n + 1) + i;
    let faces = (0..n)
        .flat_map(|j| (0..n).map(move |i| vec![v(i, j), v(i + 1, j), v(i + 1, j + 1), v(i, j + 1)]))
        .collect();
    Ok(Mesh::new(positions, faces)?)
}

fn boundary(ctx: &Context) -> Step {
    let cube = procedural::cube();
    let open_cube =
        Mesh::new(cube.positions().to_vec(), cube.faces().skip(1).map(<[u32]>::to_vec).collect())?;
    let mut cases = Vec::new();
    for (label, mode) in [("edge-only", Boundary::EdgeOnly), ("edge-and-corner", Boundary::EdgeAndCorner)] {
        for (name, mesh) in [("open cube", open_cube.clone()), ("4×4 grid", grid(4)?)] {
            let mut surface = Surface::smooth(mesh);
            surface.options.boundary = mode;
            cases.push((format!("{name}, {label}"), surface, 3, Options::default()));
        }
    }
    each(ctx, cases)
}

fn valence(ctx: &Context) -> Step {
    let narrow = Options { row_width: Some(64), ..Options::default() };
    each(
        ctx,
        vec![
            ("cone(8)".into(), Surface::smooth(procedural::cone(8)), 3, Options::default()),
            ("cone(40), 64-texel rows".into(), Surface::smooth(procedural::cone(40)), 3, narrow),
            ("cone(40)".into(), Surface::smooth(procedural::cone(40)), 3, Options::default()),
        ],
    )
}
