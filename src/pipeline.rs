//! The whole path from a case file to files on disk, as the `render` command runs it.

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use crate::assignment_outputs::AssignmentOutputs;
use crate::build_error::BuildError;
use crate::case::{
    self, AssignmentOptions, Case, LoadOptions, LoadedCase, case_to_toml, case_to_toml_anywhere, load_assignment_scene,
    load_assignment_scene_keeping_source,
};
use crate::error::Error;
use crate::film::{Film, OutputOptions, write_outputs};
use crate::options::{Profile, RenderOptions, Seeding, Spawn};
use crate::progress::{Progress, Silent};
use crate::provenance::{ContentHash, Provenance, ProvenanceError, keys};
use crate::stats::{BuildStats, Phases, RayCounts, RenderStats, this_host};
use crate::with_precision;

mod faults;
pub use faults::{FaultRenderer, case_with_faults, fault_applies, orthonormal_up, render_case_with_faults};

/// What a command wrote, and the statistics of the render behind it.
#[derive(Debug)]
pub struct Rendered {
    pub written: Vec<PathBuf>,
    pub stats: RenderStats,
}

/// Whether the run's own record (render time, thread count, host: [`Provenance::with_run`]) is
/// written into the outputs. Without it, the same case and binary give byte-identical files; the
/// record is in the statistics either way.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum RecordRun {
    #[default]
    Omitted,
    InOutputs,
}

/// Renders a loaded case to a film, in the precision it asks for.
pub fn render_case(case: &Case) -> Result<Film, Error> {
    render_case_reporting(case, &Silent)
}

/// [`render_case`], reporting the rows done to `progress`.
pub fn render_case_reporting(case: &Case, progress: &dyn Progress) -> Result<Film, Error> {
    with_precision!(case.render.precision, p => {
        let scene = p::scene::build_scene(case)?;
        let film = rendering(case, progress, |progress| p::render::render(&scene, &render_options(case), progress));
        match scene.render_failure() {
            Some(source) => Err(BuildError::CubeMap { file: case.path.clone(), source }.into()),
            None => Ok(film),
        }
    })
}

/// Brackets one render in `begin`/`finish`, counting its rows.
fn rendering<T>(case: &Case, progress: &dyn Progress, render: impl FnOnce(&dyn Progress) -> T) -> T {
    progress.begin(&case.name, u64::from(case.render.trace.height));
    let result = render(progress);
    progress.finish();
    result
}

/// [`render_case`], also counting rays and measuring the scene build (for `--stats`), with the
/// depth and normal AOVs only when `aovs`. The scene is freed before this returns, so measuring
/// adds no memory to what follows.
pub fn render_case_measured(case: &Case, progress: &dyn Progress, aovs: bool) -> Result<MeasuredRender, Error> {
    with_precision!(case.render.precision, p => {
        let start = Instant::now();
        let (scene, mut build_stats) = p::scene::build_scene_measured(case)?;
        let build_time = start.elapsed();
        let render_start = Instant::now();
        let options = RenderOptions { aovs, ..render_options(case) };
        let (film, rays) = rendering(case, progress, |progress| p::render::render_counting_rays(&scene, &options, progress));
        if let Some(source) = scene.render_failure() {
            return Err(BuildError::CubeMap { file: case.path.clone(), source }.into());
        }
        build_stats.cube_map_faces = scene.cube_map_faces();
        Ok(MeasuredRender { film, rays, build_stats, build_time, render_time: render_start.elapsed() })
    })
}

/// What [`render_case_measured`] returns.
#[derive(Debug)]
pub struct MeasuredRender {
    pub film: Film,
    pub rays: RayCounts,
    pub build_stats: BuildStats,
    pub build_time: Duration,
    pub render_time: Duration,
}

/// The renderer's options from a case's `[render]` table. A case's render always writes the
/// EXR, whose `Z` and `N` channels are the AOVs, so they are always traced.
pub fn render_options(case: &Case) -> RenderOptions {
    RenderOptions {
        trace: case.render.trace,
        spawn: match case.render.profile {
            Profile::Native => Spawn::ErrorBounds,
            Profile::Mit6837 => Spawn::Course,
        },
        seeding: Seeding::Seeded,
        aovs: true,
    }
}

/// The files a case's render writes, as its options ask.
pub fn output_options(case: &Case) -> OutputOptions {
    OutputOptions {
        tonemap: case.render.tonemap,
        depth_range: case.render.depth_range.map(|(min, max)| (min as f32, max as f32)),
        normals: case.render.normals,
    }
}

/// How a render of `case` is made, for its outputs to carry: this build, the case file's name,
/// the BLAKE3 hash of the case file and of every asset it reads ([`Case::assets`], in that
/// order, each framed by its length), and the render settings. This is the stable group only:
/// commands add the run's record when asked ([`RecordRun`]).
pub fn provenance(case: &Case) -> Result<Provenance, Error> {
    let path = &case.path;
    let source = std::fs::read(path).map_err(|source| ProvenanceError::Read {
        path: path.clone(),
        source,
    })?;
    provenance_of(case, &source)
}

