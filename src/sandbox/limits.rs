//! What a sandboxed command may use, how a limit is written (`90s`, `4GiB`), and which limit
//! stopped a command.

use std::fmt;
use std::time::Duration;

use serde::{Deserialize, Serialize};

/// The limits of one command. Each is enforced by the kernel where the machine allows it
/// ([`super::Protections`] says which were in force); the wall time always, by the sandbox.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Limits {
    /// Wall-clock time from start to the end of the last process; the whole sandbox is killed at
    /// it. The one limit that holds on every machine.
    #[serde(with = "seconds")]
    pub wall: Duration,
    /// CPU time of each process (`RLIMIT_CPU`, whole seconds, rounded up): SIGXCPU at the limit,
    /// SIGKILL a second later.
    #[serde(with = "seconds")]
    pub cpu: Duration,
    /// Address space of each process (`RLIMIT_AS`). Address space, not resident memory: a
    /// program that reserves much and touches little (many threads' stacks, a sanitizer) needs
    /// more than it uses.
    pub memory_bytes: u64,
    /// Size of any file a process writes (`RLIMIT_FSIZE`): SIGXFSZ at the limit.
    pub file_bytes: u64,
    /// Processes and threads the command may have at once (`RLIMIT_NPROC`, counted in the
    /// command's own user namespace). Threads count: a renderer with one thread per core needs
    /// one per core here.
    pub processes: u64,
    /// How much of the end of stdout and of stderr is kept (each). Output beyond it is read and
    /// dropped, so a program that prints forever is stopped by its time limits, not by a full
    /// pipe.
    pub output_bytes: usize,
}

impl Default for Limits {
    /// A ray tracer of the course renders a scene at 800×800 in well under a minute and a few
    /// hundred megabytes; these stop what is far beyond that without troubling honest programs.
    fn default() -> Limits {
        Limits {
            wall: Duration::from_secs(60),
            cpu: Duration::from_secs(60),
            memory_bytes: 4 << 30,
            file_bytes: 512 << 20,
            processes: 256,
            output_bytes: 64 << 10,
        }
    }
}

/// Limits given in a rubric or on the command line, each replacing the default when present.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LimitOverrides {
    pub wall: Option<Duration>,
    pub cpu: Option<Duration>,
    pub memory_bytes: Option<u64>,
    pub file_bytes: Option<u64>,
    pub processes: Option<u64>,
}

impl LimitOverrides {
    /// `base` with every limit this sets replaced.
    pub fn apply(&self, base: &Limits) -> Limits {
        Limits {
            wall: self.wall.unwrap_or(base.wall),
            cpu: self.cpu.unwrap_or(base.cpu),
            memory_bytes: self.memory_bytes.unwrap_or(base.memory_bytes),
            file_bytes: self.file_bytes.unwrap_or(base.file_bytes),
            processes: self.processes.unwrap_or(base.processes),
            output_bytes: base.output_bytes,
        }
    }

    /// These overrides, with those of `over` taking precedence (the command line over a rubric).
    pub fn then(&self, over: &LimitOverrides) -> LimitOverrides {
        LimitOverrides {
            wall: over.wall.or(self.wall),
            cpu: over.cpu.or(self.cpu),
            memory_bytes: over.memory_bytes.or(self.memory_bytes),
            file_bytes: over.file_bytes.or(self.file_bytes),
            processes: over.processes.or(self.processes),
        }
    }
}

/// Which limit stopped a command. `Wall`, `Cpu` (the kernel's signal) and `FileSize` (its signal,
/// or a file left at the limit) are certain; `Memory` and `Processes` are read from how the
/// program failed (an allocation or a fork that the program reported failing), since the kernel
/// only makes the call fail.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum LimitHit {
    WallTime,
    CpuTime,
    Memory,
    FileSize,
    Processes,
}

impl LimitHit {
    /// What the limit was, for a report: `timed out after 60 s`, `memory limit (4 GiB)`.
    pub fn describe(self, limits: &Limits) -> String {
        match self {
            LimitHit::WallTime => format!("timed out after {}", show_duration(limits.wall)),
            LimitHit::CpuTime => format!("CPU time limit ({})", show_duration(limits.cpu)),
            LimitHit::Memory => format!("memory limit ({})", show_bytes(limits.memory_bytes)),
            LimitHit::FileSize => format!("file size limit ({})", show_bytes(limits.file_bytes)),
            LimitHit::Processes => format!("process limit ({})", limits.processes),
        }
    }
}

impl fmt::Display for LimitHit {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            LimitHit::WallTime => "wall-time",
            LimitHit::CpuTime => "cpu-time",
            LimitHit::Memory => "memory",
            LimitHit::FileSize => "file-size",
            LimitHit::Processes => "processes",
        })
    }
}

/// A duration as written on a command line or in a rubric: seconds (`90`, `1.5`) or with a unit
/// (`90s`, `2m`, `500ms`). Must be positive and at most a day.
pub fn parse_duration(text: &str) -> Result<Duration, String> {
    let t = text.trim();
    let (number, scale) = if let Some(n) = t.strip_suffix("ms") {
        (n, 0.001)
    } else if let Some(n) = t.strip_suffix('s') {
        (n, 1.0)
    } else if let Some(n) = t.strip_suffix("min").or_else(|| t.strip_suffix('m')) {
        (n, 60.0)
    } else if let Some(n) = t.strip_suffix('h') {
        (n, 3600.0)
    } else {
        (t, 1.0)
    };
    match number.trim().parse::<f64>() {
        Ok(v) if v.is_finite() && v > 0.0 && v * scale <= 86_400.0 => Ok(Duration::from_secs_f64(v * scale)),
        _ => Err(format!(
            "`{text}` is not a time between 0 and a day: give seconds (`90`) or a unit (`90s`, `2m`, `500ms`)"
        )),
    }
}

