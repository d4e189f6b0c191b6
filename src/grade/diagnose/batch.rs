//! Diagnosing a batch of students: the mistakes' pictures of each render the batch lost points
//! on, read from the cache (or rendered), compared with the students' pictures, and the decision
//! for each image; and filling the cache once for a class (`--prepare`).

use std::collections::{BTreeMap, HashSet};
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::time::Instant;

use rayon::prelude::*;

use super::super::error::GradeError;
use super::super::golden::{CacheMode, Goldens};
use super::super::rubric::Rubric;
use super::super::score::StudentResult;
use super::super::submission::read_png;
use super::{
    Candidate, Diagnosis, DiagnosisRun, RenderDiagnosis, Scored, Subject, UNEXPLAINED, candidates, decide, expansions,
    fit_background, fit_gamma, grow, loses_points, pictures, residual, shrink, student_dir,
};
use crate::fault::FaultSet;
use crate::film::Picture;

/// Where diagnosis finds (and may keep) the mistakes' pictures, and the mistake pictures already
/// written into the report by this run.
pub(in crate::grade) struct Diagnoser<'a> {
    rubric: &'a Rubric,
    goldens: &'a Goldens,
    cache: &'a Path,
    cache_mode: CacheMode,
    out: &'a Path,
    written: Mutex<HashSet<PathBuf>>,
    run: Mutex<DiagnosisRun>,
}

impl<'a> Diagnoser<'a> {
    pub fn new(
        rubric: &'a Rubric,
        goldens: &'a Goldens,
        cache: &'a Path,
        cache_mode: CacheMode,
        out: &'a Path,
    ) -> Self {
        Diagnoser {
            rubric,
            goldens,
            cache,
            cache_mode,
            out,
            written: Mutex::new(HashSet::new()),
            run: Mutex::new(DiagnosisRun::default()),
        }
    }

    /// What this run's diagnosis cost, render by render.
    pub fn run(self) -> DiagnosisRun {
        self.run.into_inner().unwrap_or_else(|p| p.into_inner())
    }

