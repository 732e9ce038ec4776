//! The plots of a sweep's scalar results (the numeric columns of `sweep.csv`): with one
//! varied field each result against it; with two a map over the grid of the two fields, one
//! per result, and, with runs, maps of the verdict and of the last cycle's regime (with the
//! energy ratio's map: a fretting map, amplitude × load → regime). With three or more varied
//! fields there are no result plots.

use crate::io::svg::{Area, Figure, Note, Series};

/// One numeric result column of a sweep: its CSV name, its axis label and a value per
/// variant (NaN where the variant has none).
pub(crate) struct ResultColumn {
    /// Column of `sweep.csv`.
    pub name: &'static str,
    /// Axis label with its unit.
    pub label: &'static str,
    /// One value per variant, in the CSV's order.
    pub values: Vec<f64>,
}

/// Sequential colour map (viridis, sampled at five points and interpolated linearly).
pub(crate) fn colour_map(u: f64) -> String {
    const STOPS: [(f64, f64, f64); 5] = [
        (68.0, 1.0, 84.0),
        (59.0, 82.0, 139.0),
        (33.0, 145.0, 140.0),
        (94.0, 201.0, 98.0),
        (253.0, 231.0, 37.0),
    ];
    let u = if u.is_finite() {
        u.clamp(0.0, 1.0)
    } else {
        0.0
    };
    let at = u * (STOPS.len() - 1) as f64;
    let k = (at.floor() as usize).min(STOPS.len() - 2);
    let f = at - k as f64;
    let (a, b) = (STOPS[k], STOPS[k + 1]);
    let mix = |x: f64, y: f64| (x + f * (y - x)).round() as u8;
    format!(
        "#{:02x}{:02x}{:02x}",
        mix(a.0, b.0),
        mix(a.1, b.1),
        mix(a.2, b.2)
    )
}

/// Colours of the categories of a categorical map.
const CATEGORY_COLOURS: [&str; 6] = [
    "#2ca02c", "#1f77b4", "#ff7f0e", "#9467bd", "#d62728", "#7f7f7f",
];

/// A value in three significant digits.
pub(crate) fn short(v: f64) -> String {
    if v.is_finite() && v.abs() > 0.0 && !(1e-3..1e4).contains(&v.abs()) {
        format!("{v:.2e}")
    } else {
        let text = format!("{v:.3}");
        match text.contains('.') {
            true => text.trim_end_matches('0').trim_end_matches('.').to_string(),
            false => text,
        }
    }
}

/// The cell edges of grid values (midpoints between neighbours; half a spacing beyond the
/// ends; a single value gets ±10 % of itself, or ±0.5 at zero).
fn cell_edges(values: &[f64]) -> Vec<(f64, f64)> {
    let n = values.len();
    (0..n)
        .map(|i| {
            let half = |j: usize, k: usize| 0.5 * (values[k] - values[j]);
            let (below, above) = match (i > 0, i + 1 < n) {
                (true, true) => (half(i - 1, i), half(i, i + 1)),
                (true, false) => (half(i - 1, i), half(i - 1, i)),
                (false, true) => (half(i, i + 1), half(i, i + 1)),
                (false, false) => {
                    let h = if values[i].abs() > 0.0 {
                        0.1 * values[i].abs()
                    } else {
                        0.5
                    };
                    (h, h)
                }
            };
            (values[i] - below, values[i] + above)
        })
        .collect()
}

/// Each result against the single varied field: `sweep_<column>`.
fn line_plots(field: &str, x: &[f64], results: &[&ResultColumn]) -> Vec<(String, String)> {
    results
        .iter()
        .map(|r| {
            let points: Vec<(f64, f64)> = x.iter().copied().zip(r.values.iter().copied()).collect();
            let figure = Figure {
                title: format!("{} against {field}", r.label),
                x_label: field.to_string(),
                y_label: r.label.to_string(),
                dots: points.iter().map(|&(x, y)| (x, y, "black")).collect(),
                series: vec![Series {
                    label: "",
                    points,
                    colour: "black",
                }],
                ..Figure::default()
            };
            (format!("sweep_{}", r.name), figure.svg())
        })
        .collect()
}

/// A variant's cell of a map: its centre (the two varied values) and its x and y extents.
type Cell = ((f64, f64), (f64, f64), (f64, f64));

