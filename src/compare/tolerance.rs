//! How far an image may drift from its reference before the comparison fails.
//!
//! The comparator's own settings: a case file's `[tolerance]` table and `goldray diff`'s flags
//! both fill one in, so the suite and the command judge alike.

/// How far a render may drift from golden; all values are non-negative.
#[derive(Clone, Debug, PartialEq)]
pub struct Tolerance {
    pub pixel: f64,
    /// In [0, 1].
    pub fail_fraction: f64,
    pub rmse: f64,
    /// A hard cap on any single channel's error, for cases where one wrong pixel matters.
    pub max: Option<f64>,
}

impl Tolerance {
    /// What a case without `[tolerance]` gets, and what `goldray diff` applies to two EXRs: one
    /// definition, so the suite and the command judge alike.
    pub const DEFAULT: Tolerance = Tolerance {
        pixel: 0.01,
        fail_fraction: 0.001,
        rmse: 0.002,
        max: None,
    };
}

/// The case-file defaults, so that `goldray diff` on two EXRs judges like the golden suite.
pub const EXR_DEFAULTS: Tolerance = Tolerance::DEFAULT;

/// The same limits in 8-bit code values: an off-by-one code (rounding, or an ulp of drift at a
/// quantisation boundary) is within `pixel`; `rmse` is 0.002 × 255 ≈ 0.5 codes, so a uniform
/// one-code shift of the whole picture still fails.
pub const PNG_DEFAULTS: Tolerance = Tolerance {
    pixel: 1.0,
    fail_fraction: 0.001,
    rmse: 0.5,
    max: None,
};
