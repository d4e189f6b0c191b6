//! Decoded cube-map faces kept on disk between runs, each named by a hash of its PNG file.
//!
//! A face of the course's cube map is a 1024×1024 RGB PNG of 1.1 to 1.6 MB; decoding it takes
//! about 9 ms, two thirds of them inflating, which no other inflater shortens (libdeflate is
//! level with the `png` crate's fdeflate on these files; zlib-rs, zune-inflate and miniz_oxide
//! are slower). Reading its 3 MB of texels back from a file, with the checks below, takes 1 to
//! 2 ms. A teaching assistant renders the same scenes for every student, so
//! the faces are decoded once and read back after that, as renderers keep textures converted to
//! a form that loads fast (Arnold's `.tx` files, OpenImageIO's image cache).
//!
//! An entry is used only when it is whole and sound: its header names the face's size, and a
//! CRC-32 of its texels must match, so a damaged or foreign file is decoded again (and
//! replaced), never shown. Pictures are therefore the same with the cache, without it, and
//! with a damaged one. Entries are replaced atomically without a sync
//! (`atomic_write::replace_file`), so that another process reads an old entry or a whole new
//! one; the folder is kept under a size limit by removing the entries written longest ago.

use std::fs::{self, File};
use std::io::{self, Read};
use std::path::{Path, PathBuf};
use std::sync::OnceLock;
use std::time::SystemTime;

use crate::atomic_write::replace_file;

/// The first bytes of every entry; a change of format changes them, and entries of another
/// format are then decoded again.
const MAGIC: [u8; 8] = *b"GRTEXEL1";

/// Magic, width, height, CRC-32 of the texels (the integers little-endian).
const HEADER_BYTES: usize = 20;

/// The file name extension of entries: only such files are read or removed.
const EXTENSION: &str = "rgb8";

/// How large the folder may grow by default: the course's cube map takes 18 MB.
pub const DEFAULT_LIMIT_BYTES: u64 = 512 << 20;

/// A folder of decoded faces (see the module documentation).
#[derive(Debug, Clone)]
pub struct TexelCache {
    dir: PathBuf,
    limit_bytes: u64,
}

/// The cache every scene built in this process uses, if the program installed one.
static INSTALLED: OnceLock<TexelCache> = OnceLock::new();

impl TexelCache {
    pub fn new(dir: PathBuf, limit_bytes: u64) -> TexelCache {
        TexelCache { dir, limit_bytes }
    }

    /// The user's cache folder's `goldray/texels` (`$XDG_CACHE_HOME/goldray/texels`, usually
    /// `~/.cache/goldray/texels`, on Linux), beside the golden renders' cache; `None` where the
    /// system has no cache folder.
    pub fn default_dir() -> Option<PathBuf> {
        dirs::cache_dir().map(|dir| dir.join("goldray").join("texels"))
    }

    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// Makes `self` the cache of every scene built from now on in this process; a program calls
    /// it once, before building any (the library alone writes nothing to disk). `false` when a
    /// cache was installed already, which stays.
    pub fn install(self) -> bool {
        INSTALLED.set(self).is_ok()
    }

