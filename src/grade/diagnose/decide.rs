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
    // The closest first; of sets that draw this picture equally well, the one with fewer
    // mistakes in written code (a part not written is the likelier story, and no accusation).
    explaining.sort_by(|a, b| {
        a.key()
            .partial_cmp(&b.key())
            .unwrap_or(std::cmp::Ordering::Equal)
            .then(a.specific().cmp(&b.specific()))
    });
    // Parsimony: the closest set of the fewest faults, unless a larger set is far closer.
    let mut sizes: Vec<usize> = explaining.iter().map(|s| s.set.len()).collect();
    sizes.sort_unstable();
    sizes.dedup();
    let mut order: Vec<&Scored> = Vec::new();
    for size in sizes {
        let Some(best) = explaining.iter().find(|s| s.set.len() == size).copied() else {
            continue;
        };
        if order
            .first()
            .is_none_or(|chosen| best.left() * FAILING_REDUCTION < chosen.left())
        {
            order.insert(0, best);
        }
    }
    let rest: Vec<&Scored> = explaining
        .iter()
        .filter(|s| !order.iter().any(|o| o.set == s.set))
        .take(3)
        .copied()
        .collect();
    order.extend(rest);
    let order = without_accusations(order, scores, rule);
    let picture_of = |set: &FaultSet| -> Option<Arc<RgbImage>> {
        let index = subject.picture;
        if let Some(candidate) = singles.iter().chain(expanded.iter().copied()).find(|c| c.set == *set) {
            return Some(candidate.pictures[index].clone());
        }
        if let Some(known) = store.get_if_known(set) {
            return Some(known[index].clone());
        }
        // A fitted gamma: quantised from the golden film.
        let picture = store.pictures()[index];
        (set.render_part().is_empty())
            .then(|| Arc::new(picture_with_faults(store.golden_film(), picture, store.tonemap(), set)))
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
        let expected = Image::from_rgb8(RgbImage::clone(&mistake), scored.set.to_string());
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
            .filter(|s| as_close(s, scored))
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
            compared_by: compared_by(scored, subject.block, signature::reach(subject.golden)),
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
        let expected = Image::from_rgb8(RgbImage::clone(&mistake), closest.set.to_string());
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

/// Never an accusation that "a part is not there" explains as well: each set that names a
/// mistake in written code is replaced by a set of missing parts that draws the picture about as
/// well and explains it; where such a set is about as close but does not explain the image, the
/// evidence cannot tell a mistake from unfinished work, and nothing from there on is named.
fn without_accusations<'a>(order: Vec<&'a Scored>, scores: &'a [Scored], rule: &Rule) -> Vec<&'a Scored> {
    let mut kept: Vec<&Scored> = Vec::new();
    for scored in order {
        let chosen = match as_good_missing(scored, scores) {
            None => scored,
            Some(missing) if missing.explains(rule) => missing,
            Some(_) => break,
        };
        if !kept.iter().any(|k| k.set == chosen.set) {
            kept.push(chosen);
        }
    }
    kept
}

/// The closest set of missing parts only that comes about as close as `scored` (the measure
/// [`decide`]'s alternatives use), when `scored` names a mistake in written code.
fn as_good_missing<'a>(scored: &Scored, scores: &'a [Scored]) -> Option<&'a Scored> {
    if scored.specific() == 0 {
        return None;
    }
    scores
        .iter()
        .filter(|m| m.specific() == 0 && m.speckle == scored.speckle)
        .filter(|m| as_close(m, scored))
        .min_by(|a, b| a.key().partial_cmp(&b.key()).unwrap_or(std::cmp::Ordering::Equal))
}

/// Whether `other` explains the image about as well as `scored`: at most twice its failing
/// pixels (or a tenth of a percent more) and half again its RMSE.
fn as_close(other: &Scored, scored: &Scored) -> bool {
    other.residual.failing_fraction
        <= (2.0 * scored.residual.failing_fraction).max(scored.residual.failing_fraction + 0.001)
        && other.residual.rmse <= 1.5 * scored.residual.rmse + 0.5
}

fn compared_by(scored: &Scored, block: u32, reach: u32) -> String {
    if scored.set == FaultSet::single(Fault::ShadowAcne) {
        format!("the acne's signature: scattered speckles within {reach} pixels of the mistake's")
    } else if scored.speckle {
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
