//! Fields below the surface at the instants that get field files (`output.subsurface`): the
//! grid, the fields at its points from [`crate::subsurface`] (computed here from each kept
//! state; the library does no I/O), the table of `subsurface/<stem>.csv` and the colour maps.
//!
//! # Grid
//! In units of the contact half-width a at the end of normal loading: `nx` columns
//! `x_i = a (x0 + (x1 − x0) i/(nx − 1))` (x from the punch axis, `x_range = [x0, x1]`) and `nz`
//! rows `z_j = a·depth·j/(nz − 1)`. The first row is the surface limit z → 0⁺, evaluated at
//! `z = 1e−9 a` ([`SURFACE_ROW_DEPTH`]; [`crate::subsurface`] is as accurate there as at depth,
//! so σzz = −p, σxz = −q, σxx is the surface σxx0 of the field files, seed paper eq. (64), and
//! Dz = −g); the table gives the depth actually used. Rows run from the surface down, columns
//! from x0 to x1 within a row.
//!
//! # Quantities
//! As [`SubsurfacePoint`]: σxx, σzz, σxz, σyy of plane strain, the von Mises stress
//! `σ_vM = √(½[(σxx − σyy)² + (σyy − σzz)² + (σzz − σxx)²] + 3σxz²)`, the in-plane principal
//! stresses `σ1,2 = (σxx + σzz)/2 ± τ_max` and `τ_max = √(((σxx − σzz)/2)² + σxz²)`; for a
//! piezoelectric solid also D and `E = −∇φ`. σyy and σ_vM need c12, which the built-in
//! presets carry ([`crate::subsurface::PRESET_C12`]); for a piezoelectric solid of other
//! constants they are left empty and the map shows τ_max instead.
//!
//! # Maps
//! A colour map of σ_vM (τ_max without c12) and, for a piezoelectric solid, of
//! `|D| = √(Dx² + Dz²)`, in ten bands of equal width from 0 to the largest value (viridis, a
//! legend entry per band); when the largest value exceeds 1.5 times the 99th percentile (the
//! fields of a conducting punch are singular at the contact ends) the scale stops at the 99th
//! percentile and the top band holds everything above it. Depth is drawn downward (the y axis
//! is −z), the contact ends (grey) and stick-zone ends (blue) are marked by triangles on the
//! surface. Units as the field plots: x/a, σ/p0, |D|/g0 (`plot_units = normalised`) or SI.

use rayon::prelude::*;

use crate::history::SolvedState;
use crate::io::csv::{Column, Table};
use crate::io::plots::{PlotScales, ZoneEnds};
use crate::io::svg::{Area, Figure, Series};
use crate::scenario::RawSubsurface;
use crate::subsurface::{
    DEFAULT_PANELS_PER_HALF, SubsurfaceError, SubsurfaceKernel, SubsurfacePoint, SurfaceLoads,
    subsurface_fields,
};

/// Depth of the grid's first row, the surface limit, in units of a.
pub const SURFACE_ROW_DEPTH: f64 = 1e-9;

/// Colour bands of a map.
const BANDS: usize = 10;

/// Field points per parallel task.
const CHUNK: usize = 256;

/// The grid of field points (m) of `output.subsurface` (module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct SubsurfaceGrid {
    /// Column abscissae x (m).
    pub xs: Vec<f64>,
    /// Row depths z (m), the first [`SURFACE_ROW_DEPTH`]·a.
    pub zs: Vec<f64>,
    /// The unit a (m): the contact half-width at the end of normal loading.
    pub half_width: f64,
}

impl SubsurfaceGrid {
    /// The grid of `raw` for the unit `a` (m).
    pub fn new(raw: &RawSubsurface, a: f64) -> Self {
        let spaced = |from: f64, to: f64, n: usize| -> Vec<f64> {
            (0..n)
                .map(|i| a * (from + (to - from) * i as f64 / (n - 1) as f64))
                .collect()
        };
        let [x0, x1] = raw.x_range;
        let mut zs = spaced(0.0, raw.depth, raw.nz);
        zs[0] = SURFACE_ROW_DEPTH * a;
        Self {
            xs: spaced(x0, x1, raw.nx),
            zs,
            half_width: a,
        }
    }

