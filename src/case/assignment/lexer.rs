//! Reading the assignment's token stream the way its parser does.
//!
//! The course reads words with `fscanf("%s")` and numbers with `fscanf("%f")`, so a word is
//! whatever lies between whitespace, while a number is the longest numeric prefix at the cursor
//! and leaves the rest for the next read. That is why `shininess 20}` works there and why it
//! works here: the lexer is a cursor over the text, not a list of tokens made in advance.

use std::path::Path;

use crate::case::error::{CaseError, SourceLocation};

pub(super) type Result<T> = std::result::Result<T, CaseError>;

/// A word or number as written, with its byte offset for messages.
#[derive(Clone, Copy, Debug)]
pub(super) struct Token<'a> {
    pub text: &'a str,
    pub start: usize,
}

/// Three numbers read as one value, each kept so that a message can point at the bad one.
pub(super) struct Vec3<'a> {
    pub value: [f64; 3],
    pub tokens: [Token<'a>; 3],
}

pub(super) struct Lexer<'a> {
    file: &'a Path,
    text: &'a str,
    pos: usize,
}

/// C's `isspace`, which is what separates `%s` words: vertical tab and form feed included.
fn is_space(b: u8) -> bool {
    matches!(b, b' ' | b'\t' | b'\n' | b'\r' | 0x0b | 0x0c)
}

fn digits(bytes: &[u8]) -> usize {
    bytes.iter().take_while(|b| b.is_ascii_digit()).count()
}

/// Length of the decimal number `%f` would convert at the start of `s`: sign, digits with an
/// optional point, and an exponent only when digits follow it.
fn number_prefix(s: &str) -> usize {
    let b = s.as_bytes();
    let mut i = usize::from(matches!(b.first(), Some(b'+' | b'-')));
    let whole = digits(&b[i..]);
    i += whole;
    let mut fraction = 0;
    if b.get(i) == Some(&b'.') {
        fraction = digits(&b[i + 1..]);
        if whole + fraction > 0 {
            i += 1 + fraction;
        }
    }
    if whole + fraction == 0 {
        return 0;
    }
    if matches!(b.get(i), Some(b'e' | b'E')) {
        let sign = usize::from(matches!(b.get(i + 1), Some(b'+' | b'-')));
        let exponent = digits(&b[(i + 1 + sign).min(b.len())..]);
        if exponent > 0 {
            i += 1 + sign + exponent;
        }
    }
    i
}

/// `%f` also reads `inf` and `nan`; they are recognised only to be rejected with a clear reason.
fn is_non_finite_word(s: &str) -> bool {
    let unsigned = s.trim_start_matches(['+', '-']).to_ascii_lowercase();
    unsigned.starts_with("inf") || unsigned.starts_with("nan")
}

impl<'a> Lexer<'a> {
    pub fn new(file: &'a Path, text: &'a str) -> Self {
        Lexer { file, text, pos: 0 }
    }

    pub fn location(&self, offset: usize) -> SourceLocation {
        SourceLocation::from_offset(self.file, self.text, offset)
    }

    pub fn error_at(&self, offset: usize, message: impl Into<String>) -> CaseError {
        CaseError::Invalid {
            location: self.location(offset),
            message: message.into(),
        }
    }

    fn skip_space(&mut self) {
        let rest = &self.text.as_bytes()[self.pos..];
        self.pos += rest.iter().take_while(|b| is_space(**b)).count();
    }

