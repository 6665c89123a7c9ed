//! `texgeo sweep`: sharded and resumed sweeps give the merged table of one uninterrupted
//! run (times aside), and a mesh whose worker panics, aborts, segfaults, runs out of
//! memory or hangs is recorded as such while the sweep goes on.

mod common;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

use common::texgeo_env as texgeo;

fn ok(o: &Output) -> String {
    let out = String::from_utf8_lossy(&o.stdout).into_owned();
    assert!(o.status.success(), "stdout:\n{out}\nstderr:\n{}", String::from_utf8_lossy(&o.stderr));
    out
}

fn temp(name: &str) -> PathBuf {
    common::fresh_dir("sweep", name)
}

/// Built-in models plus broken files: unreadable, not closed, missing.
fn manifest(dir: &Path) -> PathBuf {
    std::fs::write(dir.join("garbage.off"), "OFF\n3 1 0\n0 0 0\n1 0 0\nnot a number\n").unwrap();
    // A cube without its top face: open.
    std::fs::write(
        dir.join("open.off"),
        "OFF\n8 5 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 1\n1 0 1\n1 1 1\n0 1 1\n\
         4 0 3 2 1\n4 0 1 5 4\n4 1 2 6 5\n4 2 3 7 6\n4 3 0 4 7\n",
    )
    .unwrap();
    let list = "builtin:cube\nbuiltin:knot\ngarbage.off\nbuiltin:two-cubes\nopen.off\nbuiltin:cavity\n\
                missing.off\nbuiltin:torus\nbuiltin:l-prism\nbuiltin:pyramid\n";
    let path = dir.join("meshes.txt");
    std::fs::write(&path, list).unwrap();
    path
}

/// The merged CSV without its measurement columns (peak memory, times).
fn table(dir: &Path) -> String {
    let mut reader = csv::Reader::from_path(dir.join("sweep.csv")).unwrap();
    let header = reader.headers().unwrap().clone();
    let keep: Vec<bool> = header.iter().map(|h| h != "peak_rss_kib" && !h.starts_with("time_")).collect();
    let pick = |r: &csv::StringRecord| {
        r.iter().zip(&keep).filter(|(_, k)| **k).map(|(c, _)| c.to_string()).collect::<Vec<_>>().join(",")
    };
    let mut lines = vec![pick(&header)];
    lines.extend(reader.records().map(|r| pick(&r.unwrap())));
    lines.join("\n")
}

/// The summary up to its timed sections.
fn summary(dir: &Path) -> String {
    let text = std::fs::read_to_string(dir.join("summary.md")).unwrap();
    text.split("## Slowest meshes").next().unwrap().to_string()
}

// A faithful GPU method, named (the task's default is `auto`, as for the command).
const VOXELIZE: [&str; 6] = ["--task", "voxelize", "--method", "zoned", "--res", "16"];

fn sweep(manifest: &Path, out: &Path, extra: &[&str], env: &[(&str, &str)]) -> Output {
    let mut args = vec!["sweep", manifest.to_str().unwrap(), "-o", out.to_str().unwrap()];
    args.extend(VOXELIZE);
    args.extend(extra);
    texgeo(&args, env)
}

