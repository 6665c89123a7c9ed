//! The worker process (`texgeo sweep worker`, started by [`super::pool`]): it runs meshes
//! one after another on one Vulkan device and one set of pipelines, so a mesh costs its
//! own work plus a JSON line each way.
//!
//! ## Protocol (one JSON object per line)
//!
//! 1. sweep → worker: `{"hello":{"task":"voxelize","options":{…},"device":null}}`, the
//!    sweep-level options with defaults filled in. The worker opens the device if those
//!    options need one.
//! 2. worker → sweep: `{"ready":{"device":"llvmpipe …"}}`, or `{"fatal":{"message":"…"}}`
//!    and exit (no device, unknown task).
//! 3. sweep → worker: `{"job":{"index":3,"mesh":"a.off","path":"/data/a.off","options":{…}}}`;
//!    worker → sweep: `{"result":{…}}`, one [`Record`], for each job.
//! 4. The sweep closes the worker's standard input; the worker exits.
//!
//! Only protocol lines reach the sweep: the worker moves its standard output to a private
//! descriptor and points descriptor 1 at standard error, so a stray print cannot corrupt
//! the stream. A panic, abort or segfault ends the process; the sweep records it for the
//! current mesh from the exit status and the tail of standard error.
//!
//! ## Test-only faults
//!
//! `TEXGEO_SWEEP_FAULT=KIND:MESH[,KIND:MESH…]` makes the worker misbehave on the named
//! meshes, so tests can check that a sweep survives it. KIND is `panic`, `abort`, `segv`,
//! `exit` (status 3), `hang` (sleeps forever), or `oom` (allocates 64 GiB; only under
//! `--memory-limit`, so a test cannot exhaust the machine). Not for use outside tests.

use std::io::{BufRead, Write};
use std::os::fd::FromRawFd as _;
use std::time::Instant;

use serde::{Deserialize, Serialize};
use serde_json::{Map, Value};

use super::record::Record;
use super::task::{Failure, Input, Task, TaskKind, Visit, parse_options};
use crate::gpu::{Context, ContextOptions, DeviceChoice};
use crate::mesh::spec::MeshSpec;
use crate::mesh::{MeshError, validate};

/// Environment variable of the test-only fault hook.
pub const FAULT_VAR: &str = "TEXGEO_SWEEP_FAULT";

/// One mesh to run.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Job {
    pub index: usize,
    pub mesh: String,
    pub path: String,
    /// Complete options for this mesh.
    pub options: Map<String, Value>,
}

/// Messages to a worker.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ToWorker {
    Hello { task: String, options: Map<String, Value>, device: Option<String> },
    Job(Job),
}

/// Messages from a worker.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum FromWorker {
    Ready { device: Option<String> },
    Fatal { message: String },
    Result(Box<Record>),
}

/// Runs the worker on standard input and output until its input ends.
pub fn main() -> std::io::Result<()> {
    let mut out = protocol_output()?;
    let stdin = std::io::stdin();
    let mut lines = stdin.lock().lines();
    let hello = match lines.next() {
        Some(line) => serde_json::from_str::<ToWorker>(&line?),
        None => return Ok(()),
    };
    let (task, options, device) = match hello {
        Ok(ToWorker::Hello { task, options, device }) => (task, options, device),
        Ok(_) => return send(&mut out, &FromWorker::Fatal { message: "expected hello first".into() }),
        Err(e) => return send(&mut out, &FromWorker::Fatal { message: format!("bad hello: {e}") }),
    };
    let Some(kind) = TaskKind::parse(&task) else {
        return send(&mut out, &FromWorker::Fatal { message: format!("unknown task '{task}'") });
    };
    kind.visit(Serve { options, device, lines: &mut lines, out: &mut out })
}

struct Serve<'a, L> {
    options: Map<String, Value>,
    device: Option<String>,
    lines: &'a mut L,
    out: &'a mut std::fs::File,
}

impl<L: Iterator<Item = std::io::Result<String>>> Visit for Serve<'_, L> {
    type Output = std::io::Result<()>;

    fn visit<T: Task>(self) -> std::io::Result<()> {
        let Serve { options, device, lines, out } = self;
        let faults = Faults::from_env();
        let mut ctx = None;
        let opened = parse_options::<T>(&options).and_then(|o| {
            if T::needs_device(&o) {
                ctx = Some(open(device.as_deref())?);
            }
            Ok(())
        });
        if let Err(message) = opened {
            return send(out, &FromWorker::Fatal { message });
        }
        send(out, &FromWorker::Ready { device: ctx.as_ref().map(|c: &Context| c.info().label()) })?;
        let mut task = T::default();
        for line in lines {
            let line = line?;
            match serde_json::from_str::<ToWorker>(&line) {
                Ok(ToWorker::Job(job)) => {
                    let record = run_job(&mut task, &mut ctx, device.as_deref(), &job, &faults);
                    send(out, &FromWorker::Result(Box::new(record)))?;
                }
                Ok(ToWorker::Hello { .. }) => {
                    send(out, &FromWorker::Fatal { message: "hello sent twice".into() })?;
                }
                Err(e) => send(out, &FromWorker::Fatal { message: format!("bad message: {e}") })?,
            }
        }
        Ok(())
    }
}

