//! The plots of a run and of a sweep (SVG) and the `index.html` that shows them.

use crate::contact::SurfacePoint;

/// How the field plots are scaled: by the end of normal loading's contact half-width a, peak
/// pressure p0, ηp0 (p0 without friction) and g0 = k·p0, the charge density that the pressure
/// carries at its peak under a conducting punch (Γ1 = kP); or in SI units. A quantity whose
/// scale is zero (no charge on an elastic half-plane) stays in SI.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlotScales {
    /// a (m); 0 for SI.
    pub length: f64,
    /// p0 (Pa).
    pub pressure: f64,
    /// ηp0 (Pa).
    pub shear: f64,
    /// g0 = k·p0 (C/m²).
    pub charge: f64,
}

impl PlotScales {
    /// Every axis in SI units.
    pub const SI: Self = Self {
        length: 0.0,
        pressure: 0.0,
        shear: 0.0,
        charge: 0.0,
    };

    /// The field plots' scales, unless the scenario asks for SI: the end of normal loading's
    /// half-width and peak pressure, or, for a history from the unloaded punch, those of the
    /// frictionless contact at its largest P (a and 2P/(πa)).
    pub(crate) fn of_run(scenario: &crate::Scenario, summary: &super::summary::Summary) -> Self {
        let n = &summary.normal_loading;
        let load = scenario.reference_load;
        let (a, p0) = if n.half_width > 0.0 {
            (n.half_width, n.peak_pressure)
        } else {
            let a = scenario.frictionless_half_width();
            (a, 2.0 * load / (std::f64::consts::PI * a))
        };
        match scenario.raw.output.plot_units {
            crate::scenario::PlotUnits::Si => PlotScales::SI,
            crate::scenario::PlotUnits::Normalised => PlotScales::normalised(
                a,
                p0,
                scenario.model.friction,
                scenario.model.pressure_charge(load) / load,
            ),
        }
    }

    /// The scales of a contact whose normal loading ended with half-width `a`, peak pressure
    /// `p0`, friction `eta` and charge per force `k` (C/N).
    pub fn normalised(a: f64, p0: f64, eta: f64, k: f64) -> Self {
        Self {
            length: a,
            pressure: p0,
            shear: if eta > 0.0 { eta * p0 } else { p0 },
            charge: (k * p0).abs(),
        }
    }

    /// `(x value, axis label)` for a length in m.
    fn x(&self) -> (f64, String) {
        scaled(self.length, "x/a", "x (m)", "a", "m")
    }
}

/// The divisor and axis label of a quantity: `name (unit)` in SI, or `ratio (symbol = value
/// unit)` when the scale is positive.
fn scaled(scale: f64, ratio: &str, si: &str, symbol: &str, unit: &str) -> (f64, String) {
    if scale > 0.0 && scale.is_finite() {
        (scale, format!("{ratio} ({symbol} = {scale:.4e} {unit})"))
    } else {
        (1.0, si.to_string())
    }
}

type Quantity = (
    &'static str,
    &'static str,
    fn(&SurfacePoint) -> f64,
    fn(&PlotScales) -> (f64, String),
);

/// The field quantities: key, title, value, and scale with its axis label.
const QUANTITIES: [Quantity; 5] = [
    (
        "p",
        "Pressure p",
        |p| p.pressure,
        |s| scaled(s.pressure, "p/p0", "p (Pa)", "p0", "Pa"),
    ),
    (
        "q",
        "Shear traction q (on the half-plane)",
        |p| p.traction,
        |s| scaled(s.shear, "q/(ηp0)", "q (Pa)", "ηp0", "Pa"),
    ),
    (
        "g",
        "Surface charge g",
        |p| p.charge,
        |s| scaled(s.charge, "g/g0", "g (C/m²)", "g0 = kp0", "C/m²"),
    ),
    (
        "sigma_xx",
        "Surface stress σxx0",
        |p| p.sigma_xx,
        |s| scaled(s.pressure, "σxx0/p0", "σxx0 (Pa)", "p0", "Pa"),
    ),
    (
        "d_x",
        "In-plane electric displacement Dx0",
        |p| p.d_x,
        |s| scaled(s.charge, "Dx0/g0", "Dx0 (C/m²)", "g0 = kp0", "C/m²"),
    ),
];