    /// The cache [`TexelCache::install`] installed, if any.
    pub fn installed() -> Option<&'static TexelCache> {
        INSTALLED.get()
    }

    /// Where the texels decoded from `png` are kept: a hash of the file's bytes, and of
    /// goldray's version, names them. An 8-bit RGB face's texels are its bytes whatever decodes
    /// them, but a face of another kind is converted (`rgb_image::decode_png`), and another
    /// version might convert it otherwise: its entries are not shared. Named once per face, for
    /// both [`TexelCache::read`] and [`TexelCache::write`] (hashing a course face takes 0.35 ms).
    pub fn entry(&self, png: &[u8]) -> PathBuf {
        let mut hasher = blake3::Hasher::new();
        hasher.update(env!("CARGO_PKG_VERSION").as_bytes());
        hasher.update(&[0]);
        hasher.update(png);
        let hash = hasher.finalize().to_hex();
        self.dir.join(format!("{}.{EXTENSION}", &hash[..32]))
    }

    /// The texels of a face of `width` × `height` texels, if `entry` (from [`TexelCache::entry`])
    /// holds them whole.
    pub fn read(&self, entry: &Path, width: usize, height: usize) -> Option<Vec<u8>> {
        let length = texel_bytes(width, height)?;
        let entry_bytes = HEADER_BYTES.checked_add(length)?;
        let mut file = File::open(entry).ok()?;
        // The size first, so that a foreign file allocates nothing beyond a face's texels.
        if file.metadata().ok()?.len() != entry_bytes as u64 {
            return None;
        }
        let mut header = [0; HEADER_BYTES];
        file.read_exact(&mut header).ok()?;
        let word = |at: usize| u32::from_le_bytes(header[at..at + 4].try_into().expect("four bytes"));
        if header[..8] != MAGIC || word(8) as usize != width || word(12) as usize != height {
            return None;
        }
        let mut texels = Vec::with_capacity(length);
        file.take(length as u64).read_to_end(&mut texels).ok()?;
        (texels.len() == length && crc32fast::hash(&texels) == word(16)).then_some(texels)
    }

    /// Stores a face's texels in `entry` (from [`TexelCache::entry`]), then removes the entries
    /// written longest ago while the folder is over its limit (never the new one).
    pub fn write(&self, entry: &Path, width: usize, height: usize, texels: &[u8]) -> io::Result<()> {
        if texel_bytes(width, height) != Some(texels.len()) {
            return Err(io::Error::new(
                io::ErrorKind::InvalidInput,
                "the texels do not fill the face",
            ));
        }
        let mut bytes = Vec::with_capacity(HEADER_BYTES + texels.len());
        bytes.extend(MAGIC);
        for word in [width as u32, height as u32, crc32fast::hash(texels)] {
            bytes.extend(word.to_le_bytes());
        }
        bytes.extend_from_slice(texels);
        // Not synced: an entry lost or cut short by a crash fails its checks and is made again.
        replace_file(entry, &bytes).map_err(io::Error::other)?;
        self.prune(entry)
    }

    /// Removes the entries written longest ago, but not `kept`, until the folder's entries fit
    /// the limit.
    fn prune(&self, kept: &Path) -> io::Result<()> {
        let mut entries = Vec::new();
        for item in fs::read_dir(&self.dir)? {
            let item = item?;
            let path = item.path();
            if path.extension().is_some_and(|e| e == EXTENSION) && item.file_type()?.is_file() {
                let metadata = item.metadata()?;
                entries.push((
                    metadata.modified().unwrap_or(SystemTime::UNIX_EPOCH),
                    metadata.len(),
                    path,
                ));
            }
        }
        let mut total: u64 = entries.iter().map(|(_, bytes, _)| bytes).sum();
        entries.sort();
        for (_, bytes, path) in entries {
            if total <= self.limit_bytes {
                break;
            }
            if path != kept {
                // Another process may have removed it first: either way it is gone.
                match fs::remove_file(&path) {
                    Ok(()) => total -= bytes,
                    Err(error) if error.kind() == io::ErrorKind::NotFound => total -= bytes,
                    Err(error) => return Err(error),
                }
            }
        }
        Ok(())
    }
}

