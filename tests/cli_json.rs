//! `--json`: each command prints one JSON object on stdout, numbers as numbers, and its
//! numbers are the text output's; `voxelize -o OUT.npy` holds the same voxels as the
//! binvox file, indexed [x, y, z], with the grid beside it.

mod common;

use common::{TempDir, stderr, stdout, texgeo};
use serde_json::Value;
use texgeo::voxel::binvox;

/// Runs texgeo, expecting success; the output.
fn run(args: &[&str]) -> std::process::Output {
    let o = texgeo(args);
    assert!(o.status.success(), "{args:?}: {}{}", stdout(&o), stderr(&o));
    o
}

/// Runs texgeo with `--json`: stdout must be exactly one JSON object on one line.
fn json(args: &[&str]) -> Value {
    let mut all = args.to_vec();
    all.push("--json");
    let out = stdout(&run(&all));
    assert_eq!(out.lines().count(), 1, "{all:?}: one line on stdout: {out}");
    let v: Value = serde_json::from_str(&out).unwrap_or_else(|e| panic!("{all:?}: {e}: {out}"));
    assert!(v.is_object(), "{out}");
    v
}

/// The text after `key` at the start of a line of `text` (`key` then spaces).
fn field<'a>(text: &'a str, key: &str) -> &'a str {
    text.lines()
        .find_map(|l| l.strip_prefix(key))
        .unwrap_or_else(|| panic!("no '{key}' in {text}"))
        .trim_start()
}

/// The first whitespace-separated word of `s`, as a number.
fn first_number<T: std::str::FromStr>(s: &str) -> T
where
    T::Err: std::fmt::Debug,
{
    s.split_whitespace().next().unwrap().trim_end_matches(',').parse().unwrap()
}

fn u(v: &Value, key: &str) -> u64 {
    v[key].as_u64().unwrap_or_else(|| panic!("'{key}' is not a whole number in {v}"))
}

fn f(v: &Value, key: &str) -> f64 {
    v[key].as_f64().unwrap_or_else(|| panic!("'{key}' is not a number in {v}"))
}

#[test]
fn mesh_stats_json_has_the_text_numbers() {
    let dir = TempDir::new("json-stats");
    let open = dir.join("open.obj");
    std::fs::write(&open, "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\n").unwrap();
    let open = open.to_str().unwrap();
    for mesh in ["builtin:torus", "builtin:cavity", open] {
        let text = stdout(&run(&["mesh", "stats", mesh]));
        let v = json(&["mesh", "stats", mesh]);
        assert_eq!(u(&v, "vertices"), first_number::<u64>(field(&text, "vertices")), "{mesh}");
        assert_eq!(u(&v, "faces"), first_number::<u64>(field(&text, "faces")), "{mesh}");
        assert_eq!(u(&v, "edges"), first_number::<u64>(field(&text, "edges")), "{mesh}");
        assert_eq!(f(&v, "area"), first_number::<f64>(field(&text, "area")), "{mesh}");
        for key in ["closed", "oriented", "manifold", "solid"] {
            assert!(v[key].is_boolean(), "{key} in {v}");
        }
        let closed = field(&text, "closed:").starts_with("yes");
        assert_eq!(v["closed"], closed, "{mesh}");
        let solid = text.contains("solid: yes");
        assert_eq!(v["solid"], solid, "{mesh}");
        // A reason exactly when it is not a solid: the text's.
        match v.get("reason") {
            None => assert!(solid),
            Some(r) => assert!(text.contains(&format!("solid: no: {}", r.as_str().unwrap())), "{r} {text}"),
        }
        let bbox = v["bbox"].as_array().unwrap();
        assert_eq!(bbox.len(), 2);
        assert!(bbox.iter().all(|c| c.as_array().unwrap().iter().all(Value::is_f64)), "{v}");
        if closed {
            assert_eq!(f(&v, "volume"), first_number::<f64>(field(&text, "volume")), "{mesh}");
        } else {
            assert!(v["volume"].is_null(), "{v}");
        }
    }
}

