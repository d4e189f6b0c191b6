//! The namespaces a command runs in, and its mount table: each layer tried on its own, so that a
//! machine which refuses one still gets the others.

use std::fs;
use std::os::fd::OwnedFd;
use std::path::{Path, PathBuf};

use rustix::fs::CWD;
use rustix::mount::{
    MountFlags, MountPropagationFlags, MoveMountFlags, OpenTreeFlags, mount, mount_change, move_mount, open_tree,
};
use rustix::process::{getgid, getuid};
use rustix::thread::{UnshareFlags, unshare_unsafe};

use super::outcome::Protections;
use super::protocol::Request;

/// Folders covered by an empty file system for the command: where other users' files and the
/// sockets of running services (a terminal multiplexer, an SSH agent, D-Bus, Docker) live, which
/// Landlock before ABI 9 does not guard. The command's own folders inside them are mounted back.
pub const HIDDEN: [&str; 9] = [
    "/tmp", "/var/tmp", "/run", "/dev/shm", "/home", "/root", "/mnt", "/media", "/srv",
];

/// The lowest `pid_max` the kernel accepts.
const PID_MAX_FLOOR: u64 = 301;

/// Moves this process into new namespaces, as many as the machine allows, and records which.
/// First a user namespace, mapping the caller's user to root inside (which gives the
/// capabilities the other namespaces and the mounts need, without any outside); then mount, PID,
/// network, IPC and UTS namespaces, each on its own. Returns the caller's user ID outside.
///
/// Must run while the process has a single thread (the kernel refuses a user namespace
/// otherwise), before the fork of the namespace's first process.
pub fn enter(p: &mut Protections) -> u32 {
    let (uid, gid) = (getuid().as_raw(), getgid().as_raw());
    // SAFETY: `unshare_unsafe` is unsafe only for CLONE_FILES (another thread's descriptors could
    // vanish under it); it is not asked for here, and this process has no other thread.
    match unsafe { unshare_unsafe(UnshareFlags::NEWUSER) } {
        Ok(()) => match map_ids(uid, gid) {
            Ok(()) => p.user_namespace = true,
            Err(e) => p.unavailable.push(format!("user namespace: cannot map the user: {e}")),
        },
        Err(e) => p.unavailable.push(format!("user namespace: {e}")),
    }
    let layers = [
        (UnshareFlags::NEWNS, "mount namespace"),
        (UnshareFlags::NEWPID, "PID namespace"),
        (UnshareFlags::NEWNET, "network namespace"),
        (UnshareFlags::NEWIPC | UnshareFlags::NEWUTS, "IPC namespace"),
    ];
    for (flag, name) in layers {
        // SAFETY: as above, no CLONE_FILES and a single thread.
        match unsafe { unshare_unsafe(flag) } {
            Ok(()) => match name {
                "mount namespace" => p.mount_namespace = true,
                "PID namespace" => p.pid_namespace = true,
                "network namespace" => p.network_namespace = true,
                _ => p.ipc_namespace = true,
            },
            Err(e) => p.unavailable.push(format!("{name}: {e}")),
        }
    }
    // A new mount namespace starts as a copy whose mounts may still propagate to the original:
    // make every mount private first, or do without mounts.
    if p.mount_namespace
        && let Err(e) = mount_change("/", MountPropagationFlags::PRIVATE | MountPropagationFlags::REC)
    {
        p.mount_namespace = false;
        p.unavailable
            .push(format!("mount namespace: cannot make mounts private: {e}"));
    }
    uid
}

/// The caller's user and group become root inside (`setgroups` denied first, as the kernel
/// requires of an unprivileged mapping).
fn map_ids(uid: u32, gid: u32) -> std::io::Result<()> {
    fs::write("/proc/self/setgroups", "deny")?;
    fs::write("/proc/self/uid_map", format!("0 {uid} 1"))?;
    fs::write("/proc/self/gid_map", format!("0 {gid} 1"))
}

