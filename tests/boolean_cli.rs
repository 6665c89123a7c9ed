//! `texgeo boolean`: outputs by extension, `--all`, `--stats`, `--transform-b`, and
//! refusals (open, inverted, inconsistent, self-intersecting, NaN, bad output) with
//! status 2, a message naming the operand and the reason, and no file written.

mod common;

use std::path::{Path, PathBuf};
use std::process::Output;
use std::sync::OnceLock;

use common::{stderr, stdout, texgeo};
use texgeo::mesh::covering::Covering;
use texgeo::mesh::formats;

/// `texgeo boolean A B --transform-b TRANSFORM --op OP -o OUT`.
fn boolean(a: &str, b: &str, transform: &str, op: &str, out: &Path) -> Output {
    texgeo(&["boolean", a, b, "--transform-b", transform, "--op", op, "-o", out.to_str().unwrap()])
}

/// `name` in one folder shared by the tests of this file.
fn temp(name: &str) -> PathBuf {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| common::fresh_dir("boolean-cli", "outputs")).join(name)
}

fn write(path: &Path, text: &str) -> String {
    std::fs::write(path, text).unwrap();
    path.to_str().unwrap().to_string()
}

fn volume(path: &Path) -> f64 {
    Covering::new(&formats::read(path).unwrap()).volume()
}

const CUBE_VERTICES: &str = "0 0 0\n1 0 0\n0 1 0\n1 1 0\n0 0 1\n1 0 1\n0 1 1\n1 1 1\n";

fn cube_off(faces: &[&str], vertices: &str) -> String {
    format!("OFF\n8 {} 0\n{vertices}{}\n", faces.len(), faces.join("\n"))
}

const FACES: [&str; 6] = ["4 0 4 6 2", "4 1 3 7 5", "4 0 1 5 4", "4 2 6 7 3", "4 0 2 3 1", "4 4 5 7 6"];

