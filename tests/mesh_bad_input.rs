//! Bad files: every reader must fail with an error naming the file, the line (or byte
//! offset) and the problem, never panic and never return part of a mesh. The files are
//! bytes in memory named like files (the readers behind `formats::read`), so parallel
//! tests share nothing.

mod common;

use std::path::{Path, PathBuf};

use common::{TempDir, assert_refused, texgeo_in_shell};

use texgeo::mesh::error::Location;
use texgeo::mesh::formats::{self, Format, ply, stl};
use texgeo::mesh::{MeshError, procedural};

/// Reads `bytes` as the file `name` (format from its extension), as `formats::read` does.
fn read_named(name: &str, bytes: &[u8]) -> texgeo::mesh::Result<texgeo::mesh::Mesh> {
    let path = Path::new(name);
    formats::read_bytes(bytes, Format::from_path(path)?, path)
}

/// Checks that reading `bytes` as the file `name` fails at `location` with a message
/// containing `message`.
fn expect(name: &str, bytes: &[u8], location: Location, message: &str) {
    let file = PathBuf::from(name);
    let result = read_named(name, bytes);
    let err = match result {
        Ok(m) => panic!("{name}: read a mesh with {} faces instead of failing", m.num_faces()),
        Err(e) => e,
    };
    let text = err.to_string();
    match &err {
        MeshError::Parse { path, location: got, message: m } => {
            assert_eq!(path, &file, "{name}: {text}");
            assert_eq!(got, &location, "{name}: {text}");
            assert!(m.contains(message), "{name}: expected '{message}' in: {text}");
        }
        other => panic!("{name}: not a parse error: {other}"),
    }
    assert!(text.starts_with(&format!("{}{location}: ", file.display())), "{name}: {text}");
}

/// Checks that `bytes`, well formed without any face, read as the file `name` give a
/// valid empty mesh (no faces) with `vertices` vertices: texgeo writes such files for
/// empty results, so every reader takes them.
fn expect_empty(name: &str, bytes: &[u8], vertices: usize) {
    match read_named(name, bytes) {
        Ok(m) => assert_eq!((m.num_faces(), m.num_vertices()), (0, vertices), "{name}"),
        Err(e) => panic!("{name}: a file without faces is an empty mesh, not an error: {e}"),
    }
}

fn line(n: usize) -> Location {
    Location::Line(n)
}

fn byte(n: usize) -> Location {
    Location::Byte(n as u64)
}

// ---------------------------------------------------------------- every format

#[test]
fn empty_files() {
    for ext in ["obj", "off", "ply", "stl"] {
        expect(&format!("empty.{ext}"), b"", Location::File, "the file is empty");
    }
}

#[test]
fn unknown_or_missing_extension() {
    expect("mesh.xyz", b"v 0 0 0", Location::File, "unknown mesh format '.xyz'");
    expect("mesh", b"v 0 0 0", Location::File, "no file extension");
}

#[test]
fn missing_file_is_an_io_error_naming_it() {
    let err = formats::read("/nonexistent/texgeo/x.obj").unwrap_err();
    match &err {
        MeshError::Io { path, error } => {
            assert_eq!(path, Path::new("/nonexistent/texgeo/x.obj"));
            assert_eq!(error.kind(), std::io::ErrorKind::NotFound);
        }
        other => panic!("not an I/O error: {other}"),
    }
    // The OS error once, after the path.
    assert_eq!(err.to_string(), "/nonexistent/texgeo/x.obj: No such file or directory (os error 2)");
}

// ---------------------------------------------------------------- OBJ

const OBJ_TRI: &str = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";

fn obj(body: &str) -> Vec<u8> {
    format!("{OBJ_TRI}{body}").into_bytes()
}

