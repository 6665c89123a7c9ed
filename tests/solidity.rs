//! One meaning of "inside" across commands: `mesh stats` reports what
//! keeps a mesh from being a solid, and `inclusion` and `voxelize` refuse it with status 2
//! and the reason — or, with `--flip-inverted`, answer for the flipped solid exactly as
//! for a well-oriented one. `--allow-open` means "inside iff the generalized winding number
//! is at least ½" for any mesh that is not a solid, by every CPU method.

mod common;

use common::shapes::union;
use common::{TempDir, assert_refused, stderr, stdout, texgeo};
use glam::DVec3;
use texgeo::mesh::procedural::{self, box_between};
use texgeo::mesh::solidity::flipped;
use texgeo::mesh::{Mesh, formats};

fn save(dir: &TempDir, name: &str, mesh: &Mesh) -> String {
    let path = dir.join(name);
    formats::write(&path, mesh).unwrap();
    path.to_string_lossy().into_owned()
}

/// A cube inside a bigger cube, both facing outwards: winding number 2 inside the small one.
fn nested() -> Mesh {
    union(&[box_between(DVec3::splat(-2.0), DVec3::splat(2.0)), procedural::cube()])
}

#[test]
fn mesh_stats_reports_shells_and_what_is_wrong() {
    let dir = TempDir::new("solidity-stats");
    let o = texgeo(&["mesh", "stats", "builtin:cavity"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stdout(&o).contains("shells                 2 (1 cavity)"), "{}", stdout(&o));
    assert!(stdout(&o).contains("solid: yes"), "{}", stdout(&o));
    for (name, mesh, needle) in [
        (
            "nested.off",
            nested(),
            "solid: no: shell 1 (the shell of face 6) lies inside shell 0 and faces the same way",
        ),
        ("inverted.off", flipped(&procedural::cube()), "solid: no: the solid is inverted"),
    ] {
        let file = save(&dir, name, &mesh);
        let o = texgeo(&["mesh", "stats", &file]);
        assert!(o.status.success(), "{name}: {}", stderr(&o));
        assert!(stdout(&o).contains(needle), "{name}: {}", stdout(&o));
    }
}

#[test]
fn inclusion_and_voxelize_refuse_what_is_not_a_solid() {
    let dir = TempDir::new("solidity-refuse");
    let nested = save(&dir, "nested.off", &nested());
    let inverted = save(&dir, "inverted.off", &flipped(&procedural::cube()));
    let out = dir.arg("out.binvox");
    for method in ["cpu", "gpu", "jordan", "winding"] {
        let o = texgeo(&["inclusion", &nested, "--random", "20", "--method", method]);
        assert_refused(&o, &["not a solid", "lies inside shell 0", "winding number is 2"]);
        let o = texgeo(&["inclusion", &inverted, "--random", "20", "--method", method]);
        assert_refused(&o, &["the solid is inverted", "--flip-inverted"]);
    }
    for method in ["cpu", "zoned", "scanline"] {
        let o = texgeo(&["voxelize", &nested, "--res", "8", "--method", method, "-o", &out]);
        assert_refused(&o, &["lies inside shell 0"]);
        let o = texgeo(&["voxelize", &inverted, "--res", "8", "--method", method, "-o", &out]);
        assert_refused(&o, &["the solid is inverted", "--flip-inverted"]);
    }
    assert!(!dir.join("out.binvox").exists());
}

#[test]
fn flip_inverted_answers_for_the_flipped_solid() {
    let dir = TempDir::new("solidity-flip");
    let inverted = save(&dir, "inverted.off", &flipped(&procedural::cube()));
    let pts = dir.join("points.txt");
    std::fs::write(&pts, "0 0 0\n2 0 0\n1 0 0\n0.5 0.5 -0.5\n").unwrap();
    let classes = dir.arg("classes.txt");
    for method in ["cpu", "bvh", "gpu", "jordan", "winding"] {
        let o = texgeo(&[
            "inclusion",
            &inverted,
            "--points",
            pts.to_str().unwrap(),
            "--method",
            method,
            "--flip-inverted",
            "-o",
            &classes,
        ]);
        assert!(o.status.success(), "{method}: {}", stderr(&o));
        assert_eq!(std::fs::read_to_string(&classes).unwrap(), "1\n0\n2\n1\n", "{method}");
    }
    let (a, b) = (dir.arg("a.binvox"), dir.arg("b.binvox"));
    let o = texgeo(&["voxelize", &inverted, "--res", "12", "--method", "cpu", "--flip-inverted", "-o", &a]);
    assert!(o.status.success(), "{}", stderr(&o));
    let o = texgeo(&["voxelize", "builtin:cube", "--res", "12", "--method", "cpu", "-o", &b]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
}

#[test]
fn allow_open_means_the_generalized_winding_number() {
    let dir = TempDir::new("solidity-open");
    // The cube without its top (z = 1) face.
    let cube = procedural::cube();
    let open =
        Mesh::new(cube.positions().to_vec(), cube.faces().take(5).map(<[u32]>::to_vec).collect()).unwrap();
    let open = save(&dir, "open.off", &open);
    let pts = dir.join("points.txt");
    // Deep in the box (w ≈ 0.93), just above the missing face (w ≈ 0.45), far (w ≈ 0.03).
    std::fs::write(&pts, "0 0 -0.9\n0 0 1.1\n0 0 3\n").unwrap();
    let classes = dir.arg("classes.txt");
    let args = |method: &'static str| {
        vec![
            "inclusion",
            open.as_str(),
            "--points",
            pts.to_str().unwrap(),
            "--allow-open",
            "--method",
            method,
            "-o",
        ]
    };
    let mut a = args("winding");
    a.push(&classes);
    let o = texgeo(&a);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(std::fs::read_to_string(&classes).unwrap(), "1\n0\n0\n");
    // Every CPU method gives the same answers by the same rule; the GPU methods refuse.
    for method in ["cpu", "tetragrid", "jordan", "voxel-space", "auto"] {
        let mut a = args(method);
        a.push(&classes);
        let o = texgeo(&a);
        assert!(o.status.success(), "{method}: {}", stderr(&o));
        assert_eq!(std::fs::read_to_string(&classes).unwrap(), "1\n0\n0\n", "{method}");
        assert_eq!(stderr(&o).matches("warning").count(), 1, "{}", stderr(&o));
        assert!(stderr(&o).contains("not closed") && stderr(&o).contains("at least ½"), "{}", stderr(&o));
    }
    for method in ["gpu", "cpu+gpu", "gpu+tetragrid"] {
        let mut a = args(method);
        a.push(&classes);
        let o = texgeo(&a);
        assert_refused(&o, &["--allow-open", "solids only", "generalized winding number", "CPU"]);
    }
    // A closed mesh under --allow-open is classified by every method as usual.
    let o = texgeo(&["inclusion", "builtin:cube", "--random", "50", "--allow-open", "--method", "cpu"]);
    assert!(o.status.success(), "{}", stderr(&o));
}

#[test]
fn every_command_labels_a_valid_solid_the_same() {
    // The built-in solids: inclusion's classes at the voxel centres equal the voxels, for
    // centres off the boundary (which voxelize decides by its tie rule).
    use texgeo::inclusion::{Class, Method, Options, build};
    use texgeo::voxel::{self, Method as VoxelMethod};
    for name in ["cavity", "two-cubes", "l-prism", "torus"] {
        let mesh = procedural::by_name(name).unwrap();
        let vox = voxel::voxelize(None, &mesh, 10, VoxelMethod::Scanline).unwrap();
        let classifier = build(Method::Cpu, &mesh, &Options::default()).unwrap();
        let g = vox.grid;
        for j in 0..10 {
            for k in 0..10 {
                for i in 0..10 {
                    match classifier.classify(g.centre(i, j, k)) {
                        Class::OnBoundary => {}
                        c => assert_eq!(c == Class::Inside, vox.volume.get(i, j, k), "{name} ({i},{j},{k})"),
                    }
                }
            }
        }
    }
}
