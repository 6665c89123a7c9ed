//! The offscreen renderer: silhouettes where the camera puts them, per-vertex colours
//! where the vertices project, edges and polylines over surfaces, voxel boundaries,
//! deterministic pictures, PNG files (lavapipe, validation on under tools/test).

mod common;

use common::{TempDir, texgeo};
use glam::DVec3;
use texgeo::gpu::Context;
use texgeo::mesh::{Mesh, procedural};
use texgeo::render::{
    Camera, Colours, Picture, Points, Polyline, Renderer, Scene, SceneMesh, Shading, View, colour, voxels,
};
use texgeo::subdiv::cpu;
use texgeo::voxel::{Grid, Volume};

const RED: [u8; 4] = [255, 0, 0, 255];
const BLACK: [u8; 4] = [0, 0, 0, 255];

fn view(scene: &Scene, w: u32, h: u32, yaw_deg: f64, pitch_deg: f64) -> View {
    let (lo, hi) = scene.bounds().unwrap();
    let camera = Camera::fit(lo, hi, yaw_deg.to_radians(), pitch_deg.to_radians(), w as f64 / h as f64);
    View { camera, width: w, height: h, background: BLACK }
}

fn close(a: [u8; 4], b: [u8; 4], tol: u8) -> bool {
    a.iter().zip(&b).take(3).all(|(x, y)| x.abs_diff(*y) <= tol)
}

#[test]
fn cube_silhouette_is_the_projected_front_face() {
    let ctx = Context::from_env().unwrap();
    let cube = procedural::cube();
    let scene = Scene::new().with_mesh(SceneMesh::new(&cube, RED).shading(Shading::Unlit));
    let mut r = Renderer::new(&ctx, 1).unwrap();
    let prepared = r.prepare(&scene).unwrap();
    let v = view(&scene, 200, 160, 0.0, 0.0);
    let pic = r.render(&prepared, &v).unwrap();
    // Looking along −z, the silhouette is the front face z = 1 (nearer, so larger).
    let corners: Vec<_> = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
        .iter()
        .map(|&(x, y)| v.camera.project(DVec3::new(x, y, 1.0), 200, 160).unwrap())
        .collect();
    let (x0, x1) = (
        corners.iter().map(|c| c.x).fold(f64::MAX, f64::min),
        corners.iter().map(|c| c.x).fold(0.0, f64::max),
    );
    let (y0, y1) = (
        corners.iter().map(|c| c.y).fold(f64::MAX, f64::min),
        corners.iter().map(|c| c.y).fold(0.0, f64::max),
    );
    assert!(x1 - x0 > 60.0 && y1 - y0 > 60.0, "the cube fills a good part of the picture: {corners:?}");
    let mut inside = 0;
    for y in 0..160 {
        for x in 0..200 {
            let (cx, cy) = (x as f64 + 0.5, y as f64 + 0.5);
            let p = pic.pixel(x, y);
            if cx > x0 + 1.0 && cx < x1 - 1.0 && cy > y0 + 1.0 && cy < y1 - 1.0 {
                assert_eq!(p, RED, "pixel ({x}, {y}) inside the silhouette");
                inside += 1;
            } else if cx < x0 - 1.0 || cx > x1 + 1.0 || cy < y0 - 1.0 || cy > y1 + 1.0 {
                assert_eq!(p, BLACK, "pixel ({x}, {y}) outside the silhouette");
            }
        }
    }
    assert!(inside > 3000);
}

/// Vertices whose faces all face the eye (visible on a convex mesh), with their pixel.
fn visible_vertices(mesh: &Mesh, camera: &Camera, w: u32, h: u32) -> Vec<(usize, u32, u32)> {
    let p = mesh.positions();
    let eye = camera.eye();
    let mut facing = vec![true; mesh.num_vertices()];
    for face in mesh.faces() {
        let (a, b, c) = (p[face[0] as usize], p[face[1] as usize], p[face[2] as usize]);
        let n = (b - a).cross(c - a);
        if n.dot(eye - a) <= 0.0 {
            for &v in face {
                facing[v as usize] = false;
            }
        }
    }
    (0..mesh.num_vertices())
        .filter(|&v| facing[v])
        .map(|v| {
            let q = camera.project(p[v], w, h).unwrap();
            (v, q.x as u32, q.y as u32)
        })
        .collect()
}