/// The grid of a two-field sweep: the cell of each variant (from its two values).
struct Grid<'a> {
    fields: [&'a str; 2],
    cells: Vec<Cell>,
}

impl<'a> Grid<'a> {
    fn new(fields: [&'a str; 2], axes: [&[f64]; 2], values: &[Vec<f64>]) -> Self {
        let edges = [cell_edges(axes[0]), cell_edges(axes[1])];
        let find = |axis: usize, v: f64| {
            let i = axes[axis]
                .iter()
                .position(|a| (a - v).abs() <= 1e-12 * a.abs().max(v.abs()))
                .unwrap_or(0);
            edges[axis][i]
        };
        let cells = values
            .iter()
            .map(|v| ((v[0], v[1]), find(0, v[0]), find(1, v[1])))
            .collect();
        Self { fields, cells }
    }

    /// An empty map figure titled `title`.
    fn figure(&self, title: String, caption: String) -> Figure<'a> {
        Figure {
            title,
            x_label: self.fields[0].to_string(),
            y_label: self.fields[1].to_string(),
            caption,
            ..Figure::default()
        }
    }

    fn rectangle(&self, k: usize) -> Vec<(f64, f64)> {
        let (_, (x0, x1), (y0, y1)) = self.cells[k];
        vec![(x0, y0), (x1, y0), (x1, y1), (x0, y1)]
    }
}

/// A map of one numeric result over the grid: cells coloured from the least (dark) to the
/// greatest value (yellow), each with its value; a variant without a value is left blank.
fn value_map(grid: &Grid<'_>, r: &ResultColumn) -> String {
    let finite = r.values.iter().copied().filter(|v| v.is_finite());
    let lo = finite.clone().fold(f64::INFINITY, f64::min);
    let hi = finite.fold(f64::NEG_INFINITY, f64::max);
    let span = if hi > lo { hi - lo } else { 1.0 };
    let mut figure = grid.figure(
        format!("{} over {} × {}", r.label, grid.fields[0], grid.fields[1]),
        format!("colour from {} (dark) to {} (yellow)", short(lo), short(hi)),
    );
    for (k, v) in r.values.iter().enumerate() {
        if !v.is_finite() {
            continue;
        }
        let u = (v - lo) / span;
        figure.areas.push(Area {
            points: grid.rectangle(k),
            fill: colour_map(u),
            opacity: 1.0,
            label: "",
        });
        let (x, y) = grid.cells[k].0;
        figure.notes.push(Note {
            at: (x, y),
            text: short(*v),
            // Light text on the dark half of the colour map.
            colour: if u < 0.5 { "white" } else { "black" },
        });
    }
    figure.svg()
}

/// A map of a categorical result (the verdict, the regime) over the grid, one colour per category.
fn category_map(grid: &Grid<'_>, name: &str, categories: &[String]) -> String {
    let mut kinds: Vec<&str> = categories.iter().map(String::as_str).collect();
    kinds.sort_unstable();
    kinds.dedup();
    // In words, as in the cells: `gross slip`, not `gross_slip`.
    let words: Vec<String> = kinds.iter().map(|k| k.replace('_', " ")).collect();
    let mut figure = grid.figure(
        format!("{name} over {} × {}", grid.fields[0], grid.fields[1]),
        String::new(),
    );
    for (k, c) in categories.iter().enumerate() {
        let i = kinds.iter().position(|x| x == c).unwrap_or(0);
        let label = words[i].as_str();
        figure.areas.push(Area {
            points: grid.rectangle(k),
            fill: CATEGORY_COLOURS[i % CATEGORY_COLOURS.len()].into(),
            opacity: 0.85,
            label,
        });
        // The category in the cell too: a map of one category has no legend.
        figure.notes.push(Note {
            at: grid.cells[k].0,
            text: c.replace('_', " "),
            colour: "black",
        });
    }
    figure.svg()
}