    fn store<'b>(
        &self,
        key: &str,
        case: &'b crate::case::Case,
        film: &'b crate::film::Film,
        pictures: Vec<Picture>,
        stored: Vec<Picture>,
    ) -> pictures::FaultPictures<'b> {
        pictures::FaultPictures::new(
            Some(self.cache.join("faults").join(key)),
            self.cache_mode,
            case,
            film,
            pictures,
            stored,
        )
    }

    /// Diagnoses every image of `students` that lost points, writes the mistakes' pictures and
    /// the residual heatmaps into the report, and fills in each such image's [`Diagnosis`]. A
    /// student's diagnosis depends on that student's images alone (the fault sets tried beyond
    /// the single mistakes are those the student's own images ask for), so that grading a class
    /// in slices, or again after a few submissions changed, names the same mistakes.
    pub fn diagnose(&self, students: &mut [StudentResult]) -> Result<(), GradeError> {
        let (rubric, goldens, out) = (self.rubric, self.goldens, self.out);
        let started = Instant::now();
        let mut renders = Vec::new();
        for (key, images) in render_groups(goldens) {
            let failing: Vec<(usize, usize)> = students
                .iter()
                .enumerate()
                .flat_map(|(s, student)| {
                    images
                        .iter()
                        .filter(|&&i| loses_points(&student.images[i]))
                        .map(move |&i| (s, i))
                })
                .collect();
            if failing.is_empty() {
                continue;
            }
            let render_started = Instant::now();
            let source = &rubric.renders[rubric.images[images[0]].render_index];
            // The pictures compared: those of the images that lost points; every picture of the
            // render is cached, for the gradings to come.
            let pictures = distinct_pictures(rubric, &mut failing.iter().map(|&(_, i)| i));
            let stored = distinct_pictures(rubric, &mut images.iter().copied());
            let film = goldens.films[images[0]].clone();
            let store = self.store(key, &source.case, &film, pictures, stored);
            // A fault set that cannot be rendered (it cannot, for the course's scenes) is left out
            // and said in the run's record, rather than stopping the grading.
            let failed = Mutex::new(Vec::new());
            let get = |set: FaultSet| match store.get(&set) {
                Ok(pictures) => Some(Candidate { set, pictures }),
                Err(error) => {
                    failed
                        .lock()
                        .unwrap_or_else(|p| p.into_inner())
                        .push(format!("{set}: {error}"));
                    None
                }
            };
            let golden_pictures = store.golden();
            // Where the golden primary rays hit nothing (the background shows).
            let misses: Vec<bool> = store.golden_film().depth.iter().map(|t| *t == f32::INFINITY).collect();
            // Read or rendered side by side: decoding cached pictures is most of a warm run's cost.
            let singles: Vec<Candidate> = candidates::singles(&source.case, store.pictures())
                .into_par_iter()
                .filter_map(get)
                .collect();

            // The students' pictures and their singles' scores, in parallel.
            let subjects: Vec<Option<Subject>> = failing
                .par_iter()
                .map(|&(s, i)| {
                    let spec = &rubric.images[i];
                    let index = store.pictures().iter().position(|p| *p == spec.output.picture())?;
                    let file = students[s].images[i].graded_file.as_ref()?;
                    let student = read_png(file).ok()?.picture;
                    let golden = &golden_pictures[index];
                    if student.dimensions() != golden.dimensions() {
                        return None;
                    }
                    let block = residual::block_size(golden);
                    Some(Subject {
                        spec,
                        picture: index,
                        by_pixel: residual::residual(golden, &student, spec.rule.threshold),
                        by_block: residual::block_residual(golden, &student, spec.rule.threshold, block),
                        student,
                        golden,
                        block,
                    })
                })
                .collect();
            let scored: Vec<Vec<Scored>> = subjects
                .par_iter()
                .map(|subject| match subject {
                    Some(subject) => singles.iter().filter_map(|c| subject.score(c)).collect(),
                    None => Vec::new(),
                })
                .collect();

            // What each student's images want tried next, rendered once for all of them.
            let mut wanted: BTreeMap<usize, Vec<FaultSet>> = BTreeMap::new();
            for ((subject, scores), &(s, _)) in subjects.iter().zip(&scored).zip(&failing) {
                if let Some(subject) = subject {
                    let background = fit_background(subject, &misses, &singles);
                    let student_wants = wanted.entry(s).or_default();
                    for set in expansions(&source.case, subject, scores, &singles)
                        .into_iter()
                        .chain(background)
                    {
                        if !student_wants.contains(&set) && !singles.iter().any(|c| c.set == set) {
                            student_wants.push(set);
                        }
                    }
                }
            }
            let mut all_wanted: Vec<FaultSet> = Vec::new();
            for set in wanted.values().flatten() {
                if !all_wanted.contains(set) {
                    all_wanted.push(*set);
                }
            }
            let fault_sets = singles.len() + all_wanted.len();
            let expanded: Vec<Candidate> = all_wanted.into_par_iter().filter_map(get).collect();

            // In the order the student's images asked for them, whoever else asked.
            let asked: Vec<Vec<&Candidate>> = failing
                .iter()
                .map(|(s, _)| {
                    let student_wants = wanted.get(s).map_or(&[][..], Vec::as_slice);
                    student_wants
                        .iter()
                        .filter_map(|set| expanded.iter().find(|c| c.set == *set))
                        .collect()
                })
                .collect();
            let mut scored: Vec<Vec<Scored>> = subjects
                .par_iter()
                .zip(scored.into_par_iter().zip(asked.par_iter()))
                .map(|(subject, (mut scores, expanded))| {
                    let Some(subject) = subject.as_ref() else {
                        return scores;
                    };
                    let known = |set: &FaultSet| singles.iter().chain(expanded.iter().copied()).find(|c| c.set == *set);
                    // A pair that draws this picture as one of its faults alone does has no
                    // evidence of the other.
                    let adds_nothing = |c: &Candidate| {
                        c.set.len() > 1
                            && c.set.faults().any(|f| {
                                known(&c.set.without(f))
                                    .is_some_and(|m| m.pictures[subject.picture] == c.pictures[subject.picture])
                            })
                    };
                    scores.extend(
                        expanded
                            .iter()
                            .filter(|c| !adds_nothing(c))
                            .filter_map(|c| subject.score(c)),
                    );
                    scores.extend(fit_gamma(subject, &store, &scores));
                    scores
                })
                .collect();
            // Several faults at once, for the images nothing above explains.
            let known: Vec<&Candidate> = singles.iter().chain(&expanded).collect();
            let grown = grow::grow(&subjects, &mut scored, &known, &singles, &get);
            let shrunk = shrink::shrink(&subjects, &mut scored, &singles, &get);
            let fault_sets = fault_sets + grown.len() + shrunk.len();
            let decided: Vec<Option<(Diagnosis, usize, usize)>> = failing
                .par_iter()
                .zip(subjects.par_iter().zip(scored.par_iter().zip(asked.par_iter())))
                .map(|(&(s, i), (subject, (scores, expanded)))| {
                    let subject = subject.as_ref()?;
                    let slug = student_dir(&students[s]);
                    let diagnosis = decide(subject, scores, &store, expanded, &singles, out, &slug, &self.written);
                    Some((diagnosis, s, i))
                })
                .collect();
            let mut explained = 0;
            for (diagnosis, s, i) in decided.into_iter().flatten() {
                explained += usize::from(diagnosis.id != UNEXPLAINED);
                students[s].images[i].diagnosis = Some(diagnosis);
            }
            renders.push((
                failing.len(),
                explained,
                RenderDiagnosis {
                    render: source.name.clone(),
                    images: failing.len(),
                    fault_sets,
                    rendered: store.rendered.load(std::sync::atomic::Ordering::Relaxed),
                    cached: store.cached.load(std::sync::atomic::Ordering::Relaxed),
                    seconds: render_started.elapsed().as_secs_f64(),
                    failed: failed.into_inner().unwrap_or_else(|p| p.into_inner()),
                },
            ));
        }
        let mut batch = DiagnosisRun {
            seconds: started.elapsed().as_secs_f64(),
            ..DiagnosisRun::default()
        };
        for (images, explained, render) in renders {
            batch.images += images;
            batch.explained += explained;
            batch.renders.push(render);
        }
        self.run.lock().unwrap_or_else(|p| p.into_inner()).add(&batch);
        Ok(())
    }
}

