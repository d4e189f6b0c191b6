//! One grading run over a class, streamed: students are graded a batch at a time, each student's
//! result written to the report as soon as the student is done (see `resume`), and only results
//! (never pictures) kept until the class-wide report is written. Memory therefore does not grow
//! with the class beyond a few kilobytes per student.

use std::collections::BTreeMap;
use std::fs;
use std::path::{Path, PathBuf};
use std::time::Instant;

use rayon::prelude::*;

use super::diagnose::{self, Diagnoser};
use super::diagnosis::DiagnosisRun;
use super::error::GradeError;
use super::golden::{CacheMode, default_cache_dir, prepare_goldens, write_golden_pictures};
use super::lms::{Class, Layout, Limits, Source, Student as LmsStudent, read_class, stage};
use super::report::{self, ClassReport, RubricSummary};
use super::resume::{StudentRecord, read_record, run_fingerprint, student_fingerprint, write_record};
use super::rubric::{Rubric, load_rubric};
use super::score::{Golden, StudentResult, Submission, grade_image};
use super::shard::{Manifest, Shard, copy_pictures, read_shards, write_manifest};
use super::similarity::{self, similar_pairs};
use super::timing::{RunCost, Timings, timed};
use super::{Diagnose, GradeOptions, html, integrity};
use crate::film::OutputError;
use crate::progress::Progress;

/// Students graded (and diagnosed) together: enough to keep every core busy, few enough that
/// their pictures, decoded for diagnosis, stay a bounded amount of memory.
const BATCH: usize = 16;

/// [`super::grade_class`], diagnosing or not. Students are streamed (in batches of [`BATCH`]); each one's result
/// is kept in the report folder, and reused by the next run with the same inputs unless
/// `options.force`. With a shard, only that slice is graded and the class-wide files are left to
/// [`super::merge_shards`].
pub fn grade(
    rubric_path: &Path,
    submissions: &Path,
    options: &GradeOptions,
    diagnose: Diagnose,
    progress: &dyn Progress,
) -> Result<ClassReport, GradeError> {
    let started = Instant::now();
    let rubric = load_rubric(rubric_path)?;
    let cache = options.cache.clone().unwrap_or_else(default_cache_dir);
    let expected: Vec<&str> = rubric.images.iter().map(|spec| spec.file.as_str()).collect();
    let class = read_class(submissions, &[&options.out, &cache], &expected, Limits::default())
        .map_err(submissions_error(submissions))?;
    let listed = Listed {
        rubric,
        started,
        submissions,
        class,
    };
    grade_listed(listed, options, diagnose, progress)
}

/// One student's folder graded as a class of one named `name`: what a student's self-check and
/// an autograder grade.
pub fn grade_one(
    rubric_path: &Path,
    folder: &Path,
    name: &str,
    options: &GradeOptions,
    diagnose: Diagnose,
    progress: &dyn Progress,
) -> Result<ClassReport, GradeError> {
    let started = Instant::now();
    let rubric = load_rubric(rubric_path)?;
    if !folder.is_dir() {
        let not_a_folder = std::io::Error::new(std::io::ErrorKind::NotADirectory, "not a folder");
        return Err(submissions_error(folder)(not_a_folder));
    }
    let class = Class {
        layout: Layout::Folders,
        archive: None,
        students: vec![LmsStudent {
            name: name.to_owned(),
            lms: None,
            source: Source::Folder(folder.to_path_buf()),
            shown: folder.to_path_buf(),
            refused: Vec::new(),
        }],
        ignored: Vec::new(),
        refused: Vec::new(),
    };
    let listed = Listed {
        rubric,
        started,
        submissions: folder,
        class,
    };
    grade_listed(listed, options, diagnose, progress)
}

/// What a class is graded from: the rubric, the students found and where, and when grading
/// started (the report's time includes reading the rubric and the class).
struct Listed<'a> {
    rubric: Rubric,
    started: Instant,
    submissions: &'a Path,
    class: Class,
}

/// The error of a submissions folder or download that cannot be read (or staged from).
fn submissions_error(path: &Path) -> impl FnOnce(std::io::Error) -> GradeError + '_ {
    move |source| GradeError::Submissions {
        path: path.to_path_buf(),
        source,
    }
}