#[test]
fn obj_truncated_and_bad_tokens() {
    expect("trunc.obj", b"v 0 0 0\nv 1 0", line(2), "a vertex needs three coordinates");
    expect("token.obj", b"v 0 0 0\nv 1 x 0\n", line(2), "'x' is not a number");
    expect("face-token.obj", &obj("f 1 2 three\n"), line(4), "vertex index 'three' is not an integer");
    expect("slashes.obj", &obj("f 1/1/1/1 2 3\n"), line(4), "'1/1/1/1' is not a face vertex");
    expect("noindex.obj", &obj("f /1 2 3\n"), line(4), "face vertex '/1' has no vertex index");
    expect("keyword.obj", b"hello world\n", line(1), "unknown OBJ statement 'hello'");
    expect("extra.obj", b"v 0 0 0 1 2\n", line(1), "this one has 5 values");
    expect("vt.obj", &obj("vt 0.5\n"), line(4), "'vt' needs at least 2 numbers, found 1");
    expect("cont.obj", &obj("f 1 2 \\\n3\n"), line(4), "line continuations");
}

#[test]
fn obj_indices_out_of_range() {
    expect(
        "range.obj",
        &obj("f 1 2 4\n"),
        line(4),
        "vertex index 4 is out of range (3 defined before this line)",
    );
    expect("zero.obj", &obj("f 0 1 2\n"), line(4), "vertex index 0 is not allowed");
    expect(
        "relative.obj",
        &obj("f -1 -2 -4\n"),
        line(4),
        "relative vertex index -4 reaches before the first",
    );
    // Forward references are not allowed: the vertex comes after the face.
    expect("forward.obj", b"v 0 0 0\nv 1 0 0\nf 1 2 3\nv 0 1 0\n", line(3), "vertex index 3 is out of range");
    expect(
        "vt-range.obj",
        &obj("vt 0 0\nf 1/1 2/2 3/1\n"),
        line(5),
        "texture coordinate index 2 is out of range",
    );
    expect("vn-range.obj", &obj("f 1//1 2//1 3//1\n"), line(4), "normal index 1 is out of range (0 defined");
    expect("huge.obj", &obj("f 1 2 99999999999999999999\n"), line(4), "is not an integer");
}

#[test]
fn obj_non_finite_coordinates() {
    expect("nan.obj", b"v 0 0 0\nv nan 0 0\n", line(2), "coordinate 'nan' is not finite");
    expect("inf.obj", b"v 0 -inf 0\n", line(1), "coordinate '-inf' is not finite");
    expect("overflow.obj", b"v 0 0 1e400\n", line(1), "coordinate '1e400' is not finite");
    expect("w0.obj", b"v 0 0 1 0\n", line(1), "vertex weight w is zero");
    expect("w-tiny.obj", b"v 0 0 1e300 1e-300\n", line(1), "divided by the weight w is not finite");
}

#[test]
fn obj_small_faces_and_no_faces() {
    expect("two.obj", &obj("f 1 2\n"), line(4), "a face needs at least 3 vertices, this one has 2");
    expect("none.obj", &obj("f\n"), line(4), "this one has 0");
    // OBJ keeps only the vertices faces use.
    expect_empty("nofaces.obj", OBJ_TRI.as_bytes(), 0);
    expect_empty("comments.obj", b"# nothing\n\n", 0);
}

#[test]
fn obj_not_utf8() {
    expect("binary.obj", b"v 0 0 0\nv 1 0 0\nv \xff\xfe 0 0\n", line(3), "invalid UTF-8 at byte 18");
}

// ---------------------------------------------------------------- OFF

