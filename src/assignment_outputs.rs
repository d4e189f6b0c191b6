//! The course binary's outputs: a colour PNG at an exact path, and optional normals and depth
//! PNGs at their own paths, plus goldray's linear EXR when asked.

use std::path::{Path, PathBuf};

use rayon::prelude::*;

use crate::atomic_write::{parent_folder, write_files_atomic};
use crate::film::{Film, OutputError, Tonemap, color_image, depth_image, encode_exr, encode_png, normals_image};
use crate::provenance::Provenance;

/// Encodes one output file.
type Encode<'a> = Box<dyn Fn() -> Result<Vec<u8>, OutputError> + Sync + 'a>;

/// Files to write into one folder: each target and its bytes.
type FolderFiles<'a> = Vec<(&'a Path, &'a [u8])>;

/// Where `goldray mit6837` writes, mirroring the course binary's `-output`, `-normals` and
/// `-depth min max file` flags.
#[derive(Clone, Debug, Default)]
pub struct AssignmentOutputs {
    pub color: Option<PathBuf>,
    pub normals: Option<PathBuf>,
    pub depth: Option<(f32, f32, PathBuf)>,
    pub exr: Option<PathBuf>,
}

impl AssignmentOutputs {
    /// Whether any file written needs the depth and normal AOVs: the normals and depth PNGs and
    /// the EXR do, the colour PNG does not.
    pub fn writes_aovs(&self) -> bool {
        self.normals.is_some() || self.depth.is_some() || self.exr.is_some()
    }

    /// Encodes every file before writing any, so a film that cannot be encoded writes nothing;
    /// the files are then replaced atomically, those of one folder all or nothing. The files are encoded in parallel, and each
    /// carries `provenance`: the course binary's PNGs carry no text chunks, but nothing that
    /// compares against them reads more than their pixels.
    pub fn write(&self, film: &Film, provenance: &Provenance) -> Result<Vec<PathBuf>, OutputError> {
        let tonemap = Tonemap::Clamp;
        let mut jobs: Vec<(&Path, Encode)> = Vec::new();
        if let Some(path) = &self.color {
            jobs.push((path, Box::new(move || encode_png(&color_image(film, tonemap)))));
        }
        if let Some(path) = &self.normals {
            jobs.push((path, Box::new(move || encode_png(&normals_image(film, tonemap)))));
        }
        if let Some((min, max, path)) = &self.depth {
            jobs.push((
                path,
                Box::new(move || encode_png(&depth_image(film, *min, *max, tonemap))),
            ));
        }
        if let Some(path) = &self.exr {
            jobs.push((path, Box::new(move || encode_exr(film))));
        }
        let files = jobs
            .par_iter()
            .map(|(path, encode)| {
                let file = path.display().to_string();
                Ok((*path, provenance.stamp(&encode()?, &file)?))
            })
            .collect::<Result<Vec<(&Path, Vec<u8>)>, OutputError>>()?;
        // The files of one folder (usually all of them) replace their targets all or nothing,
        // staged and synced side by side (`write_files_atomic`).
        let mut folders: Vec<(&Path, FolderFiles)> = Vec::new();
        for (path, bytes) in &files {
            let folder = parent_folder(path);
            match folders.iter_mut().find(|(known, _)| *known == folder) {
                Some((_, group)) => group.push((path, bytes)),
                None => folders.push((folder, vec![(path, bytes)])),
            }
        }
        for (folder, group) in &folders {
            write_files_atomic(folder, group)?;
        }
        Ok(files.into_iter().map(|(path, _)| path.to_path_buf()).collect())
    }
}