#[test]
fn valence_colours_land_where_the_vertices_project() {
    let ctx = Context::from_env().unwrap();
    let mesh = cpu::refine(&procedural::cube(), 1).unwrap(); // 8 corners of valence 3, 18 of valence 4
    let valence = colour::valences(&mesh);
    for samples in [1, 4] {
        let scene = Scene::new().with_mesh(SceneMesh::new(&mesh, RED).by_valence().shading(Shading::Unlit));
        let mut r = Renderer::new(&ctx, samples).unwrap();
        let prepared = r.prepare(&scene).unwrap();
        let v = view(&scene, 240, 200, 35.0, 25.0);
        let pic = r.render(&prepared, &v).unwrap();
        let seen = visible_vertices(&mesh, &v.camera, 240, 200);
        assert!(seen.iter().any(|s| valence[s.0] == 3) && seen.iter().any(|s| valence[s.0] == 4));
        for (vertex, x, y) in seen {
            let want = colour::valence_colour(valence[vertex]);
            assert!(
                close(pic.pixel(x, y), want, 12),
                "{samples} samples: vertex {vertex} (valence {}) at ({x}, {y}) is {:?}, not {want:?}",
                valence[vertex],
                pic.pixel(x, y)
            );
        }
    }
}

#[test]
fn per_face_colours_fill_their_faces() {
    let ctx = Context::from_env().unwrap();
    let cube = procedural::cube();
    let palette: Vec<[u8; 4]> = (0..6).map(|f| [40 * f as u8 + 20, 255 - 40 * f as u8, 100, 255]).collect();
    let scene = Scene::new().with_mesh(
        SceneMesh::new(&cube, RED).colours(Colours::PerFace(palette.clone())).shading(Shading::Unlit),
    );
    let mut r = Renderer::new(&ctx, 1).unwrap();
    let prepared = r.prepare(&scene).unwrap();
    let v = view(&scene, 200, 200, 35.0, 25.0);
    let pic = r.render(&prepared, &v).unwrap();
    let p = cube.positions();
    for (f, face) in cube.faces().enumerate() {
        let centre = face.iter().map(|&i| p[i as usize]).sum::<DVec3>() / face.len() as f64;
        let normal =
            (p[face[1] as usize] - p[face[0] as usize]).cross(p[face[2] as usize] - p[face[0] as usize]);
        if normal.dot(v.camera.eye() - centre) <= 0.0 {
            continue;
        }
        let q = v.camera.project(centre, 200, 200).unwrap();
        assert_eq!(pic.pixel(q.x as u32, q.y as u32), palette[f], "face {f}");
    }
}

#[test]
fn edges_and_polylines_are_drawn_over_the_surface() {
    let ctx = Context::from_env().unwrap();
    let cube = procedural::cube();
    let green = [0, 255, 0, 255];
    let blue = [0, 0, 255, 255];
    let scene = Scene::new()
        .with_mesh(SceneMesh::new(&cube, RED).shading(Shading::Flat).wireframe(green))
        .with_line(Polyline::new(vec![DVec3::new(1.0, -0.5, 1.0), DVec3::new(1.0, 0.5, 0.2)], blue, 3.0))
        .with_points(Points {
            positions: vec![DVec3::new(0.0, 1.0, 0.0)],
            colour: [255, 255, 0, 255],
            size: 5.0,
        });
    let mut r = Renderer::new(&ctx, 1).unwrap();
    let prepared = r.prepare(&scene).unwrap();
    assert_eq!(prepared.triangles(), 12);
    assert_eq!(prepared.segments(), 12 + 1 + 1);
    let v = view(&scene, 240, 200, 35.0, 25.0);
    let pic = r.render(&prepared, &v).unwrap();
    let at = |p: DVec3| {
        let q = v.camera.project(p, 240, 200).unwrap();
        pic.pixel(q.x as u32, q.y as u32)
    };
    // The three edges between the visible faces +x, +y, +z.
    for mid in [DVec3::new(1.0, 1.0, 0.0), DVec3::new(1.0, 0.0, 1.0), DVec3::new(0.0, 1.0, 1.0)] {
        assert_eq!(at(mid), green, "edge midpoint {mid}");
    }
    assert_eq!(at(DVec3::new(1.0, 0.0, 0.6)), blue, "polyline on the +x face");
    assert_eq!(at(DVec3::new(0.0, 1.0, 0.0)), [255, 255, 0, 255], "point on the +y face");
    // A face centre away from every line is shaded surface (red channel only).
    let c = at(DVec3::new(1.0, 0.6, -0.5));
    assert!(c[0] > 60 && c[1] == 0 && c[2] == 0, "{c:?}");
    // Hidden edges stay hidden: those of the back corner (−1, −1, −1) lie behind the faces.
    for mid in [DVec3::new(-1.0, -1.0, 0.0), DVec3::new(-1.0, 0.0, -1.0), DVec3::new(0.0, -1.0, -1.0)] {
        let c = at(mid);
        assert!(c[0] > 60 && c[1] == 0, "hidden edge midpoint {mid} shows {c:?}");
    }
}

