//! The report's pictures, rendered headless by texgeo's own Vulkan pipeline
//! (`render`): subdivision levels coloured by valence (2010 Figs. 27–30), voxelized
//! models in Perlin aspect colours (2006 Fig. 5-9), creases by sharpness, an inclusion slice, the fragment-mesh
//! layout and Boolean results (2006 Figs. 6-9 … 6-12). Each picture is described in `figures.json` (camera, model,
//! level) so a test can check it against the geometry.

use glam::DVec3;

use super::doc::Block;
use super::{Result, Run};
use crate::inclusion::solver::Solver;
use crate::inclusion::{Class, Method as InclusionMethod, Options};
use crate::mesh::{Mesh, procedural};
use crate::render::{
    Camera, Content, Look, Model, Picture, Points, Polyline, Renderer, Scene, SceneMesh, Shading, View,
    colour,
};
use crate::subdiv::{Features, Surface, cpu, fragment};
use crate::voxel::aspect::Aspect;
use crate::voxel::{self, Method as VoxelMethod};

/// A legend block: what each colour of a picture means.
fn legend(items: &[(&str, colour::Rgba)]) -> Block {
    Block::Legend(items.iter().map(|(what, [r, g, b, _])| (what.to_string(), [*r, *g, *b])).collect())
}

/// The valence colours (`colour::valence_colour`), as a legend.
fn valence_legend() -> Block {
    let names = ["2 or less", "3", "4 (regular)", "5", "6", "7", "8 or more"];
    let items: Vec<(String, colour::Rgba)> = names
        .iter()
        .enumerate()
        .map(|(i, n)| (format!("valence {n}"), colour::valence_colour(i + 2)))
        .collect();
    legend(&items.iter().map(|(w, c)| (w.as_str(), *c)).collect::<Vec<_>>())
}

/// Picture size, pixels.
pub const WIDTH: u32 = 800;
pub const HEIGHT: u32 = 600;

/// What `figures.json` says about one picture.
#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct FigureRecord {
    /// Path relative to the report folder.
    pub file: String,
    pub width: u32,
    pub height: u32,
    /// "valence", "voxels", "inclusion-slice", "fragment-layout".
    pub kind: String,
    pub model: String,
    /// Subdivision level shown (valence pictures).
    pub level: u32,
    pub camera: CameraRecord,
    pub note: String,
}

impl FigureRecord {
    /// A picture's record before it is written (the file and its size are filled in then).
    fn new(
        kind: &str,
        model: impl Into<String>,
        level: u32,
        camera: impl Into<CameraRecord>,
        note: String,
    ) -> FigureRecord {
        FigureRecord {
            kind: kind.into(),
            model: model.into(),
            level,
            camera: camera.into(),
            note,
            ..FigureRecord::default()
        }
    }
}

/// The orbit camera of a picture (`render::Camera`).
#[derive(Clone, Copy, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct CameraRecord {
    pub target: [f64; 3],
    pub yaw: f64,
    pub pitch: f64,
    pub distance: f64,
    pub fov_y: f64,
}

impl From<Camera> for CameraRecord {
    fn from(c: Camera) -> CameraRecord {
        CameraRecord {
            target: c.target.to_array(),
            yaw: c.yaw,
            pitch: c.pitch,
            distance: c.distance,
            fov_y: c.fov_y,
        }
    }
}

impl From<CameraRecord> for Camera {
    fn from(c: CameraRecord) -> Camera {
        Camera {
            target: DVec3::from_array(c.target),
            yaw: c.yaw,
            pitch: c.pitch,
            distance: c.distance,
            fov_y: c.fov_y,
        }
    }
}

fn render(run: &Run, scene: &Scene, camera: Camera) -> Result<Picture> {
    let mut renderer = Renderer::new(run.ctx, 4)?;
    let prepared = renderer.prepare(scene)?;
    let view = View { camera, width: WIDTH, height: HEIGHT, background: colour::BACKGROUND };
    Ok(renderer.render(&prepared, &view)?)
}

