//! FLIP's separable filtering of a band of rows, with edge values repeated past the borders.
//!
//! Each output value is its taps' products summed in tap order from zero, as the reference
//! implementation sums them, so the maps round as its maps do. Eight neighbouring outputs are
//! summed side by side in SIMD lanes (each lane the same IEEE operations in the same order as
//! one output alone), and 32 at a time keep their sums in registers over all the taps: the
//! filters' time had gone to storing and reloading every output once per tap.

use std::ops::Range;

use crate::simd::{Isa, Kernel, Lanes, dispatch};

use super::kernels::MAX_TAPS;

/// The rows a band's maps cover and the rows they read.
pub(super) struct Band {
    pub width: usize,
    pub height: usize,
    /// The picture's rows the planes hold (the band and the filters' reach).
    pub read: Range<usize>,
    pub rows: Range<usize>,
}

impl Band {
    /// Each row of `plane` (the rows `read`) filtered by `taps` into `out`, the row's end values
    /// repeated past its ends.
    pub fn horizontal(&self, plane: &[f32], taps: &[f32], out: &mut Vec<f32>) {
        struct Horizontal<'a>(&'a Band, &'a [f32], &'a [f32], &'a mut Vec<f32>);
        impl Kernel for Horizontal<'_> {
            type Output = ();
            #[inline(always)]
            fn run<I: Isa>(self) {
                let Horizontal(band, plane, taps, out) = self;
                let (width, radius) = (band.width, taps.len() / 2);
                out.clear();
                out.resize(plane.len(), 0.0);
                let mut padded = vec![0.0f32; width + 2 * radius];
                for (row, out_row) in plane.chunks_exact(width).zip(out.chunks_exact_mut(width)) {
                    for (i, p) in padded.iter_mut().enumerate() {
                        *p = row[i.saturating_sub(radius).min(width - 1)];
                    }
                    let mut sources = [&[][..]; MAX_TAPS];
                    for (t, source) in sources[..taps.len()].iter_mut().enumerate() {
                        *source = &padded[t..t + width];
                    }
                    weighted_sums::<I>(out_row, taps, &sources[..taps.len()]);
                }
            }
        }
        assert!(taps.len() <= MAX_TAPS, "a filter has at most {MAX_TAPS} taps");
        dispatch(Horizontal(self, plane, taps, out));
    }

    /// The band's rows of `plane` (the rows `read`) filtered down the columns by `taps`, the
    /// picture's first and last rows repeated past its ends.
    pub fn vertical(&self, plane: &[f32], taps: &[f32]) -> Vec<f32> {
        let mut out = Vec::new();
        self.vertical_into(plane, taps, &mut out);
        out
    }

    /// [`Band::vertical`] into `out`.
    pub fn vertical_into(&self, plane: &[f32], taps: &[f32], out: &mut Vec<f32>) {
        struct Vertical<'a>(&'a Band, &'a [f32], &'a [f32], &'a mut Vec<f32>);
        impl Kernel for Vertical<'_> {
            type Output = ();
            #[inline(always)]
            fn run<I: Isa>(self) {
                let Vertical(band, plane, taps, out) = self;
                let (width, radius) = (band.width, taps.len() / 2);
                out.clear();
                out.resize(band.rows.len() * width, 0.0);
                let mut sources = [&[][..]; MAX_TAPS];
                for (y, out_row) in band.rows.clone().zip(out.chunks_exact_mut(width)) {
                    for (t, source) in sources[..taps.len()].iter_mut().enumerate() {
                        let row = (y + t).saturating_sub(radius).min(band.height - 1) - band.read.start;
                        *source = &plane[row * width..(row + 1) * width];
                    }
                    weighted_sums::<I>(out_row, taps, &sources[..taps.len()]);
                }
            }
        }
        assert!(taps.len() <= MAX_TAPS, "a filter has at most {MAX_TAPS} taps");
        dispatch(Vertical(self, plane, taps, out));
    }
}

/// `out[x] = Σ taps[t] · sources[t][x]`, summed in tap order from zero, for every `x`.
#[inline(always)]
fn weighted_sums<I: Isa>(out: &mut [f32], taps: &[f32], sources: &[&[f32]]) {
    const LANES: usize = 8;
    const BLOCK: usize = 4 * LANES;
    let n = out.len();
    let mut x = 0;
    while x + BLOCK <= n {
        let mut sums = [I::F32x8::splat(0.0); 4];
        for (&tap, source) in taps.iter().zip(sources) {
            let (weight, source) = (I::F32x8::splat(tap), &source[x..x + BLOCK]);
            for (k, sum) in sums.iter_mut().enumerate() {
                *sum = *sum + weight * I::F32x8::load(&source[k * LANES..]);
            }
        }
        for (k, sum) in sums.iter().enumerate() {
            sum.store(&mut out[x + k * LANES..]);
        }
        x += BLOCK;
    }
    while x + LANES <= n {
        let mut sum = I::F32x8::splat(0.0);
        for (&tap, source) in taps.iter().zip(sources) {
            sum = sum + I::F32x8::splat(tap) * I::F32x8::load(&source[x..]);
        }
        sum.store(&mut out[x..]);
        x += LANES;
    }
    for (x, o) in out.iter_mut().enumerate().skip(x) {
        let mut sum = 0.0;
        for (&tap, source) in taps.iter().zip(sources) {
            sum += tap * source[x];
        }
        *o = sum;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::simd::{SimdPath, available, dispatch_on};

    /// The filtering as the reference implementation writes it: one output at a time.
    fn one_by_one(taps: &[f32], sources: &[&[f32]], n: usize) -> Vec<f32> {
        (0..n)
            .map(|x| taps.iter().zip(sources).fold(0.0, |sum, (&tap, s)| sum + tap * s[x]))
            .collect()
    }

    struct Sums<'a>(&'a [f32], &'a [&'a [f32]], usize);
    impl Kernel for Sums<'_> {
        type Output = Vec<f32>;
        #[inline(always)]
        fn run<I: Isa>(self) -> Vec<f32> {
            let mut out = vec![0.0; self.2];
            weighted_sums::<I>(&mut out, self.0, self.1);
            out
        }
    }

    #[test]
    fn every_path_sums_as_one_output_at_a_time() {
        let taps: Vec<f32> = (0..21).map(|t| ((t as f32) * 0.37).sin() * 0.1).collect();
        // 75 outputs: two blocks of 32, one of 8 and a tail of 3.
        let rows: Vec<Vec<f32>> = (0..21)
            .map(|r| (0..75).map(|x| ((r * 75 + x) as f32 * 0.913).cos() * 100.0).collect())
            .collect();
        let sources: Vec<&[f32]> = rows.iter().map(Vec::as_slice).collect();
        let expected = one_by_one(&taps, &sources, 75);
        for path in available() {
            let got = dispatch_on(path, Sums(&taps, &sources, 75)).expect("available");
            let bits = |v: &[f32]| v.iter().map(|f| f.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&got), bits(&expected), "{}", SimdPath::name(path));
        }
    }
}
