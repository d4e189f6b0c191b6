//! The film's file contract: what the EXR holds and how other tools see it, that its bytes are
//! reproducible, that bad data and bad files are errors, and that outputs are replaced atomically.

use std::collections::BTreeSet;
use std::fs;
use std::io::Cursor;
use std::path::{Path, PathBuf};

use exr::prelude::{ReadChannels, ReadLayers};
use goldray::atomic_write::{AtomicWriteError, write_file_atomic};
use goldray::film::{
    Film, OutputError, OutputOptions, Tonemap, decode_exr, encode_exr, read_exr, write_exr, write_outputs,
};
use goldray::provenance::{Group, Provenance, keys, strip};

/// A non-square film (height not a multiple of the 16-line ZIP block) with values that a lossy or
/// half-float path would change: tiny, huge, negative, negative zero, and misses.
fn varied_film(seed: u32) -> Film {
    let mut film = Film::new(37, 21);
    let mut state = seed.wrapping_mul(2_654_435_761).wrapping_add(1);
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 17;
        state ^= state << 5;
        f32::from_bits(0x3f80_0000 | (state >> 9)) - 1.0
    };
    for i in 0..film.color.len() {
        film.color[i] = [next() * 3.0, next() * 1e-30, -next() * 1e6];
        film.depth[i] = if i % 5 == 0 { f32::INFINITY } else { 0.1 + next() * 1e4 };
        film.normal[i] = if i % 5 == 0 { [0.0; 3] } else { [next(), -0.0, -next()] };
    }
    film
}

fn bits(film: &Film) -> Vec<u32> {
    let colors = film.color.iter().flatten();
    let normals = film.normal.iter().flatten();
    colors.chain(&film.depth).chain(normals).map(|v| v.to_bits()).collect()
}

fn all_options() -> OutputOptions {
    OutputOptions {
        tonemap: Tonemap::Srgb,
        depth_range: Some((0.0, 1e4)),
        normals: true,
    }
}

fn dir_entries(dir: &Path) -> BTreeSet<String> {
    let entries = fs::read_dir(dir).expect("list dir");
    entries
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect()
}

fn names(list: &[&str]) -> BTreeSet<String> {
    list.iter().map(|s| s.to_string()).collect()
}

#[test]
fn exr_round_trip_is_bit_exact() {
    let film = varied_film(1);
    let decoded = decode_exr(&encode_exr(&film).expect("encode")).expect("decode");
    assert_eq!((decoded.width, decoded.height), (film.width, film.height));
    assert_eq!(bits(&decoded), bits(&film));
}

#[test]
fn exr_has_the_contract_channels_layout_and_compression() {
    let bytes = encode_exr(&varied_film(2)).expect("encode");
    let meta = exr::meta::MetaData::read_from_buffered(Cursor::new(&bytes), true).expect("meta");
    assert_eq!(meta.headers.len(), 1, "one part");
    let header = &meta.headers[0];
    assert_eq!(header.compression, exr::compression::Compression::ZIP16);
    assert_eq!(header.line_order, exr::meta::attribute::LineOrder::Increasing);
    assert_eq!(header.blocks, exr::meta::BlockDescription::ScanLines);
    assert_eq!(header.layer_size, exr::math::Vec2(37, 21));
    assert_eq!(header.own_attributes.layer_position, exr::math::Vec2(0, 0));
    assert_eq!(header.shared_attributes.display_window.size, exr::math::Vec2(37, 21));
    assert_eq!(header.shared_attributes.display_window.position, exr::math::Vec2(0, 0));

    let image = exr::prelude::read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .all_layers()
        .all_attributes()
        .from_buffered(Cursor::new(&bytes))
        .expect("generic read");
    let channels = &image.layer_data[0].channel_data.list;
    let found: BTreeSet<String> = channels.iter().map(|c| c.name.to_string()).collect();
    assert_eq!(found, names(&["R", "G", "B", "Z", "N.X", "N.Y", "N.Z"]));
    for channel in channels {
        assert!(
            matches!(channel.sample_data, exr::prelude::FlatSamples::F32(_)),
            "{} is not f32",
            channel.name
        );
    }
}

#[test]
fn exr_bytes_are_identical_across_runs_and_thread_pools() {
    let film = varied_film(3);
    let encode_in_pool = |threads| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("pool");
        pool.install(|| encode_exr(&film).expect("encode"))
    };
    let reference = encode_exr(&film).expect("encode");
    assert_eq!(encode_exr(&film).expect("encode"), reference);
    assert_eq!(encode_in_pool(1), reference);
    assert_eq!(encode_in_pool(4), reference);
}