#[test]
fn shards_in_any_order_and_a_killed_run_resumed_give_the_table_of_one_run() {
    let dir = temp("shards");
    let m = manifest(&dir);
    let whole = dir.join("whole");
    let out = ok(&sweep(&m, &whole, &[], &[]));
    assert!(out.contains("10 meshes: 7 ok, 3 refused"), "{out}");
    let reference = table(&whole);
    let expected_rows = [
        ("builtin:cube", "ok", ""),
        ("garbage.off", "refused", "unreadable"),
        ("builtin:two-cubes", "ok", ""),
        ("open.off", "refused", "not-closed"),
        ("missing.off", "refused", "unreadable"),
    ];
    for (mesh, outcome, reason) in expected_rows {
        assert!(
            reference.lines().any(|l| l.contains(&format!(",{mesh},{outcome},{reason},"))),
            "{mesh}:\n{reference}"
        );
    }
    let summary_whole = summary(&whole);
    assert!(summary_whole.contains("| refused | unreadable | 2 |"), "{summary_whole}");

    for order in [vec![1, 0], vec![3, 1, 0, 2]] {
        let n = order.len();
        let out = dir.join(format!("shards-{n}"));
        for i in order {
            let shard = format!("{i}/{n}");
            let o = sweep(&m, &out, &["--shard", &shard], &[]);
            assert!(ok(&o).contains(&format!("shard {shard} has")));
        }
        ok(&texgeo(&["sweep", "merge", out.to_str().unwrap()], &[]));
        assert_eq!(table(&out), reference, "{n} shards");
        assert_eq!(summary(&out), summary_whole, "{n} shards");
    }

    // Kill a sweep while its worker hangs on the 8th mesh, tear its last line, resume.
    let killed = dir.join("killed");
    let results = killed.join("results-0-of-1.jsonl");
    let mut child = Command::new(env!("CARGO_BIN_EXE_texgeo"))
        .args(["sweep", m.to_str().unwrap(), "-o", killed.to_str().unwrap()])
        .args(VOXELIZE)
        .env("TEXGEO_SWEEP_FAULT", "hang:builtin:torus")
        .stdout(Stdio::null())
        .spawn()
        .unwrap();
    let start = Instant::now();
    while std::fs::read_to_string(&results).map_or(0, |t| t.lines().count()) < 7 {
        assert!(start.elapsed() < Duration::from_secs(120), "the sweep did not reach the 8th mesh");
        std::thread::sleep(Duration::from_millis(20));
    }
    child.kill().unwrap();
    child.wait().unwrap();
    let mut text = std::fs::read_to_string(&results).unwrap();
    text.push_str("{\"index\":7,\"mesh\":\"builtin:to");
    std::fs::write(&results, text).unwrap();
    let out = ok(&sweep(&m, &killed, &[], &[]));
    assert!(out.contains("10 meshes, 7 already recorded, 3 to run"), "{out}");
    assert_eq!(table(&killed), reference);
    assert_eq!(summary(&killed), summary_whole);
    // Resuming a finished sweep runs nothing and changes nothing.
    let out = ok(&sweep(&m, &killed, &["--resume"], &[]));
    assert!(out.contains("10 already recorded, 0 to run"), "{out}");
    assert_eq!(table(&killed), reference);
}

#[test]
fn crashes_hangs_and_out_of_memory_are_recorded_and_the_sweep_goes_on() {
    let dir = temp("faults");
    let m = manifest(&dir);
    let out = dir.join("out");
    let faults = "panic:builtin:cube,abort:builtin:knot,segv:builtin:cavity,hang:builtin:torus,\
                  oom:builtin:l-prism,exit:builtin:pyramid";
    let o = texgeo(
        &[
            "sweep",
            m.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
            "--task",
            "inclusion",
            "--method",
            "cpu",
            "--points",
            "200",
            "--timeout",
            "3",
            "--memory-limit",
            "2048",
            "--jobs",
            "2",
        ],
        &[("TEXGEO_SWEEP_FAULT", faults)],
    );
    let stdout = ok(&o);
    assert!(stdout.contains("10 meshes: 1 ok, 3 refused, 5 crashed, 1 timeout"), "{stdout}");
    let csv = std::fs::read_to_string(out.join("sweep.csv")).unwrap();
    let rows: BTreeMap<&str, &str> = csv.lines().skip(1).map(|l| (l.split(',').nth(1).unwrap(), l)).collect();
    for (mesh, needle) in [
        ("builtin:cube", ",crashed,panic,"),
        ("builtin:knot", ",crashed,abort,"),
        ("builtin:cavity", ",crashed,segfault,"),
        ("builtin:torus", ",timeout,timeout,"),
        ("builtin:l-prism", ",crashed,out-of-memory,"),
        ("builtin:pyramid", ",crashed,exit,"),
        ("builtin:two-cubes", ",ok,,"),
    ] {
        assert!(rows[mesh].contains(needle), "{mesh}: {}", rows[mesh]);
    }
    assert!(rows["builtin:cube"].contains("panicked at") && rows["builtin:cube"].contains("test-only fault"));
    assert!(rows["builtin:torus"].contains("no result within 3 s"));
    assert!(rows["builtin:l-prism"].contains("memory allocation of"));
}

#[test]
fn bad_requests_exit_2_with_one_message() {
    let dir = temp("errors");
    let m = manifest(&dir);
    let out = dir.join("out");
    let s = |o: &Output| (o.status.code(), String::from_utf8_lossy(&o.stderr).into_owned());
    let mp = m.to_str().unwrap();
    let op = out.to_str().unwrap();
    let (code, err) = s(&texgeo(&["sweep", mp, "-o", op, "--task", "inclusion", "--res", "8"], &[]));
    assert_eq!(code, Some(2));
    assert!(err.contains("task inclusion: unknown field `res`"), "{err}");

    let csv = dir.join("m.csv");
    std::fs::write(&csv, "mesh,res\nbuiltin:cube,8\nbuiltin:knot,5000\n").unwrap();
    let (code, err) = s(&texgeo(&["sweep", csv.to_str().unwrap(), "-o", op, "--task", "voxelize"], &[]));
    assert_eq!(code, Some(2));
    assert!(err.contains("m.csv:3: task voxelize: resolution 5000"), "{err}");

    // A folder holding another sweep is refused; its results are left alone.
    ok(&texgeo(&["sweep", mp, "-o", op, "--task", "inclusion", "--method", "cpu", "--points", "10"], &[]));
    let (code, err) = s(&texgeo(&["sweep", mp, "-o", op, "--task", "inclusion", "--method", "cpu"], &[]));
    assert_eq!(code, Some(2));
    assert!(err.contains("holds a sweep with other options"), "{err}");
    // Shards of another split in the same folder cannot be merged.
    std::fs::write(out.join("results-0-of-2.jsonl"), "").unwrap();
    let (code, err) = s(&texgeo(&["sweep", "merge", op], &[]));
    assert_eq!(code, Some(2));
    assert!(err.contains("different numbers of shards (1, 2)"), "{err}");
}