/// A size as written on a command line or in a rubric: bytes (`1048576`) or with a unit (`4GiB`,
/// `512MiB`, `64k`; `k`, `M`, `G`, `T` are powers of 1024 like `KiB`…, `kB`, `MB`… of 1000).
pub fn parse_bytes(text: &str) -> Result<u64, String> {
    let t = text.trim();
    let split = t.find(|c: char| !(c.is_ascii_digit() || c == '.')).unwrap_or(t.len());
    let (number, unit) = (t[..split].trim(), t[split..].trim());
    let scale: f64 = match unit.to_ascii_lowercase().as_str() {
        "" | "b" => 1.0,
        "k" | "kib" => 1024.0,
        "m" | "mib" => 1024.0 * 1024.0,
        "g" | "gib" => 1024.0 * 1024.0 * 1024.0,
        "t" | "tib" => 1024.0f64.powi(4),
        "kb" => 1e3,
        "mb" => 1e6,
        "gb" => 1e9,
        "tb" => 1e12,
        _ => {
            return Err(format!(
                "`{text}`: unknown unit `{unit}` (use B, KiB, MiB, GiB, TiB, kB, MB, GB, TB)"
            ));
        }
    };
    match number.parse::<f64>() {
        Ok(v) if v.is_finite() && v >= 1.0 && v * scale < 2f64.powi(63) => Ok((v * scale) as u64),
        _ => Err(format!(
            "`{text}` is not a size of at least one byte (e.g. `4GiB`, `512MiB`)"
        )),
    }
}

/// `60 s`, `1.5 s`, `250 ms`.
pub fn show_duration(d: Duration) -> String {
    let s = d.as_secs_f64();
    if s < 1.0 {
        format!("{} ms", (s * 1000.0).round())
    } else if s.fract() == 0.0 {
        format!("{s} s")
    } else {
        format!("{s:.1} s")
    }
}

/// `4 GiB`, `512 MiB`, `1000 B`.
pub fn show_bytes(bytes: u64) -> String {
    const UNITS: [&str; 4] = ["KiB", "MiB", "GiB", "TiB"];
    let mut value = bytes as f64;
    let mut unit = "B";
    for name in UNITS {
        if value < 1024.0 {
            break;
        }
        value /= 1024.0;
        unit = name;
    }
    if value.fract() == 0.0 {
        format!("{value} {unit}")
    } else {
        format!("{value:.1} {unit}")
    }
}

/// Durations in JSON as seconds, which a reader of `run.json` takes at a glance.
mod seconds {
    use std::time::Duration;

    use serde::{Deserialize, Deserializer, Serializer};

    pub fn serialize<S: Serializer>(d: &Duration, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_f64(d.as_secs_f64())
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Duration, D::Error> {
        let v = f64::deserialize(d)?;
        Duration::try_from_secs_f64(v).map_err(serde::de::Error::custom)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn durations_and_sizes_read_with_or_without_units_and_refuse_nonsense() {
        assert_eq!(parse_duration("90"), Ok(Duration::from_secs(90)));
        assert_eq!(parse_duration("2m"), Ok(Duration::from_secs(120)));
        assert_eq!(parse_duration("500ms"), Ok(Duration::from_millis(500)));
        assert_eq!(parse_duration("1.5s"), Ok(Duration::from_millis(1500)));
        for bad in ["0", "-1", "nan", "inf", "2 days", "", "100000"] {
            assert!(parse_duration(bad).is_err(), "{bad}");
        }
        assert_eq!(parse_bytes("4GiB"), Ok(4 << 30));
        assert_eq!(parse_bytes("512 MiB"), Ok(512 << 20));
        assert_eq!(parse_bytes("64k"), Ok(64 << 10));
        assert_eq!(parse_bytes("2MB"), Ok(2_000_000));
        assert_eq!(parse_bytes("1000"), Ok(1000));
        for bad in ["0", "-5", "4 parsecs", "", "1e30", "GiB"] {
            assert!(parse_bytes(bad).is_err(), "{bad}");
        }
        assert!(parse_bytes("4 parsecs").unwrap_err().contains("unknown unit"));
    }

    #[test]
    fn limits_show_as_people_write_them_and_overrides_stack() {
        assert_eq!(show_bytes(4 << 30), "4 GiB");
        assert_eq!(show_bytes(1536), "1.5 KiB");
        assert_eq!(show_duration(Duration::from_secs(60)), "60 s");
        assert_eq!(show_duration(Duration::from_millis(250)), "250 ms");
        let rubric = LimitOverrides {
            wall: Some(Duration::from_secs(5)),
            processes: Some(8),
            ..LimitOverrides::default()
        };
        let flags = LimitOverrides {
            wall: Some(Duration::from_secs(2)),
            ..LimitOverrides::default()
        };
        let limits = rubric.then(&flags).apply(&Limits::default());
        assert_eq!(limits.wall, Duration::from_secs(2));
        assert_eq!(limits.processes, 8);
        assert_eq!(limits.cpu, Limits::default().cpu);
        assert_eq!(LimitHit::WallTime.describe(&limits), "timed out after 2 s");
    }
}