    /// The points (x, z), row by row from the surface down.
    pub fn points(&self) -> Vec<(f64, f64)> {
        self.zs
            .iter()
            .flat_map(|&z| self.xs.iter().map(move |&x| (x, z)))
            .collect()
    }
}

/// The fields below the surface at one instant.
#[derive(Debug, Clone)]
pub struct SubsurfaceMap {
    /// The grid.
    pub grid: SubsurfaceGrid,
    /// The fields at [`SubsurfaceGrid::points`], in its order.
    pub points: Vec<SubsurfacePoint>,
    /// Whether the solid is piezoelectric (the table then has D and E).
    pub piezoelectric: bool,
}

/// The kernel and the grid of a run that asks for subsurface fields.
#[derive(Debug, Clone)]
pub(crate) struct SubsurfaceOutput {
    kernel: SubsurfaceKernel,
    grid: SubsurfaceGrid,
    piezoelectric: bool,
}

impl SubsurfaceOutput {
    /// For `material` and the grid `raw` in units of `a` (m).
    pub(crate) fn new(
        material: &crate::material::Material,
        raw: &RawSubsurface,
        a: f64,
    ) -> Result<Self, SubsurfaceError> {
        Ok(Self {
            kernel: SubsurfaceKernel::try_new(material)?,
            grid: SubsurfaceGrid::new(raw, a),
            piezoelectric: material.is_piezoelectric(),
        })
    }

    /// Whether σyy and the von Mises stress can be computed (c12 known).
    pub(crate) fn has_von_mises(&self) -> bool {
        self.kernel.has_sigma_yy()
    }

    /// The fields under a state: a spectral state's densities on the composite rule of
    /// [`SurfaceLoads::of_state`], an element state's constant on its elements.
    pub(crate) fn map(&self, state: &SolvedState) -> Result<SubsurfaceMap, SubsurfaceError> {
        let (loads, bulk_stress) = match state {
            SolvedState::Spectral(s) => (SurfaceLoads::of_state(s, DEFAULT_PANELS_PER_HALF)?, 0.0),
            SolvedState::General(_, s) => (SurfaceLoads::of_elements(s)?, s.loads.bulk_stress),
        };
        let points = self.grid.points();
        let mut chunks = points
            .par_chunks(CHUNK)
            .map(|chunk| subsurface_fields(&self.kernel, &loads, chunk))
            .collect::<Result<Vec<_>, _>>()?;
        // The uniform state of a bulk stress, added to the contact's fields.
        if bulk_stress != 0.0 {
            let bulk = self.kernel.bulk_state(bulk_stress);
            for p in chunks.iter_mut().flatten() {
                *p = p.with_bulk(bulk_stress, &bulk);
            }
        }
        Ok(SubsurfaceMap {
            grid: self.grid.clone(),
            points: chunks.into_iter().flatten().collect(),
            piezoelectric: self.piezoelectric,
        })
    }
}

