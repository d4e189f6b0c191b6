//! What happened to a sandboxed command: how it ended, what it used, what it printed last, and
//! which protections were in force while it ran.

use std::fmt;

use serde::{Deserialize, Serialize};

use super::limits::{LimitHit, Limits, show_bytes};

/// How the command's own process ended.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Exit {
    /// It exited with this code.
    Code(i32),
    /// A signal ended it (a crash: SIGSEGV, SIGABRT; or a limit: SIGXCPU, SIGXFSZ, SIGKILL).
    Signal { number: i32, name: String },
}

impl Exit {
    pub fn signal(number: i32) -> Exit {
        Exit::Signal {
            number,
            name: signal_name(number),
        }
    }
}

impl fmt::Display for Exit {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Exit::Code(code) => write!(f, "exit code {code}"),
            Exit::Signal { name, .. } => write!(f, "{name}"),
        }
    }
}

/// What one command did.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Outcome {
    pub exit: Exit,
    /// The limit that stopped it, if one did.
    pub limit: Option<LimitHit>,
    pub wall_seconds: f64,
    /// User and system time of every process of the command that ended.
    pub cpu_seconds: f64,
    /// The largest resident set of any one of its processes.
    pub peak_memory_bytes: u64,
    /// The last [`Limits::output_bytes`] of stdout and of stderr, as UTF-8 (invalid bytes
    /// replaced).
    pub stdout_tail: String,
    pub stderr_tail: String,
    /// Everything it wrote to each, kept or not.
    pub stdout_bytes: u64,
    pub stderr_bytes: u64,
    pub protections: Protections,
}

impl Outcome {
    /// Exit code 0 within every limit.
    pub fn succeeded(&self) -> bool {
        self.exit == Exit::Code(0) && self.limit.is_none()
    }

    /// One line for a summary or a grade: `exit code 0 after 1.2 s`, `crashed: SIGSEGV after
    /// 0.4 s`, `timed out after 60 s`, `memory limit (4 GiB); exit code 1 after 0.1 s`.
    pub fn describe(&self, limits: &Limits) -> String {
        let time = format!("after {:.1} s", self.wall_seconds);
        let ending = match &self.exit {
            Exit::Code(code) => format!("exit code {code} {time}"),
            Exit::Signal { name, .. } => format!("crashed: {name} {time}"),
        };
        match self.limit {
            Some(LimitHit::WallTime) => LimitHit::WallTime.describe(limits),
            Some(hit) => format!("{}; {ending}", hit.describe(limits)),
            None => ending,
        }
    }
}

/// Which protections were in force for one command: each layer the sandbox tried, whether it
/// held, and why not when it did not.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Protections {
    /// Its own user namespace: root inside (for the namespaces below) without any capability
    /// outside; the process limit counts the command's processes only.
    pub user_namespace: bool,
    /// Its own mount table: the folders below are hidden, `/proc` is its own.
    pub mount_namespace: bool,
    /// Its own process IDs: it sees only its processes, and when its first process ends every
    /// process it left behind is killed.
    pub pid_namespace: bool,
    /// Its own network, with no interface up: no connection anywhere, not even to 127.0.0.1.
    pub network_namespace: bool,
    /// Its own System V IPC and host name.
    pub ipc_namespace: bool,
    /// A `/proc` showing only the command's processes.
    pub private_proc: bool,
    /// Folders covered by an empty file system for the command (`/tmp`, `/run`, `/home`…), so
    /// that other users' files and sockets there are out of reach; the command's own folders
    /// inside them are mounted back.
    pub hidden: Vec<String>,
    /// Landlock, if the kernel has it.
    pub landlock: Option<LandlockState>,
    /// `no_new_privs`: no set-user-ID program can give the command more rights.
    pub no_new_privs: bool,
    /// No capability, and none granted by running a program as root.
    pub capabilities_dropped: bool,
    /// The seccomp filter: tracing, kernel modules, BPF, `io_uring`, new namespaces and mounts
    /// and the like are refused (see `sandbox::seccomp`).
    #[serde(default)]
    pub seccomp: bool,
    /// The resource limits set (`cpu`, `address-space`, `file-size`, `processes`, `core`).
    pub rlimits: Vec<String>,
    /// How the number of processes is bounded, in words (`RLIMIT_NPROC 256`, `pid_max 301`), or
    /// `None` when it is not.
    pub process_bound: Option<String>,
    /// Why each layer that is not in force is not: `"user namespace: Operation not permitted"`.
    pub unavailable: Vec<String>,
}

/// What Landlock enforced.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct LandlockState {
    /// The ABI version used (the kernel's, or the newest this build knows).
    pub abi: u32,
    /// Reads, writes and runs confined to the allowed folders.
    pub filesystem: bool,
    /// TCP connect and bind refused (ABI 4 and later).
    pub network: bool,
    /// Signals and abstract sockets confined to the command (ABI 6 and later).
    pub scopes: bool,
}

