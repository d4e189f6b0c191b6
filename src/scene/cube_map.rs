//! The assignment's cube-map background, sampled exactly as its reference renderer does
//! (docs/ARCHITECTURE.md, "Cube maps"): texel row 0 is the PNG's top row, faces chosen by the
//! largest component, bilinear weights with edge-clamped indices.

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use rayon::prelude::*;

use super::real::{Color, Real, Vec3};
pub use crate::build_error::CubeMapError;
use crate::rgb_image::{DEFAULT_MAX_BYTES, decode_png};
use crate::simd::Isa;
use crate::stats::CubeMapFaces;
use crate::texel_cache::TexelCache;

/// One face: a PNG read and checked at load, decoded when a ray first looks at it.
///
/// Scenes rarely see all six faces (the course's scene 7 sees two), and decoding is most of
/// what a cube map costs, so a face no ray reaches is never decoded. Everything that can be
/// checked without decoding is checked at load (the file, its PNG structure and every chunk's
/// CRC, its size), so a broken file is still an error before anything is rendered.
#[derive(Debug)]
struct Face {
    path: PathBuf,
    png: Vec<u8>,
    width: usize,
    height: usize,
    /// The texels, once a ray looked; or why the data could not be decoded.
    texels: OnceLock<Result<Texels, String>>,
    /// Where decoded texels are kept between runs, if anywhere.
    cache: Option<&'static TexelCache>,
}

/// A face's texels and where they came from.
#[derive(Debug)]
struct Texels {
    /// Red, green and blue bytes texel by texel, row by row, row 0 at the top.
    bytes: Vec<u8>,
    /// Read back from the texel cache rather than decoded (for `--stats`).
    read_from_cache: bool,
}

#[derive(Debug)]
pub struct CubeMap {
    /// In the order of `FACE_NAMES`.
    faces: [Face; 6],
}

const FACE_NAMES: [&str; 6] = ["right", "left", "up", "down", "front", "back"];
const RIGHT: usize = 0;
const LEFT: usize = 1;
const UP: usize = 2;
const DOWN: usize = 3;
const FRONT: usize = 4;
const BACK: usize = 5;

/// Linear texel values, `byte / 255` (the reference applies no gamma), computed once.
fn byte_values() -> &'static [Real; 256] {
    static VALUES: OnceLock<[Real; 256]> = OnceLock::new();
    VALUES.get_or_init(|| std::array::from_fn(|byte| byte as Real / 255.0))
}

impl CubeMap {
    /// Reads and checks `dir/{left,right,up,down,front,back}.png`, in parallel; faces are
    /// decoded through the process's installed [`TexelCache`], if any.
    pub fn load(dir: &Path) -> Result<CubeMap, CubeMapError> {
        CubeMap::load_cached(dir, TexelCache::installed())
    }

    /// [`CubeMap::load`] with faces decoded through `cache` (or none).
    pub fn load_cached(dir: &Path, cache: Option<&'static TexelCache>) -> Result<CubeMap, CubeMapError> {
        let faces: Vec<Face> = FACE_NAMES
            .par_iter()
            .map(|name| Face::read(dir.join(format!("{name}.png")), cache))
            .collect::<Result<_, _>>()?;
        let faces: [Face; 6] = faces.try_into().expect("six names give six faces");
        Ok(CubeMap { faces })
    }

    pub fn radiance(&self, direction: Vec3) -> Color {
        self.spot(direction).map_or(Color::ZERO, |(face, spot)| self.faces[face].bilinear(&spot))
    }

