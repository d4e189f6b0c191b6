//! Hostile programs: each misbehaves on scene01 only, so every test also checks that scene02 was
//! still rendered, that nothing outside the run's folders changed, and that no process of the
//! run is left.

use std::fs;
use std::io::ErrorKind;
use std::net::TcpListener;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use goldray::sandbox::{Exit, LimitHit, Outcome, RunRecord};

use super::{compiled, files_in, outcome, processes_with, run_ok, scratch, write_rubric};

static HOSTILE: OnceLock<PathBuf> = OnceLock::new();

struct Hostile {
    record: RunRecord,
    /// What the program wrote into its scene01 outputs: the action's own report.
    said: String,
}

/// Runs `hostile ACTION [EXTRA]` through the rubric with tight limits, then checks what every
/// hostile run must leave true.
fn run(name: &str, action: &str, extra: Option<&str>, limits: &str, dir: &Path) -> Hostile {
    // A copy of its own, so that its path picks out this test's processes among those of the
    // tests running beside it.
    let program = dir.join("bin").join("hostile");
    fs::create_dir_all(dir.join("bin")).unwrap();
    fs::copy(
        compiled("tests/data/hostile/hostile.cpp", "hostile", &HOSTILE),
        &program,
    )
    .unwrap();
    let rubric = write_rubric(dir, limits);
    let out = dir.join("out");
    let before = tree(dir);
    let mut args = vec![
        "run",
        "--rubric",
        rubric.to_str().unwrap(),
        "--program",
        program.to_str().unwrap(),
        action,
    ];
    args.extend(extra);
    // One command at a time: the well-behaved render must not share the cores with a fork bomb
    // or an endless loop under a two-second wall limit (on a 2-core machine it could miss it).
    args.extend(["--out", out.to_str().unwrap(), "--quiet", "--threads", "1"]);
    let (record, _) = run_ok(&args, &out);
    assert_eq!(tree(dir), before, "{name}: files outside the output folder changed");
    let left = processes_with(program.to_str().unwrap());
    assert!(left.is_empty(), "{name}: processes left behind: {left:#?}");
    let scene02 = outcome(&record, "scene02");
    assert!(scene02.succeeded(), "{name}: the other render failed: {scene02:#?}");
    assert!(super::command(&record, "scene02").outputs.iter().all(|o| o.delivered));
    let said = fs::read_to_string(out.join("a01.png")).unwrap_or_default();
    Hostile { record, said }
}

/// Every file below `dir` except the output folder, with its size: what must not change.
fn tree(dir: &Path) -> Vec<(PathBuf, u64)> {
    let mut found = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(folder) = stack.pop() {
        for entry in fs::read_dir(&folder).unwrap().flatten() {
            let path = entry.path();
            if path == dir.join("out") {
                continue;
            }
            let meta = entry.metadata().unwrap();
            if meta.is_dir() {
                stack.push(path.clone());
            }
            found.push((path, meta.len()));
        }
    }
    found.sort();
    found
}

fn scene01(h: &Hostile) -> &Outcome {
    outcome(&h.record, "scene01")
}

#[test]
fn an_endless_loop_is_stopped_by_its_cpu_limit() {
    let dir = scratch("loop");
    let h = run("loop", "loop", None, "cpu_time = 1\nwall_time = 5", &dir);
    let o = scene01(&h);
    assert_eq!(o.limit, Some(LimitHit::CpuTime), "{o:#?}");
    assert_eq!(o.exit, Exit::signal(24), "SIGXCPU");
    assert!(o.cpu_seconds >= 0.9, "{o:#?}");
}

