//! The two processes below the sandbox's init: the namespace's first process, which sets up the
//! mounts, starts the command and waits for it; and the command's process, which confines itself
//! and becomes the program.
//!
//! The first process is PID 1 of the new PID namespace when there is one: when it ends, the
//! kernel kills every process left in the namespace, so nothing the program started outlives
//! it. It is not the program itself because a PID 1 ignores the signals it sends itself, so an
//! `abort()` would not end it as SIGABRT. Without a PID namespace it is a child subreaper: what
//! the program leaves behind becomes its child, and it kills it.

use std::fs::File;
use std::io::Write;
use std::os::fd::OwnedFd;
use std::os::unix::process::CommandExt;
use std::process::Command;
use std::time::Duration;

use rustix::process::{
    DumpableBehavior, Pid, Signal, WaitOptions, WaitStatus, getpid, kill_process, kill_process_group,
    set_child_subreaper, set_dumpable_behavior, set_parent_process_death_signal, setpgid, wait,
};
use rustix::stdio::{dup2_stderr, dup2_stdin, dup2_stdout};

use super::confine::confine;
use super::namespaces::prepare_mounts;
use super::outcome::{Exit, Protections};
use super::protocol::{Request, Status};

/// The ends of the pipes the first process and the command write to.
pub struct Pipes {
    pub stdout: OwnedFd,
    pub stderr: OwnedFd,
    /// Close-on-exec: the program never sees it.
    pub status: OwnedFd,
}

/// The namespace's first process, in the child of the init. Never returns.
pub fn first_process(request: &Request, outside_uid: u32, mut p: Protections, pipes: Pipes) -> ! {
    // Dies with the init; and no process of the command may inspect it (ptrace, /proc/1/mem):
    // it is not confined.
    let _ = set_parent_process_death_signal(Some(Signal::KILL));
    let _ = set_dumpable_behavior(DumpableBehavior::NotDumpable);
    let mut status = File::from(pipes.status);
    let streams = File::open("/dev/null").and_then(|null| {
        dup2_stdin(&null)?;
        dup2_stdout(&pipes.stdout)?;
        dup2_stderr(&pipes.stderr)?;
        Ok(())
    });
    if let Err(e) = streams {
        send(
            &mut status,
            &Status::ExecFailed(format!("cannot set up standard streams: {e}")),
        );
        std::process::exit(127);
    }
    drop(pipes.stdout);
    drop(pipes.stderr);
    prepare_mounts(request, &mut p);
    if !p.pid_namespace {
        let _ = set_child_subreaper(Some(getpid()));
    }
    send(&mut status, &Status::Protections(p.clone()));
    // SAFETY: this process has one thread (it is the fork of the init, which has one), so the
    // child may run any code, not only async-signal-safe functions, before it execs.
    let pid = unsafe { libc::fork() };
    if pid == 0 {
        command_process(request, outside_uid, p, &mut status);
    }
    let Some(program) = Pid::from_raw(pid) else {
        let error = std::io::Error::last_os_error();
        send(&mut status, &Status::ExecFailed(format!("cannot fork: {error}")));
        std::process::exit(127);
    };
    let exit = loop {
        match wait(WaitOptions::empty()) {
            Ok(Some((pid, wait))) if pid == program => break exit_of(wait),
            // An orphan of the program, reparented here: reaped, and waited past.
            Ok(_) | Err(rustix::io::Errno::INTR) => {}
            Err(e) => break Exit::Code(-(e.raw_os_error())),
        }
    };
    if !p.pid_namespace {
        kill_leftovers(Some(program));
    }
    send(&mut status, &Status::Exited(exit));
    std::process::exit(0)
}

/// The command's process: confines itself, then becomes the program. Never returns.
fn command_process(request: &Request, outside_uid: u32, mut p: Protections, status: &mut File) -> ! {
    // Its own process group, so that without a PID namespace the group can be killed at the end.
    let _ = setpgid(None, None);
    let _ = set_parent_process_death_signal(Some(Signal::KILL));
    confine(request, outside_uid, &mut p);
    send(status, &Status::Protections(p));
    let job = &request.job;
    let error = Command::new(&job.program)
        .args(&job.args)
        .current_dir(&job.working_dir)
        .env_clear()
        .envs(job.env.iter().map(|(k, v)| (k, v)))
        .exec();
    let message = format!("cannot run {}: {error}", job.program.display());
    send(status, &Status::ExecFailed(message.clone()));
    let _ = std::io::stderr().write_all(format!("goldray sandbox: {message}\n").as_bytes());
    std::process::exit(127)
}

pub fn exit_of(status: WaitStatus) -> Exit {
    match (status.exit_status(), status.terminating_signal()) {
        (Some(code), _) => Exit::Code(code),
        (None, Some(signal)) => Exit::signal(signal),
        (None, None) => Exit::Code(-1),
    }
}

/// One status line. Each is far below `PIPE_BUF`, so lines from the two writers never mix.
fn send(status: &mut File, message: &Status) {
    if let Ok(mut line) = serde_json::to_vec(message) {
        line.push(b'\n');
        let _ = status.write_all(&line);
    }
}

/// Kills `group` (the program's process group), then every child this process has (what a
/// subreaper inherits: everything the program started that outlived its parent), again and again
/// until none is left, reaping them. For machines without a PID namespace; reads
/// `/proc/self/task/PID/children`, which lists a process's children.
pub fn kill_leftovers(group: Option<Pid>) {
    if let Some(group) = group {
        let _ = kill_process_group(group, Signal::KILL);
    }
    let me = getpid();
    let list = format!("/proc/self/task/{}/children", me.as_raw_nonzero());
    for _ in 0..10_000 {
        let children: Vec<Pid> = std::fs::read_to_string(&list)
            .unwrap_or_default()
            .split_whitespace()
            .filter_map(|n| n.parse().ok().and_then(Pid::from_raw))
            .collect();
        if children.is_empty() {
            break;
        }
        for child in children {
            let _ = kill_process(child, Signal::KILL);
        }
        while let Ok(Some(_)) = wait(WaitOptions::NOHANG) {}
        std::thread::sleep(Duration::from_millis(1));
    }
}
