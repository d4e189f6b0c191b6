//! Reading the measurements: which settings are worth using at all (the Pareto front), and which
//! is the cheapest that is good enough.

/// Errors closer than this (relative) are the same error. Settings that render the same picture
/// in other ways (f32 and f64, or one bounce past where nothing changes) differ in the last
/// digits of their error, and a slower setting should not reach the front by rounding.
pub const SAME_ERROR: f64 = 1e-3;

/// For each `(cost, error)` point, whether it is on the Pareto front: no other point is at most
/// as costly and at most as wrong while strictly better in one of the two (errors within
/// [`SAME_ERROR`] of each other counting as equal). Every setting off the front has another that
/// is faster without being worse, or better without being slower, so it is never the right
/// choice. Equal points are all on the front (none beats the other). NaN never dominates and is
/// never on the front.
pub fn pareto_front(points: &[(f64, f64)]) -> Vec<bool> {
    let dominates = |(ca, ea): (f64, f64), (cb, eb): (f64, f64)| {
        ca <= cb && ea <= eb * (1.0 + SAME_ERROR) && (ca < cb || ea < eb * (1.0 - SAME_ERROR))
    };
    points
        .iter()
        .map(|&p| !p.0.is_nan() && !p.1.is_nan() && !points.iter().any(|&q| dominates(q, p)))
        .collect()
}

/// The index of the least costly point whose value is at most `limit` (the first one on a tie, so
/// the answer is stable), or `None` when no point reaches it. Points are `(cost, value)`.
pub fn cheapest_within(points: &[(f64, f64)], limit: f64) -> Option<usize> {
    points
        .iter()
        .enumerate()
        .filter(|(_, (_, value))| *value <= limit)
        .min_by(|(_, (a, _)), (_, (b, _))| a.total_cmp(b))
        .map(|(index, _)| index)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_front_keeps_exactly_the_undominated_points() {
        let points = [
            (1.0, 0.5),  // fastest: on the front
            (2.0, 0.2),  // on
            (2.5, 0.3),  // dominated by (2.0, 0.2)
            (4.0, 0.05), // on
            (4.0, 0.06), // as slow as (4.0, 0.05) and worse
            (8.0, 0.05), // as good as (4.0, 0.05) and slower
            (9.0, 0.01), // the most accurate: on
            (0.5, 0.9),  // the very fastest: on
        ];
        assert_eq!(
            pareto_front(&points),
            [true, true, false, true, false, false, true, true]
        );
    }

    #[test]
    fn a_slower_setting_is_not_on_the_front_for_an_error_smaller_only_by_rounding() {
        let points = [(1.0, 0.0245), (1.2, 0.024_499_99), (1.3, 0.0244)];
        assert_eq!(
            pareto_front(&points),
            [true, false, true],
            "0.4% better is better; 4e-7 is not"
        );
        assert_eq!(
            pareto_front(&[(1.0, 0.5), (1.0, 0.500_01)]),
            [true, true],
            "as costly and as good: both"
        );
    }

    #[test]
    fn equal_points_are_both_on_the_front_and_nan_is_never() {
        assert_eq!(pareto_front(&[(1.0, 1.0), (1.0, 1.0)]), [true, true]);
        assert_eq!(pareto_front(&[(1.0, f64::NAN), (2.0, 1.0)]), [false, true]);
        assert_eq!(pareto_front(&[]), Vec::<bool>::new());
    }

    #[test]
    fn the_target_picks_the_cheapest_point_that_meets_it() {
        let points = [(5.0, 0.01), (1.0, 0.2), (3.0, 0.05), (2.0, 0.06), (4.0, 0.04)];
        assert_eq!(cheapest_within(&points, 0.05), Some(2), "0.05 meets a limit of 0.05");
        assert_eq!(
            cheapest_within(&points, 0.045),
            Some(4),
            "the cheapest that meets it, not the best"
        );
        assert_eq!(cheapest_within(&points, 1.0), Some(1));
        assert_eq!(
            cheapest_within(&[(2.0, 0.1), (2.0, 0.0)], 0.1),
            Some(0),
            "the first on a tie"
        );
        assert_eq!(cheapest_within(&points, 0.001), None);
    }
}
