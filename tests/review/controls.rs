//! The inspector used as a reviewer uses it, in a real browser: the mouse over a known pixel, the
//! wheel to zoom, the swipe slider, the F key and a click to flip, the exposure slider and the
//! channel menu from the keyboard. Each step is judged on what the reviewer sees: the readout's
//! numbers against the linear values the two EXRs hold, the zoom the page states, and the colour
//! the canvas shows at the inspected pixel against the page's curves applied to those values.

use std::path::Path;

use goldray::film::{Film, read_exr};
use serde_json::Value;

use super::cdp::Browser;
use super::served::Served;
use super::{CASE, READY, changed_project, fail_golden_check};

/// How much one notch of the wheel zooms (page.js).
const NOTCH: f64 = 1.25;

/// The page's tone curve (`srgb` in page.js) as an 8-bit value, before rounding.
fn srgb(v: f64) -> f64 {
    let v = v.clamp(0.0, 1.0);
    255.0
        * if v <= 0.0031308 {
            12.92 * v
        } else {
            1.055 * v.powf(1.0 / 2.4) - 0.055
        }
}

/// The golden and the new render, as the suite wrote them.
struct Renders {
    golden: Film,
    new: Film,
}

impl Renders {
    fn colour(film: &Film, (x, y): (u32, u32)) -> [f64; 3] {
        film.color[film.index(x, y)].map(f64::from)
    }

    /// How the page draws a pixel's colour at `ev` stops of exposure.
    fn drawn(film: &Film, pixel: (u32, u32), ev: f64) -> [f64; 3] {
        Self::colour(film, pixel).map(|v| srgb(v * 2f64.powf(ev)))
    }

    /// The depth channel's grey: near dark, far light over the finite range of both files.
    fn depth_grey(&self, (x, y): (u32, u32)) -> [f64; 3] {
        let finite = || {
            self.golden
                .depth
                .iter()
                .chain(&self.new.depth)
                .filter(|z| z.is_finite())
        };
        let lo = f64::from(finite().copied().fold(f32::INFINITY, f32::min));
        let hi = f64::from(finite().copied().fold(f32::NEG_INFINITY, f32::max));
        let z = f64::from(self.golden.depth[self.golden.index(x, y)]);
        [30.0 + 225.0 * (z - lo) / (hi - lo); 3]
    }

    /// The normals channel: each component `n` as `(n + 1) / 2`.
    fn normal_colour(&self, (x, y): (u32, u32)) -> [f64; 3] {
        self.golden.normal[self.golden.index(x, y)].map(|n| 127.5 * (f64::from(n) + 1.0))
    }

    /// The pixel to inspect: where the two renders look most different on screen (the light is
    /// 3% brighter: a few 8-bit steps at most), away from the border, from the labels drawn along
    /// the top and from the swipe's split in the middle, on an object (a finite depth).
    fn inspected(&self) -> (u32, u32) {
        let (width, height) = (self.golden.width, self.golden.height);
        let mut best = (0.0, (0, 0));
        for y in 16..height - 16 {
            for x in (16..width - 16).filter(|x| x.abs_diff(width / 2) > 4) {
                let (golden, new) = (
                    Self::drawn(&self.golden, (x, y), 0.0),
                    Self::drawn(&self.new, (x, y), 0.0),
                );
                let gap = (0..3).map(|c| (new[c] - golden[c]).abs()).fold(0.0, f64::max);
                if gap > best.0
                    && new.iter().all(|&v| v < 255.0)
                    && self.golden.depth[self.golden.index(x, y)].is_finite()
                {
                    best = (gap, (x, y));
                }
            }
        }
        // Two steps apart, two colours rounded to the nearest step stay more than TOLERANCE apart.
        assert!(
            best.0 >= 2.0,
            "the renders differ by at most {best:?} 8-bit steps: too little to tell apart"
        );
        best.1
    }
}

/// Where the inspector's canvas is in the window, in CSS pixels (the mouse's unit).
struct View {
    left: f64,
    top: f64,
    width: f64,
    /// Screen pixels per image pixel when the image fits the canvas.
    fit: f64,
}

impl View {
    fn of(browser: &mut Browser, image_width: u32) -> View {
        let rect = browser.eval(
            "(() => { const r = document.querySelector('canvas.view').getBoundingClientRect(); \
             return [r.left, r.top, r.width, r.bottom, innerHeight]; })()",
        );
        let [left, top, width, bottom, window] = [0, 1, 2, 3, 4].map(|i| rect[i].as_f64().unwrap_or(f64::NAN));
        assert!(
            bottom <= window,
            "the inspector ends at {bottom}, below the window's {window}"
        );
        View {
            left,
            top,
            width,
            fit: width / f64::from(image_width),
        }
    }