#[test]
fn non_finite_values_are_refused_and_named() {
    let mut film = varied_film(4);
    film.color[2 * 37 + 5][1] = f32::NAN;
    let message = encode_exr(&film).expect_err("NaN colour").to_string();
    assert!(
        message.contains("pixel (5, 2)") && message.contains("channel G"),
        "{message}"
    );

    let mut film = varied_film(4);
    film.normal[3][2] = f32::INFINITY;
    let message = encode_exr(&film).expect_err("inf normal").to_string();
    assert!(
        message.contains("pixel (3, 0)") && message.contains("channel N.Z"),
        "{message}"
    );
}

#[test]
fn missing_aovs_default_to_a_miss_and_other_sample_types_convert() {
    use exr::prelude::{AnyChannel, AnyChannels, FlatSamples, WritableImage, f16};
    let half = |v: f32| FlatSamples::F16(vec![f16::from_f32(v); 6]);
    let channels = AnyChannels::sort(
        vec![
            AnyChannel::new("R", half(0.5)),
            AnyChannel::new("G", FlatSamples::F32(vec![0.25; 6])),
            AnyChannel::new("B", FlatSamples::U32(vec![3; 6])),
        ]
        .into(),
    );
    let mut bytes = Vec::new();
    exr::prelude::Image::from_channels((3, 2), channels)
        .write()
        .to_buffered(Cursor::new(&mut bytes))
        .expect("write");
    let film = decode_exr(&bytes).expect("decode");
    assert_eq!((film.width, film.height), (3, 2));
    assert!(film.color.iter().all(|&c| c == [0.5, 0.25, 3.0]));
    assert!(film.depth.iter().all(|&t| t == f32::INFINITY));
    assert!(film.normal.iter().all(|&n| n == [0.0; 3]));
}

#[test]
fn a_file_without_colour_is_an_error_naming_the_channel() {
    use exr::prelude::{AnyChannel, AnyChannels, FlatSamples, WritableImage};
    let only = |name: &str| AnyChannel::new(name, FlatSamples::F32(vec![1.0; 4]));
    let channels = AnyChannels::sort(vec![only("G"), only("B"), only("Z")].into());
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("a.exr");
    exr::prelude::Image::from_channels((2, 2), channels)
        .write()
        .to_file(&path)
        .expect("write");
    let message = read_exr(&path).expect_err("no R").to_string();
    assert_eq!(message, format!("{} has no R channel", path.display()));
}

#[test]
fn truncated_and_garbage_bytes_are_errors_not_panics() {
    let bytes = encode_exr(&varied_film(5)).expect("encode");
    for len in (0..bytes.len()).step_by(97).chain([bytes.len() - 1]) {
        assert!(decode_exr(&bytes[..len]).is_err(), "truncated to {len} bytes decoded");
    }
    let mut state = 0x9e37_79b9_u32;
    let garbage: Vec<u8> = (0..4096)
        .map(|_| {
            state = state.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            (state >> 24) as u8
        })
        .collect();
    assert!(decode_exr(&garbage).is_err());
    let mut with_magic = garbage.clone();
    with_magic[..4].copy_from_slice(&[0x76, 0x2f, 0x31, 0x01]);
    assert!(decode_exr(&with_magic).is_err());
    // Corrupting single bytes anywhere must give a film or an error, never a crash.
    for position in (0..bytes.len()).step_by(13) {
        let mut corrupt = bytes.clone();
        corrupt[position] ^= 0xa5;
        let _ = decode_exr(&corrupt);
    }
}

#[test]
fn read_errors_name_the_missing_file() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("missing.exr");
    let message = read_exr(&path).expect_err("missing").to_string();
    assert!(
        message.starts_with(&format!("cannot read {}: ", path.display())),
        "{message}"
    );
}

#[test]
fn write_exr_and_read_exr_round_trip_through_a_file() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("nested/dir/a.exr");
    let film = varied_film(6);
    write_exr(&path, &film).expect("write");
    assert_eq!(bits(&read_exr(&path).expect("read")), bits(&film));
    assert_eq!(dir_entries(&dir.path().join("nested/dir")), names(&["a.exr"]));
}

