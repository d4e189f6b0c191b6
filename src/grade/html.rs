//! The HTML report: `index.html` with the class table, and one page per student with golden,
//! student and diff pictures side by side, the images that lost points first.
//!
//! Pages are self-contained (inline CSS and a few lines of inline script, relative links) so that
//! the report opens from the file system, from a zip, or from a web server alike, with no network.
//! Every string that came from a student (folder names, file paths, decoder messages that quote
//! them) is escaped; rubric file names are restricted to URL-safe characters when loaded.

use std::fmt::Write as _;
use std::path::Path;

mod download;
mod mistakes;
mod program;

use super::golden::GOLDEN_DIR;
use super::judge::{format_points, percent};
use super::outcome::Outcome;
use super::report::{ClassReport, flags};
use super::score::{ImageResult, StudentResult};
use crate::atomic_write::{replace_file, write_file_atomic};
use crate::compare::Metrics;
use crate::film::OutputError;
pub use crate::html_escape::escape;

const STYLE: &str = r#"
body{font:14px/1.4 system-ui,sans-serif;margin:1.5em;color:#222;background:#fafafa}
h1{font-size:1.5em;margin:0 0 .3em}h2{font-size:1.15em;margin:0 0 .4em}
a{color:#1a5fb4}.muted{color:#666}
table{border-collapse:collapse;background:#fff}
th,td{border:1px solid #ccc;padding:.25em .5em;text-align:center}td a{color:inherit}
th{background:#eee;font-weight:600;vertical-align:bottom}td.name{text-align:left}
.scroll{overflow-x:auto;max-width:100%}
#grades .name{position:sticky;left:0;z-index:1;background:#fff;box-shadow:1px 0 0 #ccc}
#grades th.name{background:#eee}
#grades td.lost{text-align:left;min-width:12em;max-width:24em;font-size:.9em}
img.thumb{display:block;width:48px;height:48px;margin:.2em auto 0;object-fit:contain}
.v-pass{background:#c8e6c9}.v-partial{background:#ffe0a3}.v-fail{background:#f4b4b4}
.v-missing,.v-wrong-size,.v-wrong-format,.v-too-large,.v-unreadable,.v-linked{background:#d7c8ee}
.flag{background:#fff3cd;border:1px solid #e0b000;padding:.1em .4em;border-radius:.3em}
.badge{display:inline-block;padding:0 .5em;border-radius:.8em;font-size:.85em;font-weight:600}
.chips{display:flex;flex-wrap:wrap;gap:.3em}.chips a{color:#222;text-decoration:none}
section.image{background:#fff;border:1px solid #ccc;border-left-width:6px;margin:1em 0;padding:.8em}
section.v-pass{border-left-color:#2e7d32}section.v-partial{border-left-color:#e69500}
section.v-fail{border-left-color:#c62828}section.image:not(.v-pass):not(.v-partial):not(.v-fail){border-left-color:#6a3fb5}
.panes{display:flex;gap:1em;flex-wrap:wrap}
figure{margin:0}figcaption{font-size:.85em;color:#555}
figure img,.empty{display:block;width:300px;height:300px;object-fit:contain;background:#ddd}
.empty{display:flex;align-items:center;justify-content:center;color:#555;text-align:center}
.flip .golden{display:none}.flip:hover .golden{display:block}.flip:hover .student{display:none}
table.metrics{margin-top:.6em;font-size:.9em}table.metrics th,table.metrics td{text-align:left}
img.broken{outline:3px solid #c62828}
"#;

/// Counts the pictures that loaded and outlines the ones that did not, so that a report whose
/// files were moved or lost says so (and a test can check the pictures from a headless browser).
/// Small pictures are enlarged with visible pixels instead of blurred; large ones are shrunk
/// smoothly, so that a one-pixel error in a diff still shows.
const SCRIPT: &str = r#"
addEventListener('load', function () {
  var loaded = 0, broken = 0;
  for (var i = 0; i < document.images.length; i++) {
    var img = document.images[i];
    if (img.complete && img.naturalWidth > 0) { loaded++; } else { broken++; img.classList.add('broken'); }
    if (img.naturalWidth > 0 && img.naturalWidth < img.clientWidth) { img.style.imageRendering = 'pixelated'; }
  }
  document.body.setAttribute('data-images-loaded', loaded);
  document.body.setAttribute('data-images-broken', broken);
  // Whether each student's name and summary are on screen without scrolling (the class table).
  var lost = document.querySelector('#grades td.lost');
  if (lost) {
    var inView = lost.getBoundingClientRect().right <= window.innerWidth;
    document.body.setAttribute('data-summary-in-view', inView);
    var scroll = document.querySelector('.scroll');
    document.body.setAttribute('data-table-scrolls', scroll.scrollWidth > scroll.clientWidth);
  }
});
"#;

/// Writes `index.html` and every student's page into `out`.
pub fn write_html(report: &ClassReport, out: &Path) -> Result<(), OutputError> {
    write_file_atomic(&out.join("index.html"), index(report).as_bytes())?;
    for student in &report.students {
        replace_file(&out.join(&student.page), student_page(report, student).as_bytes())?;
    }
    Ok(())
}

fn page(title: &str, body: &str) -> String {
    format!(
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n\
         <meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n\
         <title>{}</title>\n<style>{STYLE}{}{}{}</style>\n</head>\n<body>\n{body}<script>{SCRIPT}</script>\n</body>\n</html>\n",
        escape(title),
        mistakes::STYLE,
        program::STYLE,
        download::STYLE
    )
}

fn class_of(outcome: &Outcome) -> String {
    format!("v-{}", outcome.word().replace(' ', "-"))
}

fn index(report: &ClassReport) -> String {
    let rubric = &report.rubric;
    let max = format_points(rubric.max_points);
    let mut body = format!(
        "<h1>{}</h1>\n<p class=\"muted\">{} students · {} images · {max} points · rubric {} · goldray {}</p>\n",
        escape(&rubric.title),
        report.students.len(),
        rubric.images.len(),
        escape(&rubric.path.display().to_string()),
        report.goldray,
    );
    download::source(&mut body, report);
    mistakes::histogram(&mut body, report);
    // The student column stays put while the per-image cells scroll; the summary before them
    // names the images that lost points, so a wide rubric never hides a failure off screen.
    body.push_str(
        "<div class=\"scroll\"><table id=\"grades\">\n<thead><tr><th class=\"name\">Student</th><th>Total</th>\
         <th>Lost points on</th>",
    );
    for image in &rubric.images {
        let file = escape(&image.file);
        let _ = write!(
            body,
            "<th>{file}<img class=\"thumb\" src=\"{GOLDEN_DIR}/{file}\" alt=\"golden {file}\"></th>"
        );
    }
    body.push_str("</tr></thead>\n<tbody>\n");
    for student in &report.students {
        let _ = write!(
            body,
            "<tr><td class=\"name\"><a href=\"{}\">{}</a>{}</td><td>{} / {max}</td><td class=\"lost\">{}</td>",
            escape(&student.page),
            escape(&student.name),
            download::identity(student),
            format_points(student.total),
            lost_points(student)
        );
        for result in &student.images {
            let _ = write!(
                body,
                "<td class=\"{}\" title=\"{}: {}\"><a href=\"{}#{}\">{}</a></td>",
                class_of(&result.outcome),
                result.outcome.word(),
                escape(&result.explanation),
                escape(&student.page),
                escape(&result.file),
                format_points(result.points)
            );
        }
        body.push_str("</tr>\n");
    }
    body.push_str("</tbody>\n");
    if !report.students.is_empty() {
        let count = report.students.len() as f64;
        let mean = |points: f64| format_points(points / count);
        let _ = write!(
            body,
            "<tfoot><tr><th class=\"name\">Mean</th><th>{}</th><th></th>",
            mean(report.students.iter().map(|s| s.total).sum())
        );
        for (column, _) in rubric.images.iter().enumerate() {
            let sum = report.students.iter().map(|s| s.images[column].points).sum();
            let _ = write!(body, "<th>{}</th>", mean(sum));
        }
        body.push_str("</tr></tfoot>\n");
    }
    body.push_str("</table></div>\n");
    if !report.ignored.is_empty() {
        let names: Vec<String> = report.ignored.iter().map(|n| escape(n)).collect();
        let _ = writeln!(
            body,
            "<p class=\"muted\">Not student folders, ignored: {}</p>",
            names.join(", ")
        );
    }
    body.push_str(LEGEND);
    integrity_section(&mut body, report);
    page(&format!("Grades: {}", rubric.title), &body)
}

/// What grading noticed about where pictures came from: flagged images, and pairs of students
/// who handed in the same picture. Evidence for the TA, not verdicts.
fn integrity_section(body: &mut String, report: &ClassReport) {
    body.push_str("<section id=\"integrity\">\n<h2>Where the pictures came from</h2>\n");
    let flagged: Vec<&StudentResult> = report.students.iter().filter(|s| !flags(s).is_empty()).collect();
    if flagged.is_empty() {
        body.push_str("<p class=\"muted\">No image is flagged.</p>\n");
    } else {
        body.push_str("<ul class=\"flagged\">\n");
        for student in flagged {
            let items: Vec<String> = flags(student).iter().map(|f| escape(f)).collect();
            let _ = writeln!(
                body,
                "<li><a href=\"{}\">{}</a>: <span class=\"flag\">{}</span></li>",
                escape(&student.page),
                escape(&student.name),
                items.join("</span> <span class=\"flag\">")
            );
        }
        body.push_str("</ul>\n");
    }
    body.push_str("<h3>Similar submissions</h3>\n");
    if report.similar.is_empty() {
        body.push_str(
            "<p class=\"muted\">No two students handed in the same picture (pictures identical to the golden \
             or published ones aside).</p>\n",
        );
    } else {
        body.push_str("<ul class=\"similar\">\n");
        let page_of = |name: &str| {
            report
                .students
                .iter()
                .find(|s| s.name == name)
                .map_or(String::new(), |s| escape(&s.page))
        };
        for pair in &report.similar {
            let [a, b] = &pair.students;
            let files: Vec<String> = pair.files.iter().map(|f| escape(f)).collect();
            let _ = writeln!(
                body,
                "<li><a href=\"{}\">{}</a> and <a href=\"{}\">{}</a>: {}</li>",
                page_of(a),
                escape(a),
                page_of(b),
                escape(b),
                files.join(", ")
            );
        }
        body.push_str(
            "</ul>\n<p class=\"muted\">The same picture, or a failing picture with more than 99.99% \
             of its pixels the same. Two students who made the same mistake can render the same \
             picture: this is a place to look, not a finding.</p>\n",
        );
    }
    body.push_str("</section>\n");
}

/// The images that did not get full points, most points lost first (rubric order among equals),
/// each a link to its section of the student's page; past [`LOST_LISTED`] the rest are counted,
/// so that one row never grows taller than a few lines.
fn lost_points(student: &StudentResult) -> String {
    let mut lost: Vec<&ImageResult> = student.images.iter().filter(|r| r.points < r.max_points).collect();
    lost.sort_by(|a, b| earned(a).total_cmp(&earned(b)));
    let mut links: Vec<String> = lost
        .iter()
        .take(LOST_LISTED)
        .map(|r| {
            let file = escape(&r.file);
            format!(
                "<a class=\"{}\" href=\"{}#{file}\">{file}</a>",
                class_of(&r.outcome),
                escape(&student.page)
            )
        })
        .collect();
    if lost.len() > LOST_LISTED {
        links.push(format!(
            "<a href=\"{}\">{} more</a>",
            escape(&student.page),
            lost.len() - LOST_LISTED
        ));
    }
    if lost.is_empty() {
        "none".to_owned()
    } else {
        format!("{}: {}", lost.len(), links.join(", "))
    }
}

/// The share of an image's points a student earned (1 for an image worth nothing).
fn earned(result: &ImageResult) -> f64 {
    if result.max_points > 0.0 {
        result.points / result.max_points
    } else {
        1.0
    }
}

/// How many images the class table names per student before counting the rest.
const LOST_LISTED: usize = 6;

const LEGEND: &str = "<p class=\"muted\">\
<span class=\"badge v-pass\">pass</span> full points · \
<span class=\"badge v-partial\">partial</span> partial credit · \
<span class=\"badge v-fail\">fail</span> too different from the golden image · \
<span class=\"badge v-missing\">missing, wrong size, wrong format, too large, unreadable, linked</span> nothing to compare \
(linked: a symbolic link, or a file outside the student's folder, is not read) · \
<span class=\"badge v-crashed\">crashed, timed out, over limit, exit error, not run</span> the student's program \
did not make the file (from <code>goldray run</code>'s record). \
Hover a cell for the reason; click it for the pictures.</p>\n";

fn student_page(report: &ClassReport, student: &StudentResult) -> String {
    let name = escape(&student.name);
    let mut body = format!(
        "<p><a href=\"../index.html\">← all students</a></p>\n<h1>{name}{}</h1>\n\
         <p>{} / {} points · folder <code>{}</code> · {}</p>\n",
        download::identity(student),
        format_points(student.total),
        format_points(student.max_points),
        escape(&student.folder.display().to_string()),
        escape(&report.rubric.title),
    );
    for flag in flags(student) {
        let _ = writeln!(body, "<p><span class=\"flag\">{}</span></p>", escape(&flag));
    }
    download::refused(&mut body, student);
    // Every image at a glance, in rubric order; each chip jumps to its section.
    body.push_str("<nav class=\"chips\">");
    for result in &student.images {
        let file = escape(&result.file);
        let _ = write!(
            body,
            "<a class=\"badge {}\" href=\"#{file}\" title=\"{}\">{file} {}/{}</a>",
            class_of(&result.outcome),
            result.outcome.word(),
            format_points(result.points),
            format_points(result.max_points)
        );
    }
    body.push_str("</nav>\n");
    program::summary(&mut body, student);
    mistakes::summary(&mut body, student);
    // Lost points first, the largest share lost first; rubric order among equals.
    let mut order: Vec<&ImageResult> = student.images.iter().collect();
    order.sort_by(|a, b| earned(a).total_cmp(&earned(b)));
    for result in order {
        image_section(&mut body, result);
    }
    body.push_str(
        "<p class=\"muted\">Difference: the golden image in dim grey; magenta where a channel differs by more than \
         the threshold; smaller differences from dark red (a thousandth of it) to yellow (nearly it).</p>\n",
    );
    page(&format!("{} – {}", student.name, report.rubric.title), &body)
}

fn image_section(body: &mut String, result: &ImageResult) {
    let file = escape(&result.file);
    let class = class_of(&result.outcome);
    let _ = write!(
        body,
        "<section class=\"image {class}\" id=\"{file}\">\n<h2>{file} <span class=\"badge {class}\">{}</span> \
         {} / {} points</h2>\n<p>{}</p>\n",
        result.outcome.word(),
        format_points(result.points),
        format_points(result.max_points),
        escape(&result.explanation),
    );
    for flag in &result.flags {
        let _ = writeln!(body, "<p><span class=\"flag\">{}</span></p>", escape(flag));
    }
    mistakes::image_line(body, result);
    if !result.notes.is_empty() {
        body.push_str("<ul>");
        for note in &result.notes {
            let _ = write!(body, "<li>{}</li>", escape(note));
        }
        body.push_str("</ul>\n");
    }
    let golden = format!("../{GOLDEN_DIR}/{file}");
    let _ = write!(
        body,
        "<div class=\"panes\">\n<figure><figcaption>golden</figcaption><a href=\"{golden}\">\
         <img src=\"{golden}\" alt=\"golden {file}\"></a></figure>\n"
    );
    match &result.student_image {
        Some(path) => {
            let student = escape(&format!("../{path}"));
            let _ = writeln!(
                body,
                "<figure class=\"flip\"><figcaption>student (hover: golden)</figcaption><a href=\"{student}\">\
                 <img class=\"student\" src=\"{student}\" alt=\"student {file}\">\
                 <img class=\"golden\" src=\"{golden}\" alt=\"golden {file}\"></a></figure>"
            );
        }
        None => {
            let _ = writeln!(
                body,
                "<figure><figcaption>student</figcaption><div class=\"empty\">{}</div></figure>",
                result.outcome.word()
            );
        }
    }
    match &result.diff_image {
        Some(path) => {
            let diff = escape(&format!("../{path}"));
            let _ = writeln!(
                body,
                "<figure><figcaption>difference</figcaption><a href=\"{diff}\"><img src=\"{diff}\" alt=\"difference {file}\"></a></figure>"
            );
        }
        None => {
            let _ = writeln!(
                body,
                "<figure><figcaption>difference</figcaption><div class=\"empty\">nothing to compare</div></figure>"
            );
        }
    }
    body.push_str("</div>\n");
    if let Some(metrics) = &result.metrics {
        metrics_table(body, metrics);
    }
    body.push_str("</section>\n");
}

fn metrics_table(body: &mut String, m: &Metrics) {
    let worst = m.worst.map_or("none: identical".to_owned(), |w| {
        format!(
            "{} at ({}, {}): golden {}, student {}",
            w.channel, w.x, w.y, w.expected, w.actual
        )
    });
    let psnr = if m.psnr.is_finite() {
        format!("{:.2} dB", m.psnr)
    } else {
        "∞".to_owned()
    };
    let _ = writeln!(
        body,
        "<table class=\"metrics\"><tr><th>failing pixels</th><td>{} of {} ({}) differ by more than {} codes</td></tr>\
         <tr><th>largest difference</th><td>{}</td></tr>\
         <tr><th>RMSE / MAE</th><td>{:.3} / {:.3} codes</td></tr>\
         <tr><th>PSNR</th><td>{psnr}</td></tr><tr><th>FLIP mean</th><td>{:.4}</td></tr></table>",
        m.failing_pixels,
        m.pixels,
        percent(m.failing_fraction),
        m.pixel_threshold,
        escape(&worst),
        m.rmse,
        m.mae,
        m.flip
    );
}
