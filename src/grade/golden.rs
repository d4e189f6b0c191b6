//! Golden images: each distinct render of a rubric is rendered once per grading run, however many
//! students and images use it, and kept in an on-disk cache so that grading the next batch (or
//! regrading after a rubric tweak) does not render it again.
//!
//! A cache entry is the render's linear EXR, named by a hash of everything that decides its
//! pixels: the loaded case (its Debug text: camera, objects, materials, render settings, all
//! numbers in round-trip precision), the bytes of the assets it reads (OBJ meshes, cube-map
//! faces), goldray's version and the running executable itself. The last one matters during
//! development, when the renderer changes without a version bump; a stale golden would silently
//! grade every student against the wrong picture.

use std::collections::HashMap;
use std::fs;
use std::hash::{DefaultHasher, Hash, Hasher};
use std::path::{Path, PathBuf};
use std::sync::{Arc, OnceLock};
use std::time::Instant;

use crate::rgb_image::RgbImage;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::error::GradeError;
use super::rubric::{Output, Rubric};
use crate::atomic_write::write_file_atomic;
use crate::case::Case;
use crate::compare::Image;
use crate::compare::noise::png_allowance;
use crate::film::{Film, OutputError, decode_exr, encode_exr, encode_png, picture};
use crate::pipeline::{provenance, render_case_reporting};
use crate::progress::Progress;
use crate::provenance::Provenance;

/// Where the report keeps the golden PNGs, relative to the report directory.
pub const GOLDEN_DIR: &str = "golden";

/// How one render of the rubric was obtained, for the JSON report.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct GoldenRender {
    pub render: String,
    /// The cache key: the EXR is `CACHE/KEY.exr`.
    pub key: String,
    /// Read from the cache rather than rendered.
    pub cached: bool,
    /// Rendering (or reading) time.
    pub seconds: f64,
    /// Why the render could not be cached, if it could not; grading goes on without the cache.
    pub cache_note: Option<String>,
}

/// Whether a run may add to the golden cache. Shards of a class read a cache prepared once
/// (`goldray grade --prepare`), which may sit on a read-only shared folder: what they do not
/// find there they render for themselves and keep in memory only.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CacheMode {
    ReadWrite,
    ReadOnly,
}

/// The golden pictures in rubric order, as 8-bit images ready to compare.
pub struct Goldens {
    pub renders: Vec<GoldenRender>,
    /// Parallel to `Rubric::images`.
    pub images: Vec<Image>,
    /// The cache key of each image's render, parallel to `Rubric::images`: images with the same
    /// key come from the same pixels.
    pub keys: Vec<String>,
    /// Each image's golden film (shared by the images of one render), parallel to
    /// `Rubric::images`: diagnosis renders the mistakes' pictures beside it.
    pub films: Vec<Arc<Film>>,
    /// For an image judged with `statistical = true`, how far each colour value may stray for the
    /// golden's sampling noise, in codes (`compare::noise::png_allowance`); parallel to
    /// `Rubric::images`.
    pub allowances: Vec<Option<Arc<Vec<[f32; 3]>>>>,
    /// The provenance of each render an image uses, by render index (the stable group only, as
    /// the cache and the report's golden pictures are compared by content).
    pub provenances: HashMap<usize, Provenance>,
}

/// Where golden renders are cached unless the caller says otherwise: the user's cache folder
/// (`$XDG_CACHE_HOME/goldray/goldens`, usually `~/.cache/goldray/goldens`, on Linux;
/// `~/Library/Caches/goldray/goldens` on macOS), or the system's temporary folder when there is
/// none. Outside the report, so that zipping a report to send it does not drag the cache along;
/// shared by every report, which is safe because entries are named by a hash of their content.
pub fn default_cache_dir() -> PathBuf {
    dirs::cache_dir()
        .unwrap_or_else(std::env::temp_dir)
        .join("goldray")
        .join("goldens")
}