/// Grades the students of `class`, read from `submissions`.
fn grade_listed(
    listed: Listed,
    options: &GradeOptions,
    diagnose: Diagnose,
    progress: &dyn Progress,
) -> Result<ClassReport, GradeError> {
    let Listed {
        rubric,
        started,
        submissions,
        class,
    } = listed;
    let out = &options.out;
    let cache = options.cache.clone().unwrap_or_else(default_cache_dir);
    // A download's students are staged here, one folder each, while they are graded.
    let staging = if class.students.iter().any(|s| matches!(s.source, Source::Files(_))) {
        Some(
            tempfile::Builder::new()
                .prefix("goldray-grade-")
                .tempdir()
                .map_err(submissions_error(submissions))?,
        )
    } else {
        None
    };
    let names: Vec<String> = class.students.iter().map(|s| s.name.clone()).collect();
    let slugs = report::slugs(&names);
    let range = options.shard.range(names.len());
    let cache_mode = if options.shard == Shard::WHOLE {
        CacheMode::ReadWrite
    } else {
        CacheMode::ReadOnly
    };
    let goldens = prepare_goldens(&rubric, &cache, cache_mode, progress)?;
    write_golden_pictures(&rubric, &goldens, out)?;
    let published = integrity::published_hashes(&rubric.integrity, rubric.images.iter().map(|spec| spec.file.as_str()));
    let run = run_fingerprint(&rubric, &goldens, &published, diagnose);
    let diagnoser = (diagnose == Diagnose::Yes).then(|| Diagnoser::new(&rubric, &goldens, &cache, cache_mode, out));

    let mut cost = RunCost {
        shards: 1,
        ..RunCost::default()
    };
    let mut students: Vec<StudentResult> = Vec::with_capacity(range.len());
    progress.begin("grading", range.len() as u64);
    let indices: Vec<usize> = range.clone().collect();
    for batch in indices.chunks(BATCH) {
        // Each student reused or graded, one task per student and image.
        let steps = batch
            .par_iter()
            .map(|&i| {
                let student = &class.students[i];
                let (submission, shown) = match &student.source {
                    Source::Folder(path) => (Submission::new(names[i].clone(), path.clone(), slugs[i].clone()), None),
                    Source::Files(items) => {
                        // Made above whenever a student has files to stage.
                        let Some(staging) = &staging else {
                            let no_staging = std::io::Error::other("no folder to stage a download's files in");
                            return Err(submissions_error(submissions)(no_staging));
                        };
                        let root = staging.path().join(&slugs[i]);
                        let mut staged = stage(items, class.archive.as_deref(), &root, Limits::default());
                        staged.refused.extend(student.refused.iter().cloned());
                        let submission = Submission::staged(
                            names[i].clone(),
                            root.clone(),
                            slugs[i].clone(),
                            student.shown.clone(),
                            student.lms.clone(),
                            &staged,
                        );
                        (submission, Some((root, staged.shown)))
                    }
                };
                let hashing = Instant::now();
                let inputs = student_fingerprint(&run, &submission, &rubric);
                let hashing = hashing.elapsed().as_secs_f64();
                if !options.force
                    && let Some(record) = read_record(out, &submission.slug, rubric.images.len())
                    && record.run == run
                    && record.inputs == inputs
                {
                    if let Some((root, _)) = &shown {
                        let _ = fs::remove_dir_all(root);
                    }
                    return Ok(Step::Reused(record));
                }
                // Pictures an earlier grading of this student left are no longer the student's.
                let _ = fs::remove_dir_all(out.join(submission.dir()));
                let graded = rubric
                    .images
                    .par_iter()
                    .zip(&goldens.images)
                    .zip(&goldens.allowances)
                    .map(|((spec, golden), allowance)| {
                        let mut timings = Timings::default();
                        let published = published.get(&spec.file).copied();
                        grade_image(
                            spec,
                            Golden {
                                picture: golden,
                                allowance: allowance.as_deref().map(Vec::as_slice),
                            },
                            &submission,
                            &rubric.integrity,
                            published,
                            out,
                            &mut timings,
                        )
                        .map(|result| (result, timings))
                    })
                    .collect::<Result<Vec<_>, OutputError>>()?;
                // Reading the files to fingerprint them counts as reading them.
                let mut timings = Timings {
                    decode: hashing,
                    ..Timings::default()
                };
                for (_, t) in &graded {
                    timings += *t;
                }
                let result = StudentResult::new(&submission, graded.into_iter().map(|(r, _)| r).collect());
                Ok(Step::Graded {
                    result,
                    inputs,
                    timings,
                    staged: shown,
                })
            })
            .collect::<Result<Vec<Step>, GradeError>>()?;

        let (mut fresh, mut fresh_inputs, mut fresh_timings) = (Vec::new(), Vec::new(), Vec::new());
        let mut fresh_staged = Vec::new();
        let mut order = Vec::new();
        for step in steps {
            match step {
                Step::Reused(record) => {
                    cost.reused += 1;
                    order.push(Err(record.into_result()));
                }
                Step::Graded {
                    result,
                    inputs,
                    timings,
                    staged,
                } => {
                    order.push(Ok(fresh.len()));
                    fresh_staged.push(staged);
                    fresh.push(result);
                    fresh_inputs.push(inputs);
                    fresh_timings.push(timings);
                }
            }
        }
        if let Some(diagnoser) = &diagnoser
            && !fresh.is_empty()
        {
            let diagnosis_started = Instant::now();
            diagnoser.diagnose(&mut fresh)?;
            diagnose::prefer_consistent(&mut fresh);
            diagnose::gather_unfinished(&mut fresh);
            diagnose::apply_credit(&rubric, &mut fresh);
            let share = diagnosis_started.elapsed().as_secs_f64() / fresh.len() as f64;
            for timings in &mut fresh_timings {
                timings.diagnosis += share;
            }
        }
        // Diagnosis has read the staged pictures: the report names where they are in the download.
        for (result, staged) in fresh.iter_mut().zip(fresh_staged) {
            if let Some((root, shown)) = staged {
                show_download_files(result, &root, &shown);
                let _ = fs::remove_dir_all(&root);
            }
        }
        fresh
            .par_iter()
            .zip(fresh_inputs)
            .zip(fresh_timings.par_iter_mut())
            .map(|((result, inputs), timings)| {
                let slug = result.page.strip_prefix("students/").unwrap_or(&result.page);
                let slug = slug.strip_suffix(".html").unwrap_or(slug);
                let record = StudentRecord::new(&run, inputs, result.clone(), *timings);
                timed(&mut timings.report, || write_record(out, slug, &record))
            })
            .collect::<Result<Vec<()>, OutputError>>()?;
        for timings in &fresh_timings {
            cost.timings += *timings;
        }
        cost.graded += fresh.len();
        let mut fresh = fresh.into_iter().map(Some).collect::<Vec<_>>();
        for entry in order {
            let (student, kept) = match entry {
                Ok(index) => (fresh[index].take(), false),
                Err(result) => (Some(result), true),
            };
            if let Some(student) = student {
                progress.advance(1);
                if kept {
                    progress.done(&format!("{} (kept from an earlier run)", student.name));
                } else {
                    progress.done(&student.name);
                }
                students.push(student);
            }
        }
    }
    progress.finish();

    let diagnosis = diagnoser.map(Diagnoser::run);
    let slice_slugs = slugs[range].to_vec();
    let mut report = ClassReport {
        goldray: env!("CARGO_PKG_VERSION"),
        rubric: RubricSummary::of(&rubric),
        submissions: submissions.to_path_buf(),
        layout: class.layout,
        cache: cache.clone(),
        goldens: goldens.renders,
        diagnosis,
        ignored: class.ignored,
        refused: class.refused,
        similar: Vec::new(),
        students,
        cost,
    };
    report.similar = find_similar(&report.students, out);
    if options.shard == Shard::WHOLE {
        write_report(&mut report, out, started)?;
    } else {
        report.cost.seconds = started.elapsed().as_secs_f64();
        report::write_run(&report, out)?;
    }
    let manifest = Manifest {
        goldray: report.goldray.to_owned(),
        run,
        shard: options.shard,
        class: names,
        slugs: slice_slugs,
        rubric: report.rubric.clone(),
        submissions: report.submissions.clone(),
        layout: report.layout,
        cache: report.cache.clone(),
        goldens: report.goldens.clone(),
        ignored: report.ignored.clone(),
        refused: report.refused.clone(),
        diagnosis: report.diagnosis.clone(),
        cost: report.cost.clone(),
    };
    write_manifest(&manifest, out)?;
    Ok(report)
}

