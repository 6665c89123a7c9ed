//! What a sweep runs on one mesh.
//!
//! A task is a type implementing [`Task`]: its options (a serde struct with defaults, so
//! CLI flags and manifest columns fill it by name), the per-worker state it keeps between
//! meshes (pipelines, render targets), and `run`, which records sizes, checks, hashes and
//! phase times into the mesh's [`Record`] and returns a [`Failure`] for a refusal or a
//! failed check. The worker reads the mesh and records what every task shares (vertices,
//! faces, closed / oriented / manifold, read and total time) before calling `run`.
//!
//! To add a task: a module in [`super::tasks`] implementing [`Task`], one arm in
//! [`TaskKind`] (`ALL`, `name`, `visit`), and, if it needs new flags, their names in the
//! CLI (`src/bin/texgeo/sweep.rs`); `--set KEY=VALUE` reaches any option without one.

use serde::Serialize;
use serde::de::DeserializeOwned;
use serde_json::{Map, Value};

use super::record::{Outcome, Record};
use super::tasks;
use crate::gpu::Context;
use crate::mesh::solidity::NotSolid;
use crate::mesh::{Mesh, Report};

/// A refusal or a failure of one mesh.
#[derive(Clone, Debug, PartialEq)]
pub struct Failure {
    pub outcome: Outcome,
    /// A short slug counted in the summary (`not-closed`, `too-large`, `check`, …).
    pub reason: String,
    pub error: String,
}

impl Failure {
    /// The task declines the mesh with a clear error (the answer it would give a user).
    pub fn refused(reason: &str, error: impl std::fmt::Display) -> Failure {
        Failure { outcome: Outcome::Refused, reason: reason.into(), error: error.to_string() }
    }

    /// The mesh is not a solid the command would accept (`mesh::solidity`).
    pub fn not_solid(e: NotSolid) -> Failure {
        Failure::refused(e.defect.slug(), e)
    }

    /// A check failed or an unexpected error happened.
    pub fn failed(reason: &str, error: impl std::fmt::Display) -> Failure {
        Failure { outcome: Outcome::Failed, reason: reason.into(), error: error.to_string() }
    }
}

/// One kind of work a sweep runs on each mesh.
pub trait Task: Default {
    /// The name on the command line (`--task NAME`) and in the results.
    const NAME: &'static str;
    /// The task's options. `#[serde(default, deny_unknown_fields)]`: every option has a
    /// default and a misspelt one is an error.
    type Options: Serialize + DeserializeOwned + Default;

    /// Rejects option values that cannot work, before any mesh runs.
    fn validate(options: &Self::Options) -> Result<(), String>;

    /// Whether these options need a Vulkan device (the worker opens one and keeps it).
    fn needs_device(options: &Self::Options) -> bool;

    /// Runs on one mesh.
    fn run(&mut self, input: Input, options: &Self::Options, out: &mut Record) -> Result<(), Failure>;
}

/// One mesh as a task gets it: the worker's device when [`Task::needs_device`] said so,
/// the mesh, and its validation report (closed, manifold, …).
#[derive(Clone, Copy)]
pub struct Input<'a> {
    pub ctx: Option<&'a Context>,
    pub mesh: &'a Mesh,
    pub report: &'a Report,
}

/// Parses a task's options from JSON (missing keys take their defaults) and validates them.
pub fn parse_options<T: Task>(map: &Map<String, Value>) -> Result<T::Options, String> {
    let options: T::Options =
        serde_json::from_value(Value::Object(map.clone())).map_err(|e| format!("task {}: {e}", T::NAME))?;
    T::validate(&options).map_err(|e| format!("task {}: {e}", T::NAME))?;
    Ok(options)
}

/// Something done with a task type chosen at run time (see [`TaskKind::visit`]).
pub trait Visit {
    type Output;
    fn visit<T: Task>(self) -> Self::Output;
}

/// The tasks `texgeo sweep --task` knows.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum TaskKind {
    Inclusion,
    Voxelize,
    Subdivide,
    Boolean,
}

impl TaskKind {
    pub const ALL: [TaskKind; 4] =
        [TaskKind::Inclusion, TaskKind::Voxelize, TaskKind::Subdivide, TaskKind::Boolean];

    pub fn name(self) -> &'static str {
        match self {
            TaskKind::Inclusion => tasks::inclusion::Inclusion::NAME,
            TaskKind::Voxelize => tasks::voxelize::Voxelize::NAME,
            TaskKind::Subdivide => tasks::subdivide::Subdivide::NAME,
            TaskKind::Boolean => tasks::boolean::BooleanTask::NAME,
        }
    }

    pub fn parse(s: &str) -> Option<TaskKind> {
        TaskKind::ALL.into_iter().find(|t| t.name() == s)
    }

    /// Calls `v.visit::<T>()` with this kind's task type: the one place that maps kinds
    /// to types.
    pub fn visit<V: Visit>(self, v: V) -> V::Output {
        match self {
            TaskKind::Inclusion => v.visit::<tasks::inclusion::Inclusion>(),
            TaskKind::Voxelize => v.visit::<tasks::voxelize::Voxelize>(),
            TaskKind::Subdivide => v.visit::<tasks::subdivide::Subdivide>(),
            TaskKind::Boolean => v.visit::<tasks::boolean::BooleanTask>(),
        }
    }

    /// The complete options (defaults filled in) for `map`, checked.
    pub fn options(self, map: &Map<String, Value>) -> Result<Map<String, Value>, String> {
        struct Effective<'a>(&'a Map<String, Value>);
        impl Visit for Effective<'_> {
            type Output = Result<Map<String, Value>, String>;
            fn visit<T: Task>(self) -> Self::Output {
                let options = parse_options::<T>(self.0)?;
                match serde_json::to_value(&options) {
                    Ok(Value::Object(m)) => Ok(m),
                    Ok(_) => Err(format!("task {}: options are not a JSON object", T::NAME)),
                    Err(e) => Err(e.to_string()),
                }
            }
        }
        self.visit(Effective(map))
    }

    /// Whether options `map` need a Vulkan device.
    pub fn needs_device(self, map: &Map<String, Value>) -> Result<bool, String> {
        struct Needs<'a>(&'a Map<String, Value>);
        impl Visit for Needs<'_> {
            type Output = Result<bool, String>;
            fn visit<T: Task>(self) -> Self::Output {
                Ok(T::needs_device(&parse_options::<T>(self.0)?))
            }
        }
        self.visit(Needs(map))
    }
}

impl std::fmt::Display for TaskKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// A relative error as a check value, rounded to six significant digits.
pub(crate) fn relative(x: f64) -> Value {
    let v = format!("{x:.6e}").parse::<f64>().unwrap_or(x);
    serde_json::Number::from_f64(v).map_or(Value::Null, Value::Number)
}
