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

/// What `%f` makes of the text at the cursor (glibc's `scanf`, which the course binary uses).
#[derive(Debug, PartialEq)]
enum Scanned {
    /// A number: how many bytes `%f` consumes, and the value.
    Number(usize, f64),
    /// `inf`, `infinity` or `nan` (any case, signed), which `%f` reads too.
    NonFinite(usize),
    /// Nothing `%f` converts: the course's `readFloat` fails its assert.
    Nothing,
}

fn hex_digits(bytes: &[u8]) -> usize {
    bytes.iter().take_while(|b| b.is_ascii_hexdigit()).count()
}

/// `%f` at the start of `s`, byte for byte as glibc reads it: an optional sign, then a decimal
/// number (`4`, `4.`, `.4`), a hexadecimal one (`0x1.8p1`) or `inf`/`nan`. An exponent marker
/// is consumed even when no digits follow it (`1e}` reads as 1 and leaves `}`), while a
/// decimal point needs a digit on one side. What follows the number is left for the next read.
fn scan_float(s: &str) -> Scanned {
    let b = s.as_bytes();
    let sign = usize::from(matches!(b.first(), Some(b'+' | b'-')));
    let negative = b.first() == Some(&b'-');
    let rest = &b[sign..];
    let lower = |n: usize| rest.get(..n).map(<[u8]>::to_ascii_lowercase);
    if lower(8).as_deref() == Some(b"infinity") {
        return Scanned::NonFinite(sign + 8);
    }
    if matches!(lower(3).as_deref(), Some(b"inf" | b"nan")) {
        return Scanned::NonFinite(sign + 3);
    }
    let (len, magnitude) = if lower(2).as_deref() == Some(b"0x") {
        match scan_hex(&rest[2..]) {
            Some((len, value)) => (2 + len, value),
            None => return Scanned::Nothing,
        }
    } else {
        match scan_decimal(rest) {
            Some(scanned) => scanned,
            None => return Scanned::Nothing,
        }
    };
    Scanned::Number(sign + len, if negative { -magnitude } else { magnitude })
}

/// A decimal number without its sign; `None` when there is no digit before the exponent.
fn scan_decimal(b: &[u8]) -> Option<(usize, f64)> {
    let whole = digits(b);
    let mut len = whole;
    let mut fraction = 0;
    if b.get(len) == Some(&b'.') {
        fraction = digits(&b[len + 1..]);
        len += 1 + fraction;
    }
    if whole + fraction == 0 {
        return None;
    }
    let mantissa_len = len;
    let mut exponent_len = 0;
    if matches!(b.get(len), Some(b'e' | b'E')) {
        let sign = usize::from(matches!(b.get(len + 1), Some(b'+' | b'-')));
        exponent_len = digits(&b[len + 1 + sign..]);
        len += 1 + sign + exponent_len;
    }
    // Without exponent digits, the marker (and its sign) is consumed but means nothing.
    let number = if exponent_len > 0 {
        &b[..len]
    } else {
        &b[..mantissa_len]
    };
    let value = std::str::from_utf8(number).ok()?.parse::<f64>().ok()?;
    Some((len, value))
}

/// The digits of a hexadecimal number after its `0x`: hex digits with an optional point, then
/// an optional binary exponent `p±d`. glibc takes `0x.` alone as zero (and then leaves a `p`).
fn scan_hex(b: &[u8]) -> Option<(usize, f64)> {
    let whole = hex_digits(b);
    let mut len = whole;
    let mut fraction = 0;
    let point = b.get(len) == Some(&b'.');
    if point {
        fraction = hex_digits(&b[len + 1..]);
        len += 1 + fraction;
    }
    if whole + fraction == 0 {
        return point.then_some((len, 0.0));
    }
    // Keep the first 15 significant digits (60 bits, more than an f64 holds); each dropped
    // digit of the whole part scales by 16, a dropped fraction digit only loses precision.
    let mut mantissa: u64 = 0;
    let mut scale: i64 = 0;
    for (i, digit) in b[..len].iter().filter(|d| **d != b'.').enumerate() {
        let value = u64::from((*digit as char).to_digit(16).unwrap_or(0));
        if mantissa < 1 << 56 {
            mantissa = mantissa * 16 + value;
            if i >= whole {
                scale -= 4;
            }
        } else if i < whole {
            scale += 4;
        }
    }
    if matches!(b.get(len), Some(b'p' | b'P')) {
        let sign = usize::from(matches!(b.get(len + 1), Some(b'+' | b'-')));
        let count = digits(&b[len + 1 + sign..]);
        let written = &b[len + 1 + sign..len + 1 + sign + count];
        // Saturated: any exponent past ±100,000 is already far beyond zero or infinity.
        let exponent = written
            .iter()
            .fold(0i64, |e, d| (e * 10 + i64::from(d - b'0')).min(100_000));
        scale += if b.get(len + 1) == Some(&b'-') {
            -exponent
        } else {
            exponent
        };
        len += 1 + sign + count;
    }
    Some((len, scale_by_power_of_two(mantissa as f64, scale)))
}

