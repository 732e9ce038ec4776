//! The plots of a run and of a sweep (SVG) and the `index.html` that shows them.

use crate::contact::SurfacePoint;

/// The plots of the fields at the end of normal loading.
pub(crate) fn normal_loading_plots(points: &[SurfacePoint]) -> Vec<(String, String)> {
    use crate::io::svg::{Series, line_plot};
    let field =
        |f: &dyn Fn(&SurfacePoint) -> f64| points.iter().map(|p| (p.x, f(p))).collect::<Vec<_>>();
    let one = |name: &str, title: &str, y: &str, label: &str, f: &dyn Fn(&SurfacePoint) -> f64| {
        (
            name.to_string(),
            line_plot(
                &format!("End of normal loading: {title}"),
                "x (m)",
                y,
                &[Series {
                    label,
                    points: field(f),
                    colour: "black",
                }],
            ),
        )
    };
    vec![
        (
            "normal_loading_tractions".into(),
            line_plot(
                "End of normal loading: pressure p and shear traction q",
                "x (m)",
                "p, q (Pa)",
                &[
                    Series {
                        label: "p",
                        points: field(&|p| p.pressure),
                        colour: "black",
                    },
                    Series {
                        label: "q (on the half-plane)",
                        points: field(&|p| p.traction),
                        colour: "crimson",
                    },
                ],
            ),
        ),
        one(
            "normal_loading_charge",
            "surface charge g",
            "g (C/m²)",
            "g",
            &|p| p.charge,
        ),
        one(
            "normal_loading_sigma_xx",
            "surface stress σxx0",
            "σxx0 (Pa)",
            "σxx0",
            &|p| p.sigma_xx,
        ),
        one(
            "normal_loading_d_x",
            "in-plane electric displacement Dx0",
            "Dx0 (C/m²)",
            "Dx0",
            &|p| p.d_x,
        ),
    ]
}

/// One plot per field quantity (p, q, g, σxx0, Dx0) with one curve per member of a family
/// (snapshot instants of a run, or variants of a sweep), named `<prefix>_<quantity>`. Empty
/// when the family is empty.
pub fn family_plots(
    prefix: &str,
    what: &str,
    family: &[(&str, &[SurfacePoint])],
) -> Vec<(String, String)> {
    use crate::io::svg::{PALETTE, Series, line_plot};
    if family.is_empty() {
        return Vec::new();
    }
    type Quantity = (
        &'static str,
        &'static str,
        &'static str,
        fn(&SurfacePoint) -> f64,
    );
    let quantities: [Quantity; 5] = [
        ("p", "Pressure p", "p (Pa)", |p| p.pressure),
        ("q", "Shear traction q (on the half-plane)", "q (Pa)", |p| {
            p.traction
        }),
        ("g", "Surface charge g", "g (C/m²)", |p| p.charge),
        ("sigma_xx", "Surface stress σxx0", "σxx0 (Pa)", |p| {
            p.sigma_xx
        }),
        (
            "d_x",
            "In-plane electric displacement Dx0",
            "Dx0 (C/m²)",
            |p| p.d_x,
        ),
    ];
    quantities
        .iter()
        .map(|(key, title, y, f)| {
            let series: Vec<Series> = family
                .iter()
                .enumerate()
                .map(|(k, (label, points))| Series {
                    label,
                    points: points.iter().map(|p| (p.x, f(p))).collect(),
                    colour: PALETTE[k % PALETTE.len()],
                })
                .collect();
            (
                format!("{prefix}_{key}"),
                line_plot(&format!("{title} {what}"), "x (m)", y, &series),
            )
        })
        .collect()
}

/// With a history (and at least one step after normal loading): the hysteresis loop and the
/// stick-zone ends.
pub(crate) fn history_plots(
    records: &[crate::history::StepRecord],
    limit: f64,
    failed: bool,
) -> Vec<(String, String)> {
    use crate::io::svg::{Series, line_plot};
    if records.len() <= 1 {
        return Vec::new();
    }
    let note = if failed { " (stopped early)" } else { "" };
    let loop_pts: Vec<(f64, f64)> = records
        .iter()
        .map(|r| (r.displacement, r.q / limit))
        .collect();
    let ends = |f: &dyn Fn(&crate::history::StepRecord) -> f64| {
        records
            .iter()
            .map(|r| (r.t, f(r) / r.half_width))
            .collect::<Vec<_>>()
    };
    vec![
        (
            "hysteresis".into(),
            line_plot(
                &format!("Fretting loop{note}"),
                "tangential displacement δ (m)",
                "Q/(ηP) (–)",
                &[Series {
                    label: "Q–δ",
                    points: loop_pts,
                    colour: "black",
                }],
            ),
        ),
        (
            "stick_zone".into(),
            line_plot(
                &format!("Stick-zone ends and contact ends{note}"),
                "time t (s)",
                "x / a (–)",
                &[
                    Series {
                        label: "stick-zone left end",
                        points: ends(&|r| r.stick_lo),
                        colour: "navy",
                    },
                    Series {
                        label: "stick-zone right end",
                        points: ends(&|r| r.stick_hi),
                        colour: "crimson",
                    },
                    Series {
                        label: "contact ends",
                        points: ends(&|r| -r.eccentricity - r.half_width),
                        colour: "gray",
                    },
                    Series {
                        label: "",
                        points: ends(&|r| -r.eccentricity + r.half_width),
                        colour: "gray",
                    },
                ],
            ),
        ),
    ]
}

/// `index.html`: every plot on one page, in sections, and links to every file.
pub fn index_html(name: &str, sections: &[(String, Vec<String>)], files: &[String]) -> String {
    use crate::io::svg::escape;
    let name = escape(name);
    let mut body = String::new();
    for (title, plots) in sections {
        body.push_str(&format!("<h2>{}</h2>\n", escape(title)));
        for p in plots {
            body.push_str(&format!(
                "<figure><img src=\"plots/{p}.svg\" alt=\"{p}\"><figcaption>plots/{p}.svg</figcaption></figure>\n"
            ));
        }
    }
    let links: String = files
        .iter()
        .map(|f| format!("<li><a href=\"{f}\">{f}</a></li>\n", f = escape(f)))
        .collect();
    format!(
        "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>fretsim: {name}</title></head>\n<body>\n<h1>fretsim: {name}</h1>\n<p>Columns and units of every file: see the fretsim README.</p>\n{body}<h2>Files</h2>\n<ul>\n{links}</ul>\n</body></html>\n"
    )
}
