//! The render loop: bands of rows in parallel, every pixel a pure function of the scene, the
//! options and its coordinates, so the film is bit-identical for any thread count.

use rayon::prelude::*;

use super::faults;
use super::geometry::lanes::LANES;
use super::integrator::Whitted;
use super::packet::WhittedLanes;
use super::real::{Color, Real, Vec2, Vec3, to_f32};
use super::sampler::Sampler;
use super::scene::{Background, CubeMap, Intersection, Scene};
use crate::fault::{FaultPolicy, FaultSet, NoFaults};
use super::moments::{MeanOnly, Moments, WithVariance, film_vector};
use crate::film::Film;
use crate::options::{Filter, RenderOptions};
use crate::progress::Progress;
use crate::stats::counter::{NoCount, RayCounter, RayCounts};

/// Rows per parallel work item: small enough to balance two cores on a 100-row image, large
/// enough that scheduling costs nothing.
const BAND_ROWS: usize = 4;

/// The [1 2 1]⊗[1 2 1]/16 kernel over each output pixel's 3×3 block of supersamples.
const GAUSSIAN_WEIGHTS: [Real; 3] = [0.25, 0.5, 0.25];

/// The 3×3 supersamples of an output pixel, row by row: their column and row in the block and
/// their weight (`wx·wy`, as the kernel's product rounds).
const GAUSSIAN_SUBPIXELS: [(u32, u32, Real); 9] = {
    let w = GAUSSIAN_WEIGHTS;
    [
        (0, 0, w[0] * w[0]),
        (1, 0, w[1] * w[0]),
        (2, 0, w[2] * w[0]),
        (0, 1, w[0] * w[1]),
        (1, 1, w[1] * w[1]),
        (2, 1, w[2] * w[1]),
        (0, 2, w[0] * w[2]),
        (1, 2, w[1] * w[2]),
        (2, 2, w[2] * w[2]),
    ]
};

/// Renders the scene without counting anything.
pub fn render(scene: &Scene, options: &RenderOptions, progress: &dyn Progress) -> Film {
    render_counted::<NoCount, _>(scene, options, NoFaults, progress).0
}

/// [`render`] with every ray traced alone, as the integrator's faults must be: the reference
/// that the eight-lane integrator is checked against, bit for bit.
#[cfg(test)]
pub(super) fn render_one_ray_at_a_time(scene: &Scene, options: &RenderOptions) -> Film {
    let sampler = Sampler::with_seeding(options.trace.samples, options.trace.seed, options.seeding);
    let progress = &crate::progress::Silent;
    if sampler.samples_per_pixel() > 1 {
        render_pixels::<NoCount, _, WithVariance>(scene, options, sampler, NoFaults, false, progress).0
    } else {
        render_pixels::<NoCount, _, MeanOnly>(scene, options, sampler, NoFaults, false, progress).0
    }
}

/// [`render`], also counting every ray traced, by kind (for `--stats`). The film is the same.
pub fn render_counting_rays(scene: &Scene, options: &RenderOptions, progress: &dyn Progress) -> (Film, RayCounts) {
    render_counted::<RayCounts, _>(scene, options, NoFaults, progress)
}

/// [`render`] as a program with the integrator's mistakes of `faults` would (the catalogue's
/// [`crate::fault::Injection::Integrator`] faults; the others act on the case, the options or
/// the PNGs, outside the renderer). Without such a fault this is [`render`].
pub fn render_with_faults(scene: &Scene, options: &RenderOptions, faults: FaultSet, progress: &dyn Progress) -> Film {
    if faults.checks_integrator() {
        render_counted::<NoCount, _>(scene, options, faults, progress).0
    } else {
        render(scene, options, progress)
    }
}

/// The render loop. Every pixel counts its rays into a [`RayCounts`] of its own, the same code
/// whatever `C` is, and each band adds its pixels' counts into a `C`; the bands' `C`s are merged
/// once they finish. With [`NoCount`] the adding compiles away. The film does not depend on `C`.
///
/// Private, so that its only copies are those above, compiled in this crate: a copy
/// instantiated in another crate (a benchmark, say) would be optimised differently from the one
/// the command line runs. `F` is [`NoFaults`] for every render but a diagnosis's.
fn render_counted<C: RayCounter, F: FaultPolicy>(
    scene: &Scene,
    options: &RenderOptions,
    faults: F,
    progress: &dyn Progress,
) -> (Film, C) {
    let sampler = Sampler::with_seeding(options.trace.samples, options.trace.seed, options.seeding);
    if sampler.samples_per_pixel() > 1 {
        render_pixels::<C, F, WithVariance>(scene, options, sampler, faults, true, progress)
    } else {
        render_pixels::<C, F, MeanOnly>(scene, options, sampler, faults, true, progress)
    }
}

