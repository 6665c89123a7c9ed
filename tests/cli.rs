//! The `texgeo` command line: output, exit status 2 with one clear message on errors.

mod common;

use common::{TempDir, assert_refused, stderr, stdout, texgeo};

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
            "invalid value 'magic' for '--method <METHOD>' [possible values: cpu, bvh",
        ),
    ] {
        assert_refused(&texgeo(&args), &[needle]);
    }
    // clap's own usage errors: status 2, one line too.
    assert_refused(&texgeo(&["inclusion"]), &["--points <FILE>"]);
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
            "[possible values: cpu, fgpu",
        ),
    ] {
        assert_refused(&texgeo(&args), &[expect]);
    }
}