/// `content` refined to `level` and drawn from `camera`, with the model's vertex and face counts.
fn draw(
    run: &Run,
    content: Content,
    level: u32,
    look: Look,
    camera: Camera,
) -> Result<(Picture, usize, usize)> {
    let mut model = Model::new(run.ctx, content, level, look, None)?;
    let (vertices, faces) = model.counts();
    let scene = model.scene(run.ctx)?;
    Ok((render(run, &scene, camera)?, vertices, faces))
}

fn aspect() -> f64 {
    f64::from(WIDTH) / f64::from(HEIGHT)
}

/// The model of the valence pictures: a geodesic sphere (an icosahedron with every
/// triangle split in four, pushed onto the sphere): 12 vertices of valence 5, 30 of
/// valence 6, 80 triangles. Catmull-Clark adds face points of valence 3 and edge points
/// of valence 4 — the valences of the thesis' Figs. 27–30. Convex, so every vertex
/// facing the camera is visible.
pub fn valence_model() -> Mesh {
    let t = (1.0 + 5f64.sqrt()) / 2.0;
    let mut p: Vec<DVec3> = [
        (-1.0, t, 0.0),
        (1.0, t, 0.0),
        (-1.0, -t, 0.0),
        (1.0, -t, 0.0),
        (0.0, -1.0, t),
        (0.0, 1.0, t),
        (0.0, -1.0, -t),
        (0.0, 1.0, -t),
        (t, 0.0, -1.0),
        (t, 0.0, 1.0),
        (-t, 0.0, -1.0),
        (-t, 0.0, 1.0),
    ]
    .iter()
    .map(|&(x, y, z)| DVec3::new(x, y, z).normalize())
    .collect();
    let ico: [[u32; 3]; 20] = [
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    let mut mid = std::collections::HashMap::new();
    let mut midpoint = |a: u32, b: u32, p: &mut Vec<DVec3>| -> u32 {
        *mid.entry((a.min(b), a.max(b))).or_insert_with(|| {
            p.push(((p[a as usize] + p[b as usize]) * 0.5).normalize());
            (p.len() - 1) as u32
        })
    };
    let mut faces = Vec::with_capacity(80);
    for [a, b, c] in ico {
        let (ab, bc, ca) = (midpoint(a, b, &mut p), midpoint(b, c, &mut p), midpoint(c, a, &mut p));
        faces.extend([vec![a, ab, ca], vec![b, bc, ab], vec![c, ca, bc], vec![ab, bc, ca]]);
    }
    // The index list above is fixed and valid: this cannot fail.
    Mesh::new(p, faces).unwrap_or_else(|_| procedural::sphere(8, 16))
}

/// Levels 0–3 of the geodesic sphere, refined by the GPU fragment passes, vertices
/// coloured by valence (2010 Figs. 27–30).
pub fn valence_levels(run: &mut Run) -> Result<Vec<Block>> {
    let base = valence_model();
    // The unit sphere's own radius, not its bounding box's, so it fills the picture.
    let r = DVec3::splat(1.0 / 3f64.sqrt());
    let camera = Camera::fit(-r, r, Camera::YAW, Camera::PITCH, aspect());
    let look = Look { valence: true, wireframe: false, shading: Shading::Smooth, colour: colour::SURFACE };
    let mut blocks = vec![
        Block::Para(
            "Each level is refined on the GPU (fragment passes from level 2 on; levels 0–1 are the input and the \
             CPU's first level), smooth-shaded, vertices coloured by valence, colours interpolated between them."
                .into(),
        ),
        valence_legend(),
    ];
    for level in 0..=3 {
        let (picture, vertices, faces) = draw(run, Content::Mesh(base.clone()), level, look, camera)?;
        let record = FigureRecord::new(
            "valence",
            "geodesic sphere (report::reproduce::valence_model)",
            level,
            camera,
            format!("{vertices} vertices, {faces} faces"),
        );
        let caption = format!(
            "Geodesic sphere, level {level}: {vertices} vertices, {faces} faces, coloured by valence"
        );
        blocks.push(run.picture(&picture, &format!("valence-level{level}"), &caption, record)?);
    }
    Ok(blocks)
}

/// The sharpness of the crease picture's edges, three edges each.
const CREASE_SHARPNESS: [f32; 4] = [1.0, 2.0, 4.0, 10.0];

/// The crease colours (`colour::crease_colour`) of [`CREASE_SHARPNESS`], as a legend.
fn crease_legend() -> Block {
    let items: Vec<(String, colour::Rgba)> = CREASE_SHARPNESS
        .iter()
        .map(|&s| {
            let what = if s >= 10.0 { "10 (infinitely sharp)".to_string() } else { format!("{s}") };
            (format!("crease sharpness {what}"), colour::crease_colour(s))
        })
        .collect();
    legend(&items.iter().map(|(w, c)| (w.as_str(), *c)).collect::<Vec<_>>())
}

/// A cube whose twelve edges are creased at sharpness 1, 2, 4 and 10 (three edges each),
/// refined to level 3 by the GPU fragment passes, its crease edges drawn in the colour of
/// their sharpness: semi-sharp creases round off, infinitely sharp ones stay edges.
pub fn crease_sharpness(run: &mut Run) -> Result<Vec<Block>> {
    let cube = procedural::cube();
    let mut features = Features::feature_edges(&cube, 30.0, 10.0);
    for (i, c) in features.creases.iter_mut().enumerate() {
        c.sharpness = CREASE_SHARPNESS[i % CREASE_SHARPNESS.len()];
    }
    let creases = features.creases.len();
    let (lo, hi) = cube.bounds();
    let surface = Surface { features, ..Surface::smooth(cube) };
    let level = 3;
    let look = Look { valence: false, wireframe: false, shading: Shading::Smooth, colour: colour::SURFACE };
    let camera = Camera::fit(lo, hi, Camera::YAW, Camera::PITCH, aspect());
    let (picture, vertices, faces) = draw(run, Content::Surface(surface), level, look, camera)?;
    let record = FigureRecord::new(
        "creases",
        "builtin:cube",
        level,
        camera,
        format!("{creases} creased edges at sharpness 1, 2, 4, 10; {vertices} vertices, {faces} faces"),
    );
    let caption = format!(
        "Cube, level {level} on the GPU: its {creases} edges creased at sharpness 1, 2, 4 and 10, crease edges \
         coloured by sharpness"
    );
    Ok(vec![
        Block::Para(
            "Sharpness decays by one per level: an edge of sharpness 1 is sharp for one level and then smooth, \
             one of 10 or more stays sharp at every level."
                .into(),
        ),
        crease_legend(),
        run.picture(&picture, "crease-sharpness", &caption, record)?,
    ])
}

/// The knot (quick) or armadillo voxelized, in Perlin marble, whole and cut open
/// (2006 Fig. 5-9).
pub fn voxel_aspect(run: &mut Run) -> Result<Vec<Block>> {
    let armadillo = run.models_dir.join("armadillo.off");
    let (name, mesh, res) = if !run.quick && armadillo.is_file() {
        ("armadillo.off", crate::mesh::formats::read(&armadillo)?, 128)
    } else {
        ("builtin:knot", procedural::torus_knot(), 64)
    };
    // The pictures show the faithful GPU method's volume; without logic-op XOR the CPU
    // slicer gives the same volume.
    let (method, why) = if run.ctx.info().logic_op {
        (VoxelMethod::Zoned, String::new())
    } else {
        (VoxelMethod::Cpu, " (CPU slicer: this device has no logic-op XOR)".to_string())
    };
    let v = voxel::voxelize(Some(run.ctx), &mesh, res, method)?;
    let mut cut = v.volume.clone();
    let n = cut.n();
    for j in 0..n {
        for k in 0..n {
            for i in n / 2..n {
                cut.set(i, j, k, false);
            }
        }
    }
    let mut blocks = Vec::new();
    for (stem, volume, what) in
        [("voxels-aspect", v.volume, "whole"), ("voxels-aspect-cut", cut, "cut open at x = ½")]
    {
        let occupied = volume.count();
        let mut model = Model::new(
            run.ctx,
            Content::Voxels(v.grid, volume),
            0,
            Look::default(),
            Some(Aspect::default()),
        )?;
        let scene = model.scene(run.ctx)?;
        let (lo, hi) =
            scene.bounds().ok_or_else(|| super::ReproduceError::Usage("empty voxel volume".into()))?;
        let camera = Camera::fit(lo, hi, Camera::YAW, Camera::PITCH, aspect());
        let picture = render(run, &scene, camera)?;
        let record = FigureRecord::new(
            "voxels",
            name,
            0,
            camera,
            format!("{res}³, {occupied} voxels, {method}{why}, Perlin marble"),
        );
        let caption = format!(
            "{name} voxelized at {res}³ by `{method}`{why}, {what}, coloured by the Perlin aspect (marble)"
        );
        blocks.push(run.picture(&picture, stem, &caption, record)?);
    }
    Ok(blocks)
}

/// Query points on a plane z = const through the knot, coloured by the GPU test's answer
/// (inside green, outside grey, on the boundary red), with the plane's cut through the
/// surface in yellow.
pub fn inclusion_slice(run: &mut Run) -> Result<Vec<Block>> {
    let mesh = procedural::torus_knot();
    let (lo, hi) = mesh.bounds();
    let pad = (hi - lo) * 0.05;
    let (lo, hi) = (lo - pad, hi + pad);
    let side = 200usize;
    // Near the knot's mid-plane, but off z = 0, where mesh vertices lie.
    let z = 0.05;
    let points: Vec<DVec3> = (0..side * side)
        .map(|i| {
            let (u, v) = ((i % side) as f64 + 0.5, (i / side) as f64 + 0.5);
            DVec3::new(lo.x + (hi.x - lo.x) * u / side as f64, lo.y + (hi.y - lo.y) * v / side as f64, z)
        })
        .collect();
    let (classes, method) =
        match Solver::new(InclusionMethod::Gpu, &mesh, &Options::default(), Some(run.ctx), None) {
            Ok(mut s) => (s.classify_all(&points)?, "gpu"),
            Err(_) => (
                Solver::new(InclusionMethod::Cpu, &mesh, &Options::default(), None, None)?
                    .classify_all(&points)?,
                "cpu",
            ),
        };
    let group = |c: Class, colour: colour::Rgba| Points {
        positions: points.iter().zip(&classes).filter(|(_, k)| **k == c).map(|(p, _)| *p).collect(),
        colour,
        size: 3.0,
    };
    const INSIDE: colour::Rgba = [90, 200, 100, 255];
    const OUTSIDE: colour::Rgba = [110, 112, 120, 255];
    const ON: colour::Rgba = [230, 60, 50, 255];
    let inside = group(Class::Inside, INSIDE);
    let outside = group(Class::Outside, OUTSIDE);
    let on = group(Class::OnBoundary, ON);
    let counts = (inside.positions.len(), outside.positions.len(), on.positions.len());
    let mut scene = Scene::new().with_points(outside).with_points(inside).with_points(on);
    // The cut of every triangle by the plane, lifted a little towards the camera so the
    // points on the plane do not hide it.
    let lift = DVec3::new(0.0, 0.0, 1e-3 * (hi - lo).max_element());
    for f in mesh.faces() {
        let corners: Vec<DVec3> = f.iter().map(|&i| mesh.positions()[i as usize]).collect();
        let mut cut = Vec::new();
        for (k, &a) in corners.iter().enumerate() {
            let b = corners[(k + 1) % corners.len()];
            if (a.z - z) * (b.z - z) < 0.0 {
                cut.push(a + (b - a) * ((z - a.z) / (b.z - a.z)));
            }
        }
        if cut.len() == 2 {
            scene =
                scene.with_line(Polyline::new(cut.iter().map(|p| *p + lift).collect(), colour::CURVE, 2.0));
        }
    }
    let camera = Camera::fit(DVec3::new(lo.x, lo.y, z), DVec3::new(hi.x, hi.y, z), 0.0, 0.0, aspect());
    let picture = render(run, &scene, camera)?;
    let record = FigureRecord::new(
        "inclusion-slice",
        "builtin:knot",
        0,
        camera,
        format!(
            "{} points on z = {z} by `{method}`: {} inside, {} outside, {} on the boundary",
            points.len(),
            counts.0,
            counts.1,
            counts.2
        ),
    );
    let caption = format!(
        "Inclusion slice: {side}×{side} points on the plane z = {z} through the torus knot, classified by `{method}`: \
         {} inside (green), {} outside (grey), {} on the boundary (red); the plane's cut through the surface in yellow",
        counts.0, counts.1, counts.2
    );
    Ok(vec![
        run.picture(&picture, "inclusion-slice", &caption, record)?,
        legend(&[
            ("inside", INSIDE),
            ("outside", OUTSIDE),
            ("on the boundary", ON),
            ("the plane's cut through the surface", colour::CURVE),
        ]),
    ])
}

/// One fragment of the cube after two fragment passes (ring radius 5 = 2² + 1), in
/// sector layout over the level-3 surface: the centre white, the owned rings 1–4 one
/// colour per sector, the support ring grey; a line joins the entries in storage order.
pub fn fragment_layout(run: &mut Run) -> Result<Vec<Block>> {
    let cube = procedural::cube();
    // Three fragment levels after the base level (ring radii 2, 3, 5, 8); the picture
    // stops after two passes, where the stream still carries its support ring.
    let fragments = fragment::FragmentMesh::new(&cube, 4)?;
    let levels = 4 - fragments.cpu_levels();
    let mut stream = fragments.base_stream(levels, 1, |p| [p.x, p.y, p.z, 1.0], |d| d.map(f64::from));
    for j in 0..2 {
        stream = fragments.refine_stream(&stream, j, levels);
    }
    let layout = fragments.layout(2, levels, 1);
    let radius = layout.radius;
    let frag = fragments.fragments()[0];
    let start = fragments.fragment_start(&layout, 0) as usize;
    let len = frag.class.len(radius) as usize;
    let entries: Vec<DVec3> =
        stream[start..start + len].iter().map(|t| DVec3::new(t[0], t[1], t[2])).collect();
    let sectors = frag.class.valence as usize + usize::from(frag.class.boundary);
    const SECTOR: [colour::Rgba; 6] = [
        [230, 80, 60, 255],
        [70, 170, 240, 255],
        [120, 210, 90, 255],
        [240, 190, 50, 255],
        [200, 90, 220, 255],
        [60, 200, 190, 255],
    ];
    let mut owned: Vec<Vec<DVec3>> = vec![Vec::new(); sectors];
    let mut support = Vec::new();
    for (i, &p) in entries.iter().enumerate() {
        match frag.class.coords(i as u64) {
            None => {}
            Some((s, a, b)) if a.max(b) < radius => owned[s as usize % sectors].push(p),
            Some(_) => support.push(p),
        }
    }
    let surface = cpu::refine(&cube, 1 + 2)?;
    let mut scene = Scene::new()
        .with_mesh(SceneMesh::new(&surface, colour::SURFACE).wireframe(colour::EDGE).shading(Shading::Flat));
    const SUPPORT: colour::Rgba = [140, 140, 150, 255];
    const CENTRE: colour::Rgba = [255, 255, 255, 255];
    scene = scene.with_line(Polyline::new(entries.clone(), colour::CURVE, 1.5));
    for (s, pts) in owned.into_iter().enumerate() {
        scene = scene.with_points(Points { positions: pts, colour: SECTOR[s % SECTOR.len()], size: 9.0 });
    }
    scene = scene.with_points(Points { positions: support, colour: SUPPORT, size: 6.0 });
    scene = scene.with_points(Points { positions: vec![entries[0]], colour: CENTRE, size: 13.0 });
    let centre = entries[0];
    let d = centre.normalize_or(DVec3::Z);
    let (plo, phi) = entries.iter().fold((centre, centre), |(a, b), &p| (a.min(p), b.max(p)));
    let camera = Camera::fit(plo, phi, d.x.atan2(d.z), d.y.clamp(-1.0, 1.0).asin(), aspect());
    let picture = render(run, &scene, camera)?;
    let k = frag.class.valence;
    let record = FigureRecord::new(
        "fragment-layout",
        "builtin:cube",
        3,
        camera,
        format!("fragment of vertex {} (valence {k}), ring radius {radius}, {len} entries", frag.centre),
    );
    let caption = format!(
        "The fragment around a cube corner (valence {k}) after two fragment passes: {len} entries of ring radius \
         {radius} = 2²+1 over the level-3 surface; the centre white, the owned rings 1–4 one colour per sector (the \
         {k} faces around the corner), the support ring grey (dropped after the last pass); the yellow line joins \
         the entries in storage order — the centre, then ring by ring, sector by sector (SPEC §5.2)"
    );
    let sector_names: Vec<String> = (1..=sectors).map(|s| format!("sector {s}")).collect();
    let mut items: Vec<(&str, colour::Rgba)> = vec![("centre", CENTRE)];
    items.extend(sector_names.iter().enumerate().map(|(s, n)| (n.as_str(), SECTOR[s % SECTOR.len()])));
    items.extend([("support ring", SUPPORT), ("storage order", colour::CURVE)]);
    Ok(vec![run.picture(&picture, "fragment-layout", &caption, record)?, legend(&items)])
}

/// Union, intersection and difference of a torus and a sphere through its tube (2006
/// Figs. 6-9 … 6-12, `render::boolean`): the refined operands in their two colours with
/// the cut curve, and beside them the result, each face in its operand's colour.
pub fn boolean_results(run: &mut Run) -> Result<Vec<Block>> {
    use crate::boolean::{self, Names, Operation, Transform};
    let a = procedural::torus(1.0, 0.4, 48, 24);
    let b = Transform::parse("scale 0.55; translate 1 0 0.3")
        .map_err(super::ReproduceError::Usage)?
        .apply(&procedural::sphere(16, 32))?;
    let ev = boolean::evaluate(
        &a,
        &b,
        Names { a: "torus", b: "sphere" },
        &boolean::Options::default(),
        Some(run.ctx),
    )?;
    let mut blocks = vec![Block::Para(format!(
        "A torus (A, {} triangles) and a sphere through its tube (B, {} triangles), refined along their \
         intersection ({} cut triangles), cut curve in yellow; right: the result, faces coloured by the operand \
         they come from.",
        a.num_faces(),
        b.num_faces(),
        ev.refinement.stats.cut_a + ev.refinement.stats.cut_b
    ))];
    for op in [Operation::Union, Operation::Intersection, Operation::Difference] {
        let content = crate::render::boolean::content(&ev, op, true)?;
        let mut model = Model::new(run.ctx, content, 0, Look::default(), None)?;
        let scene = model.scene(run.ctx)?;
        let (lo, hi) =
            scene.bounds().ok_or_else(|| super::ReproduceError::Usage("empty Boolean scene".into()))?;
        let camera = Camera::fit(lo, hi, Camera::YAW, Camera::PITCH, aspect());
        let picture = render(run, &scene, camera)?;
        let faces = ev.result(op, true)?.num_faces();
        let record = FigureRecord::new(
            "boolean",
            "builtin torus, sphere",
            0,
            camera,
            format!("{} ({}): {faces} result triangles", op.name(), op.symbol()),
        );
        let caption = format!("A {} B: torus and sphere, {faces} result triangles", op.symbol());
        blocks.push(run.picture(&picture, &format!("boolean-{}", op.name()), &caption, record)?);
        blocks.push(legend(&[
            ("operand A, and the result's faces from A", colour::FIRST),
            ("operand B, and the result's faces from B", colour::SECOND),
            ("cut curve", colour::CURVE),
        ]));
    }
    Ok(blocks)
}
