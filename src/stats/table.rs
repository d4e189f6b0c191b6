//! The `--stats` table: one section per question (where did the time go, what did the BVHs
//! cost, how many rays and how fast, how much memory), numbers right-aligned so that two runs'
//! tables can be compared by eye.

use std::fmt::{self, Display, Formatter};
use std::time::Duration;

use super::{BvhStats, RenderStats};

const LABEL_WIDTH: usize = 32;
const VALUE_WIDTH: usize = 13;

impl Display for RenderStats {
    fn fmt(&self, f: &mut Formatter<'_>) -> fmt::Result {
        let threads = if self.threads == 1 {
            "1 thread".to_string()
        } else {
            format!("{} threads", self.threads)
        };
        let host = self
            .host
            .as_deref()
            .map(|host| format!(" on {host}"))
            .unwrap_or_default();
        writeln!(
            f,
            "Statistics for {} ({}×{}, {threads}{host})",
            self.case, self.width, self.height
        )?;
        let times = &self.seconds;
        heading(f, "Time", &[])?;
        row(f, 4, "parse", &[duration(times.parse)])?;
        row(f, 4, "build scene", &[duration(times.build)])?;
        let build = &self.build;
        if let Some(time) = build.cube_map_load_time {
            row(f, 6, "cube map load", &[duration(time)])?;
        }
        for mesh in &build.meshes {
            let name = file_name(&mesh.path);
            row(f, 6, &format!("{name}: OBJ load"), &[duration(mesh.load_time)])?;
            row(f, 6, &format!("{name}: BVH build"), &[duration(mesh.bvh.build_time)])?;
        }
        if let Some(bvh) = &build.scene_bvh {
            row(f, 6, "scene BVH build", &[duration(bvh.build_time)])?;
        }
        row(f, 4, "render", &[duration(times.render)])?;
        // Faces are loaded when a ray first looks at them, so during the render.
        if let Some(faces) = build.cube_map_faces {
            let loaded = format!("{} decoded, {} cached", faces.decoded, faces.read_from_cache);
            row(f, 6, "cube map faces", &[loaded])?;
        }
        row(f, 4, "write outputs", &[duration(times.write)])?;
        row(f, 4, "total", &[duration(times.total)])?;

        let bvhs: Vec<(String, &BvhStats)> = build
            .meshes
            .iter()
            .map(|mesh| (file_name(&mesh.path), &mesh.bvh))
            .chain(build.scene_bvh.iter().map(|bvh| ("scene (objects)".to_string(), bvh)))
            .collect();
        if bvhs.is_empty() {
            heading(f, "BVH", &["none"])?;
        } else {
            heading(f, "BVH", &["primitives", "nodes", "leaves"])?;
            for (name, bvh) in bvhs {
                row(
                    f,
                    4,
                    &name,
                    &[
                        grouped(bvh.primitives as u64),
                        grouped(bvh.nodes as u64),
                        grouped(bvh.leaves as u64),
                    ],
                )?;
            }
        }

        heading(f, "Rays", &["count", "Mrays/s"])?;
        for ((kind, count), (_, rate)) in self.rays.rows().into_iter().zip(self.mrays_per_second.rows()) {
            row(f, 4, kind, &[grouped(count), format!("{rate:.2}")])?;
        }
        let memory = self.peak_memory_bytes.map_or_else(
            || "unavailable".to_string(),
            |bytes| format!("{:.1} MiB", bytes as f64 / (1024.0 * 1024.0)),
        );
        heading(f, "Peak resident memory", &[&memory])
    }
}

fn heading(f: &mut Formatter<'_>, title: &str, columns: &[&str]) -> fmt::Result {
    let columns: Vec<String> = columns.iter().map(|c| c.to_string()).collect();
    row(f, 2, title, &columns)
}

fn row(f: &mut Formatter<'_>, indent: usize, label: &str, values: &[String]) -> fmt::Result {
    let label = format!("{:indent$}{label}", "");
    if values.is_empty() {
        return writeln!(f, "{label}");
    }
    write!(f, "{label:<LABEL_WIDTH$}")?;
    for value in values {
        write!(f, "{value:>VALUE_WIDTH$}")?;
    }
    writeln!(f)
}

/// Milliseconds below ten seconds, where renders of the shipped cases fall; seconds above.
fn duration(duration: Duration) -> String {
    let seconds = duration.as_secs_f64();
    if seconds < 10.0 {
        format!("{:.2} ms", seconds * 1e3)
    } else {
        format!("{seconds:.2} s")
    }
}

/// `1234567` → `1,234,567`: ray counts run to billions.
pub(crate) fn grouped(n: u64) -> String {
    let digits = n.to_string();
    let mut out = String::with_capacity(digits.len() + digits.len() / 3);
    for (index, digit) in digits.chars().enumerate() {
        if index > 0 && (digits.len() - index).is_multiple_of(3) {
            out.push(',');
        }
        out.push(digit);
    }
    out
}

fn file_name(path: &std::path::Path) -> String {
    path.file_name()
        .unwrap_or(path.as_os_str())
        .to_string_lossy()
        .into_owned()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn groups_thousands() {
        assert_eq!(grouped(0), "0");
        assert_eq!(grouped(999), "999");
        assert_eq!(grouped(1000), "1,000");
        assert_eq!(grouped(1_310_720), "1,310,720");
    }

    #[test]
    fn durations_are_milliseconds_then_seconds() {
        assert_eq!(duration(Duration::from_micros(1500)), "1.50 ms");
        assert_eq!(duration(Duration::from_millis(12_346)), "12.35 s");
    }
}
