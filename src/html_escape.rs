//! Escaping text for the self-contained HTML pages goldray writes (the grading report, the golden
//! review): one function, so that every page escapes student- and file-supplied text alike.

/// Text and attribute values alike: `&`, `<`, `>`, `"` and `'` become entities.
pub fn escape(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            c => out.push(c),
        }
    }
    out
}