    /// [`CubeMap::radiance`] of the directions whose bit is set in `wanted` (the others see
    /// black), each exactly as alone. Every texel is asked for from memory before any is read:
    /// the reflections off a curved surface look all over the map, and lookups one after another
    /// would each wait for their texels in turn.
    ///
    /// A kernel: compile it only inside one (see `crate::simd`).
    #[inline(always)]
    pub fn radiance_lanes<I: Isa, const N: usize>(&self, directions: &[Vec3; N], wanted: u32) -> [Color; N] {
        let mut spots = [None; N];
        for (k, spot) in spots.iter_mut().enumerate() {
            if wanted >> k & 1 != 0 {
                *spot = self.spot(directions[k]);
                if let Some((face, spot)) = spot {
                    self.faces[*face].prefetch::<I>(spot);
                }
            }
        }
        let mut seen = [Color::ZERO; N];
        for (seen, spot) in seen.iter_mut().zip(&spots) {
            if let Some((face, spot)) = spot {
                *seen = self.faces[*face].bilinear(spot);
            }
        }
        seen
    }

    /// Where `direction` looks: its face (an index into `faces`) and the texels it blends there,
    /// or `None` for a direction that is zero or not finite (which sees black).
    fn spot(&self, direction: Vec3) -> Option<(usize, Spot)> {
        let (face, u, v) = face_and_coordinates(direction)?;
        Some((face, self.faces[face].spot(u, v)))
    }

    /// The faces the directions whose bit is set in `wanted` look at, as bits (bit `i` for
    /// `faces[i]`), without decoding any: which faces a lookup of each would decode.
    pub fn faces_seen<const N: usize>(directions: &[Vec3; N], wanted: u32) -> u8 {
        let mut faces = 0;
        for (k, &direction) in directions.iter().enumerate() {
            if wanted >> k & 1 != 0
                && let Some((face, _, _)) = face_and_coordinates(direction)
            {
                faces |= 1 << face;
            }
        }
        faces
    }

    /// The faces not decoded yet, as bits (see [`CubeMap::faces_seen`]).
    pub fn undecoded_faces(&self) -> u8 {
        let mut faces = 0;
        for (index, face) in self.faces.iter().enumerate() {
            if face.texels.get().is_none() {
                faces |= 1 << index;
            }
        }
        faces
    }

    /// Decodes the faces of `faces` (bits, see [`CubeMap::faces_seen`]) side by side, a thread
    /// each. A render that knows which faces its rays will see decodes them so before it starts:
    /// decoded when first seen, they are decoded one after another, each by the first ray to
    /// look while any other ray that looks waits. A face that cannot be decoded is reported by
    /// [`CubeMap::failure`] once a ray has looked at it, as when decoded on the way.
    pub fn decode_faces(&self, faces: u8) {
        self.faces.par_iter().enumerate().filter(|(index, _)| faces >> index & 1 != 0).for_each(|(_, face)| {
            face.texels();
        });
    }

    /// Decodes every face now instead of when first seen (for a scene rendered many times).
    pub fn decode_all(&self) -> Result<(), CubeMapError> {
        self.decode_faces(u8::MAX);
        self.failure().map_or(Ok(()), Err)
    }

    /// How the faces rays looked at so far came to be: decoded from their PNG, or read from the
    /// texel cache.
    pub fn faces_loaded(&self) -> CubeMapFaces {
        let mut faces = CubeMapFaces::default();
        for face in &self.faces {
            match face.texels.get() {
                Some(Ok(texels)) if texels.read_from_cache => faces.read_from_cache += 1,
                Some(Ok(_)) => faces.decoded += 1,
                _ => {}
            }
        }
        faces
    }

    /// A face that a ray looked at but that could not be decoded (it showed black): the render
    /// that saw it must be discarded. `None` when every face seen so far was decoded.
    pub fn failure(&self) -> Option<CubeMapError> {
        self.faces.iter().find_map(|face| match face.texels.get() {
            Some(Err(reason)) => Some(CubeMapError { path: face.path.clone(), reason: reason.clone() }),
            _ => None,
        })
    }
}