#[test]
fn a_fork_bomb_is_contained_and_leaves_nothing() {
    let dir = scratch("forkbomb");
    let h = run(
        "forkbomb",
        "forkbomb",
        None,
        "wall_time = 2\ncpu_time = 1\nprocesses = 32",
        &dir,
    );
    let o = scene01(&h);
    assert!(
        matches!(o.limit, Some(LimitHit::WallTime | LimitHit::CpuTime)),
        "{o:#?}"
    );
    let p = &o.protections;
    assert!(
        p.process_bound.is_some()
            || p.unavailable
                .iter()
                .any(|u| u.contains("processes") || u.contains("pid_max")),
        "the report says how (or that nothing) bounded the processes: {p:#?}"
    );
}

#[test]
fn allocating_20_gb_hits_the_memory_limit() {
    let dir = scratch("alloc");
    let h = run("alloc", "alloc", None, "memory = \"1GiB\"\nwall_time = 10", &dir);
    let o = scene01(&h);
    if o.protections.rlimits.iter().any(|r| r == "address-space") {
        assert_eq!(o.limit, Some(LimitHit::Memory), "{o:#?}");
        assert!(o.stderr_tail.contains("bad_alloc"), "{}", o.stderr_tail);
        assert!(!o.succeeded());
    } else {
        assert!(o.protections.unavailable.iter().any(|u| u.contains("address-space")));
    }
}

#[test]
fn a_10_gb_file_stops_at_the_file_size_limit() {
    let dir = scratch("bigfile");
    let h = run("bigfile", "bigfile", None, "file_size = \"8MiB\"\nwall_time = 10", &dir);
    let o = scene01(&h);
    assert_eq!(o.limit, Some(LimitHit::FileSize), "{o:#?}");
    assert_eq!(o.exit, Exit::signal(25), "SIGXFSZ");
    // The big file did not survive the run.
    assert_eq!(
        files_in(&dir.join("out")),
        [
            "a01.png", "a01d.png", "a01n.png", "a02.png", "a02d.png", "a02n.png", "run.json"
        ]
        .iter()
        .filter(|f| !f.starts_with("a01"))
        .map(|f| f.to_string())
        .collect::<Vec<_>>()
    );
}

#[test]
fn endless_output_keeps_only_its_tail_and_is_stopped_by_time() {
    let dir = scratch("spew");
    let h = run("spew", "spew", None, "wall_time = 1.5\ncpu_time = 10", &dir);
    let o = scene01(&h);
    assert_eq!(o.limit, Some(LimitHit::WallTime), "{:?} {}", o.exit, o.stdout_bytes);
    assert!(o.stdout_tail.len() <= 64 << 10 && o.stdout_tail.len() > 60 << 10);
    assert!(o.stdout_bytes > 1 << 20, "{}", o.stdout_bytes);
    assert!(o.stdout_tail.ends_with("yyy\n") || o.stdout_tail.contains("yyyy"));
}

#[test]
fn writes_outside_the_working_folder_do_not_land() {
    let dir = scratch("escape");
    let home = dir.join("ta-home");
    fs::create_dir_all(&home).unwrap();
    for path in ["/goldray-escape-test", "/var/tmp/goldray-escape-test"] {
        let _ = fs::remove_file(path);
    }
    let h = run("escape", "escape", Some(home.to_str().unwrap()), "wall_time = 10", &dir);
    let o = scene01(&h);
    let landed: Vec<&str> = ["/goldray-escape-test", "/var/tmp/goldray-escape-test"]
        .into_iter()
        .filter(|p| Path::new(p).exists())
        .collect();
    for path in &landed {
        let _ = fs::remove_file(path);
    }
    if o.protections.filesystem_confined() {
        assert!(!h.said.contains("WROTE"), "{}", h.said);
        assert_eq!(h.said.matches("refused").count(), 5, "{}", h.said);
        assert!(landed.is_empty(), "{landed:?}");
        assert!(!home.join("pwned").exists());
    } else {
        assert!(
            o.protections.unavailable.iter().any(|u| u.starts_with("Landlock")),
            "{o:#?}"
        );
    }
}