    /// The next word without consuming it; `None` at the end of the file.
    pub fn peek(&mut self) -> Option<Token<'a>> {
        self.skip_space();
        let rest = &self.text[self.pos..];
        let len = rest.bytes().take_while(|b| !is_space(*b)).count();
        (len > 0).then(|| Token {
            text: &rest[..len],
            start: self.pos,
        })
    }

    pub fn word(&mut self) -> Option<Token<'a>> {
        let token = self.peek()?;
        self.pos += token.text.len();
        Some(token)
    }

    /// The next word, where the end of the file is an error; `wanted` says what should be there.
    pub fn word_for(&mut self, wanted: &str) -> Result<Token<'a>> {
        match self.word() {
            Some(token) => Ok(token),
            None => Err(self.unexpected(wanted)),
        }
    }

    /// "expected WANTED, found X" at the cursor, without consuming anything.
    pub fn unexpected(&mut self, wanted: &str) -> CaseError {
        let (offset, found) = match self.peek() {
            Some(token) => (token.start, quote(token.text)),
            None => (self.text.len(), "the end of the file".to_owned()),
        };
        self.error_at(offset, format!("expected {wanted}, found {found}"))
    }

    /// Consumes `word`, which must come next; `context` completes "expected `word` …".
    pub fn expect(&mut self, word: &str, context: &str) -> Result<Token<'a>> {
        match self.peek() {
            Some(token) if token.text == word => {
                self.pos += word.len();
                Ok(token)
            }
            Some(token) if token.text.len() > 1 && token.text.contains(['{', '}']) => Err(self.unexpected(&format!(
                "`{word}` {context} (braces need whitespace around them, except a `}}` \
                     right after a number)"
            ))),
            _ => Err(self.unexpected(&format!("`{word}` {context}"))),
        }
    }

    /// A finite number; `wanted` completes "expected …", e.g. "a number after `radius`".
    pub fn number(&mut self, wanted: &str) -> Result<(f64, Token<'a>)> {
        let Some(word) = self.peek() else {
            return Err(self.unexpected(wanted));
        };
        let len = number_prefix(word.text);
        if len == 0 {
            return Err(if is_non_finite_word(word.text) {
                self.non_finite(word)
            } else {
                self.unexpected(wanted)
            });
        }
        let token = Token {
            text: &word.text[..len],
            start: word.start,
        };
        match token.text.parse::<f64>() {
            Ok(value) if value.is_finite() => {
                self.pos += len;
                Ok((value, token))
            }
            _ => Err(self.non_finite(token)),
        }
    }

    fn non_finite(&self, token: Token) -> CaseError {
        let found = quote(token.text);
        self.error_at(
            token.start,
            format!("expected a finite number, found {found} (NaN and infinity are not allowed)"),
        )
    }

    /// Three numbers, as `readVector3f` reads them; `wanted` completes "expected …".
    pub fn vec3(&mut self, wanted: &str) -> Result<Vec3<'a>> {
        let (x, tx) = self.number(wanted)?;
        let (y, ty) = self.number(wanted)?;
        let (z, tz) = self.number(wanted)?;
        Ok(Vec3 {
            value: [x, y, z],
            tokens: [tx, ty, tz],
        })
    }

    /// A non-negative whole number after `label` (`%d`), for counts and indices.
    pub fn count(&mut self, label: &str) -> Result<(usize, Token<'a>)> {
        let wanted = format!("a whole number after `{label}`");
        let Some(word) = self.peek() else {
            return Err(self.unexpected(&wanted));
        };
        let b = word.text.as_bytes();
        let sign = usize::from(matches!(b.first(), Some(b'+' | b'-')));
        let len = sign + digits(&b[sign..]);
        if len == sign || matches!(b.get(len), Some(b'.' | b'e' | b'E')) {
            return Err(self.unexpected(&wanted));
        }
        let token = Token {
            text: &word.text[..len],
            start: word.start,
        };
        let value = token.text.parse::<i64>().ok().filter(|v| *v >= 0);
        match value.and_then(|v| usize::try_from(v).ok()) {
            Some(v) => {
                self.pos += len;
                Ok((v, token))
            }
            None => Err(self.error_at(
                token.start,
                format!(
                    "`{label}` must be a count ≥ 0 that fits in 64 bits, found `{}`",
                    token.text
                ),
            )),
        }
    }

    /// The text from `first` to the end of `last`, to quote a multi-token value.
    pub fn span_text(&self, first: Token<'a>, last: Token) -> &'a str {
        self.text
            .get(first.start..last.start + last.text.len())
            .unwrap_or(first.text)
    }
}

/// A word in backticks, shortened so that a runaway token cannot flood the message.
pub(super) fn quote(text: &str) -> String {
    const LIMIT: usize = 40;
    if text.chars().count() <= LIMIT {
        format!("`{text}`")
    } else {
        let head: String = text.chars().take(LIMIT - 1).collect();
        format!("`{head}…`")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_follow_scanf() {
        for (text, len) in [
            ("20}", 2),
            ("-.16", 4),
            (".4", 2),
            ("+3.", 3),
            ("1e5}", 3),
            ("1e}", 1),
            ("1e+}", 1),
            ("2.5e-3x", 6),
            ("-", 0),
            (".", 0),
            ("-.e5", 0),
            ("}", 0),
            ("1.2.3", 3),
        ] {
            assert_eq!(number_prefix(text), len, "{text}");
        }
    }

    #[test]
    fn a_number_leaves_what_touches_it_for_the_next_read() {
        let mut lexer = Lexer::new(Path::new("s.txt"), "shininess 20}\n}");
        assert_eq!(lexer.word().unwrap().text, "shininess");
        assert_eq!(lexer.number("a number").unwrap().0, 20.0);
        assert_eq!(lexer.word().unwrap().start, 12);
        assert_eq!(lexer.word().unwrap().start, 14);
        assert!(lexer.word().is_none());
    }

    #[test]
    fn non_finite_and_missing_numbers_are_errors() {
        for text in ["nan", "-inf", "1e999", "Infinity"] {
            let message = Lexer::new(Path::new("s.txt"), text)
                .number("a number")
                .unwrap_err()
                .to_string();
            assert!(message.contains("finite"), "{text}: {message}");
        }
        let message = Lexer::new(Path::new("s.txt"), "  ")
            .number("a number after `radius`")
            .unwrap_err()
            .to_string();
        assert_eq!(
            message,
            "s.txt:1:3: expected a number after `radius`, found the end of the file"
        );
    }

    #[test]
    fn counts_are_whole_and_non_negative() {
        let count = |text: &str| Lexer::new(Path::new("s.txt"), text).count("numObjects").map(|(n, _)| n);
        assert_eq!(count("3}").unwrap(), 3);
        assert!(count("2.5").is_err());
        assert!(count("-1").is_err());
        assert!(count("99999999999999999999").is_err());
        assert!(count("x").is_err());
    }
}