#[test]
fn off_bad_files() {
    let head = "OFF\n4 1 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n";
    expect("header.off", b"PLY\n", line(1), "expected an OFF header, found 'PLY'");
    expect("trunc.off", b"OFF\n3 1 0\n0 0 0\n1 0 0\n", line(4), "the file ends after 2 of 3 vertices");
    expect("trunc-face.off", head.as_bytes(), line(6), "the file ends after 0 of 1 faces");
    expect("token.off", b"OFF\n1 0 0\n0 y 0\n", line(3), "'y' is not a number");
    expect("nan.off", b"OFF\n1 0 0\n0 NaN 0\n", line(3), "coordinate 'NaN' is not finite");
    expect("inf.off", b"OFF\n1 0 0\ninf 0 0\n", line(3), "coordinate 'inf' is not finite");
    expect("range.off", format!("{head}3 0 1 4\n").as_bytes(), line(7), "vertex index 4 is out of range");
    expect("neg.off", format!("{head}3 0 -1 2\n").as_bytes(), line(7), "'-1' is not a non-negative integer");
    expect("small.off", format!("{head}2 0 1\n").as_bytes(), line(7), "at least 3 vertices, this one has 2");
    expect(
        "short-face.off",
        format!("{head}4 0 1 2\n").as_bytes(),
        line(7),
        "declares 4 vertices but lists 3",
    );
    expect(
        "counts.off",
        b"OFF\n1000000000 1 0\n0 0 0\n",
        line(3),
        "the file ends after 1 of 1000000000 vertices",
    );
    expect("utf8.off", b"OFF\n1 0 0\n\xc3\x28 0 0\n", line(3), "invalid UTF-8");
    expect_empty("nofaces.off", b"OFF\n1 0 0\n0 0 0\n", 1);
}

// ---------------------------------------------------------------- PLY, ascii

/// The tetrahedron as ascii PLY: header lines 1–10, vertices 11–14, faces 15–18.
fn ascii_tetra() -> Vec<String> {
    let mut bytes = Vec::new();
    ply::write_ascii(&mut bytes, &procedural::tetrahedron()).unwrap();
    let text = String::from_utf8(bytes).unwrap();
    let lines: Vec<String> = text.lines().map(str::to_string).collect();
    assert_eq!(lines.len(), 18);
    assert_eq!(lines[9], "end_header");
    lines
}

/// The ascii tetrahedron with line `n` (1-based) replaced.
fn ascii_with(n: usize, replacement: &str) -> Vec<u8> {
    let mut lines = ascii_tetra();
    lines[n - 1] = replacement.to_string();
    (lines.join("\n") + "\n").into_bytes()
}

#[test]
fn ply_header_errors_name_the_line() {
    expect("magic.ply", b"hello\n", line(1), "not a PLY file");
    expect(
        "no-end.ply",
        b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n",
        line(4),
        "no 'end_header'",
    );
    expect("format.ply", &ascii_with(2, "format binary_middle_endian 1.0"), line(2), "unknown format");
    expect("version.ply", &ascii_with(2, "format ascii 2.0"), line(2), "only PLY version 1.0");
    expect("type.ply", &ascii_with(5, "property quad x"), line(5), "unknown property type 'quad'");
    expect("keyword.ply", &ascii_with(3, "colour red"), line(3), "unknown header keyword 'colour'");
    expect("no-x.ply", &ascii_with(5, "property double w"), line(4), "no scalar property 'x'");
    expect("no-list.ply", &ascii_with(9, "property list uchar int corners"), line(8), "no 'vertex_indices'");
    expect(
        "float-list.ply",
        &ascii_with(9, "property list uchar float vertex_indices"),
        line(8),
        "list of integers",
    );
    expect(
        "float-count.ply",
        &ascii_with(9, "property list float int vertex_indices"),
        line(9),
        "count type",
    );
    expect(
        "bad-count.ply",
        &ascii_with(4, "element vertex -4"),
        line(4),
        "'-4' is not a non-negative integer",
    );
    expect("too-many.ply", &ascii_with(4, "element vertex 4294967296"), line(4), "more than 2^32");
    expect("no-vertex.ply", &ascii_with(4, "element point 4"), line(10), "no 'vertex' element");
    let mut bad = ascii_tetra().join("\n").into_bytes();
    bad[23] = 0xff; // inside line 3, the comment
    expect("header-utf8.ply", &bad, line(3), "header line is not text");
}

