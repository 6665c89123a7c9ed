//! `texgeo._texgeo`: the native half of the Python package. Every function calls the
//! library the `texgeo` command line calls; arrays cross as little-endian bytes (the
//! Python half, `texgeo/__init__.py`, turns them into NumPy arrays and back). The GIL is
//! released while texgeo works, and the work runs in the pool `set_threads` sized.

use std::sync::{Arc, Mutex, RwLock};

use glam::DVec3;
use pyo3::create_exception;
use pyo3::exceptions::PyException;
use pyo3::prelude::*;
use pyo3::types::PyByteArray;
use texgeo::boolean::expr::{self, Expr};
use texgeo::boolean::{self, Names, Operation};
use texgeo::gpu::{Context, ContextOptions, DeviceChoice, GpuError};
use texgeo::inclusion::solver::classify_accepted;
use texgeo::mesh::solidity::{self, Policy};
use texgeo::mesh::spec::Placed;
use texgeo::mesh::stats::Stats;
use texgeo::mesh::{Mesh, formats, procedural, triangulate};
use texgeo::subdiv::tags::{self, TaggedOptions};
use texgeo::subdiv::{Boundary, Features, Method, Surface};
use texgeo::voxel::{Choice, Grid, Volume, npy};

create_exception!(_texgeo, Error, PyException, "Every error texgeo raises: the CLI's one-line message.");
create_exception!(_texgeo, MeshError, Error, "A mesh or array that cannot be read or used.");
create_exception!(_texgeo, NotASolid, MeshError, "The mesh is not a closed solid (the message says why).");
create_exception!(_texgeo, DeviceError, Error, "No Vulkan device, or the device failed.");
create_exception!(_texgeo, InclusionError, Error, "Point-in-solid classification failed.");
create_exception!(_texgeo, VoxelError, Error, "Voxelization failed.");
create_exception!(_texgeo, SubdivisionError, Error, "Subdivision failed.");
create_exception!(_texgeo, BooleanError, Error, "A Boolean operation or CSG expression failed.");

/// The error and its causes on one line, each cause once (as the CLI prints them).
fn one_line(e: &(dyn std::error::Error + 'static)) -> String {
    let mut out = String::new();
    let mut cause: Option<&(dyn std::error::Error + 'static)> = Some(e);
    while let Some(c) = cause {
        let text = c.to_string();
        if !out.contains(&text) {
            if !out.is_empty() {
                out.push_str(": ");
            }
            out.push_str(&text);
        }
        cause = c.source();
    }
    out.lines().map(str::trim).collect::<Vec<_>>().join(" ")
}

/// Which exception class an error raises: a GPU failure anywhere in its chain is a
/// `DeviceError`, the rest `kind`.
#[derive(Clone, Copy)]
enum Kind {
    Mesh,
    NotASolid,
    Inclusion,
    Voxel,
    Subdivision,
    Boolean,
    Plain,
}

fn raise(kind: Kind, e: &(dyn std::error::Error + 'static)) -> PyErr {
    let msg = one_line(e);
    let mut cause: Option<&(dyn std::error::Error + 'static)> = Some(e);
    while let Some(c) = cause {
        if c.is::<GpuError>() {
            return DeviceError::new_err(msg);
        }
        cause = c.source();
    }
    match kind {
        Kind::Mesh => MeshError::new_err(msg),
        Kind::NotASolid => NotASolid::new_err(msg),
        Kind::Inclusion => InclusionError::new_err(msg),
        Kind::Voxel => VoxelError::new_err(msg),
        Kind::Subdivision => SubdivisionError::new_err(msg),
        Kind::Boolean => BooleanError::new_err(msg),
        Kind::Plain => Error::new_err(msg),
    }
}

/// `map_err` for library errors.
fn err<E: std::error::Error + 'static>(kind: Kind) -> impl Fn(E) -> PyErr {
    move |e| raise(kind, &e)
}

/// The pool `set_threads` made (none: rayon's global pool, every core).
static POOL: RwLock<Option<Arc<rayon::ThreadPool>>> = RwLock::new(None);

/// The device, opened on first use and kept for the process.
static DEVICE: Mutex<Option<Context>> = Mutex::new(None);

/// Runs `f` without the GIL, in the pool of `set_threads`.
fn work<T: Send>(py: Python<'_>, f: impl FnOnce() -> T + Send) -> T {
    let pool = POOL.read().ok().and_then(|p| p.clone());
    py.allow_threads(move || match pool {
        Some(pool) => pool.install(f),
        None => f(),
    })
}

/// The device (TEXGEO_DEVICE, else the first GPU, else lavapipe), opened once.
fn context() -> Result<Context, GpuError> {
    let mut slot = DEVICE.lock().unwrap_or_else(|p| p.into_inner());
    if let Some(ctx) = slot.as_ref() {
        return Ok(ctx.clone());
    }
    let ctx = Context::new(&ContextOptions { device: DeviceChoice::from_env_or(None), validation: None })?;
    *slot = Some(ctx.clone());
    Ok(ctx)
}

/// A polygon mesh, with the sharp-feature tags of the OBJ file it came from.
#[pyclass(module = "texgeo._texgeo", frozen)]
struct RawMesh {
    mesh: Mesh,
    features: Features,
    options: TaggedOptions,
}

impl RawMesh {
    fn plain(mesh: Mesh) -> RawMesh {
        RawMesh { mesh, features: Features::default(), options: TaggedOptions::default() }
    }
}

fn f64s(bytes: &[u8]) -> impl Iterator<Item = f64> + '_ {
    bytes.chunks_exact(8).map(|c| f64::from_le_bytes(c.try_into().unwrap_or([0; 8])))
}

fn points_of(bytes: &[u8], what: &str) -> PyResult<Vec<DVec3>> {
    if bytes.len() % 24 != 0 {
        return Err(MeshError::new_err(format!("{what}: expected an (n, 3) float64 array")));
    }
    let values: Vec<f64> = f64s(bytes).collect();
    if let Some(i) = values.iter().position(|v| !v.is_finite()) {
        return Err(MeshError::new_err(format!(
            "{what}: row {} has a coordinate that is not a finite number ({})",
            i / 3,
            values[i]
        )));
    }
    Ok(values.chunks_exact(3).map(|c| DVec3::new(c[0], c[1], c[2])).collect())
}

fn bytes_of<'py>(py: Python<'py>, data: &[u8]) -> Bound<'py, PyByteArray> {
    PyByteArray::new(py, data)
}

