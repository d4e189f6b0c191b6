//! What a diagnosed grading writes for people and programs: `grades.json`'s diagnoses and the
//! report's mistakes, opened in headless Chromium.

use super::*;

#[test]
fn grades_json_has_a_diagnosis_exactly_where_points_were_lost() {
    let graded = exact();
    let json: serde_json::Value =
        serde_json::from_str(&fs::read_to_string(graded.dir.join("report/grades.json")).unwrap()).unwrap();
    let mut diagnosed = 0;
    for student in json["students"].as_array().unwrap() {
        for image in student["images"].as_array().unwrap() {
            let lost = matches!(image["verdict"].as_str(), Some("partial" | "fail"));
            let diagnosis = &image["diagnosis"];
            assert_eq!(!diagnosis.is_null(), lost, "{} {}", student["name"], image["file"]);
            if lost {
                diagnosed += 1;
                for key in ["id", "explanation", "confidence", "golden", "explained"] {
                    assert!(!diagnosis[key].is_null(), "{key} in {diagnosis}");
                }
                if diagnosis["id"] != UNEXPLAINED {
                    assert!(diagnosis["residual"]["failing_fraction"].is_number(), "{diagnosis}");
                    assert!(diagnosis["residual_metrics"]["flip"].is_number(), "{diagnosis}");
                    assert!(diagnosis["mistake_image"].is_string(), "{diagnosis}");
                }
            }
        }
    }
    assert!(diagnosed > 250);
    assert!(
        json.get("diagnosis").is_none(),
        "what diagnosis cost is in run.json, not in the grades"
    );
    let run: serde_json::Value =
        serde_json::from_str(&fs::read_to_string(graded.dir.join("report/run.json")).unwrap()).unwrap();
    assert!(run["diagnosis"]["renders"].as_array().unwrap().len() == 7, "{run}");
    let csv = fs::read_to_string(graded.dir.join("report/grades.csv")).unwrap();
    assert!(csv.lines().next().unwrap().ends_with(",flags,diagnoses"), "{csv}");
    assert!(
        csv.lines()
            .any(|l| l.starts_with("no-shadows,") && l.ends_with(",no-shadows")),
        "{csv}"
    );
}

#[test]
fn the_report_shows_the_mistakes_in_headless_chromium() {
    let graded = exact();
    let out = graded.dir.join("report");
    let dom = chromium::dump_dom(&out.join("index.html"));
    chromium::assert_pictures_loaded(&dom, "the class page");
    assert!(dom.contains("<h2>Mistakes in the class</h2>"));
    for id in ["no-shadows", "gamma-applied", "nothing-shaded", "pixel-mapping"] {
        assert!(
            dom.contains(&format!("data-mistake=\"{id}\"")),
            "{id} is not in the histogram"
        );
    }
    let page = out.join(&student(graded, "no-shadows + gamma-applied=srgb").page);
    let dom = chromium::dump_dom(&page);
    chromium::assert_pictures_loaded(&dom, "the student's page");
    let leads = dom
        .find("<h2>What went wrong</h2>")
        .expect("the page leads with the mistakes");
    let first_image = dom.find("<section class=\"image").unwrap();
    assert!(leads < first_image, "the mistakes come before the images");
    for needle in [
        "data-mistake=\"no-shadows\"",
        "data-mistake=\"gamma-applied\"",
        "Explains <a href=\"#a07.png\">a07.png</a>.",
        "the mistake's render",
        "together with <code class=\"id\">gamma-applied</code>",
    ] {
        assert!(dom.contains(needle), "{needle}");
    }
    let shot = chromium::screenshot(&page, 1200, 1000, &out.join("mistakes.png"));
    let colours: std::collections::HashSet<[u8; 3]> = shot.pixels().map(|p| p.0).collect();
    assert!(
        colours.len() > 500,
        "the screenshot looks blank: {} colours",
        colours.len()
    );
    chromium::screenshot(&out.join("index.html"), 1200, 1400, &out.join("index.png"));
}