/// [`render_counted`] with the choice of moments made once per render: `M` is [`WithVariance`]
/// when a pixel has several samples, [`MeanOnly`] otherwise, so a one-sample render neither
/// squares a sample nor allocates a variance plane. Rays are traced eight at a time when
/// `in_lanes` and no integrator fault asks for them one by one.
fn render_pixels<C: RayCounter, F: FaultPolicy, M: Moments>(
    scene: &Scene,
    options: &RenderOptions,
    sampler: Sampler,
    faults: F,
    in_lanes: bool,
    progress: &dyn Progress,
) -> (Film, C) {
    let mut film = Film::new(options.trace.width, options.trace.height);
    let trace = &options.trace;
    let pixels = PixelRenderer {
        scene,
        integrator: Whitted::with_faults(scene, trace.bounces, trace.shadows, options.spawn, faults),
        lanes: (in_lanes && !faults.set().checks_integrator())
            .then(|| WhittedLanes::new(scene, trace.bounces, trace.shadows, options.spawn)),
        faults,
        sampler,
        options,
    };
    if let (Some(lanes), Background::CubeMap(map)) = (&pixels.lanes, &scene.background) {
        decode_faces_in_view(lanes, map, options);
    }
    let width = options.trace.width as usize;
    let band = width * BAND_ROWS;
    let bands: Vec<(C, M::Band)> = film
        .color
        .par_chunks_mut(band)
        .zip(film.depth.par_chunks_mut(band))
        .zip(film.normal.par_chunks_mut(band))
        .enumerate()
        .map(|(band_index, ((color, depth), normal))| {
            let mut counter = C::default();
            let mut variance = M::band(color.len());
            let pixel_count = color.len();
            let mut store = |offset: usize, pixel: Pixel<M>| {
                color[offset] = film_vector(pixel.color.mean());
                depth[offset] = pixel.depth;
                normal[offset] = pixel.normal;
                M::store(&mut variance, offset, &pixel.color);
            };
            let first = band_index * band;
            match pixels.runs() {
                Some(lanes) => {
                    // The whole band in one call into the SIMD path: a call costs far more than
                    // its instructions (see `docs/speed.md`).
                    let mut rays = RayCounts::default();
                    let centres: Vec<Vec2> = (first..first + pixel_count)
                        .map(|index| pixel_centre((index % width) as u32, (index / width) as u32))
                        .collect();
                    rays.camera += pixel_count as u64;
                    let (mut colors, mut firsts) = (Vec::with_capacity(pixel_count), Vec::new());
                    let size = (options.trace.width, options.trace.height);
                    lanes.colors(&centres, size, &mut rays, &mut colors, options.aovs.then_some(&mut firsts));
                    counter.add(&rays);
                    for (offset, &color) in colors.iter().enumerate() {
                        store(offset, Pixel::new(M::single(color), firsts.get(offset).copied().flatten()));
                    }
                }
                None => {
                    let mut scratch = Samples::default();
                    for start in (0..pixel_count).step_by(LANES) {
                        let end = (start + LANES).min(pixel_count);
                        let mut rays = RayCounts::default();
                        let coordinates = pixel_coordinates(first + start..first + end, width);
                        let centres = coordinates.map(|(x, y)| pixel_centre(x, y));
                        match pixels.first_hits(&centres[..end - start], &mut rays) {
                            Some(firsts) => {
                                let colors = pixels.samples::<M>(&coordinates[..end - start], &mut rays, &mut scratch);
                                for (k, color) in colors.enumerate() {
                                    store(start + k, Pixel::new(color, firsts[k]));
                                }
                            }
                            None => {
                                for (offset, &(x, y)) in (start..end).zip(&coordinates) {
                                    store(offset, pixels.pixel::<M>(x, y, &mut rays, &mut scratch));
                                }
                            }
                        }
                        counter.add(&rays);
                    }
                }
            }
            progress.advance((pixel_count / width) as u64);
            (counter, variance)
        })
        .collect();
    let mut counter = C::default();
    let mut variances = Vec::with_capacity(bands.len());
    for (band_counter, variance) in bands {
        counter = counter.merge(band_counter);
        variances.push(variance);
    }
    film.variance = M::assemble(variances);
    (film, counter)
}