impl Face {
    fn read(path: PathBuf, cache: Option<&'static TexelCache>) -> Result<Face, CubeMapError> {
        let error = |reason: String| CubeMapError { path: path.clone(), reason };
        let png = std::fs::read(&path).map_err(|e| error(e.to_string()))?;
        check_chunks(&png).map_err(|reason| error(format!("not a valid PNG file: {reason}")))?;
        let header = png::Decoder::new(std::io::Cursor::new(&png)).read_info().map_err(|e| error(e.to_string()))?;
        let (width, height) = (header.info().width, header.info().height);
        if width == 0 || height == 0 {
            return Err(error("the image is empty".to_string()));
        }
        Ok(Face { path, png, width: width as usize, height: height as usize, texels: OnceLock::new(), cache })
    }

    /// The decoded texels: decoded (or read from the cache) by the first ray to look, which any
    /// other waits for. Texels decoded are stored in the cache; a cache that cannot be written
    /// only means the next run decodes them again.
    fn texels(&self) -> Option<&[u8]> {
        let texels = self.texels.get_or_init(|| {
            let entry = self.cache.map(|cache| (cache, cache.entry(&self.png)));
            if let Some(bytes) = entry.as_ref().and_then(|(cache, entry)| cache.read(entry, self.width, self.height)) {
                return Ok(Texels { bytes, read_from_cache: true });
            }
            let bytes = decode_rgb8(&self.png)?;
            if bytes.len() != self.width * self.height * 3 {
                return Err("the image data does not match its header".to_string());
            }
            if let Some((cache, entry)) = entry {
                let _ = cache.write(&entry, self.width, self.height, &bytes);
            }
            Ok(Texels { bytes, read_from_cache: false })
        });
        texels.as_ref().ok().map(|texels| texels.bytes.as_slice())
    }

    /// The four texels a lookup at `(u, v)` blends, with the reference's edge-clamped indices,
    /// and their weights' fractions.
    fn spot(&self, u: Real, v: Real) -> Spot {
        let x = u * self.width as Real;
        let y = (1.0 - v) * self.height as Real;
        // `u` and `v` lie in [0, 1] (a component over the largest one, plus one, halved), so `x`
        // and `y` are non-negative and truncation is `floor`, without the library call `floor`
        // is on x86-64 without SSE4.1.
        // The neighbours' indices are counted in integers from the one conversion each way: the
        // reference's `x0 + 1` clamped to the edge, without a saturating conversion of a float
        // per neighbour (scene 6 with its faces cached: 7% less processor time).
        let (column, row) = (x as usize, y as usize);
        let columns = [column.min(self.width - 1), (column + 1).min(self.width - 1)];
        let rows = [row.min(self.height - 1), (row + 1).min(self.height - 1)].map(|row| row * self.width);
        Spot {
            texels: [rows[0] + columns[0], rows[0] + columns[1], rows[1] + columns[0], rows[1] + columns[1]].map(|texel| 3 * texel),
            alpha: x - column as Real,
            beta: y - row as Real,
        }
    }

    /// Asks for the cache lines of `spot`'s texels (a hint: it changes nothing).
    #[inline(always)]
    fn prefetch<I: Isa>(&self, spot: &Spot) {
        if let Some(texels) = self.texels() {
            for &offset in &spot.texels {
                // The last byte too: a texel's three may straddle two lines.
                I::prefetch(texels.as_ptr().wrapping_add(offset));
                I::prefetch(texels.as_ptr().wrapping_add(offset + 2));
            }
        }
    }

    fn bilinear(&self, spot: &Spot) -> Color {
        let Some(texels) = self.texels() else { return Color::ZERO };
        let values = byte_values();
        let (alpha, beta) = (spot.alpha, spot.beta);
        let texel = |corner: usize| {
            let texel = &texels[spot.texels[corner]..][..3];
            Color::new(values[texel[0] as usize], values[texel[1] as usize], values[texel[2] as usize])
        };
        texel(0) * ((1.0 - alpha) * (1.0 - beta))
            + texel(1) * (alpha * (1.0 - beta))
            + texel(2) * ((1.0 - alpha) * beta)
            + texel(3) * (alpha * beta)
    }
}

