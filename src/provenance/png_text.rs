//! Provenance in a PNG: one text chunk per entry, right after the header chunk, where every
//! reader meets them before the pixels (`tEXt` for ASCII values, `iTXt`, UTF-8, otherwise).
//! Chunks are self-contained, so splicing them in or out leaves every other byte as it was.

use std::io::Cursor;

use super::{Edit, ProvenanceError};

const SIGNATURE: usize = 8;

/// A chunk's type and where its bytes (length to CRC) start and end.
type Chunk = ([u8; 4], (usize, usize));

/// Each chunk of the file after the signature.
fn chunks(bytes: &[u8], file: &str) -> Result<Vec<Chunk>, ProvenanceError> {
    let mut found = Vec::new();
    let mut at = SIGNATURE;
    while at < bytes.len() {
        let header: Option<([u8; 4], [u8; 4])> = bytes
            .get(at..at + 8)
            .map(|h| (h[..4].try_into().expect("four"), h[4..].try_into().expect("four")));
        let end = header.and_then(|(length, _)| {
            let end = at.checked_add(12)?.checked_add(u32::from_be_bytes(length) as usize)?;
            (end <= bytes.len()).then_some(end)
        });
        let (Some((_, kind)), Some(end)) = (header, end) else {
            return Err(ProvenanceError::Png {
                file: file.to_owned(),
                reason: format!("its chunk at byte {at} is truncated"),
            });
        };
        found.push((kind, (at, end)));
        at = end;
    }
    Ok(found)
}

/// The keyword of a text chunk (`tEXt`, `zTXt`, `iTXt` all start with it), or `None` for any
/// other chunk.
fn keyword(bytes: &[u8], kind: [u8; 4], span: (usize, usize)) -> Option<&[u8]> {
    if !matches!(&kind, b"tEXt" | b"zTXt" | b"iTXt") {
        return None;
    }
    let data = &bytes[span.0 + 8..span.1 - 4];
    data.split(|&b| b == 0).next()
}

/// One chunk's bytes: length, type, data, CRC of type and data.
fn chunk(kind: &[u8; 4], data: &[u8]) -> Vec<u8> {
    let mut crc = crc32fast::Hasher::new();
    crc.update(kind);
    crc.update(data);
    let mut out = Vec::with_capacity(data.len() + 12);
    out.extend_from_slice(&(data.len() as u32).to_be_bytes());
    out.extend_from_slice(kind);
    out.extend_from_slice(data);
    out.extend_from_slice(&crc.finalize().to_be_bytes());
    out
}

/// The text chunk for one entry.
fn text_chunk(name: &str, value: &str) -> Vec<u8> {
    let mut data = name.as_bytes().to_vec();
    if value.bytes().all(|b| b.is_ascii() && b != 0) {
        data.push(0);
        data.extend_from_slice(value.as_bytes());
        chunk(b"tEXt", &data)
    } else {
        // Uncompressed, no language tag, no translated keyword.
        data.extend_from_slice(&[0, 0, 0, 0, 0]);
        data.extend_from_slice(value.as_bytes());
        chunk(b"iTXt", &data)
    }
}

/// Every uncompressed text entry before the pixels, as the png crate decodes them.
pub(super) fn read(bytes: &[u8], file: &str) -> Result<Vec<(String, String)>, ProvenanceError> {
    let fail = |error: png::DecodingError| ProvenanceError::Png {
        file: file.to_owned(),
        reason: error.to_string(),
    };
    let reader = png::Decoder::new(Cursor::new(bytes)).read_info().map_err(fail)?;
    let info = reader.info();
    let mut entries: Vec<(String, String)> = info
        .uncompressed_latin1_text
        .iter()
        .map(|t| (t.keyword.clone(), t.text.clone()))
        .collect();
    for text in &info.utf8_text {
        entries.push((text.keyword.clone(), text.get_text().map_err(fail)?));
    }
    Ok(entries)
}

/// The file without the text chunks of `edit.group`, and with `edit.entries` in text chunks
/// right after the header chunk, in their order.
pub(super) fn replace(bytes: &[u8], file: &str, edit: &Edit) -> Result<Vec<u8>, ProvenanceError> {
    let Edit { group, entries } = *edit;
    let chunks = chunks(bytes, file)?;
    let Some((b"IHDR", header)) = chunks.first().map(|(kind, span)| (kind, *span)) else {
        return Err(ProvenanceError::Png {
            file: file.to_owned(),
            reason: "it does not start with its header chunk".to_owned(),
        });
    };
    let mut out = Vec::with_capacity(bytes.len() + 48 * entries.len());
    out.extend_from_slice(&bytes[..header.1]);
    for (name, value) in entries {
        out.extend(text_chunk(name, value));
    }
    for &(kind, span) in &chunks[1..] {
        let removed = keyword(bytes, kind, span)
            .and_then(|k| std::str::from_utf8(k).ok())
            .is_some_and(|k| group.contains(k));
        if !removed {
            out.extend_from_slice(&bytes[span.0..span.1]);
        }
    }
    Ok(out)
}
