//! Round trips of every built-in model through every format, and readers on hand-made
//! files that use the formats' less common features.

mod common;

use std::path::{Path, PathBuf};

use glam::DVec3;
use texgeo::mesh::covering::Covering;
use texgeo::mesh::formats::{self, Format, obj, off, ply, stl};
use texgeo::mesh::procedural::{self, BUILTIN_NAMES};
use texgeo::mesh::spec::{MeshSpec, Placed};
use texgeo::mesh::transform::Transform;
use texgeo::mesh::triangulate;
use texgeo::mesh::{Mesh, Result};

fn models() -> Vec<(&'static str, Mesh)> {
    let mut all: Vec<_> = BUILTIN_NAMES.iter().map(|&n| (n, procedural::by_name(n).unwrap())).collect();
    // Coordinates that need all 17 digits, and a large polygon.
    let odd = procedural::sphere(5, 7).map_positions(|p| p * 0.1 + DVec3::new(1e-7, -3.3, 1e5)).unwrap();
    all.push(("odd-sphere", odd));
    all.push(("prism", prism(9)));
    all
}

/// An n-gon prism: two n-gon caps and n quads.
fn prism(n: u32) -> Mesh {
    let outline: Vec<(f64, f64)> = (0..n)
        .map(|i| {
            let t = std::f64::consts::TAU * f64::from(i) / f64::from(n);
            (t.cos(), t.sin())
        })
        .collect();
    procedural::prism(&outline, 1.0).unwrap()
}

fn path(name: &str) -> PathBuf {
    PathBuf::from(format!("memory/{name}"))
}

fn round_trip(mesh: &Mesh, format: Format, name: &str) -> Result<Mesh> {
    let mut bytes = Vec::new();
    formats::write_to(&mut bytes, mesh, format).unwrap();
    formats::read_bytes(&bytes, format, &path(name))
}

#[test]
fn obj_off_ply_round_trips_are_exact() {
    for (name, mesh) in models() {
        for format in [Format::Obj, Format::Off, Format::Ply] {
            let back = round_trip(&mesh, format, name).unwrap_or_else(|e| panic!("{name} {format:?}: {e}"));
            assert_eq!(back, mesh, "{name} through {format:?}");
        }
        let mut bytes = Vec::new();
        ply::write_ascii(&mut bytes, &mesh).unwrap();
        assert_eq!(ply::read(&bytes, &path("a.ply")).unwrap(), mesh, "{name} through ascii PLY");
    }
}

/// The triangles of `mesh` (as STL gets them) as f32-rounded coordinates.
fn f32_triangles(mesh: &Mesh) -> Vec<[[f32; 3]; 3]> {
    let t = triangulate::triangulated(mesh);
    let r = |i: u32| t.positions()[i as usize].to_array().map(|c| c as f32);
    t.faces().map(|f| [r(f[0]), r(f[1]), r(f[2])]).collect()
}

#[test]
fn stl_round_trips_are_f32_exact_and_welded() {
    for (name, mesh) in models() {
        let back = round_trip(&mesh, Format::Stl, name).unwrap();
        assert!(back.is_triangle_mesh());
        assert_eq!(f32_triangles(&back), f32_triangles(&mesh), "{name}");
        // Welding restores the shared vertices (and the centres of non-planar faces'
        // fans), so the topology survives.
        assert_eq!(back.num_vertices(), triangulate::triangulated(&mesh).num_vertices(), "{name}");
        // Triangulation adds as many edges as triangles beyond the faces: χ and the flags stay.
        let summary = |m: &Mesh| {
            let r = m.report();
            (r.is_closed(), r.is_oriented(), r.is_manifold(), r.euler_characteristic, r.components)
        };
        assert_eq!(summary(&back), summary(&mesh), "{name}");
    }
}

#[test]
fn ascii_stl_round_trip_is_exact_in_f64() {
    for (name, mesh) in models() {
        let mut bytes = Vec::new();
        stl::write_ascii(&mut bytes, &mesh).unwrap();
        let back = stl::read(&bytes, &path("a.stl")).unwrap();
        let p = |m: &Mesh| -> Vec<DVec3> {
            m.faces().flat_map(|f| f.iter().map(|&i| m.positions()[i as usize]).collect::<Vec<_>>()).collect()
        };
        let t = triangulate::triangulated(&mesh);
        assert_eq!(p(&back), p(&t), "{name}");
        assert_eq!(back.num_vertices(), t.num_vertices(), "{name}");
        assert!(back.report().is_closed(), "{name}");
    }
}

