//! The power the statistical verdict states: the smallest colour shift, over the whole picture
//! or one small area, that it detects with 80% probability at the renders' noise.
//!
//! With Šidák's fixed per-value threshold `z*`, a shift `δ` on a set of tested values with
//! differences' standard deviations `σ_i` is detected with probability
//! `1 − Π_i P(|N(δ/σ_i, 1)| ≤ z*)`; values without variance add the deterministic rule (a shift
//! beyond `pixel` on more pixels than `fail_fraction` allows fails for certain).

use rayon::prelude::*;
use serde::Serialize;

use super::normal;
use super::tolerance::Tolerance;

/// The σ of each colour value's difference, `None` for values with no variance in either image.
pub type Sigmas = Vec<[Option<f64>; 3]>;

/// The detection probability the power figures are stated at.
pub const POWER_PROBABILITY: f64 = 0.8;
/// The side of the square area of the local power figure, in pixels.
pub const POWER_WINDOW: u32 = 8;

/// The smallest shifts the test detects with `probability`; `None` where no shift would be
/// detected (nothing tested and too few deterministic pixels to break `fail_fraction`).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Power {
    pub probability: f64,
    /// Added to every colour value of the picture.
    pub uniform_shift: Option<f64>,
    /// The side of the square area of the local figures.
    pub window: u32,
    /// Added to every colour value of one `window × window` area: at the median area…
    pub local_shift_median: Option<f64>,
    /// …and at the area where the test sees least.
    pub local_shift_worst: Option<f64>,
}

/// What a shift of the colour must overcome in one area: the σ of its tested values and the
/// deterministic pixels that fail as soon as the shift passes `pixel`.
struct Area {
    sigmas: Vec<f64>,
    deterministic_pixels: usize,
}

struct Rule {
    z_critical: f64,
    pixel: f64,
    /// Failing pixels `fail_fraction` allows.
    allowed: usize,
}

impl Area {
    fn of(sigmas: &Sigmas, pixels: impl Iterator<Item = usize>) -> Area {
        let mut area = Area {
            sigmas: Vec::new(),
            deterministic_pixels: 0,
        };
        for i in pixels {
            area.sigmas.extend(sigmas[i].iter().flatten());
            area.deterministic_pixels += usize::from(sigmas[i].iter().any(Option::is_none));
        }
        area
    }

    /// The chance that a shift of `delta` on every value of the area is detected. The far tail
    /// (the shift detected with the wrong sign, under `P(Z > z*)` per value) is left out: it
    /// would add at most 10⁻³ to the chance over a whole picture.
    fn detection(&self, delta: f64, rule: &Rule) -> f64 {
        if delta > rule.pixel && self.deterministic_pixels > rule.allowed {
            return 1.0;
        }
        let log_missed: f64 = self
            .sigmas
            .iter()
            .map(|sigma| (-normal::upper_tail(rule.z_critical - delta / sigma).min(1.0)).ln_1p())
            .sum();
        -log_missed.exp_m1()
    }

    /// The smallest shift detected with [`POWER_PROBABILITY`], to 10⁻⁶ relative. The search
    /// starts from a bracket: the most sensitive value alone detects `σ_min·(z* + 0.85)` with
    /// 80%, and below `σ_min·(z* − q)`, with `n·P(Z > q) = 0.8`, even all `n` values together
    /// cannot; a shift just past `pixel` is certain when the deterministic pixels suffice.
    fn smallest_shift(&self, rule: &Rule) -> Option<f64> {
        let certain = (self.deterministic_pixels > rule.allowed).then_some(rule.pixel * (1.0 + 1e-9));
        let least = self.sigmas.iter().copied().reduce(f64::min);
        let (mut low, mut high) = match (least, certain) {
            (None, None) => return None,
            (None, Some(certain)) => (certain * 0.5, certain),
            (Some(sigma), certain) => {
                let reach = normal::upper_quantile(POWER_PROBABILITY / self.sigmas.len() as f64);
                let low = sigma * (rule.z_critical - reach).max(1e-3);
                let high = sigma * (rule.z_critical + 0.85);
                (
                    low.min(certain.unwrap_or(f64::INFINITY)) * 0.999,
                    high.min(certain.unwrap_or(f64::INFINITY)),
                )
            }
        };
        for _ in 0..24 {
            let middle = (low * high).sqrt();
            if self.detection(middle, rule) >= POWER_PROBABILITY {
                high = middle;
            } else {
                low = middle;
            }
        }
        Some(high)
    }
}

pub(super) fn power(width: u32, height: u32, sigmas: &Sigmas, z_critical: f64, tolerance: &Tolerance) -> Power {
    let rule = Rule {
        z_critical,
        pixel: tolerance.pixel,
        allowed: (tolerance.fail_fraction * sigmas.len() as f64).floor() as usize,
    };
    let (w, h) = (width as usize, height as usize);
    let uniform_shift = Area::of(sigmas, 0..sigmas.len()).smallest_shift(&rule);
    let side = POWER_WINDOW as usize;
    let (across, down) = ((w / side).max(1), (h / side).max(1));
    let (sw, sh) = (side.min(w), side.min(h));
    let mut local: Vec<Option<f64>> = (0..across * down)
        .into_par_iter()
        .map(|k| {
            let (x0, y0) = ((k % across) * sw, (k / across) * sh);
            let pixels = (y0..y0 + sh).flat_map(|y| (x0..x0 + sw).map(move |x| y * w + x));
            Area::of(sigmas, pixels).smallest_shift(&rule)
        })
        .collect();
    // Undetectable areas last: `None` stands for an infinite shift.
    local.sort_by(|a, b| a.unwrap_or(f64::INFINITY).total_cmp(&b.unwrap_or(f64::INFINITY)));
    Power {
        probability: POWER_PROBABILITY,
        uniform_shift,
        window: POWER_WINDOW,
        local_shift_median: local.get(local.len() / 2).copied().flatten(),
        local_shift_worst: local.last().copied().flatten(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn power_shrinks_with_the_noise_and_grows_with_the_area() {
        let rule = Rule {
            z_critical: 5.0,
            pixel: 0.01,
            allowed: 16,
        };
        let area = |sigma: f64, n: usize| Area {
            sigmas: vec![sigma; n],
            deterministic_pixels: 0,
        };
        let one = area(0.01, 1).smallest_shift(&rule).unwrap();
        // One value: detected 80% of the time at about z* + 0.84 σ.
        assert!((one / 0.01 - 5.84).abs() < 0.01, "{one}");
        assert!(area(0.001, 1).smallest_shift(&rule).unwrap() < one / 9.0);
        assert!(area(0.01, 64).smallest_shift(&rule).unwrap() < one);
        // Deterministic pixels beyond the allowance make any shift over `pixel` a failure.
        let flat = Area {
            sigmas: Vec::new(),
            deterministic_pixels: 17,
        };
        let shift = flat.smallest_shift(&rule).unwrap();
        assert!((shift / 0.01 - 1.0).abs() < 1e-6, "{shift}");
        let few = Area {
            sigmas: Vec::new(),
            deterministic_pixels: 16,
        };
        assert_eq!(few.smallest_shift(&rule), None);
    }
}