/// `--task boolean`: each mesh against its turned copy, checked by the volume identity and
/// by CGAL; a solid CGAL refuses (non-manifold) is recorded as declined by the reference,
/// an open mesh is refused as `texgeo boolean` refuses it, and shards merge to one table.
#[test]
fn boolean_task_checks_against_cgal_and_shards_merge_alike() {
    let dir = temp("boolean");
    std::fs::write(
        dir.join("open.off"),
        "OFF\n8 5 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 1\n1 0 1\n1 1 1\n0 1 1\n\
         4 0 3 2 1\n4 0 1 5 4\n4 1 2 6 5\n4 2 3 7 6\n4 3 0 4 7\n",
    )
    .unwrap();
    let m = dir.join("meshes.txt");
    std::fs::write(&m, "builtin:cube\nbuiltin:two-cubes\nopen.off\nbuiltin:l-prism\nbuiltin:torus\n")
        .unwrap();
    let run = |out: &Path, shard: &str| {
        ok(&texgeo(
            &[
                "sweep",
                m.to_str().unwrap(),
                "-o",
                out.to_str().unwrap(),
                "--task",
                "boolean",
                "--op",
                "union",
                "--reference",
                "cgal",
                "--shard",
                shard,
            ],
            &[],
        ))
    };
    let whole = dir.join("whole");
    let text = run(&whole, "0/1");
    assert!(text.contains("5 meshes: 4 ok, 1 refused"), "{text}");
    let reference = table(&whole);
    assert!(reference.lines().any(|l| l.contains(",open.off,refused,not-closed,")), "{reference}");
    let results = std::fs::read_to_string(whole.join("results-0-of-1.jsonl")).unwrap();
    let line = |mesh: &str| results.lines().find(|l| l.contains(&format!("\"mesh\":\"{mesh}\""))).unwrap();
    assert!(line("builtin:two-cubes").contains("\"cgal\":\"declined: self-intersecting\""), "{results}");
    for mesh in ["builtin:cube", "builtin:torus", "builtin:l-prism"] {
        assert!(line(mesh).contains("\"cgal_volume\""), "{mesh}: {}", line(mesh));
    }
    let sharded = dir.join("sharded");
    for shard in ["1/2", "0/2"] {
        run(&sharded, shard);
    }
    ok(&texgeo(&["sweep", "merge", sharded.to_str().unwrap()], &[]));
    assert_eq!(table(&sharded), reference);
}

/// Without `--method` a task uses the command's default, `auto`, and records which method
/// it chose; a method that does not exist is refused with the command's message.
#[test]
fn tasks_default_to_auto_and_record_the_choice() {
    let dir = temp("auto");
    let m = dir.join("m.txt");
    std::fs::write(&m, "builtin:cube\n").unwrap();
    let run = |task: &str, extra: &[&str]| {
        let out = dir.join(format!("{task}{}", extra.join("")));
        let mut args = vec!["sweep", m.to_str().unwrap(), "-o", out.to_str().unwrap(), "--task", task];
        args.extend(extra);
        let o = texgeo(&args, &[]);
        (o, out)
    };
    for (task, extra) in [("voxelize", ["--res", "8"]), ("inclusion", ["--points", "50"])] {
        let (o, out) = run(task, &extra);
        ok(&o);
        let line = std::fs::read_to_string(out.join("results-0-of-1.jsonl")).unwrap();
        let record: serde_json::Value = serde_json::from_str(line.trim()).unwrap();
        assert_eq!(record["outcome"], "ok", "{task}: {line}");
        assert!(record["checks"]["method"].as_str().is_some_and(|s| !s.is_empty()), "{task}: {line}");
        assert_eq!(record["checks"]["differing"], 0, "{task}: {line}");
    }
    let (o, _) = run("voxelize", &["--method", "magic"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("task voxelize: no method 'magic' (auto, cpu, fgpu"), "{err}");
}
