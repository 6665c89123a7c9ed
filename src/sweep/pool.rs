//! The sweeping process: J worker processes, one mesh at a time each, a time limit per
//! mesh. A worker that dies (panic, abort, segfault, out of memory) is recorded as its
//! current mesh's result and replaced; one that overruns the limit is killed, recorded as
//! a timeout and replaced. Workers die with the sweep (`PR_SET_PDEATHSIG`), so a killed
//! sweep leaves none behind.

use std::collections::VecDeque;
use std::io::{BufRead as _, BufReader, Write as _};
use std::os::unix::process::{CommandExt as _, ExitStatusExt as _};
use std::path::PathBuf;
use std::process::{Child, ChildStdin, Command, ExitStatus, Stdio};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{Receiver, RecvTimeoutError, channel};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use serde_json::{Map, Value};

use super::manifest::Entry;
use super::record::{Outcome, Record};
use super::task::TaskKind;
use super::worker::{FromWorker, Job, ToWorker};
use super::{Result, SweepError};

/// How long a worker may take to open its device and say it is ready.
const STARTUP: Duration = Duration::from_secs(120);
/// Lines of a worker's standard error kept to explain its death.
const STDERR_TAIL: usize = 40;

/// What a sweep runs and how.
#[derive(Clone, Debug)]
pub struct Plan {
    pub task: TaskKind,
    /// Sweep-level options, defaults filled in ([`TaskKind::options`]).
    pub options: Map<String, Value>,
    /// `--device`, passed on to the workers.
    pub device: Option<String>,
    /// Per-mesh time limit.
    pub timeout: Duration,
    /// Worker processes.
    pub jobs: usize,
    /// Address-space limit of each worker (RLIMIT_AS), MiB.
    pub memory_limit_mib: Option<u64>,
    /// The worker command: the `texgeo` binary and `["sweep", "worker"]`.
    pub program: PathBuf,
    pub args: Vec<String>,
}

impl Plan {
    /// The jobs for `entries`: each entry's options over the sweep's, checked.
    pub fn jobs_for<'a>(
        &self,
        entries: impl IntoIterator<Item = &'a Entry>,
    ) -> Result<Vec<Job>, (Option<usize>, String)> {
        entries
            .into_iter()
            .map(|e| {
                let mut m = self.options.clone();
                m.extend(e.options.clone());
                let options = self.task.options(&m).map_err(|msg| (e.line, msg))?;
                Ok(Job { index: e.index, mesh: e.mesh.clone(), path: e.path.clone(), options })
            })
            .collect()
    }
}

/// Runs `jobs` on `plan.jobs` workers, handing each record to `sink` as it comes (in
/// completion order). Returns the first error of `sink` or of starting a worker; meshes
/// not recorded by then are simply not run.
pub fn run(plan: &Plan, jobs: Vec<Job>, sink: impl FnMut(Record) -> Result<()> + Send) -> Result<()> {
    let queue = Mutex::new(VecDeque::from(jobs));
    let sink = Mutex::new(sink);
    let stop = AtomicBool::new(false);
    let error: Mutex<Option<SweepError>> = Mutex::new(None);
    let slots = plan.jobs.max(1).min(queue.lock().map(|q| q.len()).unwrap_or(1).max(1));
    std::thread::scope(|s| {
        for _ in 0..slots {
            s.spawn(|| {
                if let Err(e) = slot(plan, &queue, &sink, &stop) {
                    stop.store(true, Ordering::SeqCst);
                    if let Ok(mut slot) = error.lock() {
                        slot.get_or_insert(e);
                    }
                }
            });
        }
    });
    match error.into_inner() {
        Ok(Some(e)) => Err(e),
        _ => Ok(()),
    }
}

/// One worker slot: takes jobs until the queue is empty, replacing its worker when it
/// dies or overruns.
fn slot(
    plan: &Plan,
    queue: &Mutex<VecDeque<Job>>,
    sink: &Mutex<impl FnMut(Record) -> Result<()>>,
    stop: &AtomicBool,
) -> Result<()> {
    let mut worker: Option<Worker> = None;
    loop {
        if stop.load(Ordering::SeqCst) {
            break;
        }
        let Some(job) = queue.lock().ok().and_then(|mut q| q.pop_front()) else {
            break;
        };
        let w = match worker.take() {
            Some(w) => w,
            None => Worker::start(plan)?,
        };
        let start = Instant::now();
        let (record, survivor) = w.run(&job, plan);
        let record = record.unwrap_or_else(|(outcome, reason, error)| {
            let mut r = Record::new(job.index, &job.mesh, plan.task.name());
            r.outcome = outcome;
            r.reason = reason;
            r.error = error;
            r.time("total", start.elapsed());
            r
        });
        // A device error may leave the worker's device unusable: start afresh.
        worker = match survivor {
            Some(w) if matches!(record.reason.as_str(), "gpu" | "device") => {
                w.finish();
                None
            }
            other => other,
        };
        let mut sink = sink.lock().map_err(|_| SweepError::Worker("a results writer panicked".into()))?;
        (*sink)(record)?;
    }
    if let Some(w) = worker {
        w.finish();
    }
    Ok(())
}

