//! Minimal SVG plots for the run outputs ([`Figure`]: curves, shaded areas, dashed markers,
//! notes; no font or system-library dependency: text is left to the viewer, and
//! [`crate::io::png`] renders it with an embedded font). Deterministic output: same data, same
//! bytes.

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

/// A vertical dashed line across the plot area at `x` (contact ends, stick-zone ends).
pub struct Marker<'a> {
    /// Abscissa, in data units.
    pub x: f64,
    /// Stroke colour.
    pub colour: &'a str,
    /// Legend label (empty: not listed; markers of one label are listed once).
    pub label: &'a str,
}

/// A filled polygon in data coordinates (a shaded band, a zone, a map cell); a vertex with an
/// infinite y sits on the plot area's lower or upper edge ([`Area::band`]).
pub struct Area<'a> {
    /// Vertices, in data units.
    pub points: Vec<(f64, f64)>,
    /// Fill colour.
    pub fill: String,
    /// Fill opacity in [0, 1].
    pub opacity: f64,
    /// Legend label (empty: not listed; areas of one label are listed once).
    pub label: &'a str,
}

impl<'a> Area<'a> {
    /// A band across the whole height of the plot over `x0 ≤ x ≤ x1`.
    pub fn band(x0: f64, x1: f64, fill: &str, opacity: f64, label: &'a str) -> Self {
        let inf = f64::INFINITY;
        Self {
            points: vec![(x0, -inf), (x1, -inf), (x1, inf), (x0, inf)],
            fill: fill.into(),
            opacity,
            label,
        }
    }
}

/// Text placed at a point in data coordinates (a value in a map cell).
pub struct Note {
    /// Where (data units); the text is centred there.
    pub at: (f64, f64),
    /// The text.
    pub text: String,
    /// Text colour.
    pub colour: &'static str,
}

/// A plot: curves, shaded areas below them, dashed vertical markers and notes, with axes,
/// ticks, labels (units in the labels) and a legend to the right of the plot area when more
/// than one entry is labelled (a single curve is named by the axis label and the title).
#[derive(Default)]
pub struct Figure<'a> {
    /// Title.
    pub title: String,
    /// x-axis label.
    pub x_label: String,
    /// y-axis label.
    pub y_label: String,
    /// Curves, drawn in order over the areas.
    pub series: Vec<Series<'a>>,
    /// Shaded areas, drawn first.
    pub areas: Vec<Area<'a>>,
    /// Vertical markers.
    pub markers: Vec<Marker<'a>>,
    /// Notes.
    pub notes: Vec<Note>,
    /// Points drawn as dots: `(x, y, colour)` (the samples of a sweep).
    pub dots: Vec<(f64, f64, &'a str)>,
    /// A line of small text under the title (what the marks mean).
    pub caption: String,
}

