//! Unfinished work told from the other end: every part not written at once, then each part
//! taken back that the student's image gives no evidence of.
//!
//! The beam search ([`super::grow`]) adds one fault at a time, and keeps a fault only if it
//! brings the picture closer on its own. Some parts not written show only together: where a
//! program draws neither the floor plane nor the misses of the depth image right, a missing
//! plane alone makes the floor a miss (black, further from the student's white than the golden
//! grey), and white misses alone change nothing while the floor covers the view; together they
//! are the student's white. So for an image nothing above passes, the set of every part not
//! written that the scene can show is drawn; if it explains the image, each part in turn
//! (catalogue order) is taken out when the set without it draws the student's image as well
//! (no evidence of the part, [`super::grow::has_evidence`]), one at a time so that two parts
//! that hide each other (a mesh under a transform) are not both taken out; the set with the
//! other of the two is scored as well, as a tie. What is left is scored with the other sets,
//! for the decision. The sets are shared by every image of the
//! render, so a class with many unfinished programs renders each once.

use rayon::prelude::*;

use super::grow::has_evidence;
use super::*;

/// Adds, for every image with nothing passing that the set of all parts not written explains,
/// the smallest set of them with evidence of each part. Returns the candidates rendered.
pub(super) fn shrink(
    subjects: &[Option<Subject>],
    scores: &mut [Vec<Scored>],
    singles: &[Candidate],
    get: &(dyn Fn(FaultSet) -> Option<Candidate> + Sync),
) -> Vec<Candidate> {
    let mut parts: Vec<Fault> = singles
        .iter()
        .filter(|c| c.set.len() == 1)
        .flat_map(|c| c.set.faults())
        .filter(|f| f.unfinished_part().is_some())
        .collect();
    parts.sort_by_key(|f| f.bit());
    parts.dedup();
    let open: Vec<(usize, &Subject)> = subjects
        .iter()
        .enumerate()
        .filter_map(|(i, subject)| Some((i, subject.as_ref()?)))
        .filter(|(i, subject)| !scores[*i].iter().any(|s| passes(s, &subject.spec.rule)))
        .collect();
    if parts.len() < 2 || open.is_empty() {
        return Vec::new();
    }
    let everything = parts.iter().fold(FaultSet::NONE, |set, part| set.and(*part));
    let Some(all) = get(everything) else {
        return Vec::new();
    };
    // Each image the whole set explains, with the set it is down to and the parts taken out that
    // changed nothing in its picture.
    let mut current: Vec<(usize, &Subject, FaultSet, Vec<Fault>)> = open
        .into_iter()
        .filter(|(_, subject)| subject.score(&all).is_some_and(|s| s.explains(&subject.spec.rule)))
        .map(|(i, subject)| (i, subject, everything, Vec::new()))
        .collect();
    let mut rendered = vec![all];
    for part in parts {
        let mut wanted: Vec<FaultSet> = Vec::new();
        for (_, _, set, _) in &current {
            let without = set.without(part);
            if set.contains(part) && set.len() > 1 && !wanted.contains(&without) && find(&rendered, &without).is_none()
            {
                wanted.push(without);
            }
        }
        rendered.extend(wanted.into_par_iter().filter_map(get).collect::<Vec<_>>());
        for (_, subject, set, hidden) in &mut current {
            if !set.contains(part) || set.len() == 1 {
                continue;
            }
            let without = set.without(part);
            let (Some(with_part), Some(without_part)) = (find(&rendered, set), find(&rendered, &without)) else {
                continue;
            };
            let (with_part, without_part) = (
                &with_part.pictures[subject.picture],
                &without_part.pictures[subject.picture],
            );
            if without_part == with_part {
                hidden.push(part);
            }
            if !has_evidence(without_part, with_part, &subject.student, subject.spec.rule.threshold) {
                *set = without;
            }
        }
    }
    // A part taken out because another hid it (a mesh under a transform) could as well have
    // stayed in the place of a part that alone draws the same picture: those sets are scored too,
    // so that the decision sees the tie (and the student's other images can settle it).
    let alone = |fault: Fault, picture: usize| {
        singles
            .iter()
            .find(|c| c.set == FaultSet::single(fault))
            .map(|c| &c.pictures[picture])
    };
    let swapped = |set: &FaultSet, hidden: &[Fault], picture: usize| -> Vec<FaultSet> {
        let mut sets = Vec::new();
        for kept in set.faults() {
            for &part in hidden {
                let other = set.without(kept).and(part);
                let alike = alone(kept, picture).is_some_and(|p| alone(part, picture) == Some(p));
                if alike && other != *set && !sets.contains(&other) {
                    sets.push(other);
                }
            }
        }
        sets
    };
    let mut wanted: Vec<FaultSet> = Vec::new();
    for (_, subject, set, hidden) in &current {
        for other in swapped(set, hidden, subject.picture) {
            if !wanted.contains(&other) && find(&rendered, &other).is_none() {
                wanted.push(other);
            }
        }
    }
    rendered.extend(wanted.into_par_iter().filter_map(get).collect::<Vec<_>>());
    for (i, subject, set, hidden) in current {
        let Some(shrunk) = find(&rendered, &set) else {
            continue;
        };
        let picture = &shrunk.pictures[subject.picture];
        let ties = swapped(&set, &hidden, subject.picture)
            .into_iter()
            .filter_map(|other| find(&rendered, &other))
            .filter(|c| c.pictures[subject.picture] == *picture);
        for candidate in std::iter::once(shrunk).chain(ties) {
            if let Some(scored) = subject.score(candidate).filter(|s| s.explains(&subject.spec.rule))
                && !scores[i].iter().any(|s| s.set == candidate.set)
            {
                scores[i].push(scored);
            }
        }
    }
    rendered
}

fn passes(scored: &Scored, rule: &Rule) -> bool {
    scored.explains(rule) && scored.residual.failing_fraction <= rule.pass_fraction
}

fn find<'a>(rendered: &'a [Candidate], set: &FaultSet) -> Option<&'a Candidate> {
    rendered.iter().find(|c| c.set == *set)
}
