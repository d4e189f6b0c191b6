//! Shadow acne recognised by its signature rather than
//! pixel by pixel: which pixels turn to acne depends on each program's rounding, so a student's
//! acne never falls on goldray's speckles, and even its density differs (a plane's acne comes in
//! bands, a sphere's in salt and pepper). What every program's acne shares is where it may be
//! and what it does there. A student's image has the signature of the fault's render when
//!
//! 1. the pixels where it fails against the golden picture are, but for a few, pixels that are
//!    darker than the golden ones (and nowhere brighter) and that lie within
//!    [`reach`] of the fault render's own speckles: acne only on the surfaces where the mistake
//!    makes acne (lit ones, for shadows), and only in images the mistake can change at all;
//! 2. those pixels are scattered, not a solid region: at most [`SOLID`] of them have all eight
//!    neighbours changed too (a light or a shadow missing changes whole surfaces, whose pixels
//!    are nearly all inside);
//! 3. and they appear in the same regions: of the cells (squares of four times [`reach`]) where
//!    the fault's render has speckles, at least [`COVERED`] hold some of the student's (a
//!    plane's acne in bands leaves most pixels between the bands clean, but few cells).
//!
//! The failing fraction left is then that of the failing pixels outside the acne (rounding at
//! edges, another mistake), and the RMSE is over those pixels too; an image without the
//! signature keeps its failing pixels, so the mistake explains nothing of it.

use super::super::diagnosis::Residual;
use crate::rgb_image::RgbImage;

/// How far (in pixels, at least 2, a fortieth of the picture) a student's speckle may be from the
/// fault render's to be the same acne.
pub fn reach(picture: &RgbImage) -> u32 {
    (picture.width().min(picture.height()) / 40).max(2)
}

/// At most this share of the acne's pixels may lie inside a changed region (else it is not
/// speckles).
pub const SOLID: f64 = 0.6;
/// At least this share of the cells with the fault render's speckles must hold the student's.
pub const COVERED: f64 = 0.5;

/// The student's image against the fault's acne, by the signature (the module documentation).
pub fn acne_residual(golden: &RgbImage, fault: &RgbImage, student: &RgbImage, threshold: f64) -> Residual {
    let (w, h) = golden.dimensions();
    let reach = reach(golden);
    let changed = |picture: &RgbImage| -> Vec<bool> {
        picture
            .pixels()
            .zip(golden.pixels())
            .map(|(p, g)| {
                let d: Vec<i32> = (0..3).map(|c| i32::from(p.0[c]) - i32::from(g.0[c])).collect();
                let beyond = d.iter().any(|x| f64::from(x.abs()) > threshold);
                beyond && d.iter().all(|x| f64::from(*x) <= threshold)
            })
            .collect()
    };
    let fault_speckles = changed(fault);
    let near_fault = dilate(&fault_speckles, w, h, reach);
    let student_speckles = changed(student);
    let failing: Vec<bool> = student
        .pixels()
        .zip(golden.pixels())
        .map(|(s, g)| s.0.iter().zip(g.0).any(|(a, b)| f64::from(a.abs_diff(b)) > threshold))
        .collect();
    let acne: Vec<bool> = student_speckles
        .iter()
        .zip(&near_fault)
        .map(|(s, n)| *s && *n)
        .collect();
    let acne_count = acne.iter().filter(|a| **a).count();
    let inside = interior(&acne, w, h);
    let cell = 4 * reach;
    let (fault_cells, student_cells) = (cells(&fault_speckles, w, h, cell), cells(&acne, w, h, cell));
    let speckles = fault_cells.iter().filter(|f| **f).count();
    let covered = fault_cells
        .iter()
        .zip(&student_cells)
        .filter(|(f, s)| **f && **s)
        .count();
    let signature =
        acne_count > 0 && (inside as f64) <= SOLID * acne_count as f64 && (covered as f64) >= COVERED * speckles as f64;
    let (mut left, mut sum_sq, mut counted) = (0usize, 0u64, 0usize);
    for (((s, g), fails), is_acne) in student.pixels().zip(golden.pixels()).zip(&failing).zip(&acne) {
        if signature && *is_acne {
            continue;
        }
        left += usize::from(*fails);
        counted += 1;
        for c in 0..3 {
            let d = i64::from(s.0[c]) - i64::from(g.0[c]);
            sum_sq += (d * d) as u64;
        }
    }
    let pixels = (w as usize * h as usize).max(1);
    Residual {
        failing_fraction: left as f64 / pixels as f64,
        rmse: (sum_sq as f64 / (3 * counted.max(1)) as f64).sqrt(),
    }
}