fn i64_bytes(values: impl Iterator<Item = i64>) -> Vec<u8> {
    values.flat_map(i64::to_le_bytes).collect()
}

#[pymethods]
impl RawMesh {
    /// From float64 vertex bytes (n × 3), face offsets (m + 1) and int64 index bytes.
    #[staticmethod]
    fn from_arrays(vertices: &[u8], offsets: Vec<usize>, indices: &[u8]) -> PyResult<RawMesh> {
        let positions = points_of(vertices, "vertices")?;
        let n = positions.len();
        let mut idx = Vec::with_capacity(indices.len() / 8);
        for (i, c) in indices.chunks_exact(8).enumerate() {
            let v = i64::from_le_bytes(c.try_into().unwrap_or([0; 8]));
            if v < 0 || v as u64 >= n as u64 {
                return Err(MeshError::new_err(format!(
                    "faces: index {v} (corner {i}) is outside 0..{n} (the vertices)"
                )));
            }
            idx.push(v as u32);
        }
        if offsets.first() != Some(&0)
            || offsets.last() != Some(&idx.len())
            || offsets.windows(2).any(|w| w[0] > w[1])
        {
            return Err(MeshError::new_err("faces: inconsistent face offsets"));
        }
        Mesh::from_parts(positions, offsets, idx).map(RawMesh::plain).map_err(err(Kind::Mesh))
    }

    #[getter]
    fn num_vertices(&self) -> usize {
        self.mesh.num_vertices()
    }

    #[getter]
    fn num_faces(&self) -> usize {
        self.mesh.num_faces()
    }

