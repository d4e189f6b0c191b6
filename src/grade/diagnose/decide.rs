//! The decision for one image (the module documentation's rule) and the pictures that show it.

use super::*;

/// The decision for one image (the module documentation's rule), with its pictures written.
#[allow(clippy::too_many_arguments)]
pub(super) fn decide(
    subject: &Subject,
    scores: &[Scored],
    store: &pictures::FaultPictures,
    expanded: &[&Candidate],
    singles: &[Candidate],
    out: &Path,
    student_dir: &str,
    written: &Mutex<HashSet<PathBuf>>,
) -> Diagnosis {
    let rule = &subject.spec.rule;
    let mut explaining: Vec<&Scored> = scores.iter().filter(|s| s.explains(rule)).collect();
    explaining.sort_by(|a, b| a.key().partial_cmp(&b.key()).unwrap_or(std::cmp::Ordering::Equal));
    // Parsimony: the closest single fault, unless a pair is far closer.
    let best_single = explaining.iter().find(|s| s.set.len() == 1).copied();
    let best_pair = explaining.iter().find(|s| s.set.len() > 1).copied();
    let mut order: Vec<&Scored> = match (best_single, best_pair) {
        (Some(single), Some(pair)) if pair.left() * FAILING_REDUCTION < single.left() => {
            vec![pair, single]
        }
        (Some(single), _) => vec![single],
        (None, Some(pair)) => vec![pair],
        (None, None) => Vec::new(),
    };
    let rest: Vec<&Scored> = explaining
        .iter()
        .filter(|s| !order.iter().any(|o| o.set == s.set))
        .take(3)
        .copied()
        .collect();
    order.extend(rest);
    let picture_of = |set: &FaultSet| -> Option<RgbImage> {
        let index = subject.picture;
        if let Some(candidate) = singles.iter().chain(expanded.iter().copied()).find(|c| c.set == *set) {
            return Some(candidate.pictures[index].clone());
        }
        if let Some(known) = store.get_if_known(set) {
            return Some(known[index].clone());
        }
        // A fitted gamma: quantised from the golden film.
        let picture = store.pictures()[index];
        (set.render_part().is_empty()).then(|| picture_with_faults(store.golden_film(), picture, store.tonemap(), set))
    };
    let tolerance = Tolerance {
        pixel: rule.threshold,
        fail_fraction: rule.pass_fraction,
        rmse: f64::INFINITY,
        max: None,
    };
    let file = &subject.spec.file;
    let student = Image::from_rgb8(subject.student.clone(), file.clone());
    let write = |set: &FaultSet, mistake: &RgbImage, expected: &Image| {
        write_pictures(set, mistake, expected, &student, subject, out, student_dir, written)
    };
    for scored in order {
        let Some(mistake) = picture_of(&scored.set) else {
            continue;
        };
        let expected = Image::from_rgb8(mistake.clone(), scored.set.to_string());
        let Some(metrics) = compare(&expected, &student, &tolerance).metrics else {
            continue;
        };
        // Within the partial limits, FLIP included; speckles are judged by their blocks.
        if !scored.speckle && judge(rule, &metrics).0 == Outcome::Fail {
            continue;
        }
        let passes = if scored.speckle {
            scored.residual.failing_fraction <= rule.pass_fraction
        } else {
            judge(rule, &metrics).0 == Outcome::Pass
        };
        let alternatives: Vec<String> = explaining
            .iter()
            .filter(|s| s.set.id() != scored.set.id() && s.set.len() <= scored.set.len())
            .filter(|s| {
                s.residual.failing_fraction
                    <= (2.0 * scored.residual.failing_fraction).max(scored.residual.failing_fraction + 0.001)
                    && s.residual.rmse <= 1.5 * scored.residual.rmse + 0.5
            })
            .map(|s| s.set.id())
            .fold(Vec::new(), |mut ids, id| {
                if !ids.contains(&id) {
                    ids.push(id);
                }
                ids
            });
        let (mistake_image, residual_image) = write(&scored.set, &mistake, &expected);
        return Diagnosis {
            id: scored.set.id(),
            faults: Some(scored.set.to_string()),
            explanation: scored.set.explain(),
            hints: scored.set.faults().map(|f| f.hint().to_owned()).collect(),
            confidence: if passes && alternatives.is_empty() {
                Confidence::High
            } else {
                Confidence::Medium
            },
            explained: scored.share_explained(),
            golden: scored.golden,
            residual: Some(scored.residual),
            residual_metrics: Some(metrics),
            compared_by: compared_by(scored, subject.block),
            alternatives,
            closest: None,
            mistake_image,
            residual_image,
            credit: None,
            ties: explaining
                .iter()
                .filter(|s| s.set.id() != scored.set.id() && s.set.len() == scored.set.len())
                .filter(|s| s.residual == scored.residual && s.golden == scored.golden)
                .map(|s| s.set)
                .collect(),
        };
    }
    // Unexplained: name the closest mistake, if any came closer than the golden picture.
    let closest = scores.iter().filter(|s| s.share_explained() > 0.0).max_by(|a, b| {
        a.share_explained()
            .partial_cmp(&b.share_explained())
            .unwrap_or(std::cmp::Ordering::Equal)
    });
    let (mut mistake_image, mut residual_image) = (None, None);
    if let Some(closest) = closest
        && let Some(mistake) = picture_of(&closest.set)
    {
        let expected = Image::from_rgb8(mistake.clone(), closest.set.to_string());
        (mistake_image, residual_image) = write(&closest.set, &mistake, &expected);
    }
    Diagnosis {
        id: UNEXPLAINED.to_owned(),
        faults: None,
        explanation: "no mistake of the catalogue, alone or with another, explains this image".to_owned(),
        hints: Vec::new(),
        confidence: Confidence::None,
        explained: 0.0,
        golden: subject.by_pixel,
        residual: None,
        residual_metrics: None,
        compared_by: "pixels".to_owned(),
        alternatives: Vec::new(),
        closest: closest.map(|c| Closest {
            id: c.set.id(),
            faults: c.set.to_string(),
            explained: c.share_explained(),
        }),
        mistake_image,
        residual_image,
        credit: None,
        ties: Vec::new(),
    }
}

