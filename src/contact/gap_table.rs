//! A punch profile given as a table: heights `h_i` at distances `0 = x_0 < x_1 < … < x_n` from
//! the axis of a symmetric punch (`h(−x) = h(x)`), for a measured or designed pad that no
//! formula describes.
//!
//! The points are joined by Schumaker's shape-preserving quadratic spline (L. L. Schumaker,
//! "On shape preserving quadratic spline interpolation", SIAM J. Numer. Anal. 20 (1983)
//! 854–864): through every point, with a continuous slope, and convex where the points are. On
//! each interval `[x_i, x_{i+1}]` of secant slope `δ_i` it is one or two parabolas that leave
//! `x_i` with the node slope `s_i` and reach `x_{i+1}` with `s_{i+1}`, joined at a knot
//! `ξ = x_i + α w` (`w = x_{i+1} − x_i`) where the slope is
//!
//! ```text
//! s̄ = 2δ_i − s_i α − s_{i+1}(1 − α)
//! ```
//!
//! (so that the mean slope over the interval is δ_i); the slope rises monotonically from
//! `s_i` through `s̄` to `s_{i+1}` (h'' ≥ 0 on both parabolas) when
//! `s_i < δ_i < s_{i+1}` and α lies in
//! `[(s_i + s_{i+1} − 2δ_i)/(s_{i+1} − s_i), 2(s_{i+1} − δ_i)/(s_{i+1} − s_i)] ∩ [0, 1]`; fretsim
//! takes the middle of that range. The node slopes are `s_0 = 0` (a smooth tip on the axis),
//! inside `s_i = (w_i δ_{i−1} + w_{i−1} δ_i)/(w_{i−1} + w_i)` (the slope of the parabola
//! through three points: points on a parabola give that parabola exactly), and at the end
//! `s_n = 2δ_{n−1} − s_{n−1}`; on a straight run of points (two equal secants in a row, or a
//! flat at the axis) the slopes at its ends are the run's. Beyond `x_n` the profile goes on
//! straight with the slope `s_n`; the scenario's rules keep the contact inside the table.
//!
//! A table is refused ([`GapTable::new`]) when it is not convex (a secant slope lower than the
//! one before, or the lowest point away from the axis: the contact would not be one interval)
//! or not smooth enough for a slope-continuous profile through its points: a straight run that
//! meets a different slope at a point (a corner, where the pressure is singular), including a
//! wedge at the axis.

use serde::{Deserialize, Serialize};

/// A tabulated symmetric profile ([`crate::contact::Profile::Tabulated`]): the points as
/// given, and the spline through them.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "Vec<[f64; 2]>", into = "Vec<[f64; 2]>")]
pub struct GapTable {
    /// The points `(x_i, h_i)` as given (m).
    points: Vec<[f64; 2]>,
    /// The parabolas, in order of x, each from its `start` to the next one's.
    pieces: Vec<Piece>,
    /// The slope beyond the last point.
    end_slope: f64,
}

/// `h(x) = h0 + s0 (x − x0) + c (x − x0)²/2` from `x0`, with `∫₀^{x0} h = area`.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Piece {
    x0: f64,
    h0: f64,
    s0: f64,
    c: f64,
    area: f64,
}

impl Piece {
    fn height(&self, x: f64) -> f64 {
        let d = x - self.x0;
        self.h0 + d * (self.s0 + 0.5 * self.c * d)
    }

    fn slope(&self, x: f64) -> f64 {
        self.s0 + self.c * (x - self.x0)
    }

    fn area_to(&self, x: f64) -> f64 {
        let d = x - self.x0;
        self.area + d * (self.h0 + d * (0.5 * self.s0 + self.c * d / 6.0))
    }
}

/// Why a table is refused: the message (after the point's value, `[x, h] is invalid; …`), and
/// the index of the point it is about.
#[derive(Debug, Clone, PartialEq)]
pub struct TableIssue {
    /// The point the rule is about (`points[i]`), if one.
    pub point: Option<usize>,
    /// What is wrong and what the rule is.
    pub message: String,
}