/// A face whose corners are not in one plane is the fan from its centroid in the STL
/// export too: the export measures what `mesh stats` measures.
#[test]
fn stl_keeps_the_surface_of_non_planar_faces() {
    let mesh = procedural::bent_box();
    let stats = Covering::new(&mesh).volume();
    let writers: [Writer; 2] = [|w, m| stl::write(w, m), |w, m| stl::write_ascii(w, m)];
    for write in writers {
        let mut bytes = Vec::new();
        write(&mut bytes, &mesh).unwrap();
        let back = stl::read(&bytes, &path("bent.stl")).unwrap();
        assert!(back.report().is_closed());
        // The top's fan of 4 triangles, five planar quads of 2.
        assert_eq!(back.num_faces(), 4 + 5 * 2);
        let v = Covering::new(&back).volume();
        assert!((v - stats).abs() <= 1e-15 * stats, "{v} vs {stats}");
    }
}

/// A writer of one format.
type Writer = fn(&mut Vec<u8>, &Mesh) -> std::io::Result<()>;

/// (area, volume) from the simplicial covering.
fn measures(mesh: &Mesh) -> (f64, f64) {
    let c = Covering::new(mesh);
    (c.area(), c.volume())
}

#[test]
fn convert_keeps_area_and_volume_in_every_format() {
    // Every built-in (the star's 10-gon caps are not covered by any vertex fan), and a
    // comb-shaped prism whose teeth a fan from the first vertex folds over.
    let comb = [
        (0.0, 0.0),
        (5.0, 0.0),
        (5.0, 2.0),
        (4.0, 2.0),
        (4.0, 1.0),
        (3.0, 1.0),
        (3.0, 2.0),
        (2.0, 2.0),
        (2.0, 1.0),
        (1.0, 1.0),
        (1.0, 2.0),
        (0.0, 2.0),
    ];
    let mut all = models();
    all.push(("comb", procedural::prism(&comb, 0.75).unwrap()));
    for (name, mesh) in all {
        let (area, volume) = measures(&mesh);
        let writers: [(&str, Format, Writer); 6] = [
            ("obj", Format::Obj, |w, m| obj::write(w, m)),
            ("off", Format::Off, |w, m| off::write(w, m)),
            ("ply", Format::Ply, |w, m| ply::write(w, m)),
            ("ascii ply", Format::Ply, |w, m| ply::write_ascii(w, m)),
            ("stl", Format::Stl, |w, m| stl::write(w, m)),
            ("ascii stl", Format::Stl, |w, m| stl::write_ascii(w, m)),
        ];
        for (label, format, write) in writers {
            let mut bytes = Vec::new();
            write(&mut bytes, &mesh).unwrap();
            let back = formats::read_bytes(&bytes, format, &path(name)).unwrap();
            let (a, v) = measures(&back);
            // Binary STL rounds coordinates to f32 (fan centres included): compare with
            // the rounded triangles' measures (the triangulation itself must keep them:
            // the ascii STL, exact in f64, is held to the mesh's own).
            let (area, volume) = if label == "stl" {
                measures(&triangulate::triangulated(&mesh).map_positions(|p| p.as_vec3().as_dvec3()).unwrap())
            } else {
                (area, volume)
            };
            let ok = |x: f64, want: f64| (x - want).abs() <= 1e-11 * want.abs().max(1e-300);
            assert!(ok(a, area), "{name} as {label}: area {a} instead of {area}");
            assert!(ok(v, volume), "{name} as {label}: volume {v} instead of {volume}");
        }
    }
}

#[test]
fn files_on_disk_by_extension() {
    let dir = common::TempDir::new("mesh-formats");
    let knot = procedural::torus_knot();
    for ext in ["obj", "off", "ply", "stl", "OBJ"] {
        let file = dir.join(&format!("knot.{ext}"));
        formats::write(&file, &knot).unwrap();
        let back = formats::read(&file).unwrap();
        assert_eq!(back.num_faces(), 1200);
        assert!(back.report().is_closed());
        if ext != "stl" {
            assert_eq!(back, knot);
        }
    }
    assert_eq!(Format::from_path(Path::new("a/b.Ply")).unwrap(), Format::Ply);
}

