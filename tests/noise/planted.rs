//! The planted bugs of the statistical verdict's calibration (issue 17), shared by
//! `tests/noise.rs` and `examples/calibrate_noise.rs`: each one a small change to a sampled case,
//! made in memory, that a golden comparison must catch whatever the seed.

use goldray::case::Case;
use goldray::compare::{Comparison, Image, compare};
use goldray::film::Film;
use goldray::options::{Profile, Seeding};
use goldray::pipeline::render_options;
use goldray::progress::Silent;
use goldray::with_precision;

/// One planted bug.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Bug {
    /// The diffuse colour of material `index` is 2% brighter.
    Diffuse(usize),
    /// Every reflecting material's specular colour (its mirror reflectance) is 3% brighter.
    Mirror,
    /// The case's last light is left out.
    DroppedLight,
    /// The camera looks one pixel to the right.
    CameraShift,
    /// The sampler is seeded from the pixel index alone (`options::Seeding::PixelIndex`).
    PixelSeeded,
}

impl Bug {
    /// Every bug that can act on `case`: one diffuse change per material, then the others.
    pub fn all(case: &Case) -> Vec<Bug> {
        let mut bugs: Vec<Bug> = (0..case.materials.len()).map(Bug::Diffuse).collect();
        bugs.extend([Bug::Mirror, Bug::DroppedLight, Bug::CameraShift, Bug::PixelSeeded]);
        bugs.into_iter().filter(|bug| bug.apply(case).is_some()).collect()
    }

    pub fn name(self, case: &Case) -> String {
        match self {
            Bug::Diffuse(i) => format!("diffuse +2% ({})", case.materials[i].name),
            Bug::Mirror => "mirror reflectance +3%".to_owned(),
            Bug::DroppedLight => "a dropped light".to_owned(),
            Bug::CameraShift => "camera shifted one pixel".to_owned(),
            Bug::PixelSeeded => "sampler seeded from the pixel index".to_owned(),
        }
    }

    /// The case as the buggy program renders it, and its sampler's seeding; `None` when the case
    /// has nothing the bug acts on (no mirror, no light, one sample per pixel).
    pub fn apply(self, case: &Case) -> Option<(Case, Seeding)> {
        let mut buggy = case.clone();
        let mut seeding = Seeding::Seeded;
        match self {
            Bug::Diffuse(i) => {
                let diffuse = &mut buggy.materials.get_mut(i)?.diffuse;
                *diffuse = diffuse.map(|c| c * 1.02);
            }
            Bug::Mirror => {
                let mirrors = buggy.materials.iter_mut().filter(|m| m.specular != [0.0; 3]);
                let mut any = false;
                for material in mirrors {
                    material.specular = material.specular.map(|c| c * 1.03);
                    any = true;
                }
                if !any || case.render.trace.bounces == 0 {
                    return None;
                }
            }
            Bug::DroppedLight => {
                buggy.lights.pop()?;
            }
            Bug::CameraShift => {
                if case.render.profile != Profile::Native {
                    return None;
                }
                // One pixel on the image plane at unit distance: 2·tan(fov/2)/height.
                let camera = &mut buggy.camera;
                let d = normalize(camera.direction);
                let right = normalize(cross(d, camera.up));
                let step = 2.0 * (camera.fov.to_radians() / 2.0).tan() / f64::from(case.render.trace.height);
                camera.direction = [0, 1, 2].map(|k| d[k] + right[k] * step);
            }
            Bug::PixelSeeded => {
                if case.render.trace.samples <= 1 {
                    return None;
                }
                seeding = Seeding::PixelIndex;
            }
        }
        Some((buggy, seeding))
    }
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn normalize(v: [f64; 3]) -> [f64; 3] {
    let length = v.iter().map(|c| c * c).sum::<f64>().sqrt();
    v.map(|c| c / length)
}

/// `case` with another seed.
pub fn reseeded(case: &Case, seed: u64) -> Case {
    let mut case = case.clone();
    case.render.trace.seed = seed;
    case
}

/// `case` at another size (the same picture, fewer pixels).
pub fn resized(case: &Case, width: u32, height: u32) -> Case {
    let mut case = case.clone();
    case.render.trace.width = width;
    case.render.trace.height = height;
    case
}

/// Renders `case` with the sampler's random numbers drawn as `seeding` says.
pub fn render(case: &Case, seeding: Seeding) -> Film {
    let options = goldray::options::RenderOptions {
        seeding,
        ..render_options(case)
    };
    with_precision!(case.render.precision, p => {
        let scene = p::scene::build_scene(case).unwrap_or_else(|e| panic!("{}: {e}", case.name));
        p::render::render(&scene, &options, &Silent)
    })
}

/// `film` judged against `golden` under the case's tolerance, as the golden suite judges.
pub fn judge(case: &Case, golden: &Image, film: &Film, label: &str) -> Comparison {
    compare(golden, &Image::from_film(film, label), &case.tolerance)
}
