//! A synthetic class for `goldray grade`: a rubric over `tests/grade/class_scene.toml` at 100×100
//! (colour, normals, depth) and ten student folders rendered by goldray itself, each with the
//! mistakes of one kind of student.

use std::fs;
use std::path::{Path, PathBuf};

use goldray::case::{Case, LoadOptions, load};
use goldray::film::{Film, Tonemap, color_image, depth_image, encode_exr, encode_png, normals_image};
use goldray::pipeline::render_case;
use goldray::rgb_image::{Rgb, RgbImage};

use crate::util::png_in_layout;

pub const FILES: [&str; 3] = ["color.png", "normals.png", "depth.png"];
/// Colour counts double, like the shipped rubric.
pub const POINTS: [f64; 3] = [2.0, 1.0, 1.0];
/// A folder name that is an HTML injection if the report forgets to escape it.
pub const HOSTILE: &str = "<img src=x onerror=alert(1)> & \"Mallory\"";

/// A student's files: name in the folder, bytes.
type Files = Vec<(&'static str, Vec<u8>)>;

pub struct Class {
    pub dir: PathBuf,
    /// Removes `dir` when the class is dropped, for a class in a temporary directory.
    _temporary: Option<tempfile::TempDir>,
    pub rubric: PathBuf,
    pub submissions: PathBuf,
    /// Every student file with its bytes, to prove grading changes none of them.
    pub files: Vec<(PathBuf, Vec<u8>)>,
}

pub fn scene_path() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/grade/class_scene.toml")
}

/// The rubric of the class, with the limits of the shipped one.
pub fn rubric_text(scene: &Path) -> String {
    format!(
        r#"title = "Synthetic class"

[defaults]
threshold = 8
pass_fraction = 0.01
partial_fraction = 0.05
pass_flip = 0.1
partial_flip = 0.2
partial_credit = 0.5

[render.spheres]
case = {scene:?}
size = [100, 100]

[image."color.png"]
render = "spheres"
points = 2

[image."normals.png"]
render = "spheres"
output = "normals"

[image."depth.png"]
render = "spheres"
output = "depth"
depth = [6, 14]
"#
    )
}

pub fn case() -> Case {
    load(&scene_path(), &LoadOptions::default()).unwrap_or_else(|e| panic!("{e}"))
}

pub fn render(case: &Case) -> Film {
    render_case(case).unwrap_or_else(|e| panic!("{e}"))
}

/// Colour, normals and depth as the course binary writes them.
pub fn pictures(film: &Film) -> [RgbImage; 3] {
    [
        color_image(film, Tonemap::Clamp),
        normals_image(film, Tonemap::Clamp),
        depth_image(film, 6.0, 14.0, Tonemap::Clamp),
    ]
}

fn png(picture: &RgbImage) -> Vec<u8> {
    encode_png(picture).unwrap()
}

/// Deterministic noise of up to ±`amplitude` codes per pixel, under the 8-code threshold: only
/// the FLIP limits can notice it.
fn wobble(picture: &RgbImage, amplitude: u64) -> RgbImage {
    RgbImage::from_fn(picture.width(), picture.height(), |x, y| {
        let hash = (u64::from(x) << 32 | u64::from(y)).wrapping_mul(0x9E37_79B9_7F4A_7C15);
        let offset = ((hash >> 40) % (2 * amplitude + 1)) as i16 - amplitude as i16;
        Rgb(picture
            .get_pixel(x, y)
            .0
            .map(|c| (i16::from(c) + offset).clamp(0, 255) as u8))
    })
}

/// A PNG whose header declares `width`×`height` pixels but whose data is a few bytes: the shape
/// of a decompression bomb, without the bytes of one.
fn bomb(width: u32, height: u32, color_type: u8, bit_depth: u8) -> Vec<u8> {
    let mut header = Vec::new();
    header.extend(width.to_be_bytes());
    header.extend(height.to_be_bytes());
    header.extend([bit_depth, color_type, 0, 0, 0]);
    let mut bytes = b"\x89PNG\r\n\x1a\n".to_vec();
    for (kind, data) in [
        (&b"IHDR"[..], &header[..]),
        (b"IDAT", &[0x78, 0x9c, 0x03, 0x00][..]),
        (b"IEND", &[][..]),
    ] {
        bytes.extend((data.len() as u32).to_be_bytes());
        let start = bytes.len();
        bytes.extend(kind);
        bytes.extend(data);
        let crc = crc32(&bytes[start..]);
        bytes.extend(crc.to_be_bytes());
    }
    bytes
}

