//! A rubric rule applied to a comparison's measurements: the outcome, and the sentence a student
//! reads about it, with the short forms of fractions and points the report and the feedback
//! share.

use super::outcome::Outcome;
use super::rubric::Rule;
use crate::compare::Metrics;

/// The rule applied to a comparison's measurements, with the sentence a student reads: what was
/// measured, the limits of the grade it got, and the limit it broke when it lost points.
pub fn judge(rule: &Rule, metrics: &Metrics) -> (Outcome, String) {
    let within = |fraction: f64, flip: Option<f64>| {
        metrics.failing_fraction <= fraction && flip.is_none_or(|limit| metrics.flip <= limit)
    };
    let measured = format!(
        "{} of pixels differ by more than {} codes{}{}",
        percent(metrics.failing_fraction),
        rule.threshold,
        if rule.statistical {
            " plus the golden's sampling noise"
        } else {
            ""
        },
        rule.pass_flip
            .map_or(String::new(), |_| format!(", FLIP mean {:.4}", metrics.flip)),
    );
    let limits = |fraction: f64, flip: Option<f64>| {
        let flip = flip.map_or(String::new(), |limit| format!(" and FLIP ≤ {limit}"));
        format!("≤ {}{flip}", percent(fraction))
    };
    let pass = limits(rule.pass_fraction, rule.pass_flip);
    let partial = limits(rule.partial_fraction, rule.partial_flip);
    if within(rule.pass_fraction, rule.pass_flip) {
        (Outcome::Pass, format!("{measured}: within the pass limits ({pass})"))
    } else if within(rule.partial_fraction, rule.partial_flip) {
        let credit = rule.partial_credit * 100.0;
        (
            Outcome::Partial,
            format!(
                "{measured}: over the pass limits ({pass}), within the partial limits ({partial}): {credit}% of the points"
            ),
        )
    } else {
        (
            Outcome::Fail,
            format!("{measured}: over the partial limits ({partial})"),
        )
    }
}

/// A fraction as a short percentage: "0.5%", "12.34%", "0%", "<0.01%" (so that a handful of
/// pixels never reads as none).
pub fn percent(fraction: f64) -> String {
    if fraction > 0.0 && fraction < 0.0001 {
        return "<0.01%".to_owned();
    }
    let text = format!("{:.2}", fraction * 100.0);
    let text = text.trim_end_matches('0').trim_end_matches('.');
    format!("{text}%")
}

/// Points as a person writes them: `2`, `0.5`, `1.33`.
pub fn format_points(points: f64) -> String {
    let text = format!("{points:.2}");
    text.trim_end_matches('0').trim_end_matches('.').to_owned()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::compare::Encoding;

    const RULE: Rule = Rule {
        threshold: 8.0,
        pass_fraction: 0.01,
        partial_fraction: 0.05,
        pass_flip: Some(0.1),
        partial_flip: Some(0.2),
        partial_credit: 0.5,
        statistical: false,
    };

    fn measured(failing_fraction: f64, flip: f64) -> Metrics {
        Metrics {
            encoding: Encoding::Code8,
            pixels: 10_000,
            pixel_threshold: 8.0,
            failing_pixels: (failing_fraction * 10_000.0) as usize,
            failing_fraction,
            mae: 0.0,
            rmse: 0.0,
            psnr: f64::INFINITY,
            flip,
            worst: None,
            channels: Vec::new(),
            non_finite: None,
        }
    }

    fn verdict(rule: &Rule, fraction: f64, flip: f64) -> Outcome {
        judge(rule, &measured(fraction, flip)).0
    }

    #[test]
    fn limits_are_inclusive_and_both_must_hold() {
        assert_eq!(verdict(&RULE, 0.01, 0.1), Outcome::Pass);
        assert_eq!(verdict(&RULE, 0.0101, 0.0), Outcome::Partial);
        assert_eq!(
            verdict(&RULE, 0.0, 0.11),
            Outcome::Partial,
            "FLIP alone can cost the pass"
        );
        assert_eq!(verdict(&RULE, 0.05, 0.2), Outcome::Partial);
        assert_eq!(verdict(&RULE, 0.051, 0.0), Outcome::Fail);
        assert_eq!(verdict(&RULE, 0.0, 0.21), Outcome::Fail);
    }

    #[test]
    fn without_flip_limits_flip_is_not_judged_or_quoted() {
        let rule = Rule {
            pass_flip: None,
            partial_flip: None,
            ..RULE
        };
        let (outcome, explanation) = judge(&rule, &measured(0.0, 0.9));
        assert_eq!(outcome, Outcome::Pass);
        assert!(!explanation.contains("FLIP"), "{explanation}");
    }

    #[test]
    fn explanations_name_the_limit_that_decided() {
        let (_, partial) = judge(&RULE, &measured(0.02, 0.0));
        assert!(
            partial.starts_with("2% of pixels differ by more than 8 codes"),
            "{partial}"
        );
        assert!(
            partial.contains("over the pass limits (≤ 1% and FLIP ≤ 0.1)") && partial.contains("50% of the points"),
            "{partial}"
        );
        let (_, fail) = judge(&RULE, &measured(0.5, 0.0));
        assert!(fail.contains("over the partial limits (≤ 5% and FLIP ≤ 0.2)"), "{fail}");
    }

    #[test]
    fn percentages_are_short_and_never_round_to_nothing() {
        assert_eq!(percent(0.0), "0%");
        assert_eq!(percent(0.0144), "1.44%");
        assert_eq!(percent(0.5), "50%");
        assert_eq!(percent(1.0 / 640_000.0), "<0.01%");
    }
}
