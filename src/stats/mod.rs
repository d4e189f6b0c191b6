//! Render statistics: where a render's time went, how many rays of each kind it traced and how
//! fast, what its BVHs cost and how much memory it peaked at. `--stats` prints them as a table
//! after the render (like pbrt), `--stats-json FILE` saves the same numbers for scripts.
//!
//! Gathering them costs a handful of clock readings and one counter per band of rows (see
//! [`counter`]); none of it touches the image.

pub mod counter;
mod table;

pub(crate) use table::grouped;

pub use counter::RayCounts;

use std::path::{Path, PathBuf};
use std::time::Duration;

use serde::{Serialize, Serializer};

use crate::atomic_write::{AtomicWriteError, write_file_atomic};

/// Why `--stats-json` could not be written.
#[derive(Debug, thiserror::Error)]
pub enum StatsError {
    #[error("cannot encode the statistics as JSON: {0}")]
    Json(#[from] serde_json::Error),
    /// The path is named because the underlying error may only name a directory on the way.
    #[error("statistics {}: {source}", path.display())]
    Write { path: PathBuf, source: AtomicWriteError },
}

/// A BVH's size and what building it took.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct BvhStats {
    #[serde(rename = "build_seconds", serialize_with = "seconds")]
    pub build_time: Duration,
    pub primitives: usize,
    pub nodes: usize,
    pub leaves: usize,
}

/// One mesh file, loaded once however many objects use it.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MeshStats {
    pub path: PathBuf,
    pub triangles: usize,
    /// Reading, parsing and checking the file: the whole load but its BVH build.
    #[serde(rename = "load_seconds", serialize_with = "seconds")]
    pub load_time: Duration,
    pub bvh: BvhStats,
}

/// What building a scene measured, beyond its total time.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct BuildStats {
    /// Reading the six faces of the background's cube map, when it has one.
    #[serde(rename = "cube_map_load_seconds", serialize_with = "optional_seconds")]
    pub cube_map_load_time: Option<Duration>,
    /// The cube map's faces that rays looked at, by how each was loaded (known once the render
    /// is done).
    pub cube_map_faces: Option<CubeMapFaces>,
    /// In the order the case first uses them.
    pub meshes: Vec<MeshStats>,
    /// The BVH over the scene's objects, when there are enough objects to build one.
    pub scene_bvh: Option<BvhStats>,
}

/// The faces of a cube map that rays looked at: decoded from their PNGs, or read back from the
/// texel cache (`goldray::texel_cache`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct CubeMapFaces {
    pub decoded: u32,
    pub read_from_cache: u32,
}

/// Wall-clock time of each phase of a render; `total` also covers what falls between them.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct Phases {
    /// Reading and checking the case (or course scene) file.
    #[serde(serialize_with = "seconds")]
    pub parse: Duration,
    /// Building the scene: meshes loaded, their BVHs and the scene's BVH built, cube map read.
    #[serde(serialize_with = "seconds")]
    pub build: Duration,
    #[serde(serialize_with = "seconds")]
    pub render: Duration,
    /// Encoding and writing every output file.
    #[serde(serialize_with = "seconds")]
    pub write: Duration,
    #[serde(serialize_with = "seconds")]
    pub total: Duration,
}

/// One value per kind of ray, and for all of them together.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct PerKind<T> {
    pub camera: T,
    pub aov: T,
    pub shadow: T,
    pub reflection: T,
    pub total: T,
}

impl<T: Copy> PerKind<T> {
    fn of(rays: &RayCounts, value: impl Fn(u64) -> T) -> PerKind<T> {
        PerKind {
            camera: value(rays.camera),
            aov: value(rays.aov),
            shadow: value(rays.shadow),
            reflection: value(rays.reflection),
            total: value(rays.total()),
        }
    }

    /// Labelled values in display order.
    pub fn rows(&self) -> [(&'static str, T); 5] {
        [
            ("camera", self.camera),
            ("aov (depth, normals)", self.aov),
            ("shadow", self.shadow),
            ("reflection", self.reflection),
            ("total", self.total),
        ]
    }
}

/// Everything `--stats` reports about one render.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RenderStats {
    /// The case's name (its file stem).
    pub case: String,
    pub width: u32,
    pub height: u32,
    /// Worker threads the render ran on.
    pub threads: usize,
    /// The machine it ran on (its node name), where the system tells.
    pub host: Option<String>,
    pub seconds: Phases,
    #[serde(flatten)]
    pub build: BuildStats,
    pub rays: PerKind<u64>,
    /// Rays of each kind per second of render time, in millions.
    pub mrays_per_second: PerKind<f64>,
    /// Peak resident memory of the whole process, where the system reports it (Linux).
    pub peak_memory_bytes: Option<u64>,
}