const OBJ_CUBE_IN_GROUPS: &str = "\
# a cube, one group per face, with every OBJ index form
mtllib cube.mtl
o cube
v -1 -1 -1
v 1 -1 -1
v -1 1 -1
v 1 1 -1
v -1 -1 1 1
v 1 -1 1 1.0 0.5 0.25
v -1 1 1
v 2 2 2 2   # w = 2 divides: (1, 1, 1)
vt 0 0
vt 1 0
vt 1 1 0
vn 0 0 1
g minus_x
usemtl red
s off
f 1 5 7 3
g plus_x
f 2/1 4/2 8/3 6/1
g minus_y
usemtl blue
f 1//1 2//1 6//1 5//1
g plus_y
f -6/-3/-1 -2/-2/-1 -1/-1/-1 -5/-1/-1
g minus_z
f 1 3 4 2 # trailing comment
l 1 2 3
p 1
g plus_z
f 5 6 8 7
";

#[test]
fn obj_groups_merge_and_keep_shared_vertices() {
    let m = obj::read(OBJ_CUBE_IN_GROUPS.as_bytes(), &path("cube.obj")).unwrap();
    assert_eq!(m, procedural::cube());
    let r = m.report();
    assert!(r.is_closed() && r.is_manifold());
}

#[test]
fn obj_polygons_stay_polygons() {
    let text = "v 0 0 0\nv 1 0 0\nv 2 1 0\nv 1 2 0\nv 0 1 0\nv 0.5 0.5 1\n\
                f 1 5 4 3 2\nf 1 2 6\nf 2 3 6\nf 3 4 6\nf 4 5 6\nf 5 1 6\n";
    let m = obj::read(text.as_bytes(), &path("house.obj")).unwrap();
    assert_eq!(m.num_faces(), 6);
    assert_eq!(m.face(0), &[0, 4, 3, 2, 1]);
    assert_eq!(m.report().face_degrees.get(&5), Some(&1));
    assert!(m.report().is_closed());
    // CRLF line ends read the same.
    let crlf = text.replace('\n', "\r\n");
    assert_eq!(obj::read(crlf.as_bytes(), &path("house.obj")).unwrap(), m);
}

#[test]
fn obj_drops_unused_vertices_keeping_order() {
    let text = "v 9 9 9\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 8 8 8\nv 0 0 1\nf 2 4 3\nf 2 3 6\nf 2 6 4\nf 3 4 6\n";
    let m = obj::read(text.as_bytes(), &path("t.obj")).unwrap();
    assert_eq!(m.num_vertices(), 4);
    assert_eq!(m.positions()[0], DVec3::ZERO);
    assert_eq!(m.face(0), &[0, 2, 1]);
    assert!(m.report().is_closed());
}

/// A cube as PLY with extra elements and properties of many types, in `format`.
fn odd_ply(format: &str) -> Vec<u8> {
    let cube = procedural::cube();
    let mut out = format!(
        "ply\r\nformat {format} 1.0\ncomment extra stuff everywhere\nobj_info made by hand\n\
         element material 2\nproperty uchar red\nproperty list ushort float weights\n\
         element vertex 8\nproperty float x\nproperty short flags\nproperty double y\n\
         property list uchar int neighbours\nproperty int8 z\nproperty uint16 tag\n\
         element face 6\nproperty list uint uint16 vertex_index\nproperty float quality\n\
         element edge 1\nproperty int vertex1\nproperty int vertex2\nend_header\n"
    )
    .into_bytes();
    let ascii = format == "ascii";
    let big = format == "binary_big_endian";
    macro_rules! put {
        ($v:expr) => {{
            let v = $v;
            if ascii {
                out.extend_from_slice(format!("{v} ").as_bytes());
            } else if big {
                out.extend_from_slice(&v.to_be_bytes());
            } else {
                out.extend_from_slice(&v.to_le_bytes());
            }
        }};
    }
    let newline = |out: &mut Vec<u8>| {
        if ascii {
            out.push(b'\n');
        }
    };
    for m in 0..2u8 {
        put!(m);
        put!(2u16);
        put!(0.5f32);
        put!(1.5f32);
        newline(&mut out);
    }
    for p in cube.positions() {
        put!(p.x as f32);
        put!(-7i16);
        put!(p.y);
        put!(3u8);
        for n in [1i32, 2, 3] {
            put!(n);
        }
        put!(p.z as i8);
        put!(65535u16);
        newline(&mut out);
    }
    for f in cube.faces() {
        put!(f.len() as u32);
        for &i in f {
            put!(i as u16);
        }
        put!(0.25f32);
        newline(&mut out);
    }
    put!(0i32);
    put!(1i32);
    newline(&mut out);
    out
}

