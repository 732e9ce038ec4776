//! Minimal SVG line plots for the run outputs (no font or system-library dependency: text is
//! left to the browser). Deterministic output: same data, same bytes.

use std::fmt::Write;

/// One curve: label, points, and an SVG colour.
pub struct Series<'a> {
    /// Legend label.
    pub label: &'a str,
    /// `(x, y)` points, drawn in order.
    pub points: Vec<(f64, f64)>,
    /// Stroke colour.
    pub colour: &'a str,
}

fn nice_ticks(lo: f64, hi: f64) -> Vec<f64> {
    let span = (hi - lo).abs().max(f64::MIN_POSITIVE);
    let raw = span / 5.0;
    let mag = 10f64.powf(raw.log10().floor());
    let step = [1.0, 2.0, 5.0, 10.0]
        .iter()
        .map(|m| m * mag)
        .find(|s| span / s <= 6.0)
        .unwrap_or(10.0 * mag);
    let start = (lo / step).ceil() * step;
    (0..20)
        .map(|i| start + i as f64 * step)
        .take_while(|v| *v <= hi + 1e-9 * step)
        .collect()
}

/// Colours for families of curves (one per snapshot instant or sweep variant); beyond ten,
/// [`line_plot`] dashes the repeated colours.
pub const PALETTE: [&str; 10] = [
    "#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#17becf", "#8c564b", "#e377c2",
    "#7f7f7f", "#bcbd22",
];