/// Where the contact and its stick zone end at one instant (m), marked on the field plots.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ZoneEnds {
    /// Contact ends `(c − a, c + a)`.
    pub contact: (f64, f64),
    /// Stick-zone ends, `None` without friction.
    pub stick: Option<(f64, f64)>,
}

impl ZoneEnds {
    /// The ends of a contact state's contact and stick zone.
    pub fn of(state: &crate::contact::ContactState) -> Self {
        Self {
            contact: (
                state.centre - state.half_width,
                state.centre + state.half_width,
            ),
            stick: state.traction.stick.as_ref().map(|z| (z.lo, z.hi)),
        }
    }
}

/// The marks of one curve's zone ends on a field plot whose x is divided by `x_scale`: the
/// stick zone shaded (`shade`, a single curve) or its ends dashed in the curve's colour, and
/// the contact ends dashed grey.
fn zone_marks<'a>(
    ends: &ZoneEnds,
    x_scale: f64,
    colour: &'a str,
    shade: bool,
    figure: &mut crate::io::svg::Figure<'a>,
) {
    use crate::io::svg::{Area, Marker};
    let (c0, c1) = ends.contact;
    // A family's contact ends that nearly coincide (within 1 % of a) are drawn once.
    let tolerance = 1e-2 * 0.5 * (c1 - c0).abs() / x_scale;
    for x in [c0, c1] {
        let drawn = figure
            .markers
            .iter()
            .any(|m| m.colour == "#777" && (m.x - x / x_scale).abs() <= tolerance);
        if drawn {
            continue;
        }
        figure.markers.push(Marker {
            x: x / x_scale,
            colour: "#777",
            label: if shade { "contact ends" } else { "" },
        });
    }
    if let Some((s0, s1)) = ends.stick {
        if shade {
            figure.areas.push(Area::band(
                s0 / x_scale,
                s1 / x_scale,
                "#4a90d9",
                0.15,
                "stick zone",
            ));
        } else {
            for x in [s0, s1] {
                figure.markers.push(Marker {
                    x: x / x_scale,
                    colour,
                    label: "",
                });
            }
        }
    }
}

/// The caption of a family's field plot: what its dashed lines mark.
const FAMILY_CAPTION: &str =
    "dashed: stick-zone ends (in the curve's colour) and contact ends (grey)";

/// The plots of the fields at the end of normal loading: p and q together, then g, σxx0 and
/// Dx0, each with the contact ends (dashed) and the stick zone (shaded) marked.
pub(crate) fn normal_loading_plots(
    points: &[SurfacePoint],
    ends: &ZoneEnds,
    scales: &PlotScales,
) -> Vec<(String, String)> {
    use crate::io::svg::{Figure, Series};
    let (x_scale, x_label) = scales.x();
    let field = |f: fn(&SurfacePoint) -> f64, scale: f64| {
        points
            .iter()
            .map(|p| (p.x / x_scale, f(p) / scale))
            .collect::<Vec<_>>()
    };
    let [p, q, rest @ ..] = &QUANTITIES;
    let (p_scale, p_label) = (p.3)(scales);
    // p and q on one axis: q in the pressure's scale.
    let tractions_label =
        p_label
            .replacen("p/p0", "p/p0, q/p0", 1)
            .replacen("p (Pa)", "p, q (Pa)", 1);
    let mut tractions = Figure {
        title: "End of normal loading: pressure p and shear traction q".into(),
        x_label: x_label.clone(),
        y_label: tractions_label,
        series: vec![
            Series {
                label: "p",
                points: field(p.2, p_scale),
                colour: "black",
            },
            Series {
                label: "q (on the half-plane)",
                points: field(q.2, p_scale),
                colour: "crimson",
            },
        ],
        ..Figure::default()
    };
    zone_marks(ends, x_scale, "black", true, &mut tractions);
    let mut plots = vec![("normal_loading_tractions".to_string(), tractions.svg())];
    let names = [
        "normal_loading_charge",
        "normal_loading_sigma_xx",
        "normal_loading_d_x",
    ];
    for ((_, title, f, scale), name) in rest.iter().zip(names) {
        let (s, label) = scale(scales);
        let mut figure = Figure {
            title: format!("End of normal loading: {}", title.to_lowercase()),
            x_label: x_label.clone(),
            y_label: label,
            series: vec![Series {
                label: "",
                points: field(*f, s),
                colour: "black",
            }],
            ..Figure::default()
        };
        zone_marks(ends, x_scale, "black", true, &mut figure);
        plots.push((name.to_string(), figure.svg()));
    }
    plots
}

