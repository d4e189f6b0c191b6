//! Reading an EXR back into a film: goldens in the test suite, both sides of `goldray diff`,
//! a grading's cached golden renders.

use std::io::Cursor;
use std::panic::{self, AssertUnwindSafe};

use ::exr::block::UncompressedBlock;
use ::exr::block::chunk::Chunk;
use ::exr::image::read::image::LayersReader;
use ::exr::meta::MetaData;
use ::exr::prelude::{AnyChannels, FlatSamples, Layer, ReadChannels, ReadLayers, read};
use rayon::prelude::*;

use super::super::Film;
use super::super::error::OutputError;
use super::VARIANCE_CHANNELS;

/// The most pixel bytes a decoded file may claim. The exr crate allocates every channel before it
/// reads a single block, so a corrupt header claiming a gigantic image would abort the process on
/// allocation failure instead of returning an error. 1 GiB is about a 6000×6000 film with all
/// seven channels: far beyond any golden image, far below a header typo.
const MAX_DECODE_BYTES: usize = 1 << 30;

/// Blocks inflated side by side at a time: enough to keep every thread busy (an 800×800 film
/// has 50), few enough that a large file's samples are not held twice over, once inflated in
/// blocks and once in the layer's channels.
const BLOCKS_AT_ONCE: usize = 64;

/// The layer goldray reads: the first valid one, at its largest resolution, every channel.
type FirstLayer = Layer<AnyChannels<FlatSamples>>;

/// [`super::decode_exr`] with `file` (the source) named in its errors.
pub(super) fn decode_exr_named(bytes: &[u8], file: &str) -> Result<Film, OutputError> {
    let invalid = |source| OutputError::DecodeExr {
        file: file.to_owned(),
        source,
    };
    let unsupported = |reason: String| OutputError::UnsupportedExr {
        file: file.to_owned(),
        reason,
    };

    // The header read on its own, unvalidated, so that a size no film could have is refused
    // with its own reason; the block reader below reads it again and validates it, and would
    // refuse such a header only as a chunk count not matching the file.
    let meta = MetaData::read_from_buffered(bytes, false).map_err(invalid)?;
    let claimed = meta.headers.iter().try_fold(0usize, |total, header| {
        let layer = header.layer_size.area().checked_mul(header.channels.bytes_per_pixel)?;
        total.checked_add(layer)
    });
    if claimed.is_none_or(|bytes| bytes > MAX_DECODE_BYTES) {
        return Err(unsupported(format!(
            "its header claims more than {MAX_DECODE_BYTES} bytes of pixels"
        )));
    }

    // The exr crate is fuzzed but not panic-free on every corrupt block; an unreadable golden
    // file must be an error the comparator can report, not a crashed test run.
    let layer = panic::catch_unwind(AssertUnwindSafe(|| read_first_layer(bytes)))
        .map_err(|_| unsupported("the EXR decoder failed on its contents".to_owned()))?
        .map_err(invalid)?;
    film_from_layer(&layer, file)
}

/// What the exr crate's reader gives (`read().no_deep_data().largest_resolution_level()
/// .all_channels().first_valid_layer()`), each block decompressed on rayon's pool: the crate's
/// own parallel reader builds a fresh thread pool for every file, and its sequential one leaves
/// the other cores idle while a film's blocks are inflated one after another (the twin of
/// `write_compressed_in_parallel`). A block's decompression depends on the block alone, so the
/// samples are the sequential reader's whatever the threads. The blocks go [`BLOCKS_AT_ONCE`]
/// at a time, in the file's order.
fn read_first_layer(bytes: &[u8]) -> ::exr::error::Result<FirstLayer> {
    let wanted = read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .first_valid_layer();
    let chunks = ::exr::block::read(Cursor::new(bytes), false)?;
    let meta = chunks.meta_data().clone();
    let mut layers = wanted.create_layers_reader(chunks.headers())?;
    let mut chunks = chunks.filter_chunks(false, |meta, tile, block| layers.filter_block(meta, tile, block))?;
    loop {
        let compressed: Vec<Chunk> = chunks
            .by_ref()
            .take(BLOCKS_AT_ONCE)
            .collect::<::exr::error::Result<_>>()?;
        if compressed.is_empty() {
            break;
        }
        let blocks: Vec<UncompressedBlock> = compressed
            .into_par_iter()
            .map(|chunk| UncompressedBlock::decompress_chunk(chunk, &meta, false))
            .collect::<::exr::error::Result<_>>()?;
        for block in blocks {
            layers.read_block(&meta.headers, block)?;
        }
    }
    Ok(layers.into_layers())
}

