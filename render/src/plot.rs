//! Line charts (the training loss curve).

use super::canvas::{Canvas, Rgb};

/// One line of a chart.
#[derive(Debug, Clone)]
pub struct Series {
    /// `(x, y)` points in order.
    pub points: Vec<(f64, f64)>,
    /// Line colour.
    pub colour: Rgb,
    /// Line width in pixels.
    pub width: f64,
}

const BACKGROUND: Rgb = [255, 255, 255];
const AXIS: Rgb = [60, 60, 60];
const GRID: Rgb = [225, 225, 225];

/// Compact tick label: `1e-3`, `0.5`, `20k`.
fn label(value: f64) -> String {
    if value == 0.0 {
        return "0".into();
    }
    let a = value.abs();
    if a >= 1000.0 && (value / 1000.0).fract() == 0.0 {
        format!("{}k", value / 1000.0)
    } else if (0.01..1000.0).contains(&a) {
        let s = format!("{value:.2}");
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        format!("{value:.0e}")
    }
}

/// A chart of `series` with a log-10 y axis (non-positive values are skipped), a title and axis
/// captions, `width x height` pixels.
pub fn log_chart(
    series: &[Series],
    title: &str,
    x_caption: &str,
    y_caption: &str,
    width: usize,
    height: usize,
) -> Canvas {
    let mut canvas = Canvas::new(width, height, BACKGROUND);
    let (left, right, top, bottom) = (70.0, 20.0, 36.0, 40.0);
    let plot_w = width as f64 - left - right;
    let plot_h = height as f64 - top - bottom;
    let finite = series
        .iter()
        .flat_map(|s| s.points.iter())
        .filter(|p| p.0.is_finite() && p.1.is_finite() && p.1 > 0.0);
    let (mut x_min, mut x_max, mut y_min, mut y_max) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for &(x, y) in finite {
        x_min = x_min.min(x);
        x_max = x_max.max(x);
        y_min = y_min.min(y.log10());
        y_max = y_max.max(y.log10());
    }
    canvas.text(left as i64, 10, title, 2, AXIS);
    if x_min > x_max {
        return canvas;
    }
    if x_max == x_min {
        x_max = x_min + 1.0;
    }
    let (y_lo, y_hi) = (y_min.floor(), y_max.ceil().max(y_min.floor() + 1.0));
    let px = |x: f64| left + (x - x_min) / (x_max - x_min) * plot_w;
    let py = |ly: f64| top + (y_hi - ly) / (y_hi - y_lo) * plot_h;
    // Decade grid lines with labels, and 2x / 5x minor lines.
    let mut decade = y_lo;
    while decade <= y_hi + 1e-9 {
        let y = py(decade);
        canvas.line(left, y, left + plot_w, y, 1.0, GRID);
        let text = label(10f64.powf(decade));
        let w = Canvas::text_width(&text, 1) as f64;
        canvas.text((left - 6.0 - w) as i64, (y - 3.0) as i64, &text, 1, AXIS);
        for minor in [2.0f64, 5.0] {
            let ly = decade + minor.log10();
            if ly < y_hi {
                let y = py(ly);
                canvas.line(left, y, left + plot_w, y, 1.0, [240, 240, 240]);
            }
        }
        decade += 1.0;
    }
    for k in 0..=4 {
        let x = x_min + (x_max - x_min) * k as f64 / 4.0;
        let text = label(x.round());
        let w = Canvas::text_width(&text, 1) as f64;
        canvas.text(
            (px(x) - w / 2.0) as i64,
            (top + plot_h + 8.0) as i64,
            &text,
            1,
            AXIS,
        );
    }
    for s in series {
        let mut last: Option<(f64, f64)> = None;
        for &(x, y) in &s.points {
            if !(x.is_finite() && y.is_finite() && y > 0.0) {
                last = None;
                continue;
            }
            let p = (px(x), py(y.log10()));
            if let Some(q) = last {
                canvas.line(q.0, q.1, p.0, p.1, s.width, s.colour);
            }
            last = Some(p);
        }
    }
    canvas.line(left, top, left, top + plot_h, 1.0, AXIS);
    canvas.line(left, top + plot_h, left + plot_w, top + plot_h, 1.0, AXIS);
    let w = Canvas::text_width(x_caption, 1) as f64;
    canvas.text(
        (left + plot_w / 2.0 - w / 2.0) as i64,
        height as i64 - 14,
        x_caption,
        1,
        AXIS,
    );
    canvas.text(6, (top - 14.0) as i64, y_caption, 1, AXIS);
    canvas
}
