//! The pictures of one rubric render as faulty programs would draw them, rendered once per fault
//! set and kept beside the golden renders: `CACHE/faults/KEY/SET/PICTURE.png`, where `KEY` is the
//! golden's cache key (which already names the renderer build, so a stale entry cannot match),
//! `SET` the fault set as written (`no-shadows+gamma-applied=2.2`) and `PICTURE` `color`,
//! `normals` or `depth-MIN-MAX`. A set whose faults all act on the PNGs is quantised from the
//! golden film and never rendered nor stored.
//!
//! Most mistakes change one picture of a render and leave the others as the golden draws them
//! (of the 94 fault sets of course scene 7, 79 draw the golden normals), so each distinct picture
//! is stored once, as `KEY/by-content/HASH.png` (BLAKE3 of its size and codes), and every set's
//! file is a hard link to it: a picture is decoded once per run however many sets draw it (the
//! reader knows a link by its file's identity), where decoding was most of a warm diagnosis.
//! Where links cannot be made, each set keeps its own copy, as before.

use std::collections::HashMap;
use std::fs;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};

use super::super::golden::CacheMode;
use crate::atomic_write::{link_file, publish_file, write_file_atomic};
use crate::case::Case;
use crate::fault::FaultSet;
use crate::film::{Film, Picture, Tonemap, encode_png, picture_with_faults};
use crate::pipeline::FaultRenderer;
use crate::rgb_image::{RgbImage, decode_png};

/// How many rendered films are kept for pairing with PNG faults.
const KEPT_FILMS: usize = 6;

/// A picture's part of a cache file name.
pub fn picture_name(picture: Picture) -> String {
    match picture {
        Picture::Color => "color".to_owned(),
        Picture::Normals => "normals".to_owned(),
        Picture::Depth { min, max } => format!("depth-{min}-{max}"),
    }
}

/// A fault set's pictures, in the order of [`FaultPictures::pictures`]. A picture many sets draw
/// alike (most often the golden one) is one allocation shared by all of them: of course scene 7's
/// 94 fault sets, 79 draw the golden normals, and a copy each was 150 MB of pages to fault in.
pub type SetPictures = Arc<Vec<Arc<RgbImage>>>;

/// Every picture a rubric takes from one render, for any fault set.
pub struct FaultPictures<'a> {
    dir: Option<PathBuf>,
    /// Whether pictures rendered now are written to `dir`.
    mode: CacheMode,
    renderer: FaultRenderer,
    golden: &'a Film,
    tonemap: Tonemap,
    /// The pictures diagnosis compares (those of the images that lost points), in memory.
    pictures: Vec<Picture>,
    /// Every picture the rubric takes from the render (a superset), written to the cache when a
    /// set is rendered, so that a later grading finds whichever it needs.
    stored: Vec<Picture>,
    memo: Mutex<HashMap<String, SetPictures>>,
    /// Cache files decoded in this run, by file identity: one picture stored for many sets.
    decoded: Mutex<HashMap<FileIdentity, Arc<RgbImage>>>,
    /// The golden pictures, in the order of `pictures`: shared by every set that leaves one as
    /// the golden draws it.
    golden_pictures: Vec<Arc<RgbImage>>,
    /// The last films rendered, by render part, so that a render fault paired with PNG faults
    /// is quantised again rather than rendered again.
    films: Mutex<Vec<(String, Arc<Film>)>>,
    /// Fault sets rendered, and read from the cache, in this run.
    pub rendered: AtomicUsize,
    pub cached: AtomicUsize,
}