#[test]
fn one_operation_and_all_of_them() {
    let out = temp("union.obj");
    let o = texgeo(&[
        "boolean",
        "builtin:cube",
        "builtin:cube",
        "--transform-b",
        "translate 1 1 1",
        "--op",
        "union",
        "-o",
        out.to_str().unwrap(),
        "--stats",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    // Two 2×2×2 cubes overlapping in a unit cube.
    assert!((volume(&out) - 15.0).abs() < 1e-12, "{}", volume(&out));
    let text = stdout(&o);
    for want in [
        "A ∪ B",
        "candidate pairs",
        "point tests",
        "saved",
        "phase 1",
        "phase 2",
        "union volume 15 exact (± ",
    ] {
        assert!(text.contains(want), "{want}: {text}");
    }

    let dir = temp("all");
    let o = texgeo(&[
        "boolean",
        "builtin:sphere",
        "builtin:cube",
        "--transform-b",
        "scale 0.7; rotate 1 1 0 30",
        "--all",
        dir.to_str().unwrap(),
        "--format",
        "ply",
        "--pictures",
        dir.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: Vec<f64> = ["union", "intersection", "difference", "symmetric-difference"]
        .iter()
        .map(|op| volume(&dir.join(format!("{op}.ply"))))
        .collect();
    assert!((v[0] - v[1] - v[3]).abs() < 1e-9 * v[0], "{v:?}");
    // One Fig. 6-9 … 6-12 picture per operation, not one colour.
    for op in ["union", "intersection", "difference", "symmetric-difference"] {
        let p = texgeo::render::Picture::load_png(dir.join(format!("{op}.png"))).unwrap();
        assert_eq!((p.width, p.height), (800, 600), "{op}");
        assert!(p.rgba.chunks_exact(4).any(|c| c != &p.rgba[..4]), "{op}: one colour");
    }
}

#[test]
fn bad_operands_exit_2_and_write_nothing() {
    let open = write(&temp("open.off"), &cube_off(&FACES[1..], CUBE_VERTICES));
    let reversed: Vec<String> = FACES
        .iter()
        .map(|f| {
            let mut w: Vec<&str> = f.split(' ').collect();
            w[1..].reverse();
            w.join(" ")
        })
        .collect();
    let reversed: Vec<&str> = reversed.iter().map(String::as_str).collect();
    let inverted = write(&temp("inverted.off"), &cube_off(&reversed, CUBE_VERTICES));
    let mut mixed = FACES.to_vec();
    mixed[2] = reversed[2];
    let inconsistent = write(&temp("inconsistent.off"), &cube_off(&mixed, CUBE_VERTICES));
    let nan = write(&temp("nan.off"), &cube_off(&FACES, &CUBE_VERTICES.replace("1 1 1", "1 nan 1")));
    // Two overlapping cubes in one file.
    let two = format!(
        "OFF\n16 12 0\n{CUBE_VERTICES}{}\n{}\n{}\n",
        CUBE_VERTICES
            .lines()
            .map(|l| l
                .split(' ')
                .map(|x| (x.parse::<f64>().unwrap() + 0.5).to_string())
                .collect::<Vec<_>>()
                .join(" "))
            .collect::<Vec<_>>()
            .join("\n"),
        FACES.join("\n"),
        FACES
            .iter()
            .map(|f| {
                let mut w = f.split(' ');
                let n = w.next().unwrap();
                std::iter::once(n.to_string())
                    .chain(w.map(|i| (i.parse::<u32>().unwrap() + 8).to_string()))
                    .collect::<Vec<_>>()
                    .join(" ")
            })
            .collect::<Vec<_>>()
            .join("\n")
    );
    let crossing = write(&temp("crossing.off"), &two);
    let out = temp("never.off");
    for (file, reason) in [
        (&open, "open"),
        (&inverted, "inverted"),
        (&inconsistent, "consistently oriented"),
        (&crossing, "intersects itself"),
        (&nan, "not finite"),
    ] {
        let o = texgeo(&["boolean", "builtin:cube", file, "--op", "difference", "-o", out.to_str().unwrap()]);
        assert_eq!(o.status.code(), Some(2), "{file}: {}", stderr(&o));
        let e = stderr(&o);
        assert!(e.contains(file.as_str()) && e.to_lowercase().contains(reason), "{file}: {e}");
        assert_eq!(e.lines().count(), 1, "{e}");
        assert!(!out.exists(), "{file}: an output was written");
    }
    // Self-intersecting operands go through when asked (here B does not meet A).
    let o = texgeo(&[
        "boolean",
        "builtin:sphere",
        &crossing,
        "--transform-b",
        "translate 5 0 0",
        "--op",
        "difference",
        "--allow-self-intersections",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    std::fs::remove_file(&out).unwrap();
    // A bad output extension or transform is refused before any work.
    for args in [
        vec!["--op", "union", "-o", "out.xyz"],
        vec!["--op", "onion", "-o", "x.off"],
        vec!["--op", "union", "--transform-b", "twist 3", "-o", "x.off"],
    ] {
        let mut all = vec!["boolean", "builtin:cube", "builtin:cube"];
        all.extend(args);
        let o = texgeo(&all);
        assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    }
    assert!(!Path::new("x.off").exists() && !Path::new("out.xyz").exists());
}

#[test]
fn empty_results_are_written_in_every_format_and_read_back_as_operands() {
    let sphere_volume = {
        let out = temp("sphere.off");
        assert!(texgeo(&["mesh", "convert", "builtin:sphere", out.to_str().unwrap()]).status.success());
        volume(&out)
    };
    for ext in ["off", "obj", "ply", "stl"] {
        // A − A, and A ∩ B of disjoint solids: no faces, a well-formed file.
        for (name, transform, op) in
            [("minus-itself", "scale 1", "difference"), ("disjoint", "translate 5 0 0", "intersection")]
        {
            let empty = temp(&format!("{name}.{ext}"));
            let o = boolean("builtin:cube", "builtin:cube", transform, op, &empty);
            assert!(o.status.success(), "{name}.{ext}: {}", stderr(&o));
            assert_eq!(formats::read(&empty).unwrap().num_faces(), 0, "{name}.{ext}");
            let o = texgeo(&["mesh", "stats", empty.to_str().unwrap()]);
            assert!(stdout(&o).contains("solid: yes (empty)"), "{name}.{ext}: {}", stdout(&o));
            // As an operand: sphere ∪ ∅ = sphere, ∅ − sphere = ∅.
            let union = temp(&format!("{name}-{ext}-union.off"));
            let o = texgeo(&[
                "boolean",
                "builtin:sphere",
                empty.to_str().unwrap(),
                "--op",
                "union",
                "-o",
                union.to_str().unwrap(),
            ]);
            assert!(o.status.success(), "{name}.{ext}: {}", stderr(&o));
            assert!((volume(&union) - sphere_volume).abs() <= 1e-12 * sphere_volume, "{name}.{ext}");
            let none = temp(&format!("{name}-{ext}-none.off"));
            let o = texgeo(&[
                "boolean",
                empty.to_str().unwrap(),
                "builtin:sphere",
                "--op",
                "difference",
                "-o",
                none.to_str().unwrap(),
            ]);
            assert!(o.status.success(), "{name}.{ext}: {}", stderr(&o));
            assert_eq!(formats::read(&none).unwrap().num_faces(), 0, "{name}.{ext}");
        }
    }
}

#[test]
fn a_sliver_difference_is_repaired_says_so_and_is_an_operand() {
    // A sphere minus its copy turned 1e-6°: thin slivers whose faces cross once the
    // intersection points are rounded, unless the output is repaired.
    let out = temp("slivers.off");
    let o = texgeo(&[
        "boolean",
        "builtin:sphere",
        "builtin:sphere",
        "--transform-b",
        "rotate x 1e-6",
        "--op",
        "difference",
        "-o",
        out.to_str().unwrap(),
        "--stats",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let line =
        stdout(&o).lines().find(|l| l.starts_with("difference after rounding")).unwrap_or("").to_string();
    assert!(line.contains(" edges collapsed") && !line.contains(" 0 edges collapsed"), "{}", stdout(&o));
    let stats = texgeo(&["mesh", "stats", out.to_str().unwrap()]);
    assert!(stdout(&stats).contains("solid: yes"), "{}", stdout(&stats));
    let again = temp("slivers-union.off");
    let o = texgeo(&[
        "boolean",
        out.to_str().unwrap(),
        "builtin:cube",
        "--transform-b",
        "translate 5 0 0",
        "--op",
        "union",
        "-o",
        again.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
}

/// The unit cube with its top split so that a vertex lies on the top front edge, which
/// the front face keeps whole: a face of no area (corners on that edge) closes it, as STL
/// export of polygon meshes makes them. `plug_corners` extra vertices lie on the edge:
/// one plugged by a triangle, two by a quad.
fn plugged_cube(plug_corners: usize) -> String {
    let (extra, top, plug) = match plug_corners {
        1 => ("0.5 0 1\n", vec!["3 4 8 6", "3 8 7 6", "3 8 5 7"], "3 4 5 8"),
        _ => ("0.25 0 1\n0.75 0 1\n", vec!["6 4 8 9 5 7 6"], "4 4 5 9 8"),
    };
    let mut faces: Vec<&str> = FACES[..5].to_vec();
    faces.extend(top);
    faces.push(plug);
    format!("OFF\n{} {} 0\n{CUBE_VERTICES}{extra}{}\n", 8 + plug_corners, faces.len(), faces.join("\n"))
}

#[test]
fn faces_of_no_area_are_left_out_as_every_command_does() {
    for corners in [1, 2] {
        let cube = write(&temp(&format!("plugged-{corners}.off")), &plugged_cube(corners));
        let stats = stdout(&texgeo(&["mesh", "stats", &cube]));
        assert!(stats.contains("degenerate faces       1") && stats.contains("solid: yes"), "{stats}");
        // B straddles the top front edge around the plugged junction.
        let transform = "scale 0.25; translate 0.5 0 1";
        for (op, want) in [("union", 1.09375), ("difference", 0.96875), ("intersection", 0.03125)] {
            let out = temp(&format!("plugged-{corners}-{op}.off"));
            let o = boolean(&cube, "builtin:cube", transform, op, &out);
            assert!(o.status.success(), "{corners} {op}: {}", stderr(&o));
            assert!((volume(&out) - want).abs() < 1e-12, "{corners} {op}: {}", volume(&out));
            let stats = stdout(&texgeo(&["mesh", "stats", out.to_str().unwrap()]));
            assert!(stats.contains("solid: yes"), "{corners} {op}: {stats}");
        }
    }
}