/// Every how many pixels, across and down, [`decode_faces_in_view`] traces one: a face that
/// covers a square this wide anywhere a ray reaches is found (under 2% of a one-sample render's
/// rays); one seen only in smaller spots is decoded when first seen, as without the probe.
const PROBE_SPACING: usize = 8;

/// Decodes, side by side before the render, the cube-map faces that rays through a sparse grid
/// of the picture's pixel centres look at (at any bounce), so that the faces the render will
/// see are not decoded one after another by the first rays to look while others wait. The
/// course's scene 7 sees two faces: both were decoded by one thread, in turn, each while the
/// other thread waited. Changes no pixel: decoding is the same whenever it happens.
fn decode_faces_in_view(lanes: &WhittedLanes<'_>, map: &CubeMap, options: &RenderOptions) {
    let undecoded = map.undecoded_faces();
    if undecoded == 0 {
        return;
    }
    let (width, height) = (options.trace.width, options.trace.height);
    let centres: Vec<Vec2> = (0..height as usize)
        .step_by(PROBE_SPACING)
        .flat_map(|y| (0..width as usize).step_by(PROBE_SPACING).map(move |x| pixel_centre(x as u32, y as u32)))
        .collect();
    map.decode_faces(lanes.cube_map_faces_seen(&centres, (width, height)) & undecoded);
}

/// A pixel's sample points and the colours seen through them, kept from pixel to pixel so that
/// no pixel allocates.
#[derive(Default)]
struct Samples {
    points: Vec<Vec2>,
    colors: Vec<Color>,
}

struct Pixel<M> {
    color: M,
    depth: f32,
    normal: [f32; 3],
}

struct PixelRenderer<'a, F: FaultPolicy> {
    scene: &'a Scene,
    integrator: Whitted<'a, F>,
    /// The same integrator eight rays at a time, for every render without the integrator's
    /// faults: it draws the same picture, bit for bit.
    lanes: Option<WhittedLanes<'a>>,
    faults: F,
    sampler: Sampler,
    options: &'a RenderOptions,
}