/// A student of a batch: reused from an earlier run, or graded now (not yet diagnosed).
enum Step {
    Reused(StudentRecord),
    Graded {
        result: StudentResult,
        inputs: String,
        timings: Timings,
        /// For a download's student: the staging folder, and where each staged file came from.
        staged: Option<(PathBuf, BTreeMap<PathBuf, String>)>,
    },
}

/// Replaces the staged paths of a download's student's graded files by where the files are in
/// the download (`class.zip/alice_12_34_a01.png`, or inside the student's own zip), which is what
/// the report shows and what stays the same from one run to the next.
fn show_download_files(result: &mut StudentResult, root: &Path, shown: &BTreeMap<PathBuf, String>) {
    for image in &mut result.images {
        if let Some(file) = &mut image.graded_file
            && let Ok(relative) = file.strip_prefix(root)
        {
            *file = shown
                .get(relative)
                .map_or_else(|| result.folder.join(relative), PathBuf::from);
        }
    }
}

/// Combines the outputs of the N shards of a class (`shards`, in any order) into `out`: the
/// students' pictures copied, and `grades.csv`, `grades.json`, `index.html` and the students'
/// pages written as one run over the whole class writes them.
pub(super) fn merge(out: &Path, shards: &[PathBuf]) -> Result<ClassReport, GradeError> {
    let started = Instant::now();
    let shards = read_shards(shards)?;
    for shard in &shards {
        copy_pictures(shard, out)?;
    }
    let first = &shards[0].manifest;
    let mut cost = RunCost::default();
    let mut diagnosis: Option<DiagnosisRun> = None;
    for shard in &shards {
        cost += &shard.manifest.cost;
        if let Some(run) = &shard.manifest.diagnosis {
            diagnosis.get_or_insert_with(DiagnosisRun::default).add(run);
        }
    }
    let (rubric, submissions, cache, goldens, ignored) = (
        first.rubric.clone(),
        first.submissions.clone(),
        first.cache.clone(),
        first.goldens.clone(),
        first.ignored.clone(),
    );
    let (layout, refused) = (first.layout, first.refused.clone());
    let students: Vec<StudentResult> = shards
        .into_iter()
        .flat_map(|shard| shard.records)
        .map(StudentRecord::into_result)
        .collect();
    let mut report = ClassReport {
        goldray: env!("CARGO_PKG_VERSION"),
        rubric,
        submissions,
        layout,
        cache,
        goldens,
        diagnosis,
        ignored,
        refused,
        similar: find_similar(&students, out),
        students,
        cost,
    };
    let shards_seconds = report.cost.seconds;
    write_report(&mut report, out, started)?;
    report.cost.seconds += shards_seconds;
    report::write_run(&report, out)?;
    Ok(report)
}