impl TableIssue {
    fn at(point: usize, message: String) -> Self {
        Self {
            point: Some(point),
            message,
        }
    }
}

impl GapTable {
    /// The profile through `points` `[x (m), h (m)]`: x from 0 (the axis), strictly
    /// increasing; the heights are taken relative to the first. At least three points; convex
    /// and smooth (module docs).
    pub fn new(points: Vec<[f64; 2]>) -> Result<Self, TableIssue> {
        let n = points.len();
        if n < 3 {
            return Err(TableIssue {
                point: None,
                message: format!(
                    "{n} point(s) is invalid; a table needs at least 3 `[x, h]` points"
                ),
            });
        }
        if let Some(i) = points.iter().position(|p| !p.iter().all(|v| v.is_finite())) {
            return Err(TableIssue::at(
                i,
                "is invalid; x and h must be finite numbers (m)".into(),
            ));
        }
        if points[0][0] != 0.0 {
            return Err(TableIssue::at(
                0,
                "is invalid; the first point must be on the axis, x = 0 (the table gives x ≥ 0 of a symmetric punch)".into(),
            ));
        }
        if let Some(i) = (1..n).find(|&i| points[i][0] <= points[i - 1][0]) {
            return Err(TableIssue::at(
                i,
                "is invalid; x must increase strictly from point to point".into(),
            ));
        }
        let x: Vec<f64> = points.iter().map(|p| p[0]).collect();
        let h: Vec<f64> = points.iter().map(|p| p[1] - points[0][1]).collect();
        let w: Vec<f64> = x.windows(2).map(|p| p[1] - p[0]).collect();
        let secant: Vec<f64> = (0..n - 1).map(|i| (h[i + 1] - h[i]) / w[i]).collect();
        let scale = secant.iter().fold(0.0_f64, |m, s| m.max(s.abs()));
        let tol = 1e-9 * scale;
        let same = |a: f64, b: f64| (a - b).abs() <= tol;
        if secant[0] < -tol {
            return Err(TableIssue::at(
                1,
                "is invalid; it is lower than the point on the axis, and the axis must be the profile's lowest point".into(),
            ));
        }
        if let Some(i) = (1..n - 1).find(|&i| secant[i] < secant[i - 1] - tol) {
            return Err(TableIssue::at(
                i,
                format!(
                    "is invalid; it makes the profile concave (slope {:.4e} before it, {:.4e} after), and the profile must be convex (smooth a measured profile before tabulating it)",
                    secant[i - 1],
                    secant[i]
                ),
            ));
        }
        // Intervals that the convex interpolant must take straight: a flat at the axis (the
        // slope is 0 there), or two equal secants in a row.
        let straight = |i: usize| {
            (i == 0 && same(secant[0], 0.0))
                || (i > 0 && same(secant[i - 1], secant[i]))
                || (i + 2 < n && same(secant[i + 1], secant[i]))
        };
        let m = n - 1;
        let mut slope = vec![0.0; n];
        for j in 1..n {
            slope[j] = if straight(j - 1) {
                secant[j - 1]
            } else if j < m && straight(j) {
                secant[j]
            } else if j < m {
                (w[j] * secant[j - 1] + w[j - 1] * secant[j]) / (w[j - 1] + w[j])
            } else {
                2.0 * secant[m - 1] - slope[m - 1]
            };
        }
        let mut pieces: Vec<Piece> = Vec::with_capacity(2 * m);
        let mut area = 0.0;
        let mut push = |x0: f64, h0: f64, s0: f64, c: f64, width: f64| {
            let piece = Piece {
                x0,
                h0,
                s0,
                c,
                area,
            };
            area = piece.area_to(x0 + width);
            pieces.push(piece);
        };
        for i in 0..m {
            let (s0, s1, d) = (slope[i], slope[i + 1], secant[i]);
            if straight(i) {
                if !(same(s0, d) && same(s1, d)) {
                    let corner = if same(s0, d) { i + 1 } else { i };
                    return Err(TableIssue::at(
                        corner,
                        format!(
                            "is invalid; it is a corner of the profile (a straight run of slope {d:.4e} meets another slope there), and the profile must have a continuous slope (round the corner with more points)"
                        ),
                    ));
                }
                push(x[i], h[i], d, 0.0, w[i]);
                continue;
            }
            // s0 < d < s1 here (module docs): two parabolas, joined at ξ = x_i + αw.
            let rise = s1 - s0;
            let lower = ((s0 + s1 - 2.0 * d) / rise).max(0.0);
            let upper = (2.0 * (s1 - d) / rise).min(1.0);
            let alpha = 0.5 * (lower + upper);
            let mid = 2.0 * d - s0 * alpha - s1 * (1.0 - alpha);
            let (w0, w1) = (alpha * w[i], (1.0 - alpha) * w[i]);
            push(x[i], h[i], s0, (mid - s0) / w0, w0);
            let h_mid = h[i] + 0.5 * (s0 + mid) * w0;
            push(x[i] + w0, h_mid, mid, (s1 - mid) / w1, w1);
        }
        let end_slope = slope[m];
        push(x[m], h[m], end_slope, 0.0, 0.0);
        Ok(Self {
            points,
            pieces,
            end_slope,
        })
    }

