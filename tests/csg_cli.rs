//! `texgeo csg` and `texgeo boolean` with more than two operands: an expression of five
//! operands equals the same operations done one by one with `texgeo boolean`, and
//! mistakes in the expression or the operands are one line with status 2 before any mesh
//! is read.

mod common;

use common::{TempDir, assert_refused, stderr, stdout, texgeo};
use texgeo::mesh::covering::Covering;
use texgeo::mesh::formats;

/// The five operands: NAME, MESH, STEPS (the transform placing it).
const OPERANDS: [(&str, &str, &str); 5] = [
    ("a", "builtin:cube", ""),
    ("b", "builtin:cube", "rotate 1 2 3 20; translate 0.7 0.3 0.2"),
    ("c", "builtin:sphere", "scale 0.9; translate -0.8 0.5 0.3"),
    ("d", "builtin:cube", "scale 1.3; rotate 3 1 2 35; translate 0.2 -0.1 0.4"),
    ("e", "builtin:tetrahedron", "scale 1.5; rotate 1 0 1 15; translate 0.9 0.8 -0.2"),
];

fn ok(args: &[&str]) -> String {
    let o = texgeo(args);
    assert!(o.status.success(), "{args:?}: {}", stderr(&o));
    stdout(&o)
}

/// Faces and volume of a mesh file (0 for the empty solid).
fn read(path: &str) -> (usize, f64) {
    let m = formats::read(std::path::Path::new(path)).unwrap();
    (m.num_faces(), if m.num_faces() == 0 { 0.0 } else { Covering::new(&m).volume() })
}

#[test]
fn an_expression_equals_its_operations_one_by_one() {
    let dir = TempDir::new("csg");
    // Python's precedence: ((((a | b) - c) & d) ^ e).
    let expr = "(a | b) - c & d ^ e";
    let specs: Vec<String> = OPERANDS
        .iter()
        .map(|(n, m, t)| if t.is_empty() { format!("{n}={m}") } else { format!("{n}={m}@{t}") })
        .collect();
    let out = dir.arg("csg.off");
    let mut args = vec!["csg", expr];
    args.extend(specs.iter().map(String::as_str));
    args.extend(["-o", &out, "--stats"]);
    let text = ok(&args);
    assert!(text.starts_with(&format!("{expr}: ")), "{text}");
    for want in [
        "step 1/4: a (builtin:cube) ∪ b (builtin:cube) = a | b:",
        "step 4/4: (",
        "operation(s)",
        "exact (± ",
        "), before rounding to f64",
        // Inner results are the next operation's operands as they are, exactly.
        "kept exact for the next operation (not rounded)",
    ] {
        assert!(text.contains(want), "{want}: {text}");
    }

    let mut previous = "builtin:cube".to_string();
    for (i, (op, (_, mesh, steps))) in
        ["union", "difference", "intersection", "symmetric-difference"].iter().zip(&OPERANDS[1..]).enumerate()
    {
        let step = dir.arg(&format!("step{i}.off"));
        ok(&["boolean", &previous, mesh, "--transform-b", steps, "--op", op, "-o", &step]);
        previous = step;
    }
    // One by one, each result is rounded to f64 before it is used again; in the
    // expression nothing is rounded before the end: the same solid up to rounding.
    let (faces, volume) = read(&out);
    let (want_faces, want_volume) = read(&previous);
    assert!(faces > 0 && want_faces > 0);
    assert!((volume - want_volume).abs() <= 1e-12 * want_volume.abs(), "{volume} vs {want_volume}");
    assert!(volume > 0.1, "{volume}");
    assert_eq!(text.matches("after rounding to f64").count(), 1, "{text}");

    // More than two operands to `boolean`: the left fold, as `a - b - c`. An expression of
    // one operand writes it placed by its transform.
    let (c, e) = (dir.arg("c.off"), dir.arg("e.off"));
    ok(&["csg", "c", &specs[2], "-o", &c]);
    ok(&["csg", "e", &specs[4], "-o", &e]);
    let (folded, three) = (dir.arg("folded.off"), dir.arg("three.off"));
    let step0 = dir.arg("step0.off");
    ok(&["boolean", &step0, &c, &e, "--op", "difference", "-o", &folded]);
    ok(&[
        "csg",
        "a - b - c",
        &format!("a={step0}"),
        &specs[2].replacen("c=", "b=", 1),
        &specs[4].replacen("e=", "c=", 1),
        "-o",
        &three,
    ]);
    assert_eq!(std::fs::read(&folded).unwrap(), std::fs::read(&three).unwrap());
    assert!(read(&folded).1 < read(&step0).1);
}

