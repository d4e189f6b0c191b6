//! `goldray grade`: a class's renders against a rubric; one slice of it (`--shard`), the shards'
//! outputs combined (`--merge`), or the golden cache filled once for the shards (`--prepare`).

use std::path::PathBuf;
use std::process::ExitCode;

use goldray::grade::{
    Diagnose, GradeOptions, Shard, default_cache_dir, grade_class_diagnosing, merge_shards, prepare_cache, summary,
    time_spent,
};

use super::Failure;
use super::common::ThreadFlags;
use super::progress::Reporter;

#[derive(Clone, Debug, clap::Args)]
pub struct GradeArgs {
    /// The rubric (TOML): expected files, their golden renders, limits and points.
    #[arg(long, required_unless_present = "merge")]
    rubric: Option<PathBuf>,
    /// A folder holding one folder per student, or a Canvas or Moodle download (its .zip, or the
    /// folder it was extracted to); with --merge, the shards' report folders.
    #[arg(value_name = "SUBMISSIONS")]
    inputs: Vec<PathBuf>,
    /// Folder to write grades.csv, grades.json and index.html (with the pictures) into.
    #[arg(long, default_value = "grade-report")]
    out: PathBuf,
    #[command(flatten)]
    threads: ThreadFlags,
    /// Golden image cache [default: the user cache folder's goldray/goldens, e.g.
    /// ~/.cache/goldray/goldens]. Entries are named by content, so one cache serves every report.
    #[arg(long)]
    cache: Option<PathBuf>,
    /// No progress and no summary.
    #[arg(long)]
    quiet: bool,
    /// Do not name the mistake behind each image that lost points (faster: no fault renders).
    #[arg(long)]
    no_diagnose: bool,
    /// Grade every student again, even those an earlier run into the same --out already graded
    /// and whose files have not changed.
    #[arg(long)]
    force: bool,
    /// Grade only the K-th of N slices of the class (by sorted folder name) into --out, for
    /// --merge to combine; the cache is only read (fill it first with --prepare).
    #[arg(long, value_name = "K/N", conflicts_with_all = ["prepare", "merge"])]
    shard: Option<Shard>,
    /// Render the rubric's golden images (and, unless --no-diagnose, the mistakes' pictures) into
    /// the cache, and grade nothing.
    #[arg(long, conflicts_with_all = ["merge", "force"])]
    prepare: bool,
    /// Combine the shards' report folders (given after it) into OUT: grades.csv, grades.json and
    /// index.html as one run over the whole class writes them.
    #[arg(long, value_name = "OUT", conflicts_with_all = ["rubric", "cache", "no_diagnose", "force"])]
    merge: Option<PathBuf>,
}

pub fn run(args: GradeArgs) -> Result<ExitCode, Failure> {
    let reporter = Reporter::new(args.quiet);
    let diagnose = if args.no_diagnose { Diagnose::No } else { Diagnose::Yes };
    if let Some(out) = &args.merge {
        if args.inputs.is_empty() {
            return Err(Failure::Usage(
                "--merge OUT needs the shards' report folders after it: goldray grade --merge OUT SHARD_DIR..."
                    .to_owned(),
            ));
        }
        goldray::atomic_write::check_writable_folder(out)?;
        let report = args.threads.install(|| merge_shards(out, &args.inputs))??;
        if !args.quiet {
            println!("{}", summary(&report, out));
        }
        return Ok(ExitCode::SUCCESS);
    }
    let Some(rubric) = &args.rubric else {
        return Err(Failure::Usage("--rubric is required".to_owned()));
    };
    if args.prepare {
        if let Some(extra) = args.inputs.first() {
            return Err(Failure::Usage(format!(
                "--prepare grades nothing: remove {} (it only needs --rubric and --cache)",
                extra.display()
            )));
        }
        let cache = args.cache.clone().unwrap_or_else(default_cache_dir);
        let prepared = args
            .threads
            .install(|| prepare_cache(rubric, &cache, diagnose, &reporter))??;
        if !args.quiet {
            let rendered = prepared.goldens.iter().filter(|g| !g.cached).count();
            println!(
                "{} golden renders ({rendered} rendered, {} already cached), {} mistake renders; cache: {}",
                prepared.goldens.len(),
                prepared.goldens.len() - rendered,
                prepared.mistakes_rendered,
                cache.display()
            );
        }
        return Ok(ExitCode::SUCCESS);
    }
    let submissions = match args.inputs.as_slice() {
        [one] => one,
        [] => return Err(Failure::Usage("the submissions folder is missing".to_owned())),
        [_, extra, ..] => {
            return Err(Failure::Usage(format!(
                "one submissions folder only ({} is one too many; several folders are for --merge)",
                extra.display()
            )));
        }
    };
    goldray::atomic_write::check_writable_folder(&args.out)?;
    let shard = args.shard.unwrap_or(Shard::WHOLE);
    let options = GradeOptions {
        out: args.out.clone(),
        cache: args.cache.clone(),
        shard,
        force: args.force,
    };
    let report = args
        .threads
        .install(|| grade_class_diagnosing(rubric, submissions, &options, diagnose, &reporter))??;
    if !args.quiet {
        if shard == Shard::WHOLE {
            println!("{}", summary(&report, &args.out));
        } else {
            println!(
                "graded slice {shard} of the class: {} students\n{}\nshard output: {} (combine the slices with goldray grade --merge OUT SHARD_DIR...)",
                report.students.len(),
                time_spent(&report.cost),
                args.out.display()
            );
        }
    }
    Ok(ExitCode::SUCCESS)
}
