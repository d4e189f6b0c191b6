//! The pixel values behind a case's pictures, for the page's inspector: every channel of both
//! images as linear `f32` (the EXR is HDR: the page applies the exposure and the tone curve
//! itself, and shows the values under the cursor), the variance of sampled renders and the
//! statistical test's z of each colour value.
//!
//! The page receives it as a script, `goldrayCase(META, "BASE64")`: a script loads from a
//! static page opened from the file system, where a browser refuses `fetch`, and from the
//! review server alike. META names the planes in order; the bytes are the planes one after
//! another, little-endian `f32`, row 0 at the top.

use serde_json::json;

use super::case_review::CaseReview;
use crate::compare::{Encoding, Image, noise};

/// The script that hands the case's values to the page.
pub fn case_script(review: &CaseReview) -> String {
    let mut names = Vec::new();
    let mut bytes = Vec::new();
    let mut plane = |name: String, values: &mut dyn Iterator<Item = f32>| {
        names.push(name);
        for value in values {
            bytes.extend_from_slice(&value.to_le_bytes());
        }
    };
    let sides = [("expected", review.expected.as_ref()), ("actual", Some(&review.actual))];
    for (side, image) in sides {
        let Some(image) = image else { continue };
        for channel in &image.channels {
            plane(format!("{side}.{}", channel.name), &mut channel.values.iter());
        }
        if let Some(variance) = &image.variance {
            for (c, name) in ["R", "G", "B"].iter().enumerate() {
                plane(format!("{side}.var.{name}"), &mut variance.iter().map(|v| v[c]));
            }
        }
    }
    let mut z_critical = None;
    if let (Some(expected), Some(noise)) = (
        review.expected.as_ref(),
        review.comparison.as_ref().and_then(|c| c.noise.as_ref()),
    ) && let Some(z) = z_scores(expected, &review.actual)
    {
        z_critical = Some(noise.z_critical);
        for (c, name) in ["R", "G", "B"].iter().enumerate() {
            plane(
                format!("z.{name}"),
                &mut z.iter().map(|z| z[c].map_or(f32::NAN, |z| z as f32)),
            );
        }
    }
    let image = &review.actual;
    let meta = json!({
        "id": review.id,
        "width": image.width,
        "height": image.height,
        "linear": image.encoding == Encoding::Linear,
        "pixel": review.comparison.as_ref().map(|c| c.tolerance.pixel),
        "zCritical": z_critical,
        // The largest colour difference: where the inspector's readout starts.
        "worst": review
            .comparison
            .as_ref()
            .and_then(|c| c.metrics.as_ref()?.worst)
            .map(|w| [w.x, w.y]),
        "planes": names,
    });
    format!("goldrayCase({meta}, \"{}\");\n", base64(&bytes))
}

fn z_scores(expected: &Image, actual: &Image) -> Option<Vec<[Option<f64>; 3]>> {
    let sigmas = noise::sigmas(expected, actual)?;
    Some(noise::z_scores(expected, actual, &sigmas))
}

/// Standard base64 with padding (RFC 4648), which the page decodes with `atob`.
pub fn base64(bytes: &[u8]) -> String {
    const ALPHABET: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for chunk in bytes.chunks(3) {
        let b = [chunk[0], *chunk.get(1).unwrap_or(&0), *chunk.get(2).unwrap_or(&0)];
        let n = (u32::from(b[0]) << 16) | (u32::from(b[1]) << 8) | u32::from(b[2]);
        for (i, shift) in [18, 12, 6, 0].into_iter().enumerate() {
            if i <= chunk.len() {
                out.push(char::from(ALPHABET[((n >> shift) & 63) as usize]));
            } else {
                out.push('=');
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::base64;

    #[test]
    fn base64_matches_rfc_4648() {
        for (input, output) in [
            ("", ""),
            ("f", "Zg=="),
            ("fo", "Zm8="),
            ("foo", "Zm9v"),
            ("foob", "Zm9vYg=="),
            ("fooba", "Zm9vYmE="),
            ("foobar", "Zm9vYmFy"),
        ] {
            assert_eq!(base64(input.as_bytes()), output);
        }
    }
}
