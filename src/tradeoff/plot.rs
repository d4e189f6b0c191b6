//! `tradeoff.png`: error against render time on log-log axes, one curve per filter over the
//! sample counts, the bounce sweep as a dashed curve, and the Pareto front as a staircase with
//! its settings ringed.
//!
//! Log-log because both costs and errors span orders of magnitude, and because there a
//! convergence rate is a slope: error ∝ time^−½ is a straight line of slope −½. The text is set
//! in DejaVu Sans compiled into the binary (`assets/fonts`), so the plot is the same on every
//! machine and needs no system fonts.

use std::io::Cursor;
use std::sync::OnceLock;

use plotters::prelude::*;
use plotters::style::{FontStyle, register_font};

use super::Tradeoff;
use super::error::TradeoffError;
use super::measure::Measurement;

/// The PNG's `Software` text, by which a later run recognises its own plot.
pub const SOFTWARE: &str = "goldray tradeoff";

pub const WIDTH: u32 = 960;
pub const HEIGHT: u32 = 640;

const FONT: &str = "sans-serif";
static DEJAVU_SANS: &[u8] = include_bytes!("../../assets/fonts/DejaVuSans.ttf");

/// One colour per curve, told apart by people with the common colour-vision deficiencies
/// (Okabe and Ito's palette).
const PALETTE: [RGBColor; 6] = [
    RGBColor(0, 114, 178),
    RGBColor(230, 159, 0),
    RGBColor(0, 158, 115),
    RGBColor(204, 121, 167),
    RGBColor(86, 180, 233),
    RGBColor(213, 94, 0),
];

/// A curve of the plot: its legend text, its points in order with their labels, and whether it
/// is drawn dashed.
struct Curve {
    name: String,
    points: Vec<((f64, f64), String)>,
    dashed: bool,
}

/// Draws the plot and encodes it as an 8-bit RGB PNG marked with [`SOFTWARE`].
pub fn plot_png(t: &Tradeoff) -> Result<Vec<u8>, TradeoffError> {
    if !font_registered() {
        return Err(TradeoffError::Plot(
            "the bundled font DejaVu Sans does not load".to_owned(),
        ));
    }
    let mut pixels = vec![255u8; (WIDTH * HEIGHT * 3) as usize];
    draw(t, &mut pixels).map_err(|e| TradeoffError::Plot(e.to_string()))?;
    encode(&pixels).map_err(|e| TradeoffError::Plot(e.to_string()))
}

/// Whether `bytes` is a PNG that goldray tradeoff wrote.
pub fn is_our_png(bytes: &[u8]) -> bool {
    let mut decoder = png::Decoder::new(Cursor::new(bytes));
    decoder.set_ignore_text_chunk(false);
    decoder.read_info().is_ok_and(|reader| {
        reader
            .info()
            .uncompressed_latin1_text
            .iter()
            .any(|t| t.keyword == "Software" && t.text == SOFTWARE)
    })
}

fn font_registered() -> bool {
    static REGISTERED: OnceLock<bool> = OnceLock::new();
    *REGISTERED.get_or_init(|| register_font(FONT, FontStyle::Normal, DEJAVU_SANS).is_ok())
}

fn encode(pixels: &[u8]) -> Result<Vec<u8>, png::EncodingError> {
    let mut bytes = Vec::new();
    let mut encoder = png::Encoder::new(&mut bytes, WIDTH, HEIGHT);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    encoder.add_text_chunk("Software".to_owned(), SOFTWARE.to_owned())?;
    let mut writer = encoder.write_header()?;
    writer.write_image_data(pixels)?;
    writer.finish()?;
    Ok(bytes)
}

/// Where a measurement goes on the axes. A log axis has no zero, so an exact match (error 0)
/// sits on the floor of the axis, which is below every non-zero value.
fn position(m: &Measurement, t: &Tradeoff, floor: (f64, f64)) -> (f64, f64) {
    (m.seconds.max(floor.0), t.metric.of(&m.errors).max(floor.1))
}

/// Half the smallest positive value, or `fallback` when there is none.
fn floor_of(values: impl Iterator<Item = f64>, fallback: f64) -> f64 {
    values
        .filter(|v| *v > 0.0)
        .fold(None, |low: Option<f64>, v| Some(low.map_or(v, |l| l.min(v))))
        .map_or(fallback, |v| v / 2.0)
}

