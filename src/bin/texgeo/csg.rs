//! `texgeo csg`: a CSG expression over named solids ([`texgeo::boolean::expr`]), one
//! Boolean operation per operator, evaluated like `texgeo boolean`.

use std::ffi::OsString;
use std::os::unix::ffi::OsStrExt as _;
use std::path::PathBuf;

use texgeo::boolean::expr::{Expr, is_name};
use texgeo::mesh::spec::Placed;

use crate::boolean::{Evaluate, Operand, check_mesh_output, run_expression};

#[derive(clap::Args)]
pub struct Args {
    /// The expression, e.g. "(a | b) - c": `|` union, `&` intersection, `-` difference,
    /// `^` symmetric difference, and parentheses. As in Python, `-` binds tightest, then
    /// `&`, then `^`, then `|`, and each goes left to right (`a - b - c` is (a − b) − c).
    /// Each operator is one Boolean operation; its result, its points rounded to f64, is
    /// the operand of the next.
    #[arg(value_name = "EXPR")]
    expr: String,
    /// The operands, each NAME=MESH: a name of the expression (a letter or `_`, then
    /// letters, digits or `_`) and a closed mesh file or `builtin:NAME`; NAME=MESH@STEPS
    /// places it first, with the steps of `boolean --transform-b` (e.g.
    /// a=part.off@"rotate z 90; translate 1 0 0"). Every operand must appear in EXPR.
    #[arg(required = true, value_name = "NAME=MESH[@STEPS]")]
    operands: Vec<OsString>,
    /// Output mesh (.obj .off .ply .stl).
    #[arg(short, long)]
    output: PathBuf,
    #[command(flatten)]
    evaluate: Evaluate,
}

pub fn run(device: Option<&str>, args: Args) -> anyhow::Result<()> {
    // Everything a user can get wrong is checked before any mesh is read.
    let expr = Expr::parse(&args.expr)?;
    let mut operands: Vec<Operand> = Vec::with_capacity(args.operands.len());
    for text in &args.operands {
        let operand = parse_operand(text)?;
        if let Some(first) = operands.iter().find(|o| o.name == operand.name) {
            anyhow::bail!("operand '{}' is given twice ({} and {})", operand.name, first.mesh, operand.mesh);
        }
        operands.push(operand);
    }
    let names: Vec<&str> = operands.iter().map(|o| o.name.as_str()).collect();
    expr.check_names(&names)?;
    let used = expr.names();
    if let Some(unused) = operands.iter().find(|o| !used.iter().any(|(n, _)| *n == o.name)) {
        anyhow::bail!("operand {} is not used in the expression", unused.label);
    }
    check_mesh_output(&args.output, &operands.iter().map(|o| &o.mesh).collect::<Vec<_>>())?;
    run_expression(device, &expr, &operands, &args.output, &args.evaluate, &args.expr)
}

/// NAME=MESH or NAME=MESH@STEPS (MESH@STEPS read by [`Placed`]).
fn parse_operand(text: &OsString) -> anyhow::Result<Operand> {
    let bytes = text.as_bytes();
    let shown = text.to_string_lossy();
    let Some(eq) = bytes.iter().position(|&c| c == b'=') else {
        anyhow::bail!("operand '{shown}': expected NAME=MESH or NAME=MESH@STEPS");
    };
    let name = std::str::from_utf8(&bytes[..eq]).ok().filter(|n| is_name(n)).ok_or_else(|| {
        anyhow::anyhow!(
            "operand '{shown}': '{}' is not a name (a letter or '_', then letters, digits or '_')",
            String::from_utf8_lossy(&bytes[..eq])
        )
    })?;
    let placed = Placed::parse(std::ffi::OsStr::from_bytes(&bytes[eq + 1..]))
        .map_err(|e| anyhow::anyhow!("operand {name}: {e}"))?;
    if placed.spec.file().is_some_and(|f| f.as_os_str().is_empty()) {
        anyhow::bail!("operand '{shown}': expected a mesh file or builtin:NAME after '='");
    }
    let mesh = placed.spec;
    Ok(Operand {
        name: name.to_string(),
        label: format!("{name} ({mesh})"),
        mesh,
        transform: placed.transform,
    })
}