/// The face `direction` looks at (an index into [`CubeMap`]'s faces) and where on it, `(u, v)`
/// in `[0, 1]`; `None` for a direction that is zero or not finite (which sees black).
fn face_and_coordinates(direction: Vec3) -> Option<(usize, Real, Real)> {
    let d = direction.normalize_or_zero();
    let (x, y, z) = (d.x, d.y, d.z);
    let (ax, ay, az) = (x.abs(), y.abs(), z.abs());
    let half = |a: Real, b: Real| (a / b + 1.0) * 0.5;
    let (face, u, v) = if ax >= ay && ax >= az {
        if x > 0.0 { (RIGHT, half(z, x), half(y, x)) } else { (LEFT, half(z, x), 1.0 - half(y, x)) }
    } else if ay >= az {
        if y > 0.0 { (UP, half(x, y), half(z, y)) } else { (DOWN, 1.0 - half(x, y), 1.0 - half(z, y)) }
    } else if z > 0.0 {
        (FRONT, 1.0 - half(x, z), half(y, z))
    } else {
        (BACK, half(x, z), 1.0 - half(y, z))
    };
    (u.is_finite() && v.is_finite()).then_some((face, u, v))
}

/// Where a lookup reads on its face: the byte offsets of the four texels it blends (the texel
/// the direction falls in, the next column, the next row, and both) and the fractions `alpha`
/// and `beta` of the way to the next column and row.
#[derive(Clone, Copy)]
struct Spot {
    texels: [usize; 4],
    alpha: Real,
    beta: Real,
}

/// A face's texels as RGB bytes. An 8-bit RGB PNG (the course's faces) is decoded by the `png`
/// crate straight into the buffer the texels are kept in, without the chunks' CRCs, which
/// [`check_chunks`] verified at load; any other PNG is converted to 8-bit RGB by [`decode_png`].
fn decode_rgb8(png: &[u8]) -> Result<Vec<u8>, String> {
    let mut decoder = png::Decoder::new(std::io::Cursor::new(png));
    decoder.ignore_checksums(true);
    let mut reader = decoder.read_info().map_err(|e| e.to_string())?;
    if reader.output_color_type() != (png::ColorType::Rgb, png::BitDepth::Eight) {
        let decoded = decode_png(png, DEFAULT_MAX_BYTES).map_err(|e| e.to_string())?;
        return Ok(decoded.image.into_raw());
    }
    let size = reader.output_buffer_size().ok_or("the image is too large")?;
    let mut texels = vec![0; size];
    reader.next_frame(&mut texels).map_err(|e| e.to_string())?;
    Ok(texels)
}