/// Escape text for SVG/HTML.
pub fn escape(text: &str) -> String {
    text.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// A tick label: the shortest form that shows the tick spacing `step` (fixed notation for
/// 1e−3 ≤ |v| < 1e4, scientific otherwise; `0` for zero).
fn tick_label(v: f64, step: f64) -> String {
    if v.abs() < 1e-9 * step {
        return "0".into();
    }
    let step_exp = step.log10().floor() as i32;
    if (1e-3..1e4).contains(&v.abs()) {
        format!("{v:.*}", (-step_exp).max(0) as usize)
    } else {
        let exp = v.abs().log10().floor() as i32;
        format!("{v:.*e}", (exp - step_exp).max(0) as usize)
    }
}

/// A line plot as an SVG document: axes with ticks, labels (units in the labels), and a legend
/// to the right of the plot area when more than one series is labelled (series with an empty
/// label are not listed; a single curve is named by the axis label and the title).
pub fn line_plot(title: &str, x_label: &str, y_label: &str, series: &[Series<'_>]) -> String {
    let legend = series.iter().filter(|s| !s.label.is_empty()).count() > 1;
    let right = if legend { 250.0 } else { 40.0 };
    let (w, h, left, top, bottom) = (960.0, 440.0, 90.0, 40.0, 60.0);
    let (title, x_label, y_label) = (escape(title), escape(x_label), escape(y_label));
    let pts = series
        .iter()
        .flat_map(|s| s.points.iter())
        .filter(|(x, y)| x.is_finite() && y.is_finite());
    let (mut x0, mut x1, mut y0, mut y1) = (
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    );
    for (x, y) in pts {
        x0 = x0.min(*x);
        x1 = x1.max(*x);
        y0 = y0.min(*y);
        y1 = y1.max(*y);
    }
    if !(x0.is_finite() && y0.is_finite()) {
        (x0, x1, y0, y1) = (0.0, 1.0, 0.0, 1.0);
    }
    if x1 - x0 <= 0.0 {
        x1 = x0 + 1.0;
    }
    if y1 - y0 <= 0.0 {
        y1 = y0 + 1.0;
    }
    let pad = 0.05 * (y1 - y0);
    let (y0, y1) = (y0 - pad, y1 + pad);
    let sx = |x: f64| left + (x - x0) / (x1 - x0) * (w - left - right);
    let sy = |y: f64| h - bottom - (y - y0) / (y1 - y0) * (h - top - bottom);
    let mut svg = String::new();
    let _ = write!(
        svg,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" viewBox="0 0 {w} {h}" font-family="sans-serif" font-size="12">"#
    );
    let _ = write!(svg, r#"<rect width="{w}" height="{h}" fill="white"/>"#);
    let _ = write!(
        svg,
        r#"<text x="{}" y="22" text-anchor="middle" font-size="14">{title}</text>"#,
        (left + w - right) / 2.0
    );
    let step_of = |ticks: &[f64]| match ticks {
        [a, b, ..] => b - a,
        _ => 1.0,
    };
    let x_ticks = nice_ticks(x0, x1);
    let x_step = step_of(&x_ticks);
    for t in x_ticks {
        let x = sx(t);
        let _ = write!(
            svg,
            r##"<line x1="{x:.1}" y1="{:.1}" x2="{x:.1}" y2="{top}" stroke="#ddd"/>"##,
            h - bottom
        );
        let _ = write!(
            svg,
            r#"<text x="{x:.1}" y="{:.1}" text-anchor="middle">{}</text>"#,
            h - bottom + 16.0,
            tick_label(t, x_step)
        );
    }
    let y_ticks = nice_ticks(y0, y1);
    let y_step = step_of(&y_ticks);
    for t in y_ticks {
        let y = sy(t);
        let _ = write!(
            svg,
            r##"<line x1="{left}" y1="{y:.1}" x2="{:.1}" y2="{y:.1}" stroke="#ddd"/>"##,
            w - right
        );
        let _ = write!(
            svg,
            r#"<text x="{:.1}" y="{:.1}" text-anchor="end">{}</text>"#,
            left - 6.0,
            y + 4.0,
            tick_label(t, y_step)
        );
    }
    let _ = write!(
        svg,
        r#"<rect x="{left}" y="{top}" width="{:.1}" height="{:.1}" fill="none" stroke="black"/>"#,
        w - left - right,
        h - top - bottom
    );
    let _ = write!(
        svg,
        r#"<text x="{:.1}" y="{:.1}" text-anchor="middle">{x_label}</text>"#,
        left + (w - left - right) / 2.0,
        h - 14.0
    );
    let _ = write!(
        svg,
        r#"<text x="16" y="{:.1}" text-anchor="middle" transform="rotate(-90 16 {:.1})">{y_label}</text>"#,
        top + (h - top - bottom) / 2.0,
        top + (h - top - bottom) / 2.0
    );
    let mut legend_row = 0;
    for (k, s) in series.iter().enumerate() {
        let path: Vec<String> = s
            .points
            .iter()
            .filter(|(x, y)| x.is_finite() && y.is_finite())
            .map(|(x, y)| format!("{:.2},{:.2}", sx(*x), sy(*y)))
            .collect();
        // Colours repeat after the palette: dash the repeats so that curves stay distinct.
        let dash = match k / PALETTE.len() {
            0 => "",
            1 => r#" stroke-dasharray="6 3""#,
            _ => r#" stroke-dasharray="2 2""#,
        };
        let _ = write!(
            svg,
            r#"<polyline fill="none" stroke="{}" stroke-width="1.5"{dash} points="{}"/>"#,
            s.colour,
            path.join(" ")
        );
        if !legend || s.label.is_empty() {
            continue;
        }
        let ly = top + 8.0 + 18.0 * legend_row as f64;
        legend_row += 1;
        let lx = w - right + 12.0;
        let _ = write!(
            svg,
            r#"<line x1="{lx:.1}" y1="{ly:.1}" x2="{:.1}" y2="{ly:.1}" stroke="{}" stroke-width="2"{dash}/><text x="{:.1}" y="{:.1}">{}</text>"#,
            lx + 24.0,
            s.colour,
            lx + 30.0,
            ly + 4.0,
            escape(s.label)
        );
    }
    svg.push_str("</svg>\n");
    svg
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn plot_is_well_formed_and_deterministic() {
        let s = Series {
            label: "loop",
            points: vec![(0.0, 0.0), (1.0, 2.0), (2.0, 1.0)],
            colour: "black",
        };
        let a = line_plot("t", "x", "y", &[s]);
        assert!(a.starts_with("<svg") && a.trim_end().ends_with("</svg>"));
        assert!(a.contains("<polyline"));
        let s2 = Series {
            label: "loop",
            points: vec![(0.0, 0.0), (1.0, 2.0), (2.0, 1.0)],
            colour: "black",
        };
        assert_eq!(a, line_plot("t", "x", "y", &[s2]));
    }

    #[test]
    fn tick_labels_show_the_spacing_and_no_more() {
        assert_eq!(tick_label(0.4, 0.2), "0.4");
        assert_eq!(tick_label(2.0, 0.5), "2.0");
        assert_eq!(tick_label(5e-5, 1e-5), "5e-5");
        assert_eq!(tick_label(-2.5e-5, 5e-6), "-2.5e-5");
        assert_eq!(tick_label(1.2e7, 2e6), "1.2e7");
        assert_eq!(tick_label(1e-22, 0.5), "0");
        assert_eq!(tick_label(250.0, 50.0), "250");
    }

    #[test]
    fn text_is_escaped_and_a_legend_lists_the_labelled_series_when_there_are_several() {
        let series = |labels: &[&'static str]| -> Vec<Series<'static>> {
            labels
                .iter()
                .enumerate()
                .map(|(k, label)| Series {
                    label,
                    points: vec![(0.0, k as f64), (1.0, 1.0 - k as f64)],
                    colour: "black",
                })
                .collect()
        };
        let entries =
            |svg: &str| svg.matches("<line x1=").count() - svg.matches("stroke=\"#ddd\"").count();
        let svg = line_plot("a & b", "x (m)", "p (Pa)", &series(&["p < q & r", "", "s"]));
        assert!(svg.contains("p &lt; q &amp; r") && svg.contains("a &amp; b"));
        assert_eq!(svg.matches("<polyline").count(), 3);
        assert_eq!(entries(&svg), 2);
        let svg = line_plot("one", "x (m)", "p (Pa)", &series(&["p", ""]));
        assert_eq!(svg.matches("<polyline").count(), 2);
        assert_eq!(entries(&svg), 0, "a single labelled curve has no legend");
    }
}
