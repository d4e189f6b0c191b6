//! Writing a render's files all-or-nothing, so that an interrupted or failed render never leaves a
//! new EXR beside an old PNG, and a golden-suite reader never sees half a file.

use std::path::{Path, PathBuf};

use crate::rgb_image::RgbImage;
use rayon::prelude::*;

use super::error::OutputError;
use super::exr::encode_exr_named;
use super::png::{color_image, depth_image, encode_png_named, normals_image};
use super::{Film, Tonemap};
use crate::atomic_write::write_files_atomic;
use crate::provenance::Provenance;

/// Which previews accompany the EXR; the EXR itself is always written because it is what golden
/// comparisons read.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OutputOptions {
    pub tonemap: Tonemap,
    pub depth_range: Option<(f32, f32)>,
    pub normals: bool,
}

/// Writes `NAME.exr`, `NAME.png` and the requested `NAME_depth.png` / `NAME_normals.png` into
/// `dir` (created if missing) and returns their paths in that order. Each file carries
/// `provenance` (EXR header attributes, PNG text chunks).
///
/// Everything is encoded before anything touches the disk, so a film the EXR refuses writes
/// nothing. Files are then staged in a hidden directory inside `dir` and renamed into place one by
/// one; if a rename fails, the ones already made are undone, so existing outputs are either all
/// replaced or all left byte-identical.
pub fn write_outputs(
    dir: &Path,
    name: &str,
    film: &Film,
    options: &OutputOptions,
    provenance: &Provenance,
) -> Result<Vec<PathBuf>, OutputError> {
    if name.is_empty() || Path::new(name).file_name() != Some(name.as_ref()) {
        return Err(OutputError::InvalidName { name: name.to_owned() });
    }
    let path = |suffix: &str| dir.join(format!("{name}{suffix}"));
    let png = |path: PathBuf, image: &dyn Fn() -> RgbImage| -> Result<(PathBuf, Vec<u8>), OutputError> {
        let file = path.display().to_string();
        let bytes = provenance.stamp(&encode_png_named(&image(), &file)?, &file)?;
        Ok((path, bytes))
    };

    // Encoded in parallel (the EXR on one thread, so its bytes stay a function of the film).
    let tonemap = options.tonemap;
    let previews = || -> Result<Vec<(PathBuf, Vec<u8>)>, OutputError> {
        let mut jobs: Vec<(PathBuf, Box<dyn Fn() -> RgbImage + Send + Sync>)> =
            vec![(path(".png"), Box::new(move || color_image(film, tonemap)))];
        if let Some((min, max)) = options.depth_range {
            jobs.push((
                path("_depth.png"),
                Box::new(move || depth_image(film, min, max, tonemap)),
            ));
        }
        if options.normals {
            jobs.push((path("_normals.png"), Box::new(move || normals_image(film, tonemap))));
        }
        jobs.into_par_iter().map(|(path, image)| png(path, &*image)).collect()
    };
    let exr_path = path(".exr");
    let exr = || -> Result<Vec<u8>, OutputError> {
        let file = exr_path.display().to_string();
        Ok(provenance.stamp(&encode_exr_named(film, &file)?, &file)?)
    };
    let (exr, previews) = rayon::join(exr, previews);
    let mut files = vec![(exr_path.clone(), exr?)];
    files.extend(previews?);

    let pending: Vec<(&Path, &[u8])> = files.iter().map(|(p, b)| (p.as_path(), &b[..])).collect();
    write_files_atomic(dir, &pending)?;
    Ok(files.into_iter().map(|(path, _)| path).collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn messages_name_the_file_and_the_problem() {
        let error = OutputError::MissingChannel {
            file: "a.exr".into(),
            channel: "R",
        };
        assert_eq!(error.to_string(), "a.exr has no R channel");
    }

    #[test]
    fn names_with_directories_are_refused() {
        let options = OutputOptions {
            tonemap: Tonemap::Srgb,
            depth_range: None,
            normals: false,
        };
        for name in ["", "..", "a/b", "/abs"] {
            let result = write_outputs(
                Path::new("unused"),
                name,
                &Film::new(1, 1),
                &options,
                &Provenance::default(),
            );
            assert!(matches!(result, Err(OutputError::InvalidName { .. })), "{name:?}");
        }
        assert!(!Path::new("unused").exists());
    }
}
