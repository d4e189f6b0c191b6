//! A rubric that grants credit per mistake.

use super::*;

#[test]
fn a_rubric_can_grant_credit_per_mistake() {
    let dir = fresh_dir("diagnose-credit");
    let plain = course_rubric(&dir);
    let rubric = load_rubric(&plain).unwrap();
    let renderers = renderers_for(&rubric, Perturbation::None);
    let submissions = dir.join("submissions");
    write_student(
        &rubric,
        &renderers,
        &"no-shadows".parse().unwrap(),
        Perturbation::None,
        &submissions.join("s"),
    );
    let credited = dir.join("credited.toml");
    let text = fs::read_to_string(&plain).unwrap();
    fs::write(&credited, format!("{text}\n[mistake.\"no-shadows\"]\ncredit = 0.75\n")).unwrap();
    let cache = Some(Path::new(env!("CARGO_TARGET_TMPDIR")).join("diagnose-cache"));
    let grade = |rubric: &Path, out: &str| {
        let options = GradeOptions {
            out: dir.join(out),
            cache: cache.clone(),
            ..GradeOptions::default()
        };
        grade_class(rubric, &submissions, &options, &Silent).unwrap()
    };
    let without = grade(&plain, "plain");
    let with = grade(&credited, "credited");
    let a07 = |r: &ClassReport| r.students[0].images[18].clone();
    assert_eq!(a07(&without).points, 0.0, "{}", a07(&without).explanation);
    assert_eq!(a07(&with).points, 1.5, "{}", a07(&with).explanation);
    assert_eq!(a07(&with).diagnosis.unwrap().credit, Some(0.75));
    assert!(
        a07(&with)
            .explanation
            .contains("75% of the points for the diagnosed mistake no-shadows")
    );
    assert_eq!(with.students[0].total, without.students[0].total + 1.5);
    // The other images are as they were.
    for (a, b) in with.students[0]
        .images
        .iter()
        .zip(&without.students[0].images)
        .filter(|(a, _)| a.file != "a07.png")
    {
        assert_eq!(a.points, b.points, "{}", a.file);
    }

    fs::write(&credited, format!("{text}\n[mistake.\"no-shadow\"]\ncredit = 0.75\n")).unwrap();
    let error = load_rubric(&credited).unwrap_err().to_string();
    assert!(
        error.contains("not a mistake of the catalogue") && error.contains("did you mean `no-shadows`"),
        "{error}"
    );
    fs::write(&credited, format!("{text}\n[mistake.\"no-shadows\"]\ncredit = 2\n")).unwrap();
    let error = load_rubric(&credited).unwrap_err().to_string();
    assert!(error.contains("between 0 and 1"), "{error}");
}