impl<'a> FaultPictures<'a> {
    /// `dir`: this render's cache folder, or `None` to cache nothing (`mode` says whether it may
    /// be written); `pictures` those compared, `stored` every picture of the render the rubric
    /// uses.
    pub fn new(
        dir: Option<PathBuf>,
        mode: CacheMode,
        case: &'a Case,
        golden: &'a Film,
        pictures: Vec<Picture>,
        stored: Vec<Picture>,
    ) -> Self {
        let golden_pictures = pictures
            .iter()
            .map(|p| Arc::new(picture_with_faults(golden, *p, case.render.tonemap, &FaultSet::NONE)))
            .collect();
        FaultPictures {
            dir,
            mode,
            renderer: FaultRenderer::new(case),
            golden,
            tonemap: case.render.tonemap,
            pictures,
            stored,
            memo: Mutex::new(HashMap::new()),
            decoded: Mutex::new(HashMap::new()),
            films: Mutex::new(Vec::new()),
            golden_pictures,
            rendered: AtomicUsize::new(0),
            cached: AtomicUsize::new(0),
        }
    }

    pub fn pictures(&self) -> &[Picture] {
        &self.pictures
    }

    /// The golden pictures, in the order of [`FaultPictures::pictures`].
    pub fn golden(&self) -> &[Arc<RgbImage>] {
        &self.golden_pictures
    }

    /// The film's pictures with `faults`; each one equal to the golden picture is the golden's.
    /// From the golden film, a picture none of the faults can change (`tests/faults.rs` holds
    /// the catalogue to that) is not made at all: a fitted gamma's depth and normals, say.
    fn quantise(&self, film: &Film, faults: &FaultSet) -> Vec<Arc<RgbImage>> {
        let golden_film = std::ptr::eq(film, self.golden);
        self.pictures
            .iter()
            .zip(&self.golden_pictures)
            .map(|(p, golden)| {
                if golden_film && !p.among(faults.pictures()) {
                    golden.clone()
                } else {
                    shared(picture_with_faults(film, *p, self.tonemap, faults), golden)
                }
            })
            .collect()
    }

    /// Every picture of the render quantised and written to the cache (best effort: a cache that
    /// cannot be written costs a render next time, nothing more).
    fn store_all(&self, label: &str, film: &Film, faults: &FaultSet) {
        if self.mode == CacheMode::ReadOnly {
            return;
        }
        let Some(dir) = &self.dir else {
            return;
        };
        for picture in &self.stored {
            let image = picture_with_faults(film, *picture, self.tonemap, faults);
            let (path, content) = (entry_in(dir, label, *picture), content_entry(dir, &image));
            // Encoded at most once: for the stored content, or for a copy where links fail.
            let mut png = None;
            let stored = content.exists() || {
                png = encode_png(&image).ok();
                png.as_ref().is_some_and(|bytes| publish_file(&content, bytes).is_ok())
            };
            if !(stored && link_file(&content, &path).is_ok()) {
                if png.is_none() {
                    png = encode_png(&image).ok();
                }
                if let Some(bytes) = &png {
                    let _ = write_file_atomic(&path, bytes);
                }
            }
        }
    }

    /// The pictures a program with `faults` writes, in the order of [`FaultPictures::pictures`]:
    /// from this run's memory, the cache, the golden film (PNG faults only) or a render.
    pub fn get(&self, faults: &FaultSet) -> Result<SetPictures, crate::Error> {
        let label = faults.to_string();
        if let Some(found) = self.lock().get(&label) {
            return Ok(found.clone());
        }
        let pictures = Arc::new(if faults.render_part().is_empty() {
            self.quantise(self.golden, faults)
        } else if let Some(cached) = self.read_cache(&label) {
            self.cached.fetch_add(1, Ordering::Relaxed);
            cached
        } else {
            let film = self.film(&faults.render_part())?;
            self.store_all(&label, &film, faults);
            self.quantise(&film, faults)
        });
        self.lock().insert(label, pictures.clone());
        Ok(pictures)
    }

    /// The film of a render part, from the last few rendered or rendered now.
    fn film(&self, render_part: &FaultSet) -> Result<Arc<Film>, crate::Error> {
        let label = render_part.to_string();
        let mut films = self.films.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
        if let Some((_, film)) = films.iter().find(|(l, _)| *l == label) {
            return Ok(film.clone());
        }
        drop(films);
        let film = Arc::new(self.renderer.render(render_part)?);
        self.rendered.fetch_add(1, Ordering::Relaxed);
        films = self.films.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
        if films.len() >= KEPT_FILMS {
            films.remove(0);
        }
        films.push((label, film.clone()));
        Ok(film)
    }