/// The bytes of a face's RGB texels, `None` when that overflows.
fn texel_bytes(width: usize, height: usize) -> Option<usize> {
    width.checked_mul(height)?.checked_mul(3)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn texels(width: usize, height: usize, seed: u8) -> Vec<u8> {
        (0..width * height * 3)
            .map(|i| (i as u8).wrapping_mul(31).wrapping_add(seed))
            .collect()
    }

    fn entries(dir: &Path) -> Vec<PathBuf> {
        let mut paths: Vec<PathBuf> = fs::read_dir(dir).unwrap().map(|e| e.unwrap().path()).collect();
        paths.sort();
        paths
    }

    #[test]
    fn texels_written_are_read_back_for_the_same_png_only() {
        let dir = tempfile::tempdir().unwrap();
        let cache = TexelCache::new(dir.path().join("texels"), DEFAULT_LIMIT_BYTES);
        let face = texels(5, 3, 1);
        assert_eq!(cache.read(&cache.entry(b"png one"), 5, 3), None, "nothing stored yet");
        cache.write(&cache.entry(b"png one"), 5, 3, &face).unwrap();
        assert_eq!(cache.read(&cache.entry(b"png one"), 5, 3), Some(face));
        assert_eq!(
            cache.read(&cache.entry(b"png two"), 5, 3),
            None,
            "another file's bytes name another entry"
        );
        assert_eq!(
            cache.read(&cache.entry(b"png one"), 3, 5),
            None,
            "the size must match the face's"
        );
        let names = entries(cache.dir());
        assert_eq!(names.len(), 1, "no temporary file is left: {names:?}");
    }

    #[test]
    fn a_damaged_or_foreign_entry_is_not_used() {
        let dir = tempfile::tempdir().unwrap();
        let cache = TexelCache::new(dir.path().to_path_buf(), DEFAULT_LIMIT_BYTES);
        let face = texels(4, 4, 9);
        let entry = cache.entry(b"face");
        cache.write(&entry, 4, 4, &face).unwrap();
        let sound = fs::read(&entry).unwrap();

        let mut flipped = sound.clone();
        flipped[HEADER_BYTES + 17] ^= 0x10;
        fs::write(&entry, &flipped).unwrap();
        assert_eq!(cache.read(&entry, 4, 4), None, "a texel changed: the CRC tells");

        fs::write(&entry, &sound[..sound.len() - 1]).unwrap();
        assert_eq!(cache.read(&entry, 4, 4), None, "cut short");

        let mut foreign = sound.clone();
        foreign[7] = b'9';
        fs::write(&entry, &foreign).unwrap();
        assert_eq!(cache.read(&entry, 4, 4), None, "another format");

        cache.write(&entry, 4, 4, &face).unwrap();
        assert_eq!(cache.read(&entry, 4, 4), Some(face), "written again, it is used again");
    }

    #[test]
    fn the_folder_is_kept_under_its_limit_by_removing_the_oldest_entries() {
        let dir = tempfile::tempdir().unwrap();
        let entry_bytes = (HEADER_BYTES + 10 * 10 * 3) as u64;
        let cache = TexelCache::new(dir.path().to_path_buf(), 2 * entry_bytes);
        let old = SystemTime::now() - std::time::Duration::from_secs(3600);
        for (k, name) in [&b"a"[..], b"b"].into_iter().enumerate() {
            cache
                .write(&cache.entry(name), 10, 10, &texels(10, 10, k as u8))
                .unwrap();
            let file = File::options().write(true).open(cache.entry(name)).unwrap();
            file.set_modified(old + std::time::Duration::from_secs(k as u64))
                .unwrap();
        }
        fs::write(dir.path().join("notes.txt"), "not an entry").unwrap();
        cache.write(&cache.entry(b"c"), 10, 10, &texels(10, 10, 2)).unwrap();
        assert_eq!(cache.read(&cache.entry(b"a"), 10, 10), None, "the oldest entry went");
        assert!(cache.read(&cache.entry(b"b"), 10, 10).is_some() && cache.read(&cache.entry(b"c"), 10, 10).is_some());
        assert!(dir.path().join("notes.txt").exists(), "only entries are removed");

        let tiny = TexelCache::new(dir.path().to_path_buf(), 1);
        tiny.write(&tiny.entry(b"d"), 10, 10, &texels(10, 10, 3)).unwrap();
        assert!(
            tiny.read(&tiny.entry(b"d"), 10, 10).is_some(),
            "the entry just written stays, even over the limit"
        );
        assert_eq!(entries(dir.path()).len(), 2, "d and the notes");
    }

    #[test]
    fn a_folder_that_cannot_be_written_is_an_error_not_a_panic() {
        let dir = tempfile::tempdir().unwrap();
        let file = dir.path().join("a file");
        fs::write(&file, "").unwrap();
        let cache = TexelCache::new(file.join("texels"), DEFAULT_LIMIT_BYTES);
        assert!(cache.write(&cache.entry(b"face"), 1, 1, &[1, 2, 3]).is_err());
        assert_eq!(cache.read(&cache.entry(b"face"), 1, 1), None);
        assert!(
            cache.write(&cache.entry(b"face"), 2, 1, &[1, 2, 3]).is_err(),
            "texels that do not fill the face"
        );
    }
}