/// [`provenance`] of a case whose file's bytes (`source`) were kept when it was loaded
/// ([`LoadedCase`]): the hash is of the text that was parsed, and the file is not read again.
pub fn provenance_of(case: &Case, source: &[u8]) -> Result<Provenance, Error> {
    let mut hash = ContentHash::default();
    hash.add(source);
    for path in case.assets() {
        let bytes = std::fs::read(&path).map_err(|source| ProvenanceError::Read { path, source })?;
        hash.add(&bytes);
    }
    let settings = &case.render;
    let trace = &settings.trace;
    let file_name = case.path.file_name().unwrap_or(case.path.as_os_str());
    Ok(Provenance::this_build()
        .with(keys::CASE, file_name.to_string_lossy())
        .with(keys::CASE_HASH, hash.finish())
        .with(keys::SIZE, format_args!("{}x{}", trace.width, trace.height))
        .with(keys::SAMPLES, trace.samples)
        .with(keys::SEED, trace.seed)
        .with(keys::FILTER, trace.filter.name())
        .with(keys::BOUNCES, trace.bounces)
        .with(keys::SHADOWS, trace.shadows)
        .with(keys::PRECISION, settings.precision.name())
        .with(keys::PROFILE, settings.profile.name())
        .with(keys::TONEMAP, settings.tonemap.name()))
}

/// Loads, renders and writes `DIR/NAME.exr` and its PNGs. Nothing is written unless every
/// stage succeeds, and existing outputs are replaced atomically.
pub fn render_case_file(
    path: &Path,
    out_dir: &Path,
    load: &LoadOptions,
    record: RecordRun,
    progress: &dyn Progress,
) -> Result<Rendered, Error> {
    measured_run(
        || Ok(case::load_keeping_source(path, load)?),
        progress,
        true,
        record,
        |case, film, provenance| {
            Ok(write_outputs(
                out_dir,
                &case.name,
                film,
                &output_options(case),
                provenance,
            )?)
        },
    )
}

/// `goldray mit6837`: renders a course scene file as the course binary would and writes the
/// files its flags name; the depth and normal AOVs are traced only when one of them is written.
pub fn render_assignment(
    scene: &Path,
    options: &AssignmentOptions,
    outputs: &AssignmentOutputs,
    record: RecordRun,
    progress: &dyn Progress,
) -> Result<Rendered, Error> {
    measured_run(
        || Ok(load_assignment_scene_keeping_source(scene, options)?),
        progress,
        outputs.writes_aovs(),
        record,
        |_, film, provenance| Ok(outputs.write(film, provenance)?),
    )
}

/// Load, build, render (with the AOVs when `aovs`) and write with the case's provenance (and the
/// run's record when `record` asks), timing each phase and counting rays. The commands always
/// measure: counting costs nothing measurable (`cargo bench -p goldray-bench -- stats_overhead`), so `--stats`
/// only decides whether the numbers are shown, and can never change what is rendered.
fn measured_run(
    load: impl FnOnce() -> Result<LoadedCase, Error>,
    progress: &dyn Progress,
    aovs: bool,
    record: RecordRun,
    write: impl FnOnce(&Case, &Film, &Provenance) -> Result<Vec<PathBuf>, Error>,
) -> Result<Rendered, Error> {
    let start = Instant::now();
    let LoadedCase { case, source } = load()?;
    let parse = start.elapsed();
    // Hashing the case and its assets (about 0.1 s for a 50 MB mesh) overlaps the scene build,
    // which reads the same files, rather than adding to it.
    let (provenance, measured) = std::thread::scope(|scope| {
        let hashing = scope.spawn(|| provenance_of(&case, &source));
        let measured = render_case_measured(&case, progress, aovs);
        let provenance = hashing.join().unwrap_or_else(|panic| std::panic::resume_unwind(panic));
        (provenance, measured)
    });
    let measured = measured?;
    let threads = rayon::current_num_threads();
    let provenance = match record {
        RecordRun::Omitted => provenance?,
        RecordRun::InOutputs => {
            provenance?.with_run(measured.render_time.as_secs_f64(), threads, this_host().as_deref())
        }
    };
    let write_start = Instant::now();
    let written = write(&case, &measured.film, &provenance)?;
    let phases = Phases {
        parse,
        build: measured.build_time,
        render: measured.render_time,
        write: write_start.elapsed(),
        total: start.elapsed(),
    };
    let stats = RenderStats::new(
        &case.name,
        (case.render.trace.width, case.render.trace.height),
        phases,
        measured.build_stats,
        &measured.rays,
        threads,
    );
    Ok(Rendered { written, stats })
}

/// `goldray import`: the TOML case equivalent to a course scene file, with asset paths
/// relative to where the TOML will live, or absolute when that is unknown (`None`: standard
/// output).
pub fn import_assignment(scene: &Path, options: &AssignmentOptions, toml_path: Option<&Path>) -> Result<String, Error> {
    let case = load_assignment_scene(scene, options)?;
    Ok(match toml_path {
        Some(path) => case_to_toml(&case, path),
        None => case_to_toml_anywhere(&case),
    })
}