    /// The pictures of `faults` when some run already made them, without rendering.
    pub fn get_if_known(&self, faults: &FaultSet) -> Option<SetPictures> {
        self.lock().get(&faults.to_string()).cloned()
    }

    /// The golden film: PNG faults (a fitted gamma) are quantised from it directly.
    pub fn golden_film(&self) -> &Film {
        self.golden
    }

    pub fn tonemap(&self) -> Tonemap {
        self.tonemap
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, HashMap<String, SetPictures>> {
        self.memo.lock().unwrap_or_else(|poisoned| poisoned.into_inner())
    }

    fn entry(&self, label: &str, picture: Picture) -> Option<PathBuf> {
        Some(entry_in(self.dir.as_ref()?, label, picture))
    }

    /// Every picture of the set, or nothing: a partial or damaged entry is rendered again. A file
    /// that this run already decoded under another set's name (a link to the same content) is
    /// not decoded again.
    fn read_cache(&self, label: &str) -> Option<Vec<Arc<RgbImage>>> {
        let (width, height) = (self.golden.width, self.golden.height);
        self.pictures
            .iter()
            .zip(&self.golden_pictures)
            .map(|(p, golden)| {
                let path = self.entry(label, *p)?;
                let identity = file_identity(&path)?;
                if let Some(known) = self.decoded_files().get(&identity) {
                    return Some(known.clone());
                }
                let bytes = fs::read(&path).ok()?;
                let picture = decode_png(&bytes, 3 * u64::from(width) * u64::from(height)).ok()?.image;
                if picture.dimensions() != (width, height) {
                    return None;
                }
                let picture = shared(picture, golden);
                self.decoded_files().insert(identity, picture.clone());
                Some(picture)
            })
            .collect()
    }

    fn decoded_files(&self) -> std::sync::MutexGuard<'_, HashMap<FileIdentity, Arc<RgbImage>>> {
        self.decoded.lock().unwrap_or_else(|poisoned| poisoned.into_inner())
    }
}

/// `picture`, or `golden` when they are the same picture.
fn shared(picture: RgbImage, golden: &Arc<RgbImage>) -> Arc<RgbImage> {
    if picture == **golden {
        golden.clone()
    } else {
        Arc::new(picture)
    }
}

/// The folder of a render's cache that holds each distinct picture once.
const CONTENT_DIR: &str = "by-content";

/// A set's picture in the render's cache folder `dir`.
fn entry_in(dir: &Path, label: &str, picture: Picture) -> PathBuf {
    dir.join(label).join(format!("{}.png", picture_name(picture)))
}

/// Where a picture's content is stored once for every set that draws it.
fn content_entry(dir: &Path, image: &RgbImage) -> PathBuf {
    let mut hasher = blake3::Hasher::new();
    hasher.update(&image.width().to_le_bytes());
    hasher.update(&image.height().to_le_bytes());
    hasher.update(image.as_raw());
    dir.join(CONTENT_DIR)
        .join(format!("{}.png", &hasher.finalize().to_hex()[..32]))
}

/// What tells one file from another whatever its names: device and inode on Unix (hard links
/// share them); elsewhere the path, so that only a file's own name finds it again.
#[cfg(unix)]
type FileIdentity = (u64, u64);
#[cfg(not(unix))]
type FileIdentity = PathBuf;

#[cfg(unix)]
fn file_identity(path: &Path) -> Option<FileIdentity> {
    use std::os::unix::fs::MetadataExt;
    let meta = fs::metadata(path).ok()?;
    Some((meta.dev(), meta.ino()))
}

#[cfg(not(unix))]
fn file_identity(path: &Path) -> Option<FileIdentity> {
    fs::metadata(path).ok().map(|_| path.to_path_buf())
}
