//! Memory stays flat as the class grows: students are streamed, so grading 1,000 students takes
//! about the peak memory of grading 10. Measured on the `goldray grade` process itself (its
//! maximum resident set size, from `wait4`), with 64×64 pictures so that the test takes seconds.

use std::fs;
use std::path::Path;
use std::process::Command;

use goldray::film::{Tonemap, color_image, encode_png};
use goldray::rgb_image::Rgb;

use super::class::{case, render, scene_path};

/// A one-image rubric over the class scene at 64×64: small enough to grade 1,000 students in
/// seconds, large enough that holding every student's picture (12 KiB, 48 KiB as compared) would
/// show.
fn rubric(dir: &Path) -> std::path::PathBuf {
    let path = dir.join("rubric.toml");
    fs::write(
        &path,
        format!(
            "[render.spheres]\ncase = {:?}\nsize = [64, 64]\n\n[image.\"color.png\"]\nrender = \"spheres\"\n",
            scene_path()
        ),
    )
    .unwrap();
    path
}

/// `students` folders: most identical to the golden picture, some with one pixel off, one in ten
/// failing (colours inverted), which is diagnosed.
fn class(dir: &Path, students: usize) -> std::path::PathBuf {
    let mut small = case();
    small.render.trace.width = 64;
    small.render.trace.height = 64;
    let golden = color_image(&render(&small), Tonemap::Clamp);
    let submissions = dir.join(format!("class-{students}"));
    for student in 0..students {
        let mut picture = golden.clone();
        match student % 10 {
            0..=5 => {}
            6..=8 => picture.put_pixel((student % 64) as u32, 3, Rgb([255, 0, 255])),
            _ => picture.pixels_mut().for_each(|p| p.0 = p.0.map(|c| 255 - c)),
        }
        let folder = submissions.join(format!("student{student:04}"));
        fs::create_dir_all(&folder).unwrap();
        fs::write(folder.join("color.png"), encode_png(&picture).unwrap()).unwrap();
    }
    submissions
}

/// Grades `submissions` on two threads and returns the process's peak resident memory in KiB.
fn peak_kib(rubric: &Path, submissions: &Path, out: &Path, cache: &Path) -> i64 {
    // Reaped by `wait4` below, which `Child::wait` cannot replace: it also returns the usage.
    #[allow(clippy::zombie_processes)]
    let child = Command::new(env!("CARGO_BIN_EXE_goldray"))
        .args(["grade", "--quiet", "--threads", "2", "--rubric"])
        .args([rubric, submissions])
        .arg("--out")
        .arg(out)
        .arg("--cache")
        .arg(cache)
        .spawn()
        .expect("the goldray binary runs");
    let mut status = 0;
    // SAFETY: an all-zero `rusage` is a valid value for the kernel to overwrite.
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    // SAFETY: `wait4` on our own child, with valid pointers to `status` and `usage`; the child is
    // reaped here, and `Child` never waits for it again.
    let pid = unsafe { libc::wait4(child.id() as libc::pid_t, &mut status, 0, &mut usage) };
    assert_eq!(pid, child.id() as libc::pid_t);
    assert!(
        libc::WIFEXITED(status) && libc::WEXITSTATUS(status) == 0,
        "status {status}"
    );
    assert!(out.join("grades.csv").exists());
    usage.ru_maxrss
}

#[test]
fn peak_memory_of_a_thousand_students_is_close_to_that_of_ten() {
    let dir = tempfile::tempdir().unwrap();
    let rubric = rubric(dir.path());
    let cache = dir.path().join("cache");
    let small = class(dir.path(), 10);
    let large = class(dir.path(), 1000);
    // The golden picture and the mistakes' pictures rendered once; both measured runs read them.
    let prepared = Command::new(env!("CARGO_BIN_EXE_goldray"))
        .args(["grade", "--prepare", "--quiet", "--rubric"])
        .arg(&rubric)
        .arg("--cache")
        .arg(&cache)
        .status()
        .unwrap();
    assert!(prepared.success());
    let ten = peak_kib(&rubric, &small, &dir.path().join("ten"), &cache);
    let thousand = peak_kib(&rubric, &large, &dir.path().join("thousand"), &cache);
    println!("peak resident memory: 10 students {ten} KiB, 1000 students {thousand} KiB");
    assert!(
        (thousand as f64) < 1.5 * ten as f64,
        "10 students {ten} KiB, 1000 students {thousand} KiB"
    );
}
