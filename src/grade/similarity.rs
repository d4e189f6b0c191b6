//! Students who handed in the same picture: pairs with pixel-identical images, or near-identical
//! failing ones, found without comparing every pair of a class.
//!
//! Every submitted picture gets a [`Fingerprint`] while it is graded: a hash of all its pixels,
//! and for a picture that lost points, hashes of a few fixed random samples of its pixels. Pixel-
//! identical pictures share the first; two pictures that agree on more than 99.99% of their
//! pixels agree on a 512-pixel sample with probability above 95%, so they almost surely share one
//! of [`BANDS`] sample hashes, while pictures that differ on a percent of their pixels share one
//! with a probability of about 10⁻². Only pictures that share a hash are compared in full. Pictures
//! identical to the golden image or to the published reference are left out: matching the answer
//! is not copying a classmate.

use std::collections::{BTreeMap, BTreeSet, HashMap};
use std::path::Path;

use crate::rgb_image::RgbImage;
use serde::{Deserialize, Serialize};

use super::integrity::pixel_hash;
use super::submission::read_png;

/// Independent pixel samples per failing picture.
const BANDS: usize = 8;
/// Pixels per sample.
const SAMPLE: u64 = 512;
/// Near-identical: more than this fraction of pixels equal.
pub const NEAR_IDENTICAL: f64 = 0.9999;

/// What pairing needs to know of one submitted picture.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Fingerprint {
    pub pixels: u64,
    /// Sample hashes, for pictures that lost points (the near-identical test is for those only).
    pub samples: Option<[u64; BANDS]>,
}

impl Fingerprint {
    pub fn of(picture: &RgbImage, lost_points: bool) -> Fingerprint {
        Fingerprint {
            pixels: pixel_hash(picture),
            samples: lost_points.then(|| sample_hashes(picture)),
        }
    }
}

/// Hashes of [`BANDS`] fixed pseudo-random samples of the picture's pixels; the positions depend
/// only on the picture's size, so two pictures of one size are sampled at the same places.
fn sample_hashes(picture: &RgbImage) -> [u64; BANDS] {
    let pixels = u64::from(picture.width()) * u64::from(picture.height());
    let raw = picture.as_raw();
    std::array::from_fn(|band| {
        let mut hash = 0xcbf2_9ce4_8422_2325_u64 ^ pixels;
        for i in 0..SAMPLE {
            let index = (mix((band as u64) << 32 | i) % pixels.max(1)) as usize * 3;
            for &byte in raw.get(index..index + 3).unwrap_or(&[]) {
                hash = (hash ^ u64::from(byte)).wrapping_mul(0x0000_0100_0000_01b3);
            }
        }
        hash
    })
}