/// A line plot as an SVG document ([`Figure`] with curves only).
#[cfg(test)]
pub fn line_plot(title: &str, x_label: &str, y_label: &str, series: &[Series<'_>]) -> String {
    Figure {
        title: title.into(),
        x_label: x_label.into(),
        y_label: y_label.into(),
        series: series
            .iter()
            .map(|s| Series {
                label: s.label,
                points: s.points.clone(),
                colour: s.colour,
            })
            .collect(),
        ..Figure::default()
    }
    .svg()
}

/// The data range of a figure: `(x0, x1, y0, y1)`, never empty, y padded by 5 %.
fn data_range(figure: &Figure<'_>) -> (f64, f64, f64, f64) {
    let pts = figure
        .series
        .iter()
        .flat_map(|s| s.points.iter().copied())
        .chain(figure.areas.iter().flat_map(|a| a.points.iter().copied()))
        .chain(figure.dots.iter().map(|&(x, y, _)| (x, y)))
        .filter(|(x, y)| x.is_finite() && y.is_finite());
    let (mut x0, mut x1, mut y0, mut y1) = (
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    );
    for (x, y) in pts {
        x0 = x0.min(x);
        x1 = x1.max(x);
        y0 = y0.min(y);
        y1 = y1.max(y);
    }
    for m in figure.markers.iter().filter(|m| m.x.is_finite()) {
        x0 = x0.min(m.x);
        x1 = x1.max(m.x);
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
    // Dots at the ends of the x range stay whole.
    let x_pad = if figure.dots.is_empty() {
        0.0
    } else {
        0.03 * (x1 - x0)
    };
    (x0 - x_pad, x1 + x_pad, y0 - pad, y1 + pad)
}

/// The sample drawn beside a legend label.
enum Swatch<'a> {
    /// A curve: colour and dash.
    Line(&'a str, &'static str),
    /// An area: fill and opacity.
    Fill(&'a str, f64),
    /// A vertical dashed marker: colour.
    Marker(&'a str),
}

impl Swatch<'_> {
    /// The swatch's SVG, its left end at (x, y).
    fn draw(&self, x: f64, y: f64) -> String {
        match self {
            Swatch::Line(colour, dash) => format!(
                r#"<line x1="{x:.1}" y1="{y:.1}" x2="{:.1}" y2="{y:.1}" stroke="{colour}" stroke-width="2"{dash}/>"#,
                x + 24.0
            ),
            Swatch::Fill(fill, opacity) => format!(
                r#"<rect x="{x:.1}" y="{:.1}" width="24" height="10" fill="{fill}" fill-opacity="{opacity}"/>"#,
                y - 5.0
            ),
            Swatch::Marker(colour) => format!(
                r#"<line x1="{x:.1}" y1="{:.1}" x2="{x:.1}" y2="{:.1}" stroke="{colour}" stroke-width="1" stroke-dasharray="4 3"/>"#,
                y - 7.0,
                y + 7.0,
                x = x + 12.0
            ),
        }
    }
}

/// The legend entries of a figure, each label once, curves first, then areas and markers.
fn legend_entries<'a>(figure: &'a Figure<'a>) -> Vec<(&'a str, Swatch<'a>)> {
    let mut seen = std::collections::BTreeSet::new();
    let curves = figure
        .series
        .iter()
        .enumerate()
        .map(|(k, s)| (s.label, Swatch::Line(s.colour, dash_of(k))));
    let areas = figure
        .areas
        .iter()
        .map(|a| (a.label, Swatch::Fill(a.fill.as_str(), a.opacity)));
    let markers = figure
        .markers
        .iter()
        .map(|m| (m.label, Swatch::Marker(m.colour)));
    curves
        .chain(areas)
        .chain(markers)
        .filter(|(label, _)| !label.is_empty() && seen.insert(*label))
        .collect()
}

/// Colours repeat after the palette: dash the repeats so that curves stay distinct.
fn dash_of(k: usize) -> &'static str {
    match k / PALETTE.len() {
        0 => "",
        1 => r#" stroke-dasharray="6 3""#,
        _ => r#" stroke-dasharray="2 2""#,
    }
}