/// The columns of `subsurface/<stem>.csv`: x_m, z_m, x_over_a, z_over_a, the stresses (Pa;
/// syy_Pa and von_mises_Pa empty without c12) and, for a piezoelectric solid, D (C/m²) and E
/// (V/m).
pub fn subsurface_table(map: &SubsurfaceMap) -> Table {
    let a = map.grid.half_width;
    let real = |f: fn(&SubsurfacePoint) -> f64| Column::Real(map.points.iter().map(f).collect());
    let maybe = |f: fn(&SubsurfacePoint) -> Option<f64>| {
        Column::MaybeReal(map.points.iter().map(f).collect())
    };
    let mut columns = vec![
        ("x_m", real(|p| p.x)),
        ("z_m", real(|p| p.z)),
        (
            "x_over_a",
            Column::Real(map.points.iter().map(|p| p.x / a).collect()),
        ),
        (
            "z_over_a",
            Column::Real(map.points.iter().map(|p| p.z / a).collect()),
        ),
        ("sxx_Pa", real(|p| p.sigma_xx)),
        ("szz_Pa", real(|p| p.sigma_zz)),
        ("sxz_Pa", real(|p| p.sigma_xz)),
        ("syy_Pa", maybe(|p| p.sigma_yy)),
        ("von_mises_Pa", maybe(|p| p.von_mises)),
        ("principal_1_Pa", real(|p| p.max_principal)),
        (
            "principal_2_Pa",
            real(|p| p.max_principal - 2.0 * p.max_shear),
        ),
        ("max_shear_Pa", real(|p| p.max_shear)),
    ];
    if map.piezoelectric {
        columns.extend([
            ("d_x_C_per_m2", real(|p| p.d_x)),
            ("d_z_C_per_m2", real(|p| p.d_z)),
            ("e_x_V_per_m", real(|p| p.e_x)),
            ("e_z_V_per_m", real(|p| p.e_z)),
        ]);
    }
    Table { columns }
}

/// The top of a map's colour scale: the largest value, or the 99th percentile when the
/// largest exceeds 1.5 times it (a singular field); and whether it was clipped.
fn colour_top(values: &[f64]) -> (f64, bool) {
    let mut sorted: Vec<f64> = values.iter().copied().filter(|v| v.is_finite()).collect();
    if sorted.is_empty() {
        return (1.0, false);
    }
    sorted.sort_by(f64::total_cmp);
    let max = sorted[sorted.len() - 1];
    let p99 = sorted[((sorted.len() - 1) as f64 * 0.99).round() as usize];
    match max > 1.5 * p99 && p99 > 0.0 {
        true => (p99, true),
        false => (if max > 0.0 { max } else { 1.0 }, false),
    }
}

/// The edges of the cells around grid values: midpoints between neighbours, half a spacing
/// beyond the ends (one value: ±0.5).
fn edges(values: &[f64]) -> Vec<(f64, f64)> {
    let n = values.len();
    (0..n)
        .map(|i| {
            let below = if i > 0 {
                0.5 * (values[i] - values[i - 1])
            } else if n > 1 {
                0.5 * (values[1] - values[0])
            } else {
                0.5
            };
            let above = if i + 1 < n {
                0.5 * (values[i + 1] - values[i])
            } else {
                below
            };
            (values[i] - below, values[i] + above)
        })
        .collect()
}

/// A colour map of `values` (one per grid point, already scaled) over the grid scaled by
/// `length`: the module docs' bands, the surface line and the zone ends.
struct MapPlot<'a> {
    title: String,
    x_label: String,
    y_label: String,
    unit: &'a str,
    length: f64,
    values: Vec<f64>,
}

