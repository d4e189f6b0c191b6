//! Running one untrusted command (a student's program) with limits and isolation, and saying
//! what happened and which protections were in force.
//!
//! ```text
//! caller (the library, any number of threads)
//!  └─ goldray __sandbox-init      a fresh process with one thread: enters the namespaces,
//!      │                          keeps the output's tail, enforces the wall time, reports
//!      └─ first process           PID 1 of the new PID namespace: mounts, then waits; its end
//!          │                      kills every process left in the namespace
//!          └─ the command         drops capabilities, enters Landlock, sets rlimits,
//!                                 installs the seccomp filter, execs
//! ```
//!
//! Every layer is tried on its own and the run never refuses to happen: where the machine lacks
//! one (an old kernel, a container without user namespaces), the command runs with the others,
//! and [`Protections`] says exactly which held. The layers: a user namespace (root inside, no
//! capability outside), mount, PID, network, IPC and UTS namespaces, the usual folders of other
//! users and services hidden (`/tmp`, `/run`, `/home`…), its own `/proc`, Landlock (write only in
//! the working folder; read only the system's programs and libraries and the job's own paths; no
//! TCP), no capabilities, `no_new_privs`, a seccomp filter (no tracing, kernel modules, BPF,
//! `io_uring`, new namespaces or mounts), and rlimits (CPU, address space, file size, processes,
//! no core files). The wall time is enforced by the init on every machine.
//!
//! The init is the `goldray` binary itself, started with the hidden command [`INIT_COMMAND`]: a
//! library caller names the binary in [`Sandbox::new`] (the command line uses its own path).
//! Linux only: elsewhere [`Sandbox::run`] fails with [`SandboxError::Unsupported`].

mod error;
mod limits;
mod outcome;
mod record;
mod tail;

#[cfg(target_os = "linux")]
mod child;
#[cfg(target_os = "linux")]
mod confine;
#[cfg(target_os = "linux")]
mod init;
#[cfg(target_os = "linux")]
mod landlock;
#[cfg(target_os = "linux")]
mod namespaces;
mod protocol;
#[cfg(target_os = "linux")]
mod seccomp;
mod spawn;

use std::path::PathBuf;

use serde::{Deserialize, Serialize};

pub use error::SandboxError;
pub use limits::{LimitHit, LimitOverrides, Limits, parse_bytes, parse_duration, show_bytes, show_duration};
#[cfg(target_os = "linux")]
pub use namespaces::HIDDEN;
pub use outcome::{Exit, LandlockState, Outcome, Protections, describe_limits, signal_name};
pub use protocol::Reply;
pub use record::{CommandRecord, OutputRecord, RUN_RECORD, RunRecord, Skipped};
pub use spawn::Sandbox;

/// The hidden first argument that makes the `goldray` binary the sandbox's init
/// ([`serve_init`]).
pub const INIT_COMMAND: &str = "__sandbox-init";

/// One command to run.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Job {
    /// The program, by absolute path (no search in `PATH`: the caller decides what runs).
    pub program: PathBuf,
    pub args: Vec<String>,
    /// Where it runs: the one folder it may write, and may read.
    pub working_dir: PathBuf,
    /// Further files and folders it may read (and run), besides the system's programs and
    /// libraries: its own program's folder, a build's copy of the submission.
    pub readable: Vec<PathBuf>,
    /// Its whole environment (nothing of the caller's is passed on unless listed here).
    pub env: Vec<(String, String)>,
}

impl Job {
    /// `program` with `args` in `working_dir`, with a plain environment: the caller's `PATH`,
    /// `HOME` and `TMPDIR` set to the working folder (the only place it may write), the C locale.
    pub fn new(program: impl Into<PathBuf>, args: Vec<String>, working_dir: impl Into<PathBuf>) -> Job {
        let working_dir = working_dir.into();
        let folder = working_dir.to_string_lossy().into_owned();
        let path = std::env::var("PATH").unwrap_or_else(|_| "/usr/local/bin:/usr/bin:/bin".to_owned());
        Job {
            program: program.into(),
            args,
            env: vec![
                ("PATH".to_owned(), path),
                ("HOME".to_owned(), folder.clone()),
                ("TMPDIR".to_owned(), folder),
                ("LC_ALL".to_owned(), "C".to_owned()),
            ],
            working_dir,
            readable: Vec::new(),
        }
    }

    /// The command as it would be typed: the program, then its arguments.
    pub fn argv(&self) -> Vec<String> {
        std::iter::once(self.program.to_string_lossy().into_owned())
            .chain(self.args.iter().cloned())
            .collect()
    }
}

/// The init's side: reads a request (JSON) from `input`, runs it, and returns the reply that the
/// binary writes to its standard output. Must be called first thing in a fresh process that has
/// started no thread (the binary does so for [`INIT_COMMAND`]).
pub fn serve_init(input: impl std::io::Read) -> Reply {
    #[cfg(target_os = "linux")]
    {
        init::serve(input)
    }
    #[cfg(not(target_os = "linux"))]
    {
        let _ = input;
        Reply::Failed("the sandbox needs Linux".to_owned())
    }
}
