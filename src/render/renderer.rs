//! The render loop: bands of rows in parallel, every pixel a pure function of the scene, the
//! options and its coordinates, so the film is bit-identical for any thread count.

use rayon::prelude::*;

use super::faults;
use super::integrator::Whitted;
use super::real::{Real, Vec2, to_f32};
use super::sampler::Sampler;
use super::scene::{Intersection, Scene};
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

/// Renders the scene without counting anything.
pub fn render(scene: &Scene, options: &RenderOptions, progress: &dyn Progress) -> Film {
    render_counted::<NoCount, _>(scene, options, NoFaults, progress).0
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
        render_pixels::<C, F, WithVariance>(scene, options, sampler, faults, progress)
    } else {
        render_pixels::<C, F, MeanOnly>(scene, options, sampler, faults, progress)
    }
}

/// [`render_counted`] with the choice of moments made once per render: `M` is [`WithVariance`]
/// when a pixel has several samples, [`MeanOnly`] otherwise, so a one-sample render neither
/// squares a sample nor allocates a variance plane.
fn render_pixels<C: RayCounter, F: FaultPolicy, M: Moments>(
    scene: &Scene,
    options: &RenderOptions,
    sampler: Sampler,
    faults: F,
    progress: &dyn Progress,
) -> (Film, C) {
    let mut film = Film::new(options.trace.width, options.trace.height);
    let pixels = PixelRenderer {
        scene,
        integrator: Whitted::with_faults(scene, options.trace.bounces, options.trace.shadows, options.spawn, faults),
        faults,
        sampler,
        options,
    };
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
            for (offset, ((color, depth), normal)) in color.iter_mut().zip(depth).zip(normal).enumerate() {
                let index = band_index * band + offset;
                let (x, y) = ((index % width) as u32, (index / width) as u32);
                let mut rays = RayCounts::default();
                let pixel = pixels.pixel::<M>(x, y, &mut rays);
                counter.add(&rays);
                *color = film_vector(pixel.color.mean());
                *depth = pixel.depth;
                *normal = pixel.normal;
                M::store(&mut variance, offset, &pixel.color);
            }
            progress.advance((color.len() / width) as u64);
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

struct Pixel<M> {
    color: M,
    depth: f32,
    normal: [f32; 3],
}

struct PixelRenderer<'a, F: FaultPolicy> {
    scene: &'a Scene,
    integrator: Whitted<'a, F>,
    faults: F,
    sampler: Sampler,
    options: &'a RenderOptions,
}

impl<F: FaultPolicy> PixelRenderer<'_, F> {
    /// The pixel's colour (with its moments `M`) and AOVs; every ray traced for it is added to
    /// `rays`.
    fn pixel<M: Moments>(&self, x: u32, y: u32, rays: &mut RayCounts) -> Pixel<M> {
        let (width, height) = (self.options.trace.width, self.options.trace.height);
        let centre = Vec2::new(x as Real + 0.5, y as Real + 0.5);
        match self.options.trace.filter {
            Filter::None if self.sampler.samples_per_pixel() == 1 => {
                rays.camera += 1;
                let (color, first) = self.integrator.trace(self.scene.camera.ray(centre, width, height), rays);
                Pixel::new(M::single(color), first.filter(|_| self.options.aovs).as_ref())
            }
            Filter::None => {
                let color = self.samples::<M>(x, y, width, height, rays);
                Pixel::new(color, self.first_hit(centre, rays).as_ref())
            }
            Filter::Gaussian => {
                let mut color = M::zero();
                for (j, wy) in GAUSSIAN_WEIGHTS.iter().enumerate() {
                    for (i, wx) in GAUSSIAN_WEIGHTS.iter().enumerate() {
                        let sub = self.samples::<M>(3 * x + i as u32, 3 * y + j as u32, 3 * width, 3 * height, rays);
                        color.add_weighted(&sub, wx * wy);
                    }
                }
                Pixel::new(color, self.first_hit(centre, rays).as_ref())
            }
        }
    }

    /// Mean colour of a (sub)pixel's stratified samples in an image of `width × height`, with
    /// the variance of that mean when `M` keeps it.
    fn samples<M: Moments>(&self, x: u32, y: u32, width: u32, height: u32, rays: &mut RayCounts) -> M {
        let count = self.sampler.samples_per_pixel();
        let origin = Vec2::new(x as Real, y as Real);
        rays.camera += u64::from(count);
        let mut moments = M::Accumulator::default();
        for index in 0..count {
            let raster = origin + self.sampler.offset(x, y, index);
            M::push(&mut moments, self.integrator.trace(self.scene.camera.ray(raster, width, height), rays).0);
        }
        M::of(moments, count)
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

impl<M> Pixel<M> {
    fn new(color: M, first: Option<&Intersection>) -> Pixel<M> {
        match first {
            Some(hit) => Pixel {
                color,
                depth: to_f32(hit.surface.t),
                normal: film_vector(hit.surface.shading_normal),
            },
            None => Pixel { color, depth: f32::INFINITY, normal: [0.0; 3] },
        }
    }
}
