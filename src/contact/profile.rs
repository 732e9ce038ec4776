//! The punch's profile: the height `h(x)` of its surface above its lowest point, at a distance x
//! from its axis. The rigid punch imposes on the contact (eq. 18, with uz positive into the
//! solid)
//!
//! ```text
//! uz(x) = δ0 − h(x − x_p),   ∂uz/∂x = −h'(x − x_p)
//! ```
//!
//! where δ0 is the approach and x_p the punch axis in the frame of the solid. Only the cylinder
//! exists so far, `h(x) = x²/(2R)`, `h'(x) = x/R`: its constant curvature 1/R makes the
//! frictionless pressure the square-root ellipse and normal loading self-similar (Spence), which
//! the spectral solver of the paper relies on ([`Profile::curvature`]).

use serde::{Deserialize, Serialize};

/// A punch profile.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Profile {
    /// A circular cylinder of radius R (m), in its parabolic (small-slope) form.
    Cylinder {
        /// Radius R (m).
        radius: f64,
    },
}

impl Profile {
    /// A cylinder of radius `radius` (m).
    pub fn cylinder(radius: f64) -> Self {
        Self::Cylinder { radius }
    }

    /// The height h(x) of the surface above its lowest point at x from the axis (m).
    pub fn gap(&self, x: f64) -> f64 {
        match *self {
            Self::Cylinder { radius } => x * x / (2.0 * radius),
        }
    }

    /// `∫ h dx` from `x1` to `x2` (m²): the mean gap of an element of the general solver times
    /// its width.
    pub fn gap_integral(&self, x1: f64, x2: f64) -> f64 {
        match *self {
            Self::Cylinder { radius } => (x2.powi(3) - x1.powi(3)) / (6.0 * radius),
        }
    }

    /// The slope h'(x) (–).
    pub fn slope(&self, x: f64) -> f64 {
        match *self {
            Self::Cylinder { radius } => x / radius,
        }
    }

    /// `h''/Y*` for a pressure compliance Y* (1/Pa): the scale of the pressure's unit response
    /// on the collocation grid (eq. 52's right-hand side).
    pub fn pressure_scale(&self, compliance: f64) -> f64 {
        match *self {
            Self::Cylinder { radius } => 1.0 / (radius * compliance),
        }
    }

    /// The curvature h'' (1/m), constant for the profiles that the spectral solver takes: the
    /// pressure then scales with one unit response of the collocation grid.
    pub fn curvature(&self) -> f64 {
        match *self {
            Self::Cylinder { radius } => 1.0 / radius,
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
}
