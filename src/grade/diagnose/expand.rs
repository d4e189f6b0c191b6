//! What is tried when no single fault explains an image: the background fitted to the
//! student's misses, the rest of each promising family, a gamma fitted by golden-section
//! search, and pairs of faults that each explained part of it.

use super::*;

/// What to render next for an image no single fault explains cleanly: the other members of the
/// promising families, and pairs: each of the closest promising faults with the faults that
/// change most of the pixels it leaves failing.
/// `cubemap-ignored` with the flat colour the student's picture shows where the golden rays
/// miss, when it shows one there (the course's scenes give a colour beside the cube map, which
/// the import drops): the median of those pixels, if most of them are within the rubric's
/// threshold of it.
pub(super) fn fit_background(subject: &Subject, misses: &[bool], singles: &[Candidate]) -> Option<FaultSet> {
    let tried = singles.iter().any(|c| c.set.contains(Fault::CubemapIgnored));
    if !tried || subject.golden.as_raw().len() != misses.len() * 3 {
        return None;
    }
    let seen: Vec<[u8; 3]> = subject
        .student
        .pixels()
        .zip(misses)
        .filter(|(_, miss)| **miss)
        .map(|(p, _)| p.0)
        .collect();
    if seen.len() * 100 < misses.len() {
        return None;
    }
    let median = [0, 1, 2].map(|c| {
        let mut values: Vec<u8> = seen.iter().map(|p| p[c]).collect();
        values.sort_unstable();
        values[values.len() / 2]
    });
    let threshold = subject.spec.rule.threshold;
    let close = seen
        .iter()
        .filter(|p| p.iter().zip(median).all(|(v, m)| f64::from(v.abs_diff(m)) <= threshold))
        .count();
    (close * 5 >= seen.len() * 4 && median != [0; 3])
        .then(|| FaultSet::NONE.with(crate::fault::Parameter::Background(median)))
}

pub(super) fn expansions(
    case: &crate::case::Case,
    subject: &Subject,
    scores: &[Scored],
    singles: &[Candidate],
) -> Vec<FaultSet> {
    let rule = &subject.spec.rule;
    let mut promising: Vec<&Scored> = scores.iter().filter(|s| s.promising()).collect();
    promising.sort_by(|a, b| a.left().partial_cmp(&b.left()).unwrap_or(std::cmp::Ordering::Equal));
    let mut wanted = Vec::new();
    for scored in &promising {
        for fault in scored
            .set
            .faults()
            .filter(|f| f.is_family() && *f != Fault::GammaApplied)
        {
            wanted.extend(candidates::members(case, fault));
        }
    }
    let passes = |s: &Scored| s.explains(rule) && s.residual.failing_fraction <= rule.pass_fraction;
    if scores.iter().any(|s| s.set.len() == 1 && passes(s)) {
        return wanted;
    }
    let picture = |set: &FaultSet| {
        singles
            .iter()
            .find(|c| c.set == *set)
            .map(|c| &c.pictures[subject.picture])
    };
    let threshold = rule.threshold;
    for a in promising.iter().take(PAIRED) {
        let Some(a_picture) = picture(&a.set) else { continue };
        // Each partner B predicted without a render: A's picture plus what B changes in the
        // golden one (flipped to A's orientation, or A flipped when B is a flip). Additive
        // changes (a light, a shadow, a highlight) compose exactly, the others roughly; the
        // prediction only chooses which pairs to render.
        let mut partners: Vec<(f64, FaultSet)> = singles
            .iter()
            .filter(|b| b.set != a.set && *b.pictures[subject.picture] != *subject.golden)
            .filter_map(|b| {
                let set = candidates::pair(&a.set, &b.set)?;
                let predicted = predict(a_picture, &a.set, &b.pictures[subject.picture], &b.set, subject.golden);
                let r = residual::residual(&predicted, &subject.student, threshold);
                (r.rmse <= a.residual.rmse * PARTNER_GAIN && r.failing_fraction <= a.residual.failing_fraction)
                    .then_some((r.rmse, set))
            })
            .collect();
        partners.sort_by(|x, y| x.0.partial_cmp(&y.0).unwrap_or(std::cmp::Ordering::Equal));
        wanted.extend(partners.into_iter().take(PARTNERS).map(|(_, set)| set));
    }
    wanted
}

/// The picture of A and B together, predicted from their pictures alone (see [`expansions`]).
pub(super) fn predict(a: &RgbImage, a_set: &FaultSet, b: &RgbImage, b_set: &FaultSet, golden: &RgbImage) -> RgbImage {
    use crate::fault::Mapping;
    let flip = |image: &RgbImage, mapping: Option<Mapping>| match mapping {
        Some(Mapping::UpsideDown) => image.flipped_vertically(),
        Some(Mapping::Mirrored) => image.flipped_horizontally(),
        _ => image.clone(),
    };
    let b_flip = b_set.mapping().filter(|m| *m != Mapping::Centres);
    if b_flip.is_some() {
        return flip(a, b_flip);
    }
    let a_flip = a_set.mapping().filter(|m| *m != Mapping::Centres);
    let (b, golden) = (flip(b, a_flip), flip(golden, a_flip));
    let mut out = a.clone();
    for ((o, b), g) in out.pixels_mut().zip(b.pixels()).zip(golden.pixels()) {
        for c in 0..3 {
            o.0[c] = (i32::from(o.0[c]) + i32::from(b.0[c]) - i32::from(g.0[c])).clamp(0, 255) as u8;
        }
    }
    out
}

/// `gamma-applied` with the γ that fits the image best (golden-section search on the RMSE),
/// when a gamma member looked promising; quantised from the golden film, so nothing renders.
pub(super) fn fit_gamma(subject: &Subject, store: &pictures::FaultPictures, scores: &[Scored]) -> Option<Scored> {
    let promising = scores
        .iter()
        .any(|s| s.set.contains(Fault::GammaApplied) && s.set.len() == 1 && s.promising());
    if !promising || store.pictures()[subject.picture] != Picture::Color {
        return None;
    }
    let picture = |gamma: f64| {
        let set = FaultSet::NONE.with(Parameter::Gamma(Gamma::Power(gamma)));
        (
            set,
            picture_with_faults(store.golden_film(), Picture::Color, store.tonemap(), &set),
        )
    };
    let cost = |gamma: f64| {
        let (set, image) = picture(gamma);
        subject.score_picture(set, &image).residual.rmse
    };
    let (mut lo, mut hi) = (1.0f64, 3.4f64);
    let ratio = (5f64.sqrt() - 1.0) / 2.0;
    let (mut a, mut b) = (hi - ratio * (hi - lo), lo + ratio * (hi - lo));
    let (mut fa, mut fb) = (cost(a), cost(b));
    for _ in 0..16 {
        if fa <= fb {
            hi = b;
            (b, fb) = (a, fa);
            a = hi - ratio * (hi - lo);
            fa = cost(a);
        } else {
            lo = a;
            (a, fa) = (b, fb);
            b = lo + ratio * (hi - lo);
            fb = cost(b);
        }
    }
    let gamma = ((lo + hi) / 2.0 * 100.0).round() / 100.0;
    let (set, image) = picture(gamma);
    Some(subject.score_picture(set, &image))
}
