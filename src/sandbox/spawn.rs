//! The caller's side: starts the sandbox's init for one command, hands it the job, waits, and
//! reads its report.

use std::io::{Read, Write};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::thread;
use std::time::{Duration, Instant};

use super::error::SandboxError;
use super::limits::Limits;
use super::outcome::Outcome;
use super::protocol::{Reply, Request};
use super::{INIT_COMMAND, Job};

/// How long past the command's wall-time limit the init may take to clean up and report before
/// it is presumed stuck and killed.
const GRACE: Duration = Duration::from_secs(30);

/// Runs jobs in the sandbox, through `init`: the `goldray` binary.
#[derive(Clone, Debug)]
pub struct Sandbox {
    init: PathBuf,
}

impl Sandbox {
    /// `init` is the `goldray` binary (the command line passes its own path; a test passes
    /// `env!("CARGO_BIN_EXE_goldray")`).
    pub fn new(init: impl Into<PathBuf>) -> Sandbox {
        Sandbox { init: init.into() }
    }

    /// Runs `job` within `limits`. An error means the sandbox could not run it at all; a
    /// command that ran and failed, crashed or hit a limit is an [`Outcome`].
    pub fn run(&self, job: &Job, limits: &Limits) -> Result<Outcome, SandboxError> {
        if !cfg!(target_os = "linux") {
            return Err(SandboxError::Unsupported);
        }
        if !job.program.is_absolute() {
            return Err(SandboxError::RelativeProgram(job.program.clone()));
        }
        if !job.working_dir.is_dir() {
            return Err(SandboxError::WorkingDir(job.working_dir.clone()));
        }
        let request = serde_json::to_vec(&Request {
            job: job.clone(),
            limits: limits.clone(),
        })?;
        let mut child = Command::new(&self.init)
            .arg(INIT_COMMAND)
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .map_err(|source| SandboxError::Start {
                init: self.init.clone(),
                source,
            })?;
        if let Some(mut stdin) = child.stdin.take() {
            // An init that died at once is reported below, from its status and stderr.
            let _ = stdin.write_all(&request);
        }
        let stdout = child
            .stdout
            .take()
            .map(|out| thread::spawn(move || read_all(out, usize::MAX)));
        let stderr = child
            .stderr
            .take()
            .map(|err| thread::spawn(move || read_all(err, 64 << 10)));
        let status = wait_until(&mut child, Instant::now() + limits.wall + GRACE);
        let stdout = stdout.and_then(|t| t.join().ok()).unwrap_or_default();
        let stderr = stderr.and_then(|t| t.join().ok()).unwrap_or_default();
        let Some(status) = status else {
            return Err(SandboxError::Hung(GRACE.as_secs()));
        };
        match serde_json::from_slice::<Reply>(&stdout) {
            Ok(Reply::Done(outcome)) => Ok(*outcome),
            Ok(Reply::Failed(message)) => Err(SandboxError::Setup(message)),
            Err(_) => Err(SandboxError::NoReport {
                status: status.to_string(),
                stderr: String::from_utf8_lossy(&stderr).into_owned(),
            }),
        }
    }

    pub fn init(&self) -> &Path {
        &self.init
    }
}

/// Waits for the init until `deadline`; past it, kills its whole process group (it leads one)
/// and returns `None`.
fn wait_until(child: &mut Child, deadline: Instant) -> Option<std::process::ExitStatus> {
    loop {
        match child.try_wait() {
            Ok(Some(status)) => return Some(status),
            Ok(None) if Instant::now() < deadline => thread::sleep(Duration::from_millis(10)),
            _ => {
                if let Some(pid) = rustix::process::Pid::from_raw(child.id() as i32) {
                    let _ = rustix::process::kill_process_group(pid, rustix::process::Signal::KILL);
                }
                let _ = child.kill();
                let _ = child.wait();
                return None;
            }
        }
    }
}

/// Everything `reader` gives, keeping at most the last `keep` bytes.
fn read_all(mut reader: impl Read, keep: usize) -> Vec<u8> {
    let mut kept = Vec::new();
    let mut buffer = [0u8; 16 << 10];
    loop {
        match reader.read(&mut buffer) {
            Ok(0) => break,
            Ok(n) => {
                kept.extend_from_slice(&buffer[..n]);
                if kept.len() > keep {
                    kept.drain(..kept.len() - keep);
                }
            }
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
            Err(_) => break,
        }
    }
    kept
}