impl Protections {
    /// The layers in force, as a line: `user, mount, PID, network and IPC namespaces; Landlock
    /// ABI 7 (files, TCP, scopes); …`.
    pub fn summary(&self) -> String {
        let mut parts = Vec::new();
        let namespaces: Vec<&str> = [
            (self.user_namespace, "user"),
            (self.mount_namespace, "mount"),
            (self.pid_namespace, "PID"),
            (self.network_namespace, "network"),
            (self.ipc_namespace, "IPC"),
        ]
        .iter()
        .filter(|(on, _)| *on)
        .map(|(_, name)| *name)
        .collect();
        if !namespaces.is_empty() {
            parts.push(format!("{} namespaces", join_and(&namespaces)));
        }
        if self.private_proc {
            parts.push("own /proc".to_owned());
        }
        if !self.hidden.is_empty() {
            parts.push(format!("hidden: {}", self.hidden.join(" ")));
        }
        if let Some(landlock) = self.landlock.as_ref().filter(|l| l.filesystem || l.network) {
            let mut what = Vec::new();
            if landlock.filesystem {
                what.push("files");
            }
            if landlock.network {
                what.push("TCP");
            }
            if landlock.scopes {
                what.push("signals");
            }
            parts.push(format!("Landlock ABI {} ({})", landlock.abi, what.join(", ")));
        }
        if self.no_new_privs {
            parts.push("no_new_privs".to_owned());
        }
        if self.capabilities_dropped {
            parts.push("no capabilities".to_owned());
        }
        if self.seccomp {
            parts.push("seccomp".to_owned());
        }
        if !self.rlimits.is_empty() {
            parts.push(format!("rlimits: {}", self.rlimits.join(", ")));
        }
        if let Some(bound) = &self.process_bound {
            parts.push(format!("processes: {bound}"));
        }
        if parts.is_empty() {
            "none (only the wall-time limit)".to_owned()
        } else {
            parts.join("; ")
        }
    }

    /// Whether the command could neither write outside its folder nor read private files:
    /// Landlock's file rules held.
    pub fn filesystem_confined(&self) -> bool {
        self.landlock.as_ref().is_some_and(|l| l.filesystem)
    }

    /// Whether the command had no network: its own network namespace, or Landlock's TCP rules.
    pub fn network_cut(&self) -> bool {
        self.network_namespace || self.landlock.as_ref().is_some_and(|l| l.network)
    }

    /// Whether no process of the command can outlive it: its own PID namespace (or, failing
    /// that, the sandbox kills what is left among its descendants, which a process can escape
    /// only by leaving them).
    pub fn leftovers_killed(&self) -> bool {
        self.pid_namespace
    }
}

fn join_and(items: &[&str]) -> String {
    match items {
        [] => String::new(),
        [one] => (*one).to_owned(),
        [rest @ .., last] => format!("{} and {last}", rest.join(", ")),
    }
}

/// `SIGSEGV`, `SIGABRT`…, or `signal 40` for one without a name.
pub fn signal_name(number: i32) -> String {
    const NAMES: [&str; 32] = [
        "",
        "SIGHUP",
        "SIGINT",
        "SIGQUIT",
        "SIGILL",
        "SIGTRAP",
        "SIGABRT",
        "SIGBUS",
        "SIGFPE",
        "SIGKILL",
        "SIGUSR1",
        "SIGSEGV",
        "SIGUSR2",
        "SIGPIPE",
        "SIGALRM",
        "SIGTERM",
        "SIGSTKFLT",
        "SIGCHLD",
        "SIGCONT",
        "SIGSTOP",
        "SIGTSTP",
        "SIGTTIN",
        "SIGTTOU",
        "SIGURG",
        "SIGXCPU",
        "SIGXFSZ",
        "SIGVTALRM",
        "SIGPROF",
        "SIGWINCH",
        "SIGIO",
        "SIGPWR",
        "SIGSYS",
    ];
    match usize::try_from(number).ok().and_then(|n| NAMES.get(n)) {
        Some(name) if !name.is_empty() => (*name).to_owned(),
        _ => format!("signal {number}"),
    }
}

/// A limit in words for the summary's limits line.
pub fn describe_limits(limits: &Limits) -> String {
    format!(
        "wall {}, CPU {}, memory {}, files {}, {} processes",
        super::limits::show_duration(limits.wall),
        super::limits::show_duration(limits.cpu),
        show_bytes(limits.memory_bytes),
        show_bytes(limits.file_bytes),
        limits.processes
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exits_serialise_plainly_and_name_their_signal() {
        assert_eq!(serde_json::to_string(&Exit::Code(3)).unwrap(), r#"{"code":3}"#);
        assert_eq!(
            serde_json::to_string(&Exit::signal(11)).unwrap(),
            r#"{"signal":{"number":11,"name":"SIGSEGV"}}"#
        );
        assert_eq!(signal_name(6), "SIGABRT");
        assert_eq!(signal_name(40), "signal 40");
        assert_eq!(signal_name(-1), "signal -1");
    }

    #[test]
    fn the_summary_names_only_what_was_in_force() {
        assert_eq!(Protections::default().summary(), "none (only the wall-time limit)");
        let p = Protections {
            user_namespace: true,
            pid_namespace: true,
            network_namespace: true,
            landlock: Some(LandlockState {
                abi: 7,
                filesystem: true,
                network: true,
                scopes: false,
            }),
            rlimits: vec!["cpu".to_owned(), "core".to_owned()],
            ..Protections::default()
        };
        assert_eq!(
            p.summary(),
            "user, PID and network namespaces; Landlock ABI 7 (files, TCP); rlimits: cpu, core"
        );
    }
}
