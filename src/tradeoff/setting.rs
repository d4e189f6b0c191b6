//! One point of a sweep, shared by the sweep that plans it and the measurement that renders it.

use crate::case::Case;
use crate::options::{Filter, Precision};

/// One point of the sweep: a value on every axis. Everything else (scene, size, seed, shadows)
/// is the case's own, so two settings differ only in what the sweep varies.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Setting {
    /// Per pixel (per sub-pixel with the Gaussian filter); a perfect square.
    pub samples: u32,
    pub filter: Filter,
    pub bounces: u32,
    pub precision: Precision,
}

impl Setting {
    /// The setting the case file itself asks for.
    pub fn of(case: &Case) -> Setting {
        Setting {
            samples: case.render.trace.samples,
            filter: case.render.trace.filter,
            bounces: case.render.trace.bounces,
            precision: case.render.precision,
        }
    }

    /// A short name without commas (it is a CSV field and a plot label): `16spp gaussian 2b f32`.
    pub fn label(&self) -> String {
        format!(
            "{}spp {} {}b {}",
            self.samples,
            self.filter.name(),
            self.bounces,
            self.precision.name()
        )
    }

    /// Camera rays per output pixel: the part of the cost known before rendering, which weighs
    /// the progress bar.
    pub fn camera_rays_per_pixel(&self) -> u64 {
        let subpixels = match self.filter {
            Filter::None => 1,
            Filter::Gaussian => 9,
        };
        u64::from(self.samples) * subpixels
    }

    /// The case with this setting in its `[render]` table.
    pub fn apply(&self, case: &Case) -> Case {
        let mut case = case.clone();
        case.render.trace.samples = self.samples;
        case.render.trace.filter = self.filter;
        case.render.trace.bounces = self.bounces;
        case.render.precision = self.precision;
        case
    }
}
