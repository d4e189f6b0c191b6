//! What the command's own process does to itself just before it becomes the program: gives up
//! every capability, enters Landlock, sets its resource limits and installs the seccomp filter.
//! All of it is inherited by the program and everything it starts, and none of it can be undone.

use rustix::process::{Resource, Rlimit, getrlimit, getuid, setrlimit};
use rustix::thread::{
    CapabilitiesSecureBits, CapabilitySet, CapabilitySets, remove_capability_from_bounding_set, set_capabilities,
    set_capabilities_secure_bits, set_no_new_privs,
};

use super::outcome::Protections;
use super::protocol::Request;

/// Applies every confinement, recording each that held.
pub fn confine(request: &Request, outside_uid: u32, p: &mut Protections) {
    drop_capabilities(p);
    super::landlock::restrict(request, p);
    match set_no_new_privs(true) {
        Ok(()) => p.no_new_privs = true,
        Err(e) => p.unavailable.push(format!("no_new_privs: {e}")),
    }
    set_limits(request, outside_uid, p);
    match super::seccomp::restrict() {
        Ok(()) => p.seccomp = true,
        Err(e) => p.unavailable.push(format!("seccomp: {e}")),
    }
}

/// No capability now, none in the bounding set, and (with the `NO_ROOT` secure bit) none granted
/// when root runs a program: root inside the user namespace is then an ordinary user.
fn drop_capabilities(p: &mut Protections) {
    let bits = CapabilitiesSecureBits::NO_ROOT
        | CapabilitiesSecureBits::NO_ROOT_LOCKED
        | CapabilitiesSecureBits::NO_SETUID_FIXUP
        | CapabilitiesSecureBits::NO_SETUID_FIXUP_LOCKED
        | CapabilitiesSecureBits::KEEP_CAPS_LOCKED
        | CapabilitiesSecureBits::NO_CAP_AMBIENT_RAISE
        | CapabilitiesSecureBits::NO_CAP_AMBIENT_RAISE_LOCKED;
    let no_root = set_capabilities_secure_bits(bits).is_ok();
    let mut bounding_emptied = true;
    for capability in CapabilitySet::all().iter() {
        if remove_capability_from_bounding_set(capability).is_err() {
            bounding_emptied = false;
        }
    }
    let empty = CapabilitySets {
        effective: CapabilitySet::empty(),
        permitted: CapabilitySet::empty(),
        inheritable: CapabilitySet::empty(),
    };
    let cleared = set_capabilities(None, empty).is_ok();
    // Root that keeps neither the secure bit nor an empty bounding set gets every capability
    // back when it runs a program.
    p.capabilities_dropped = cleared && (no_root || bounding_emptied || !getuid().is_root());
    if !p.capabilities_dropped {
        p.unavailable.push("capabilities: could not drop them all".to_owned());
    }
}

fn set_limits(request: &Request, outside_uid: u32, p: &mut Protections) {
    let limits = &request.limits;
    let cpu = (limits.cpu.as_secs_f64().ceil() as u64).max(1);
    let mut set = |resource: Resource, name: &str, soft: u64, hard: u64| {
        // Never above a hard limit set by whoever started goldray: lowering is always allowed.
        let ceiling = getrlimit(resource).maximum;
        let clamp = |v: u64| ceiling.map_or(v, |c| v.min(c));
        let limit = Rlimit {
            current: Some(clamp(soft)),
            maximum: Some(clamp(hard)),
        };
        match setrlimit(resource, limit) {
            Ok(()) => {
                p.rlimits.push(name.to_owned());
                true
            }
            Err(e) => {
                p.unavailable.push(format!("rlimit {name}: {e}"));
                false
            }
        }
    };
    // SIGXCPU at the limit, SIGKILL a second later for a program that catches it.
    set(Resource::Cpu, "cpu", cpu, cpu + 1);
    set(Resource::As, "address-space", limits.memory_bytes, limits.memory_bytes);
    set(Resource::Fsize, "file-size", limits.file_bytes, limits.file_bytes);
    set(Resource::Core, "core", 0, 0);
    // RLIMIT_NPROC counts the processes of a user in a user namespace; the kernel never applies
    // it to the machine's root. So it bounds the command only in its own user namespace, as a
    // user other than root outside; elsewhere it would count the user's other processes too.
    if p.user_namespace && outside_uid != 0 {
        if set(Resource::Nproc, "processes", limits.processes, limits.processes) {
            p.process_bound = Some(format!("RLIMIT_NPROC {} in its user namespace", limits.processes));
        }
    } else if p.process_bound.is_none() {
        p.unavailable.push(if outside_uid == 0 {
            "rlimit processes: the kernel does not apply it to root".to_owned()
        } else {
            "rlimit processes: without a user namespace it would count the user's other processes".to_owned()
        });
    }
}
