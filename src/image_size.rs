//! The one rule for how large an image may be, wherever a size is given: a case's `[render]`
//! table, a rubric, `goldray mit6837 -size`, `goldray tradeoff --size`.

use std::fmt;

/// The largest side a render may have unless the user insists (`--force`). A film of this size
/// already holds 16384² × 7 floats, 7.5 GB: a larger one is almost always a typo.
pub const MAX_IMAGE_SIZE: u32 = 16384;

/// A side outside the allowed range. Displays as what would be valid, so that each caller can
/// put the offending value and its location in front.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
pub struct SideError {
    /// The largest side allowed.
    pub max: u32,
    /// Whether `--force` would lift the limit.
    pub forceable: bool,
}

impl fmt::Display for SideError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "must be between 1 and {}", self.max)?;
        if self.forceable {
            write!(f, " (pass --force to render larger images)")?;
        }
        Ok(())
    }
}

/// How a caller treats the limit.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SizeLimit {
    /// At most [`MAX_IMAGE_SIZE`], and the user can pass `--force`.
    Forceable,
    /// At most [`MAX_IMAGE_SIZE`], with no way around it (a rubric, a tradeoff sweep).
    Fixed,
    /// Any positive side: `--force` was given.
    Lifted,
}

/// Checks one side of an image.
pub fn check_side(side: i64, limit: SizeLimit) -> Result<u32, SideError> {
    let max = match limit {
        SizeLimit::Lifted => u32::MAX,
        SizeLimit::Forceable | SizeLimit::Fixed => MAX_IMAGE_SIZE,
    };
    match u32::try_from(side) {
        Ok(side) if (1..=max).contains(&side) => Ok(side),
        _ => Err(SideError {
            max,
            forceable: limit == SizeLimit::Forceable,
        }),
    }
}

/// Checks both sides, naming the size in the error: `size 0 400: each side must be between …`.
pub fn check_size(width: i64, height: i64, limit: SizeLimit) -> Result<(u32, u32), String> {
    let explain = |error: SideError| format!("size {width} {height}: each side {error}");
    Ok((
        check_side(width, limit).map_err(explain)?,
        check_side(height, limit).map_err(explain)?,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sides_from_one_to_the_maximum_pass_and_force_lifts_only_the_maximum() {
        assert_eq!(check_side(1, SizeLimit::Fixed), Ok(1));
        assert_eq!(check_side(16384, SizeLimit::Forceable), Ok(16384));
        let over = check_side(16385, SizeLimit::Forceable).unwrap_err();
        assert_eq!(
            over.to_string(),
            "must be between 1 and 16384 (pass --force to render larger images)"
        );
        assert_eq!(check_side(16385, SizeLimit::Lifted), Ok(16385));
        for bad in [0, -400, i64::MAX] {
            assert!(check_side(bad, SizeLimit::Lifted).is_err(), "{bad}");
        }
        assert_eq!(
            check_side(0, SizeLimit::Lifted).unwrap_err().to_string(),
            "must be between 1 and 4294967295"
        );
        assert_eq!(
            check_side(0, SizeLimit::Fixed).unwrap_err().to_string(),
            "must be between 1 and 16384"
        );
    }

    #[test]
    fn sizes_name_both_sides() {
        assert_eq!(check_size(800, 600, SizeLimit::Fixed), Ok((800, 600)));
        assert_eq!(
            check_size(-400, 400, SizeLimit::Forceable).unwrap_err(),
            "size -400 400: each side must be between 1 and 16384 (pass --force to render larger images)"
        );
    }
}
