//! Provenance in an EXR header: `string` attributes spliced into (or cut out of) the header of a
//! single-part file, with the chunk offset table shifted to match.
//!
//! A header is the magic number, a version word, then attributes (`name\0type\0` a little-endian
//! `i32` size and the value) ended by an empty name; the offset table that follows holds the
//! absolute file position of each chunk, `chunkCount` of them.

use super::{Edit, ProvenanceError};

/// Version-word flags of files this splicer refuses: deep data, and several parts (one header
/// and offset table each).
const DEEP: u32 = 0x800;
const MULTI_PART: u32 = 0x1000;

/// The longest attribute name or type any EXR may hold (with the long-names flag).
const MAX_NAME: usize = 255;

struct Attribute<'a> {
    /// Where the attribute's bytes start and end in the file.
    span: (usize, usize),
    name: &'a [u8],
    kind: &'a [u8],
    value: &'a [u8],
}

struct Header<'a> {
    attributes: Vec<Attribute<'a>>,
    /// The position of the empty name that ends the header.
    end: usize,
}

fn parse<'a>(bytes: &'a [u8], file: &str) -> Result<Header<'a>, ProvenanceError> {
    let bad = |reason: &str| ProvenanceError::Exr {
        file: file.to_owned(),
        reason: reason.to_owned(),
    };
    let truncated = || bad("its header is truncated");
    let word = |at: usize| -> Option<[u8; 4]> { bytes.get(at..at + 4)?.try_into().ok() };
    let flags = u32::from_le_bytes(word(4).ok_or_else(truncated)?);
    if flags & (DEEP | MULTI_PART) != 0 {
        return Err(bad("it is a deep or multi-part file"));
    }
    let name_at = |at: usize| -> Result<&'a [u8], ProvenanceError> {
        let rest = bytes.get(at..).ok_or_else(truncated)?;
        let length = rest
            .iter()
            .take(MAX_NAME + 1)
            .position(|&b| b == 0)
            .ok_or_else(truncated)?;
        Ok(&rest[..length])
    };
    let mut attributes = Vec::new();
    let mut at = 8;
    loop {
        let name = name_at(at)?;
        if name.is_empty() {
            return Ok(Header { attributes, end: at });
        }
        let kind = name_at(at + name.len() + 1)?;
        let size_at = at + name.len() + kind.len() + 2;
        let size = i32::from_le_bytes(word(size_at).ok_or_else(truncated)?);
        let size = usize::try_from(size).map_err(|_| bad("an attribute has a negative size"))?;
        let value_at = size_at + 4;
        let value = bytes.get(value_at..value_at + size).ok_or_else(truncated)?;
        attributes.push(Attribute {
            span: (at, value_at + size),
            name,
            kind,
            value,
        });
        at = value_at + size;
    }
}

/// Every `string` attribute of the (first) header, as text.
pub(super) fn read(bytes: &[u8], file: &str) -> Result<Vec<(String, String)>, ProvenanceError> {
    Ok(parse(bytes, file)?
        .attributes
        .iter()
        .filter(|a| a.kind == b"string")
        .map(|a| {
            (
                String::from_utf8_lossy(a.name).into_owned(),
                String::from_utf8_lossy(a.value).into_owned(),
            )
        })
        .collect())
}

/// The file without the attributes of `edit.group`, and with `edit.entries` added as `string`
/// attributes at the end of the header, in their order.
pub(super) fn replace(bytes: &[u8], file: &str, edit: &Edit) -> Result<Vec<u8>, ProvenanceError> {
    let Edit { group, entries } = *edit;
    let bad = |reason: &str| ProvenanceError::Exr {
        file: file.to_owned(),
        reason: reason.to_owned(),
    };
    let header = parse(bytes, file)?;
    let chunks = header
        .attributes
        .iter()
        .find(|a| a.name == b"chunkCount" && a.kind == b"int" && a.value.len() == 4)
        .map(|a| i32::from_le_bytes([a.value[0], a.value[1], a.value[2], a.value[3]]))
        .and_then(|count| usize::try_from(count).ok())
        .ok_or_else(|| bad("its header has no chunkCount"))?;

    let mut out = Vec::with_capacity(bytes.len() + 64 * entries.len());
    out.extend_from_slice(&bytes[..8]);
    for attribute in &header.attributes {
        let removed = std::str::from_utf8(attribute.name).is_ok_and(|name| group.contains(name));
        if !removed {
            out.extend_from_slice(&bytes[attribute.span.0..attribute.span.1]);
        }
    }
    for (name, value) in entries {
        let size = i32::try_from(value.len()).map_err(|_| bad("a provenance value is over 2 GiB"))?;
        out.extend_from_slice(name.as_bytes());
        out.extend_from_slice(b"\0string\0");
        out.extend_from_slice(&size.to_le_bytes());
        out.extend_from_slice(value.as_bytes());
    }
    out.push(0);

    let table = header.end + 1;
    let table_end = chunks
        .checked_mul(8)
        .and_then(|length| table.checked_add(length))
        .filter(|&end| end <= bytes.len())
        .ok_or_else(|| bad("its chunk offset table is truncated"))?;
    let shift = out.len() as i64 - table as i64;
    for entry in bytes[table..table_end].chunks_exact(8) {
        let offset = u64::from_le_bytes(entry.try_into().expect("eight bytes"));
        let moved = i64::try_from(offset)
            .ok()
            .and_then(|offset| offset.checked_add(shift))
            .and_then(|offset| u64::try_from(offset).ok())
            .ok_or_else(|| bad("a chunk offset is out of range"))?;
        out.extend_from_slice(&moved.to_le_bytes());
    }
    out.extend_from_slice(&bytes[table_end..]);
    Ok(out)
}