    /// The points as given (m).
    pub fn points(&self) -> &[[f64; 2]] {
        &self.points
    }

    /// The last tabulated x (m).
    pub fn extent(&self) -> f64 {
        self.points[self.points.len() - 1][0]
    }

    /// The piece that holds t ≥ 0.
    fn piece(&self, t: f64) -> &Piece {
        let k = self.pieces.partition_point(|p| p.x0 <= t);
        &self.pieces[k.saturating_sub(1)]
    }

    /// h(x) (m).
    pub fn gap(&self, x: f64) -> f64 {
        let t = x.abs();
        self.piece(t).height(t)
    }

    /// h'(x) (–).
    pub fn slope(&self, x: f64) -> f64 {
        let t = x.abs();
        x.signum() * self.piece(t).slope(t)
    }

    /// `∫ h dx` from `x1` to `x2` (m²).
    pub fn gap_integral(&self, x1: f64, x2: f64) -> f64 {
        let odd = |x: f64| {
            let t = x.abs();
            x.signum() * self.piece(t).area_to(t)
        };
        odd(x2) - odd(x1)
    }

    /// The half-width of a flat face on the axis (m): where the profile first rises (0 for a
    /// table without a flat).
    pub fn flat_half_width(&self) -> f64 {
        self.pieces
            .iter()
            .find(|p| p.s0 != 0.0 || p.c != 0.0)
            .map_or(0.0, |p| p.x0)
    }

    /// h''(0⁺) (1/m): the tip's curvature.
    pub fn tip_curvature(&self) -> f64 {
        self.pieces[0].c
    }

    /// The load (N/m) of the frictionless contact of half-width `a` (m) on a half-plane of
    /// pressure compliance Y* (1/Pa), `P = (2/Y*)∫₀^a x h'(x)/√(a² − x²) dx`, in closed form on
    /// each piece (h' = α + βx there: `∫ x/√(a² − x²) = −√(a² − x²)` and
    /// `∫ x²/√(a² − x²) = (a²/2) arcsin(x/a) − (x/2)√(a² − x²)`).
    pub fn frictionless_load(&self, a: f64, compliance: f64) -> f64 {
        let root = |x: f64| (a * a - x * x).max(0.0).sqrt();
        let second = |x: f64| 0.5 * a * a * (x / a).clamp(-1.0, 1.0).asin() - 0.5 * x * root(x);
        let mut sum = 0.0;
        for (k, p) in self.pieces.iter().enumerate() {
            if p.x0 >= a {
                break;
            }
            let end = self.pieces.get(k + 1).map_or(a, |q| q.x0.min(a));
            let (alpha, beta) = (p.s0 - p.c * p.x0, p.c);
            sum += alpha * (root(p.x0) - root(end)) + beta * (second(end) - second(p.x0));
        }
        2.0 * sum / compliance
    }