    fn vertices<'py>(&self, py: Python<'py>) -> Bound<'py, PyByteArray> {
        let bytes: Vec<u8> =
            self.mesh.positions().iter().flat_map(|p| p.to_array()).flat_map(f64::to_le_bytes).collect();
        bytes_of(py, &bytes)
    }

    /// (offsets as int64 bytes, indices as int64 bytes).
    fn face_parts<'py>(&self, py: Python<'py>) -> (Bound<'py, PyByteArray>, Bound<'py, PyByteArray>) {
        let (offsets, indices) = self.mesh.face_parts();
        (
            bytes_of(py, &i64_bytes(offsets.iter().map(|&o| o as i64))),
            bytes_of(py, &i64_bytes(indices.iter().map(|&i| i64::from(i)))),
        )
    }

    /// Triangle index bytes (int64): planar polygons triangulated in their plane as
    /// `mesh convert` does, over the same vertices.
    fn triangles<'py>(&self, py: Python<'py>) -> Bound<'py, PyByteArray> {
        let m = &self.mesh;
        let bytes = work(py, || {
            let tris: Vec<[u32; 3]> =
                m.faces().flat_map(|f| triangulate::face_triangles(m.positions(), f)).collect();
            i64_bytes(tris.iter().flatten().map(|&i| i64::from(i)))
        });
        bytes_of(py, &bytes)
    }

    fn save(&self, py: Python<'_>, path: std::path::PathBuf) -> PyResult<()> {
        work(py, || formats::write(&path, &self.mesh)).map_err(err(Kind::Mesh))
    }

    /// `texgeo mesh stats --json`.
    fn stats_json(&self, py: Python<'_>) -> PyResult<String> {
        let stats = work(py, || Stats::of(&self.mesh))
            .map_err(|d| MeshError::new_err(format!("cannot measure it: {d}")))?;
        serde_json::to_string(&stats).map_err(|e| Error::new_err(e.to_string()))
    }

    /// Labels (0 outside, 1 inside, 2 on the boundary) as bytes, and the method that ran.
    #[pyo3(signature = (points, method = "auto", allow_open = false, flip_inverted = false))]
    fn contains<'py>(
        &self,
        py: Python<'py>,
        points: &[u8],
        method: &str,
        allow_open: bool,
        flip_inverted: bool,
    ) -> PyResult<(Bound<'py, PyByteArray>, String)> {
        let method = inclusion_method(method, Kind::Inclusion)?;
        let points = points_of(points, "points")?;
        let policy = Policy { allow_open, flip_inverted, ..Policy::default() };
        let mesh = &self.mesh;
        let (classes, name) = work(py, || {
            let solid = solidity::require_solid(mesh.clone(), policy).map_err(err(Kind::NotASolid))?;
            classify_accepted(&solid, &points, method, allow_open, context).map_err(err(Kind::Inclusion))
        })?;
        let bytes: Vec<u8> = classes.iter().map(|&c| c as u8).collect();
        Ok((bytes_of(py, &bytes), name))
    }

    #[pyo3(signature = (res, method = "auto", allow_open = false, flip_inverted = false))]
    fn voxelize(
        &self,
        py: Python<'_>,
        res: usize,
        method: &str,
        allow_open: bool,
        flip_inverted: bool,
    ) -> PyResult<RawVoxels> {
        let choice: Choice = method.parse().map_err(|e: String| VoxelError::new_err(e))?;
        texgeo::voxel::grid::check_resolution(res).map_err(err(Kind::Voxel))?;
        let policy = Policy { allow_open, flip_inverted, ..Policy::default() };
        let mesh = &self.mesh;
        let (grid, volume, method) = work(py, || {
            let solid = solidity::require_solid(mesh.clone(), policy).map_err(err(Kind::NotASolid))?;
            texgeo::voxel::voxelize_accepted(&solid, res, choice, || Ok(context()?)).map_err(err(Kind::Voxel))
        })?;
        Ok(RawVoxels { grid, volume, method })
    }

    #[pyo3(signature = (level, method = "gpu", boundary = None, crease_angle = None, crease_sharpness = 10.0))]
    fn subdivide(
        &self,
        py: Python<'_>,
        level: u32,
        method: &str,
        boundary: Option<&str>,
        crease_angle: Option<f64>,
        crease_sharpness: f32,
    ) -> PyResult<RawMesh> {
        let Some(method) = texgeo::choice::parse::<Method>(method) else {
            return Err(SubdivisionError::new_err(format!(
                "unknown method '{method}' (expected gpu or cpu)"
            )));
        };
        let mut surface = Surface {
            mesh: self.mesh.clone(),
            features: self.features.clone(),
            options: self.options.over(Default::default()),
        };
        if let Some(b) = boundary {
            surface.options.boundary = match b {
                "none" => Boundary::None,
                "edge-only" => Boundary::EdgeOnly,
                "edge-and-corner" => Boundary::EdgeAndCorner,
                b => {
                    return Err(SubdivisionError::new_err(format!(
                        "unknown boundary '{b}' (expected none, edge-only or edge-and-corner)"
                    )));
                }
            };
        }
        if let Some(degrees) = crease_angle {
            if !(0.0..=180.0).contains(&degrees) {
                return Err(SubdivisionError::new_err("crease_angle must be in 0..=180 degrees"));
            }
            if !(crease_sharpness.is_finite() && crease_sharpness >= 0.0) {
                return Err(SubdivisionError::new_err("crease_sharpness must be a finite number ≥ 0"));
            }
            let features = Features::feature_edges(&surface.mesh, degrees, crease_sharpness);
            surface.features.creases.extend(features.creases);
        }
        let mesh = work(py, || -> PyResult<Mesh> {
            match method {
                Method::Gpu => {
                    let ctx = context().map_err(err(Kind::Plain))?;
                    let run = texgeo::subdiv::gpu::refine_surface(&ctx, &surface, level)
                        .map_err(err(Kind::Subdivision))?;
                    Ok(run.mesh)
                }
                Method::Cpu => {
                    let refined = texgeo::subdiv::cpu::refine_surface(&surface, level)
                        .map_err(err(Kind::Subdivision))?;
                    Ok(refined.mesh)
                }
            }
        })?;
        Ok(RawMesh::plain(mesh))
    }
}

