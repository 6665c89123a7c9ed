//! The thesis' numbers (`reference/`) as facts, under the same names as today's, so a
//! claim is computed the same way from both.

use super::facts::{Facts, Source, Stat};
use crate::report::bench::{boolean, inclusion, subdiv, voxelize};

/// The two theses this report reproduces, cited in full wherever the report names them.
pub const CITATIONS: [&str; 2] = [
    "Carlos J. Ogayar Anguita, “Optimización de algoritmos geométricos básicos mediante el uso de \
     recubrimientos simpliciales”, PhD thesis, Universidad de Granada, 2006 (inclusion test, voxelization, \
     Booleans).",
    "Arasay Baryolo Morales and Yandry Fernández Font, “Subdivisión de superficies mediante el uso de la \
     unidad de procesamiento gráfico”, diploma thesis, Universidad de las Ciencias Informáticas, La Habana, \
     2010 (Catmull-Clark subdivision).",
];

/// (column of the thesis CSV, fact key, unit, scale to texgeo's unit).
type Columns<'a> = &'a [(&'a str, &'a str, &'static str)];

/// Reads one transcribed table: every row of `model` + `columns`.
fn table(facts: &mut Facts, experiment: &'static str, csv: &str, size_column: &str, columns: Columns) {
    let mut lines = csv.lines().filter(|l| !l.trim().is_empty());
    let header: Vec<&str> = lines.next().unwrap_or("").split(',').collect();
    let col = |name: &str| header.iter().position(|h| *h == name);
    for line in lines {
        let cells: Vec<&str> = line.split(',').collect();
        let model = cells[0].to_string();
        let size = col(size_column).and_then(|c| cells.get(c)).and_then(|v| v.parse::<f64>().ok());
        if let Some(size) = size {
            facts.model(experiment, &model, size, &model);
        }
        for &(column, key, unit) in columns {
            let Some(cell) = col(column).and_then(|c| cells.get(c)) else { continue };
            match cell.trim().parse::<f64>() {
                Ok(v) => facts.add(experiment, &model, key, unit, Stat::exact(v)),
                Err(_) if cell.trim().is_empty() => {}
                // "stack overflow" and the like: the thesis says why there is no number.
                Err(_) => facts.missing(experiment, &model, key, unit, cell.trim()),
            }
        }
    }
}

/// Every transcribed table of both theses.
pub fn facts() -> Facts {
    let mut f = Facts::new(Source::Thesis);
    inclusion_tables(&mut f);
    voxelize_table(&mut f);
    subdivide_table(&mut f);
    boolean_table(&mut f);
    f
}

/// A transcribed inclusion table: (table, size column, columns).
type InclusionTable = (&'static str, &'static str, Columns<'static>);

/// The inclusion tables of times by method, read before the TetraGrid tables. Table 4-6 as
/// printed repeats Table 4-5's TetraGrid columns under its method names
/// (`inclusion::TABLE_4_6_NOTE`): its numbers stay under its own keys, shown beside today's
/// Table 4-6 and used by no claim; TetraGrid 32³ comes from Table 4-5.
const INCLUSION_TIMES: [InclusionTable; 3] = [
    (
        "4-9",
        "faces",
        &[
            ("feito_cpu", "time:cpu", "s"),
            ("feito_gpu", "time:gpu", "s"),
            ("feito_gpu_tetragrid_32", "time:gpu+tetragrid", "s"),
            ("bsp", "time:bsp", "s"),
            ("jordan", "time:jordan", "s"),
            ("jordan_octree_6", "time:jordan-octree", "s"),
        ],
    ),
    (
        "4-6",
        "faces",
        &[
            ("basic", "table4-6:basic", "s"),
            ("cpu_gpu", "table4-6:cpu+gpu", "s"),
            ("gpu", "table4-6:gpu", "s"),
            ("octants", "table4-6:octants", "s"),
            ("tetragrid_32", "table4-6:tetragrid", "s"),
            ("gpu_tetragrid_32", "table4-6:gpu+tetragrid", "s"),
        ],
    ),
    ("4-5", "faces", &[("tetragrid_32", "time:tetragrid", "s")]),
];

/// The inclusion tables of each method's index, read after the TetraGrid tables.
const INCLUSION_INDEXES: [InclusionTable; 2] = [
    (
        "4-7",
        "triangles",
        &[
            ("feito_octants_kb", "memory:octants", "KiB"),
            ("feito_tetragrid_32_kb", "memory:tetragrid", "KiB"),
            ("bsp_kb", "memory:bsp", "KiB"),
            ("jordan_octree_6_kb", "memory:jordan-octree", "KiB"),
        ],
    ),
    (
        "4-8",
        "triangles",
        &[
            ("feito_octants_s", "build:octants", "s"),
            ("feito_tetragrid_32_s", "build:tetragrid", "s"),
            ("bsp_s", "build:bsp", "s"),
            ("jordan_octree_6_s", "build:jordan-octree", "s"),
        ],
    ),
];

/// Tables 4-4 to 4-9 of the inclusion test.
fn inclusion_tables(f: &mut Facts) {
    let read = |f: &mut Facts, &(id, size, columns): &InclusionTable| {
        table(f, "inclusion", inclusion::thesis_csv(id), size, columns)
    };
    INCLUSION_TIMES.iter().for_each(|t| read(f, t));
    tetragrid_tables(f);
    INCLUSION_INDEXES.iter().for_each(|t| read(f, t));
}

/// Tables 4-5 (query time) and 4-4 (build time and memory) at every TetraGrid resolution.
fn tetragrid_tables(f: &mut Facts) {
    let inc = "inclusion";
    let grid_times: Vec<(String, String)> = [2, 4, 8, 16, 32, 64]
        .iter()
        .map(|n| (format!("tetragrid_{n}"), format!("time:tetragrid-{n}")))
        .collect();
    let cols: Vec<(&str, &str, &str)> =
        grid_times.iter().map(|(c, k)| (c.as_str(), k.as_str(), "s")).collect();
    table(f, inc, inclusion::thesis_csv("4-5"), "faces", &cols);
    let builds: Vec<(String, String, String, String)> = [2, 4, 8, 16, 32, 64]
        .iter()
        .map(|n| {
            (
                format!("time_{n}"),
                format!("build:tetragrid-{n}"),
                format!("kb_{n}"),
                format!("memory:tetragrid-{n}"),
            )
        })
        .collect();
    let mut cols: Vec<(&str, &str, &str)> = Vec::new();
    for (tc, tk, mc, mk) in &builds {
        cols.push((tc, tk, "s"));
        cols.push((mc, mk, "KiB"));
    }
    table(f, inc, inclusion::thesis_csv("4-4"), "triangles", &cols);
}

/// Table 5-2: one row per (resolution, model).
fn voxelize_table(f: &mut Facts) {
    for line in voxelize::THESIS_TABLE.lines().skip(1).filter(|l| !l.trim().is_empty()) {
        let c: Vec<&str> = line.split(',').collect();
        let (Some(n), Some(model), Some(faces)) =
            (c.first(), c.get(1), c.get(2).and_then(|v| v.parse::<f64>().ok()))
        else {
            continue;
        };
        f.model("voxelize", model, faces, model);
        for (i, method) in ["cpu", "fgpu", "pgpu", "zoned", "fang", "sramek"].iter().enumerate() {
            if let Some(v) = c.get(3 + i).and_then(|v| v.parse::<f64>().ok()) {
                f.add("voxelize", model, &format!("time:{method}@{n}"), "s", Stat::exact(v));
            }
        }
    }
}

/// Table 5 of the 2010 thesis: models unnamed; rows numbered, the first is the cube.
fn subdivide_table(f: &mut Facts) {
    for (i, line) in subdiv::THESIS_TABLE5.lines().skip(1).filter(|l| !l.trim().is_empty()).enumerate() {
        let c: Vec<f64> = line.split(',').filter_map(|v| v.trim().parse().ok()).collect();
        let [fragments, faces, _vertices, tcpu1, tgpu, tcpu2] = c[..] else { continue };
        let model = if i == 0 { "row 1: cube".to_string() } else { format!("row {}", i + 1) };
        f.model("subdivide", &model, faces, &model);
        let sub = |f: &mut Facts, key: &str, v: f64| f.add("subdivide", &model, key, "s", Stat::exact(v));
        sub(f, "time:tcpu1", tcpu1);
        sub(f, "time:tgpu", tgpu);
        sub(f, "time:gpu-path", tcpu1 + tgpu);
        sub(f, "time:tcpu2", tcpu2);
        f.add("subdivide", &model, "faces", "", Stat::exact(faces));
        f.add("subdivide", &model, "fragments", "", Stat::exact(fragments));
    }
}

/// Table 6-1: one row per (pair, operation); phases from the difference, which every
/// pair has. The thesis' grouped ("optimizado") runs used the GPU point test.
fn boolean_table(f: &mut Facts) {
    for line in boolean::THESIS_TABLE.lines().skip(1).filter(|l| !l.trim().is_empty()) {
        let c: Vec<&str> = line.split(',').collect();
        let v: Vec<Option<f64>> = c.iter().map(|x| x.trim().parse::<f64>().ok()).collect();
        let (Some(pair), Some(op), Some(Some(triangles))) = (c.first(), c.get(1), v.get(2)) else { continue };
        let Some(&[Some(p1), Some(p2), Some(pt), Some(g1), Some(g2), Some(gt)]) = v.get(3..9) else {
            continue;
        };
        let _ = g1;
        f.model("boolean", pair, *triangles, pair);
        let b = |f: &mut Facts, key: &str, v: f64| f.add("boolean", pair, key, "s", Stat::exact(v));
        b(f, &format!("time:plain:{op}"), pt);
        b(f, &format!("time:grouped:{op}"), gt);
        if *op == "difference" {
            b(f, "time:phase1", p1);
            b(f, "time:phase2-plain", p2);
            b(f, "time:phase2-grouped", g2);
            b(f, "time:total", gt);
        }
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn every_thesis_table_is_read() {
        let f = super::facts();
        assert_eq!(f.get("inclusion", "Armadillo", "time:cpu").unwrap().value, 20.785783);
        assert_eq!(f.get("inclusion", "Torusknot", "time:tetragrid-64").unwrap().value, 0.001527);
        // Table 4-6's printed numbers only under its own keys, never as a method's time.
        assert_eq!(f.get("inclusion", "Torusknot", "table4-6:basic").unwrap().value, 0.027244);
        assert!(f.get("inclusion", "Torusknot", "time:octants").is_err());
        assert!(f.get("inclusion", "Torusknot", "time:cpu+gpu").is_err());
        assert_eq!(f.get("inclusion", "Torusknot", "time:tetragrid").unwrap().value, 0.001706);
        assert_eq!(f.get("inclusion", "Torusknot", "memory:tetragrid-32").unwrap().value, 953.0);
        assert_eq!(
            f.get("inclusion", "Chinese Dragon", "memory:bsp").unwrap_err().to_string(),
            "stack overflow"
        );
        assert_eq!(f.get("voxelize", "Armadillo", "time:zoned@256").unwrap().value, 0.008743);
        assert_eq!(f.get("subdivide", "row 1: cube", "time:gpu-path").unwrap().value, 0.015 + 0.031);
        assert_eq!(f.models_of("inclusion").len(), 9);
        assert_eq!(f.get("boolean", "Armadillo", "time:grouped:difference").unwrap().value, 102.500169);
        assert_eq!(f.get("boolean", "Torre", "time:phase2-plain").unwrap().value, 0.676856);
        assert_eq!(f.size("boolean", "LionHd"), Some(44032.0));
        assert_eq!(f.models_of("boolean").len(), 12);
    }
}