impl Figure<'_> {
    /// The figure as an SVG document. Deterministic: same data, same bytes.
    pub fn svg(&self) -> String {
        let entries = legend_entries(self);
        let legend = entries.len() > 1;
        let right = if legend { 250.0 } else { 40.0 };
        let top = if self.caption.is_empty() { 40.0 } else { 56.0 };
        let (w, h, left, bottom) = (960.0, 440.0 + top - 40.0, 90.0, 60.0);
        let (x0, x1, y0, y1) = data_range(self);
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
            r#"<text x="{}" y="22" text-anchor="middle" font-size="14">{}</text>"#,
            (left + w - right) / 2.0,
            escape(&self.title)
        );
        if !self.caption.is_empty() {
            let _ = write!(
                svg,
                r##"<text x="{}" y="40" text-anchor="middle" font-size="11" fill="#444">{}</text>"##,
                (left + w - right) / 2.0,
                escape(&self.caption)
            );
        }
        self.axes(&mut svg, (x0, x1, y0, y1), (w, h, left, right, top, bottom));
        // Areas under everything else, clipped to the plot area.
        let _ = write!(
            svg,
            r#"<clipPath id="plot-area"><rect x="{left}" y="{top}" width="{:.1}" height="{:.1}"/></clipPath><g clip-path="url(#plot-area)">"#,
            w - left - right,
            h - top - bottom
        );
        for a in self.areas.iter().filter(|a| !a.points.is_empty()) {
            // An infinite y stands for the plot area's edge (a band across the plot).
            let path: Vec<String> = a
                .points
                .iter()
                .filter(|(x, y)| x.is_finite() && !y.is_nan())
                .map(|(x, y)| format!("{:.2},{:.2}", sx(*x), sy(y.clamp(y0, y1))))
                .collect();
            let _ = write!(
                svg,
                r#"<polygon class="area" fill="{}" fill-opacity="{}" stroke="none" points="{}"/>"#,
                a.fill,
                a.opacity,
                path.join(" ")
            );
        }
        for m in self.markers.iter().filter(|m| m.x.is_finite()) {
            let _ = write!(
                svg,
                r#"<line class="marker" x1="{x:.2}" y1="{top}" x2="{x:.2}" y2="{:.1}" stroke="{}" stroke-width="1" stroke-dasharray="4 3"/>"#,
                h - bottom,
                m.colour,
                x = sx(m.x)
            );
        }
        for (k, s) in self.series.iter().enumerate() {
            let path: Vec<String> = s
                .points
                .iter()
                .filter(|(x, y)| x.is_finite() && y.is_finite())
                .map(|(x, y)| format!("{:.2},{:.2}", sx(*x), sy(*y)))
                .collect();
            let _ = write!(
                svg,
                r#"<polyline fill="none" stroke="{}" stroke-width="1.5"{} points="{}"/>"#,
                s.colour,
                dash_of(k),
                path.join(" ")
            );
        }
        for (x, y, colour) in self
            .dots
            .iter()
            .filter(|d| d.0.is_finite() && d.1.is_finite())
        {
            let _ = write!(
                svg,
                r#"<circle cx="{:.2}" cy="{:.2}" r="3.5" fill="{colour}"/>"#,
                sx(*x),
                sy(*y)
            );
        }
        svg.push_str("</g>");
        for n in &self.notes {
            let _ = write!(
                svg,
                r#"<text x="{:.1}" y="{:.1}" text-anchor="middle" font-size="11" fill="{}">{}</text>"#,
                sx(n.at.0),
                sy(n.at.1) + 4.0,
                n.colour,
                escape(&n.text)
            );
        }
        if legend {
            for (row, (label, swatch)) in entries.iter().enumerate() {
                let ly = top + 8.0 + 18.0 * row as f64;
                let lx = w - right + 12.0;
                svg.push_str(&swatch.draw(lx, ly));
                let _ = write!(
                    svg,
                    r#"<text x="{:.1}" y="{:.1}">{}</text>"#,
                    lx + 30.0,
                    ly + 4.0,
                    escape(label)
                );
            }
        }
        svg.push_str("</svg>\n");
        svg
    }

    /// Grid, ticks, frame and axis labels.
    fn axes(
        &self,
        svg: &mut String,
        (x0, x1, y0, y1): (f64, f64, f64, f64),
        (w, h, left, right, top, bottom): (f64, f64, f64, f64, f64, f64),
    ) {
        let sx = |x: f64| left + (x - x0) / (x1 - x0) * (w - left - right);
        let sy = |y: f64| h - bottom - (y - y0) / (y1 - y0) * (h - top - bottom);
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
            r#"<text x="{:.1}" y="{:.1}" text-anchor="middle">{}</text>"#,
            left + (w - left - right) / 2.0,
            h - 14.0,
            escape(&self.x_label)
        );
        let mid = top + (h - top - bottom) / 2.0;
        let _ = write!(
            svg,
            r#"<text x="16" y="{mid:.1}" text-anchor="middle" transform="rotate(-90 16 {mid:.1})">{}</text>"#,
            escape(&self.y_label)
        );
    }
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
