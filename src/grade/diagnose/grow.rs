//! Fault sets of any size, for an image that no single fault, family member or pair explains:
//! unfinished code has several parts missing at once. A small beam search grows sets one fault
//! at a time:
//!
//! 1. each set of the beam (at first the closest sets found so far) is offered the single faults
//!    that change the golden picture where the student's image still fails against the set's
//!    picture, and not where it already agrees with it and the set draws the golden picture
//!    (counted from the pictures alone, so only promising sets are rendered): the [`OFFERED`]
//!    best parts not written and the [`OFFERED`] best mistakes in written code, so that where
//!    both draw the same (a sphere gone unlit on black, a sphere gone), the part not written is
//!    there for the decision to prefer;
//! 2. the set with the fault added is rendered and kept only if the fault has evidence of its
//!    own: where the grown set's picture differs from the set's, the student's image comes
//!    clearly closer to the grown one on a real share of what was left failing, and to the old
//!    one on few pixels ("closer", not "equal": a missing plane shows the background, which is
//!    itself right only once the missing background is added too); and only if each of its
//!    faults changes its picture (a fault hidden by another, such as a flipped normal under flat
//!    colours, has no evidence);
//! 3. the [`BEAM`] closest sets kept are grown again, until one passes against its picture, no
//!    fault has evidence, or a set has [`MAX_FAULTS`] faults.
//!
//! A fault is therefore in a set only for pixels of the student's own image that it accounts for,
//! and the search stops when what is left is noise.

use std::collections::{HashMap, HashSet};

use rayon::prelude::*;

use super::mask::Mask;
use super::*;

/// The largest set grown.
pub const MAX_FAULTS: usize = 6;
/// How many sets are grown at each step, and how many faults each is offered.
const BEAM: usize = 3;
const OFFERED: usize = 3;
/// A fault added to a set must account for this share of the pixels the set left failing…
pub const REAL_SHARE: f64 = 0.1;
/// …and for this share of the picture (about 10 pixels of 100×100), against at most a third as
/// many pixels that the set already drew right and the fault draws wrong.
const FLOOR: f64 = 0.001;
const AGAINST: usize = 3;

/// One image's search: the sets it grows and those it already tried.
struct Search {
    beam: Vec<Scored>,
    tried: HashSet<String>,
}

/// Grows fault sets for every image whose scores hold nothing that passes, and adds the sets
/// kept to its scores. Returns the candidates rendered, for the decision's pictures.
pub(super) fn grow(
    subjects: &[Option<Subject>],
    scores: &mut [Vec<Scored>],
    known: &[&Candidate],
    singles: &[Candidate],
    get: &(dyn Fn(FaultSet) -> Option<Candidate> + Sync),
) -> Vec<Candidate> {
    let mut searches: Vec<Option<Search>> = subjects
        .iter()
        .zip(scores.iter())
        .map(|(subject, scores)| start(subject.as_ref()?, scores))
        .collect();
    let changes = single_changes(&searches, subjects, singles);
    let mut grown: Vec<Candidate> = Vec::new();
    for _ in 1..MAX_FAULTS {
        // What each image offers its beam, from the pictures alone.
        let offers: Vec<Vec<(usize, FaultSet)>> = searches
            .par_iter_mut()
            .zip(subjects.par_iter())
            .map(|(search, subject)| match (search, subject) {
                (Some(search), Some(subject)) => {
                    let changed = &changes[&change_key(subject)];
                    offer(search, subject, known, &grown, singles, changed)
                }
                _ => Vec::new(),
            })
            .collect();
        let mut wanted: Vec<FaultSet> = Vec::new();
        for (_, set) in offers.iter().flatten() {
            if !wanted.contains(set) && !grown.iter().any(|c| c.set == *set) {
                wanted.push(*set);
            }
        }
        if wanted.is_empty() {
            break;
        }
        grown.extend(wanted.into_par_iter().filter_map(get).collect::<Vec<_>>());
        searches
            .par_iter_mut()
            .zip(subjects.par_iter().zip(scores.par_iter_mut()))
            .zip(offers.par_iter())
            .for_each(|((search, (subject, scores)), offers)| {
                if let (Some(state), Some(subject)) = (search.as_mut(), subject)
                    && !step(state, subject, scores, offers, known, &grown)
                {
                    *search = None;
                }
            });
    }
    grown
}

