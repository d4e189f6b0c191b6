//! The review page's HTML: a bar of view controls, then one section per case that leads with
//! what changed (verdict, the numbers that decided it, how the two files were made
//! differently) above the golden, the new render and the heatmap side by side, and an inspector
//! to swipe or flip between them and read the values under the cursor.
//!
//! The page is self-contained: inline CSS and script, pictures and pixel values from the
//! review server, from files beside it, or inside it (see [`Resources`]); it works offline and
//! from the file system. Every text that came from a file (descriptions, provenance values,
//! paths, messages) is escaped.

use std::collections::BTreeSet;
use std::fmt::Write as _;

use super::case_review::CaseReview;
use crate::compare::{Comparison, Encoding, Verdict};
pub use crate::html_escape::escape;
use crate::provenance::Provenance;

const STYLE: &str = include_str!("page.css");
const SCRIPT: &str = include_str!("page.js");

/// Where the page finds each case's pictures and values.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Resources {
    /// `img/ID.*.png` and `data/ID.js` beside the page, from the server or a folder.
    Linked,
    /// Inside the page: PNGs as `data:` URIs and the values as inline scripts (one file).
    Embedded,
}

/// One case's parts as the page needs them.
pub struct CaseParts<'a> {
    pub review: &'a CaseReview,
    /// `(expected, actual, heatmap)` sources for `<img src>`.
    pub sources: [Option<String>; 3],
    /// The inline script (embedded pages) or the path of the script file (linked ones).
    pub data: String,
}

/// What the page says above the cases.
pub struct Heading {
    pub title: String,
    /// Lines under the title (what was skipped and why, where the decisions go).
    pub notes: Vec<String>,
    /// Accept and reject buttons, which post to the server the page came from.
    pub decisions: bool,
}

pub fn page(heading: &Heading, cases: &[CaseParts], resources: Resources) -> String {
    let mut body = String::new();
    let any = |f: fn(&CaseReview) -> bool| cases.iter().any(|c| f(c.review));
    let _ = write!(
        body,
        "<header class=\"bar\"><h1>{}</h1>\n\
         <label>Channel <select id=\"channel\"><option value=\"color\">colour</option>\
         <option value=\"depth\"{}>depth</option><option value=\"normal\"{}>normals</option>\
         <option value=\"variance\"{}>variance</option><option value=\"z\"{}>z-evidence</option></select></label>\n\
         <label>Exposure <input type=\"range\" id=\"exposure\" min=\"-10\" max=\"10\" step=\"0.25\" value=\"0\">\
         <output id=\"exposure-value\">+0 EV</output></label>\n\
         <label>Inspector <select id=\"mode\"><option value=\"swipe\">swipe</option>\
         <option value=\"flip\">flip (F)</option><option value=\"diff\">difference</option></select></label>\n",
        escape(&heading.title),
        disabled(!any(|r| has_channel(r, "Z"))),
        disabled(!any(|r| has_channel(r, "N.X"))),
        disabled(!any(|r| r.actual.variance.is_some())),
        disabled(!any(|r| r.comparison.as_ref().is_some_and(|c| c.noise.is_some()))),
    );
    if heading.decisions && !cases.is_empty() {
        body.push_str("<button id=\"accept-all\" class=\"accept\">Accept all</button>\n");
    }
    body.push_str("</header>\n");
    for note in &heading.notes {
        let _ = writeln!(body, "<p class=\"note\">{}</p>", escape(note));
    }
    if cases.is_empty() {
        body.push_str("<p class=\"empty\">Nothing to review: no pending golden.</p>\n");
    }
    body.push_str("<main>\n");
    for case in cases {
        section(&mut body, case, heading.decisions);
    }
    body.push_str("</main>\n");
    let _ = writeln!(body, "<script>{SCRIPT}</script>");
    for case in cases {
        match resources {
            Resources::Linked => {
                let _ = writeln!(body, "<script src=\"{}\"></script>", escape(&case.data));
            }
            Resources::Embedded => {
                let _ = writeln!(body, "<script>{}</script>", case.data);
            }
        }
    }
    format!(
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n\
         <meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n\
         <meta http-equiv=\"Content-Security-Policy\" content=\"default-src 'none'; script-src 'self' 'unsafe-inline' file:; \
         style-src 'unsafe-inline'; img-src 'self' data: file:; connect-src 'self'\">\n\
         <title>{}</title>\n<style>{STYLE}</style>\n</head>\n<body data-cases=\"{}\" data-decisions=\"{}\">\n{body}</body>\n</html>\n",
        escape(&heading.title),
        cases.len(),
        heading.decisions,
    )
}