#[test]
fn inclusion_json_counts_equal_the_text_counts() {
    let dir = TempDir::new("json-inclusion");
    let labels = dir.arg("labels.npy");
    for method in ["cpu", "octants", "auto"] {
        let args = ["inclusion", "builtin:knot", "--random", "3000", "--method", method];
        let text = stdout(&run(&args));
        let v = json(&args);
        // "MESH: N points, I inside, O outside, B on the boundary"
        let words: Vec<&str> = text.lines().next().unwrap().split_whitespace().collect();
        let n = |i: usize| words[i].parse::<u64>().unwrap();
        assert_eq!(
            (u(&v, "points"), u(&v, "inside"), u(&v, "outside"), u(&v, "boundary")),
            (n(1), n(3), n(5), n(7))
        );
        assert_eq!(u(&v, "points"), 3000);
        assert!(v["method"].is_string() && f(&v, "build_ms") >= 0.0 && f(&v, "classify_ms") >= 0.0, "{v}");
        assert!(v["structure_bytes"].is_u64(), "{v}");
        assert_eq!(v.get("auto").is_some(), method == "auto", "{v}");
        // With -o the object is printed too, and the file holds the same counts.
        let mut with_output = args.to_vec();
        with_output.extend(["-o", &labels]);
        let w = json(&with_output);
        let bytes = std::fs::read(&labels).unwrap();
        let data = &bytes[bytes.len() - 3000..];
        let count = |c: u8| data.iter().filter(|&&b| b == c).count() as u64;
        assert_eq!((count(1), count(0), count(2)), (u(&w, "inside"), u(&w, "outside"), u(&w, "boundary")));
    }
}

/// The voxels of a `.npy` volume written by texgeo: (N, N, N) bool, C order.
fn read_npy_volume(path: &std::path::Path) -> (usize, Vec<u8>) {
    let bytes = std::fs::read(path).unwrap();
    assert!(bytes.starts_with(b"\x93NUMPY\x01\x00"));
    let len = u16::from_le_bytes([bytes[8], bytes[9]]) as usize;
    let header = std::str::from_utf8(&bytes[10..10 + len]).unwrap();
    assert!(header.contains("'descr': '|b1'") && header.contains("'fortran_order': False"), "{header}");
    let shape = header.split("'shape': (").nth(1).unwrap().split(')').next().unwrap();
    let dims: Vec<usize> = shape.split(',').map(|s| s.trim().parse().unwrap()).collect();
    assert!(dims.len() == 3 && dims[0] == dims[1] && dims[1] == dims[2], "{header}");
    let data = bytes[10 + len..].to_vec();
    assert_eq!(data.len(), dims[0].pow(3));
    (dims[0], data)
}

#[test]
fn voxelize_json_and_npy_match_the_binvox() {
    let dir = TempDir::new("json-voxelize");
    let bv = dir.arg("v.binvox");
    let npy = dir.arg("v.npy");
    for (mesh, res, method) in [("builtin:knot", "19", "cpu"), ("builtin:cavity", "16", "scanline")] {
        let args = ["voxelize", mesh, "--res", res, "--method", method, "-o"];
        let text = stdout(&run(&[&args[..], &[&bv]].concat()));
        let v = json(&[&args[..], &[&npy]].concat());
        // "MESH: N³ voxels, K occupied, …"
        let line = text.lines().find(|l| l.contains("occupied")).unwrap();
        let occupied: u64 = line.split(", ").nth(1).unwrap().split(' ').next().unwrap().parse().unwrap();
        assert_eq!(u(&v, "occupied"), occupied, "{mesh}");
        assert_eq!(v["method"], method);
        assert!(f(&v, "pitch") > 0.0 && v["timings"]["total_ms"].is_f64(), "{v}");
        let (grid, volume) = binvox::read(&bv).unwrap();
        let (min, side) = grid.cube_out();
        let n = grid.n;
        assert_eq!(u(&v, "resolution") as usize, n);
        let origin: Vec<f64> = v["origin"].as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect();
        assert_eq!(origin, min.to_array().to_vec());
        assert_eq!(f(&v, "pitch"), side / n as f64);
        // The same bits, indexed [x, y, z].
        let (m, data) = read_npy_volume(&dir.join("v.npy"));
        assert_eq!(m, n);
        for x in 0..n {
            for y in 0..n {
                for z in 0..n {
                    assert_eq!(data[(x * n + y) * n + z] == 1, volume.get(x, y, z), "{mesh} ({x}, {y}, {z})");
                }
            }
        }
        assert!(data.iter().all(|&b| b <= 1));
        assert_eq!(data.iter().filter(|&&b| b == 1).count() as u64, occupied);
        // The grid beside it.
        let side_file: Value = serde_json::from_slice(&std::fs::read(dir.join("v.json")).unwrap()).unwrap();
        assert_eq!(side_file["origin"], v["origin"]);
        assert_eq!(side_file["pitch"], v["pitch"]);
        assert_eq!(u(&side_file, "resolution") as usize, n);
    }
}