impl<F: FaultPolicy> PixelRenderer<'_, F> {
    /// The integrator for runs of eight pixels side by side, when pixels are one sample each
    /// and the eight-lane integrator can draw them.
    fn runs(&self) -> Option<&WhittedLanes<'_>> {
        self.lanes.as_ref().filter(|_| self.one_ray_per_pixel())
    }

    /// Whether a pixel is one sample through its centre, unfiltered: its colour is one ray's.
    fn one_ray_per_pixel(&self) -> bool {
        self.options.trace.filter == Filter::None && self.sampler.samples_per_pixel() == 1
    }

    /// The pixel's colour (with its moments `M`) and AOVs; every ray traced for it is added to
    /// `rays`. `scratch` holds its samples on the way.
    fn pixel<M: Moments>(&self, x: u32, y: u32, rays: &mut RayCounts, scratch: &mut Samples) -> Pixel<M> {
        let (width, height) = (self.options.trace.width, self.options.trace.height);
        let centre = pixel_centre(x, y);
        if self.one_ray_per_pixel() {
            rays.camera += 1;
            let ray = self.scene.camera.ray(centre, width, height);
            let (color, first) = self.integrator.trace(ray, rays);
            let first = first.filter(|_| self.options.aovs).map(|hit| (hit.surface.t, hit.surface.shading_normal));
            return Pixel::new(M::single(color), first);
        }
        let color = self.samples(&[(x, y)], rays, scratch).next().expect("one pixel's samples give one colour");
        let first = self.first_hit(centre, rays).map(|hit| (hit.surface.t, hit.surface.shading_normal));
        Pixel::new(color, first)
    }

    /// The colours (with their moments `M`) of the pixels at `coordinates`, in order, each from
    /// all its samples: each sub-pixel of the filter takes the sampler's samples. The pixels'
    /// samples are traced together, so that a run of pixels goes into the SIMD path once, not
    /// once a pixel (a call costs far more than its instructions: see `docs/speed.md`). Every ray
    /// traced is added to `rays`; `scratch` holds the samples on the way.
    fn samples<'s, M: Moments>(
        &self,
        coordinates: &[(u32, u32)],
        rays: &mut RayCounts,
        scratch: &'s mut Samples,
    ) -> impl Iterator<Item = M> + 's {
        let (width, height) = (self.options.trace.width, self.options.trace.height);
        let (subpixels, scale): (&'static [(u32, u32, Real)], u32) = match self.options.trace.filter {
            Filter::None => (&[(0, 0, 1.0)], 1),
            Filter::Gaussian => (&GAUSSIAN_SUBPIXELS, 3),
        };
        let count = self.sampler.samples_per_pixel() as usize;
        // The samples in order: pixel by pixel, sub-pixel by sub-pixel, each sub-pixel's `count`.
        scratch.points.clear();
        for &(x, y) in coordinates {
            for &(i, j, _) in subpixels {
                let (sx, sy) = (scale * x + i, scale * y + j);
                self.sampler.pixel(sx, sy).push_points(Vec2::new(sx as Real, sy as Real), &mut scratch.points);
            }
        }
        self.trace_points(&scratch.points, (scale * width, scale * height), rays, &mut scratch.colors);
        scratch.colors.chunks_exact(count * subpixels.len()).map(move |pixel| {
            let mut color = M::zero();
            for (colors, &(_, _, weight)) in pixel.chunks_exact(count).zip(subpixels) {
                let finished = M::of_samples(colors);
                if scale == 1 {
                    color = finished;
                } else {
                    color.add_weighted(&finished, weight);
                }
            }
            color
        })
    }

    /// What the rays through the centres of up to eight pixels hit first (its `t` and shading
    /// normal), for the AOVs, traced as one packet; all `None` when no AOV is written. `None`
    /// when the eight-lane integrator cannot draw the picture: [`PixelRenderer::pixel`] then
    /// traces each pixel's AOV ray alone, through the faults.
    fn first_hits(&self, centres: &[Vec2], rays: &mut RayCounts) -> Option<[Option<(Real, Vec3)>; LANES]> {
        let lanes = self.lanes.as_ref()?;
        if !self.options.aovs {
            return Some([None; LANES]);
        }
        rays.aov += centres.len() as u64;
        Some(lanes.first_hits(centres, (self.options.trace.width, self.options.trace.height)))
    }

    /// The colours seen along the camera rays through `points`, on the raster of an image of
    /// `size`, in place of `colors`' contents and in the same order: eight at a time when the
    /// eight-lane integrator can draw them, one at a time otherwise.
    fn trace_points(&self, points: &[Vec2], (width, height): (u32, u32), rays: &mut RayCounts, colors: &mut Vec<Color>) {
        rays.camera += points.len() as u64;
        colors.clear();
        let Some(lanes) = &self.lanes else {
            for &point in points {
                let ray = self.scene.camera.ray(point, width, height);
                colors.push(self.integrator.trace(ray, rays).0);
            }
            return;
        };
        lanes.colors(points, (width, height), rays, colors, None);
    }

    /// The AOVs come from one ray through the output pixel's centre: depth and normals averaged
    /// across an edge would describe no surface at all. Traced only when the AOVs are wanted.
    fn first_hit(&self, centre: Vec2, rays: &mut RayCounts) -> Option<Intersection> {
        if !self.options.aovs {
            return None;
        }
        rays.aov += 1;
        let ray = self.scene.camera.ray(centre, self.options.trace.width, self.options.trace.height);
        faults::intersect(self.scene, &ray, self.faults)
    }
}

/// The column and row of each pixel of `indices` (row-major in an image `width` pixels wide),
/// at most eight; the lanes past them are `(0, 0)`.
fn pixel_coordinates(indices: std::ops::Range<usize>, width: usize) -> [(u32, u32); LANES] {
    let mut coordinates = [(0, 0); LANES];
    for (coordinate, index) in coordinates.iter_mut().zip(indices) {
        *coordinate = ((index % width) as u32, (index / width) as u32);
    }
    coordinates
}

/// The centre of pixel `(x, y)` on the raster.
fn pixel_centre(x: u32, y: u32) -> Vec2 {
    Vec2::new(x as Real + 0.5, y as Real + 0.5)
}

impl<M> Pixel<M> {
    /// A pixel of colour `color` whose AOVs show `first` (the `t` and shading normal of the
    /// first hit), or a miss.
    fn new(color: M, first: Option<(Real, Vec3)>) -> Pixel<M> {
        match first {
            Some((t, normal)) => Pixel { color, depth: to_f32(t), normal: film_vector(normal) },
            None => Pixel { color, depth: f32::INFINITY, normal: [0.0; 3] },
        }
    }
}

#[cfg(test)]
mod tests;