impl MapPlot<'_> {
    fn svg(&self, grid: &SubsurfaceGrid, ends: &ZoneEnds) -> String {
        use crate::io::sweep_plots::{colour_map, short};
        let (hi, clipped) = colour_top(&self.values);
        let band = |v: f64| ((v / hi * BANDS as f64).floor().max(0.0) as usize).min(BANDS - 1);
        let colour = |k: usize| colour_map((k as f64 + 0.5) / BANDS as f64);
        let xs: Vec<f64> = grid.xs.iter().map(|x| x / self.length).collect();
        let zs: Vec<f64> = grid.zs.iter().map(|z| z / self.length).collect();
        let x_edges = edges(&xs);
        let mut z_edges = edges(&zs);
        z_edges[0].0 = 0.0;
        let caption = format!(
            "{BANDS} colour bands from 0 to {}{}; triangles on the surface: contact ends (grey), stick-zone ends (blue)",
            short(hi),
            if clipped {
                " (the 99th percentile: the field is singular at the contact ends; larger values in the top band)"
            } else {
                ""
            }
        );
        let labels: Vec<String> = (0..BANDS)
            .rev()
            .map(|k| {
                let (lo, up) = (hi * k as f64 / BANDS as f64, hi * (k + 1) as f64 / BANDS as f64);
                match (clipped, k + 1 == BANDS) {
                    (true, true) => format!("≥ {} {}", short(lo), self.unit),
                    _ => format!("{} – {} {}", short(lo), short(up), self.unit),
                }
            })
            .collect();
        let mut figure = Figure {
            title: self.title.clone(),
            x_label: self.x_label.clone(),
            y_label: self.y_label.clone(),
            caption,
            ..Figure::default()
        };
        // The legend: one swatch per band, the highest first (drawn nowhere: no vertices).
        for (label, k) in labels.iter().zip((0..BANDS).rev()) {
            figure.areas.push(Area {
                points: Vec::new(),
                fill: colour(k),
                opacity: 1.0,
                label,
            });
        }
        // Cells, a row's neighbours of one band merged into one rectangle.
        let nx = xs.len();
        for (j, &(z_top, z_bottom)) in z_edges.iter().enumerate() {
            let row = &self.values[j * nx..(j + 1) * nx];
            let mut i = 0;
            while i < nx {
                let k = band(row[i]);
                let mut end = i + 1;
                while end < nx && band(row[end]) == k {
                    end += 1;
                }
                let (x0, mut x1) = (x_edges[i].0, x_edges[end - 1].1);
                let mut bottom = z_bottom;
                // Each cell reaches a quarter cell into its right and lower neighbours, which
                // are drawn after it: no seams where the renderer blends the shared edges.
                if end < nx {
                    x1 += 0.25 * (x_edges[end].1 - x_edges[end].0);
                }
                if j + 1 < z_edges.len() {
                    bottom += 0.25 * (z_bottom - z_top);
                }
                figure.areas.push(Area {
                    points: vec![(x0, -bottom), (x1, -bottom), (x1, -z_top), (x0, -z_top)],
                    fill: colour(k),
                    opacity: 1.0,
                    label: "",
                });
                i = end;
            }
        }
        // Zone ends: triangles above the surface pointing at it.
        let (x_lo, x_hi) = (x_edges[0].0, x_edges[nx - 1].1);
        let depth = z_edges[z_edges.len() - 1].1;
        let (w, h) = (0.012 * (x_hi - x_lo), 0.04 * depth);
        let triangle = |x: f64| vec![(x - w, h), (x + w, h), (x, 0.0)];
        let mut mark = |x: f64, fill: &str, label: &'static str| {
            let x = x / self.length;
            if (x_lo..=x_hi).contains(&x) {
                figure.areas.push(Area {
                    points: triangle(x),
                    fill: fill.into(),
                    opacity: 1.0,
                    label,
                });
            }
        };
        mark(ends.contact.0, "#777", "contact ends");
        mark(ends.contact.1, "#777", "contact ends");
        if let Some((s0, s1)) = ends.stick {
            mark(s0, "#4a90d9", "stick-zone ends");
            mark(s1, "#4a90d9", "stick-zone ends");
        }
        figure.series.push(Series {
            label: "",
            points: vec![(x_lo, 0.0), (x_hi, 0.0)],
            colour: "black",
        });
        figure.svg()
    }
}

