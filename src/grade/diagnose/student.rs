//! Decisions that look at a student's images together: choosing among equally good
//! explanations the one the student's other images share, and the rubric's credit per mistake.

use super::*;

/// The rubric's credit for diagnosed mistakes (`[mistake."ID"] credit`): an image whose diagnosis
/// names only credited mistakes gets at least the product of their credits times its points.
/// Without credits nothing changes.
pub(in crate::grade) fn apply_credit(rubric: &Rubric, students: &mut [StudentResult]) {
    if rubric.mistake_credit.is_empty() {
        return;
    }
    let credit_of = |id: &str| {
        rubric
            .mistake_credit
            .iter()
            .find(|(f, _)| f.name() == id)
            .map(|(_, c)| *c)
    };
    for student in students.iter_mut() {
        for image in &mut student.images {
            let Some(diagnosis) = &mut image.diagnosis else {
                continue;
            };
            if diagnosis.id == UNEXPLAINED {
                continue;
            }
            let credits: Option<Vec<f64>> = diagnosis.id.split('+').map(credit_of).collect();
            let Some(credit) = credits.map(|c| c.iter().product::<f64>()) else {
                continue;
            };
            let points = image.max_points * credit;
            if points > image.points {
                image.points = points;
                diagnosis.credit = Some(credit);
                image.explanation.push_str(&format!(
                    "; the rubric grants {} of the points for the diagnosed mistake {}",
                    super::super::judge::percent(credit),
                    diagnosis.id
                ));
            }
        }
        student.recount();
    }
}

/// Where mistakes tie on an image (they draw the same picture there), the one the student's other
/// images are diagnosed with, unambiguously, is named: a depth image that an inverted depth and a
/// missing object both turn black is blamed on the inverted depth of a student whose other depth
/// images are inverted.
pub(in crate::grade) fn prefer_consistent(students: &mut [StudentResult]) {
    for student in students.iter_mut() {
        let clear: Vec<String> = student
            .images
            .iter()
            .filter_map(|i| i.diagnosis.as_ref())
            .filter(|d| d.ties.is_empty() && d.id != UNEXPLAINED)
            .flat_map(|d| d.id.split('+').map(str::to_owned).collect::<Vec<_>>())
            .collect();
        let made = |set: &FaultSet| set.faults().all(|f| clear.iter().any(|id| id == f.name()));
        // Never from a part not written to a mistake in written code that draws the same.
        let specific = |set: &FaultSet| set.faults().filter(|f| f.unfinished_part().is_none()).count();
        for image in &mut student.images {
            let Some(diagnosis) = &mut image.diagnosis else {
                continue;
            };
            let current = diagnosis.id.parse::<FaultSet>().ok();
            if current.as_ref().is_some_and(made) {
                continue;
            }
            let most = current.as_ref().map_or(usize::MAX, specific);
            let Some(better) = diagnosis.ties.iter().find(|t| made(t) && specific(t) <= most).copied() else {
                continue;
            };
            let previous = std::mem::replace(&mut diagnosis.id, better.id());
            diagnosis.alternatives.retain(|a| *a != diagnosis.id);
            diagnosis.alternatives.insert(0, previous);
            diagnosis.faults = Some(better.to_string());
            diagnosis.explanation = better.explain();
            diagnosis.hints = better.faults().map(|f| f.hint().to_owned()).collect();
        }
    }
}

/// How many distinct unwritten parts make a student's work "unfinished" (one finding) rather
/// than a mistake or two, each named on its own.
pub const UNFINISHED_PARTS: usize = 2;

/// Gathers a student's "not implemented" diagnoses into one [`Unfinished`] finding when they
/// name at least [`UNFINISHED_PARTS`] parts: a student who never wrote planes, triangles and
/// transforms is told so in one line, with the images each part explains.
pub(in crate::grade) fn gather_unfinished(students: &mut [StudentResult]) {
    for student in students.iter_mut() {
        student.unfinished = unfinished_of(student);
    }
}

fn unfinished_of(student: &StudentResult) -> Option<Unfinished> {
    let mut parts: Vec<(Fault, Vec<String>)> = Vec::new();
    for image in &student.images {
        let Some(diagnosis) = &image.diagnosis else { continue };
        let Ok(set) = diagnosis.id.parse::<FaultSet>() else {
            continue;
        };
        for fault in set.faults().filter(|f| f.unfinished_part().is_some()) {
            match parts.iter_mut().find(|(known, _)| *known == fault) {
                Some((_, images)) => images.push(image.file.clone()),
                None => parts.push((fault, vec![image.file.clone()])),
            }
        }
    }
    if parts.len() < UNFINISHED_PARTS {
        return None;
    }
    parts.sort_by_key(|(fault, _)| *fault as u32);
    let names: Vec<&str> = parts.iter().filter_map(|(f, _)| f.unfinished_part()).collect();
    Some(Unfinished {
        summary: format!("unfinished: {} are not implemented", listed(&names)),
        parts: parts
            .into_iter()
            .map(|(fault, images)| UnfinishedPart {
                id: fault.name().to_owned(),
                part: fault.unfinished_part().unwrap_or_default().to_owned(),
                images,
            })
            .collect(),
    })
}

/// `a`, `a and b`, `a, b and c`.
fn listed(names: &[&str]) -> String {
    match names {
        [] => String::new(),
        [one] => (*one).to_owned(),
        [rest @ .., last] => format!("{} and {last}", rest.join(", ")),
    }
}