/// In the namespace's first process (PID 1 of a new PID namespace): hides [`HIDDEN`] behind empty
/// file systems, with the command's own paths mounted back at the same places, gives the
/// namespace its own `/proc`, and bounds its process IDs. Each step that fails is recorded and
/// skipped.
pub fn prepare_mounts(request: &Request, p: &mut Protections) {
    if !p.mount_namespace {
        return;
    }
    let job = &request.job;
    let mut needed: Vec<&Path> = vec![&job.working_dir, &job.program];
    needed.extend(job.readable.iter().map(PathBuf::as_path));
    needed.sort_by_key(|path| path.components().count());
    for hidden in HIDDEN {
        hide(Path::new(hidden), &needed, request.limits.file_bytes, p);
    }
    if p.pid_namespace {
        match mount(
            "proc",
            "/proc",
            "proc",
            MountFlags::NOSUID | MountFlags::NODEV | MountFlags::NOEXEC,
            None,
        ) {
            Ok(()) => p.private_proc = true,
            Err(e) => p.unavailable.push(format!("own /proc: {e}")),
        }
    }
    // Only in an own user namespace: on a kernel where pid_max is not per PID namespace (before
    // 6.14) the write is then refused instead of changing the machine's.
    if p.private_proc && p.user_namespace {
        let max = (request.limits.processes + 1).max(PID_MAX_FLOOR);
        match fs::write("/proc/sys/kernel/pid_max", max.to_string()) {
            Ok(()) => p.process_bound = Some(format!("pid_max {max} in its PID namespace")),
            Err(e) => p.unavailable.push(format!("pid_max of the PID namespace: {e}")),
        }
    }
}

/// Covers `dir` with an empty tmpfs, then mounts each of `needed` that lies inside it back at its
/// own path. When one cannot be mounted back, the cover is taken away again.
fn hide(dir: &Path, needed: &[&Path], size: u64, p: &mut Protections) {
    match fs::symlink_metadata(dir) {
        Ok(meta) if meta.is_dir() => {}
        _ => return,
    }
    // A path that does not exist needs no keeping (and must not cost the others their cover).
    let inside: Vec<&Path> = needed
        .iter()
        .copied()
        .filter(|path| path.starts_with(dir) && fs::symlink_metadata(path).is_ok())
        .collect();
    let mut trees: Vec<(&Path, OwnedFd, bool)> = Vec::new();
    for path in &inside {
        let is_dir = path.is_dir();
        let flags = OpenTreeFlags::OPEN_TREE_CLONE | OpenTreeFlags::OPEN_TREE_CLOEXEC | OpenTreeFlags::AT_RECURSIVE;
        match open_tree(CWD, *path, flags) {
            Ok(fd) => trees.push((path, fd, is_dir)),
            Err(e) => {
                p.unavailable
                    .push(format!("hiding {}: cannot keep {}: {e}", dir.display(), path.display()));
                return;
            }
        }
    }
    // Room for what a program may leave there when Landlock is missing, never more than its
    // file limit.
    let options = format!("size={},mode=755", size.clamp(1 << 20, 64 << 20));
    let options = std::ffi::CString::new(options).unwrap_or_default();
    if let Err(e) = mount(
        "tmpfs",
        dir,
        "tmpfs",
        MountFlags::NOSUID | MountFlags::NODEV,
        options.as_c_str(),
    ) {
        p.unavailable.push(format!("hiding {}: {e}", dir.display()));
        return;
    }
    let mut placed_trees: Vec<&Path> = Vec::new();
    for (path, tree, is_dir) in &trees {
        // Inside a tree already mounted back (the program inside the submission's folder): there
        // already, and the mount point must not be made over the real file.
        if placed_trees.iter().any(|done| path.starts_with(done)) {
            continue;
        }
        let placed = if *is_dir {
            fs::create_dir_all(path)
        } else {
            path.parent()
                .map_or(Ok(()), fs::create_dir_all)
                .and_then(|()| fs::OpenOptions::new().write(true).create_new(true).open(path).map(drop))
        };
        let moved = placed
            .map_err(|e| rustix::io::Errno::from_io_error(&e).unwrap_or(rustix::io::Errno::IO))
            .and_then(|()| move_mount(tree, "", CWD, *path, MoveMountFlags::MOVE_MOUNT_F_EMPTY_PATH));
        if let Err(e) = moved {
            let _ = rustix::mount::unmount(dir, rustix::mount::UnmountFlags::DETACH);
            p.unavailable.push(format!(
                "hiding {}: cannot mount {} back: {e}",
                dir.display(),
                path.display()
            ));
            return;
        }
        placed_trees.push(path);
    }
    p.hidden.push(dir.display().to_string());
}