/// SplitMix64's finaliser: a stateless, well-spread hash of a counter.
fn mix(mut x: u64) -> u64 {
    x = x.wrapping_add(0x9e37_79b9_7f4a_7c15);
    x = (x ^ (x >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    x = (x ^ (x >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    x ^ (x >> 31)
}

/// One picture as pairing sees it.
pub struct Entry<'a> {
    pub student: &'a str,
    /// The expected file, and its place in the rubric (files are listed in rubric order).
    pub file: &'a str,
    pub order: usize,
    pub path: &'a Path,
    pub fingerprint: &'a Fingerprint,
}

/// Two students and the files on which they handed in the same (or nearly the same) picture.
#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord, Serialize)]
pub struct SimilarPair {
    pub students: [String; 2],
    pub files: Vec<String>,
}

/// Every pair of students with a pixel-identical picture, or a near-identical picture that lost
/// points, on the same expected file; sorted by the students' names.
pub fn similar_pairs(entries: &[Entry]) -> Vec<SimilarPair> {
    let mut shared: BTreeMap<(String, String), BTreeSet<(usize, String)>> = BTreeMap::new();
    let mut record = |a: &Entry, b: &Entry| {
        let key = if a.student <= b.student {
            (a.student.to_owned(), b.student.to_owned())
        } else {
            (b.student.to_owned(), a.student.to_owned())
        };
        if key.0 != key.1 {
            shared.entry(key).or_default().insert((a.order, a.file.to_owned()));
        }
    };
    let mut by_file: HashMap<&str, Vec<&Entry>> = HashMap::new();
    for entry in entries {
        by_file.entry(entry.file).or_default().push(entry);
    }
    for pictures in by_file.values() {
        let mut exact: HashMap<u64, Vec<usize>> = HashMap::new();
        let mut bands: HashMap<(usize, u64), Vec<usize>> = HashMap::new();
        for (i, entry) in pictures.iter().enumerate() {
            exact.entry(entry.fingerprint.pixels).or_default().push(i);
            for (band, hash) in entry.fingerprint.samples.iter().flatten().enumerate() {
                bands.entry((band, *hash)).or_default().push(i);
            }
        }
        let mut identical: BTreeSet<(usize, usize)> = BTreeSet::new();
        for group in exact.values() {
            for (n, &a) in group.iter().enumerate() {
                for &b in &group[n + 1..] {
                    identical.insert((a, b));
                    record(pictures[a], pictures[b]);
                }
            }
        }
        let mut candidates: BTreeSet<(usize, usize)> = BTreeSet::new();
        for group in bands.values() {
            for (n, &a) in group.iter().enumerate() {
                for &b in &group[n + 1..] {
                    if !identical.contains(&(a, b)) {
                        candidates.insert((a, b));
                    }
                }
            }
        }
        let mut decoded: HashMap<usize, Option<RgbImage>> = HashMap::new();
        let mut picture = |i: usize| -> Option<RgbImage> {
            decoded
                .entry(i)
                .or_insert_with(|| read_png(pictures[i].path).ok().map(|s| s.picture))
                .clone()
        };
        for (a, b) in candidates {
            if let (Some(first), Some(second)) = (picture(a), picture(b))
                && equal_fraction(&first, &second) > NEAR_IDENTICAL
            {
                record(pictures[a], pictures[b]);
            }
        }
    }
    shared
        .into_iter()
        .map(|((a, b), files)| SimilarPair {
            students: [a, b],
            files: files.into_iter().map(|(_, file)| file).collect(),
        })
        .collect()
}

/// The fraction of pixels equal in both pictures (0 for pictures of different sizes).
fn equal_fraction(a: &RgbImage, b: &RgbImage) -> f64 {
    if a.dimensions() != b.dimensions() {
        return 0.0;
    }
    let equal = a.pixels().zip(b.pixels()).filter(|(p, q)| p == q).count();
    equal as f64 / (a.width() as f64 * a.height() as f64).max(1.0)
}

#[cfg(test)]
mod tests {
    use std::path::PathBuf;

    use super::*;
    use crate::rgb_image::Rgb;

    fn picture(seed: u32, changed: u32) -> RgbImage {
        let mut picture = RgbImage::from_fn(100, 100, |x, y| Rgb([(x * 2) as u8, (y * 2) as u8, seed as u8]));
        for i in 0..changed {
            picture.put_pixel(i % 100, i / 100, Rgb([255, 0, 255]));
        }
        picture
    }

    /// Saves each student's picture of `a01.png` and pairs them, as grading would.
    fn pairs_of(students: &[(&str, RgbImage)]) -> Vec<SimilarPair> {
        let dir = tempfile::tempdir().unwrap();
        let saved: Vec<(&str, PathBuf, Fingerprint)> = students
            .iter()
            .map(|(name, picture)| {
                let path = dir.path().join(format!("{name}.png"));
                crate::film::write_png(&path, picture).unwrap();
                (*name, path, Fingerprint::of(picture, true))
            })
            .collect();
        let entries: Vec<Entry> = saved
            .iter()
            .map(|(name, path, fingerprint)| Entry {
                student: name,
                file: "a01.png",
                order: 0,
                path,
                fingerprint,
            })
            .collect();
        similar_pairs(&entries)
    }

    #[test]
    fn identical_pictures_pair_and_different_ones_do_not() {
        // eve differs from dan on one pixel of 10,000: 99.99% equal is not more than 99.99%.
        let mut eve = picture(3, 0);
        eve.put_pixel(50, 50, Rgb([1, 2, 3]));
        let pairs = pairs_of(&[
            ("ann", picture(1, 0)),
            ("ben", picture(1, 0)),
            ("cat", picture(2, 0)),
            ("dan", picture(3, 0)),
            ("eve", eve),
            ("fay", picture(4, 0)),
        ]);
        assert_eq!(
            pairs,
            [SimilarPair {
                students: ["ann".into(), "ben".into()],
                files: vec!["a01.png".into()],
            }]
        );
    }

    #[test]
    fn near_identical_failing_pictures_pair_through_their_samples() {
        let big = |changed: u32| {
            let mut p = RgbImage::from_fn(400, 400, |x, y| Rgb([(x % 256) as u8, (y % 256) as u8, 7]));
            for i in 0..changed {
                p.put_pixel(i * 7 % 400, i * 13 % 400, Rgb([255, 0, 255]));
            }
            p
        };
        // 160,000 pixels: 5 changed is 99.997% equal (near-identical), 400 changed is 99.75%.
        let pairs = pairs_of(&[("ann", big(0)), ("ben", big(5)), ("cat", big(400))]);
        assert_eq!(pairs.len(), 1, "{pairs:?}");
        assert_eq!(pairs[0].students, ["ann".to_owned(), "ben".to_owned()]);
    }
}