#[test]
fn write_outputs_writes_exactly_the_requested_files_in_order() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("out");
    let film = varied_film(7);
    let provenance = Provenance::this_build().with(keys::SEED, 7);
    let written = write_outputs(&out, "scene", &film, &all_options(), &provenance).expect("write");
    let expected: Vec<PathBuf> = ["scene.exr", "scene.png", "scene_depth.png", "scene_normals.png"]
        .iter()
        .map(|name| out.join(name))
        .collect();
    assert_eq!(written, expected);
    assert_eq!(
        dir_entries(&out),
        names(&["scene.exr", "scene.png", "scene_depth.png", "scene_normals.png"])
    );
    let exr = fs::read(&expected[0]).expect("exr");
    assert_eq!(
        strip(&exr, Group::All).expect("strip"),
        encode_exr(&film).expect("encode")
    );
    assert_eq!(
        exr,
        provenance
            .stamp(&encode_exr(&film).expect("encode"), "scene.exr")
            .expect("stamp")
    );
    for file in &expected {
        let found = Provenance::read(file).expect("readable").expect("stamped");
        assert_eq!(found, provenance, "{}", file.display());
    }
    let png = goldray::rgb_image::read_png(&expected[1]).expect("png");
    assert_eq!(png, goldray::film::color_image(&film, Tonemap::Srgb));

    let bare = OutputOptions {
        tonemap: Tonemap::Clamp,
        depth_range: None,
        normals: false,
    };
    let written = write_outputs(&out, "bare", &film, &bare, &Provenance::default()).expect("write");
    assert_eq!(written, vec![out.join("bare.exr"), out.join("bare.png")]);
    assert_eq!(dir_entries(&out).len(), 6);
}

#[test]
fn write_outputs_replaces_existing_files() {
    let dir = tempfile::tempdir().expect("tempdir");
    let (old, new) = (varied_film(8), varied_film(9));
    write_outputs(dir.path(), "a", &old, &all_options(), &Provenance::default()).expect("first");
    write_outputs(dir.path(), "a", &new, &all_options(), &Provenance::default()).expect("second");
    assert_eq!(bits(&read_exr(&dir.path().join("a.exr")).expect("read")), bits(&new));
    assert_eq!(dir_entries(dir.path()).len(), 4, "no temp files left");
}

#[test]
fn a_failed_write_leaves_existing_outputs_untouched_and_no_temp_files() {
    let all = ["a.exr", "a.png", "a_depth.png", "a_normals.png"];
    // A directory where an output should go makes that rename fail: first, middle and last.
    for blocked in all {
        let dir = tempfile::tempdir().expect("tempdir");
        write_outputs(
            dir.path(),
            "a",
            &varied_film(10),
            &all_options(),
            &Provenance::default(),
        )
        .expect("first");
        fs::remove_file(dir.path().join(blocked)).expect("remove");
        fs::create_dir(dir.path().join(blocked)).expect("block");
        let before: Vec<Option<Vec<u8>>> = all.iter().map(|f| fs::read(dir.path().join(f)).ok()).collect();

        let error = write_outputs(
            dir.path(),
            "a",
            &varied_film(11),
            &all_options(),
            &Provenance::default(),
        )
        .expect_err("blocked output");
        assert!(
            matches!(error, OutputError::Write(AtomicWriteError::Write { .. })),
            "{error}"
        );
        assert!(
            error
                .to_string()
                .contains(&dir.path().join(blocked).display().to_string())
        );

        let after: Vec<Option<Vec<u8>>> = all.iter().map(|f| fs::read(dir.path().join(f)).ok()).collect();
        assert!(before == after, "outputs changed when {blocked} was blocked");
        assert_eq!(
            dir_entries(dir.path()),
            names(&all),
            "leftovers when {blocked} was blocked"
        );
    }
}

#[test]
fn an_unwritable_directory_is_an_error_naming_it() {
    let dir = tempfile::tempdir().expect("tempdir");
    let not_a_dir = dir.path().join("file");
    fs::write(&not_a_dir, b"keep").expect("file");
    let error = write_outputs(
        &not_a_dir,
        "a",
        &varied_film(12),
        &all_options(),
        &Provenance::default(),
    )
    .expect_err("not a directory");
    assert!(
        error
            .to_string()
            .starts_with(&format!("cannot write {}", not_a_dir.display()))
    );
    assert_eq!(fs::read(&not_a_dir).expect("read"), b"keep");
}

#[test]
fn a_refused_film_writes_nothing() {
    let dir = tempfile::tempdir().expect("tempdir");
    let mut film = varied_film(13);
    film.color[0][0] = f32::NAN;
    let error = write_outputs(dir.path(), "a", &film, &all_options(), &Provenance::default()).expect_err("NaN");
    let exr = dir.path().join("a.exr");
    assert!(matches!(error, OutputError::NonFinite { .. }));
    assert!(
        error
            .to_string()
            .starts_with(&format!("refusing to write {}", exr.display()))
    );
    assert!(dir_entries(dir.path()).is_empty());
}

#[test]
fn write_file_atomic_replaces_and_creates_parents() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("reports/r.json");
    write_file_atomic(&path, b"old").expect("first");
    write_file_atomic(&path, b"new").expect("second");
    assert_eq!(fs::read(&path).expect("read"), b"new");
    assert_eq!(dir_entries(&dir.path().join("reports")), names(&["r.json"]));
}
