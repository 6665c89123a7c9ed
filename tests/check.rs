//! `texgeo check`: the shader correctness suite passes on the default device (lavapipe
//! under tools/test, with the validation layer on), lists every check in its table and
//! its JUnit file, marks checks a masked feature prevents as not supported (skipped in
//! JUnit, never passed), and refuses unknown check names with status 2.

mod common;

use std::process::Command;

use common::{TempDir, assert_refused, stderr, stdout, texgeo};

/// The table row of `name`: (result, rest of the line).
fn row<'a>(table: &'a str, name: &str) -> Option<&'a str> {
    table
        .lines()
        .find_map(|l| l.strip_prefix(name).filter(|rest| rest.starts_with("  ")).map(str::trim_start))
}

#[test]
fn every_check_passes_and_the_junit_file_lists_each() {
    let dir = TempDir::new("check-all");
    let junit = dir.arg("check.xml");
    let out = texgeo(&["check", "--junit", &junit]);
    let table = stdout(&out);
    assert_eq!(out.status.code(), Some(0), "{table}{}", stderr(&out));
    let names: Vec<&str> = texgeo::check::all().iter().map(|c| c.name).collect();
    assert!(names.len() >= 15, "{names:?}");
    for group in ["reduce", "xor", "inclusion", "voxel", "subdiv", "render"] {
        assert!(names.iter().any(|n| n.starts_with(group)), "no {group} check in {names:?}");
    }
    for name in &names {
        let r = row(&table, name).unwrap_or_else(|| panic!("no row for {name}:\n{table}"));
        assert!(r.starts_with("pass "), "{name}: {r}");
    }
    assert!(table.contains(&format!("{} passed, 0 failed, 0 not supported", names.len())), "{table}");

    let xml = std::fs::read_to_string(dir.join("check.xml")).unwrap();
    let doc = roxmltree::Document::parse(&xml).unwrap_or_else(|e| panic!("{e}:\n{xml}"));
    let cases: Vec<_> = doc.descendants().filter(|n| n.has_tag_name("testcase")).collect();
    assert_eq!(cases.len(), names.len(), "{xml}");
    for (case, name) in cases.iter().zip(&names) {
        assert_eq!(case.attribute("name"), Some(*name));
        assert!(case.children().all(|c| !c.is_element()), "{name} passed, so it has no child: {xml}");
    }
    let suite = doc.descendants().find(|n| n.has_tag_name("testsuite")).unwrap();
    assert_eq!(suite.attribute("tests"), Some(names.len().to_string().as_str()));
    assert_eq!(suite.attribute("failures"), Some("0"));
    assert_eq!(dir.entries(), ["check.xml"], "no temporary file left");
}

#[test]
fn a_masked_logic_op_makes_the_xor_checks_not_supported() {
    let dir = TempDir::new("check-masked");
    let junit = dir.arg("masked.xml");
    let out = Command::new(env!("CARGO_BIN_EXE_texgeo"))
        .args(["check", "--only", "xor,reduce-npot,voxel-pgpu", "--junit", &junit])
        .env("TEXGEO_MASK_FEATURES", "logic_op")
        .output()
        .unwrap();
    let table = stdout(&out);
    assert_eq!(out.status.code(), Some(0), "not supported is no failure: {table}{}", stderr(&out));
    for name in ["xor-parity", "xor-top-left", "voxel-pgpu"] {
        let r = row(&table, name).unwrap_or_else(|| panic!("no row for {name}:\n{table}"));
        assert!(r.starts_with("not supported") && r.contains("logicOp"), "{name}: {r}");
    }
    assert!(row(&table, "reduce-npot").is_some_and(|r| r.starts_with("pass ")), "{table}");
    assert!(row(&table, "inclusion-grid").is_none(), "--only runs only what it names: {table}");
    assert!(table.contains("1 passed, 0 failed, 3 not supported"), "{table}");

    let xml = std::fs::read_to_string(dir.join("masked.xml")).unwrap();
    let doc = roxmltree::Document::parse(&xml).unwrap_or_else(|e| panic!("{e}:\n{xml}"));
    let cases: Vec<_> = doc.descendants().filter(|n| n.has_tag_name("testcase")).collect();
    assert_eq!(cases.len(), 4, "{xml}");
    for case in cases {
        let skipped = case.children().find(|c| c.has_tag_name("skipped"));
        if case.attribute("name") == Some("reduce-npot") {
            assert!(skipped.is_none(), "{xml}");
        } else {
            let message = skipped.and_then(|s| s.attribute("message")).unwrap_or_default();
            assert!(message.starts_with("not supported: ") && message.contains("logicOp"), "{xml}");
        }
    }
}

#[test]
fn unknown_check_names_are_refused_with_the_valid_ones() {
    let out = texgeo(&["check", "--only", "xor,no-such-check"]);
    assert_refused(&out, &["no check 'no-such-check'", "xor-parity", "render-msaa", "groups: reduce, xor"]);
    assert!(stdout(&out).is_empty(), "nothing ran: {}", stdout(&out));
}