/// The search for one image, or `None` when a single fault or a set of parts not written
/// already passes against its picture (a pair with a mistake in written code that passes is
/// searched on, for parts not written that draw the same).
fn start(subject: &Subject, scores: &[Scored]) -> Option<Search> {
    let rule = &subject.spec.rule;
    let passes = |s: &Scored| s.explains(rule) && s.residual.failing_fraction <= rule.pass_fraction;
    if scores
        .iter()
        .any(|s| passes(s) && (s.set.len() == 1 || s.specific() == 0))
    {
        return None;
    }
    let mut beam: Vec<Scored> = scores
        .iter()
        .filter(|s| s.promising() && !s.speckle && s.set.len() < MAX_FAULTS)
        .copied()
        .collect();
    beam.sort_by(unwritten_first);
    beam.truncate(BEAM);
    (!beam.is_empty()).then(|| Search {
        beam,
        tried: scores.iter().map(|s| s.set.to_string()).collect(),
    })
}

fn picture_of<'a>(
    set: &FaultSet,
    known: &'a [&Candidate],
    grown: &'a [Candidate],
    index: usize,
) -> Option<&'a RgbImage> {
    known
        .iter()
        .copied()
        .chain(grown)
        .find(|c| c.set == *set)
        .map(|c| &*c.pictures[index])
}

/// Which pictures and thresholds the searches compare: the key of [`single_changes`].
fn change_key(subject: &Subject) -> (usize, u64) {
    (subject.picture, subject.spec.rule.threshold.to_bits())
}

/// Where each single fault changes the golden picture (`None` for speckled faults, which are not
/// offered), for every picture and threshold an image still searched compares: made once for
/// all the steps and images of the render.
fn single_changes(
    searches: &[Option<Search>],
    subjects: &[Option<Subject>],
    singles: &[Candidate],
) -> HashMap<(usize, u64), Vec<Option<Mask>>> {
    let mut wanted: Vec<((usize, u64), &RgbImage)> = Vec::new();
    let searched = searches
        .iter()
        .zip(subjects)
        .filter_map(|(search, subject)| search.as_ref().and(subject.as_ref()));
    for subject in searched {
        if !wanted.iter().any(|(key, _)| *key == change_key(subject)) {
            wanted.push((change_key(subject), subject.golden));
        }
    }
    wanted
        .into_par_iter()
        .map(|((picture, threshold), golden)| {
            let masks = singles
                .iter()
                .map(|c| {
                    (!c.set.faults().any(Fault::is_speckle))
                        .then(|| Mask::differing(&c.pictures[picture], golden, f64::from_bits(threshold)))
                })
                .collect();
            ((picture, threshold), masks)
        })
        .collect()
}

/// Each set of the beam with each of the [`OFFERED`] single faults that best cover what it left
/// failing: (the set's place in the beam, the grown set). `changes` holds where each single
/// changes the golden picture.
fn offer(
    search: &mut Search,
    subject: &Subject,
    known: &[&Candidate],
    grown: &[Candidate],
    singles: &[Candidate],
    changes: &[Option<Mask>],
) -> Vec<(usize, FaultSet)> {
    let threshold = subject.spec.rule.threshold;
    let mut offers = Vec::new();
    for (place, base) in search.beam.iter().enumerate() {
        let Some(base_picture) = picture_of(&base.set, known, grown, subject.picture) else {
            continue;
        };
        let failing = Mask::differing(base_picture, &subject.student, threshold);
        let base_changed = Mask::differing(base_picture, subject.golden, threshold);
        let left = failing.count();
        let mut ranked: Vec<(bool, i64, FaultSet)> = singles
            .iter()
            .zip(changes)
            .filter_map(|(c, changed)| {
                let changed = changed.as_ref()?;
                let set = candidates::pair(&base.set, &c.set)?;
                let covered = changed.count_both(&failing);
                // Where the set already changed the golden picture, what the fault would do on
                // top of it cannot be told from the pictures.
                let spoiled = changed.count_outside(&failing, &base_changed);
                let enough = covered as f64 >= REAL_SHARE * left as f64 && covered > spoiled;
                let unwritten = c.set.faults().all(|f| f.unfinished_part().is_some());
                enough.then_some((unwritten, covered as i64 - spoiled as i64, set))
            })
            .collect();
        ranked.sort_by_key(|(unwritten, gain, _)| (std::cmp::Reverse(*unwritten), std::cmp::Reverse(*gain)));
        for unwritten in [true, false] {
            let mut offered = 0;
            for (_, _, set) in ranked.iter().filter(|r| r.0 == unwritten) {
                if offered == OFFERED {
                    break;
                }
                if search.tried.insert(set.to_string()) {
                    offers.push((place, *set));
                    offered += 1;
                }
            }
        }
    }
    offers
}

