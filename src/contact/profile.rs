//! The punch's profile: the height `h(x)` of its surface above its lowest point, at a distance x
//! from its axis. The rigid punch imposes on the contact (eq. 18, with uz positive into the
//! solid)
//!
//! ```text
//! uz(x) = δ0 − h(x − x_p),   ∂uz/∂x = −h'(x − x_p)
//! ```
//!
//! where δ0 is the approach and x_p the punch axis in the frame of the solid.
//!
//! - The cylinder, `h(x) = x²/(2R)`, `h'(x) = x/R`: its constant curvature 1/R makes the
//!   frictionless pressure the square-root ellipse and normal loading self-similar (Spence),
//!   which the spectral solver of the paper relies on ([`Profile::curvature`]).
//! - The flat punch with rounded corners, the standard fretting-fatigue pad: a flat face of
//!   half-width b and corners of radius R, `h(x) = (|x| − b)²/(2R)` for `|x| > b` and 0 on the
//!   flat. Its contact is not self-similar; the general solver takes it
//!   ([`crate::history::NormalEnd`]). For a contact `|x| ≤ a`, `a > b`, `φ0 = arcsin(b/a)`,
//!   the frictionless half-plane with pressure compliance Y* carries (Ciavarella, Hills and
//!   Monno 1998, from `P = (1/Y*)∫ x h'(x)/√(a² − x²) dx`)
//!
//! ```text
//! P = a² (π/2 − φ0 − sin φ0 cos φ0)/(R Y*),
//! p(0) = (2a/(π R Y*)) [π/2 − φ0 − sin φ0 ln((1 + cos φ0)/sin φ0)]
//! ```
//!
//! which are Hertz's `P = πa²/(2RY*)` and `p0 = a/(RY*)` at b = 0.
//! - The power law `h(x) = A|x|ⁿ`, n ≥ 1 (convex; n = 2 with A = 1/(2R) is the cylinder):
//!   `P = 2nA aⁿ W(n)/Y*` with Wallis's `W(n) = ∫₀^{π/2} sinⁿφ dφ`
//!   ([`crate::analytical::power_law_half_width`]). The general solver takes it too.
//!
//! - A table of heights, `h(x)` through points `(x_i, h_i)` of one side of a symmetric punch
//!   joined by Schumaker's convex, slope-continuous quadratic spline ([`GapTable`]): for a
//!   measured or designed pad. Its frictionless load is the integral above in closed form on
//!   each parabola. The general solver takes it.
//!
//! On an uncoupled half-plane the Cattaneo-type stick zone of a symmetric punch under Q from
//! zero at constant P carries the load `P(c) = P − |Q|/η` of the same punch (Jäger's and
//! Ciavarella's superposition): `c/a = (1 − |Q|/(ηP))^(1/n)` for the power law.

use serde::{Deserialize, Serialize};

use super::GapTable;

/// A punch profile.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Profile {
    /// A circular cylinder of radius R (m), in its parabolic (small-slope) form.
    Cylinder {
        /// Radius R (m).
        radius: f64,
    },
    /// A flat face of half-width b (m) with corners of radius R (m), parabolic beyond it.
    FlatRounded {
        /// Half-width b of the flat face (m).
        half_flat: f64,
        /// Corner radius R (m).
        radius: f64,
    },
    /// A power law `h = A|x|ⁿ`, n ≥ 1.
    PowerLaw {
        /// A (m^(1−n)).
        coefficient: f64,
        /// n.
        exponent: f64,
    },
    /// A table of heights `[x, h]` (m) from the axis, joined by a convex spline.
    Tabulated {
        /// The points and their spline.
        points: GapTable,
    },
}

impl Profile {
    /// A cylinder of radius `radius` (m).
    pub fn cylinder(radius: f64) -> Self {
        Self::Cylinder { radius }
    }

    /// A flat punch of half-width `half_flat` with corners of radius `radius` (m).
    pub fn flat_rounded(half_flat: f64, radius: f64) -> Self {
        Self::FlatRounded { half_flat, radius }
    }

    /// The power law `h = coefficient·|x|^exponent`.
    pub fn power_law(coefficient: f64, exponent: f64) -> Self {
        Self::PowerLaw {
            coefficient,
            exponent,
        }
    }

    /// Whether the spectral solver of the paper takes the profile (the cylinder only).
    pub fn is_cylinder(&self) -> bool {
        matches!(self, Self::Cylinder { .. })
    }