/// Renders (or loads from `cache_dir`) every render an image uses, storing what it rendered in the
/// cache unless `mode` is read-only. The renders are read (or rendered) side by side, and the
/// images' golden pictures made side by side: reading seven cached 800×800 films one after
/// another was a sixth of grading a 20-student class.
pub fn prepare_goldens(
    rubric: &Rubric,
    cache_dir: &Path,
    mode: CacheMode,
    progress: &dyn Progress,
) -> Result<Goldens, GradeError> {
    // The renders the images use, in the order the images first name them.
    let mut used: Vec<usize> = Vec::new();
    for spec in &rubric.images {
        if !used.contains(&spec.render_index) {
            used.push(spec.render_index);
        }
    }
    let keyed: Vec<(String, Provenance)> = first_error(used.par_iter().map(|&index| {
        let source = &rubric.renders[index];
        let provenance = provenance(&source.case).map_err(|error| GradeError::Golden {
            location: source.location.clone(),
            render: source.name.clone(),
            source: Box::new(error),
        })?;
        Ok((cache_key(&source.case), provenance))
    }))?;
    let mut keys: HashMap<usize, String> = HashMap::new();
    let mut provenances: HashMap<usize, Provenance> = HashMap::new();
    // Two differently named renders with the same content are one render.
    let mut distinct = Vec::new();
    for (&index, (key, provenance)) in used.iter().zip(keyed) {
        if !keys.values().any(|known| *known == key) {
            distinct.push(index);
        }
        keys.insert(index, key);
        provenances.insert(index, provenance);
    }
    let made: Vec<(GoldenRender, Film)> = first_error(distinct.par_iter().map(|&index| {
        let source = &rubric.renders[index];
        let started = Instant::now();
        let key = &keys[&index];
        let path = cache_dir.join(format!("{key}.exr"));
        let (film, cached, cache_note) = match read_cached(&path, &source.case) {
            Some(film) => (film, true, None),
            None => {
                progress.step(&format!("rendering golden {}", source.name));
                let film =
                    render_case_reporting(&source.case, progress).map_err(|source_error| GradeError::Golden {
                        location: source.location.clone(),
                        render: source.name.clone(),
                        source: Box::new(source_error),
                    })?;
                let note = match mode {
                    CacheMode::ReadWrite => store(&path, &film, &provenances[&index]).err(),
                    CacheMode::ReadOnly => Some("not stored: this run only reads the cache".to_owned()),
                };
                (film, false, note)
            }
        };
        let render = GoldenRender {
            render: source.name.clone(),
            key: key.clone(),
            cached,
            seconds: started.elapsed().as_secs_f64(),
            cache_note,
        };
        Ok((render, film))
    }))?;
    let mut renders = Vec::with_capacity(made.len());
    let mut films_by_key: HashMap<String, Arc<Film>> = HashMap::new();
    for (render, film) in made {
        films_by_key.insert(render.key.clone(), Arc::new(film));
        renders.push(render);
    }
    let films: HashMap<usize, Arc<Film>> = keys
        .iter()
        .map(|(&index, key)| (index, films_by_key[key].clone()))
        .collect();

    let (allowances, images): (Vec<_>, Vec<_>) = rubric
        .images
        .par_iter()
        .map(|spec| {
            let film = &films[&spec.render_index];
            let tonemap = rubric.renders[spec.render_index].case.render.tonemap;
            let statistical = spec.rule.statistical && spec.output == Output::Color;
            let allowance = statistical
                .then(|| png_allowance(film, tonemap).map(Arc::new))
                .flatten();
            let golden = picture(film, spec.output.picture(), tonemap);
            (
                allowance,
                Image::from_rgb8(golden, Path::new(GOLDEN_DIR).join(&spec.file)),
            )
        })
        .unzip();
    Ok(Goldens {
        renders,
        images,
        keys: rubric
            .images
            .iter()
            .map(|spec| keys[&spec.render_index].clone())
            .collect(),
        films: rubric
            .images
            .iter()
            .map(|spec| films[&spec.render_index].clone())
            .collect(),
        allowances,
        provenances,
    })
}

/// The results of `work` in order, or the first error in that order (whichever finished first),
/// so that a run with several failing renders names the same one every time.
fn first_error<T: Send>(
    work: impl IndexedParallelIterator<Item = Result<T, GradeError>>,
) -> Result<Vec<T>, GradeError> {
    let results: Vec<Result<T, GradeError>> = work.collect();
    results.into_iter().collect()
}

/// Writes each golden picture to `REPORT/golden/FILE`, for the HTML report.
/// Each carries the provenance of its render.
pub fn write_golden_pictures(rubric: &Rubric, goldens: &Goldens, report_dir: &Path) -> Result<(), OutputError> {
    let written: Vec<Result<(), OutputError>> = rubric
        .images
        .par_iter()
        .zip(&goldens.images)
        .map(|(spec, image)| {
            let provenance = &goldens.provenances[&spec.render_index];
            write_golden_png(
                &report_dir.join(GOLDEN_DIR).join(&spec.file),
                &image.preview,
                provenance,
            )
        })
        .collect();
    written.into_iter().collect()
}

/// The cached film, if there is a readable one of the right size, with the variance channels a
/// sampled render has (a rubric's `statistical = true` needs them). A damaged entry is treated as
/// absent and rendered again, which also repairs it.
fn read_cached(path: &Path, case: &Case) -> Option<Film> {
    let bytes = fs::read(path).ok()?;
    let film = decode_exr(&bytes).ok()?;
    let trace = &case.render.trace;
    let complete = film.variance.is_some() == (trace.samples > 1);
    (film.width == trace.width && film.height == trace.height && complete).then_some(film)
}

fn store(path: &Path, film: &Film, provenance: &Provenance) -> Result<(), String> {
    let file = path.display().to_string();
    let bytes = encode_exr(film).map_err(|e| e.to_string())?;
    let bytes = provenance.stamp(&bytes, &file).map_err(|e| e.to_string())?;
    write_file_atomic(path, &bytes).map_err(|e| e.to_string())
}

/// A golden picture of the report, with the provenance of its render.
fn write_golden_png(path: &Path, picture: &RgbImage, provenance: &Provenance) -> Result<(), OutputError> {
    let file = path.display().to_string();
    let bytes = provenance.stamp(&encode_png(picture)?, &file)?;
    Ok(write_file_atomic(path, &bytes)?)
}

/// 16 hex digits naming a render's pixels (see the module documentation). Assets that cannot be
/// read are hashed as absent: the render itself will then fail and say why.
pub fn cache_key(case: &Case) -> String {
    let mut hasher = DefaultHasher::new();
    env!("CARGO_PKG_VERSION").hash(&mut hasher);
    build_identity().hash(&mut hasher);
    format!("{case:?}").hash(&mut hasher);
    for asset in case.assets() {
        asset.hash(&mut hasher);
        fs::read(&asset).ok().hash(&mut hasher);
    }
    format!("{:016x}", hasher.finish())
}

/// A hash of the running executable, read once per process.
fn build_identity() -> u64 {
    static IDENTITY: OnceLock<u64> = OnceLock::new();
    *IDENTITY.get_or_init(|| {
        let mut hasher = DefaultHasher::new();
        std::env::current_exe().and_then(fs::read).ok().hash(&mut hasher);
        hasher.finish()
    })
}