#[test]
fn ply_ascii_data_errors_name_the_line() {
    expect("token.ply", &ascii_with(12, "1 x -1"), line(12), "vertex 1, property 'y': 'x' is not a number");
    expect(
        "nan.ply",
        &ascii_with(13, "nan 1 -1"),
        line(13),
        "vertex 2, property 'x': coordinate NaN is not finite",
    );
    expect("inf.ply", &ascii_with(13, "-1 inf -1"), line(13), "coordinate inf is not finite");
    expect(
        "range.ply",
        &ascii_with(15, "3 0 1 7"),
        line(15),
        "vertex index 7 is out of range (the file has 4",
    );
    expect("neg.ply", &ascii_with(15, "3 0 -1 2"), line(15), "vertex index -1 is negative");
    expect(
        "small.ply",
        &ascii_with(16, "2 0 1"),
        line(16),
        "a face needs at least 3 vertices, this one has 2",
    );
    expect(
        "short.ply",
        &ascii_with(17, "3 0 1"),
        line(17),
        "face 2, property 'vertex_indices': the line ends early",
    );
    expect("extra.ply", &ascii_with(11, "1 1 1 1"), line(11), "unexpected extra value '1'");
    expect(
        "int-range.ply",
        &ascii_with(18, "3 1 3 4294967296"),
        line(18),
        "4294967296 is out of range for int",
    );
    let utf8 = replace_bytes(ascii_with(12, "1 \u{fffd} 1"), "\u{fffd}", b"\xff");
    expect("utf8.ply", &utf8, line(12), "invalid UTF-8");
}

#[test]
fn ply_ascii_counts_larger_than_the_file() {
    let lines = ascii_tetra();
    let cut = (lines[..16].join("\n") + "\n").into_bytes();
    expect("trunc.ply", &cut, line(16), "the file ends after 2 of 4 'face' entries");
    expect(
        "counts.ply",
        &ascii_with(8, "element face 1000"),
        line(18),
        "the file ends after 4 of 1000 'face' entries",
    );
    let mut more = ascii_tetra().join("\n");
    more.push_str("\n1 2 3\n");
    expect("more.ply", more.as_bytes(), line(19), "content after the last element");
}

// ---------------------------------------------------------------- PLY, binary

/// The cube as binary PLY (`double` x y z, `uchar` count, `int` indices) and the offset of
/// its data: vertices at 24 bytes each, then faces at 1 + 4·4 bytes each.
fn binary_cube() -> (Vec<u8>, usize) {
    let mut bytes = Vec::new();
    ply::write(&mut bytes, &procedural::cube()).unwrap();
    let end = b"end_header\n";
    let data = bytes.windows(end.len()).position(|w| w == end).unwrap() + end.len();
    assert_eq!(bytes.len(), data + 8 * 24 + 6 * 17);
    (bytes, data)
}

const FACES: usize = 8 * 24;

#[test]
fn ply_binary_data_errors_name_the_byte() {
    let (good, data) = binary_cube();

    let mut b = good.clone();
    let at = data + 3 * 24 + 8; // vertex 3, y
    b[at..at + 8].copy_from_slice(&f64::NAN.to_le_bytes());
    expect("nan.ply", &b, byte(at), "vertex 3, property 'y': coordinate NaN is not finite");

    let mut b = good.clone();
    let at = data + 24; // vertex 1, x
    b[at..at + 8].copy_from_slice(&f64::INFINITY.to_le_bytes());
    expect("inf.ply", &b, byte(at), "vertex 1, property 'x': coordinate inf is not finite");

    let mut b = good.clone();
    let at = data + FACES + 2 * 17 + 1 + 4; // face 2, second index
    b[at..at + 4].copy_from_slice(&8i32.to_le_bytes());
    expect("range.ply", &b, byte(at), "face 2, property 'vertex_indices': vertex index 8 is out of range");

    let mut b = good.clone();
    b[at..at + 4].copy_from_slice(&(-3i32).to_le_bytes());
    expect("neg.ply", &b, byte(at), "vertex index -3 is negative");

    let mut b = good.clone();
    let at = data + FACES + 17; // face 1, count
    b[at] = 2;
    expect("small.ply", &b, byte(at), "face 1, property 'vertex_indices': a face needs at least 3 vertices");
}