    /// The half-width of the flat face (m; 0 but for the flat punch and a table with a flat).
    pub fn flat_half_width(&self) -> f64 {
        match self {
            Self::FlatRounded { half_flat, .. } => *half_flat,
            Self::Tabulated { points } => points.flat_half_width(),
            _ => 0.0,
        }
    }

    /// The height h(x) of the surface above its lowest point at x from the axis (m).
    pub fn gap(&self, x: f64) -> f64 {
        match self {
            Self::Cylinder { radius } => x * x / (2.0 * radius),
            Self::FlatRounded { half_flat, radius } => {
                let d = (x.abs() - half_flat).max(0.0);
                d * d / (2.0 * radius)
            }
            Self::PowerLaw {
                coefficient,
                exponent,
            } => coefficient * x.abs().powf(*exponent),
            Self::Tabulated { points } => points.gap(x),
        }
    }

    /// `∫ h dx` from `x1` to `x2` (m²): the mean gap of an element of the general solver times
    /// its width.
    pub fn gap_integral(&self, x1: f64, x2: f64) -> f64 {
        // Antiderivatives, odd in x.
        let odd = |f: &dyn Fn(f64) -> f64| f(x2) - f(x1);
        match self {
            Self::Cylinder { radius } => (x2.powi(3) - x1.powi(3)) / (6.0 * radius),
            Self::FlatRounded { half_flat, radius } => odd(&|x: f64| {
                x.signum() * (x.abs() - half_flat).max(0.0).powi(3) / (6.0 * radius)
            }),
            Self::PowerLaw {
                coefficient,
                exponent,
            } => odd(&|x: f64| {
                x.signum() * coefficient * x.abs().powf(exponent + 1.0) / (exponent + 1.0)
            }),
            Self::Tabulated { points } => points.gap_integral(x1, x2),
        }
    }

    /// The slope h'(x) (–).
    pub fn slope(&self, x: f64) -> f64 {
        match self {
            Self::Cylinder { radius } => x / radius,
            Self::FlatRounded { half_flat, radius } => {
                x.signum() * (x.abs() - half_flat).max(0.0) / radius
            }
            Self::PowerLaw {
                coefficient,
                exponent,
            } => x.signum() * coefficient * exponent * x.abs().powf(exponent - 1.0),
            Self::Tabulated { points } => points.slope(x),
        }
    }

    /// `h''/Y*` for a pressure compliance Y* (1/Pa): the scale of the pressure's unit response
    /// on the collocation grid (eq. 52's right-hand side; the spectral solver's cylinder).
    pub fn pressure_scale(&self, compliance: f64) -> f64 {
        1.0 / (self.radius() * compliance)
    }

    /// The curvature h'' (1/m): the cylinder's, constant, which the spectral solver relies on
    /// (the pressure then scales with one unit response of the collocation grid); the flat
    /// punch's corners'; for the power law, `2A`, its value at n = 2; for a table, the tip's
    /// (the spectral solver never takes these three; [`Self::frictionless_half_width`] is the
    /// general solver's guess).
    pub fn curvature(&self) -> f64 {
        1.0 / self.radius()
    }

    /// 1/h'' of [`Self::curvature`] (m).
    fn radius(&self) -> f64 {
        match self {
            Self::Cylinder { radius } | Self::FlatRounded { radius, .. } => *radius,
            Self::PowerLaw { coefficient, .. } => 1.0 / (2.0 * coefficient),
            Self::Tabulated { points } => 1.0 / points.tip_curvature(),
        }
    }