impl RenderStats {
    /// `case` names what was rendered (a case's file stem) and `(width, height)` is its image size.
    /// Call once the render is written: the peak memory is read now.
    pub fn new(
        case: &str,
        (width, height): (u32, u32),
        phases: Phases,
        build: BuildStats,
        rays: &RayCounts,
        threads: usize,
    ) -> RenderStats {
        let seconds = phases.render.as_secs_f64();
        RenderStats {
            case: case.to_owned(),
            width,
            height,
            threads,
            host: this_host(),
            seconds: phases,
            build,
            rays: PerKind::of(rays, |count| count),
            mrays_per_second: PerKind::of(rays, |count| {
                if seconds > 0.0 {
                    count as f64 / seconds / 1e6
                } else {
                    0.0
                }
            }),
            peak_memory_bytes: peak_resident_bytes(),
        }
    }

    /// Writes the statistics as pretty-printed JSON, replacing `path` atomically.
    pub fn write_json(&self, path: &Path) -> Result<(), StatsError> {
        let mut json = serde_json::to_vec_pretty(self)?;
        json.push(b'\n');
        write_file_atomic(path, &json).map_err(|source| StatsError::Write {
            path: path.to_path_buf(),
            source,
        })
    }
}

/// This machine's name (`uname`'s node name), or `None` where it has none.
pub fn this_host() -> Option<String> {
    let name = rustix::system::uname().nodename().to_string_lossy().into_owned();
    (!name.is_empty()).then_some(name)
}

/// The process's peak resident set size so far, from Linux's `/proc/self/status` (`VmHWM`);
/// `None` on systems without it.
pub fn peak_resident_bytes() -> Option<u64> {
    vm_hwm_bytes(&std::fs::read_to_string("/proc/self/status").ok()?)
}

fn vm_hwm_bytes(status: &str) -> Option<u64> {
    let line = status.lines().find_map(|line| line.strip_prefix("VmHWM:"))?;
    let kib = line.trim().strip_suffix("kB")?.trim().parse::<u64>().ok()?;
    Some(kib * 1024)
}

fn seconds<S: Serializer>(duration: &Duration, serializer: S) -> Result<S::Ok, S::Error> {
    serializer.serialize_f64(duration.as_secs_f64())
}

fn optional_seconds<S: Serializer>(duration: &Option<Duration>, serializer: S) -> Result<S::Ok, S::Error> {
    duration.map(|d| d.as_secs_f64()).serialize(serializer)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn peak_memory_comes_from_vm_hwm_in_kib() {
        let status = "Name:\tgoldray\nVmPeak:\t  20000 kB\nVmHWM:\t    1234 kB\nVmRSS:\t 1000 kB\n";
        assert_eq!(vm_hwm_bytes(status), Some(1234 * 1024));
        assert_eq!(vm_hwm_bytes("Name:\tgoldray\n"), None);
        if cfg!(target_os = "linux") {
            assert!(peak_resident_bytes().is_some_and(|bytes| bytes > 0));
        }
    }

    #[test]
    fn rates_are_millions_of_rays_per_second_of_render_time() {
        let rays = RayCounts {
            camera: 3_000_000,
            aov: 0,
            shadow: 1_000_000,
            reflection: 0,
        };
        let phases = Phases {
            render: Duration::from_secs(2),
            ..Phases::default()
        };
        let stats = RenderStats::new("tiny", (200, 200), phases, BuildStats::default(), &rays, 2);
        assert_eq!(
            (stats.case.as_str(), stats.width, stats.height, stats.threads),
            ("tiny", 200, 200, 2)
        );
        assert_eq!(stats.mrays_per_second.camera, 1.5);
        assert_eq!(stats.mrays_per_second.shadow, 0.5);
        assert_eq!(stats.mrays_per_second.total, 2.0);
        assert_eq!(stats.rays.rows()[4], ("total", 4_000_000));
        let instant = RenderStats::new("tiny", (200, 200), Phases::default(), BuildStats::default(), &rays, 1);
        assert_eq!(instant.mrays_per_second.total, 0.0, "no division by a zero render time");
    }
}