type Death = (Outcome, String, String);

/// A running worker process.
struct Worker {
    child: Child,
    stdin: ChildStdin,
    lines: Receiver<std::io::Result<String>>,
    stderr: Arc<Mutex<VecDeque<String>>>,
    stderr_done: Receiver<()>,
}

impl Worker {
    fn start(plan: &Plan) -> Result<Worker> {
        let mut cmd = Command::new(&plan.program);
        cmd.args(&plan.args).stdin(Stdio::piped()).stdout(Stdio::piped()).stderr(Stdio::piped());
        // Its own process group: a timeout kills the worker and anything it started.
        cmd.process_group(0);
        let parent = std::process::id();
        let limit = plan.memory_limit_mib.map(|m| m.saturating_mul(1 << 20));
        // SAFETY: only async-signal-safe calls (prctl, getppid, setrlimit, _exit) between
        // fork and exec.
        unsafe {
            cmd.pre_exec(move || {
                libc::prctl(libc::PR_SET_PDEATHSIG, libc::SIGKILL as libc::c_ulong);
                if libc::getppid() as u32 != parent {
                    libc::_exit(1);
                }
                if let Some(bytes) = limit {
                    let rl =
                        libc::rlimit { rlim_cur: bytes as libc::rlim_t, rlim_max: bytes as libc::rlim_t };
                    if libc::setrlimit(libc::RLIMIT_AS, &rl) != 0 {
                        return Err(std::io::Error::last_os_error());
                    }
                }
                Ok(())
            });
        }
        let mut child = cmd
            .spawn()
            .map_err(|e| SweepError::Worker(format!("cannot start {}: {e}", plan.program.display())))?;
        let (Some(stdin), Some(stdout), Some(stderr)) =
            (child.stdin.take(), child.stdout.take(), child.stderr.take())
        else {
            return Err(SweepError::Worker("no pipes to the worker".into()));
        };
        let (tx, lines) = channel();
        std::thread::spawn(move || {
            for line in BufReader::new(stdout).lines() {
                let end = line.is_err();
                if tx.send(line).is_err() || end {
                    break;
                }
            }
        });
        let tail = Arc::new(Mutex::new(VecDeque::new()));
        let (done_tx, stderr_done) = channel();
        let keep = Arc::clone(&tail);
        std::thread::spawn(move || {
            for line in BufReader::new(stderr).lines().map_while(std::result::Result::ok) {
                if let Ok(mut t) = keep.lock() {
                    if t.len() == STDERR_TAIL {
                        t.pop_front();
                    }
                    t.push_back(line);
                }
            }
            let _ = done_tx.send(());
        });
        let mut w = Worker { child, stdin, lines, stderr: tail, stderr_done };
        let hello = ToWorker::Hello {
            task: plan.task.name().to_string(),
            options: plan.options.clone(),
            device: plan.device.clone(),
        };
        if let Err(e) = w.send(&hello) {
            let (_, _, why) = w.death();
            return Err(SweepError::Worker(format!("{e}; {why}")));
        }
        match w.lines.recv_timeout(STARTUP) {
            Ok(Ok(line)) => match serde_json::from_str::<FromWorker>(&line) {
                Ok(FromWorker::Ready { .. }) => Ok(w),
                Ok(FromWorker::Fatal { message }) => {
                    w.kill();
                    Err(SweepError::Worker(message))
                }
                _ => {
                    w.kill();
                    Err(SweepError::Worker(format!("unexpected first line: {line}")))
                }
            },
            Err(RecvTimeoutError::Timeout) => {
                w.kill();
                Err(SweepError::Worker(format!("not ready after {} s", STARTUP.as_secs())))
            }
            _ => {
                let (_, _, why) = w.death();
                Err(SweepError::Worker(format!("it ended before it was ready: {why}")))
            }
        }
    }

    fn send(&mut self, msg: &ToWorker) -> std::io::Result<()> {
        let mut line = serde_json::to_vec(msg).map_err(std::io::Error::other)?;
        line.push(b'\n');
        self.stdin.write_all(&line)?;
        self.stdin.flush()
    }