/// `value · 2^exponent` without the intermediate overflow or underflow of one big power.
fn scale_by_power_of_two(mut value: f64, mut exponent: i64) -> f64 {
    while exponent != 0 && value != 0.0 && value.is_finite() {
        let step = exponent.clamp(-1000, 1000);
        value *= 2f64.powi(step as i32);
        exponent -= step;
    }
    value
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
        let hint = self.peek().map_or("", |token| comment_hint(token.text));
        self.error_at(offset, format!("expected {wanted}, found {found}{hint}"))
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

    /// A number as `%f` reads it; `wanted` completes "expected …", e.g. "a number after
    /// `radius`". It must be finite as the course's `float`: `nan`, `inf` and values beyond
    /// single precision read as non-finite there and make no picture.
    pub fn number(&mut self, wanted: &str) -> Result<(f64, Token<'a>)> {
        let Some(word) = self.peek() else {
            return Err(self.unexpected(wanted));
        };
        let (len, value) = match scan_float(word.text) {
            Scanned::Number(len, value) => (len, Some(value)),
            Scanned::NonFinite(len) => (len, None),
            Scanned::Nothing => return Err(self.unexpected(wanted)),
        };
        let token = Token {
            text: &word.text[..len],
            start: word.start,
        };
        match value {
            Some(value) if (value as f32).is_finite() => {
                self.pos += len;
                Ok((value, token))
            }
            Some(_) => Err(self.error_at(
                token.start,
                format!(
                    "{} is beyond single precision: the course reads numbers as `float`, where it \
                     is infinite (the largest is about 3.4e38)",
                    quote(token.text)
                ),
            )),
            None => Err(self.non_finite(token)),
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

    /// A non-negative whole number after `label`, as `%d` reads it, for counts and indices.
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
        // The course reads counts with `%d` into an `int`: a larger one wraps around, and a
        // negative one silently means none (and `numLights -1` keeps the ambient light as
        // written, where `numLights 0` makes it white). Both are refused.
        let value = token
            .text
            .parse::<i64>()
            .ok()
            .filter(|v| *v >= 0 && *v <= i64::from(i32::MAX));
        match value.and_then(|v| usize::try_from(v).ok()) {
            Some(v) => {
                self.pos += len;
                Ok((v, token))
            }
            None => Err(self.error_at(
                token.start,
                format!(
                    "`{label}` must be a whole number from 0 to {} (a C `int`), found `{}`",
                    i32::MAX,
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

/// Said when a word looks like the start of a comment, which the course's format does not have:
/// its binary reads `#` or `//` as a word and stops ("Unknown token", or an assert).
pub(super) fn comment_hint(word: &str) -> &'static str {
    if word.starts_with('#') || word.starts_with("//") {
        " (the course's scene format has no comments)"
    } else {
        ""
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

    /// Each row is what glibc's `fscanf("%f")` consumed and converted, recorded with a C
    /// program on glibc 2.36 (the course binary links the system's glibc).
    #[test]
    fn numbers_follow_glibc_scanf() {
        use Scanned::{NonFinite, Nothing, Number};
        for (text, expected) in [
            ("20}", Number(2, 20.0)),
            ("-.16", Number(4, -0.16)),
            (".4", Number(2, 0.4)),
            ("4.", Number(2, 4.0)),
            ("+3.", Number(3, 3.0)),
            ("-0", Number(2, -0.0)),
            ("00.5", Number(4, 0.5)),
            ("1e-3", Number(4, 1e-3)),
            ("1e0010", Number(6, 1e10)),
            ("1.e5", Number(4, 1e5)),
            ("1e5}", Number(3, 1e5)),
            ("1e5e5", Number(3, 1e5)),
            ("2.5e-3x", Number(6, 2.5e-3)),
            ("1.2.3", Number(3, 1.2)),
            ("1,5", Number(1, 1.0)),
            // An exponent marker without digits is consumed and ignored.
            ("1e}", Number(2, 1.0)),
            ("1e+}", Number(3, 1.0)),
            ("1E-", Number(3, 1.0)),
            ("0e", Number(2, 0.0)),
            ("1ex", Number(2, 1.0)),
            // Hexadecimal, as C99 and glibc read it.
            ("0x1.8p1", Number(7, 3.0)),
            ("-0x1p3}", Number(6, -8.0)),
            ("0X.8", Number(4, 0.5)),
            ("0x1e3", Number(5, 483.0)),
            ("0xABCDEF", Number(8, 11_259_375.0)),
            ("0x1P-2", Number(6, 0.25)),
            ("0x1p}", Number(4, 1.0)),
            ("0x1p+}", Number(5, 1.0)),
            ("0x1.", Number(4, 1.0)),
            ("0x.8p", Number(5, 0.5)),
            ("0x.}", Number(3, 0.0)),
            ("0x.p1", Number(3, 0.0)),
            ("0x1ffffffffffffffffffffp0", Number(25, 2.417_851_639_229_258_3e24)),
            ("inf", NonFinite(3)),
            ("-INF", NonFinite(4)),
            ("infinity", NonFinite(8)),
            ("nan(123)", NonFinite(3)),
            ("NaN", NonFinite(3)),
            ("-", Nothing),
            ("+", Nothing),
            (".", Nothing),
            ("+-1", Nothing),
            ("-.e5", Nothing),
            (".e5", Nothing),
            ("0x", Nothing),
            ("0x}", Nothing),
            ("0xg", Nothing),
            ("0xp1", Nothing),
            ("in", Nothing),
            ("}", Nothing),
        ] {
            assert_eq!(scan_float(text), expected, "{text}");
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
        for text in ["nan", "-inf", "1e999", "Infinity", "1e39", "-0x1p128"] {
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
        assert_eq!(count("+3").unwrap(), 3);
        assert_eq!(count("-0").unwrap(), 0);
        assert_eq!(count("2147483647").unwrap(), 2_147_483_647);
        assert!(count("2147483648").is_err(), "wraps around in a C int");
        assert!(count("-1").is_err());
        assert!(count("99999999999999999999").is_err());
        assert!(count("x").is_err());
    }
}
