//! The sandbox's init: `goldray __sandbox-init`, a fresh process started by [`super::Sandbox`]
//! for one command. It enters the namespaces, forks the namespace's first process, keeps the tail
//! of what the command prints, kills everything at the wall-time limit, and reports.
//!
//! It is a process of its own, not a fork of the caller, because the caller may have many
//! threads: the kernel gives a user namespace only to a single-threaded process, and after a
//! fork of a multi-threaded process only async-signal-safe code may run. Here every step is
//! plain Rust in a process that has one thread until it has forked.

use std::io::Read;
use std::os::fd::{AsFd, OwnedFd};
use std::path::Path;
use std::time::{Duration, Instant};

use rustix::event::{PollFd, PollFlags, Timespec, poll};
use rustix::pipe::{PipeFlags, pipe_with};
use rustix::process::{
    DumpableBehavior, Pid, Signal, WaitOptions, getpid, kill_process, set_child_subreaper, set_dumpable_behavior,
    set_parent_process_death_signal, setsid, waitpid,
};

use super::child::{Pipes, exit_of, first_process, kill_leftovers};
use super::limits::{LimitHit, Limits};
use super::namespaces;
use super::outcome::{Exit, Outcome, Protections};
use super::protocol::{Reply, Request, Status};
use super::tail::Tail;

/// Reads the request from `input`, runs the command, and says what happened.
pub fn serve(mut input: impl Read) -> Reply {
    let mut text = String::new();
    if let Err(e) = input.read_to_string(&mut text) {
        return Reply::Failed(format!("cannot read the request: {e}"));
    }
    match serde_json::from_str::<Request>(&text) {
        Ok(request) => match run(&request) {
            Ok(outcome) => Reply::Done(Box::new(outcome)),
            Err(message) => Reply::Failed(message),
        },
        Err(e) => Reply::Failed(format!("cannot read the request: {e}")),
    }
}

fn run(request: &Request) -> Result<Outcome, String> {
    // A session of its own (no terminal, a process group to kill), gone with its caller, out of
    // reach of the command's processes, and the parent of whatever they leave behind.
    let _ = setsid();
    let _ = set_parent_process_death_signal(Some(Signal::KILL));
    let _ = set_dumpable_behavior(DumpableBehavior::NotDumpable);
    let _ = set_child_subreaper(Some(getpid()));
    let mut protections = Protections::default();
    let outside_uid = namespaces::enter(&mut protections);
    let pipe = || pipe_with(PipeFlags::CLOEXEC).map_err(|e| format!("cannot make a pipe: {e}"));
    let ((out_read, out_write), (err_read, err_write), (status_read, status_write)) = (pipe()?, pipe()?, pipe()?);
    let start = Instant::now();
    // SAFETY: this process has one thread (it was started for this and has started none), so
    // the child may run any code before it execs, not only async-signal-safe functions.
    let pid = unsafe { libc::fork() };
    if pid == 0 {
        drop((out_read, err_read, status_read));
        let pipes = Pipes {
            stdout: out_write,
            stderr: err_write,
            status: status_write,
        };
        first_process(request, outside_uid, protections.clone(), pipes);
    }
    drop((out_write, err_write, status_write));
    let first = Pid::from_raw(pid).ok_or_else(|| format!("cannot fork: {}", std::io::Error::last_os_error()))?;
    let limits = &request.limits;
    let mut streams = Streams::new([out_read, err_read, status_read], limits.output_bytes);
    let deadline = start + limits.wall;
    let mut wall_hit = false;
    let first_ended = loop {
        let left = deadline.saturating_duration_since(Instant::now());
        streams.pump(left.min(Duration::from_millis(20)));
        match waitpid(Some(first), WaitOptions::NOHANG) {
            Ok(Some((_, status))) => break Some(status),
            Ok(None) | Err(rustix::io::Errno::INTR) => {}
            Err(_) => break None,
        }
        if Instant::now() >= deadline {
            wall_hit = true;
            // The first process's end ends the PID namespace and everything in it.
            let _ = kill_process(first, Signal::KILL);
            break waitpid(Some(first), WaitOptions::empty())
                .ok()
                .flatten()
                .map(|(_, s)| s);
        }
    };
    let wall_seconds = start.elapsed().as_secs_f64();
    if !protections.pid_namespace {
        kill_leftovers(None);
    }
    streams.drain(Duration::from_millis(500));
    let (cpu_seconds, peak_memory_bytes) = children_usage();
    let [stdout, stderr, status] = streams.tails;
    let mut exit = None;
    for line in status.text().lines() {
        match serde_json::from_str::<Status>(line) {
            Ok(Status::Protections(p)) => protections = p,
            Ok(Status::Exited(e)) => exit = Some(e),
            Ok(Status::ExecFailed(_)) | Err(_) => {}
        }
    }
    let exit = match (wall_hit, exit) {
        (true, _) => Exit::signal(Signal::KILL.as_raw()),
        (false, Some(exit)) => exit,
        // The first process itself ended without a word: report how.
        (false, None) => first_ended.map_or(Exit::Code(-1), exit_of),
    };
    let stderr_tail = stderr.text();
    let limit = classify(
        &exit,
        wall_hit,
        cpu_seconds,
        &stderr_tail,
        &request.job.working_dir,
        limits,
    );
    Ok(Outcome {
        exit,
        limit,
        wall_seconds,
        cpu_seconds,
        peak_memory_bytes,
        stdout_tail: stdout.text(),
        stderr_tail,
        stdout_bytes: stdout.total(),
        stderr_bytes: stderr.total(),
        protections,
    })
}