/// A voxel volume on its grid.
#[pyclass(module = "texgeo._texgeo", frozen)]
struct RawVoxels {
    grid: Grid,
    volume: Volume,
    method: String,
}

#[pymethods]
impl RawVoxels {
    #[getter]
    fn n(&self) -> usize {
        self.grid.n
    }

    #[getter]
    fn origin(&self) -> [f64; 3] {
        self.grid.cube_out().0.to_array()
    }

    #[getter]
    fn pitch(&self) -> f64 {
        let (_, side) = self.grid.cube_out();
        side / self.grid.n as f64
    }

    #[getter]
    fn method(&self) -> String {
        self.method.clone()
    }

    /// Every voxel, [x, y, z] order, one byte each.
    fn occupied<'py>(&self, py: Python<'py>) -> Bound<'py, PyByteArray> {
        let v = &self.volume;
        let bytes = work(py, || npy::bytes_xyz(v));
        bytes_of(py, &bytes)
    }

    /// Writes `.binvox` or `.npy` (with its grid in a `.json` beside it).
    fn save(&self, py: Python<'_>, path: std::path::PathBuf) -> PyResult<()> {
        texgeo::output::check_extension(
            &path,
            &["binvox", "npy"],
            "the volume is written as binvox or NumPy",
        )
        .map_err(err(Kind::Voxel))?;
        work(py, || npy::write_by_extension(&path, &self.grid, &self.volume)).map_err(err(Kind::Voxel))
    }
}

/// Reads a mesh file (with its OBJ tags) or `builtin:NAME`, placed by the steps after
/// `@` if any (`PATH@STEPS`).
#[pyfunction]
fn load(py: Python<'_>, path: std::path::PathBuf) -> PyResult<RawMesh> {
    let placed = Placed::parse(path.as_os_str())
        .map_err(|e| MeshError::new_err(format!("{}: {e}", path.display())))?;
    let spec = &placed.spec;
    let tagged = work(py, || -> PyResult<_> {
        let (mesh, t) = spec.load_with_tags().map_err(err(Kind::Mesh))?;
        let mesh = match &placed.transform {
            Some(steps) => steps.apply(&mesh).map_err(err(Kind::Mesh))?,
            None => mesh,
        };
        // Built-in models have no tags, hence no file to name.
        tags::interpret(mesh, &t, spec.file().unwrap_or(std::path::Path::new(""))).map_err(err(Kind::Mesh))
    })?;
    Ok(RawMesh { mesh: tagged.mesh, features: tagged.features, options: tagged.options })
}

/// An inclusion method by its command-line name (`auto` included), as `--method` takes it.
fn inclusion_method(name: &str, kind: Kind) -> PyResult<texgeo::inclusion::Choice> {
    name.parse::<texgeo::inclusion::Choice>().map_err(|_| {
        let expected: Vec<&str> = std::iter::once("auto")
            .chain(texgeo::inclusion::Method::ALL.map(texgeo::inclusion::Method::name))
            .collect();
        let msg = format!("unknown inclusion method '{name}' (expected one of: {})", expected.join(", "));
        match kind {
            Kind::Boolean => BooleanError::new_err(msg),
            _ => InclusionError::new_err(msg),
        }
    })
}

/// The names of the built-in models.
#[pyfunction]
fn builtins() -> Vec<&'static str> {
    procedural::BUILTIN_NAMES.to_vec()
}

fn boolean_options(method: &str, allow_self_intersections: bool) -> PyResult<boolean::Options> {
    let method = inclusion_method(method, Kind::Boolean)?;
    Ok(boolean::Options { method, allow_self_intersections, ..boolean::Options::default() })
}