/// Writes the class-wide files: `grades.csv`, `grades.json`, the HTML pages and `run.json`.
fn write_report(report: &mut ClassReport, out: &Path, started: Instant) -> Result<(), GradeError> {
    let report_started = Instant::now();
    report::write_data(report, out)?;
    html::write_html(report, out)?;
    report.cost.timings.report += report_started.elapsed().as_secs_f64();
    report.cost.seconds = started.elapsed().as_secs_f64();
    report::write_run(report, out)?;
    Ok(())
}

/// Pairs of students who handed in the same (or nearly the same failing) picture. A picture that
/// lost points is compared in full from the report's copy of it (in `out`), which is there for
/// every such picture however the class was read: a download's staged files are gone by now, and
/// shards merged on another machine never had the submissions.
fn find_similar(students: &[StudentResult], out: &Path) -> Vec<similarity::SimilarPair> {
    let copies: Vec<Vec<Option<PathBuf>>> = students
        .iter()
        .map(|student| {
            student
                .images
                .iter()
                .map(|image| match &image.student_image {
                    Some(copy) if copy.starts_with("students/") => Some(out.join(copy)),
                    _ => image.graded_file.clone(),
                })
                .collect()
        })
        .collect();
    similar_pairs(
        &students
            .iter()
            .zip(&copies)
            .flat_map(|(student, copies)| {
                student
                    .images
                    .iter()
                    .zip(copies)
                    .enumerate()
                    .filter_map(|(order, (image, copy))| {
                        Some(similarity::Entry {
                            student: &student.name,
                            file: &image.file,
                            order,
                            path: copy.as_deref()?,
                            fingerprint: image.fingerprint.as_ref()?,
                        })
                    })
            })
            .collect::<Vec<_>>(),
    )
}