#[test]
fn ply_binary_truncated_and_counts_larger_than_the_file() {
    let (good, data) = binary_cube();

    // Cut inside the last face: its count says 4 indices, only 6 bytes follow.
    let cut = &good[..good.len() - 10];
    let at = data + FACES + 5 * 17;
    expect("trunc-face.ply", cut, byte(at), "face 5, property 'vertex_indices': a list of 4 × 4 bytes");

    // Cut inside the vertices: the element does not fit.
    let cut = &good[..data + 100];
    expect(
        "trunc-vertex.ply",
        cut,
        byte(data),
        "element 'vertex' (header line 4) claims 8 × 24 bytes = 192 bytes, but only 100",
    );

    // Cut right after the header.
    expect("trunc-header.ply", &good[..data], byte(data), "but only 0 bytes are left");

    // A count that could never fit: refused before anything is allocated.
    let text =
        String::from_utf8_lossy(&good[..data]).replace("element vertex 8", "element vertex 3000000000");
    let mut b = text.into_bytes();
    let data2 = b.len();
    b.extend_from_slice(&good[data..]);
    expect("counts.ply", &b, byte(data2), "claims 3000000000 × 24 bytes = 72000000000 bytes");

    // A face list claiming 200 indices.
    let mut b = good.clone();
    let at = data + FACES + 3 * 17;
    b[at] = 200;
    expect("list.ply", &b, byte(at), "a list of 200 × 4 bytes = 800 bytes");
}

#[test]
fn ply_big_endian_errors_name_the_byte() {
    let header = "ply\nformat binary_big_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
                  property float z\nelement face 1\nproperty list uchar uint vertex_indices\nend_header\n";
    let mut b = header.as_bytes().to_vec();
    let data = b.len();
    for v in [0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, f32::NAN, 0.0] {
        b.extend_from_slice(&v.to_be_bytes());
    }
    b.push(3);
    for i in [0u32, 1, 2] {
        b.extend_from_slice(&i.to_be_bytes());
    }
    expect("be-nan.ply", &b, byte(data + 2 * 12 + 4), "vertex 2, property 'y': coordinate NaN");
    // The same file with the NaN fixed reads.
    let at = data + 28;
    b[at..at + 4].copy_from_slice(&1.0f32.to_be_bytes());
    let m = ply::read(&b, std::path::Path::new("be.ply")).unwrap();
    assert_eq!(m.num_faces(), 1);
}

// ---------------------------------------------------------------- STL

fn binary_cube_stl() -> Vec<u8> {
    let mut bytes = Vec::new();
    stl::write(&mut bytes, &procedural::cube()).unwrap();
    assert_eq!(bytes.len(), 84 + 12 * 50);
    bytes
}

#[test]
fn stl_neither_binary_nor_ascii() {
    expect("short.stl", b"hello world\n", Location::File, "not an STL file");
    expect("short2.stl", b"hello world\n", Location::File, "too short (12 bytes) for a binary STL header");
    expect("garbage.stl", &[b'x'; 100], byte(80), "does not start with 'solid'");
}

#[test]
fn stl_binary_truncated_or_counts_larger_than_the_file() {
    let good = binary_cube_stl();
    expect(
        "trunc.stl",
        &good[..good.len() - 1],
        byte(80),
        "claims 12 triangles, which take 684 bytes, but the file has 683",
    );
    let mut b = good.clone();
    b[80..84].copy_from_slice(&1_000_000_000u32.to_le_bytes());
    expect("counts.stl", &b, byte(80), "claims 1000000000 triangles, which take 50000000084 bytes");
    // A binary file whose header starts with "solid", cut short: not text either.
    let mut b = good[..good.len() - 7].to_vec();
    b[..5].copy_from_slice(b"solid");
    expect("solid-trunc.stl", &b, byte(80), "starts with 'solid' but is not text");
    // Zero triangles.
    let mut b = good[..84].to_vec();
    b[80..84].copy_from_slice(&0u32.to_le_bytes());
    expect_empty("zero.stl", &b, 0);
}

