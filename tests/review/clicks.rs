//! Accept and Reject clicked in a real browser: the mouse goes to the button, presses and
//! releases, the page posts as it does for a reviewer, and the files on disk are then compared
//! with what insta writes.

use std::path::Path;

use goldray::rgb_image::RgbImage;

use super::cdp::Browser;
use super::served::Served;
use super::{
    CASE, READY, assert_accepted_as_insta_would, changed_project, fail_golden_check, files, insta_accepted,
    pending_files,
};

/// Pixels of the Accept buttons' green (`button.accept` in page.css), which fades once a
/// button is disabled: what tells a reviewer that there is still something to decide.
fn accept_green(shot: &RgbImage) -> usize {
    shot.pixels().filter(|p| p.0 == [0x2e, 0x7d, 0x32]).count()
}

/// The status line the page shows in the case's title once the server has answered.
fn decided_status(browser: &mut Browser) -> String {
    let status = browser.wait_for(
        "the case to show the server's answer",
        "document.querySelector('section.decided .status')?.textContent",
    );
    status.as_str().unwrap_or_default().to_owned()
}

#[test]
fn clicking_accept_on_the_page_writes_what_insta_accept_writes() {
    let project = changed_project();
    let root = project.path();
    fail_golden_check(root);
    let insta = insta_accepted(root);
    let before = files(root);
    let served = Served::start(root);
    let mut browser = Browser::open(&served.url, 1280, 1000, READY);

    let dom = browser.eval("document.documentElement.outerHTML");
    let dom = dom.as_str().unwrap_or_default();
    for expected in [
        format!("id=\"case-{CASE}\""),
        "data-cases-loaded=\"1\"".to_owned(),
        // The golden, the new render and the heatmap, each loaded; the first two also drawn
        // from their linear values.
        "data-images-loaded=\"3\"".to_owned(),
        "data-images-broken=\"0\"".to_owned(),
        "data-panes-drawn=\"2\"".to_owned(),
        "<span class=\"badge\">FAIL</span>".to_owned(),
        "broke fail_fraction".to_owned(),
        "made differently</b> golden: case hash".to_owned(),
    ] {
        assert!(dom.contains(&expected), "the page lacks `{expected}`:\n{dom}");
    }
    assert_eq!(files(root), before, "opening the page writes nothing");
    // Kept under target/tmp for a person to look at.
    let shots = Path::new(env!("CARGO_TARGET_TMPDIR"));
    let open = browser.screenshot(&shots.join("review-before-accept.png"));
    assert!(
        accept_green(&open) > 500,
        "the Accept buttons are green before the click"
    );

    browser.click(&format!("button.accept[data-case=\"{CASE}\"]"));
    assert_eq!(
        decided_status(&mut browser),
        format!("accepted: wrote golden/{CASE}.snap, golden/{CASE}.snap.exr")
    );
    let buttons = browser.eval("[...document.querySelectorAll('button')].map(b => b.disabled)");
    assert_eq!(
        buttons,
        serde_json::json!([true, true, true]),
        "Accept all, Accept and Reject"
    );
    assert_eq!(
        browser.eval("document.body.dataset.open"),
        "0",
        "nothing left to decide"
    );
    let shot = browser.screenshot(&shots.join("review-accepted.png"));
    assert_eq!(accept_green(&shot), 0, "no Accept button is offered after the click");
    drop(browser);
    drop(served);
    assert_accepted_as_insta_would(root, &before, &insta);
}

#[test]
fn clicking_reject_on_the_page_keeps_the_golden_and_removes_the_pending_files() {
    let project = changed_project();
    let root = project.path();
    let golden = files(root);
    fail_golden_check(root);
    let served = Served::start(root);
    let mut browser = Browser::open(&served.url, 1280, 1000, READY);
    browser.click(&format!("button.reject[data-case=\"{CASE}\"]"));
    assert_eq!(
        decided_status(&mut browser),
        format!("rejected: removed golden/{CASE}.snap.new, golden/{CASE}.snap.new.exr")
    );
    assert!(pending_files(root).is_empty());
    assert_eq!(files(root), golden, "the golden and the case as they were");

    // Opened again, the page has nothing left to show.
    browser.navigate(&served.url, &format!("document.body.dataset.cases === '0' && {READY}"));
    let text = browser.eval("document.body.innerText");
    let text = text.as_str().unwrap_or_default();
    assert!(text.contains("0 pending goldens"), "{text}");
    assert!(text.contains("Nothing to review"), "{text}");
    assert_eq!(browser.eval("document.querySelectorAll('button').length"), 0);
}
