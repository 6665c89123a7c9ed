//! The `texgeo` command line: output, exit status 2 with one clear message on errors.

mod common;

use common::{TempDir, assert_refused, stderr, stdout, texgeo, texgeo_in_shell};

#[test]
fn info_names_the_device_and_logic_op() {
    let o = texgeo(&["info"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let out = stdout(&o);
    assert!(out.contains("device: "), "{out}");
    assert!(out.contains("logicOp: yes"), "{out}");
}

#[test]
fn mesh_stats_and_convert() {
    let o = texgeo(&["mesh", "stats", "builtin:cube"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let out = stdout(&o);
    assert!(out.contains("closed: yes, oriented: yes, manifold: yes"), "{out}");
    assert!(out.contains("Euler characteristic   2"), "{out}");
    assert!(out.contains("area                   24"), "{out}");
    let dir = TempDir::new("cli-stats");
    let obj = dir.join("knot.obj");
    let o = texgeo(&["mesh", "convert", "builtin:knot", obj.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let o = texgeo(&["mesh", "stats", obj.to_str().unwrap()]);
    assert!(stdout(&o).contains("1200 (1200×3-gon)"), "{}", stdout(&o));
    // -o/--output as every command spells it; the positional form above still works.
    for flag in ["-o", "--output"] {
        let off = dir.join(&format!("cube{flag}.off"));
        let o = texgeo(&["mesh", "convert", "builtin:cube", flag, off.to_str().unwrap()]);
        assert!(o.status.success(), "{flag}: {}", stderr(&o));
        assert!(std::fs::read_to_string(&off).unwrap().starts_with("OFF"), "{flag}");
    }
    let o = texgeo(&["mesh", "convert", "builtin:cube"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("--output"), "{}", stderr(&o));
    let (a, b) = (dir.join("a.off"), dir.join("b.off"));
    let o = texgeo(&["mesh", "convert", "builtin:cube", a.to_str().unwrap(), "-o", b.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2), "two outputs are refused");
    assert!(!a.exists() && !b.exists());
}

#[test]
fn errors_exit_2_with_one_message() {
    let dir = TempDir::new("cli-errors");
    let bad = dir.join("bad.off");
    std::fs::write(&bad, "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n").unwrap();
    for (args, needle) in [
        (vec!["mesh", "stats", "no/such/file.off"], "no/such/file.off"),
        (vec!["mesh", "stats", bad.to_str().unwrap()], "bad.off:6: vertex index 7 is out of range"),
        (vec!["mesh", "stats", "builtin:nothing"], "no built-in model 'nothing'"),
        (vec!["mesh", "stats", "model.xyz"], "unknown mesh format"),
        (
            vec!["inclusion", "builtin:cube", "--random", "10", "--method", "magic"],
            "invalid value 'magic' for '--method <METHOD>' [possible values: auto, cpu, bvh",
        ),
    ] {
        assert_refused(&texgeo(&args), &[needle]);
    }
    // clap's own usage errors: status 2, one line too.
    assert_refused(&texgeo(&["inclusion"]), &["--points <FILE>"]);
}

/// A point file larger than one read block (4 MiB) is read, classified and written a
/// block at a time: the same labels as the same points read whole from `.npy` by another
/// method; a bad line late in it is an error with its line number and leaves no file.
#[test]
fn inclusion_streams_a_large_point_file() {
    let dir = TempDir::new("cli-inclusion-blocks");
    let knot = texgeo::mesh::procedural::by_name("knot").unwrap();
    let (lo, hi) = knot.bounds();
    let pts = texgeo::random::Rng::new(21).points_in_box(160_000, lo - (hi - lo) * 0.1, hi + (hi - lo) * 0.1);
    let mut text = String::from("# many points\n");
    for (i, p) in pts.iter().enumerate() {
        text.push_str(&format!("{} {} {}{}\n", p.x, p.y, p.z, if i % 5000 == 0 { " # mark" } else { "" }));
    }
    assert!(text.len() > 8 << 20, "{} bytes: not more than one block", text.len());
    let (txt, npy) = (dir.join("p.txt"), dir.join("p.npy"));
    std::fs::write(&txt, &text).unwrap();
    let mut bytes = Vec::new();
    texgeo::inclusion::points::write_npy(&mut bytes, &pts).unwrap();
    std::fs::write(&npy, bytes).unwrap();
    let run = |points: &str, method: &str, out: &str| {
        let o = texgeo(&["inclusion", "builtin:knot", "--points", points, "--method", method, "-o", out]);
        assert!(o.status.success(), "{method}: {}", stderr(&o));
        std::fs::read_to_string(out).unwrap()
    };
    let streamed = run(&dir.arg("p.txt"), "auto", &dir.arg("a.txt"));
    let whole = run(&dir.arg("p.npy"), "bvh", &dir.arg("b.txt"));
    assert_eq!(streamed.lines().count(), 160_000);
    assert!(streamed == whole, "the streamed labels differ from the whole file's");
    // From a pipe (no length to size the reads by): the same labels.
    let o = texgeo_in_shell(
        &format!("cat '{}' |", dir.arg("p.txt")),
        &["inclusion", "builtin:knot", "--points", "/dev/stdin", "-o", &dir.arg("d.txt")],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(std::fs::read_to_string(dir.join("d.txt")).unwrap() == whole, "labels read from a pipe differ");
    assert!(streamed.contains("1\n") && streamed.contains("0\n"));
    text.push_str("1 2\n");
    std::fs::write(&txt, &text).unwrap();
    let o = texgeo(&["inclusion", "builtin:knot", "--points", &dir.arg("p.txt"), "-o", &dir.arg("c.txt")]);
    // (After the line saying which method `auto` picked: the error is found in a later block.)
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    let last = err.trim_end().lines().last().unwrap_or("");
    assert!(last.starts_with("texgeo: error: ") && last.contains("p.txt:160002: expected 'x y z'"), "{err}");
    assert!(!dir.join("c.txt").exists());
}

#[test]
fn inclusion_writes_one_class_per_point() {
    let dir = TempDir::new("cli-inclusion");
    let pts = dir.join("points.txt");
    std::fs::write(&pts, "# x y z\n0 0 0\n2 0 0\n1 0 0\n0.5 0.5 -0.5\n").unwrap();
    let out = dir.join("classes.txt");
    for method in ["cpu", "tetragrid", "gpu", "cpu+gpu", "gpu+tetragrid", "jordan", "winding"] {
        let o = texgeo(&[
            "inclusion",
            "builtin:cube",
            "--points",
            pts.to_str().unwrap(),
            "--method",
            method,
            "-o",
            out.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{method}: {}", stderr(&o));
        assert_eq!(std::fs::read_to_string(&out).unwrap(), "1\n0\n2\n1\n", "{method}");
    }
    let o = texgeo(&["inclusion", "builtin:knot", "--random", "500", "--method", "gpu"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stdout(&o).contains("500 points"), "{}", stdout(&o));
}

#[test]
fn open_meshes_are_refused_unless_allowed() {
    let dir = TempDir::new("cli-open");
    let open = dir.join("open.off");
    std::fs::write(&open, "OFF\n4 3 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n").unwrap();
    let o = texgeo(&["inclusion", open.to_str().unwrap(), "--random", "10", "--method", "cpu"]);
    assert_refused(&o, &["not closed", "--allow-open"]);
    let o = texgeo(&[
        "inclusion",
        open.to_str().unwrap(),
        "--random",
        "10",
        "--method",
        "winding",
        "--allow-open",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stderr(&o).contains("warning"), "{}", stderr(&o));
}

#[test]
fn voxelize_writes_binvox_slices_and_aspect() {
    let dir = TempDir::new("cli-voxelize");
    let out = dir.join("knot.binvox");
    let slices = dir.join("knot-slices");
    let aspect = dir.join("knot-aspect");
    let o = texgeo(&[
        "voxelize",
        "builtin:knot",
        "--res",
        "24",
        "--method",
        "pgpu",
        "-o",
        out.to_str().unwrap(),
        "--slices",
        slices.to_str().unwrap(),
        "--aspect",
        "perlin",
        "--aspect-out",
        aspect.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stdout(&o).contains("occupied"), "{}", stdout(&o));
    let (grid, volume) = texgeo::voxel::binvox::read(&out).unwrap();
    assert_eq!(grid.n, 24);
    let expected = texgeo::voxel::voxelize(
        None,
        &texgeo::mesh::procedural::torus_knot(),
        24,
        texgeo::voxel::Method::Cpu,
    )
    .unwrap();
    assert_eq!(volume, expected.volume);
    assert_eq!(std::fs::read_dir(&slices).unwrap().count(), 24);
    assert!(aspect.join("front.png").exists());
    // Too large a grid, an open mesh, an unknown method: one message, status 2.
    let x = dir.arg("x.binvox");
    for (args, expect) in [
        (vec!["voxelize", "builtin:cube", "--res", "5000", "-o", &x], "1024"),
        (
            vec!["voxelize", "builtin:cube", "--res", "8", "--method", "magic", "-o", &x],
            "no method 'magic' (auto, cpu, fgpu",
        ),
    ] {
        assert_refused(&texgeo(&args), &[expect]);
    }
}

#[test]
fn voxelize_defaults_to_auto_which_names_its_pick_and_gives_the_exact_voxels() {
    let dir = TempDir::new("cli-voxelize-auto");
    let auto = dir.arg("auto.binvox");
    let o = texgeo(&["voxelize", "builtin:knot", "--res", "40", "-o", &auto]);
    assert!(o.status.success(), "{}", stderr(&o));
    let err = stderr(&o);
    let line = err.lines().find(|l| l.contains("--method auto: ")).unwrap_or_else(|| panic!("{err}"));
    let picked = line.split("--method auto: ").nth(1).unwrap().split(' ').next().unwrap();
    assert!(texgeo::choice::parse::<texgeo::voxel::Method>(picked).is_some(), "{line}");
    assert!(stdout(&o).contains(&format!("method {picked} in")), "{}", stdout(&o));
    let auto = std::fs::read(&auto).unwrap();
    for method in ["scanline", "cpu", "fang", "auto"] {
        let out = dir.arg(&format!("{method}.binvox"));
        let o = texgeo(&["voxelize", "builtin:knot", "--res", "40", "--method", method, "-o", &out]);
        assert!(o.status.success(), "{method}: {}", stderr(&o));
        assert!(std::fs::read(&out).unwrap() == auto, "{method} differs from auto");
    }
}

#[test]
fn the_pipeline_cache_is_kept_in_the_cache_folder_and_survives_a_corrupt_file() {
    let dir = TempDir::new("cli-pipeline-cache");
    let out = dir.arg("x.binvox");
    let run = |cache: &str| {
        std::process::Command::new(env!("CARGO_BIN_EXE_texgeo"))
            .args(["voxelize", "builtin:cube", "--res", "8", "--method", "zoned", "-o", &out])
            .env("TEXGEO_CACHE_DIR", dir.join("cache"))
            .env("TEXGEO_CACHE", cache)
            .output()
            .unwrap()
    };
    let folder = dir.join("cache").join("pipelines-v2");
    let o = run("off");
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(!folder.exists(), "TEXGEO_CACHE=off wrote {}", folder.display());
    let o = run("on");
    assert!(o.status.success(), "{}", stderr(&o));
    let files: Vec<_> = std::fs::read_dir(&folder).unwrap().map(|e| e.unwrap().path()).collect();
    assert_eq!(files.len(), 1, "{files:?}");
    let good = std::fs::read(&files[0]).unwrap();
    assert!(good.starts_with(b"texgeo cache 1\n") && good.len() >= 15 + 72 + 32, "{good:?}");
    // Torn or overwritten with garbage: ignored, and replaced by a whole file.
    for bad in [&good[..good.len() - 3], b"garbage".as_slice()] {
        std::fs::write(&files[0], bad).unwrap();
        let o = run("on");
        assert!(o.status.success(), "{}", stderr(&o));
        let again = std::fs::read(&files[0]).unwrap();
        assert!(again.starts_with(b"texgeo cache 1\n") && again.len() >= 15 + 72 + 32, "{again:?}");
    }
    assert_eq!(std::fs::read_dir(&folder).unwrap().count(), 1, "temporary files left");
}

#[test]
fn numeric_options_must_be_finite_and_positive() {
    let dir = TempDir::new("cli-numbers");
    let out = dir.arg("x.binvox");
    for (args, needle) in [
        (vec!["voxelize", "builtin:cube", "--res", "8", "-o", &out, "--frequency", "nan"], "--frequency"),
        (vec!["voxelize", "builtin:cube", "--res", "8", "-o", &out, "--frequency", "inf"], "--frequency"),
        (vec!["voxelize", "builtin:cube", "--res", "8", "-o", &out, "--frequency", "0"], "--frequency"),
        (vec!["voxelize", "builtin:cube", "--res", "0", "-o", &out], "resolution 0"),
        (vec!["voxelize", "builtin:cube", "--res", "8", "-o", &out, "--zone", "0"], "--zone"),
        (vec!["inclusion", "builtin:cube", "--random", "0"], "--random"),
        (vec!["inclusion", "builtin:cube", "--random", "10", "--batch", "0"], "--batch"),
        (vec!["bench", "xor", "--runs", "0"], "--runs"),
        (vec!["bench", "inclusion", "--sets", "0"], "--sets"),
    ] {
        assert_refused(&texgeo(&args), &[needle]);
    }
    assert!(!dir.join("x.binvox").exists());
    // `--zone auto` and a number are both fine.
    for zone in ["auto", "5"] {
        let o = texgeo(&[
            "voxelize",
            "builtin:cube",
            "--res",
            "8",
            "--method",
            "zoned",
            "--zone",
            zone,
            "-o",
            &out,
        ]);
        assert!(o.status.success(), "{zone}: {}", stderr(&o));
    }
}

#[test]
fn file_errors_say_the_os_error_once() {
    let o = texgeo(&["voxelize", "builtin:cube", "--res", "8", "-o", "/nonexistent/texgeo/x.binvox"]);
    assert_refused(&o, &["/nonexistent/texgeo/x.binvox"]);
    let o = texgeo(&["mesh", "stats", "/nonexistent/texgeo/m.off"]);
    assert_refused(&o, &["/nonexistent/texgeo/m.off: No such file or directory (os error 2)"]);
    assert_eq!(stderr(&o).matches("os error").count(), 1, "{}", stderr(&o));
}

#[test]
fn a_gpu_method_without_a_vulkan_driver_suggests_a_cpu_one() {
    // No ICD: the loader finds no driver.
    let run = |args: &[&str]| {
        std::process::Command::new(env!("CARGO_BIN_EXE_texgeo"))
            .args(args)
            .env("VK_DRIVER_FILES", "/nonexistent/texgeo-icd.json")
            .env("VK_ICD_FILENAMES", "/nonexistent/texgeo-icd.json")
            .env_remove("TEXGEO_VALIDATION")
            .env_remove("TEXGEO_REQUIRE_VALIDATION")
            .output()
            .unwrap()
    };
    let dir = TempDir::new("cli-nodriver");
    let out = dir.arg("x.binvox");
    assert_refused(
        &run(&["inclusion", "builtin:cube", "--random", "10", "--method", "gpu"]),
        &["--method cpu"],
    );
    assert_refused(
        &run(&["voxelize", "builtin:cube", "--res", "8", "--method", "pgpu", "-o", &out]),
        &["--method cpu"],
    );
    assert_refused(&run(&["subdivide", "builtin:cube", "-l", "2", "--method", "gpu"]), &["--method cpu"]);
    // The CPU methods do not need it.
    let o = run(&["inclusion", "builtin:cube", "--random", "10", "--method", "cpu"]);
    assert!(o.status.success(), "{}", stderr(&o));
}

#[test]
fn coordinates_whose_area_or_volume_overflow_are_refused() {
    let dir = TempDir::new("cli-huge");
    let huge = dir.join("huge.off");
    let m = texgeo::mesh::procedural::cube().map_positions(|p| p * 1e200).unwrap();
    texgeo::mesh::formats::write(&huge, &m).unwrap();
    let huge = huge.to_str().unwrap();
    let out = dir.arg("x.binvox");
    for args in [
        vec!["mesh", "stats", huge],
        vec!["inclusion", huge, "--random", "10", "--method", "cpu"],
        vec!["voxelize", huge, "--res", "8", "--method", "cpu", "-o", &out],
    ] {
        assert_refused(&texgeo(&args), &["overflows f64", "1e200"]);
    }
    // 10⁸⁰: the volume is 8·10²⁴⁰, which f64 holds: measured, not refused.
    let big = dir.join("big.off");
    let m = texgeo::mesh::procedural::cube().map_positions(|p| p * 1e80).unwrap();
    texgeo::mesh::formats::write(&big, &m).unwrap();
    let big = big.to_str().unwrap();
    let o = texgeo(&["mesh", "stats", big]);
    assert!(o.status.success(), "{}", stderr(&o));
    let (v, want) = (number_after(&stdout(&o), "volume"), 8.0 * 1e80f64.powi(3));
    assert!((v - want).abs() <= 1e-12 * want, "{v}");
    for args in [
        vec!["inclusion", big, "--random", "10", "--method", "cpu"],
        vec!["voxelize", big, "--res", "8", "--method", "cpu", "-o", &out],
    ] {
        let o = texgeo(&args);
        assert!(o.status.success(), "{args:?}: {}", stderr(&o));
    }
}

/// `builtin:cube` scaled by `s`, written to `dir/name`.
fn scaled_cube(dir: &TempDir, name: &str, s: f64) -> String {
    let path = dir.join(name);
    let m = texgeo::mesh::procedural::cube().map_positions(|p| p * s).unwrap();
    texgeo::mesh::formats::write(&path, &m).unwrap();
    path.to_str().unwrap().to_string()
}

/// Tiny coordinates: the cube scaled by 2⁻³⁰⁰ (products of coordinates 2⁻⁹⁰⁰) and by
/// 10⁻¹⁴⁰ (products underflow f64) gets the unit cube's labels at the points scaled the
/// same way, from every inclusion method, and the unit cube's voxels.
#[test]
fn tiny_meshes_get_the_unit_meshes_answers() {
    let dir = TempDir::new("cli-tiny");
    let steps = [-1.5, -1.0, -0.5, 0.0, 0.25, 1.0, 1.5];
    let mut grid: Vec<[f64; 3]> = Vec::new();
    for x in steps {
        for y in steps {
            for z in steps {
                grid.push([x, y, z]);
            }
        }
    }
    let points = |name: &str, s: f64| {
        let path = dir.join(name);
        let text: String =
            grid.iter().map(|p| format!("{:e} {:e} {:e}\n", p[0] * s, p[1] * s, p[2] * s)).collect();
        std::fs::write(&path, text).unwrap();
        path.to_str().unwrap().to_string()
    };
    let labels = |mesh: &str, pts: &str, method: &str| {
        let out = dir.join("labels.txt");
        let o =
            texgeo(&["inclusion", mesh, "--points", pts, "--method", method, "-o", out.to_str().unwrap()]);
        assert!(o.status.success(), "{method} {mesh}: {}", stderr(&o));
        std::fs::read_to_string(&out).unwrap()
    };
    let unit_points = points("unit.txt", 1.0);
    let scales = [2f64.powi(-300), 1e-140];
    let cases: Vec<(String, String)> = scales
        .iter()
        .enumerate()
        .map(|(i, &s)| (scaled_cube(&dir, &format!("tiny{i}.off"), s), points(&format!("tiny{i}.txt"), s)))
        .collect();
    for method in [
        "auto",
        "cpu",
        "bvh",
        "octants",
        "tetragrid",
        "jordan",
        "jordan-octree",
        "winding",
        "voxel-space",
        "gpu",
        "cpu+gpu",
        "gpu+tetragrid",
    ] {
        let want = labels("builtin:cube", &unit_points, method);
        // The centre is inside, a far corner outside: the unit cube's answer is right.
        let lines: Vec<&str> = want.lines().collect();
        assert_eq!(lines.len(), grid.len());
        assert_ne!(lines[grid.iter().position(|p| *p == [0.0; 3]).unwrap()], lines[0], "{method}");
        for (mesh, pts) in &cases {
            assert_eq!(labels(mesh, pts, method), want, "{method} on {mesh}");
        }
    }
    // Voxels: the same bytes after the header, whose cube is the unit one's scaled.
    let binvox = |mesh: &str, method: &str| {
        let out = dir.join("v.binvox");
        let o = texgeo(&["voxelize", mesh, "--res", "16", "--method", method, "-o", out.to_str().unwrap()]);
        assert!(o.status.success(), "{method} {mesh}: {}", stderr(&o));
        let bytes = std::fs::read(&out).unwrap();
        let at = bytes.windows(5).position(|w| w == b"data\n").unwrap() + 5;
        let header = String::from_utf8(bytes[..at].to_vec()).unwrap();
        (number_after(&header, "scale"), bytes[at..].to_vec())
    };
    for method in ["cpu", "scanline", "auto", "fgpu"] {
        let (side, want) = binvox("builtin:cube", method);
        for ((mesh, _), s) in cases.iter().zip(scales) {
            let (tiny_side, got) = binvox(mesh, method);
            assert_eq!(got, want, "{method} on {mesh}");
            assert_eq!(tiny_side, side * s, "{method} on {mesh}");
        }
    }
}

/// The number after `label` on the line of `text` that has it.
fn number_after(text: &str, label: &str) -> f64 {
    let line = text.lines().find(|l| l.contains(label)).unwrap_or_else(|| panic!("no {label:?} in {text}"));
    let rest = &line[line.find(label).unwrap() + label.len()..];
    rest.split_whitespace().next().unwrap().trim_end_matches(',').parse().unwrap_or_else(|_| panic!("{line}"))
}

/// Volumes far from the origin: a cube at 10⁷ and its copy turned 90° about z (exactly:
/// the coordinates are swapped), two shells 10⁷ apart, volume 16; and the union of the
/// cube with its copy turned 10° about the origin, the sum of their volumes.
#[test]
fn volumes_far_from_the_origin_are_exact() {
    let dir = TempDir::new("cli-far");
    let cube = texgeo::mesh::procedural::cube();
    let far = cube.map_positions(|p| p + glam::DVec3::new(1e7, 0.0, 0.0)).unwrap();
    let turned = far.map_positions(|p| glam::DVec3::new(-p.y, p.x, p.z)).unwrap();
    let (mut positions, mut faces) = (far.positions().to_vec(), Vec::new());
    positions.extend_from_slice(turned.positions());
    for f in far.faces() {
        faces.push(f.to_vec());
        faces.push(f.iter().map(|&i| i + 8).collect());
    }
    let both = texgeo::mesh::Mesh::new(positions, faces).unwrap();
    let both_path = dir.join("both.off");
    texgeo::mesh::formats::write(&both_path, &both).unwrap();
    let o = texgeo(&["mesh", "stats", both_path.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v = number_after(&stdout(&o), "volume");
    assert!((v - 16.0).abs() <= 1e-12 * 16.0, "{v}");

    let far_path = dir.join("far.off");
    texgeo::mesh::formats::write(&far_path, &far).unwrap();
    let far_path = far_path.to_str().unwrap();
    let out = dir.join("union.off");
    let o = texgeo(&[
        "boolean",
        far_path,
        far_path,
        "--op",
        "union",
        "--transform-b",
        "rotate y 10",
        "--method",
        "cpu",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    // The turned copy lies 1.7·10⁶ away: the union is both cubes, 8 + the copy's volume
    // (8 up to the rounding of its turned coordinates, ~10⁻⁹).
    let copy = texgeo::boolean::Transform::parse("rotate y 10").unwrap().apply(&far).unwrap();
    let want = 8.0 + texgeo::mesh::covering::measures(&copy).0;
    assert!((want - 16.0).abs() < 1e-7, "{want}");
    let v = number_after(&stdout(&o), "volume");
    assert!((v - want).abs() <= 1e-12 * want, "{v} vs {want}");
    let o = texgeo(&["mesh", "stats", out.to_str().unwrap()]);
    let w = number_after(&stdout(&o), "volume");
    assert!((w - want).abs() <= 1e-12 * want, "{w} vs {want}");
    // Two small solids far apart are not flat: the result is an operand again.
    let again = dir.join("again.off");
    let o = texgeo(&[
        "boolean",
        out.to_str().unwrap(),
        far_path,
        "--op",
        "union",
        "--method",
        "cpu",
        "-o",
        again.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v = number_after(&stdout(&o), "volume");
    assert!((v - want).abs() <= 1e-12 * want, "{v} vs {want}");
}

#[test]
fn sizes_that_do_not_fit_are_refused_before_any_work() {
    // Far more than any machine has: refused at once, with the estimate.
    let o = texgeo(&[
        "inclusion",
        "builtin:cube",
        "--random",
        "100000000000000",
        "--method",
        "cpu",
        "-o",
        "/tmp/x.txt",
    ]);
    assert_refused(&o, &["100000000000000 points", "MiB", "of text"]);
    let o = texgeo(&["subdivide", "builtin:knot", "-l", "10", "--method", "cpu", "-o", "/tmp/x.obj"]);
    assert_refused(&o, &["level 10", "MiB", "/tmp/x.obj would be about"]);
    assert!(!stdout(&o).contains("CPU reference"), "{}", stdout(&o));
    let o = texgeo(&["subdivide", "builtin:cube", "-l", "40", "--method", "gpu"]);
    assert_refused(&o, &["level 40", "32-bit"]);
    assert!(!stdout(&o).contains("device"), "{}", stdout(&o));
    let o = texgeo(&["voxelize", "builtin:cube", "--res", "100000", "-o", "/tmp/x.binvox"]);
    assert_refused(&o, &["resolution 100000", "1024"]);
}

#[test]
fn thread_counts_above_the_cap_are_refused() {
    for n in ["1025", "100000", "9223372036854775808", "0"] {
        let o = texgeo(&["--threads", n, "mesh", "builtins"]);
        assert_refused(&o, &["--threads"]);
    }
    let o = texgeo(&["--threads", "3", "mesh", "stats", "builtin:cube"]);
    assert!(o.status.success(), "{}", stderr(&o));
}

#[test]
fn option_values_that_would_overflow_are_refused_up_front() {
    let dir = TempDir::new("cli-overflow");
    let out = dir.arg("bench");
    for (args, needles) in [
        (
            vec!["sweep", "m.txt", "--task", "inclusion", "-o", &out, "--timeout", "1e20"],
            vec!["--timeout", "1e20"],
        ),
        (vec!["sweep", "m.txt", "--task", "inclusion", "-o", &out, "--timeout", "nan"], vec!["--timeout"]),
        (vec!["bench", "scale", "--budget", "1e30", "-o", &out], vec!["--budget"]),
        (
            vec!["bench", "xor", "--triangles", "18446744073709551615", "-o", &out],
            vec!["at most 1431655765 triangles"],
        ),
        (vec!["bench", "xor", "--triangles", "1000000000", "-o", &out], vec!["1000000000 triangles", "MiB"]),
        (
            vec!["bench", "inclusion", "--points", "18446744073709551615", "-o", &out],
            vec!["more than", "MiB"],
        ),
        (vec!["bench", "scale", "--points", "100000000000", "-o", &out], vec!["100000000000 points", "MiB"]),
        (vec!["bench", "boolean", "--scaling", "100000000000", "-o", &out], vec!["--scaling 100000000000"]),
        (
            vec!["bench", "boolean", "--scaling", "2000000000", "-o", &out],
            vec!["--scaling 2000000000", "MiB"],
        ),
        (
            vec!["voxelize", "builtin:cube", "--res", "9223372036854775808", "-o", "a.binvox"],
            vec!["more than"],
        ),
        (
            vec!["subdivide", "builtin:cube", "-l", "4000000000"],
            vec!["more than 18446744073709551615 vertices"],
        ),
    ] {
        let started = std::time::Instant::now();
        let o = texgeo(&args);
        assert_refused(&o, &needles);
        assert!(!stderr(&o).contains(" 0 MiB"), "{args:?}: {}", stderr(&o));
        // Refused from the numbers, not after trying (a generous bound on a loaded machine).
        assert!(started.elapsed().as_secs() < 60, "{args:?}");
    }
    // Levels past 2^64 faces are "more than", not a count that stopped or wrapped.
    let a = stderr(&texgeo(&["subdivide", "builtin:cube", "-l", "32"]));
    let b = stderr(&texgeo(&["subdivide", "builtin:cube", "-l", "64"]));
    assert!(a.contains("more than") && b.contains("more than"), "{a}{b}");
}

#[test]
fn mesh_paths_need_not_be_utf8() {
    use std::os::unix::ffi::OsStrExt as _;
    let dir = TempDir::new("cli-os-path");
    let path = dir.path().join(std::ffi::OsStr::from_bytes(b"t\xffe.off"));
    assert!(texgeo(&["mesh", "convert", "builtin:tetrahedron", dir.arg("t.off").as_str()]).status.success());
    std::fs::rename(dir.join("t.off"), &path).unwrap();
    for (before, after) in [(&["mesh", "stats"][..], &[][..]), (&["inclusion"][..], &["--random", "10"][..])]
    {
        let o = std::process::Command::new(env!("CARGO_BIN_EXE_texgeo"))
            .args(before)
            .arg(&path)
            .args(after)
            .output()
            .unwrap();
        assert!(o.status.success(), "{before:?}: {}", stderr(&o));
        assert!(stdout(&o).contains("t\u{fffd}e.off"), "{}", stdout(&o));
    }
}

#[test]
fn an_empty_mesh_is_a_solid_that_holds_nothing() {
    let dir = TempDir::new("cli-empty");
    std::fs::write(dir.join("empty.off"), "OFF\n0 0 0\n").unwrap();
    let empty = dir.arg("empty.off");
    let o = texgeo(&["mesh", "stats", &empty]);
    assert!(o.status.success(), "{}", stderr(&o));
    let out = stdout(&o);
    for needle in [
        "faces                  0",
        "volume                 0 ",
        "area                   0\n",
        "solid: yes (empty)",
    ] {
        assert!(out.contains(needle), "'{needle}' in {out}");
    }
    for method in ["auto", "cpu", "bvh", "jordan", "winding", "gpu"] {
        let labels = dir.arg(&format!("{method}.txt"));
        let o = texgeo(&["inclusion", &empty, "--random", "20", "--method", method, "-o", &labels]);
        assert!(o.status.success(), "{method}: {}", stderr(&o));
        assert_eq!(std::fs::read_to_string(&labels).unwrap(), "0\n".repeat(20), "{method}");
    }
    for method in ["scanline", "cpu", "zoned"] {
        let out = dir.join(&format!("{method}.binvox"));
        let o = texgeo(&["voxelize", &empty, "--res", "8", "--method", method, "-o", out.to_str().unwrap()]);
        assert!(o.status.success(), "{method}: {}", stderr(&o));
        assert!(stdout(&o).contains("8³ voxels, 0 occupied"), "{method}: {}", stdout(&o));
        let (_, volume) = texgeo::voxel::binvox::read(&out).unwrap();
        assert_eq!(volume.count(), 0);
    }
}

#[test]
fn an_all_holes_subdivision_is_written_readable_and_validates() {
    let dir = TempDir::new("cli-holes");
    let cube = dir.join("cube.obj");
    assert!(texgeo(&["mesh", "convert", "builtin:cube", cube.to_str().unwrap()]).status.success());
    let mut text = std::fs::read_to_string(&cube).unwrap();
    text.push_str("t hole 6/0/0 0 1 2 3 4 5\n");
    std::fs::write(&cube, text).unwrap();
    for ext in ["obj", "off"] {
        let out = dir.arg(&format!("out.{ext}"));
        // --validate reads OpenSubdiv's result, a file without faces, back too.
        let o = texgeo(&[
            "subdivide",
            cube.to_str().unwrap(),
            "-l",
            "1",
            "--method",
            "cpu",
            "--validate",
            "-o",
            &out,
        ]);
        assert!(o.status.success(), "{ext}: {}{}", stdout(&o), stderr(&o));
        assert!(
            stdout(&o).contains("level 1: ") && stdout(&o).contains("validation passed"),
            "{}",
            stdout(&o)
        );
        let o = texgeo(&["mesh", "stats", &out]);
        assert!(o.status.success(), "{ext}: {}", stderr(&o));
        assert!(stdout(&o).contains("faces                  0") && stdout(&o).contains("solid: yes (empty)"));
    }
}
