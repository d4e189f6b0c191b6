//! What the integration tests share: running the binary and finding the shipped cases. Each test
//! binary includes this module and uses part of it.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use goldray::case::{Case, LoadOptions, load};

/// Runs the `goldray` binary with `args` and returns what it did, whatever the exit code. Decoded
/// cube-map faces are kept under the build's folder for integration tests, not in the user's
/// cache folder.
pub fn goldray(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_goldray"))
        .env(
            "GOLDRAY_TEXEL_CACHE",
            Path::new(env!("CARGO_TARGET_TMPDIR")).join("texels"),
        )
        .args(args)
        .output()
        .expect("the goldray binary runs")
}

pub fn stderr(output: &Output) -> String {
    String::from_utf8_lossy(&output.stderr).into_owned()
}

/// A file of the project, by its path from the root (`cases/jitter.toml`).
pub fn project_file(relative: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(relative)
}

/// A shipped case file, by file name (`jitter.toml`).
pub fn shipped(file: &str) -> PathBuf {
    project_file("cases").join(file)
}

/// A shipped case, loaded, by name without the extension (`jitter`).
pub fn load_shipped(name: &str) -> Case {
    load(&shipped(&format!("{name}.toml")), &LoadOptions::default()).unwrap_or_else(|e| panic!("{e}"))
}

/// `goldray render CASE --out OUT --threads THREADS --quiet EXTRA…`, which must succeed.
pub fn render_on_threads(case: &Path, out: &Path, threads: &str, extra: &[&str]) {
    let (case, out) = (case.to_str().expect("UTF-8 path"), out.to_str().expect("UTF-8 path"));
    let mut args = vec!["render", case, "--out", out, "--threads", threads, "--quiet"];
    args.extend(extra);
    let result = goldray(&args);
    assert!(result.status.success(), "{case}: {}", stderr(&result));
}

/// `picture` encoded as a PNG of another colour type and bit depth than goldray writes (RGBA,
/// 16-bit RGB, grey, …), with another compression and filter: what other programs hand in.
pub fn png_in_layout(picture: &goldray::rgb_image::RgbImage, color: png::ColorType, depth: png::BitDepth) -> Vec<u8> {
    let samples: Vec<u16> = picture
        .pixels()
        .flat_map(|p| {
            let [r, g, b] = p.0.map(u16::from);
            let grey = (r + g + b) / 3;
            match color {
                png::ColorType::Grayscale => vec![grey],
                png::ColorType::GrayscaleAlpha => vec![grey, 255],
                png::ColorType::Rgba => vec![r, g, b, 255],
                _ => vec![r, g, b],
            }
        })
        .collect();
    let data: Vec<u8> = match depth {
        png::BitDepth::Sixteen => samples.iter().flat_map(|&v| (v * 257).to_be_bytes()).collect(),
        _ => samples.iter().map(|&v| v as u8).collect(),
    };
    let mut bytes = Vec::new();
    let mut encoder = png::Encoder::new(&mut bytes, picture.width(), picture.height());
    encoder.set_color(color);
    encoder.set_depth(depth);
    encoder.set_compression(png::Compression::High);
    encoder.set_filter(png::Filter::Paeth);
    encoder.write_header().unwrap().write_image_data(&data).unwrap();
    bytes
}

/// A PNG file as 8-bit RGB, which must decode.
pub fn read_png(path: &Path) -> goldray::rgb_image::RgbImage {
    goldray::rgb_image::read_png(path).unwrap_or_else(|e| panic!("{e}"))
}