fn compared_by(scored: &Scored, block: u32) -> String {
    if scored.speckle {
        format!("blocks of {block}×{block} pixels")
    } else {
        "pixels".to_owned()
    }
}

/// The mistake's picture (`mistakes/SET/FILE`, once per run) and the student's difference from
/// it (`students/NAME/STEM.mistake.png`), relative to the report directory. Pictures that cannot
/// be written are left out of the report rather than failing it.
#[allow(clippy::too_many_arguments)]
fn write_pictures(
    set: &FaultSet,
    mistake: &RgbImage,
    expected: &Image,
    student: &Image,
    subject: &Subject,
    out: &Path,
    student_dir: &str,
    written: &Mutex<HashSet<PathBuf>>,
) -> (Option<String>, Option<String>) {
    let file = &subject.spec.file;
    let mistake_path = format!("{MISTAKES_DIR}/{set}/{file}");
    let absolute = out.join(&mistake_path);
    let first = written
        .lock()
        .unwrap_or_else(|p| p.into_inner())
        .insert(absolute.clone());
    let mistake_ok = !first || encode_png(mistake).is_ok_and(|bytes| replace_file(&absolute, &bytes).is_ok());
    let stem = file.strip_suffix(".png").unwrap_or(file);
    let residual_path = format!("{student_dir}/{stem}.mistake.png");
    let residual_ok = diff_heatmap(expected, student, subject.spec.rule.threshold).is_some_and(|heatmap| {
        encode_png(&heatmap).is_ok_and(|bytes| replace_file(&out.join(&residual_path), &bytes).is_ok())
    });
    (mistake_ok.then_some(mistake_path), residual_ok.then_some(residual_path))
}