    /// The screen point over the middle of image pixel `(x, y)` at fit, in whole pixels, as a
    /// mouse moves.
    fn over(&self, (x, y): (u32, u32)) -> (f64, f64) {
        (
            (self.left + (f64::from(x) + 0.5) * self.fit).round(),
            (self.top + (f64::from(y) + 0.5) * self.fit).round(),
        )
    }
}

/// Waits until the readout names `pixel`, then checks its golden, new render and difference rows
/// against the EXRs' linear values (the page shows five significant digits).
fn assert_readout(browser: &mut Browser, pixel: (u32, u32), renders: &Renders) {
    let header = format!("({}, {})", pixel.0, pixel.1);
    let rows = browser.wait_for(
        &format!("the readout of pixel {header}"),
        &format!(
            "(() => {{ const rows = [...document.querySelectorAll('table.readout tr')]\
             .map(r => [...r.cells].map(c => c.textContent)); return rows[0]?.[0] === '{header}' && rows; }})()"
        ),
    );
    let rows: Vec<Vec<String>> = serde_json::from_value(rows).unwrap_or_else(|e| panic!("the readout: {e}"));
    assert_eq!(rows[0][1..4], ["R", "G", "B"], "{rows:?}");
    let golden = Renders::colour(&renders.golden, pixel);
    let new = Renders::colour(&renders.new, pixel);
    let difference = [0, 1, 2].map(|c| new[c] - golden[c]);
    let expected = [("golden", golden), ("new render", new), ("difference", difference)];
    assert_eq!(rows.len(), 4, "{rows:?}");
    for (row, (title, values)) in rows[1..].iter().zip(expected) {
        assert_eq!(row[0], title, "{rows:?}");
        for (c, value) in values.into_iter().enumerate() {
            let shown: f64 = row[c + 1].parse().unwrap_or_else(|e| panic!("`{}`: {e}", row[c + 1]));
            assert!(
                (shown - value).abs() <= 6e-5 * value.abs(),
                "{title} {} at {header}: the page shows {shown}, the EXR holds {value}",
                rows[0][c + 1]
            );
        }
    }
}

/// How far an 8-bit colour on the canvas may be from the value the page computed: the canvas
/// rounds to the nearest step (and the test's arithmetic is not the browser's to the last bit).
const TOLERANCE: f64 = 0.6;

/// Checks that the inspector's canvas shows `expected` (8-bit, before rounding) at the screen
/// point `at`.
fn assert_shows(browser: &mut Browser, (x, y): (f64, f64), expected: [f64; 3], what: &str) {
    let shown = browser.eval(&format!(
        "(() => {{ const c = document.querySelector('canvas.view'), r = c.getBoundingClientRect(), \
         k = c.width / r.width; return [...c.getContext('2d').getImageData(Math.floor(({x} - r.left) * k), \
         Math.floor(({y} - r.top) * k), 1, 1).data].slice(0, 3); }})()"
    ));
    let shown: Vec<f64> = (0..3).map(|c| shown[c].as_f64().unwrap_or(f64::NAN)).collect();
    assert!(
        shown.iter().zip(expected).all(|(s, e)| (s - e).abs() <= TOLERANCE),
        "the inspector shows {shown:?} where {what} is {expected:.1?}"
    );
}

/// The zoom the page states, in screen pixels per image pixel.
fn zoom(browser: &mut Browser) -> f64 {
    let text = browser.eval("document.querySelector('output.zoom').textContent");
    let text = text.as_str().unwrap_or_default();
    text.strip_prefix("zoom ")
        .and_then(|z| z.strip_suffix('×'))
        .and_then(|z| z.parse().ok())
        .unwrap_or_else(|| panic!("the zoom reads `{text}`"))
}

/// Clicks the word before a control in the bar ("Channel", "Exposure"), which gives the control
/// the keyboard focus.
fn click_label(browser: &mut Browser, id: &str) {
    let at = browser.eval(&format!(
        "(() => {{ const r = document.getElementById('{id}').closest('label').getBoundingClientRect(); \
         return [r.left + 4, r.top + r.height / 2]; }})()"
    ));
    browser.click_at(at[0].as_f64().unwrap_or(f64::NAN), at[1].as_f64().unwrap_or(f64::NAN));
    browser.wait_for(
        &format!("#{id} to have the focus"),
        &format!("document.activeElement.id === '{id}'"),
    );
}

/// Waits until `expression` is `expected`.
fn wait_until(browser: &mut Browser, expression: &str, expected: &str) {
    let quoted = Value::from(expected);
    browser.wait_for(
        &format!("{expression} to be {quoted}"),
        &format!("{expression} === {quoted}"),
    );
}

