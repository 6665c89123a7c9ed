//! The modules of `src/inclusion` and `src/subdiv` import each other without cycles: in
//! inclusion `mod.rs` only declares and re-exports, shared types live in leaf modules, and
//! one factory (`solver.rs`) builds every method. Read from the sources (comments and
//! tests left out).

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

/// Module → the sibling modules its code names (`super::x`, `use super::{x, …}`), with
/// `mod` standing for items defined in `mod.rs`.
fn graph(dir: &Path) -> BTreeMap<String, BTreeSet<String>> {
    let files: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "rs"))
        .collect();
    let modules: BTreeSet<String> =
        files.iter().map(|p| p.file_stem().unwrap().to_string_lossy().into_owned()).collect();
    let mut g = BTreeMap::new();
    for path in &files {
        let name = path.file_stem().unwrap().to_string_lossy().into_owned();
        let text = std::fs::read_to_string(path).unwrap();
        let code: String = text
            .split("#[cfg(test)]")
            .next()
            .unwrap()
            .lines()
            .map(|l| l.split("//").next().unwrap())
            .collect::<Vec<_>>()
            .join("\n");
        let mut deps = BTreeSet::new();
        let mut note = |item: &str| {
            let item = item.trim().split("::").next().unwrap().trim();
            if item.is_empty() || item == "self" || item == "*" {
                return;
            }
            if modules.contains(item) {
                deps.insert(item.to_string());
            } else if name != "mod" {
                deps.insert("mod".to_string());
            }
        };
        for (i, _) in code.match_indices("super::") {
            let rest = &code[i + 7..];
            if let Some(list) = rest.strip_prefix('{') {
                list.split('}').next().unwrap().split(',').for_each(&mut note);
            } else {
                note(rest.split(|c: char| !(c.is_alphanumeric() || c == '_')).next().unwrap());
            }
        }
        if name == "mod" {
            for line in code.lines().filter(|l| {
                let t = l.trim_start();
                !(t.starts_with("pub mod")
                    || t.starts_with("mod ")
                    || t.starts_with("pub use")
                    || t.starts_with("use "))
            }) {
                for m in &modules {
                    if m != "mod" && line.contains(&format!("{m}::")) {
                        deps.insert(m.clone());
                    }
                }
            }
        }
        deps.remove(&name);
        g.insert(name, deps);
    }
    g
}

fn cycle(g: &BTreeMap<String, BTreeSet<String>>) -> Option<Vec<String>> {
    fn visit(
        g: &BTreeMap<String, BTreeSet<String>>,
        u: &str,
        stack: &mut Vec<String>,
        done: &mut BTreeSet<String>,
    ) -> Option<Vec<String>> {
        if let Some(at) = stack.iter().position(|s| s == u) {
            let mut c = stack[at..].to_vec();
            c.push(u.to_string());
            return Some(c);
        }
        if done.contains(u) {
            return None;
        }
        stack.push(u.to_string());
        for v in g.get(u).into_iter().flatten() {
            if let Some(c) = visit(g, v, stack, done) {
                return Some(c);
            }
        }
        stack.pop();
        done.insert(u.to_string());
        None
    }
    let mut done = BTreeSet::new();
    g.keys().find_map(|u| visit(g, u, &mut Vec::new(), &mut done))
}

#[test]
fn inclusion_modules_import_without_cycles() {
    let g = graph(&Path::new(env!("CARGO_MANIFEST_DIR")).join("src/inclusion"));
    assert!(g.len() > 10, "{g:?}");
    assert_eq!(cycle(&g), None, "{g:?}");
    // mod.rs names no child in its code.
    assert!(g["mod"].is_empty(), "{:?}", g["mod"]);
}

#[test]
fn subdiv_modules_import_without_cycles() {
    let g = graph(&Path::new(env!("CARGO_MANIFEST_DIR")).join("src/subdiv"));
    assert!(g.len() > 8, "{g:?}");
    assert_eq!(cycle(&g), None, "{g:?}");
}