/// Walks a PNG's chunks: the signature, each chunk's length within the file and its CRC, an
/// `IHDR` first and an `IEND` last. What a decoder would reject about the file's structure,
/// without inflating the image data.
fn check_chunks(png: &[u8]) -> Result<(), String> {
    const SIGNATURE: [u8; 8] = [0x89, b'P', b'N', b'G', b'\r', b'\n', 0x1a, b'\n'];
    let mut rest = png.strip_prefix(&SIGNATURE[..]).ok_or("no PNG signature")?;
    let mut first = true;
    loop {
        if rest.len() < 12 {
            return Err("the file ends inside a chunk (no IEND)".to_string());
        }
        let length = u32::from_be_bytes(rest[..4].try_into().expect("four bytes")) as usize;
        if length > rest.len() - 12 {
            return Err("a chunk runs past the end of the file".to_string());
        }
        let (kind, data) = (&rest[4..8], &rest[8..8 + length]);
        let crc = u32::from_be_bytes(rest[8 + length..12 + length].try_into().expect("four bytes"));
        let mut hasher = crc32fast::Hasher::new();
        hasher.update(kind);
        hasher.update(data);
        if hasher.finalize() != crc {
            return Err(format!("the CRC of a {} chunk does not match", String::from_utf8_lossy(kind)));
        }
        if first && kind != b"IHDR" {
            return Err("the first chunk is not IHDR".to_string());
        }
        first = false;
        if kind == b"IEND" {
            return Ok(());
        }
        rest = &rest[12 + length..];
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn face(width: usize, height: usize, texels: Vec<[u8; 3]>) -> Face {
        let texels = OnceLock::from(Ok(Texels { bytes: texels.into_flattened(), read_from_cache: false }));
        Face { path: PathBuf::new(), png: Vec::new(), width, height, texels, cache: None }
    }

    fn uniform_face(byte: u8) -> Face {
        face(2, 2, vec![[byte; 3]; 4])
    }

    fn cube(bytes: [u8; 6]) -> CubeMap {
        CubeMap { faces: bytes.map(uniform_face) }
    }

    fn value(byte: u8) -> Real {
        byte as Real / 255.0
    }

    #[test]
    fn picks_the_face_of_the_largest_component_with_ties_to_x_then_y() {
        let map = cube([10, 20, 30, 40, 50, 60]);
        assert_eq!(map.radiance(Vec3::new(2.0, 1.0, 1.0)).x, value(10));
        assert_eq!(map.radiance(Vec3::new(-2.0, 1.0, 1.0)).x, value(20));
        assert_eq!(map.radiance(Vec3::new(0.0, 3.0, -1.0)).x, value(30));
        assert_eq!(map.radiance(Vec3::new(0.0, -3.0, 1.0)).x, value(40));
        assert_eq!(map.radiance(Vec3::new(0.5, 0.0, 1.0)).x, value(50));
        assert_eq!(map.radiance(Vec3::new(0.5, 0.0, -1.0)).x, value(60));
        assert_eq!(map.radiance(Vec3::new(1.0, 1.0, 1.0)).x, value(10), "a three-way tie goes to x");
        assert_eq!(map.radiance(Vec3::new(0.0, -1.0, 1.0)).x, value(40), "a y–z tie goes to y");
    }

    #[test]
    fn the_faces_seen_are_those_lookups_read_and_only_those_wanted() {
        let map = cube([10, 20, 30, 40, 50, 60]);
        let directions = [
            Vec3::new(2.0, 1.0, 1.0),
            Vec3::new(-2.0, 1.0, 1.0),
            Vec3::new(0.0, 3.0, -1.0),
            Vec3::ZERO,
            Vec3::new(0.5, 0.0, -1.0),
            Vec3::new(Real::NAN, 1.0, 0.0),
            Vec3::new(1.0, 1.0, 1.0),
            Vec3::new(0.0, -3.0, 1.0),
        ];
        let byte = |face: usize| [10, 20, 30, 40, 50, 60][face];
        for k in 0..directions.len() {
            let faces = CubeMap::faces_seen(&directions, 1 << k);
            match map.spot(directions[k]) {
                Some((face, _)) => {
                    assert_eq!(faces, 1 << face, "direction {k}");
                    assert_eq!(map.radiance(directions[k]).x, value(byte(face)), "direction {k}");
                }
                None => assert_eq!(faces, 0, "direction {k} sees black"),
            }
        }
        assert_eq!(CubeMap::faces_seen(&directions, 0b1111_0111), 0b10_1111, "every face but front");
        assert_eq!(CubeMap::faces_seen(&directions, 0b1000_0100), 0b00_1100, "up and down: wanted lanes only");
    }

    #[test]
    fn decoding_faces_decodes_those_asked_for() {
        let dir = faces_with_a_damaged_right_face(true);
        let map = CubeMap::load(dir.path()).expect("the damage only shows when decoding");
        assert_eq!(map.undecoded_faces(), 0b11_1111);
        map.decode_faces(0b10_0010);
        assert_eq!(map.undecoded_faces(), 0b01_1101);
        assert!(map.failure().is_none(), "left and back decode");
        map.decode_faces(0b00_0001);
        assert_eq!(map.undecoded_faces(), 0b01_1100, "the damaged face counts as decoded");
        assert!(map.failure().expect("right is damaged").path.ends_with("right.png"));
    }

    #[test]
    fn bilinear_weights_follow_the_reference_indexing() {
        // Columns 0..3 hold 0, 0.2, 0.4, 0.6 on every row.
        let face = face(4, 1, (0..4).map(|i| [i * 51; 3]).collect());
        // u = 0.3 → X = 1.2 → 0.8·texel(1) + 0.2·texel(2).
        assert!((face.bilinear(&face.spot(0.3, 0.5)).x - (0.8 * 0.2 + 0.2 * 0.4)).abs() < 1e-6);
        // Past the last column the index clamps to the edge.
        assert!((face.bilinear(&face.spot(0.99, 0.5)).x - 0.6).abs() < 1e-6);
    }

    #[test]
    fn v_counts_up_from_the_bottom_row() {
        let face = face(1, 2, vec![[255; 3], [0; 3]]);
        assert!(face.bilinear(&face.spot(0.5, 0.99)).x > 0.9, "v near 1 is the top row");
        assert!(face.bilinear(&face.spot(0.5, 0.01)).x < 0.1, "v near 0 is the bottom row");
    }

    #[test]
    fn missing_face_names_its_path() {
        let dir = tempfile::tempdir().unwrap();
        let error = CubeMap::load(dir.path()).unwrap_err();
        assert!(error.path.starts_with(dir.path()), "{error}");
    }

    /// Six 2×2 faces, `right` with its image data cut to the zlib header (`fix_crc`: and its
    /// chunk's length and CRC made to match, so that only decoding can tell).
    fn faces_with_a_damaged_right_face(fix_crc: bool) -> tempfile::TempDir {
        let dir = tempfile::tempdir().unwrap();
        let mut face = Vec::new();
        let mut encoder = png::Encoder::new(&mut face, 2, 2);
        encoder.set_color(png::ColorType::Rgb);
        encoder.write_header().unwrap().write_image_data(&[200, 100, 50].repeat(4)).unwrap();
        for name in FACE_NAMES {
            std::fs::write(dir.path().join(format!("{name}.png")), &face).unwrap();
        }
        let path = dir.path().join("right.png");
        let png = std::fs::read(&path).unwrap();
        let idat = png.windows(4).position(|w| w == b"IDAT").unwrap();
        let length = u32::from_be_bytes(png[idat - 4..idat].try_into().unwrap()) as usize;
        let mut damaged = png[..idat - 4].to_vec();
        damaged.extend(2u32.to_be_bytes());
        damaged.extend(&png[idat..idat + 6]);
        let crc = if fix_crc { crc32fast::hash(&png[idat..idat + 6]) } else { 0 };
        damaged.extend(crc.to_be_bytes());
        damaged.extend(&png[idat + 8 + length..]);
        std::fs::write(&path, damaged).unwrap();
        dir
    }

    #[test]
    fn a_damaged_face_is_an_error_at_load() {
        let dir = faces_with_a_damaged_right_face(false);
        let error = CubeMap::load(dir.path()).unwrap_err();
        assert!(error.path.ends_with("right.png") && error.reason.contains("CRC"), "{error}");
    }

    #[test]
    fn faces_are_decoded_when_first_seen_and_an_undecodable_one_is_reported() {
        let dir = faces_with_a_damaged_right_face(true);
        let map = CubeMap::load(dir.path()).expect("the damage only shows when decoding");
        assert!(map.faces.iter().all(|face| face.texels.get().is_none()), "nothing decoded yet");
        assert_eq!(map.radiance(-Vec3::X), Color::new(value(200), value(100), value(50)));
        assert!(map.failure().is_none(), "the left face decodes");
        assert!(map.faces[RIGHT].texels.get().is_none(), "the right face was not needed");
        assert_eq!(map.radiance(Vec3::X), Color::ZERO, "an undecodable face shows black");
        let error = map.failure().expect("the right face could not be decoded");
        assert!(error.path.ends_with("right.png"), "{error}");
        assert!(map.decode_all().is_err());
    }

    #[test]
    fn faces_are_read_from_the_texel_cache_and_stored_there_when_decoded() {
        let dir = faces_with_a_damaged_right_face(true);
        let cache_dir = tempfile::tempdir().unwrap();
        let cache: &'static TexelCache =
            Box::leak(Box::new(TexelCache::new(cache_dir.path().to_path_buf(), u64::MAX)));
        let decoded = Color::new(value(200), value(100), value(50));
        let map = CubeMap::load_cached(dir.path(), Some(cache)).unwrap();
        assert_eq!(map.radiance(-Vec3::X), decoded);
        let left = std::fs::read(dir.path().join("left.png")).unwrap();
        assert_eq!(cache.read(&cache.entry(&left), 2, 2), Some([200, 100, 50].repeat(4)), "the decoded face was stored");
        assert_eq!(map.radiance(Vec3::X), Color::ZERO, "the damaged face still shows black");
        assert_eq!(std::fs::read_dir(cache_dir.path()).unwrap().count(), 1, "nothing stored for it");

        // Every face but `right` is the same PNG, so one entry serves them all: give it other
        // texels, and a new map shows those without decoding.
        cache.write(&cache.entry(&left), 2, 2, &[7; 12]).unwrap();
        let map = CubeMap::load_cached(dir.path(), Some(cache)).unwrap();
        assert_eq!(map.radiance(Vec3::Y), Color::splat(value(7)), "read from the cache");

        // A damaged entry is decoded again, and repaired.
        let entry = std::fs::read_dir(cache_dir.path()).unwrap().next().unwrap().unwrap().path();
        let mut bytes = std::fs::read(&entry).unwrap();
        *bytes.last_mut().unwrap() ^= 1;
        std::fs::write(&entry, bytes).unwrap();
        let map = CubeMap::load_cached(dir.path(), Some(cache)).unwrap();
        assert_eq!(map.radiance(Vec3::Z), decoded);
        assert_eq!(cache.read(&cache.entry(&left), 2, 2), Some([200, 100, 50].repeat(4)), "repaired");
    }

    #[test]
    fn lookups_side_by_side_see_what_each_sees_alone() {
        // Faces of 3×2 texels, every texel different, so that each weight shows.
        let faces = std::array::from_fn(|f| face(3, 2, (0..6).map(|i| [(40 * f + 7 * i) as u8, (i * 31) as u8, 200]).collect()));
        let map = CubeMap { faces };
        let directions = [
            Vec3::new(2.0, 0.3, -0.7),
            Vec3::new(-0.2, -1.0, 0.45),
            Vec3::ZERO,
            Vec3::new(0.1, 0.2, 3.0),
            Vec3::new(-0.5, 0.5, -1.0),
            Vec3::new(Real::NAN, 1.0, 0.0),
            Vec3::new(-4.0, 1.0, 2.0),
            Vec3::new(0.3, 5.0, -0.2),
        ];
        let wanted = 0b1101_1111;
        let seen = map.radiance_lanes::<crate::simd::Portable, 8>(&directions, wanted);
        for (k, (&direction, seen)) in directions.iter().zip(seen).enumerate() {
            let alone = if wanted >> k & 1 != 0 { map.radiance(direction) } else { Color::ZERO };
            assert_eq!(seen, alone, "lane {k}");
        }
        assert!(seen.iter().filter(|color| color.x > 0.0).count() >= 5);
    }
}