#[test]
fn stl_binary_non_finite_coordinates() {
    let mut b = binary_cube_stl();
    let at = 84 + 3 * 50 + 12 + 12 + 8; // triangle 3, vertex 1, z
    b[at..at + 4].copy_from_slice(&f32::NAN.to_le_bytes());
    expect("nan.stl", &b, byte(at), "triangle 3, vertex 1: coordinate NaN is not finite");
    let mut b = binary_cube_stl();
    let at = 84 + 11 * 50 + 12; // triangle 11, vertex 0, x
    b[at..at + 4].copy_from_slice(&f32::NEG_INFINITY.to_le_bytes());
    expect("inf.stl", &b, byte(at), "triangle 11, vertex 0: coordinate -inf is not finite");
    // The facet normal is not used, so a NaN there is fine.
    let mut b = binary_cube_stl();
    b[84..88].copy_from_slice(&f32::NAN.to_le_bytes());
    assert_eq!(read_named("normal.stl", &b).unwrap().num_faces(), 12);
}

const ASCII_FACET: &str =
    "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\n";

/// One ascii facet with line `n` (1-based) replaced, closed with `endsolid`.
fn ascii_stl_with(n: usize, replacement: &str) -> Vec<u8> {
    let mut lines: Vec<&str> = ASCII_FACET.lines().collect();
    lines[n - 1] = replacement;
    (lines.join("\n") + "\nendsolid t\n").into_bytes()
}

#[test]
fn stl_ascii_errors_name_the_line() {
    expect(
        "trunc.stl",
        b"solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\n",
        line(4),
        "the file ends inside a facet's vertex loop",
    );
    expect("trunc2.stl", ASCII_FACET.as_bytes(), line(8), "the file ends before 'endsolid'");
    expect("token.stl", &ascii_stl_with(5, "vertex 1 zero 0"), line(5), "'zero' is not a number");
    expect("nan.stl", &ascii_stl_with(6, "vertex 0 nan 0"), line(6), "coordinate 'nan' is not finite");
    expect("inf.stl", &ascii_stl_with(4, "vertex inf 0 0"), line(4), "coordinate 'inf' is not finite");
    expect("short-vertex.stl", &ascii_stl_with(4, "vertex 0 0"), line(4), "a vertex needs three coordinates");
    expect("two.stl", &ascii_stl_with(6, ""), line(7), "a facet needs at least 3 vertices, this one has 2");
    expect("keyword.stl", &ascii_stl_with(3, "inner loop"), line(3), "expected 'outer loop', found 'inner'");
    expect(
        "normal.stl",
        &ascii_stl_with(2, "facet normal 0 0"),
        line(2),
        "a facet normal needs three numbers",
    );
    expect("endfacet.stl", &ascii_stl_with(8, "endloop"), line(8), "expected 'endfacet', found 'endloop'");
    expect_empty("no-facets.stl", b"solid t\nendsolid t\n", 0);
    expect("utf8.stl", b"solid t\nfacet \xff\n", line(2), "invalid UTF-8 at byte 14");
}

/// `bytes` with the first occurrence of `marker` replaced by raw bytes.
fn replace_bytes(bytes: Vec<u8>, marker: &str, with: &[u8]) -> Vec<u8> {
    let m = marker.as_bytes();
    let at = bytes.windows(m.len()).position(|w| w == m).unwrap();
    [&bytes[..at], with, &bytes[at + m.len()..]].concat()
}

// ---------------------------------------------------------------- mutations

