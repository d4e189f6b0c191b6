//! The end of a stream: what a command printed last is what explains how it failed.

use std::collections::VecDeque;

/// Keeps the last `keep` bytes of everything pushed, and counts it all.
#[derive(Debug)]
pub struct Tail {
    keep: usize,
    bytes: VecDeque<u8>,
    total: u64,
}

impl Tail {
    pub fn new(keep: usize) -> Tail {
        Tail {
            keep,
            bytes: VecDeque::with_capacity(keep.min(64 << 10)),
            total: 0,
        }
    }

    pub fn push(&mut self, chunk: &[u8]) {
        self.total += chunk.len() as u64;
        let chunk = &chunk[chunk.len().saturating_sub(self.keep)..];
        let overflow = (self.bytes.len() + chunk.len()).saturating_sub(self.keep);
        self.bytes.drain(..overflow);
        self.bytes.extend(chunk);
    }

    pub fn total(&self) -> u64 {
        self.total
    }

    /// The kept bytes as text, invalid UTF-8 (a character cut in two at the start, binary
    /// output) replaced.
    pub fn text(&self) -> String {
        let (a, b) = self.bytes.as_slices();
        String::from_utf8_lossy(&[a, b].concat()).into_owned()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keeps_the_last_bytes_and_counts_them_all() {
        let mut tail = Tail::new(8);
        tail.push(b"hello ");
        tail.push(b"world");
        assert_eq!(tail.text(), "lo world");
        tail.push(&[b'x'; 100]);
        assert_eq!(tail.text(), "xxxxxxxx");
        assert_eq!(tail.total(), 111);
        let mut empty = Tail::new(0);
        empty.push(b"abc");
        assert_eq!((empty.text().as_str(), empty.total()), ("", 3));
    }
}
