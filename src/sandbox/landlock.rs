//! Landlock rules for the command: write only in its working folder; read and run only the
//! system's programs and libraries, the few files of `/etc` they need, its own folders, and its
//! own `/proc`; no TCP; signals and abstract sockets only within the command.
//!
//! The rules are asked for at the newest ABI this build knows, and the `landlock` crate keeps
//! what the running kernel supports ("best effort"); what held is recorded.

use std::path::{Path, PathBuf};

use landlock::{
    ABI, Access, AccessFs, AccessNet, BitFlags, LandlockStatus, Ruleset, RulesetAttr, RulesetCreatedAttr, RulesetError,
    RulesetStatus, Scope, path_beneath_rules,
};

use super::outcome::{LandlockState, Protections};
use super::protocol::Request;

const NEWEST: ABI = ABI::V10;

/// Read and run: where programs, their libraries and compilers live. World-readable on every
/// system, and what any program needs to start.
const SYSTEM: [&str; 9] = [
    "/usr",
    "/bin",
    "/sbin",
    "/lib",
    "/lib32",
    "/lib64",
    "/libx32",
    "/opt",
    "/sys/devices/system/cpu",
];

/// Read only: the files of `/etc` that the loader, the C library and compilers read. Not the
/// whole of `/etc`, which holds secrets (`shadow`, keys) that root inside could read.
const ETC: [&str; 14] = [
    "/etc/ld.so.cache",
    "/etc/ld.so.conf",
    "/etc/ld.so.conf.d",
    "/etc/ld.so.preload",
    "/etc/alternatives",
    "/etc/localtime",
    "/etc/passwd",
    "/etc/group",
    "/etc/nsswitch.conf",
    "/etc/locale.alias",
    "/etc/gcc",
    "/etc/mime.types",
    "/etc/os-release",
    "/etc/debian_version",
];

/// Read and write: the devices every program may open.
const DEVICES: [&str; 3] = ["/dev/null", "/dev/zero", "/dev/full"];

/// Read only: randomness.
const RANDOM: [&str; 2] = ["/dev/urandom", "/dev/random"];

/// Restricts this process (and so the program it becomes) to the rules above, and records what
/// the kernel enforced.
pub fn restrict(request: &Request, p: &mut Protections) {
    match rules(request, p.private_proc) {
        Ok(status) => {
            let abi = match status.landlock {
                LandlockStatus::Available { effective_abi, .. } => Some(effective_abi as u32),
                _ => None,
            };
            match (abi, status.ruleset) {
                (Some(abi), RulesetStatus::FullyEnforced | RulesetStatus::PartiallyEnforced) => {
                    p.landlock = Some(LandlockState {
                        abi,
                        filesystem: true,
                        network: abi >= 4,
                        scopes: abi >= 6,
                    });
                }
                _ => p.unavailable.push(format!("Landlock: {}", describe(status.landlock))),
            }
        }
        Err(e) => p.unavailable.push(format!("Landlock: {e}")),
    }
}

fn rules(request: &Request, private_proc: bool) -> Result<landlock::RestrictionStatus, RulesetError> {
    let job = &request.job;
    let read = AccessFs::from_read(NEWEST);
    let read_write_file: BitFlags<AccessFs> = AccessFs::ReadFile | AccessFs::WriteFile;
    let mut readable: Vec<PathBuf> = SYSTEM.iter().chain(&ETC).map(PathBuf::from).collect();
    readable.extend(job.readable.iter().cloned());
    readable.push(job.program.clone());
    if private_proc {
        readable.push(PathBuf::from("/proc"));
    }
    Ruleset::default()
        .handle_access(AccessFs::from_all(NEWEST))?
        .handle_access(AccessNet::from_all(NEWEST))?
        .scope(Scope::from_all(NEWEST))?
        .create()?
        .add_rules(path_beneath_rules(existing(&readable), read))?
        .add_rules(path_beneath_rules(
            existing(&DEVICES.map(PathBuf::from)),
            read_write_file,
        ))?
        .add_rules(path_beneath_rules(
            existing(&RANDOM.map(PathBuf::from)),
            AccessFs::ReadFile,
        ))?
        .add_rules(path_beneath_rules(
            existing(std::slice::from_ref(&job.working_dir)),
            AccessFs::from_all(NEWEST),
        ))?
        .restrict_self()
}

/// Rules need an open file: a path missing on this system is left out.
fn existing(paths: &[PathBuf]) -> Vec<&Path> {
    paths.iter().map(PathBuf::as_path).filter(|p| p.exists()).collect()
}

fn describe(status: LandlockStatus) -> &'static str {
    match status {
        LandlockStatus::NotEnabled => "supported by the kernel but not enabled (boot with lsm=…,landlock)",
        LandlockStatus::NotImplemented => "not built into this kernel",
        LandlockStatus::Available { .. } => "not enforced",
    }
}