#[test]
fn segments_passing_behind_the_eye_are_clipped_to_the_near_plane() {
    let ctx = Context::from_env().unwrap();
    let green = [0, 255, 0, 255];
    let camera = Camera { target: DVec3::ZERO, yaw: 0.0, pitch: 0.0, distance: 5.0, fov_y: Camera::FOV_Y };
    // From behind the eye (z = 10, above) to in front of it (below right).
    let (a, b) = (DVec3::new(0.3, 3.0, 10.0), DVec3::new(1.0, -0.8, -1.0));
    let scene = Scene::new().with_line(Polyline::new(vec![a, b], green, 3.0));
    let mut r = Renderer::new(&ctx, 1).unwrap();
    let prepared = r.prepare(&scene).unwrap();
    let (w, h) = (160, 120);
    let pic = r.render(&prepared, &View { camera, width: w, height: h, background: BLACK }).unwrap();
    // The visible part on the CPU: from b to where the segment leaves the eye's half-space
    // (a hair in front of the eye), projected.
    let eye_z = |p: DVec3| p.z - camera.eye().z;
    let t = (eye_z(b) + 1e-3) / (eye_z(b) - eye_z(a));
    let front = b + (a - b) * t;
    let (p, q) = (camera.project(b, w, h).unwrap(), camera.project(front, w, h).unwrap());
    let distance = |x: f64, y: f64| {
        let (d, v) = (q - p, glam::DVec2::new(x, y) - p);
        let s = (v.dot(d) / d.length_squared()).clamp(0.0, 1.0);
        (v - d * s).length()
    };
    let mut on = 0;
    for y in 0..h {
        for x in 0..w {
            if pic.pixel(x, y) == green {
                on += 1;
                let dist = distance(x as f64 + 0.5, y as f64 + 0.5);
                assert!(dist < 3.0, "pixel ({x}, {y}) is {dist:.1} px off the visible segment");
            }
        }
    }
    assert!(on > 100, "{on} pixels");
}

#[test]
fn pictures_are_deterministic() {
    let ctx = Context::from_env().unwrap();
    let knot = procedural::torus_knot();
    let scene = Scene::new()
        .with_mesh(SceneMesh::new(&knot, colour::SURFACE).shading(Shading::Smooth).wireframe(colour::EDGE));
    let render = |samples| {
        let mut r = Renderer::new(&ctx, samples).unwrap();
        let prepared = r.prepare(&scene).unwrap();
        let v = View::fit(&scene, 160, 120).unwrap();
        let a = r.render(&prepared, &v).unwrap();
        let b = r.render(&prepared, &v).unwrap();
        assert_eq!(a, b, "same renderer, same picture");
        a
    };
    for samples in [1, 4] {
        let a = render(samples);
        assert_eq!(a, render(samples), "a new renderer draws the same picture ({samples} samples)");
        assert!(a.rgba.chunks_exact(4).any(|p| p != colour::BACKGROUND.as_slice()));
    }
}