    /// Runs one job: its record (or why there is none), and the worker if it survived.
    fn run(mut self, job: &Job, plan: &Plan) -> (std::result::Result<Record, Death>, Option<Worker>) {
        if let Ok(mut t) = self.stderr.lock() {
            t.clear();
        }
        if self.send(&ToWorker::Job(job.clone())).is_err() {
            return (Err(self.death()), None);
        }
        match self.lines.recv_timeout(plan.timeout) {
            Ok(Ok(line)) => match serde_json::from_str::<FromWorker>(&line) {
                Ok(FromWorker::Result(record)) if record.index == job.index => (Ok(*record), Some(self)),
                _ => {
                    self.kill();
                    let e = format!("unexpected answer from the worker: {}", truncate(&line, 200));
                    (Err((Outcome::Failed, "protocol".into(), e)), None)
                }
            },
            Err(RecvTimeoutError::Timeout) => {
                self.kill();
                let e = format!("no result within {}; the worker was killed", seconds(plan.timeout));
                (Err((Outcome::Timeout, "timeout".into(), e)), None)
            }
            _ => (Err(self.death()), None),
        }
    }

    /// Kills the worker's process group and reaps it.
    fn kill(&mut self) {
        // SAFETY: signals our own child's process group (its pid, set by process_group(0)).
        unsafe {
            libc::kill(-(self.child.id() as libc::pid_t), libc::SIGKILL);
        }
        let _ = self.child.kill();
        let _ = self.child.wait();
    }

    /// Waits for a worker whose output ended and explains its death.
    fn death(mut self) -> Death {
        let status = wait_timeout(&mut self.child, Duration::from_secs(5));
        // Standard error may still hold the panic message: wait (briefly) for its end.
        let _ = self.stderr_done.recv_timeout(Duration::from_secs(2));
        let tail: Vec<String> = self.stderr.lock().map(|t| t.iter().cloned().collect()).unwrap_or_default();
        match status {
            Some(status) => explain(status, &tail),
            None => {
                self.kill();
                (Outcome::Crashed, "protocol".into(), "the worker closed its output but did not exit".into())
            }
        }
    }

    /// Closes the worker's input (it then exits) and reaps it.
    fn finish(self) {
        let Worker { mut child, stdin, .. } = self;
        drop(stdin);
        if wait_timeout(&mut child, Duration::from_secs(10)).is_none() {
            let _ = child.kill();
            let _ = child.wait();
        }
    }
}

fn wait_timeout(child: &mut Child, limit: Duration) -> Option<ExitStatus> {
    let start = Instant::now();
    loop {
        match child.try_wait() {
            Ok(Some(status)) => return Some(status),
            Ok(None) if start.elapsed() < limit => std::thread::sleep(Duration::from_millis(5)),
            _ => return None,
        }
    }
}

/// Outcome, reason and message for a worker that ended on its own.
fn explain(status: ExitStatus, stderr: &[String]) -> Death {
    let oom = stderr.iter().find(|l| l.starts_with("memory allocation of") && l.ends_with("failed"));
    if let Some(line) = oom {
        return (Outcome::Crashed, "out-of-memory".into(), format!("worker aborted: {line}"));
    }
    if let Some((i, at)) =
        stderr.iter().enumerate().find_map(|(i, l)| l.find("panicked at").map(|at| (i, at)))
    {
        // From "panicked at": the thread's name and id before it vary from run to run.
        let mut msg = stderr[i][at..].trim().to_string();
        if let Some(next) = stderr.get(i + 1).filter(|l| !l.starts_with("note:")) {
            msg = format!("{msg} {}", next.trim());
        }
        return (Outcome::Crashed, "panic".into(), format!("worker {}", truncate(&msg, 400)));
    }
    match (status.signal(), status.code()) {
        (Some(sig), _) => {
            let (reason, what) = match sig {
                libc::SIGSEGV => ("segfault", "segmentation fault (SIGSEGV)"),
                libc::SIGABRT => ("abort", "aborted (SIGABRT)"),
                libc::SIGBUS => ("bus-error", "bus error (SIGBUS)"),
                libc::SIGILL => ("illegal-instruction", "illegal instruction (SIGILL)"),
                libc::SIGFPE => ("arithmetic", "arithmetic exception (SIGFPE)"),
                libc::SIGKILL => ("killed", "killed (SIGKILL; the out-of-memory killer?)"),
                _ => ("signal", "ended by a signal"),
            };
            let detail = if reason == "signal" { format!("{what} {sig}") } else { what.to_string() };
            (Outcome::Crashed, reason.into(), format!("worker died: {detail}"))
        }
        (None, Some(code)) => (Outcome::Crashed, "exit".into(), format!("worker exited with status {code}")),
        (None, None) => (Outcome::Crashed, "exit".into(), "worker ended".into()),
    }
}

fn seconds(d: Duration) -> String {
    let s = d.as_secs_f64();
    if s.fract() == 0.0 { format!("{s:.0} s") } else { format!("{s} s") }
}

fn truncate(s: &str, max: usize) -> String {
    if s.chars().count() <= max {
        s.to_string()
    } else {
        format!("{}…", s.chars().take(max).collect::<String>())
    }
}