#[test]
fn empty_operands_and_results() {
    // a − a is the empty solid, written as a file without faces; in an expression and read
    // back from its file it leaves a union as it was and empties an intersection.
    let dir = TempDir::new("csg-empty");
    let empty = dir.arg("empty.off");
    let text = ok(&["csg", "a - a", "a=builtin:cube", "-o", &empty]);
    assert!(text.starts_with("a - a: 0 triangles, volume 0 -> "), "{text}");
    assert_eq!(read(&empty), (0, 0.0));
    let sphere = dir.arg("sphere.off");
    ok(&["csg", "b", "b=builtin:sphere", "-o", &sphere]);
    let (_, want) = read(&sphere);
    let e = format!("e={empty}");
    for (expr, operands, volume) in [
        ("(a - a) | b", vec!["a=builtin:cube", "b=builtin:sphere"], want),
        ("e | b", vec![e.as_str(), "b=builtin:sphere"], want),
        ("b - e", vec![e.as_str(), "b=builtin:sphere"], want),
        ("b & e", vec![e.as_str(), "b=builtin:sphere"], 0.0),
        ("e - b", vec![e.as_str(), "b=builtin:sphere"], 0.0),
        ("(b & (a - a)) | e", vec!["a=builtin:cube", "b=builtin:sphere", e.as_str()], 0.0),
        ("e", vec![e.as_str()], 0.0),
    ] {
        let out = dir.arg("out.off");
        let mut args = vec!["csg", expr];
        args.extend(operands);
        args.extend(["-o", &out]);
        ok(&args);
        let (faces, got) = read(&out);
        assert_eq!(faces == 0, volume == 0.0, "{expr}: {faces} faces");
        assert!((got - volume).abs() <= 1e-12 * want, "{expr}: {got} vs {volume}");
    }
    // `boolean` with more operands folds through the empty solid the same way.
    let out = dir.arg("folded.off");
    ok(&["boolean", &empty, "builtin:sphere", &empty, "--op", "union", "-o", &out]);
    assert!((read(&out).1 - want).abs() <= 1e-12 * want);
}

#[test]
fn mistakes_are_one_line_before_any_mesh_is_read() {
    let dir = TempDir::new("csg-errors");
    let out = dir.arg("never.off");
    // The operands do not exist: every refusal comes before reading them.
    for (expr, operands, message) in [
        (
            "(a | b) - )",
            vec!["a=no-a.off", "b=no-b.off"],
            "column 11 of the expression: expected an operand name, found ')'",
        ),
        (
            "a | b &",
            vec!["a=no-a.off", "b=no-b.off"],
            "column 8 of the expression: expected an operand name, found the end",
        ),
        (
            "(a | b",
            vec!["a=no-a.off", "b=no-b.off"],
            "column 7 of the expression: expected an operator or ')' closing the '(' of column 1, found the end",
        ),
        (
            "a b",
            vec!["a=no-a.off", "b=no-b.off"],
            "column 3 of the expression: expected an operator, found 'b'",
        ),
        (
            "a + b",
            vec!["a=no-a.off", "b=no-b.off"],
            "column 3 of the expression: unexpected character '+' (operands are names; operators are | & - ^ and parentheses)",
        ),
        (
            "a | dd",
            vec!["a=no-a.off", "b=no-b.off"],
            "column 5 of the expression: unknown operand 'dd' (given: a, b)",
        ),
        (
            "a | b",
            vec!["a=no-a.off", "b=no-b.off", "c=builtin:cube"],
            "operand c (builtin:cube) is not used in the expression",
        ),
        (
            "a | b",
            vec!["a=no-a.off", "b=no-b.off", "a=other.off"],
            "operand 'a' is given twice (no-a.off and other.off)",
        ),
        (
            "a | b",
            vec!["a=no-a.off", "2b=no-b.off"],
            "operand '2b=no-b.off': '2b' is not a name (a letter or '_', then letters, digits or '_')",
        ),
        (
            "a | b",
            vec!["a=no-a.off", "no-b.off"],
            "operand 'no-b.off': expected NAME=MESH or NAME=MESH@STEPS",
        ),
        (
            "a | b",
            vec!["a=no-a.off", "b=builtin:cube@twist 3"],
            "operand b: unknown transform step 'twist 3' (expected translate, rotate, scale or matrix)",
        ),
    ] {
        let mut args = vec!["csg", expr];
        args.extend(operands);
        args.extend(["-o", &out]);
        let o = texgeo(&args);
        assert_refused(&o, &[]);
        assert_eq!(stderr(&o).trim_end(), format!("texgeo: error: {message}"), "{expr}");
    }
    // `boolean` keeps its two-operand options to two operands.
    let o = texgeo(&["boolean", "no-a.off", "no-b.off", "no-c.off", "--all", dir.path().to_str().unwrap()]);
    assert_refused(&o, &["--all takes exactly two operands"]);
    assert!(dir.entries().is_empty(), "{:?}", dir.entries());
}