/// Renders (or finds in `cache`) every single mistake's pictures of every render of the rubric and
/// caches them, so that later gradings, and shards that only read the cache, find them there.
/// Returns how many fault sets were rendered now.
pub(in crate::grade) fn prepare_mistakes(rubric: &Rubric, goldens: &Goldens, cache: &Path) -> usize {
    let mut rendered = 0;
    for (key, images) in render_groups(goldens) {
        let source = &rubric.renders[rubric.images[images[0]].render_index];
        let pictures = distinct_pictures(rubric, &mut images.iter().copied());
        let film = goldens.films[images[0]].clone();
        let store = pictures::FaultPictures::new(
            Some(cache.join("faults").join(key)),
            CacheMode::ReadWrite,
            &source.case,
            &film,
            pictures.clone(),
            pictures,
        );
        candidates::singles(&source.case, store.pictures())
            .into_par_iter()
            .for_each(|set| drop(store.get(&set)));
        rendered += store.rendered.load(std::sync::atomic::Ordering::Relaxed);
    }
    rendered
}

impl DiagnosisRun {
    /// Another batch's (or shard's) diagnosis added in.
    pub fn add(&mut self, other: &DiagnosisRun) {
        self.seconds += other.seconds;
        self.images += other.images;
        self.explained += other.explained;
        for render in &other.renders {
            match self.renders.iter_mut().find(|r| r.render == render.render) {
                Some(known) => known.add(render.clone()),
                None => self.renders.push(render.clone()),
            }
        }
    }
}

impl RenderDiagnosis {
    /// Another batch of students' diagnosis of the same render.
    fn add(&mut self, other: RenderDiagnosis) {
        self.images += other.images;
        self.fault_sets = self.fault_sets.max(other.fault_sets);
        self.rendered += other.rendered;
        self.cached += other.cached;
        self.seconds += other.seconds;
        self.failed.extend(other.failed);
    }
}

/// The rubric's images grouped by golden render (two rubric renders with the same content are
/// one), in rubric order.
fn render_groups(goldens: &Goldens) -> Vec<(&str, Vec<usize>)> {
    let mut groups: BTreeMap<&str, Vec<usize>> = BTreeMap::new();
    for (index, key) in goldens.keys.iter().enumerate() {
        groups.entry(key.as_str()).or_default().push(index);
    }
    let mut groups: Vec<(&str, Vec<usize>)> = groups.into_iter().collect();
    groups.sort_by_key(|(_, images)| images[0]);
    groups
}

/// The distinct film pictures of some of the rubric's images, in order of first use.
fn distinct_pictures(rubric: &Rubric, images: &mut dyn Iterator<Item = usize>) -> Vec<Picture> {
    let mut pictures: Vec<Picture> = Vec::new();
    for i in images {
        let picture = rubric.images[i].output.picture();
        if !pictures.contains(&picture) {
            pictures.push(picture);
        }
    }
    pictures
}