#[test]
fn voxel_boundary_faces() {
    let grid = Grid::new(3, DVec3::ZERO, 3.0).unwrap();
    let mut volume = Volume::new(3).unwrap();
    volume.set(1, 1, 1, true);
    let (mesh, colours) = voxels::surface(&grid, &volume, |_, _, _| RED).unwrap();
    assert_eq!(mesh.num_faces(), 6);
    let report = mesh.report();
    assert!(colours.iter().all(|&c| c == RED));
    // Outward orientation: the voxel's volume (divergence theorem) is +1.
    let volume_of = |m: &Mesh| -> f64 {
        let p = m.positions();
        m.faces()
            .map(|f| {
                let (a, b, c, d) = (p[f[0] as usize], p[f[1] as usize], p[f[2] as usize], p[f[3] as usize]);
                (a.dot(b.cross(c)) + a.dot(c.cross(d))) / 6.0
            })
            .sum()
    };
    assert!((volume_of(&mesh) - 1.0).abs() < 1e-12, "{}", volume_of(&mesh));
    assert!(report.faces == 6, "{report}");
    volume.set(2, 1, 1, true);
    volume.set(0, 0, 0, true);
    let (mesh, _) = voxels::surface(&grid, &volume, |i, _, _| [i as u8, 0, 0, 255]).unwrap();
    assert_eq!(mesh.num_faces(), 10 + 6);
    assert!((volume_of(&mesh) - 3.0).abs() < 1e-12);
}

#[test]
fn bad_requests_are_errors() {
    let ctx = Context::from_env().unwrap();
    let cube = procedural::cube();
    let mut r = Renderer::new(&ctx, 1).unwrap();
    let wrong = Scene::new().with_mesh(SceneMesh::new(&cube, RED).colours(Colours::PerVertex(vec![RED; 3])));
    let e = r.prepare(&wrong).err().expect("3 colours for 8 vertices");
    assert!(e.to_string().contains("3 colours given for a mesh with 8 vertices"), "{e}");
    let scene = Scene::new().with_mesh(SceneMesh::new(&cube, RED));
    let prepared = r.prepare(&scene).unwrap();
    let mut v = View::fit(&scene, 10, 10).unwrap();
    v.width = 0;
    assert!(r.render(&prepared, &v).is_err());
    assert!(View::fit(&Scene::new(), 10, 10).is_err(), "an empty scene has no view to fit");
    // The renderer still works after a refused request.
    v.width = 10;
    assert!(r.render(&prepared, &v).is_ok());
}

#[test]
fn png_round_trip_leaves_no_temporary_file() {
    let tmp = TempDir::new("render");
    let dir = tmp.path();
    let pic = Picture::new(3, 2, (0..24).collect()).unwrap();
    let path = dir.join("p.png");
    pic.save_png(&path).unwrap();
    assert_eq!(Picture::load_png(&path).unwrap(), pic);
    let names: Vec<_> = std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().file_name()).collect();
    assert_eq!(names, vec![std::ffi::OsString::from("p.png")]);
    assert!(pic.save_png(dir.join("no/such/dir/p.png")).is_err());
}

#[test]
fn gpu_memory_is_counted_and_returned() {
    let ctx = Context::from_env().unwrap();
    let before = ctx.live_allocations();
    let cube = procedural::cube();
    let scene = Scene::new().with_mesh(SceneMesh::new(&cube, RED).wireframe(BLACK));
    {
        let mut r = Renderer::new(&ctx, 4).unwrap();
        let prepared = r.prepare(&scene).unwrap();
        r.render(&prepared, &View::fit(&scene, 32, 32).unwrap()).unwrap();
        assert!(ctx.live_allocations() > before, "buffers and targets are allocated");
    }
    assert_eq!(ctx.live_allocations(), before, "everything the renderer made is freed");
}