/// The colour maps of one instant (module docs): `subsurface_<stem>_von_mises` (or
/// `_max_shear` without c12) and, for a piezoelectric solid, `subsurface_<stem>_d`. `label`
/// names the instant in the titles.
pub(crate) fn subsurface_plots(
    stem: &str,
    label: &str,
    map: &SubsurfaceMap,
    ends: &ZoneEnds,
    scales: &PlotScales,
) -> Vec<(String, String)> {
    let (length, x_label, y_label) = match scales.length > 0.0 {
        true => (
            scales.length,
            format!("x/a (a = {:.4e} m)", scales.length),
            "−z/a (depth z below the surface)".to_string(),
        ),
        false => (1.0, "x (m)".into(), "−z (m) (depth z below the surface)".into()),
    };
    let by = |scale: f64, ratio: &'static str, si: &'static str| match scale > 0.0 {
        true => (scale, ratio),
        false => (1.0, si),
    };
    let has_von_mises = map.points.iter().all(|p| p.von_mises.is_some());
    let (stress, stress_unit) = by(scales.pressure, "p0", "Pa");
    let (key, title, values): (&str, &str, Vec<f64>) = if has_von_mises {
        (
            "von_mises",
            "von Mises stress σvM",
            map.points
                .iter()
                .map(|p| p.von_mises.unwrap_or(f64::NAN) / stress)
                .collect(),
        )
    } else {
        (
            "max_shear",
            "In-plane maximum shear stress τmax",
            map.points.iter().map(|p| p.max_shear / stress).collect(),
        )
    };
    let mut plots = vec![(
        format!("subsurface_{stem}_{key}"),
        MapPlot {
            title: format!("{title} below the surface, {label}"),
            x_label: x_label.clone(),
            y_label: y_label.clone(),
            unit: stress_unit,
            length,
            values,
        }
        .svg(&map.grid, ends),
    )];
    if map.piezoelectric {
        let (charge, charge_unit) = by(scales.charge, "g0", "C/m²");
        plots.push((
            format!("subsurface_{stem}_d"),
            MapPlot {
                title: format!("Electric displacement |D| below the surface, {label}"),
                x_label,
                y_label,
                unit: charge_unit,
                length,
                values: map
                    .points
                    .iter()
                    .map(|p| p.d_x.hypot(p.d_z) / charge)
                    .collect(),
            }
            .svg(&map.grid, ends),
        ));
    }
    plots
}

#[cfg(test)]
mod tests {
    use super::*;

    fn raw(nx: usize, nz: usize) -> RawSubsurface {
        RawSubsurface {
            depth: 2.0,
            x_range: [-1.0, 3.0],
            nx,
            nz,
        }
    }

    #[test]
    fn the_grid_spans_the_range_in_units_of_a_from_the_surface_limit() {
        let grid = SubsurfaceGrid::new(&raw(5, 3), 1e-4);
        assert_eq!(grid.xs.len(), 5);
        assert!((grid.xs[0] + 1e-4).abs() < 1e-18 && (grid.xs[4] - 3e-4).abs() < 1e-18);
        assert!((grid.xs[1]).abs() < 1e-18);
        assert!((grid.zs[0] - 1e-13).abs() < 1e-25);
        assert!((grid.zs[1] - 1e-4).abs() < 1e-18 && (grid.zs[2] - 2e-4).abs() < 1e-18);
        let points = grid.points();
        assert_eq!(points.len(), 15);
        assert_eq!(points[5], (grid.xs[0], grid.zs[1]), "rows from the surface down");
    }

    #[test]
    fn a_singular_field_has_its_colour_scale_clipped() {
        let mut values: Vec<f64> = (0..1000).map(|k| k as f64 / 1000.0).collect();
        assert_eq!(colour_top(&values), (0.999, false));
        values[17] = 40.0;
        let (top, clipped) = colour_top(&values);
        assert!(clipped && top < 1.0, "{top}");
    }

