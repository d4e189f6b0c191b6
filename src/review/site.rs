//! The review page with everything it loads, as named files: what the server answers with and
//! what `--static DIR` and `goldray diff --html` write. One builder for all three, so that the
//! page a CI artifact shows is the page the server shows, less its buttons.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use super::case_review::CaseReview;
use super::error::ReviewError;
use super::page::{CaseParts, Heading, Resources, page};
use super::payload::{base64, case_script};
use crate::atomic_write::write_files_atomic;

/// The page's files by their path relative to the page (`index.html`, `img/NAME.heatmap.png`,
/// `data/NAME.js`).
#[derive(Debug, Default)]
pub struct Site {
    files: BTreeMap<String, Vec<u8>>,
}

pub const INDEX: &str = "index.html";

impl Site {
    /// Draws every case's pictures and values and the page that shows them.
    pub fn build(heading: &Heading, reviews: &[CaseReview], resources: Resources) -> Result<Site, ReviewError> {
        let mut files = BTreeMap::new();
        let mut parts = Vec::with_capacity(reviews.len());
        for review in reviews {
            let pictures = review.pictures()?;
            let id = &review.id;
            let mut source = |kind: &str, png: Option<Vec<u8>>| {
                png.map(|png| match resources {
                    Resources::Embedded => format!("data:image/png;base64,{}", base64(&png)),
                    Resources::Linked => {
                        let path = format!("img/{id}.{kind}.png");
                        files.insert(path.clone(), png);
                        path
                    }
                })
            };
            let sources = [
                source("expected", pictures.expected),
                source("actual", Some(pictures.actual)),
                source("heatmap", pictures.heatmap),
            ];
            let script = case_script(review);
            let data = match resources {
                Resources::Embedded => script,
                Resources::Linked => {
                    let path = format!("data/{id}.js");
                    files.insert(path.clone(), script.into_bytes());
                    path
                }
            };
            parts.push(CaseParts { review, sources, data });
        }
        files.insert(INDEX.to_owned(), page(heading, &parts, resources).into_bytes());
        Ok(Site { files })
    }

    /// A file of the page and its media type; `None` for any other path.
    pub fn get(&self, path: &str) -> Option<(&[u8], &'static str)> {
        let bytes = self.files.get(path)?;
        let kind = match path.rsplit('.').next() {
            Some("html") => "text/html; charset=utf-8",
            Some("png") => "image/png",
            Some("js") => "text/javascript; charset=utf-8",
            _ => "application/octet-stream",
        };
        Some((bytes, kind))
    }

    /// Drops a decided case's files, so that the server no longer offers them.
    pub fn forget(&mut self, id: &str) {
        self.files
            .retain(|path, _| !(path.starts_with(&format!("img/{id}.")) || *path == format!("data/{id}.js")));
    }

    pub fn index(&self) -> &[u8] {
        self.files.get(INDEX).map_or(&[], Vec::as_slice)
    }

    /// Writes every file under `dir` (created if missing), all or nothing; returns the page's path.
    pub fn write(&self, dir: &Path) -> Result<PathBuf, ReviewError> {
        let paths: Vec<(PathBuf, &[u8])> = self
            .files
            .iter()
            .map(|(path, bytes)| (dir.join(path), bytes.as_slice()))
            .collect();
        for (path, _) in &paths {
            if let Some(parent) = path.parent() {
                std::fs::create_dir_all(parent).map_err(|source| crate::atomic_write::AtomicWriteError::Write {
                    path: parent.to_path_buf(),
                    source,
                })?;
            }
        }
        let files: Vec<(&Path, &[u8])> = paths.iter().map(|(p, b)| (p.as_path(), *b)).collect();
        write_files_atomic(dir, &files)?;
        Ok(dir.join(INDEX))
    }
}