/// `--boolean B --op OP`: the operands in their two colours with the cut curve over them,
/// and beside them the result, its faces coloured by operand (Figs. 6-9 … 6-12).
#[test]
fn boolean_pictures_show_both_operands_and_the_cut_curve() {
    let tmp = TempDir::new("render-boolean");
    let dir = tmp.path();
    let png = dir.join("torus-and-knot.png");
    let o = texgeo(&[
        "render",
        "builtin:torus",
        "--boolean",
        "builtin:knot",
        "--op",
        "intersection",
        "--size",
        "400x300",
        "-o",
        png.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let p = Picture::load_png(&png).unwrap();
    let pixels: Vec<&[u8]> = p.rgba.chunks_exact(4).collect();
    // Shaded surfaces keep their hue: A is orange (red ≫ blue), B blue (blue ≫ red).
    let orange = pixels.iter().filter(|c| c[0] as i32 > c[2] as i32 + 60).count();
    let blue = pixels.iter().filter(|c| c[2] as i32 > c[0] as i32 + 60).count();
    let curve = pixels.iter().filter(|c| close([c[0], c[1], c[2], c[3]], colour::CURVE, 8)).count();
    assert!(orange > 500 && blue > 500 && curve > 100, "orange {orange}, blue {blue}, curve {curve}");
    let o = texgeo(&["render", "builtin:torus", "--boolean", "builtin:knot", "-o", png.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("--op"));
}

/// An OBJ's crease tags are refined with the mesh and their edges drawn over the surface
/// in the colour of their sharpness; without the tags (the same mesh as OFF) nothing is.
#[test]
fn crease_edges_are_drawn_over_the_subdivided_surface() {
    let tmp = TempDir::new("render-creases");
    let dir = tmp.path();
    let tagged = concat!(env!("CARGO_MANIFEST_DIR"), "/reference/subdiv/cube_creases.obj");
    let plain = dir.join("cube.off");
    assert!(texgeo(&["mesh", "convert", tagged, plain.to_str().unwrap()]).status.success());
    let mut counts = Vec::new();
    for input in [tagged, plain.to_str().unwrap()] {
        let png = dir.join("creases.png");
        let o = texgeo(&["render", input, "-l", "2", "--size", "320x240", "-o", png.to_str().unwrap()]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let p = Picture::load_png(&png).unwrap();
        // Crease colours run from yellow to red: strong red, weak blue, unlike the grey surface.
        counts.push(p.rgba.chunks_exact(4).filter(|c| c[0] > 200 && c[2] < 90).count());
    }
    assert!(counts[0] > 100 && counts[1] == 0, "crease pixels with tags, without: {counts:?}");
}

#[test]
fn render_command_writes_pictures_and_refuses_bad_requests() {
    let tmp = TempDir::new("render-cli");
    let dir = tmp.path();
    let png = dir.join("cube.png");
    let o = texgeo(&[
        "render",
        "builtin:cube",
        "-l",
        "2",
        "--valence",
        "--wireframe",
        "--size",
        "64x48",
        "-o",
        png.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(String::from_utf8_lossy(&o.stdout).contains("level 2, 98 vertices, 96 faces"));
    let p = Picture::load_png(&png).unwrap();
    assert_eq!((p.width, p.height), (64, 48));
    let binvox = dir.join("cube.binvox");
    assert!(
        texgeo(&["voxelize", "builtin:cube", "--res", "8", "-o", binvox.to_str().unwrap()]).status.success()
    );
    let b = binvox.to_str().unwrap();
    let out = dir.join("x.png");
    let out = out.to_str().unwrap();
    for (args, needle) in [
        (vec!["render", "builtin:cube", "-o", "cube.jpg"], "name it .png"),
        (vec!["render", b, "-l", "1", "-o", out], "--level applies to meshes"),
        (vec!["render", b, "--valence", "-o", out], "--valence applies to meshes"),
        (vec!["render", "builtin:cube", "--aspect", "perlin", "-o", out], "--aspect colours voxels"),
        (vec!["render", "builtin:cube", "builtin:knot", "-l", "1", "-o", out], "several models"),
        (vec!["render", "builtin:cube", "--size", "0x10", "-o", out], "not a size"),
        (vec!["render", "builtin:cube", "--pitch", "95", "-o", out], "--pitch"),
        (vec!["render", "builtin:cube", "--samples", "3", "-o", out], "3-sample"),
        (vec!["render", "builtin:nothing", "-o", out], "no built-in model"),
    ] {
        let o = texgeo(&args);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(needle), "{args:?}: {err}");
    }
    assert!(!dir.join("x.png").exists(), "no picture from a refused request");
}