    /// A Hertz contact on an isotropic half-plane: the table's columns, and the map's bands,
    /// legend and marks.
    #[test]
    fn table_and_map_of_an_elastic_solid() {
        let material = crate::material::Material::Elastic(crate::material::ALUMINIUM);
        let out = SubsurfaceOutput::new(&material, &raw(9, 5), 1e-4).unwrap();
        let a = 1e-4;
        let rule = crate::subsurface::SurfaceRule::new(0.0, a, &[], DEFAULT_PANELS_PER_HALF)
            .unwrap();
        let loads = SurfaceLoads::from_fn(rule, |x| {
            (1e8 * (1.0 - (x / a).powi(2)).max(0.0).sqrt(), 0.0, 0.0)
        })
        .unwrap();
        let points = subsurface_fields(&out.kernel, &loads, &out.grid.points()).unwrap();
        let map = SubsurfaceMap {
            grid: out.grid.clone(),
            points,
            piezoelectric: false,
        };
        let table = subsurface_table(&map);
        let names: Vec<&str> = table.columns.iter().map(|(n, _)| *n).collect();
        assert_eq!(
            names,
            [
                "x_m",
                "z_m",
                "x_over_a",
                "z_over_a",
                "sxx_Pa",
                "szz_Pa",
                "sxz_Pa",
                "syy_Pa",
                "von_mises_Pa",
                "principal_1_Pa",
                "principal_2_Pa",
                "max_shear_Pa",
            ]
        );
        assert_eq!(table.rows(), 45);
        let ends = ZoneEnds {
            contact: (-a, a),
            stick: Some((-0.5 * a, 0.5 * a)),
        };
        let scales = PlotScales::normalised(a, 1e8, 0.3, 0.0);
        let plots = subsurface_plots("normal_loading", "end of normal loading", &map, &ends, &scales);
        assert_eq!(plots.len(), 1);
        let (name, svg) = &plots[0];
        assert_eq!(name, "subsurface_normal_loading_von_mises");
        assert!(svg.contains("−z/a") && svg.contains("σvM"));
        assert!(svg.contains(">contact ends<") && svg.contains(">stick-zone ends<"));
        // The legend's ten bands, 0.0 – 0.05 p0 … up to the largest value.
        assert_eq!(svg.matches(" p0<").count(), BANDS, "{svg}");
        // The largest value (on the axis) is in the top band's colour.
        let top = crate::io::sweep_plots::colour_map((BANDS as f64 - 0.5) / BANDS as f64);
        assert!(svg.matches(&format!(r#"fill="{top}""#)).count() >= 2, "{top}");
    }

    /// A piezoelectric solid of unknown c12: empty σyy and von Mises cells, a map of τmax
    /// instead, and a map of |D|, whose singular values (a spike at one point) clip the scale.
    #[test]
    fn a_piezoelectric_map_without_c12_shows_the_maximum_shear_and_d() {
        let grid = SubsurfaceGrid::new(&raw(20, 10), 1e-4);
        let points: Vec<SubsurfacePoint> = grid
            .points()
            .iter()
            .enumerate()
            .map(|(k, &(x, z))| SubsurfacePoint {
                x,
                z,
                sigma_xx: -1e7,
                sigma_zz: -2e7,
                sigma_xz: 0.0,
                sigma_yy: None,
                d_x: if k == 5 { 1.0 } else { 1e-3 * k as f64 },
                d_z: 0.0,
                e_x: 0.0,
                e_z: 0.0,
                von_mises: None,
                max_principal: -1e7,
                max_shear: 5e6,
            })
            .collect();
        let map = SubsurfaceMap {
            grid,
            points,
            piezoelectric: true,
        };
        let csv = String::from_utf8(subsurface_table(&map).csv()).unwrap();
        let mut lines = csv.lines();
        assert!(lines.next().unwrap().ends_with(
            "syy_Pa,von_mises_Pa,principal_1_Pa,principal_2_Pa,max_shear_Pa,d_x_C_per_m2,d_z_C_per_m2,e_x_V_per_m,e_z_V_per_m"
        ));
        assert!(lines.next().unwrap().contains(",,,"), "empty σyy and von Mises");
        let ends = ZoneEnds {
            contact: (-1e-4, 1e-4),
            stick: None,
        };
        let plots = subsurface_plots("t_1.000000", "t = 1 s", &map, &ends, &PlotScales::SI);
        let names: Vec<&str> = plots.iter().map(|(n, _)| n.as_str()).collect();
        assert_eq!(names, ["subsurface_t_1.000000_max_shear", "subsurface_t_1.000000_d"]);
        assert!(plots[0].1.contains("τmax") && plots[0].1.contains("x (m)"));
        assert!(plots[1].1.contains("99th percentile") && plots[1].1.contains("≥ "));
        assert!(!plots[1].1.contains(">stick-zone ends<"), "no stick zone, no legend entry");
    }
}
