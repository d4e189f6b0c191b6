//! The linear EXR: the one output that golden comparisons and external viewers (tev, Blender,
//! OpenImageIO) trust, so it must hold exactly what was rendered and be byte-stable.

use std::io::{Cursor, Seek, Write};
use std::path::Path;

use ::exr::block::UncompressedBlock;
use ::exr::block::chunk::Chunk;
use ::exr::block::writer::ChunksWriter;
use ::exr::image::write::layers::{LayersWriter, WritableLayers};
use ::exr::prelude::{
    AnyChannel, AnyChannels, Blocks, Compression, Encoding, FlatSamples, Image, Layer, LayerAttributes, LineOrder,
    WritableImage,
};
use rayon::prelude::*;

use super::Film;
use super::error::OutputError;
use crate::atomic_write::write_file_atomic;

mod decode;

use decode::decode_exr_named;

/// What in-memory EXR bytes are called in messages, where there is no file path to name.
const IN_MEMORY: &str = "EXR data";

/// The channels goldray writes, in the contract's order, which is also the order in which the
/// first non-finite value of a pixel is reported.
const CHANNELS: [&str; 7] = ["R", "G", "B", "Z", "N.X", "N.Y", "N.Z"];

/// The variance of each pixel's mean colour, written only for a render with several samples per
/// pixel (`Film::variance`). A layer `var` in OpenEXR's naming, so tev and Blender show it as
/// its own image beside the colour.
pub const VARIANCE_CHANNELS: [&str; 3] = ["var.R", "var.G", "var.B"];

/// Encodes the film as a one-part, ZIP-compressed, increasing-line-order f32 scanline EXR. The
/// blocks are compressed side by side on rayon's pool and written in increasing order, so the
/// bytes are a pure function of the film (see [`write_compressed_in_parallel`]).
pub fn encode_exr(film: &Film) -> Result<Vec<u8>, OutputError> {
    encode_exr_named(film, IN_MEMORY)
}

/// Reads the first part of an EXR. Only R, G and B are required so that EXRs from other tools
/// (or goldray files stripped of AOVs) can still be compared; a missing depth is a miss (`+inf`)
/// and a missing normal is zero, the same values a miss renders to.
pub fn decode_exr(bytes: &[u8]) -> Result<Film, OutputError> {
    decode_exr_named(bytes, IN_MEMORY)
}

/// [`decode_exr`] on a file, with the path in every error.
pub fn read_exr(path: &Path) -> Result<Film, OutputError> {
    let bytes = std::fs::read(path).map_err(|source| OutputError::Read {
        path: path.to_path_buf(),
        source,
    })?;
    decode_exr_named(&bytes, &path.display().to_string())
}

/// [`encode_exr`] written atomically: a reader sees the old file or the new one, never a part.
pub fn write_exr(path: &Path, film: &Film) -> Result<(), OutputError> {
    let bytes = encode_exr_named(film, &path.display().to_string())?;
    Ok(write_file_atomic(path, &bytes)?)
}

/// [`encode_exr`] with `file` (the destination) named in its errors.
pub(super) fn encode_exr_named(film: &Film, file: &str) -> Result<Vec<u8>, OutputError> {
    check_film(film, file)?;
    let mut bytes = Vec::new();
    write_compressed_in_parallel(&film_image(film), Cursor::new(&mut bytes)).map_err(|source| {
        OutputError::EncodeExr {
            file: file.to_owned(),
            source,
        }
    })?;
    Ok(bytes)
}

/// The film as the exr crate's image: its channels, sorted by name as the format wants, in one
/// ZIP-compressed scanline layer written in increasing line order.
fn film_image(film: &Film) -> Image<Layer<AnyChannels<FlatSamples>>> {
    let channel = |name: &str, values: Vec<f32>| AnyChannel::new(name, FlatSamples::F32(values));
    let mut list = vec![
        channel("R", film.color.iter().map(|c| c[0]).collect()),
        channel("G", film.color.iter().map(|c| c[1]).collect()),
        channel("B", film.color.iter().map(|c| c[2]).collect()),
        channel("Z", film.depth.clone()),
        channel("N.X", film.normal.iter().map(|n| n[0]).collect()),
        channel("N.Y", film.normal.iter().map(|n| n[1]).collect()),
        channel("N.Z", film.normal.iter().map(|n| n[2]).collect()),
    ];
    if let Some(variance) = &film.variance {
        for (c, name) in VARIANCE_CHANNELS.into_iter().enumerate() {
            list.push(channel(name, variance.iter().map(|v| v[c]).collect()));
        }
    }
    let channels = AnyChannels::sort(list.into_iter().collect());
    let encoding = Encoding {
        compression: Compression::ZIP16,
        blocks: Blocks::ScanLines,
        line_order: LineOrder::Increasing,
    };
    let size = (film.width as usize, film.height as usize);
    Image::from_layer(Layer::new(size, LayerAttributes::default(), encoding, channels))
}