/// The result plots of a sweep (module docs). `values` holds each variant's varied values,
/// `categories` the categorical results by name, one value per variant (sweeps with runs: the
/// verdict and the last cycle's regime; `failed` for a variant whose run stopped), drawn as
/// maps over two varied fields.
pub(crate) fn sweep_plots(
    fields: &[&str],
    axes: &[Vec<f64>],
    values: &[Vec<f64>],
    results: &[ResultColumn],
    categories: &[(&str, Vec<String>)],
) -> Vec<(String, String)> {
    let results: Vec<&ResultColumn> = results
        .iter()
        .filter(|r| r.values.iter().any(|v| v.is_finite()))
        .collect();
    match (fields, axes) {
        ([field], _) => {
            let x: Vec<f64> = values.iter().map(|v| v[0]).collect();
            line_plots(field, &x, &results)
        }
        ([f0, f1], [a0, a1]) => {
            let grid = Grid::new([f0, f1], [a0, a1], values);
            let categorical = categories
                .iter()
                .map(|(name, v)| (format!("map_{name}"), category_map(&grid, name, v)));
            let numeric = results
                .iter()
                .map(|r| (format!("map_{}", r.name), value_map(&grid, r)));
            categorical.chain(numeric).collect()
        }
        _ => Vec::new(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn column(values: Vec<f64>) -> ResultColumn {
        ResultColumn {
            name: "b_over_a",
            label: "stick ratio b/a (–)",
            values,
        }
    }

    #[test]
    fn one_varied_field_plots_each_result_against_it() {
        let values = vec![vec![0.1], vec![0.2], vec![0.3]];
        let results = [column(vec![0.9, 0.8, 0.7]), {
            let mut c = column(vec![f64::NAN; 3]);
            c.name = "potential_V";
            c
        }];
        let plots = sweep_plots(
            &["friction"],
            &[vec![0.1, 0.2, 0.3]],
            &values,
            &results,
            &[],
        );
        assert_eq!(plots.len(), 1, "a column without values is not plotted");
        let (name, svg) = &plots[0];
        assert_eq!(name, "sweep_b_over_a");
        assert_eq!(svg.matches("<circle").count(), 3);
        assert!(svg.contains("against friction"));
    }

    #[test]
    fn two_varied_fields_give_maps_with_a_cell_per_variant() {
        let axes = [vec![1.0, 2.0], vec![10.0, 20.0, 30.0]];
        let values: Vec<Vec<f64>> = axes[0]
            .iter()
            .flat_map(|a| axes[1].iter().map(move |b| vec![*a, *b]))
            .collect();
        let results = [column((0..6).map(|k| k as f64).collect())];
        let verdicts: Vec<String> = ["steady_cyclic_slip", "failed"]
            .iter()
            .cycle()
            .take(6)
            .map(|s| s.to_string())
            .collect();
        let regimes = vec!["partial_slip".to_string(); 6];
        let categories = [("verdict", verdicts), ("regime", regimes)];
        let plots = sweep_plots(&["a", "b"], &axes, &values, &results, &categories);
        let names: Vec<&str> = plots.iter().map(|(n, _)| n.as_str()).collect();
        assert_eq!(names, ["map_verdict", "map_regime", "map_b_over_a"]);
        assert!(plots[1].1.contains(">partial slip<"));
        let verdict = &plots[0].1;
        assert_eq!(verdict.matches(r#"class="area""#).count(), 6);
        assert!(!verdict.contains("steady_cyclic_slip"), "in words");
        assert_eq!(
            verdict.matches(">steady cyclic slip<").count(),
            4,
            "each cell names its category, and the legend once"
        );
        assert_eq!(verdict.matches(">failed<").count(), 4);
        let map = &plots[2].1;
        assert_eq!(map.matches(r#"class="area""#).count(), 6);
        assert!(map.contains(r##"fill="#440154""##), "least value dark");
        assert!(map.contains(r##"fill="#fde725""##), "greatest value yellow");
        assert!(!map.contains(r#"fill="""#));
        assert!(sweep_plots(&["a", "b", "c"], &[], &values, &results, &[]).is_empty());
    }

    #[test]
    fn cell_edges_are_midpoints() {
        assert_eq!(
            cell_edges(&[0.0, 1.0, 3.0]),
            [(-0.5, 0.5), (0.5, 2.0), (2.0, 4.0)]
        );
        assert_eq!(cell_edges(&[2.0]), [(1.8, 2.2)]);
        assert_eq!(short(0.12345), "0.123");
        assert_eq!(short(2.0), "2");
        assert_eq!(short(1.5e-9), "1.50e-9");
    }
}