/// One member of a family of field curves: legend label, samples and zone ends.
pub type FamilyMember<'a> = (&'a str, &'a [SurfacePoint], ZoneEnds);

/// One plot per field quantity (p, q, g, σxx0, Dx0) with one curve per member of a family
/// (snapshot instants of a run, or variants of a sweep), named `<prefix>_<quantity>`, each
/// member's stick-zone ends dashed in its colour and its contact ends dashed grey (a single
/// member: the stick zone shaded). Empty when the family is empty.
pub fn family_plots(
    prefix: &str,
    what: &str,
    family: &[FamilyMember<'_>],
    scales: &PlotScales,
) -> Vec<(String, String)> {
    use crate::io::svg::{Figure, PALETTE, Series};
    if family.is_empty() {
        return Vec::new();
    }
    let (x_scale, x_label) = scales.x();
    let single = family.len() == 1;
    QUANTITIES
        .iter()
        .map(|(key, title, f, scale)| {
            let (s, y_label) = scale(scales);
            let mut figure = Figure {
                title: format!("{title} {what}"),
                x_label: x_label.clone(),
                y_label,
                caption: if single {
                    String::new()
                } else {
                    FAMILY_CAPTION.into()
                },
                ..Figure::default()
            };
            for (k, (label, points, ends)) in family.iter().enumerate() {
                let colour = PALETTE[k % PALETTE.len()];
                figure.series.push(Series {
                    label,
                    points: points.iter().map(|p| (p.x / x_scale, f(p) / s)).collect(),
                    colour,
                });
                zone_marks(ends, x_scale, colour, single, &mut figure);
            }
            (format!("{prefix}_{key}"), figure.svg())
        })
        .collect()
}

/// `index.html`: a contents list (a link to each section), then every plot on one page, in
/// sections (each plot shown by its SVG, with a link to it), and links to
/// every file.
pub fn index_html(name: &str, sections: &[(String, Vec<String>)], files: &[String]) -> String {
    use crate::io::svg::escape;
    let name = escape(name);
    let anchor = |k: usize| format!("section-{}", k + 1);
    let mut contents = String::from("<nav><h2>Contents</h2>\n<ol>\n");
    let mut body = String::new();
    for (k, (title, plots)) in sections.iter().enumerate() {
        let title = escape(title);
        contents.push_str(&format!(
            "<li><a href=\"#{}\">{title}</a> ({} plot{})</li>\n",
            anchor(k),
            plots.len(),
            if plots.len() == 1 { "" } else { "s" }
        ));
        body.push_str(&format!("<h2 id=\"{}\">{title}</h2>\n", anchor(k)));
        for p in plots {
            body.push_str(&format!(
                "<figure id=\"{p}\"><img src=\"plots/{p}.svg\" alt=\"{p}\" style=\"max-width:100%\"><figcaption><a href=\"plots/{p}.svg\">plots/{p}.svg</a></figcaption></figure>\n"
            ));
        }
    }
    contents.push_str("<li><a href=\"#files\">Files</a></li>\n</ol></nav>\n");
    let links: String = files
        .iter()
        .map(|f| format!("<li><a href=\"{f}\">{f}</a></li>\n", f = escape(f)))
        .collect();
    format!(
        "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>fretsim: {name}</title></head>\n<body>\n<h1>fretsim: {name}</h1>\n<p>Columns and units of every file: see the fretsim README.</p>\n{contents}{body}<h2 id=\"files\">Files</h2>\n<ul>\n{links}</ul>\n</body></html>\n"
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn samples() -> Vec<SurfacePoint> {
        (0..9)
            .map(|k| {
                let x = (k as f64 - 4.0) * 0.5e-5;
                SurfacePoint {
                    x,
                    pressure: (1.0 - (x / 2e-5).powi(2)).max(0.0),
                    traction: 0.1 * x,
                    charge: 0.0,
                    sigma_xx: -1.0,
                    d_x: 0.0,
                }
            })
            .collect()
    }

    const ENDS: ZoneEnds = ZoneEnds {
        contact: (-2e-5, 2e-5),
        stick: Some((-1.5e-5, 1e-5)),
    };

    /// p, q, g and σxx0 at the end of normal loading: the contact ends dashed at x/a = ±1 and
    /// the stick zone shaded over [−0.75, 0.5] a, both in the legend.
    #[test]
    fn normal_loading_plots_mark_the_contact_ends_and_shade_the_stick_zone() {
        let scales = PlotScales::normalised(2e-5, 1.0, 0.3, 0.0);
        let plots = normal_loading_plots(&samples(), &ENDS, &scales);
        assert_eq!(plots.len(), 4);
        for (name, svg) in &plots {
            assert_eq!(svg.matches(r#"class="marker""#).count(), 2, "{name}");
            assert_eq!(svg.matches(r#"class="area""#).count(), 1, "{name}");
            assert!(
                svg.contains(">contact ends<") && svg.contains(">stick zone<"),
                "{name}"
            );
        }
        let svg = &plots[0].1;
        let xs: Vec<f64> = svg
            .split(r#"class="marker" x1=""#)
            .skip(1)
            .map(|s| s.split('"').next().unwrap().parse().unwrap())
            .collect();
        assert_eq!(xs.len(), 2);
        // x spans [−1, 1] (the samples): the markers at the plot area's edges.
        assert!(
            (xs[0] - 90.0).abs() < 0.01 && (xs[1] - 710.0).abs() < 0.01,
            "{xs:?}"
        );
    }

    /// A family marks each member's stick-zone ends dashed in its colour (no band) and the
    /// contact ends that coincide once.
    #[test]
    fn family_plots_dash_each_members_stick_ends_and_shared_contact_ends_once() {
        let points = samples();
        let other = ZoneEnds {
            contact: ENDS.contact,
            stick: Some((-1e-5, 1.5e-5)),
        };
        let family: Vec<FamilyMember> = vec![("A", &points, ENDS), ("B", &points, other)];
        let plots = family_plots("snapshots", "at t", &family, &PlotScales::SI);
        assert_eq!(plots.len(), 5);
        for (name, svg) in &plots {
            assert_eq!(svg.matches(r#"class="area""#).count(), 0, "{name}");
            assert_eq!(
                svg.matches(r#"class="marker""#).count(),
                2 + 2 + 2,
                "{name}"
            );
            assert_eq!(svg.matches(r##"class="marker" x1"##).count(), 6);
            assert!(svg.contains(crate::io::svg::PALETTE[1]));
            assert!(svg.contains("dashed: stick-zone ends"));
        }
        // A single member is drawn like a normal-loading plot: the stick zone shaded.
        let plots = family_plots("snapshots", "at t", &family[..1], &PlotScales::SI);
        assert!(
            plots
                .iter()
                .all(|(_, svg)| svg.matches(r#"class="area""#).count() == 1)
        );
    }

    #[test]
    fn the_page_opens_with_a_contents_list_of_its_sections() {
        let sections = vec![
            (
                "Results against friction".to_string(),
                vec!["sweep_b_over_a".to_string()],
            ),
            (
                "Fields & more".to_string(),
                vec!["a".to_string(), "b".to_string()],
            ),
        ];
        let html = index_html("s", &sections, &["sweep.csv".to_string()]);
        let contents = html.find("<h2>Contents</h2>").unwrap();
        assert!(contents < html.find("<h2 id=\"section-1\">").unwrap());
        assert!(
            html.contains("<li><a href=\"#section-1\">Results against friction</a> (1 plot)</li>")
        );
        assert!(html.contains("<li><a href=\"#section-2\">Fields &amp; more</a> (2 plots)</li>"));
        assert!(html.contains("<h2 id=\"section-2\">Fields &amp; more</h2>"));
        assert!(
            html.contains("<a href=\"#files\">Files</a>") && html.contains("<h2 id=\"files\">")
        );
    }
}