#[test]
fn subdivide_json_counts_and_validation() {
    let args = ["subdivide", "builtin:pyramid", "-l", "2", "--method", "cpu", "--validate"];
    let text = stdout(&run(&args));
    let v = json(&args);
    let line = text.lines().find(|l| l.starts_with("level 2:")).unwrap();
    let words: Vec<&str> = line.split_whitespace().collect();
    assert_eq!(u(&v, "refined_vertices"), words[2].parse::<u64>().unwrap());
    assert_eq!(u(&v, "refined_faces"), words[4].parse::<u64>().unwrap());
    assert_eq!((u(&v, "vertices"), u(&v, "faces"), u(&v, "level")), (5, 5, 2));
    assert_eq!(v["method"], "cpu");
    assert!(v["gpu"].is_null());
    let val = &v["validation"];
    assert_eq!(val["passed"], true, "{v}");
    assert!(val["tolerance"].is_f64() && val["comparison"]["max_error"].is_f64(), "{v}");
    assert_eq!(val["comparison"]["vertices"][0], v["refined_vertices"]);
    // Without --validate: no comparison.
    let v = json(&args[..6]);
    assert!(v["validation"].is_null(), "{v}");
}

#[test]
fn boolean_and_csg_json_have_the_text_volumes() {
    let dir = TempDir::new("json-boolean");
    let out = dir.arg("u.off");
    let args = [
        "boolean",
        "builtin:cube",
        "builtin:sphere",
        "--op",
        "union",
        "--transform-b",
        "translate 0.5 0.5 0.5",
        "-o",
        &out,
        "--stats",
    ];
    let text = stdout(&run(&args));
    let v = json(&args);
    // "A ∪ B: N triangles, volume V -> OUT"
    let line = text.lines().find(|l| l.contains("triangles, volume")).unwrap();
    let triangles: u64 = line.split(": ").nth(1).unwrap().split(' ').next().unwrap().parse().unwrap();
    let volume: f64 = line.split("volume ").nth(1).unwrap().split(' ').next().unwrap().parse().unwrap();
    let op = &v["operations"][0];
    assert_eq!((op["op"].as_str(), u(op, "triangles"), f(op, "volume")), (Some("union"), triangles, volume));
    // "union volume V exact (± E; written, rounded to f64: W)": the exact result's volume,
    // which for solids this thick differs from the written file's only in the last digits.
    let line = text.lines().find(|l| l.starts_with("union volume ")).unwrap();
    let exact: f64 = line.split(' ').nth(2).unwrap().parse().unwrap();
    assert_eq!((f(op, "exact_volume"), f(op, "exact_volume_error") < 1e-15 * exact), (exact, true), "{v}");
    assert!((exact - volume).abs() <= 1e-12 * volume, "{exact} vs {volume}");
    assert!(v["stats"]["refinement"]["candidate_pairs"].is_u64(), "{v}");
    assert!(v["stats"]["classification"]["point_tests"].is_u64(), "{v}");
    assert!(v["time"]["total_ms"].is_f64(), "{v}");
    // csg: the same operation as an expression.
    let cargs = ["csg", "a | b", "a=builtin:cube", "b=builtin:sphere@translate 0.5 0.5 0.5", "-o", &out];
    let c = json(&cargs);
    assert_eq!((u(&c, "triangles"), f(&c, "volume"), f(&c, "exact_volume")), (triangles, volume, exact));
}

#[test]
fn info_json_names_the_text_device() {
    let text = stdout(&run(&["info"]));
    let v = json(&["info"]);
    let name = &v["device"]["name"];
    assert!(field(&text, "device:").starts_with(name.as_str().unwrap()), "{v} {text}");
    assert!(v["device"]["max_image_3d"].is_u64() && v["device"]["logic_op"].is_boolean(), "{v}");
    assert!(v["validation"].is_boolean());
    let all = json(&["info", "--all"]);
    assert!(all["devices"].as_array().unwrap().iter().any(|d| d["name"] == *name), "{all}");
}

#[test]
fn every_output_is_spelled_dash_o_or_output() {
    for cmd in
        [&["demo"][..], &["reproduce"], &["bench", "reduce"], &["voxelize"], &["inclusion"], &["subdivide"]]
    {
        let help = stdout(&run(&[cmd, &["--help"][..]].concat()));
        assert!(help.contains("-o, --output"), "{cmd:?}: {help}");
        assert!(!help.contains("--out "), "{cmd:?}: the old spelling is a hidden alias: {help}");
    }
    // The old spelling still works.
    let o = texgeo(&["reproduce", "--out", "/nonexistent-dir/x", "--only", "nothing"]);
    assert!(!stderr(&o).contains("unexpected argument '--out'"), "{}", stderr(&o));
}