#[pyfunction]
#[pyo3(signature = (a, b, op, method = "octants", allow_self_intersections = false))]
fn boolean_op(
    py: Python<'_>,
    a: &RawMesh,
    b: &RawMesh,
    op: &str,
    method: &str,
    allow_self_intersections: bool,
) -> PyResult<RawMesh> {
    let op: Operation = op.parse().map_err(|e: String| BooleanError::new_err(e))?;
    let options = boolean_options(method, allow_self_intersections)?;
    let mesh = work(py, || -> PyResult<Mesh> {
        let ctx = if options.method.is_cpu() { None } else { Some(context().map_err(err(Kind::Plain))?) };
        let names = Names { a: "a", b: "b" };
        let ev =
            boolean::evaluate(&a.mesh, &b.mesh, names, &options, ctx.as_ref()).map_err(err(Kind::Boolean))?;
        Ok(ev.output(op, true).map_err(err(Kind::Boolean))?.mesh)
    })?;
    Ok(RawMesh::plain(mesh))
}

#[pyfunction]
#[pyo3(signature = (text, names, meshes, method = "octants", allow_self_intersections = false))]
fn csg(
    py: Python<'_>,
    text: &str,
    names: Vec<String>,
    meshes: Vec<PyRef<'_, RawMesh>>,
    method: &str,
    allow_self_intersections: bool,
) -> PyResult<RawMesh> {
    let e = Expr::parse(text).map_err(err(Kind::Boolean))?;
    let known: Vec<&str> = names.iter().map(String::as_str).collect();
    e.check_names(&known).map_err(err(Kind::Boolean))?;
    let used = e.names();
    if let Some(unused) = names.iter().find(|n| !used.iter().any(|(u, _)| u == n)) {
        return Err(BooleanError::new_err(format!("operand {unused} is not used in the expression")));
    }
    let options = boolean_options(method, allow_self_intersections)?;
    let operands: Vec<expr::Operand> = names
        .iter()
        .zip(&meshes)
        .map(|(n, m)| expr::Operand { name: n.clone(), label: n.clone(), mesh: m.mesh.clone() })
        .collect();
    let mesh = work(py, || -> PyResult<Mesh> {
        let ctx = if options.method.is_cpu() { None } else { Some(context().map_err(err(Kind::Plain))?) };
        expr::evaluate(&e, &operands, &options, ctx.as_ref(), |_| {}).map_err(err(Kind::Boolean))
    })?;
    Ok(RawMesh::plain(mesh))
}

/// `texgeo info --json`: the device, opened if it was not.
#[pyfunction]
fn device_json(py: Python<'_>) -> PyResult<String> {
    let ctx = work(py, context).map_err(err(Kind::Plain))?;
    let value = serde_json::json!({ "device": ctx.info(), "validation": ctx.validating() });
    Ok(value.to_string())
}

/// Runs texgeo's work on `n` threads from now on (the answers do not depend on it).
#[pyfunction]
fn set_threads(n: usize) -> PyResult<()> {
    if n == 0 || n > 1024 {
        return Err(Error::new_err(format!("{n} threads: expected 1 to 1024")));
    }
    let pool =
        rayon::ThreadPoolBuilder::new().num_threads(n).build().map_err(|e| Error::new_err(e.to_string()))?;
    *POOL.write().unwrap_or_else(|p| p.into_inner()) = Some(Arc::new(pool));
    Ok(())
}

#[pymodule]
fn _texgeo(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("Error", py.get_type::<Error>())?;
    m.add("MeshError", py.get_type::<MeshError>())?;
    m.add("NotASolid", py.get_type::<NotASolid>())?;
    m.add("DeviceError", py.get_type::<DeviceError>())?;
    m.add("InclusionError", py.get_type::<InclusionError>())?;
    m.add("VoxelError", py.get_type::<VoxelError>())?;
    m.add("SubdivisionError", py.get_type::<SubdivisionError>())?;
    m.add("BooleanError", py.get_type::<BooleanError>())?;
    m.add_class::<RawMesh>()?;
    m.add_class::<RawVoxels>()?;
    m.add_function(wrap_pyfunction!(load, m)?)?;
    m.add_function(wrap_pyfunction!(builtins, m)?)?;
    m.add_function(wrap_pyfunction!(boolean_op, m)?)?;
    m.add_function(wrap_pyfunction!(csg, m)?)?;
    m.add_function(wrap_pyfunction!(device_json, m)?)?;
    m.add_function(wrap_pyfunction!(set_threads, m)?)?;
    Ok(())
}