/// `mesh convert` of a mesh to every format and back: exact for the polygon formats; for
/// binary STL, the triangulated mesh rounded to f32 (same area and volume), or a clear
/// error when a coordinate does not fit f32.
fn converts_back(m: &texgeo::mesh::Mesh) {
    use texgeo::mesh::covering::Covering;
    use texgeo::mesh::formats::Format;
    // OBJ keeps only the vertices faces use: none in a mesh without faces.
    let empty = texgeo::mesh::Mesh::new(Vec::new(), Vec::new()).unwrap();
    for format in [Format::Obj, Format::Off, Format::Ply] {
        let mut bytes = Vec::new();
        formats::write_to(&mut bytes, m, format).unwrap();
        let want = if format == Format::Obj && m.num_faces() == 0 { &empty } else { m };
        assert_eq!(&formats::read_bytes(&bytes, format, Path::new("back")).unwrap(), want, "{format:?}");
    }
    let mut bytes = Vec::new();
    match formats::write_to(&mut bytes, m, Format::Stl) {
        Ok(()) => {
            let back = formats::read_bytes(&bytes, Format::Stl, Path::new("back.stl")).unwrap();
            let want =
                texgeo::mesh::triangulate::triangulated(m).map_positions(|p| p.as_vec3().as_dvec3()).unwrap();
            let (a, b) = (Covering::new(&back), Covering::new(&want));
            let same = |x: f64, y: f64| x == y || (x - y).abs() <= 1e-9 * x.abs().max(y.abs());
            assert!(same(a.area(), b.area()), "{} vs {}", a.area(), b.area());
            assert!(
                same(a.volume(), b.volume()) || !b.volume().is_finite(),
                "{} vs {}",
                a.volume(),
                b.volume()
            );
        }
        Err(e) => assert!(e.to_string().contains("does not fit binary STL"), "{e}"),
    }
}

/// Random byte flips, cuts and insertions in valid files of every format: a reader may
/// accept the result (then it is a valid mesh by construction, which converts to every
/// format and back) or reject it with a parse error, but never panic.
#[test]
fn mutated_files_never_panic() {
    use texgeo::mesh::formats::Format;
    use texgeo::random::Rng;
    let mesh = procedural::pyramid();
    let mut rng = Rng::new(2006);
    let mut files: Vec<(Format, Vec<u8>)> = Vec::new();
    for format in [Format::Obj, Format::Off, Format::Ply, Format::Stl] {
        let mut bytes = Vec::new();
        formats::write_to(&mut bytes, &mesh, format).unwrap();
        files.push((format, bytes));
    }
    let mut ascii = Vec::new();
    ply::write_ascii(&mut ascii, &mesh).unwrap();
    files.push((Format::Ply, ascii));
    let mut ascii = Vec::new();
    stl::write_ascii(&mut ascii, &mesh).unwrap();
    files.push((Format::Stl, ascii));
    let path = std::path::Path::new("mutated");
    let interesting = b"0123456789-+.eE \n#/nainf\xff\x00";
    for (format, good) in &files {
        let (mut accepted, mut rejected) = (0, 0);
        for _ in 0..3000 {
            let mut b = good.clone();
            for _ in 0..1 + rng.below(3) {
                let at = rng.below(b.len() as u64 + 1) as usize;
                match rng.below(4) {
                    0 if at < b.len() => b[at] = rng.below(256) as u8,
                    1 if at < b.len() => b[at] = interesting[rng.below(interesting.len() as u64) as usize],
                    2 => b.truncate(at),
                    _ => b.insert(at, interesting[rng.below(interesting.len() as u64) as usize]),
                }
            }
            match formats::read_bytes(&b, *format, path) {
                Ok(m) => {
                    // Possibly without faces: a mutation can leave a well-formed empty mesh.
                    accepted += 1;
                    converts_back(&m);
                }
                Err(MeshError::Parse { .. }) => rejected += 1,
                Err(e) => panic!("{format:?}: not a parse error: {e}"),
            }
        }
        assert!(
            rejected > 100,
            "{format:?}: only {rejected} of 3000 mutations rejected ({accepted} accepted)"
        );
    }
}

// ---------------------------------------------------------------- endless inputs

/// Runs texgeo with at most 2 GiB of address space and 60 s of CPU: an endless input read
/// whole would fail the limit (or the test) instead of filling the machine.
fn bounded(args: &[&str]) -> std::process::Output {
    texgeo_in_shell("ulimit -v 2097152; ulimit -t 60;", args)
}

