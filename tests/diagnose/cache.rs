//! The mistake cache: each distinct picture stored once, read back to the same diagnoses.

use super::*;

/// The mistakes' pictures are stored once per distinct picture (most mistakes leave a render's
/// normals and depth as the golden draws them), every set's file a link to it, and a grading
/// that reads them back names the same mistakes.
#[cfg(unix)]
#[test]
fn the_mistake_cache_stores_each_picture_once() {
    use std::os::unix::fs::MetadataExt;
    let dir = fresh_dir("diagnose-content-cache");
    let rubric_path = course_rubric(&dir);
    let rubric = load_rubric(&rubric_path).unwrap();
    let renderers = renderers_for(&rubric, Perturbation::None);
    let submissions = dir.join("submissions");
    let made: FaultSet = "no-shadows".parse().unwrap();
    write_student(&rubric, &renderers, &made, Perturbation::None, &submissions.join("s"));
    let grade = |out: &str| {
        let options = GradeOptions {
            out: dir.join(out),
            cache: Some(dir.join("cache")),
            ..GradeOptions::default()
        };
        grade_class(&rubric_path, &submissions, &options, &Silent).unwrap()
    };
    let first = grade("first");
    let faults = dir.join("cache/faults");
    let (mut files, mut inodes, mut contents) = (0, std::collections::HashSet::new(), 0);
    for render in fs::read_dir(&faults).unwrap() {
        for set in fs::read_dir(render.unwrap().path()).unwrap() {
            let set = set.unwrap().path();
            for file in fs::read_dir(&set).unwrap() {
                let meta = file.unwrap().metadata().unwrap();
                if set.ends_with("by-content") {
                    contents += 1;
                } else {
                    files += 1;
                    inodes.insert((meta.dev(), meta.ino()));
                }
            }
        }
    }
    assert!(files > 0, "nothing cached in {}", faults.display());
    assert_eq!(
        inodes.len(),
        contents,
        "every set's file is a link to one stored picture"
    );
    assert!(contents * 2 < files, "{contents} pictures stored for {files} files");

    let second = grade("second");
    let read: usize = second
        .diagnosis
        .as_ref()
        .unwrap()
        .renders
        .iter()
        .map(|r| r.cached)
        .sum();
    let rendered: usize = second
        .diagnosis
        .as_ref()
        .unwrap()
        .renders
        .iter()
        .map(|r| r.rendered)
        .sum();
    assert!(read > 0 && rendered == 0, "read {read}, rendered {rendered}");
    let ids = |report: &ClassReport| -> Vec<Option<String>> {
        report.students[0]
            .images
            .iter()
            .map(|i| i.diagnosis.as_ref().map(|d| d.id.clone()))
            .collect()
    };
    assert_eq!(ids(&first), ids(&second));
    assert!(ids(&second).contains(&Some("no-shadows".to_owned())));
}