/// The command's stdout, stderr and the status pipe, read as they come.
struct Streams {
    fds: [Option<OwnedFd>; 3],
    tails: [Tail; 3],
}

impl Streams {
    fn new(fds: [OwnedFd; 3], keep: usize) -> Streams {
        Streams {
            fds: fds.map(Some),
            // The status pipe is kept whole: a few short lines.
            tails: [Tail::new(keep), Tail::new(keep), Tail::new(1 << 20)],
        }
    }

    /// Reads what is ready within `wait`.
    fn pump(&mut self, wait: Duration) {
        let open: Vec<usize> = (0..3).filter(|&i| self.fds[i].is_some()).collect();
        if open.is_empty() {
            std::thread::sleep(wait);
            return;
        }
        let borrowed: Vec<_> = open
            .iter()
            .filter_map(|&i| self.fds[i].as_ref().map(|fd| fd.as_fd()))
            .collect();
        let mut polled: Vec<PollFd> = borrowed
            .iter()
            .map(|fd| PollFd::new(fd, PollFlags::IN | PollFlags::HUP))
            .collect();
        let timeout = Timespec {
            tv_sec: wait.as_secs() as i64,
            tv_nsec: i64::from(wait.subsec_nanos()),
        };
        if poll(&mut polled, Some(&timeout)).is_err() {
            return;
        }
        let ready: Vec<bool> = polled.iter().map(|p| !p.revents().is_empty()).collect();
        drop(polled);
        drop(borrowed);
        let mut buffer = vec![0u8; 64 << 10];
        for (&i, ready) in open.iter().zip(ready) {
            if !ready {
                continue;
            }
            let Some(fd) = &self.fds[i] else { continue };
            match rustix::io::read(fd, &mut buffer) {
                Ok(0) => self.fds[i] = None,
                Ok(n) => self.tails[i].push(&buffer[..n]),
                Err(rustix::io::Errno::INTR | rustix::io::Errno::AGAIN) => {}
                Err(_) => self.fds[i] = None,
            }
        }
    }

    /// Reads until every writer is gone (their processes have ended), or at most `grace`: a
    /// process that escaped the sandbox may keep a pipe open.
    fn drain(&mut self, grace: Duration) {
        let end = Instant::now() + grace;
        while self.fds.iter().any(Option::is_some) && Instant::now() < end {
            self.pump(Duration::from_millis(10));
        }
    }
}

/// CPU time and the largest resident set of every process this one has reaped: the first
/// process, and through it the command and what it started.
fn children_usage() -> (f64, u64) {
    // SAFETY: an all-zero `rusage` is a valid value (integers and timevals).
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    // SAFETY: `getrusage` writes one `rusage` through the pointer, which points to one.
    if unsafe { libc::getrusage(libc::RUSAGE_CHILDREN, &mut usage) } != 0 {
        return (0.0, 0);
    }
    let seconds = |t: libc::timeval| t.tv_sec as f64 + t.tv_usec as f64 / 1e6;
    let cpu = seconds(usage.ru_utime) + seconds(usage.ru_stime);
    (cpu, (usage.ru_maxrss.max(0) as u64) * 1024)
}

/// Which limit, if any, ended the command (see [`LimitHit`] for which are certain).
fn classify(
    exit: &Exit,
    wall_hit: bool,
    cpu_seconds: f64,
    stderr: &str,
    working_dir: &Path,
    limits: &Limits,
) -> Option<LimitHit> {
    if wall_hit {
        return Some(LimitHit::WallTime);
    }
    let cpu_limit = limits.cpu.as_secs_f64().ceil().max(1.0);
    match exit {
        Exit::Code(0) => None,
        Exit::Signal { number, .. } if *number == libc::SIGXCPU => Some(LimitHit::CpuTime),
        Exit::Signal { number, .. } if *number == libc::SIGKILL && cpu_seconds >= cpu_limit => Some(LimitHit::CpuTime),
        Exit::Signal { number, .. } if *number == libc::SIGXFSZ => Some(LimitHit::FileSize),
        _ => {
            let said = stderr.to_ascii_lowercase();
            let says = |phrases: &[&str]| phrases.iter().any(|p| said.contains(p));
            if file_at_limit(working_dir, limits.file_bytes) {
                Some(LimitHit::FileSize)
            } else if says(&[
                "bad_alloc",
                "cannot allocate memory",
                "out of memory",
                "memory allocation of",
                "memoryerror",
                "failed to allocate",
            ]) {
                Some(LimitHit::Memory)
            } else if says(&[
                "cannot fork",
                "fork: retry",
                "fork failed",
                "resource temporarily unavailable",
            ]) {
                Some(LimitHit::Processes)
            } else {
                None
            }
        }
    }
}

/// Whether a file in `dir` (not following links, at most 10,000 entries) reached `limit` bytes.
fn file_at_limit(dir: &Path, limit: u64) -> bool {
    let mut stack = vec![dir.to_path_buf()];
    let mut seen = 0;
    while let Some(dir) = stack.pop() {
        let Ok(entries) = std::fs::read_dir(&dir) else { continue };
        for entry in entries.flatten() {
            seen += 1;
            if seen > 10_000 {
                return false;
            }
            match entry.metadata() {
                Ok(meta) if meta.is_dir() => stack.push(entry.path()),
                Ok(meta) if meta.is_file() && meta.len() >= limit => return true,
                _ => {}
            }
        }
    }
    false
}