#[test]
fn ply_skips_what_it_does_not_need_in_every_encoding() {
    for format in ["ascii", "binary_little_endian", "binary_big_endian"] {
        let m = ply::read(&odd_ply(format), &path("odd.ply")).unwrap_or_else(|e| panic!("{format}: {e}"));
        assert_eq!(m, procedural::cube(), "{format}");
    }
}

#[test]
fn ply_binary_trailing_bytes_are_ignored() {
    let mut bytes = Vec::new();
    ply::write(&mut bytes, &procedural::pyramid()).unwrap();
    bytes.extend_from_slice(b"\n\n");
    assert_eq!(ply::read(&bytes, &path("p.ply")).unwrap(), procedural::pyramid());
}

#[test]
fn ply_large_faces_use_a_wide_count() {
    let big = prism(300);
    let mut bytes = Vec::new();
    ply::write(&mut bytes, &big).unwrap();
    assert!(bytes.windows(29).any(|w| w == b"property list uint int vertex"));
    assert_eq!(ply::read(&bytes, &path("big.ply")).unwrap(), big);
}

const STL_TETRA: &str = "solid tetra
  facet normal 0 0 -1
    outer loop
      vertex 0 0 0
      vertex 0 1 0
      vertex 1 0 0
    endloop
  endfacet
  facet normal 0 -1 0
    outer loop
      vertex -0 0 0
      vertex 1 0 0
      vertex 0 0 1
    endloop
  endfacet
  FACET NORMAL -1 0 0
    OUTER LOOP
      VERTEX 0 0 0
      VERTEX 0 0 1
      VERTEX 0 1 0
    ENDLOOP
  ENDFACET
endsolid tetra
solid second part of the same file
  facet normal 1 1 1
    outer loop
      vertex 1 0 0
      vertex 0 1 0
      vertex 0 0 1
    endloop
  endfacet
endsolid
";

#[test]
fn stl_ascii_welds_bitwise_equal_vertices() {
    let m = stl::read(STL_TETRA.as_bytes(), &path("t.stl")).unwrap();
    // −0 and +0 weld too.
    assert_eq!((m.num_vertices(), m.num_faces()), (4, 4));
    let r = m.report();
    assert!(r.is_closed() && r.is_manifold(), "{r}");
    assert_eq!(r.euler_characteristic, 2);
}

#[test]
fn stl_binary_whose_header_starts_with_solid() {
    let mut bytes = Vec::new();
    stl::write(&mut bytes, &procedural::tetrahedron()).unwrap();
    bytes[..5].copy_from_slice(b"solid");
    let m = stl::read(&bytes, &path("t.stl")).unwrap();
    assert_eq!(m, procedural::tetrahedron());
    // Normals are written and unit length.
    let n = DVec3::new(
        f64::from(f32::from_le_bytes(bytes[84..88].try_into().unwrap())),
        f64::from(f32::from_le_bytes(bytes[88..92].try_into().unwrap())),
        f64::from(f32::from_le_bytes(bytes[92..96].try_into().unwrap())),
    );
    assert!((n.length() - 1.0).abs() < 1e-6);
}

#[test]
fn off_reads_what_the_thesis_files_use() {
    let text = "COFF\n# a comment\n4 4 6\n0 0 0 1 0 0 1\n1 0 0 1 0 0 1\n0 1 0 1 0 0 1\n0 0 1 1 0 0 1\n\
                3 0 2 1\n3 0 1 3 255 0 0\n3 0 3 2\n3 1 2 3\n";
    let m = off::read(text.as_bytes(), &path("t.off")).unwrap();
    assert_eq!((m.num_vertices(), m.num_faces()), (4, 4));
    assert!(m.report().is_closed());
}