fn section(body: &mut String, case: &CaseParts, decisions: bool) {
    let review = case.review;
    let id = &review.id;
    let word = review.verdict_word();
    let _ = write!(
        body,
        "<section class=\"case v-{}\" id=\"case-{id}\" data-case=\"{id}\">\n<h2>{} <span class=\"badge\">{word}</span>\
         <span class=\"status\"></span></h2>\n",
        word.to_lowercase(),
        escape(&review.title),
    );
    if decisions {
        let _ = writeln!(
            body,
            "<div class=\"actions\"><button class=\"accept\" data-action=\"accept\" data-case=\"{id}\">Accept</button>\
             <button class=\"reject\" data-action=\"reject\" data-case=\"{id}\">Reject</button></div>"
        );
    }
    if let Some(description) = &review.description {
        let _ = writeln!(body, "<p class=\"desc\">{}</p>", escape(description));
    }
    if let Some(comparison) = &review.comparison {
        numbers(body, comparison);
    }
    for note in &review.notes {
        let _ = writeln!(body, "<p class=\"note\">{}</p>", escape(note));
    }
    if let Some(line) = &review.made_differently {
        let _ = writeln!(body, "<p class=\"made\"><b>made differently</b> {}</p>", escape(line));
    }
    provenance(body, review);
    let [expected, actual, heatmap] = &case.sources;
    let _ = write!(
        body,
        "<div class=\"panes\">\n{}{}{}</div>\n",
        figure(
            "expected",
            expected.as_deref(),
            &format!("golden · {}", review.expected_file)
        ),
        figure(
            "actual",
            actual.as_deref(),
            &format!("new render · {}", review.actual_file)
        ),
        figure("diff", heatmap.as_deref(), heatmap_caption(review)),
    );
    body.push_str(
        "<div class=\"inspector\"><div class=\"view-wrap\"><canvas class=\"view\" role=\"img\"></canvas>\
         <input type=\"range\" class=\"swipe\" min=\"0\" max=\"1\" step=\"0.001\" value=\"0.5\" aria-label=\"swipe\"></div>\
         <div class=\"side\"><p class=\"hint\"><output class=\"zoom\"></output> · wheel: zoom · drag: pan · \
         double-click: fit · F: flip</p>\
         <table class=\"readout\"></table></div></div>\n",
    );
    if let Some(comparison) = &review.comparison {
        let _ = writeln!(
            body,
            "<details class=\"report\"><summary>the suite's report (tolerance from {})</summary><pre>{}</pre></details>",
            escape(&review.tolerance_from),
            escape(&comparison.to_string())
        );
    }
    body.push_str("</section>\n");
}