fn send(out: &mut std::fs::File, msg: &FromWorker) -> std::io::Result<()> {
    let mut line = serde_json::to_vec(msg).map_err(std::io::Error::other)?;
    line.push(b'\n');
    out.write_all(&line)?;
    out.flush()
}

fn open(device: Option<&str>) -> Result<Context, String> {
    let options = ContextOptions { device: DeviceChoice::from_env_or(device), validation: None };
    Context::new(&options).map_err(|e| format!("opening the Vulkan device: {e}"))
}

/// Runs one job; every outcome but a crash comes back as a record.
fn run_job<T: Task>(
    task: &mut T,
    ctx: &mut Option<Context>,
    device: Option<&str>,
    job: &Job,
    faults: &Faults,
) -> Record {
    let start = Instant::now();
    // The kernel's peak-RSS mark reset (Linux ≥ 4.0): the reading below is this mesh's peak.
    crate::host::reset_peak_rss();
    let mut rec = Record::new(job.index, &job.mesh, T::NAME);
    faults.trigger(&job.mesh);
    let result = (|| -> Result<(), Failure> {
        let options = parse_options::<T>(&job.options).map_err(|e| Failure::failed("options", e))?;
        if T::needs_device(&options) && ctx.is_none() {
            *ctx = Some(open(device).map_err(|e| Failure::failed("device", e))?);
        }
        let t = Instant::now();
        let mesh = MeshSpec::parse(&job.path).load().map_err(unreadable)?;
        rec.time("read", t.elapsed());
        let t = Instant::now();
        let report = validate::report(&mesh);
        rec.time("validate", t.elapsed());
        rec.size("vertices", mesh.num_vertices());
        rec.size("faces", mesh.num_faces());
        rec.check("closed", report.is_closed());
        rec.check("oriented", report.is_oriented());
        rec.check("manifold", report.is_manifold());
        task.run(Input { ctx: ctx.as_ref(), mesh: &mesh, report: &report }, &options, &mut rec)
    })();
    if let Err(f) = result {
        rec.outcome = f.outcome;
        rec.reason = f.reason;
        rec.error = f.error;
    }
    rec.time("total", start.elapsed());
    // Without the reset (kernels before 4.0) this is the worker's peak so far.
    rec.peak_rss_kib = crate::host::peak_rss_kib();
    rec
}

fn unreadable(e: MeshError) -> Failure {
    match e {
        MeshError::Io { .. } | MeshError::Parse { .. } | MeshError::Unsuitable(_) => {
            Failure::refused("unreadable", e)
        }
        MeshError::Invalid(_) => Failure::refused("invalid-mesh", e),
    }
}

/// A private descriptor for protocol lines; descriptor 1 then goes to standard error.
fn protocol_output() -> std::io::Result<std::fs::File> {
    // SAFETY: descriptor calls on this process's own standard descriptors; the duplicate
    // is owned by the returned File alone.
    unsafe {
        let fd = libc::fcntl(1, libc::F_DUPFD_CLOEXEC, 3);
        if fd < 0 || libc::dup2(2, 1) < 0 {
            return Err(std::io::Error::last_os_error());
        }
        Ok(std::fs::File::from_raw_fd(fd))
    }
}

/// The test-only fault hook (see the module documentation).
struct Faults(Vec<(String, String)>);

impl Faults {
    fn from_env() -> Faults {
        let spec = std::env::var(FAULT_VAR).unwrap_or_default();
        Faults(
            spec.split(',')
                .filter_map(|f| f.split_once(':'))
                .map(|(k, m)| (k.trim().to_string(), m.trim().to_string()))
                .collect(),
        )
    }

    fn trigger(&self, mesh: &str) {
        let Some((kind, _)) = self.0.iter().find(|(_, m)| m == mesh) else {
            return;
        };
        match kind.as_str() {
            "panic" => panic!("test-only fault: panic on {mesh}"),
            "abort" => std::process::abort(),
            // SAFETY: restoring the default action (std installs a handler for stack
            // overflows) and raising the signal at ourselves: the process ends.
            "segv" => unsafe {
                libc::signal(libc::SIGSEGV, libc::SIG_DFL);
                libc::raise(libc::SIGSEGV);
            },
            "exit" => std::process::exit(3),
            "hang" => loop {
                std::thread::sleep(std::time::Duration::from_secs(3600));
            },
            "oom" => {
                let mut limit = libc::rlimit { rlim_cur: 0, rlim_max: 0 };
                // SAFETY: getrlimit writes into the struct we pass.
                let limited = unsafe { libc::getrlimit(libc::RLIMIT_AS, &mut limit) } == 0
                    && limit.rlim_cur != libc::RLIM_INFINITY;
                if !limited {
                    panic!("test-only fault 'oom' needs --memory-limit");
                }
                let v: Vec<u8> = Vec::with_capacity(64 << 30);
                std::hint::black_box(v);
            }
            other => panic!("unknown test-only fault '{other}'"),
        }
    }
}