/// The grid's curves (one per precision and filter, labelled by samples per pixel) and the
/// bounce sweep's (labelled b0, b1, …).
fn curves(t: &Tradeoff, floor: (f64, f64)) -> Vec<Curve> {
    let mut curves = Vec::new();
    let mut kinds: Vec<_> = Vec::new();
    for m in t.measurements.iter().filter(|m| m.in_grid) {
        let kind = (m.setting.precision, m.setting.filter);
        if !kinds.contains(&kind) {
            kinds.push(kind);
        }
    }
    for (precision, filter) in kinds {
        let mut members: Vec<&Measurement> = t
            .measurements
            .iter()
            .filter(|m| m.in_grid && m.setting.precision == precision && m.setting.filter == filter)
            .collect();
        members.sort_by_key(|m| m.setting.samples);
        curves.push(Curve {
            name: format!(
                "{}, filter {}, {} bounces: samples per pixel",
                precision.name(),
                filter.name(),
                t.bounces.enough()
            ),
            points: members
                .iter()
                .map(|m| (position(m, t, floor), m.setting.samples.to_string()))
                .collect(),
            dashed: false,
        });
    }
    let mut bounces: Vec<&Measurement> = t.measurements.iter().filter(|m| m.in_bounce_sweep).collect();
    bounces.sort_by_key(|m| m.setting.bounces);
    curves.push(Curve {
        name: format!(
            "{}, bounces 0…{} at {} spp, filter {}",
            t.base.precision.name(),
            t.bounces.last,
            t.base.samples,
            t.base.filter.name()
        ),
        points: bounces
            .iter()
            .map(|m| (position(m, t, floor), format!("b{}", m.setting.bounces)))
            .collect(),
        dashed: true,
    });
    curves
}

/// The front's points in order of time, joined as a staircase: from each setting, what the next
/// faster-to-slower step buys. Everything above and right of it is beaten by a front setting.
fn staircase(front: &[(f64, f64)]) -> Vec<(f64, f64)> {
    let mut steps = Vec::with_capacity(front.len() * 2);
    for (i, &(x, y)) in front.iter().enumerate() {
        if i > 0 {
            steps.push((x, front[i - 1].1));
        }
        steps.push((x, y));
    }
    steps
}

/// A label's box in pixels: left, top, right, bottom.
type Rect = (i32, i32, i32, i32);

/// Where a `size` label beside the point at `at` (pixels) overlaps no label placed so far: above
/// right, below right, above left or below left, in that order. `None` when all four collide:
/// where settings crowd together a missing label beats an unreadable pile (the legend and the
/// report name every point anyway).
fn place_label(placed: &mut Vec<Rect>, at: (i32, i32), size: (i32, i32)) -> Option<(i32, i32)> {
    let (width, height) = size;
    // Clear of the ring around a front setting.
    let gap = 10;
    let offsets = [
        (gap, -height - gap / 2),
        (gap, gap / 2),
        (-width - gap, -height - gap / 2),
        (-width - gap, gap / 2),
    ];
    let overlaps = |a: &Rect, b: &Rect| a.0 < b.2 && b.0 < a.2 && a.1 < b.3 && b.1 < a.3;
    let rect = offsets
        .iter()
        .map(|(dx, dy)| (at.0 + dx, at.1 + dy, at.0 + dx + width, at.1 + dy + height))
        .find(|candidate| !placed.iter().any(|p| overlaps(p, candidate)))?;
    placed.push(rect);
    Some((rect.0, rect.1))
}

/// A compact tick label: `0.01`, `2.5`, `300`, `1e-5`.
fn tick(value: f64) -> String {
    if !(1e-3..1e5).contains(&value.abs()) {
        return format!("{value:.0e}");
    }
    let decimals = (2 - value.abs().log10().floor() as i32).max(0) as usize;
    let text = format!("{value:.decimals$}");
    if text.contains('.') {
        text.trim_end_matches('0').trim_end_matches('.').to_owned()
    } else {
        text
    }
}