/// The figures that decided the verdict, each beside its limit.
fn numbers(body: &mut String, comparison: &Comparison) {
    body.push_str("<ul class=\"numbers\">");
    if let Verdict::Fail { breaches } = &comparison.verdict {
        for breach in breaches {
            let _ = write!(body, "<li class=\"breach\">broke {}</li>", escape(&breach.to_string()));
        }
    }
    if let Verdict::Mismatch { expected, actual } = &comparison.verdict {
        let _ = write!(
            body,
            "<li class=\"breach\">cannot compare: golden {}x{} {}, new render {}x{} {}</li>",
            expected.width,
            expected.height,
            expected.channels.join(" "),
            actual.width,
            actual.height,
            actual.channels.join(" ")
        );
    }
    let t = &comparison.tolerance;
    if let Some(m) = &comparison.metrics {
        let units = if m.encoding == Encoding::Linear { "" } else { " codes" };
        let _ = write!(
            body,
            "<li><b>{:.3}%</b> of pixels fail (limit {:.3}%; a pixel fails beyond {}{units})</li>",
            m.failing_fraction * 100.0,
            t.fail_fraction * 100.0,
            t.pixel
        );
        let rmse_limit = if comparison.noise.is_some() {
            "not judged on a sampled case".to_owned()
        } else {
            format!("limit {}", t.rmse)
        };
        let _ = write!(body, "<li>RMSE <b>{:.5}</b> ({rmse_limit})</li>", m.rmse);
        let _ = write!(body, "<li>FLIP <b>{:.4}</b></li>", m.flip);
        if let Some(worst) = &m.worst {
            let _ = write!(body, "<li>largest: {}</li>", escape(&worst.to_string()));
        }
    }
    if let Some(noise) = &comparison.noise {
        let _ = write!(
            body,
            "<li>statistical: <b>{}</b> of {} colour values significant (|z| over {:.2}, α {})</li>",
            noise.significant, noise.tests, noise.z_critical, noise.alpha
        );
        let p = &noise.power;
        let shift = |s: Option<f64>| s.map_or_else(|| "none".to_owned(), |s| format!("{s:.2e}"));
        let _ = write!(
            body,
            "<li>power: {:.0}% to see a shift of {} everywhere, {} over {}×{} pixels</li>",
            p.probability * 100.0,
            shift(p.uniform_shift),
            shift(p.local_shift_median),
            p.window,
            p.window
        );
    }
    body.push_str("</ul>\n");
}

/// Both files' provenance side by side, the rows that differ marked.
fn provenance(body: &mut String, review: &CaseReview) {
    let [golden, render] = &review.provenance;
    let keys: BTreeSet<&str> = [golden, render]
        .into_iter()
        .flatten()
        .flat_map(|p| p.entries().map(|(k, _)| k))
        .collect();
    if keys.is_empty() {
        return;
    }
    body.push_str(
        "<details class=\"provenance\"><summary>provenance</summary><table><tr><th></th><th>golden</th>\
         <th>new render</th></tr>",
    );
    for key in keys {
        let (a, b) = (value(golden, key), value(render, key));
        let _ = write!(
            body,
            "<tr{}><th>{}</th><td>{}</td><td>{}</td></tr>",
            if a == b { "" } else { " class=\"differs\"" },
            escape(key),
            escape(a),
            escape(b)
        );
    }
    body.push_str("</table></details>\n");
}

/// One provenance entry, or a dash where the file has none.
fn value<'a>(provenance: &'a Option<Provenance>, key: &str) -> &'a str {
    provenance.as_ref().and_then(|p| p.get(key)).unwrap_or("—")
}

fn figure(side: &str, source: Option<&str>, caption: &str) -> String {
    let picture = match source {
        Some(source) => format!(
            "<img class=\"picture\" src=\"{}\" alt=\"{side}\"><canvas class=\"pane\" data-side=\"{side}\"></canvas>",
            escape(source)
        ),
        None => format!("<div class=\"missing\">none</div><canvas class=\"pane\" data-side=\"{side}\"></canvas>"),
    };
    format!(
        "<figure class=\"{side}\">{picture}<figcaption>{}</figcaption></figure>\n",
        escape(caption)
    )
}

fn heatmap_caption(review: &CaseReview) -> &'static str {
    match review.comparison.as_ref().map(|c| c.noise.is_some()) {
        Some(true) => "evidence · |z| from 1 (dark red) to the threshold (yellow); magenta significant or failing",
        Some(false) => "difference · a thousandth of the threshold (red) to the threshold (yellow); magenta fails",
        None => "difference · no golden to compare with",
    }
}

fn has_channel(review: &CaseReview, name: &str) -> bool {
    review.actual.channels.iter().any(|c| c.name == name)
}

fn disabled(yes: bool) -> &'static str {
    if yes { " disabled" } else { "" }
}