/// Whether each `cell × cell` square of the picture holds a set pixel, row by row.
fn cells(mask: &[bool], w: u32, h: u32, cell: u32) -> Vec<bool> {
    let (columns, rows) = (w.div_ceil(cell) as usize, h.div_ceil(cell) as usize);
    let mut out = vec![false; columns * rows];
    for (i, set) in mask.iter().enumerate() {
        if *set {
            let (x, y) = (i % w as usize, i / w as usize);
            out[(y / cell as usize) * columns + x / cell as usize] = true;
        }
    }
    out
}

/// How many set pixels have all eight neighbours set.
fn interior(mask: &[bool], w: u32, h: u32) -> usize {
    let (w, h) = (w as usize, h as usize);
    let mut count = 0;
    for y in 1..h.saturating_sub(1) {
        for x in 1..w.saturating_sub(1) {
            let all = (y - 1..=y + 1).all(|yy| (x - 1..=x + 1).all(|xx| mask[yy * w + xx]));
            count += usize::from(all);
        }
    }
    count
}

/// Every pixel within `reach` (a square) of a set one.
fn dilate(mask: &[bool], w: u32, h: u32, reach: u32) -> Vec<bool> {
    let (w, h, r) = (w as usize, h as usize, reach as usize);
    // Rows first, then columns: a square of side 2r + 1.
    let mut rows = vec![false; mask.len()];
    for y in 0..h {
        for x in 0..w {
            let (from, to) = (x.saturating_sub(r), (x + r).min(w - 1));
            rows[y * w + x] = mask[y * w + from..=y * w + to].iter().any(|m| *m);
        }
    }
    let mut out = vec![false; mask.len()];
    for y in 0..h {
        let (from, to) = (y.saturating_sub(r), (y + r).min(h - 1));
        for x in 0..w {
            out[y * w + x] = (from..=to).any(|yy| rows[yy * w + x]);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rgb_image::Rgb;

    /// A lit grey square on black, with every `period`-th pixel of it `shade` (acne) or all.
    fn picture(period: u32, shade: u8) -> RgbImage {
        RgbImage::from_fn(40, 40, |x, y| {
            let lit = (10..30).contains(&x) && (10..30).contains(&y);
            match (lit, period > 0 && (x * 7 + y * 3) % period == 0) {
                (false, _) => Rgb([0; 3]),
                (true, true) => Rgb([shade; 3]),
                (true, false) => Rgb([200; 3]),
            }
        })
    }

    #[test]
    fn acne_elsewhere_on_the_same_surface_has_the_signature() {
        let golden = picture(0, 200);
        let fault = picture(2, 20);
        // Other speckles, another density: the same acne.
        let student = RgbImage::from_fn(40, 40, |x, y| {
            let lit = (10..30).contains(&x) && (10..30).contains(&y);
            if lit && (x + 5 * y) % 3 == 0 {
                Rgb([40; 3])
            } else {
                *golden.get_pixel(x, y)
            }
        });
        let r = acne_residual(&golden, &fault, &student, 8.0);
        assert_eq!(r.failing_fraction, 0.0);
        // Solid darkening (a light missing) is not acne; nor is brightening.
        let dark = picture(1, 20);
        assert!(acne_residual(&golden, &fault, &dark, 8.0).failing_fraction > 0.2);
        let bright = RgbImage::from_fn(40, 40, |x, y| {
            let p = student.get_pixel(x, y).0[0];
            Rgb([if p == 40 { 255 } else { p }; 3])
        });
        assert!(acne_residual(&golden, &fault, &bright, 8.0).failing_fraction > 0.05);
        // Speckles where the fault makes none are not its acne.
        let elsewhere = RgbImage::from_fn(40, 40, |x, y| {
            if x < 8 && y < 8 && (x + y) % 2 == 0 {
                Rgb([0, 0, 0])
            } else {
                *golden.get_pixel(x, y)
            }
        });
        let golden_lit_corner = RgbImage::from_fn(40, 40, |x, y| {
            if x < 8 && y < 8 {
                Rgb([200; 3])
            } else {
                *golden.get_pixel(x, y)
            }
        });
        let r = acne_residual(&golden_lit_corner, &fault, &elsewhere, 8.0);
        assert!(r.failing_fraction > 0.01, "{r:?}");
    }
}