fn draw(t: &Tradeoff, pixels: &mut [u8]) -> Result<(), Box<dyn std::error::Error>> {
    let root = BitMapBackend::with_buffer(pixels, (WIDTH, HEIGHT)).into_drawing_area();
    root.fill(&WHITE)?;
    let floor = (
        floor_of(t.measurements.iter().map(|m| m.seconds), 1e-6),
        floor_of(t.measurements.iter().map(|m| t.metric.of(&m.errors)), 1e-6),
    );
    let all: Vec<(f64, f64)> = t.measurements.iter().map(|m| position(m, t, floor)).collect();
    let (x_min, x_max) = all
        .iter()
        .fold((f64::MAX, f64::MIN), |(lo, hi), p| (lo.min(p.0), hi.max(p.0)));
    let (y_min, y_max) = all
        .iter()
        .fold((f64::MAX, f64::MIN), |(lo, hi), p| (lo.min(p.1), hi.max(p.1)));

    let caption = format!(
        "{}: {} against time ({} spp reference)",
        t.case_name,
        t.metric.title(),
        t.reference.samples
    );
    let mut chart = ChartBuilder::on(&root)
        .caption(caption, (FONT, 22))
        .margin(18)
        .x_label_area_size(52)
        .y_label_area_size(76)
        // Room above the points for the legend, and beside them for the labels.
        .build_cartesian_2d(
            (x_min / 1.6..x_max * 2.0).log_scale(),
            (y_min / 1.6..y_max * 4.0).log_scale(),
        )?;
    chart
        .configure_mesh()
        .x_desc("render time (seconds, log scale)")
        .y_desc(format!("{} (log scale)", t.metric.title()))
        .x_label_formatter(&|v| tick(*v))
        .y_label_formatter(&|v| tick(*v))
        .label_style((FONT, 14))
        .axis_desc_style((FONT, 16))
        .light_line_style(RGBColor(235, 235, 235))
        .bold_line_style(RGBColor(200, 200, 200))
        .draw()?;

    let mut front: Vec<(f64, f64)> = all
        .iter()
        .zip(&t.pareto)
        .filter(|(_, on)| **on)
        .map(|(p, _)| *p)
        .collect();
    front.sort_by(|a, b| a.0.total_cmp(&b.0).then(b.1.total_cmp(&a.1)));
    let front_style = RGBColor(40, 40, 40).stroke_width(2);
    chart
        .draw_series(DashedLineSeries::new(
            staircase(&front),
            5,
            4,
            RGBColor(90, 90, 90).stroke_width(1),
        ))?
        .label(format!(
            "Pareto front by {}: nothing is both faster and better",
            t.metric.column()
        ))
        .legend(move |(x, y)| Circle::new((x, y), 7, front_style));
    chart.draw_series(front.iter().map(|&p| Circle::new(p, 9, front_style)))?;

    let mut placed: Vec<Rect> = Vec::new();
    for (index, curve) in curves(t, floor).into_iter().enumerate() {
        let color = PALETTE[index % PALETTE.len()];
        let style = color.stroke_width(2);
        let line: Vec<(f64, f64)> = curve.points.iter().map(|(p, _)| *p).collect();
        let drawn = if curve.dashed {
            chart.draw_series(DashedLineSeries::new(line, 8, 5, style))?
        } else {
            chart.draw_series(LineSeries::new(line, style))?
        };
        drawn
            .label(curve.name)
            .legend(move |(x, y)| PathElement::new(vec![(x - 12, y), (x + 12, y)], style));
        chart.draw_series(curve.points.iter().map(|&(p, _)| Circle::new(p, 4, color.filled())))?;
        let label_style = TextStyle::from((FONT, 13).into_font()).color(&color);
        for (p, label) in curve.points {
            let (width, height) = root.estimate_text_size(&label, &label_style)?;
            if let Some(corner) = place_label(&mut placed, chart.backend_coord(&p), (width as i32, height as i32)) {
                root.draw(&Text::new(label, corner, label_style.clone()))?;
            }
        }
    }

    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .margin(10)
        .label_font((FONT, 14))
        .background_style(WHITE.mix(0.9))
        .border_style(RGBColor(160, 160, 160))
        .draw()?;
    root.present()?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ticks_are_compact() {
        assert_eq!(tick(0.01), "0.01");
        assert_eq!(tick(0.025), "0.025");
        assert_eq!(tick(2.5), "2.5");
        assert_eq!(tick(300.0), "300");
        assert_eq!(tick(1e-5), "1e-5");
    }

    #[test]
    fn labels_move_aside_for_each_other_and_give_up_when_boxed_in() {
        let mut placed = Vec::new();
        let first = place_label(&mut placed, (100, 100), (20, 10)).unwrap();
        assert_eq!(first, (110, 85), "above right");
        let second = place_label(&mut placed, (102, 100), (20, 10)).unwrap();
        assert_eq!(second, (112, 105), "below right, since above right is taken");
        assert!(
            place_label(&mut placed, (101, 100), (20, 10)).is_some(),
            "a left side is free"
        );
        assert!(place_label(&mut placed, (101, 100), (20, 10)).is_some());
        assert_eq!(
            place_label(&mut placed, (101, 100), (20, 10)),
            None,
            "all four sides are taken"
        );
        assert_eq!(placed.len(), 4);
    }

    #[test]
    fn the_front_is_joined_as_a_staircase() {
        let steps = staircase(&[(1.0, 0.5), (2.0, 0.2), (4.0, 0.1)]);
        assert_eq!(steps, [(1.0, 0.5), (2.0, 0.5), (2.0, 0.2), (4.0, 0.2), (4.0, 0.1)]);
    }

    #[test]
    fn our_png_is_recognised_and_others_are_not() {
        let bytes = encode(&vec![0; (WIDTH * HEIGHT * 3) as usize]).unwrap();
        assert!(is_our_png(&bytes));
        let other = crate::film::encode_png(&crate::rgb_image::RgbImage::new(4, 4)).unwrap();
        assert!(!is_our_png(&other));
        assert!(!is_our_png(b"not a png"));
    }
}
