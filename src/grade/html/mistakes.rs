//! The diagnosis in the HTML report: the class histogram of mistakes on `index.html`, the
//! mistakes that lead each student's page (each once, with the images it explains and a row of
//! pictures: student, golden, the mistake's render, the difference from it), and one line per
//! image section.

use std::fmt::Write as _;

use super::super::diagnosis::{Confidence, Diagnosis, UNEXPLAINED, Unfinished};
use super::super::golden::GOLDEN_DIR;
use super::super::judge::{format_points, percent};
use super::super::report::{ClassReport, mistakes_of};
use super::super::score::{ImageResult, StudentResult};
use super::escape;
use crate::fault::Fault;

pub const STYLE: &str = r#"
#mistakes{margin-top:1em}#mistakes table{margin:.4em 0}#mistakes td{text-align:left;vertical-align:top}
#mistakes td.count{text-align:right;white-space:nowrap}
.bar{display:inline-block;height:.9em;background:#c62828;vertical-align:middle;min-width:2px}
.bar.unexplained{background:#777}
code.id{font-weight:600;color:#8a1c1c}
section.mistake{background:#fff;border:1px solid #ccc;border-left:6px solid #8a1c1c;margin:1em 0;padding:.8em}
section.mistake.unexplained{border-left-color:#777}section.mistake.unfinished{border-left-color:#b26a00}
section.mistake .hint{color:#444}section.mistake .panes figure img{width:220px;height:220px}
.confidence{font-size:.85em;color:#555}
p.diagnosis{background:#fbeaea;border-radius:.3em;padding:.3em .5em}
"#;

/// `index.html`: how many students made each mistake (a student counts once per mistake, however
/// many images it explains), most frequent first, with the students' names.
pub fn histogram(body: &mut String, report: &ClassReport) {
    if report.diagnosis.is_none() {
        return;
    }
    body.push_str("<section id=\"mistakes\">\n<h2>Mistakes in the class</h2>\n");
    // id → the students who made it, in report order.
    let mut made: Vec<(String, Vec<&StudentResult>)> = Vec::new();
    for student in &report.students {
        for id in mistakes_of(student) {
            match made.iter_mut().find(|(known, _)| *known == id) {
                Some((_, students)) => students.push(student),
                None => made.push((id, vec![student])),
            }
        }
    }
    if made.is_empty() {
        body.push_str(
            "<p class=\"muted\">No image lost points on a comparison: nothing to diagnose.</p>\n</section>\n",
        );
        return;
    }
    // Most students first; unexplained last.
    made.sort_by_key(|(id, students)| (id == UNEXPLAINED, std::cmp::Reverse(students.len())));
    let class = report.students.len().max(1);
    body.push_str(
        "<table class=\"histogram\"><thead><tr><th>mistake</th><th>students</th><th></th></tr></thead><tbody>\n",
    );
    for (id, students) in &made {
        let width = 12.0 * students.len() as f64 / class as f64;
        let names: Vec<String> = students
            .iter()
            .take(8)
            .map(|s| format!("<a href=\"{}#mistakes\">{}</a>", escape(&s.page), escape(&s.name)))
            .collect();
        let more = if students.len() > 8 {
            format!(" and {} more", students.len() - 8)
        } else {
            String::new()
        };
        let unexplained = if id == UNEXPLAINED { " unexplained" } else { "" };
        let _ = writeln!(
            body,
            "<tr data-mistake=\"{id}\"><td><code class=\"id\">{id}</code><br><span class=\"muted\">{}</span></td>\
             <td class=\"count\"><span class=\"bar{unexplained}\" style=\"width:{width:.2}em\"></span> {}</td>\
             <td>{}{more}</td></tr>",
            escape(&describe(id)),
            students.len(),
            names.join(", "),
            id = escape(id),
        );
    }
    // Counted from the students, not from this run's diagnosis, which may have reused earlier
    // results or diagnosed one slice of the class.
    let diagnoses: Vec<&Diagnosis> = report
        .students
        .iter()
        .flat_map(|s| &s.images)
        .filter_map(|i| i.diagnosis.as_ref())
        .collect();
    let explained = diagnoses.iter().filter(|d| d.id != UNEXPLAINED).count();
    let _ = writeln!(
        body,
        "</tbody></table>\n<p class=\"muted\">Each image that lost points was compared with the golden render redrawn \
         under each known mistake; a mistake is named when the image is much closer to its render than to the golden \
         one ({explained} of {} images explained).</p>\n</section>",
        diagnoses.len()
    );
}

/// A mistake's sentence, for an id of one or two catalogue faults (or `unexplained`).
fn describe(id: &str) -> String {
    if id == UNEXPLAINED {
        return "images no known mistake explains".to_owned();
    }
    let parts: Vec<&str> = id
        .split('+')
        .filter_map(|part| part.parse::<Fault>().ok())
        .map(Fault::explanation)
        .collect();
    parts.join("; and ")
}

/// The top of a student's page: each mistake once (a pair's two apart), with the images it
/// explains and the pictures of the one that lost the most points; then the images nothing
/// explains.
pub fn summary(body: &mut String, student: &StudentResult) {
    // Catalogue id → the images whose diagnosis names it, in rubric order.
    let mut groups: Vec<(String, Vec<&ImageResult>)> = Vec::new();
    for image in &student.images {
        let Some(diagnosis) = &image.diagnosis else { continue };
        for id in diagnosis.id.split('+') {
            match groups.iter_mut().find(|(known, _)| known == id) {
                Some((_, images)) => images.push(image),
                None => groups.push((id.to_owned(), vec![image])),
            }
        }
    }
    if groups.is_empty() {
        return;
    }
    // The parts never written are one finding, before the mistakes in what was written.
    if let Some(unfinished) = &student.unfinished {
        groups.retain(|(id, _)| !unfinished.parts.iter().any(|p| p.id == *id));
    }
    let lost = |images: &[&ImageResult]| images.iter().map(|i| i.max_points - i.points).sum::<f64>();
    groups.sort_by(|a, b| {
        (a.0 == UNEXPLAINED)
            .cmp(&(b.0 == UNEXPLAINED))
            .then(lost(&b.1).total_cmp(&lost(&a.1)))
    });
    body.push_str("<div id=\"mistakes\">\n<h2>What went wrong</h2>\n");
    if let Some(unfinished) = &student.unfinished {
        unfinished_section(body, student, unfinished);
    }
    for (id, mut images) in groups {
        images.sort_by(|a, b| (b.max_points - b.points).total_cmp(&(a.max_points - a.points)));
        let links: Vec<String> = images
            .iter()
            .map(|i| format!("<a href=\"#{file}\">{file}</a>", file = escape(&i.file)))
            .collect();
        let first = images[0];
        let Some(diagnosis) = &first.diagnosis else { continue };
        if id == UNEXPLAINED {
            let _ = writeln!(
                body,
                "<section class=\"mistake unexplained\" data-mistake=\"{UNEXPLAINED}\"><h3>Not explained by a known \
                 mistake</h3>\n<p>{}: these images lost points, and no mistake of the catalogue, alone or with another, \
                 explains them. Compare them with the golden images below.</p>",
                links.join(", ")
            );
            if let Some(closest) = &diagnosis.closest {
                let _ = writeln!(
                    body,
                    "<p class=\"muted\">Closest for {}: <code class=\"id\">{}</code>, which accounts for {} of its failing \
                     pixels (not enough to name it).</p>",
                    escape(&first.file),
                    escape(&closest.faults),
                    percent(closest.explained)
                );
            }
            pictures(body, first, diagnosis, "closest mistake's render");
            body.push_str("</section>\n");
            continue;
        }
        // The mistake as this student made it: its family member, from the first image.
        let label = diagnosis
            .faults
            .as_deref()
            .and_then(|faults| faults.split('+').find(|f| f.split('=').next() == Some(id.as_str())))
            .unwrap_or(&id)
            .to_owned();
        let fault: Option<Fault> = id.parse().ok();
        let (explanation, hint) = match (&label, fault) {
            (label, Some(fault)) => (
                label
                    .parse::<crate::fault::FaultSet>()
                    .map_or(fault.explanation().to_owned(), |set| set.explain()),
                fault.hint().to_owned(),
            ),
            _ => (diagnosis.explanation.clone(), diagnosis.hints.join("; ")),
        };
        let together = if diagnosis.id.contains('+') {
            format!(
                " In {} together with <code class=\"id\">{}</code>.",
                escape(&first.file),
                escape(
                    diagnosis
                        .id
                        .split('+')
                        .filter(|other| *other != id)
                        .collect::<Vec<_>>()
                        .join("+")
                        .as_str()
                )
            )
        } else {
            String::new()
        };
        let _ = writeln!(
            body,
            "<section class=\"mistake\" data-mistake=\"{}\"><h3><code class=\"id\">{}</code> \
             <span class=\"confidence\">{}</span></h3>\n<p>{}.</p>\n<p class=\"hint\">Where to look: {}.</p>\n\
             <p>Explains {}.{together}{}</p>",
            escape(&id),
            escape(&label),
            confidence(diagnosis),
            escape(&capitalised(&explanation)),
            escape(&hint),
            links.join(", "),
            credit(&images),
        );
        let caption = if diagnosis.id.contains('+') {
            "with both mistakes"
        } else {
            "the mistake's render"
        };
        pictures(body, first, diagnosis, caption);
        body.push_str("</section>\n");
    }
    body.push_str("</div>\n");
}

/// The one finding for the parts never written: the sentence, each part with where to start and
/// the images it explains, and the pictures of the image that lost the most points.
fn unfinished_section(body: &mut String, student: &StudentResult, unfinished: &Unfinished) {
    let _ = writeln!(
        body,
        "<section class=\"mistake unfinished\" data-mistake=\"unfinished\"><h3>Unfinished</h3>\n<p>{}.</p>\n<ul>",
        escape(&capitalised(&unfinished.summary))
    );
    for part in &unfinished.parts {
        let hint = part.id.parse::<Fault>().map_or("", Fault::hint);
        let links: Vec<String> = part
            .images
            .iter()
            .map(|file| format!("<a href=\"#{file}\">{file}</a>", file = escape(file)))
            .collect();
        let _ = writeln!(
            body,
            "<li data-part=\"{id}\"><code class=\"id\">{id}</code>: {part}. <span class=\"hint\">Where to start: {}.</span> \
             Explains {}.</li>",
            escape(hint),
            links.join(", "),
            id = escape(&part.id),
            part = escape(&part.part),
        );
    }
    body.push_str("</ul>\n");
    let lost = |i: &&ImageResult| i.max_points - i.points;
    let worst = student
        .images
        .iter()
        .filter(|i| {
            i.diagnosis
                .as_ref()
                .is_some_and(|d| d.id.split('+').any(|id| unfinished.parts.iter().any(|p| p.id == id)))
        })
        .max_by(|a, b| lost(a).total_cmp(&lost(b)));
    if let Some(image) = worst
        && let Some(diagnosis) = &image.diagnosis
    {
        pictures(body, image, diagnosis, "the unfinished program's render");
    }
    body.push_str("</section>\n");
}

/// The line in an image's own section.
pub fn image_line(body: &mut String, result: &ImageResult) {
    let Some(diagnosis) = &result.diagnosis else { return };
    if diagnosis.id == UNEXPLAINED {
        body.push_str("<p class=\"diagnosis\">Diagnosis: not explained by a known mistake.</p>\n");
    } else {
        let _ = writeln!(
            body,
            "<p class=\"diagnosis\">Diagnosis: <a href=\"#mistakes\"><code class=\"id\">{}</code></a>: {}.</p>",
            escape(diagnosis.faults.as_deref().unwrap_or(&diagnosis.id)),
            escape(&diagnosis.explanation)
        );
    }
}

fn confidence(diagnosis: &Diagnosis) -> String {
    let word = match diagnosis.confidence {
        Confidence::High => "sure",
        Confidence::Medium => "likely",
        Confidence::None => "",
    };
    let alternatives = if diagnosis.alternatives.is_empty() {
        String::new()
    } else {
        format!(", or {}", diagnosis.alternatives.join(" or "))
    };
    format!(
        "{word}: explains {} of the failing pixels{alternatives}",
        percent(diagnosis.explained)
    )
}

fn credit(images: &[&ImageResult]) -> String {
    let credited: f64 = images
        .iter()
        .filter(|i| i.diagnosis.as_ref().is_some_and(|d| d.credit.is_some()))
        .map(|i| i.points)
        .sum();
    if credited > 0.0 {
        format!(
            " The rubric grants credit for this mistake: {} points.",
            format_points(credited)
        )
    } else {
        String::new()
    }
}

fn capitalised(text: &str) -> String {
    let mut chars = text.chars();
    chars
        .next()
        .map_or(String::new(), |c| c.to_uppercase().collect::<String>() + chars.as_str())
}

/// Student | golden | the mistake's render | the difference between the student's picture and it.
fn pictures(body: &mut String, result: &ImageResult, diagnosis: &Diagnosis, mistake_caption: &str) {
    let file = escape(&result.file);
    let figure = |caption: &str, path: Option<String>| match path {
        Some(path) => {
            let path = escape(&format!("../{path}"));
            format!(
                "<figure><figcaption>{caption}</figcaption><a href=\"{path}\"><img src=\"{path}\" alt=\"{caption} {file}\"></a></figure>"
            )
        }
        None => format!("<figure><figcaption>{caption}</figcaption><div class=\"empty\">none</div></figure>"),
    };
    let _ = writeln!(
        body,
        "<div class=\"panes\">{}{}{}{}</div>",
        figure("student", result.student_image.clone()),
        figure("golden", Some(format!("{GOLDEN_DIR}/{}", result.file))),
        figure(mistake_caption, diagnosis.mistake_image.clone()),
        figure("student vs that render", diagnosis.residual_image.clone()),
    );
}