    /// The frictionless contact half-width (m) under `load` (N/m): the root of
    /// [`Self::frictionless_load`], which rises with a for a convex profile (bisection).
    pub fn frictionless_half_width(&self, load: f64, compliance: f64) -> f64 {
        let mut hi = self.extent();
        while self.frictionless_load(hi, compliance) < load && hi < 1e6 * self.extent() {
            hi *= 2.0;
        }
        let mut lo = 0.0;
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if self.frictionless_load(mid, compliance) < load {
                lo = mid;
            } else {
                hi = mid;
            }
            if hi - lo <= 1e-15 * hi {
                break;
            }
        }
        0.5 * (lo + hi)
    }

    /// The end slope beyond the table (–).
    pub fn end_slope(&self) -> f64 {
        self.end_slope
    }
}

impl TryFrom<Vec<[f64; 2]>> for GapTable {
    type Error = String;

    fn try_from(points: Vec<[f64; 2]>) -> Result<Self, String> {
        let points_copy = points.clone();
        Self::new(points).map_err(|issue| match issue.point {
            Some(i) => format!("points[{i}] {:?} {}", points_copy[i], issue.message),
            None => issue.message,
        })
    }
}

impl From<GapTable> for Vec<[f64; 2]> {
    fn from(table: GapTable) -> Self {
        table.points
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sampled(f: impl Fn(f64) -> f64, extent: f64, n: usize) -> GapTable {
        let points = (0..=n)
            .map(|i| {
                // Uneven spacing: the points need not be equally spaced.
                let u = i as f64 / n as f64;
                let x = extent * (0.7 * u + 0.3 * u * u);
                [x, f(x)]
            })
            .collect();
        GapTable::new(points).unwrap()
    }

    /// Points on a parabola give that parabola (the three-point node slopes are exact, and so
    /// is each interval's pair of parabolas): h, h' and ∫h of a cylinder to round-off, at
    /// points between and beyond the nodes.
    #[test]
    fn a_table_of_a_cylinder_is_the_cylinder() {
        let radius = 0.01;
        let cylinder = crate::contact::Profile::cylinder(radius);
        let table = sampled(|x| x * x / (2.0 * radius), 1e-4, 9);
        for k in 0..=300 {
            let x = -1.2e-4 + 2.4e-4 * k as f64 / 300.0;
            if x.abs() <= 1e-4 {
                assert!((table.gap(x) - cylinder.gap(x)).abs() <= 1e-13 * cylinder.gap(1e-4));
                assert!((table.slope(x) - cylinder.slope(x)).abs() <= 1e-12 * 1e-2);
                let exact = cylinder.gap_integral(-3e-5, x);
                assert!((table.gap_integral(-3e-5, x) - exact).abs() <= 1e-13 * 1e-4 * 5e-7);
            }
        }
        assert!((table.tip_curvature() * radius - 1.0).abs() < 1e-10);
        let y = 2.3e-11;
        let hertz = crate::analytical::Hertz::new(2240.0, radius, y).half_width;
        let a = table.frictionless_half_width(2240.0, y);
        assert!((a / hertz - 1.0).abs() < 1e-12, "{a} against {hertz}");
    }

    /// Points of a convex profile that no parabola fits (the power law |x|⁴): the spline goes
    /// through every point, its slope is continuous and rises everywhere (convex), and it
    /// converges to the profile as the table is refined (third order in the spacing, as a
    /// quadratic spline does: measured 2.7e−3, 3.8e−4 and 5.0e−5 of h at the table's end with
    /// 11, 21 and 41 points, falling 7.2× and 7.6× as the points double).
    #[test]
    fn a_table_of_a_power_law_interpolates_convexly_and_converges() {
        let power = crate::contact::Profile::power_law(1.25e11, 4.0);
        let extent = 1e-4;
        let mut errors = Vec::new();
        for n in [10, 20, 40] {
            let table = sampled(|x| power.gap(x), extent, n);
            for p in table.points() {
                assert!((table.gap(p[0]) - p[1]).abs() <= 1e-14 * power.gap(extent));
            }
            let mut worst: f64 = 0.0;
            let mut last_slope = -1.0;
            for k in 0..=2000 {
                let x = extent * k as f64 / 2000.0;
                let s = table.slope(x);
                assert!(s >= last_slope - 1e-15, "slope falls at {x}");
                last_slope = s;
                worst = worst.max((table.gap(x) - power.gap(x)).abs());
            }
            for piece in &table.pieces {
                assert!(piece.c >= 0.0);
            }
            // Continuity of h and h' at every knot.
            for pair in table.pieces.windows(2) {
                let (p, q) = (&pair[0], &pair[1]);
                assert!((p.height(q.x0) - q.h0).abs() <= 1e-15 * power.gap(extent));
                assert!((p.slope(q.x0) - q.s0).abs() <= 1e-12 * table.end_slope());
            }
            errors.push(worst / power.gap(extent));
        }
        assert!(errors[0] < 3e-3 && errors[1] < errors[0] / 6.0 && errors[2] < errors[1] / 6.0);
    }

    /// A flat face with rounded corners, `h = (x − b)²/(2R)` beyond b, with a point at b: the
    /// flat is taken straight and the corner parabola exactly (its node slope is the flat's).
    #[test]
    fn a_table_of_a_flat_punch_keeps_the_flat_and_the_corner() {
        let (b, radius) = (1e-5, 0.01);
        let flat = crate::contact::Profile::flat_rounded(b, radius);
        let xs = [0.0, 0.5e-5, 1e-5, 2e-5, 3.5e-5, 5e-5, 8e-5];
        let table = GapTable::new(xs.iter().map(|&x| [x, flat.gap(x)]).collect()).unwrap();
        for k in 0..=400 {
            let x = 8e-5 * k as f64 / 400.0;
            assert!(
                (table.gap(x) - flat.gap(x)).abs() <= 1e-12 * flat.gap(8e-5),
                "{x}"
            );
        }
        assert!(table.slope(0.7e-5).abs() < 1e-18);
        assert!((table.flat_half_width() - b).abs() < 1e-20);
        let cylinder = sampled(|x| x * x / (2.0 * radius), 1e-4, 9);
        assert!(cylinder.flat_half_width().abs() < f64::MIN_POSITIVE);
    }

    /// The rules: at least three points; the first on the axis; x increasing; the lowest point
    /// on the axis; convex; no corner (a wedge at the axis, a flat meeting a straight flank).
    #[test]
    fn tables_that_are_not_convex_or_not_smooth_are_refused() {
        let refuse = |points: Vec<[f64; 2]>| GapTable::new(points).unwrap_err();
        assert_eq!(refuse(vec![[0.0, 0.0], [1e-5, 1e-9]]).point, None);
        assert_eq!(
            refuse(vec![[1e-6, 0.0], [1e-5, 1e-9], [2e-5, 4e-9]]).point,
            Some(0)
        );
        assert_eq!(
            refuse(vec![[0.0, 0.0], [2e-5, 1e-9], [2e-5, 4e-9]]).point,
            Some(2)
        );
        assert_eq!(
            refuse(vec![[0.0, 0.0], [1e-5, -1e-9], [2e-5, 4e-9]]).point,
            Some(1)
        );
        let concave = refuse(vec![[0.0, 0.0], [1e-5, 1e-9], [2e-5, 4e-9], [3e-5, 5e-9]]);
        assert_eq!(concave.point, Some(2));
        assert!(concave.message.contains("convex"), "{}", concave.message);
        let wedge = refuse(vec![[0.0, 0.0], [1e-5, 1e-7], [2e-5, 2e-7], [3e-5, 4e-7]]);
        assert_eq!(wedge.point, Some(0));
        assert!(wedge.message.contains("corner"));
        let chamfer = refuse(vec![[0.0, 0.0], [1e-5, 0.0], [2e-5, 1e-7], [3e-5, 2e-7]]);
        assert_eq!(chamfer.point, Some(1));
        assert!(GapTable::new(vec![[0.0, 0.0], [1e-5, 1e-9], [2e-5, 4e-9]]).is_ok());
        let nan = refuse(vec![[0.0, 0.0], [1e-5, f64::NAN], [2e-5, 4e-9]]);
        assert_eq!(nan.point, Some(1));
    }
}