#[test]
fn endless_and_random_devices_stop_at_the_first_impossible_byte() {
    let dir = TempDir::new("endless");
    for (name, device, at) in [
        ("zero.off", "/dev/zero", "byte 0"),
        ("zero.obj", "/dev/zero", "byte 0"),
        ("zero.ply", "/dev/zero", "byte 0"),
        ("zero.stl", "/dev/zero", "byte 84"),
        ("random.off", "/dev/urandom", "byte "),
        ("random.obj", "/dev/urandom", "byte "),
        ("random.ply", "/dev/urandom", "byte "),
        ("random.stl", "/dev/urandom", "byte "),
    ] {
        let link = dir.join(name);
        std::os::unix::fs::symlink(device, &link).unwrap();
        let o = bounded(&["mesh", "stats", link.to_str().unwrap()]);
        assert_refused(&o, &[name, at, "stopped reading"]);
    }
    std::os::unix::fs::symlink("/dev/zero", dir.join("zero.npy")).unwrap();
    for points in ["/dev/zero", "/dev/urandom", &dir.arg("zero.npy")] {
        let o = bounded(&["inclusion", "builtin:cube", "--points", points]);
        assert_refused(&o, &[points, "byte ", "stopped reading"]);
    }
}

#[test]
fn over_long_lines_are_refused_with_the_limit_and_offset() {
    let dir = TempDir::new("long-lines");
    let line = "#".repeat(texgeo::mesh::formats::bounded::MAX_LINE + 1);
    std::fs::write(dir.join("long.off"), format!("OFF\n{line}\n4 4 0\n")).unwrap();
    std::fs::write(dir.join("long.txt"), format!("1 2 3\n{line}\n4 5 6\n")).unwrap();
    let o = bounded(&["mesh", "stats", &dir.arg("long.off")]);
    assert_refused(&o, &["long.off: byte 4: a line longer than 16 MiB"]);
    let o = bounded(&["inclusion", "builtin:cube", "--method", "cpu", "--points", &dir.arg("long.txt")]);
    assert_refused(&o, &["long.txt: byte 6: a line longer than 16 MiB"]);
    // A PLY header without end.
    std::fs::write(dir.join("long.ply"), format!("ply\n{}", "comment x\n".repeat(120_000))).unwrap();
    let o = bounded(&["mesh", "stats", &dir.arg("long.ply")]);
    assert_refused(&o, &["long.ply: byte 0: no 'end_header' line within the first 1 MiB"]);
}

// ---------------------------------------------------------------- terminal safety

#[test]
fn control_bytes_from_files_and_names_are_escaped_in_messages() {
    let dir = TempDir::new("escape");
    let cases: [(&str, &str, &str); 5] = [
        // C1 controls and bidirectional overrides are valid UTF-8 text: quoted, escaped.
        ("bad.obj", "v 0 0 0\n\u{9b}2Jclear 1 2\n", "unknown OBJ statement '\\u{9b}2Jclear'"),
        ("bad.off", "OFF\n1 0 0\n0 \u{202e}1 0\n", "'\\u{202e}1' is not a number"),
        ("bad.binvox", "#binvox 1\n\u{9b}5mdim 4 4 4\ndata\n", "unknown header line '\\u{9b}5mdim'"),
        // ASCII controls stop the reading and are named, not echoed.
        ("esc.off", "OFF\n1 0 0\n0 \x1b]0;title\x07 0\n", "byte 0x1b cannot be part of OFF text"),
        // Names too.
        ("bad\x1b[31mname.off", "PLY\n", "bad\\x1b[31mname.off:1"),
    ];
    for (name, text, needle) in cases {
        std::fs::write(dir.join(name), text).unwrap();
        let o = if name.ends_with(".binvox") {
            common::texgeo(&["render", &dir.arg(name), "-o", &dir.arg("x.png")])
        } else {
            common::texgeo(&["mesh", "stats", &dir.arg(name)])
        };
        assert_refused(&o, &[needle]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(
            !err.chars().any(|c| (c.is_control() && c != '\n') || c == '\u{202e}'),
            "{name}: raw control characters in {err:?}"
        );
    }
}
