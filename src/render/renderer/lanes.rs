//! The render loop's bands drawn eight rays at a time, by [`WhittedLanes`].
//!
//! A whole band goes into the SIMD path in one call: a call costs far more than its few
//! instructions (every constant the kernel splats again, a result copied out, the registers
//! saved), and a band of four rows makes thousands of packets. So the pixel loop, the sampler
//! and the moments run inside the kernel, compiled for the path the processor takes. (No
//! closure may carry the kernel's work: a closure is compiled without its enclosing function's
//! target features, and every lane operation in it would become a call.)

use super::super::geometry::lanes::LANES;
use super::super::packet::WhittedLanes;
use super::super::sampler::Sampler;
use super::{BandFilm, Moments, Pixel, Samples, pixel_at, pixel_centres, pixel_moments, sample_points};
use crate::options::{Filter, RenderOptions};
use crate::simd::{Isa, Kernel, dispatch};
use crate::stats::counter::RayCounts;

/// Draws `film`'s pixels with `lanes`, adding every ray traced to `rays`: runs of eight pixels
/// side by side when a pixel is one sample through its centre, each pixel's samples eight at a
/// time otherwise, with its AOV rays eight pixels to a packet.
pub(super) fn render_band<M: Moments>(
    lanes: &WhittedLanes<'_>,
    sampler: Sampler,
    options: &RenderOptions,
    film: &mut BandFilm<'_, M>,
    rays: &mut RayCounts,
) {
    struct Band<'a, 'b, 'c, M: Moments> {
        lanes: &'a WhittedLanes<'a>,
        sampler: Sampler,
        options: &'a RenderOptions,
        film: &'b mut BandFilm<'c, M>,
        rays: &'b mut RayCounts,
    }
    impl<M: Moments> Kernel for Band<'_, '_, '_, M> {
        type Output = ();
        #[inline(always)]
        fn run<I: Isa>(self) {
            let Band { lanes, sampler, options, film, rays } = self;
            if options.trace.filter == Filter::None && sampler.samples_per_pixel() == 1 {
                runs::<I, M>(lanes, options, film, rays);
            } else {
                sampled::<I, M>(lanes, sampler, options, film, rays);
            }
        }
    }
    dispatch(Band { lanes, sampler, options, film, rays })
}

/// One sample a pixel, through its centre: eight pixels side by side to a packet.
#[inline(always)]
fn runs<I: Isa, M: Moments>(lanes: &WhittedLanes<'_>, options: &RenderOptions, film: &mut BandFilm<'_, M>, rays: &mut RayCounts) {
    let size = (options.trace.width, options.trace.height);
    let width = options.trace.width as usize;
    let count = film.len();
    for start in (0..count).step_by(LANES) {
        let end = (start + LANES).min(count);
        let centres = pixel_centres(film.first + start..film.first + end, width);
        rays.camera += (end - start) as u64;
        let traced = lanes.trace_in::<I>(&centres[..end - start], size, options.aovs, rays);
        for (k, offset) in (start..end).enumerate() {
            film.store(offset, Pixel::new(M::single(traced.color[k]), traced.first[k]));
        }
    }
}

/// Several samples a pixel, or the filter's sub-pixels: each pixel's samples traced eight at a
/// time, and the AOV rays through the centres of eight pixels as one packet.
#[inline(always)]
fn sampled<I: Isa, M: Moments>(
    lanes: &WhittedLanes<'_>,
    sampler: Sampler,
    options: &RenderOptions,
    film: &mut BandFilm<'_, M>,
    rays: &mut RayCounts,
) {
    let size = (options.trace.width, options.trace.height);
    let width = options.trace.width as usize;
    let count = film.len();
    let mut scratch = Samples::default();
    for start in (0..count).step_by(LANES) {
        let end = (start + LANES).min(count);
        let centres = pixel_centres(film.first + start..film.first + end, width);
        let firsts = if options.aovs {
            rays.aov += (end - start) as u64;
            lanes.first_hits_in::<I>(&centres[..end - start], size)
        } else {
            [None; LANES]
        };
        for (k, offset) in (start..end).enumerate() {
            let raster = sample_points(sampler, options, pixel_at(film, offset, width), &mut scratch.points);
            rays.camera += scratch.points.len() as u64;
            scratch.colors.clear();
            lanes.colors_in::<I>(&scratch.points, raster, rays, &mut scratch.colors);
            let color = pixel_moments::<M>(sampler, options.trace.filter, &scratch.colors);
            film.store(offset, Pixel::new(color, firsts[k]));
        }
    }
}