/// The film a layer holds. Only R, G and B are required (see [`super::decode_exr`]).
fn film_from_layer(layer: &FirstLayer, file: &str) -> Result<Film, OutputError> {
    let unsupported = |reason: String| OutputError::UnsupportedExr {
        file: file.to_owned(),
        reason,
    };
    let (width, height) = (layer.size.width(), layer.size.height());
    let too_big = || unsupported(format!("its size {width}x{height} does not fit a film"));
    let mut film = Film::new(
        u32::try_from(width).map_err(|_| too_big())?,
        u32::try_from(height).map_err(|_| too_big())?,
    );

    let channel = |name: &'static str| -> Result<Option<Vec<f32>>, OutputError> {
        let Some(found) = layer.channel_data.list.iter().find(|c| c.name == *name) else {
            return Ok(None);
        };
        if found.sample_data.len() != width * height {
            return Err(unsupported(format!("its {name} channel is subsampled")));
        }
        Ok(Some(found.sample_data.values_as_f32().collect()))
    };
    let required = |name: &'static str| {
        channel(name)?.ok_or_else(|| OutputError::MissingChannel {
            file: file.to_owned(),
            channel: name,
        })
    };

    let [r, g, b] = [required("R")?, required("G")?, required("B")?];
    for (i, pixel) in film.color.iter_mut().enumerate() {
        *pixel = [r[i], g[i], b[i]];
    }
    if let Some(z) = channel("Z")? {
        film.depth = z;
    }
    for (axis, name) in ["N.X", "N.Y", "N.Z"].into_iter().enumerate() {
        if let Some(values) = channel(name)? {
            for (normal, value) in film.normal.iter_mut().zip(values) {
                normal[axis] = value;
            }
        }
    }
    let [vr, vg, vb] = VARIANCE_CHANNELS.map(channel);
    if let (Some(r), Some(g), Some(b)) = (vr?, vg?, vb?) {
        film.variance = Some((0..width * height).map(|i| [r[i], g[i], b[i]]).collect());
    }
    Ok(film)
}

#[cfg(test)]
mod tests {
    use ::exr::prelude::{
        AnyChannel, Blocks, Compression, Encoding, Image, LayerAttributes, LineOrder, WritableImage, f16,
    };

    use super::super::{decode_exr, encode_exr};
    use super::*;

    /// An EXR of another tool's kind: 16-bit colour, 32-bit depth, an integer channel goldray
    /// ignores, 101 lines compressed with `compression` (PIZ: blocks of 32 lines, the last
    /// short; ZIP1: 101 blocks of a line, more than [`BLOCKS_AT_ONCE`]).
    fn foreign_exr(compression: Compression) -> Vec<u8> {
        let (width, height) = (45, 101);
        let value = |k: usize, salt: usize| ((k * 7919 + salt * 104_729) % 1013) as f32 / 97.0;
        let half = |salt| FlatSamples::F16((0..width * height).map(|k| f16::from_f32(value(k, salt))).collect());
        let list = vec![
            AnyChannel::new("R", half(1)),
            AnyChannel::new("G", half(2)),
            AnyChannel::new("B", half(3)),
            AnyChannel::new(
                "Z",
                FlatSamples::F32((0..width * height).map(|k| value(k, 4)).collect()),
            ),
            AnyChannel::new("id", FlatSamples::U32((0..width * height).map(|k| k as u32).collect())),
        ];
        let encoding = Encoding {
            compression,
            blocks: Blocks::ScanLines,
            line_order: LineOrder::Increasing,
        };
        let channels = AnyChannels::sort(list.into_iter().collect());
        let image = Image::from_layer(Layer::new(
            (width, height),
            LayerAttributes::default(),
            encoding,
            channels,
        ));
        let mut bytes = Vec::new();
        image
            .write()
            .non_parallel()
            .to_buffered(Cursor::new(&mut bytes))
            .unwrap();
        bytes
    }

    #[test]
    fn blocks_decompressed_side_by_side_give_the_sequential_readers_samples() {
        const { assert!(101 > BLOCKS_AT_ONCE, "ZIP1 makes more blocks than one batch") };
        for compression in [Compression::PIZ, Compression::ZIP1] {
            let bytes = foreign_exr(compression);
            let sequential = read()
                .no_deep_data()
                .largest_resolution_level()
                .all_channels()
                .first_valid_layer()
                .all_attributes()
                .non_parallel()
                .from_buffered(Cursor::new(&bytes))
                .unwrap();
            let expected = film_from_layer(&sequential.layer_data, "expected").unwrap();
            assert!(expected.depth.iter().any(|&z| z != expected.depth[0]));
            for threads in [1, 4] {
                let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
                let layer = pool.install(|| read_first_layer(&bytes)).unwrap();
                assert!(
                    layer == sequential.layer_data,
                    "{compression:?}, {threads} threads: the layer differs"
                );
                assert_eq!(
                    pool.install(|| decode_exr(&bytes)).unwrap(),
                    expected,
                    "{compression:?}, {threads} threads"
                );
            }
        }
    }

    #[test]
    fn a_cut_off_file_is_an_error_naming_it() {
        let mut bytes = foreign_exr(Compression::PIZ);
        bytes.truncate(bytes.len() - 100);
        let error = decode_exr_named(&bytes, "student.exr").unwrap_err();
        assert!(error.to_string().contains("student.exr"), "{error}");
    }

    #[test]
    fn a_header_claiming_a_huge_image_is_refused_before_allocating() {
        let mut bytes = encode_exr(&Film::new(4, 4)).unwrap();
        let key = b"dataWindow\0box2i\0";
        let at = bytes.windows(key.len()).position(|w| w == key).unwrap() + key.len() + 4;
        bytes[at + 8..at + 16].copy_from_slice(&[[0xff, 0xff, 0, 0]; 2].concat());
        let error = decode_exr(&bytes).unwrap_err();
        assert!(matches!(error, OutputError::UnsupportedExr { .. }), "{error}");
    }
}