#[test]
fn the_inspector_zooms_reads_values_swipes_flips_and_follows_exposure_and_channel() {
    let project = changed_project();
    let root = project.path();
    fail_golden_check(root);
    let golden = root.join("golden");
    let renders = Renders {
        golden: read_exr(&golden.join(format!("{CASE}.snap.exr"))).unwrap_or_else(|e| panic!("{e}")),
        new: read_exr(&golden.join(format!("{CASE}.snap.new.exr"))).unwrap_or_else(|e| panic!("{e}")),
    };
    let pixel = renders.inspected();
    let drawn = |film: &Film, ev: f64| Renders::drawn(film, pixel, ev);
    let served = Served::start(root);
    let mut browser = Browser::open(&served.url, 1280, 1400, READY);
    let view = View::of(&mut browser, renders.golden.width);
    let at = view.over(pixel);

    // At fit, over the pixel: its values in both files; the swipe shows the golden left of the
    // split in the middle and the new render right of it.
    assert!(
        (zoom(&mut browser) - view.fit).abs() < 0.01 * view.fit,
        "the zoom at fit"
    );
    browser.move_to(at.0, at.1);
    assert_readout(&mut browser, pixel, &renders);
    let (side, film) = match at.0 < view.left + view.width / 2.0 {
        true => ("the golden", &renders.golden),
        false => ("the new render", &renders.new),
    };
    assert_shows(&mut browser, at, drawn(film, 0.0), side);

    // Five notches of the wheel zoom about the cursor; three image pixels to the right on
    // screen is then three pixels on in the image.
    let stated = "document.querySelector('output.zoom').textContent";
    for _ in 0..5 {
        let before = browser.eval(stated);
        browser.wheel_up(at.0, at.1);
        browser.wait_for("the wheel to zoom", &format!("{stated} !== {before}"));
    }
    let scale = view.fit * NOTCH.powi(5);
    assert!((zoom(&mut browser) - scale).abs() < 0.01 * scale, "five notches in");
    browser.move_to((at.0 + 3.0 * scale).round(), at.1);
    assert_readout(&mut browser, (pixel.0 + 3, pixel.1), &renders);
    browser.move_to(at.0, at.1);
    assert_readout(&mut browser, pixel, &renders);
    assert_shows(&mut browser, at, drawn(film, 0.0), side);

    // The swipe slider from the keyboard: Home shows only the new render, End only the golden.
    browser.click("input.swipe");
    browser.press("Home");
    wait_until(&mut browser, "document.querySelector('input.swipe').value", "0");
    assert_shows(&mut browser, at, drawn(&renders.new, 0.0), "the new render");
    browser.press("End");
    wait_until(&mut browser, "document.querySelector('input.swipe').value", "1");
    assert_shows(&mut browser, at, drawn(&renders.golden, 0.0), "the golden");

    // F flips to the new render, and a click on the picture back to the golden.
    let label = "document.querySelector('canvas.view').getAttribute('aria-label')";
    browser.press("f");
    wait_until(&mut browser, "document.getElementById('mode').value", "flip");
    wait_until(&mut browser, label, "new render (click or F: golden)");
    assert_shows(&mut browser, at, drawn(&renders.new, 0.0), "the new render");
    browser.click_at(at.0, at.1);
    wait_until(&mut browser, label, "golden (click or F: new render)");
    assert_shows(&mut browser, at, drawn(&renders.golden, 0.0), "the golden");

    // Four steps down the exposure slider: -1 EV halves every value before the tone curve.
    click_label(&mut browser, "exposure");
    for _ in 0..4 {
        browser.press("ArrowLeft");
    }
    wait_until(
        &mut browser,
        "document.getElementById('exposure-value').textContent",
        "-1 EV",
    );
    assert_shows(&mut browser, at, drawn(&renders.golden, -1.0), "the golden at -1 EV");

    // Down the channel menu: depth, then normals.
    click_label(&mut browser, "channel");
    browser.press("ArrowDown");
    wait_until(&mut browser, "document.getElementById('channel').value", "depth");
    assert_shows(&mut browser, at, renders.depth_grey(pixel), "the golden's depth");
    browser.press("ArrowDown");
    wait_until(&mut browser, "document.getElementById('channel').value", "normal");
    let normal = renders.normal_colour(pixel);
    assert_shows(&mut browser, at, normal, "the golden's normal");

    // The screen shows what the canvas holds (kept under target/tmp for a person to look at).
    let shot = browser.screenshot(&Path::new(env!("CARGO_TARGET_TMPDIR")).join("review-inspector.png"));
    let on_screen = shot.get_pixel(at.0 as u32, at.1 as u32).0;
    assert!(
        on_screen
            .iter()
            .zip(normal)
            .all(|(&s, n)| (f64::from(s) - n).abs() <= TOLERANCE),
        "the screen shows {on_screen:?} where the golden's normal is {normal:.1?}"
    );
}