#[test]
fn another_students_folder_cannot_be_read() {
    let dir = scratch("read");
    let other = dir.join("submissions/other-student");
    fs::create_dir_all(&other).unwrap();
    let secret = other.join("secret.txt");
    fs::write(&secret, "TOP-SECRET answer\n").unwrap();
    let h = run("read", "read", Some(secret.to_str().unwrap()), "wall_time = 10", &dir);
    let o = scene01(&h);
    if o.protections.filesystem_confined() {
        assert!(h.said.contains("refused"), "{}", h.said);
        assert!(!h.said.contains("TOP-SECRET"));
    } else {
        assert!(o.protections.unavailable.iter().any(|u| u.starts_with("Landlock")));
    }
}

#[test]
fn a_connection_to_the_host_fails() {
    let dir = scratch("connect");
    let listener = TcpListener::bind("127.0.0.1:0").unwrap();
    listener.set_nonblocking(true).unwrap();
    let port = listener.local_addr().unwrap().port().to_string();
    let h = run("connect", "connect", Some(&port), "wall_time = 10", &dir);
    let o = scene01(&h);
    if o.protections.network_cut() {
        assert!(
            h.said.contains("refused") && !h.said.contains("CONNECTED"),
            "{}",
            h.said
        );
        assert!(matches!(listener.accept(), Err(e) if e.kind() == ErrorKind::WouldBlock));
    } else {
        assert!(
            o.protections
                .unavailable
                .iter()
                .any(|u| u.starts_with("network namespace"))
        );
    }
}

#[test]
fn the_system_calls_exploits_start_from_are_refused() {
    let dir = scratch("syscalls");
    let h = run("syscalls", "syscalls", None, "wall_time = 10", &dir);
    let o = scene01(&h);
    assert!(h.said.contains("fork: works"), "{}", h.said);
    if o.protections.seccomp {
        for call in [
            "unshare",
            "ptrace",
            "io_uring_setup",
            "bpf",
            "perf_event_open",
            "userfaultfd",
            "keyctl",
            "clone(CLONE_NEWUSER)",
        ] {
            assert!(h.said.contains(&format!("{call}: refused")), "{call}:\n{}", h.said);
        }
        assert!(!h.said.contains("ALLOWED"), "{}", h.said);
    } else {
        assert!(
            o.protections.unavailable.iter().any(|u| u.starts_with("seccomp")),
            "{o:#?}"
        );
    }
}

#[test]
fn a_process_left_behind_is_killed() {
    let dir = scratch("linger");
    let marker = dir.join("out-of-reach-marker");
    let h = run(
        "linger",
        "linger",
        Some(marker.to_str().unwrap()),
        "wall_time = 10",
        &dir,
    );
    let o = scene01(&h);
    assert!(o.succeeded(), "{o:#?}");
    assert!(h.said.contains("left a process behind"));
    // `run` checked that no process of it is left; a survivor would write the marker later.
    std::thread::sleep(std::time::Duration::from_millis(2500));
    assert!(!marker.exists());
}

#[test]
fn crashes_and_exit_codes_are_recorded_with_their_stderr() {
    for (action, exit, said) in [
        ("abort", Exit::signal(6), "about to abort"),
        ("segfault", Exit::signal(11), "about to crash"),
        ("exit3", Exit::Code(3), "giving up with code 3"),
    ] {
        let dir = scratch(&format!("crash-{action}"));
        let h = run(action, action, None, "wall_time = 10", &dir);
        let o = scene01(&h);
        assert_eq!(o.exit, exit, "{action}");
        assert_eq!(o.limit, None, "{action}: {o:#?}");
        assert!(o.stderr_tail.contains(said), "{action}: {}", o.stderr_tail);
        let files: Vec<&str> = super::command(&h.record, "scene01")
            .outputs
            .iter()
            .filter(|f| f.delivered)
            .map(|f| f.file.as_str())
            .collect();
        assert!(files.is_empty(), "{action}: {files:?}");
    }
}