/// Scores the grown sets, keeps those whose new fault has evidence of its own, and makes the
/// closest kept the next beam. Returns whether the search goes on.
fn step(
    search: &mut Search,
    subject: &Subject,
    scores: &mut Vec<Scored>,
    offers: &[(usize, FaultSet)],
    known: &[&Candidate],
    grown: &[Candidate],
) -> bool {
    let threshold = subject.spec.rule.threshold;
    let mut kept: Vec<Scored> = Vec::new();
    for (place, set) in offers {
        let base = &search.beam[*place];
        let (Some(base_picture), Some(candidate)) = (
            picture_of(&base.set, known, grown, subject.picture),
            grown.iter().find(|c| c.set == *set),
        ) else {
            continue;
        };
        let Some(scored) = subject.score(candidate) else {
            continue;
        };
        let picture = &candidate.pictures[subject.picture];
        let hidden = set.faults().any(|f| {
            picture_of(&set.without(f), known, grown, subject.picture).is_some_and(|without| without == &**picture)
        });
        if !hidden
            && scored.residual.failing_fraction <= base.residual.failing_fraction
            && scored.residual.rmse < base.residual.rmse
            && has_evidence(base_picture, picture, &subject.student, threshold)
        {
            kept.push(scored);
        }
    }
    kept.sort_by(unwritten_first);
    scores.extend(kept.iter().copied());
    let rule = &subject.spec.rule;
    let done = kept.is_empty()
        || kept
            .iter()
            .any(|s| s.specific() == 0 && s.explains(rule) && s.residual.failing_fraction <= rule.pass_fraction);
    kept.truncate(BEAM);
    search.beam = kept;
    !done
}

/// Sets with fewer mistakes in written code first, then the closest: the search follows the
/// story of unfinished work as long as the evidence allows, and the decision still sees every
/// set kept.
fn unwritten_first(a: &Scored, b: &Scored) -> std::cmp::Ordering {
    a.specific()
        .cmp(&b.specific())
        .then(a.key().partial_cmp(&b.key()).unwrap_or(std::cmp::Ordering::Equal))
}

/// Whether the student's image, where `grown` differs from `base`, comes clearly closer to
/// `grown` (by more than the threshold) on a real share of the pixels `base` left failing, and
/// clearly closer to `base` on few.
pub(super) fn has_evidence(base: &RgbImage, grown: &RgbImage, student: &RgbImage, threshold: f64) -> bool {
    let (mut left, mut agrees, mut against) = (0usize, 0usize, 0usize);
    for ((b, g), s) in base.pixels().zip(grown.pixels()).zip(student.pixels()) {
        left += usize::from(!close(b, s, threshold));
        if close(b, g, threshold) {
            continue;
        }
        let (to_base, to_grown) = (distance(b, s), distance(g, s));
        if to_grown + threshold < to_base {
            agrees += 1;
        } else if to_base + threshold < to_grown {
            against += 1;
        }
    }
    let pixels = (base.width() as usize * base.height() as usize).max(1);
    agrees as f64 >= REAL_SHARE * left as f64 && agrees as f64 >= FLOOR * pixels as f64 && against * AGAINST <= agrees
}

/// The largest channel difference, in codes.
fn distance(a: &crate::rgb_image::Rgb, b: &crate::rgb_image::Rgb) -> f64 {
    a.0.iter()
        .zip(b.0)
        .map(|(x, y)| f64::from(x.abs_diff(y)))
        .fold(0.0, f64::max)
}

fn close(a: &crate::rgb_image::Rgb, b: &crate::rgb_image::Rgb, threshold: f64) -> bool {
    a.0.iter().zip(b.0).all(|(x, y)| f64::from(x.abs_diff(y)) <= threshold)
}