    /// The frictionless contact half-width (m) under load P (N/m) on a half-plane of pressure
    /// compliance Y* (1/Pa): Hertz's for the cylinder, [`crate::analytical::FlatRounded`]'s
    /// for the flat punch, and for the power law, from `P = (1/Y*)∫ x h'(x)/√(a² − x²) dx`,
    /// `P = 2nA aⁿ W(n)/Y*` with Wallis's integral `W(n) = ∫₀^{π/2} sinⁿφ dφ`; for a table,
    /// the root of its load ([`GapTable::frictionless_half_width`]).
    pub fn frictionless_half_width(&self, load: f64, compliance: f64) -> f64 {
        match self {
            Self::Cylinder { radius } => {
                crate::analytical::Hertz::new(load, *radius, compliance).half_width
            }
            Self::FlatRounded { half_flat, radius } => crate::analytical::FlatRounded {
                half_flat: *half_flat,
                radius: *radius,
                compliance,
            }
            .half_width(load),
            Self::PowerLaw {
                coefficient,
                exponent,
            } => {
                crate::analytical::power_law_half_width(*coefficient, *exponent, load, compliance)
            }
            Self::Tabulated { points } => points.frictionless_half_width(load, compliance),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// h' is the derivative of h and h'' of h' (central differences, exact for a parabola to
    /// round-off).
    #[test]
    fn slope_and_curvature_are_the_derivatives_of_the_gap() {
        let p = Profile::cylinder(0.06);
        let step = 1e-6;
        for x in [-3e-5, 0.0, 1e-5, 4e-5] {
            let slope = (p.gap(x + step) - p.gap(x - step)) / (2.0 * step);
            assert!((slope - p.slope(x)).abs() <= 1e-9 * p.slope(4e-5), "{x}");
            let curvature = (p.slope(x + step) - p.slope(x - step)) / (2.0 * step);
            assert!((curvature - p.curvature()).abs() <= 1e-9 * p.curvature());
        }
        assert!(p.gap(0.0).abs() < f64::MIN_POSITIVE);
        // The integral by Simpson's rule, exact for a parabola.
        let (x1, x2) = (-1e-5, 3e-5);
        let simpson = (x2 - x1) / 6.0 * (p.gap(x1) + 4.0 * p.gap(0.5 * (x1 + x2)) + p.gap(x2));
        assert!((p.gap_integral(x1, x2) - simpson).abs() <= 1e-15 * simpson);
    }

    /// The power law: h' is the derivative of h, ∫h that of a fine midpoint rule, and n = 2
    /// with A = 1/(2R) is the cylinder (its frictionless half-width Hertz's).
    #[test]
    fn the_power_law_slope_and_integral_are_those_of_its_gap() {
        let p = Profile::power_law(1.25e11, 4.0);
        for x in [-3e-5_f64, 1e-6, 2e-5] {
            let step = 1e-10;
            let slope = (p.gap(x + step) - p.gap(x - step)) / (2.0 * step);
            assert!((slope - p.slope(x)).abs() <= 1e-6 * p.slope(x).abs());
        }
        let (x1, x2) = (-3e-5, 2e-5);
        let n = 200_000;
        let h = (x2 - x1) / n as f64;
        let midpoint: f64 = (0..n).map(|i| p.gap(x1 + (i as f64 + 0.5) * h) * h).sum();
        assert!((p.gap_integral(x1, x2) - midpoint).abs() <= 1e-8 * midpoint);
        let (parabola, cylinder) = (Profile::power_law(1.0 / 0.12, 2.0), Profile::cylinder(0.06));
        for x in [-3e-5, 2e-5] {
            assert!((parabola.gap(x) - cylinder.gap(x)).abs() <= 1e-15 * cylinder.gap(x));
        }
        let (load, compliance) = (2000.0, 2.3e-11);
        let hertz = cylinder.frictionless_half_width(load, compliance);
        assert!((parabola.frictionless_half_width(load, compliance) / hertz - 1.0).abs() < 1e-13);
    }

    /// The flat punch with rounded corners: zero on the flat, the corner parabola beyond it,
    /// continuous in h and h'; its integral against a fine midpoint rule across the corners.
    #[test]
    fn the_flat_punch_is_flat_then_parabolic_and_its_integral_is_exact() {
        let (b, radius) = (1e-5, 0.01);
        let p = Profile::flat_rounded(b, radius);
        assert!(!p.is_cylinder() && Profile::cylinder(radius).is_cylinder());
        for x in [-0.9 * b, 0.0, 0.5 * b, b] {
            assert!(p.gap(x).abs() < f64::MIN_POSITIVE && p.slope(x).abs() < f64::MIN_POSITIVE);
        }
        for x in [-3e-5_f64, 1.5e-5, 4e-5] {
            let d = x.abs() - b;
            assert!((p.gap(x) - d * d / (2.0 * radius)).abs() <= 1e-15 * p.gap(x));
            let step = 1e-9;
            let slope = (p.gap(x + step) - p.gap(x - step)) / (2.0 * step);
            assert!((slope - p.slope(x)).abs() <= 1e-6 * p.slope(x).abs());
        }
        for (x1, x2) in [(-3e-5, 2e-5), (-5e-6, 5e-6), (5e-6, 3e-5)] {
            let n = 200_000;
            let h = (x2 - x1) / n as f64;
            let midpoint: f64 = (0..n).map(|i| p.gap(x1 + (i as f64 + 0.5) * h) * h).sum();
            let exact = p.gap_integral(x1, x2);
            assert!((exact - midpoint).abs() <= 1e-8 * midpoint.max(1e-30), "{x1} {x2}");
        }
    }
}