#[test]
fn text_formats_accept_a_byte_order_mark() {
    let mesh = procedural::pyramid();
    let bom = b"\xef\xbb\xbf";
    let writers: [(Format, Writer); 4] = [
        (Format::Obj, |w, m| obj::write(w, m)),
        (Format::Off, |w, m| off::write(w, m)),
        (Format::Ply, |w, m| ply::write_ascii(w, m)),
        (Format::Stl, |w, m| stl::write_ascii(w, m)),
    ];
    for (format, write) in writers {
        let mut bytes = bom.to_vec();
        write(&mut bytes, &mesh).unwrap();
        let back =
            formats::read_bytes(&bytes, format, &path("bom")).unwrap_or_else(|e| panic!("{format:?}: {e}"));
        let want = if format == Format::Stl { triangulate::triangulated(&mesh) } else { mesh.clone() };
        assert_eq!(back.num_faces(), want.num_faces(), "{format:?}");
        assert_eq!(measures(&back), measures(&want), "{format:?}");
    }
    // A binary PLY's header may carry one too.
    let mut bytes = bom.to_vec();
    ply::write(&mut bytes, &mesh).unwrap();
    assert_eq!(ply::read(&bytes, &path("bom.ply")).unwrap(), mesh);
    // And a point file.
    let pts =
        texgeo::inclusion::points::parse(b"\xef\xbb\xbf# points\n0 0 0\n1 2 3\n", &path("p.txt")).unwrap();
    assert_eq!(pts, vec![DVec3::ZERO, DVec3::new(1.0, 2.0, 3.0)]);
    // Errors still name the right line and byte.
    let e = formats::read_bytes(b"\xef\xbb\xbfOFF\n1 0 0\n0 y 0\n", Format::Off, &path("b.off")).unwrap_err();
    assert!(e.to_string().ends_with("b.off:3: 'y' is not a number"), "{e}");
}

#[test]
fn empty_meshes_are_written_and_read_back_in_every_format() {
    let dir = common::TempDir::new("formats-empty");
    let empty = Mesh::new(Vec::new(), Vec::new()).unwrap();
    // What an all-holes subdivision leaves: vertices, no faces.
    let points = Mesh::new(vec![DVec3::ZERO, DVec3::X, DVec3::Y], Vec::new()).unwrap();
    for (mesh, name) in [(&empty, "empty"), (&points, "points")] {
        for ext in ["obj", "off", "ply", "stl"] {
            let file = dir.join(&format!("{name}.{ext}"));
            formats::write(&file, mesh).unwrap();
            let back = formats::read(&file).unwrap_or_else(|e| panic!("{name}.{ext}: {e}"));
            assert_eq!(back.num_faces(), 0, "{name}.{ext}");
            // OBJ and STL keep only what faces use; OFF and PLY every vertex.
            let kept = if matches!(ext, "off" | "ply") { mesh.num_vertices() } else { 0 };
            assert_eq!(back.num_vertices(), kept, "{name}.{ext}");
        }
        let mut ascii = Vec::new();
        ply::write_ascii(&mut ascii, mesh).unwrap();
        assert_eq!(ply::read(&ascii, &path("a.ply")).unwrap(), *mesh, "{name} through ascii PLY");
        let mut ascii = Vec::new();
        stl::write_ascii(&mut ascii, mesh).unwrap();
        assert_eq!(stl::read(&ascii, &path("a.stl")).unwrap().num_faces(), 0, "{name} through ascii STL");
    }
}

#[test]
fn steps_after_the_last_at_place_the_mesh() {
    let p = Placed::parse("builtin:cube@scale 2; translate 1 0 0").unwrap();
    assert_eq!(p.spec, MeshSpec::parse("builtin:cube"));
    assert_eq!(p.transform, Some(Transform::parse("scale 2; translate 1 0 0").unwrap()));
    let cube = procedural::cube();
    let placed = p.load().unwrap();
    for (q, c) in placed.positions().iter().zip(cube.positions()) {
        assert_eq!(*q, *c * 2.0 + DVec3::X);
    }
    let p = Placed::parse("a@b/x.off@rotate z 90").unwrap();
    assert_eq!(p.spec, MeshSpec::parse("a@b/x.off"));
    assert_eq!(Placed::parse("x.off").unwrap(), Placed { spec: MeshSpec::parse("x.off"), transform: None });
    // A file whose name has an `@` is read whole.
    let dir = std::env::temp_dir().join(format!("texgeo-placed-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let at = dir.join("at@sign.off");
    formats::write(&at, &cube).unwrap();
    let whole = Placed::parse(&at);
    std::fs::remove_dir_all(&dir).unwrap();
    assert_eq!(whole.unwrap(), Placed { spec: MeshSpec::parse(&at), transform: None });
    let e = Placed::parse("x.off@twist 3").unwrap_err();
    assert!(e.starts_with("unknown transform step 'twist 3'"), "{e}");
}