/// What the exr crate's `to_buffered` writes, each block compressed on rayon's pool: ZIP
/// compression on one thread was most of the time of writing a 512×512 film with variance
/// (about 100 ms, against a 50 ms render). The crate's own parallel writer would build a fresh
/// thread pool for every file, beside the pool whose threads are writing films already. The
/// blocks are made and written in the order the sequential writer takes them, and a block's
/// compression depends on the block alone, so the bytes are those of the sequential writer
/// whatever the threads.
fn write_compressed_in_parallel<L>(image: &Image<L>, write: impl Write + Seek) -> ::exr::error::UnitResult
where
    for<'a> L: WritableLayers<'a>,
{
    let headers = image.write().infer_meta_data();
    let layers = image.layer_data.create_writer(&headers);
    ::exr::block::write(write, headers, true, |meta, chunk_writer| {
        let blocks: Vec<(usize, UncompressedBlock)> = meta
            .collect_ordered_block_data(|index| layers.extract_uncompressed_block(&meta.headers, index))
            .collect();
        let chunks: Vec<(usize, Chunk)> = blocks
            .into_par_iter()
            .map(|(index, block)| Ok((index, block.compress_to_chunk(&meta.headers)?)))
            .collect::<::exr::error::Result<_>>()?;
        for (index, chunk) in chunks {
            chunk_writer.write_chunk(index, chunk)?;
        }
        Ok(())
    })
}

/// Refuses a film whose buffers disagree with its size, or that holds a value no viewer or metric
/// can use. Depth alone may be `+inf`: that is how a miss is stored.
fn check_film(film: &Film, file: &str) -> Result<(), OutputError> {
    let pixels = film.width as usize * film.height as usize;
    let variances = film.variance.as_ref().map_or(pixels, Vec::len);
    if film.width == 0
        || film.height == 0
        || [film.color.len(), film.depth.len(), film.normal.len(), variances] != [pixels; 4]
    {
        return Err(OutputError::FilmShape {
            file: file.to_owned(),
            width: film.width,
            height: film.height,
            colors: film.color.len(),
            depths: film.depth.len(),
            normals: film.normal.len(),
            variances,
        });
    }
    let non_finite = |i: usize, channel, value| OutputError::NonFinite {
        file: file.to_owned(),
        x: (i % film.width as usize) as u32,
        y: (i / film.width as usize) as u32,
        channel,
        value,
    };
    let pixel_values = film.color.iter().zip(&film.depth).zip(&film.normal);
    for (i, ((color, &depth), normal)) in pixel_values.enumerate() {
        let values = [color[0], color[1], color[2], depth, normal[0], normal[1], normal[2]];
        let bad = values.iter().zip(CHANNELS).find(|&(&value, channel)| {
            if channel == "Z" {
                value.is_nan()
            } else {
                !value.is_finite()
            }
        });
        if let Some((&value, channel)) = bad {
            return Err(non_finite(i, channel, value));
        }
    }
    let variances = film.variance.iter().flatten().enumerate();
    let bad = variances.flat_map(|(i, v)| {
        v.iter()
            .zip(VARIANCE_CHANNELS)
            .map(move |(&value, channel)| (i, value, channel))
    });
    if let Some((i, value, channel)) = bad
        .into_iter()
        .find(|&(_, value, _)| !(value.is_finite() && value >= 0.0))
    {
        return Err(non_finite(i, channel, value));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn blocks_compressed_side_by_side_give_the_sequential_writers_bytes() {
        // Five blocks of 16 lines, the last short, every channel varying so that no block
        // compresses to the same bytes as another.
        let (width, height) = (37, 70);
        let mut film = Film::new(width, height);
        let value = |k: usize, salt: usize| ((k * 7919 + salt * 104_729) % 1013) as f32 / 97.0;
        for k in 0..film.color.len() {
            film.color[k] = [value(k, 1), value(k, 2), value(k, 3)];
            film.depth[k] = if k % 11 == 0 { f32::INFINITY } else { value(k, 4) };
            film.normal[k] = [value(k, 5), -value(k, 6), value(k, 7)];
        }
        film.variance = Some(
            (0..film.color.len())
                .map(|k| [value(k, 8), value(k, 9), value(k, 10)])
                .collect(),
        );
        let mut sequential = Vec::new();
        film_image(&film)
            .write()
            .non_parallel()
            .to_buffered(Cursor::new(&mut sequential))
            .unwrap();
        for threads in [1, 4] {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            let bytes = pool.install(|| encode_exr(&film)).unwrap();
            assert!(
                bytes == sequential,
                "{threads} threads: the bytes differ from the sequential writer's"
            );
        }
        let decoded = decode_exr(&sequential).unwrap();
        assert_eq!(decoded.color, film.color);
        assert_eq!(decoded.variance, film.variance);
    }

    #[test]
    fn first_bad_value_is_named_by_pixel_and_channel() {
        let mut film = Film::new(3, 2);
        film.normal[4][1] = f32::NEG_INFINITY;
        film.color[5][0] = f32::NAN;
        let message = encode_exr(&film).unwrap_err().to_string();
        assert!(message.contains("pixel (1, 1)"), "{message}");
        assert!(message.contains("N.Y"), "{message}");
    }

    #[test]
    fn depth_may_be_infinite_but_not_nan() {
        let mut film = Film::new(2, 2);
        assert!(encode_exr(&film).is_ok());
        film.depth[2] = f32::NAN;
        let message = encode_exr(&film).unwrap_err().to_string();
        assert!(message.contains("pixel (0, 1)") && message.contains(" Z "), "{message}");
    }

    #[test]
    fn mismatched_buffers_and_empty_films_are_refused() {
        let mut film = Film::new(2, 2);
        film.depth.pop();
        assert!(matches!(encode_exr(&film), Err(OutputError::FilmShape { .. })));
        assert!(matches!(
            encode_exr(&Film::new(0, 4)),
            Err(OutputError::FilmShape { .. })
        ));
    }
}