fn crc32(bytes: &[u8]) -> u32 {
    let mut crc = !0u32;
    for &byte in bytes {
        crc ^= u32::from(byte);
        for _ in 0..8 {
            crc = if crc & 1 == 1 {
                (crc >> 1) ^ 0xEDB8_8320
            } else {
                crc >> 1
            };
        }
    }
    !crc
}

/// The class in a fresh temporary directory, removed with the `Class`.
pub fn make_class() -> Class {
    let temporary = tempfile::tempdir().unwrap();
    let mut class = make_class_at(temporary.path());
    class._temporary = Some(temporary);
    class
}

/// The class in `dir`, emptied first and kept afterwards, so that its report can be looked at.
pub fn make_class_at(dir: &Path) -> Class {
    if dir.exists() {
        fs::remove_dir_all(dir).unwrap();
    }
    fs::create_dir_all(dir).unwrap();
    let rubric = dir.join("rubric.toml");
    fs::write(&rubric, rubric_text(&scene_path())).unwrap();
    let submissions = dir.join("submissions");

    let base = case();
    let golden = render(&base);
    let perfect = pictures(&golden);
    let perfect_png = perfect.each_ref().map(png);

    let mut students: Vec<(&str, Files)> = Vec::new();
    let all = |pngs: [Vec<u8>; 3]| FILES.iter().copied().zip(pngs).collect::<Vec<_>>();
    students.push(("perfect", all(perfect_png.clone())));

    let mut no_shadows = base.clone();
    no_shadows.render.trace.shadows = false;
    students.push(("no_shadows", all(pictures(&render(&no_shadows)).each_ref().map(png))));

    let mut shifted = base.clone();
    shifted.camera.center[0] += 1.0;
    students.push(("shifted_camera", all(pictures(&render(&shifted)).each_ref().map(png))));

    students.push((
        "gamma",
        all([
            png(&color_image(&golden, Tonemap::Srgb)),
            perfect_png[1].clone(),
            perfect_png[2].clone(),
        ]),
    ));

    let mut corrupt = perfect_png[2].clone();
    for byte in &mut corrupt[60..120] {
        *byte ^= 0x5a;
    }
    students.push((
        "missing_and_corrupt",
        vec![
            ("normals.png", perfect_png[1][..perfect_png[1].len() / 2].to_vec()),
            ("depth.png", corrupt),
        ],
    ));

    let mut small = base.clone();
    (small.render.trace.width, small.render.trace.height) = (120, 90);
    students.push(("wrong_sizes", all(pictures(&render(&small)).each_ref().map(png))));

    students.push((
        "formats",
        all([
            png_in_layout(&perfect[0], png::ColorType::Rgba, png::BitDepth::Eight),
            png_in_layout(&perfect[1], png::ColorType::Rgb, png::BitDepth::Sixteen),
            png_in_layout(&perfect[2], png::ColorType::Grayscale, png::BitDepth::Eight),
        ]),
    ));

    students.push((
        "bad_files",
        all([
            encode_exr(&golden).unwrap(),
            bomb(50_000, 50_000, 2, 8),
            bomb(16_000, 16_000, 6, 16),
        ]),
    ));

    let mut scribbled = perfect[0].clone();
    for (x, y) in (0..12).flat_map(|x| (0..12).map(move |y| (40 + x, 40 + y))) {
        scribbled.put_pixel(x, y, Rgb([255, 255, 0]));
    }
    students.push((
        "scribbled",
        all([
            png(&scribbled),
            png(&wobble(&perfect[1], 3)),
            png(&wobble(&perfect[2], 7)),
        ]),
    ));

    let mut files = Vec::new();
    for (name, pngs) in students {
        for (file, bytes) in pngs {
            files.push((submissions.join(name).join(file), bytes));
        }
    }
    // Nested one level down and upper-cased, as a zip extracted on another system leaves them.
    let nested = submissions.join(HOSTILE).join("submission");
    for (bytes, shown) in perfect_png.iter().zip(["COLOR.PNG", "Normals.png", "depth.png"]) {
        files.push((nested.join(shown), bytes.clone()));
    }
    files.push((submissions.join("README.txt"), b"loose file: not a student".to_vec()));
    files.push((submissions.join(".hidden/color.png"), perfect_png[0].clone()));
    for (path, bytes) in &files {
        fs::create_dir_all(path.parent().unwrap()).unwrap();
        fs::write(path, bytes).unwrap();
    }
    Class {
        dir: dir.to_path_buf(),
        _temporary: None,
        rubric,
        submissions,
        files,
    }
}
