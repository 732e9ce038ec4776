//! Surface fretting-fatigue indicators, accumulated cycle by cycle on a fixed grid of surface
//! points: pure computation on what each step gives at the grid points ([`PointSample`]); no
//! I/O. The cycles are those of [`crate::analysis`]: from a positive extreme of Q to the next.
//!
//! # Definitions (per grid point x, over one cycle)
//! ```text
//! s(x, t)      accumulated slip from the cycle's start, s = Σ Δs over the cycle's steps, with
//!              Δs = Δux − Δδ the step's increment of the half-plane's tangential surface
//!              displacement relative to the punch (zero on stuck points; a point out of
//!              contact at the end of a step accumulates none in it)
//! δslip(x)     slip amplitude: (max_t s − min_t s)/2 (the start, s = 0, included)
//! σmax, σmin   largest and smallest σxx0 (seed eq. 64), at every grid point, in or out of
//!              contact; range σmax − σmin
//! τ(x)         largest |q| over the cycle (in a slip zone q = ±ηp: the frictional shear
//!              stress of the slip)
//! F1 = τ δslip                  Ruiz's first parameter (frictional work density /4)
//! F2 = max(σmax, 0) τ δslip     Ruiz's fretting damage parameter
//! ε = ∂ux/∂x                    the surface strain εxx of plane strain (εyy = 0)
//! SWT = max(σmax, 0) Δε/2       Smith–Watson–Topper at the surface, Δε = max ε − min ε
//! ΔDx0, ΔEx                     ranges of Dx0 (seed eq. 65) and of Ex = −∂φ/∂x at the
//!                               surface (piezoelectric half-plane only)
//! ```
//! ε and ∂φ/∂x are taken from the step's surface fields by inverting eqs. 64–65,
//! `σxx0 = −Δ1 p − Δ2 g + Δ3 ε` and `Dx0 = −(e15/c44) q − Δ4 ∂φ/∂x` ([`point_sample`]).
//! A compressive σmax opens no crack: F2 and SWT are then 0. The cycle's largest δslip over
//! the grid is its maximum local slip amplitude ([`CycleSlip`]).
//!
//! The accumulation holds one set of running extremes per grid point and the previous step's
//! samples: its cost per step does not grow with the history.
//!
//! # References
//! - C. Ruiz, P. H. B. Boddington and K. C. Chen, "An investigation of fatigue and fretting
//!   in a dovetail joint", *Experimental Mechanics* 24, 208–217 (1984): F1 = τδ, F2 = σT τδ.
//! - D. Nowell and D. A. Hills, "Crack initiation criteria in fretting fatigue", *Wear* 136,
//!   329–343 (1990): F1 and F2 on the Hertzian fretting contact.
//! - K. N. Smith, P. Watson and T. H. Topper, "A stress–strain function for the fatigue of
//!   metals", *Journal of Materials* 5, 767–778 (1970): SWT = σmax εa.

use serde::{Deserialize, Serialize};

use crate::contact::general::{ElementState, PointLogs};
use crate::contact::{ContactModel, SurfacePoint};
use crate::history::{Regime, StateView, StepRecord};

/// What one step gives at one grid point.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct PointSample {
    /// Whether the point is in contact at the end of the step.
    pub in_contact: bool,
    /// The step's slip increment Δs (m; zero out of contact and on stuck points).
    pub slip_increment: f64,
    /// q (Pa).
    pub traction: f64,
    /// σxx0 (Pa).
    pub sigma_xx: f64,
    /// ε = ∂ux/∂x (–).
    pub strain: f64,
    /// Dx0 (C/m²).
    pub d_x: f64,
    /// Ex = −∂φ/∂x (V/m; zero on an elastic half-plane).
    pub e_x: f64,
}

/// The sample of a point from its surface fields (seed eqs. 64–65 inverted for ε and ∂φ/∂x).
pub fn point_sample(
    model: &ContactModel,
    point: &SurfacePoint,
    in_contact: bool,
    slip_increment: f64,
) -> PointSample {
    let d = &model.field_coefficients;
    let strain = (point.sigma_xx + d.delta1 * point.pressure + d.delta2 * point.charge) / d.delta3;
    let e_x = if model.compliance.electric.is_some() && d.delta4.abs() > 0.0 {
        (point.d_x + d.e15_over_c44 * point.traction) / d.delta4
    } else {
        0.0
    };
    PointSample {
        in_contact,
        slip_increment: if in_contact { slip_increment } else { 0.0 },
        traction: point.traction,
        sigma_xx: point.sigma_xx,
        strain,
        d_x: point.d_x,
        e_x,
    }
}

/// Nodes of the graded rule on the pieces of a slip zone between two grid points
/// ([`crate::history::slip_increments`]). Measured on the default history at M = 64 on the
/// default grid (400 points over ±2a) against 64 nodes: the slip increments within 4.8e−14 of
/// the step's largest (test `the_grid_rule_gives_the_slip_increments_to_a_small_error`; the
/// plain Gauss–Legendre rule of 8 or 6 nodes on these pieces gave 1.1e−9 and 9.7e−8).
pub const GRID_PIECE_NODES: usize = 16;

/// The samples of a step at the grid points `grid`, from the state before it (`None` at the
/// end of normal loading: no slip) and its state. The slip increment of a spectral state is
/// [`crate::history::slip_increments`]'s; that of an element state is the general solver's
/// own, the mean slip of the element holding x (`GeneralState::slip`). A step where the
/// spectral solver takes the state back from the general solver (the one step whose states
/// are of different solvers) counts no slip: its increment is not defined between the two
/// discretisations. A held step (the general solver carries its state over) counts none.
/// The fields of an element state are evaluated with the logarithms kept in `logs` where
/// given ([`PointLogs`]: the same values to round-off, faster over the steps of one mesh).
pub fn step_samples(
    model: &ContactModel,
    grid: &[f64],
    old: Option<StateView<'_>>,
    new: StateView<'_>,
    logs: Option<&mut PointLogs>,
) -> Vec<PointSample> {
    match new {
        StateView::Spectral(state) => {
            let slips = match old {
                Some(StateView::Spectral(before)) => {
                    crate::history::slip_increments(model, before, state, grid, GRID_PIECE_NODES)
                }
                _ => vec![0.0; grid.len()],
            };
            let (c, a) = (state.centre, state.half_width);
            let points = model.surface_points(state, grid);
            grid.iter()
                .zip(slips)
                .zip(&points)
                .map(|((&x, slip), point)| point_sample(model, point, (x - c).abs() < a, slip))
                .collect()
        }
        StateView::General(solver, state) => {
            let edges = &state.mesh.edges;
            // A held step carries the state, and with it the last step's slip, over.
            let slipping = match old {
                None => false,
                Some(StateView::General(_, before)) => before != state,
                Some(StateView::Spectral(_)) => true,
            };
            let points = solver.surface_points(model, state, grid, logs);
            grid.iter()
                .zip(&points)
                .map(|(&x, point)| {
                    let element = match edges.partition_point(|&e| e <= x) {
                        0 => None,
                        k if k > state.codes.len() => None,
                        k => Some(k - 1),
                    };
                    let in_contact =
                        element.is_some_and(|i| state.codes[i] != ElementState::Exterior);
                    let slip = match element {
                        Some(i) if slipping => state.slip[i],
                        _ => 0.0,
                    };
                    point_sample(model, point, in_contact, slip)
                })
                .collect()
        }
    }
}

/// The running extremes of one grid point over the cycle under way.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
struct Running {
    slip: f64,
    slip_range: (f64, f64),
    sigma: (f64, f64),
    traction: f64,
    strain: (f64, f64),
    d_x: (f64, f64),
    e_x: (f64, f64),
}

fn widen(range: &mut (f64, f64), v: f64) {
    range.0 = range.0.min(v);
    range.1 = range.1.max(v);
}

impl Running {
    /// At the cycle's first step: no slip yet, every range the sample's value.
    fn start(s: &PointSample) -> Self {
        Self {
            slip: 0.0,
            slip_range: (0.0, 0.0),
            sigma: (s.sigma_xx, s.sigma_xx),
            traction: s.traction.abs(),
            strain: (s.strain, s.strain),
            d_x: (s.d_x, s.d_x),
            e_x: (s.e_x, s.e_x),
        }
    }

    fn add(&mut self, s: &PointSample) {
        if s.in_contact {
            self.slip += s.slip_increment;
            widen(&mut self.slip_range, self.slip);
        }
        widen(&mut self.sigma, s.sigma_xx);
        self.traction = self.traction.max(s.traction.abs());
        widen(&mut self.strain, s.strain);
        widen(&mut self.d_x, s.d_x);
        widen(&mut self.e_x, s.e_x);
    }

    fn indicators(&self, x: f64) -> PointIndicators {
        let slip_amplitude = 0.5 * (self.slip_range.1 - self.slip_range.0);
        let tension = self.sigma.1.max(0.0);
        let ruiz_f1 = self.traction * slip_amplitude;
        PointIndicators {
            x,
            slip_amplitude,
            sigma_max: self.sigma.1,
            sigma_min: self.sigma.0,
            traction_max: self.traction,
            ruiz_f1,
            ruiz_f2: tension * ruiz_f1,
            strain_amplitude: 0.5 * (self.strain.1 - self.strain.0),
            swt: tension * 0.5 * (self.strain.1 - self.strain.0),
            d_x_range: self.d_x.1 - self.d_x.0,
            e_x_range: self.e_x.1 - self.e_x.0,
        }
    }
}

/// The indicators of one grid point over one cycle (module docs).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PointIndicators {
    /// x (m).
    pub x: f64,
    /// δslip (m).
    pub slip_amplitude: f64,
    /// Largest σxx0 (Pa).
    pub sigma_max: f64,
    /// Smallest σxx0 (Pa).
    pub sigma_min: f64,
    /// τ, the largest |q| (Pa).
    pub traction_max: f64,
    /// F1 = τ δslip (Pa·m = J/m²).
    pub ruiz_f1: f64,
    /// F2 = max(σmax, 0) τ δslip (Pa²·m).
    pub ruiz_f2: f64,
    /// Δε/2 (–).
    pub strain_amplitude: f64,
    /// SWT = max(σmax, 0) Δε/2 (Pa).
    pub swt: f64,
    /// Range of Dx0 (C/m²).
    pub d_x_range: f64,
    /// Range of Ex (V/m).
    pub e_x_range: f64,
}

/// The indicators of one cycle on the grid.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FatigueProfile {
    /// Cycle number (as in `cycles.csv`).
    pub cycle: usize,
    /// First and last step.
    pub steps: (usize, usize),
    /// The grid's length unit a (m): x/a is written beside x.
    pub half_width: f64,
    /// One entry per grid point, in increasing x.
    pub points: Vec<PointIndicators>,
}

/// The largest value of an indicator over the grid and where it is.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Extreme {
    /// The value.
    pub value: f64,
    /// Where (m).
    pub x: f64,
    /// Where, in units of a.
    pub x_over_a: f64,
}

/// The largest value of each indicator of a cycle ([`FatigueProfile::maxima`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct FatigueMaxima {
    /// δslip (m).
    pub slip_amplitude: Extreme,
    /// σmax (Pa).
    pub sigma_xx_max: Extreme,
    /// σmax − σmin (Pa).
    pub sigma_xx_range: Extreme,
    /// F1 (J/m²).
    pub ruiz_f1: Extreme,
    /// F2 (Pa·J/m²).
    pub ruiz_f2: Extreme,
    /// SWT (Pa).
    pub swt: Extreme,
    /// Range of Dx0 (C/m²; piezoelectric half-plane only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub d_x_range: Option<Extreme>,
    /// Range of Ex (V/m; piezoelectric half-plane only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub e_x_range: Option<Extreme>,
}

impl FatigueProfile {
    /// The largest value of `f` over the grid and its point (the first of equal ones).
    pub fn extreme(&self, f: impl Fn(&PointIndicators) -> f64) -> Extreme {
        let mut best = Extreme {
            value: f64::NEG_INFINITY,
            x: f64::NAN,
            x_over_a: f64::NAN,
        };
        for p in &self.points {
            let v = f(p);
            if v > best.value {
                best = Extreme {
                    value: v,
                    x: p.x,
                    x_over_a: p.x / self.half_width,
                };
            }
        }
        best
    }

    /// The largest value of each indicator; the electric ones when `electric`.
    pub fn maxima(&self, electric: bool) -> FatigueMaxima {
        FatigueMaxima {
            slip_amplitude: self.extreme(|p| p.slip_amplitude),
            sigma_xx_max: self.extreme(|p| p.sigma_max),
            sigma_xx_range: self.extreme(|p| p.sigma_max - p.sigma_min),
            ruiz_f1: self.extreme(|p| p.ruiz_f1),
            ruiz_f2: self.extreme(|p| p.ruiz_f2),
            swt: self.extreme(|p| p.swt),
            d_x_range: electric.then(|| self.extreme(|p| p.d_x_range)),
            e_x_range: electric.then(|| self.extreme(|p| p.e_x_range)),
        }
    }
}

/// A closed cycle's largest local slip amplitude (`max_local_slip_m` in `cycles.csv`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct CycleSlip {
    /// Cycle number.
    pub cycle: usize,
    /// First and last step.
    pub steps: (usize, usize),
    /// max over the grid of δslip (m).
    pub max_local_slip: f64,
}

/// The indicators taken as the steps arrive: [`FatigueAnalysis::push`] each step's record and
/// samples in order (step 0 first), then [`FatigueAnalysis::finish`]. It closes a cycle at
/// each forward-slip record followed by a reverse-slip one, as
/// [`crate::analysis::CycleAnalysis`] does, and at the last record when it ends a forward
/// phase (where the cycle analysis closes a cycle only if the prescribed load is back at the
/// cycle's start: the caller matches the cycles by their steps). It keeps the indicators of
/// the last two cycles closed and the largest local slip amplitude of each.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct FatigueAnalysis {
    grid: Vec<f64>,
    half_width: f64,
    /// The previous record's regime and step, and its samples.
    previous: Option<(Regime, usize, Vec<PointSample>)>,
    several: bool,
    /// The cycle under way: its first step and the running extremes.
    open: Option<(usize, Vec<Running>)>,
    cycles: Vec<CycleSlip>,
    /// The indicators of the last two cycles closed, the later last.
    last: Vec<FatigueProfile>,
}

impl FatigueAnalysis {
    /// An analysis on the grid points `grid` (m, increasing), with `half_width` the unit of
    /// x/a.
    pub fn new(grid: Vec<f64>, half_width: f64) -> Self {
        Self {
            grid,
            half_width,
            previous: None,
            several: false,
            open: None,
            cycles: Vec::new(),
            last: Vec::new(),
        }
    }

    /// The grid points (m).
    pub fn grid(&self) -> &[f64] {
        &self.grid
    }

    /// Take the next step: its record and its samples at the grid points.
    ///
    /// # Panics
    /// If `samples` has not one entry per grid point.
    pub fn push(&mut self, record: &StepRecord, samples: Vec<PointSample>) {
        assert_eq!(samples.len(), self.grid.len(), "one sample per grid point");
        if let Some((regime, step, _)) = &self.previous {
            let (regime, step) = (*regime, *step);
            if self.several && regime == Regime::ForwardSlip && record.regime == Regime::ReverseSlip
            {
                self.close_at(step);
            }
            if let Some((_, running)) = &mut self.open {
                running.iter_mut().zip(&samples).for_each(|(r, s)| r.add(s));
            }
            self.several = true;
        }
        self.previous = Some((record.regime, record.step, samples));
    }

    /// Close the cycle under way (if any) at the step `extreme` (the previous record), and
    /// open the next from its samples.
    fn close_at(&mut self, extreme: usize) {
        if let Some((first, running)) = self.open.take() {
            let profile = FatigueProfile {
                cycle: self.cycles.len() + 1,
                steps: (first, extreme),
                half_width: self.half_width,
                points: running
                    .iter()
                    .zip(&self.grid)
                    .map(|(r, &x)| r.indicators(x))
                    .collect(),
            };
            self.cycles.push(CycleSlip {
                cycle: profile.cycle,
                steps: profile.steps,
                max_local_slip: profile.extreme(|p| p.slip_amplitude).value,
            });
            if self.last.len() == 2 {
                self.last.remove(0);
            }
            self.last.push(profile);
        }
        let samples = &self.previous.as_ref().expect("a previous record").2;
        self.open = Some((extreme, samples.iter().map(Running::start).collect()));
    }

    /// The cycles' largest local slip amplitudes and the indicators of the last two cycles
    /// (the later last; a caller whose cycle analysis leaves a trailing cycle open takes the
    /// one before), the last record closing a cycle when it ends a forward phase.
    pub fn finish(mut self) -> (Vec<CycleSlip>, Vec<FatigueProfile>) {
        if let Some((Regime::ForwardSlip, step, _)) = &self.previous
            && self.several
        {
            let step = *step;
            self.close_at(step);
        }
        (self.cycles, self.last)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn record(step: usize, regime: Regime) -> StepRecord {
        let json = serde_json::json!({
            "step": step, "t": step as f64, "q": 0.0, "normal_load": 1.0, "charge": 0.0,
            "potential": 0.0, "regime": regime, "phase": 0, "half_width": 1.0,
            "eccentricity": 0.0, "stick_lo": 0.0, "stick_hi": 0.0, "left_slip_sign": 0.0,
            "right_slip_sign": 0.0, "iterations": 0, "newton_iterations": 0, "residual": 0.0,
            "admissibility": {"stick_excess": 0.0, "slip_reversal": 0.0, "min_pressure": 0.0},
            "displacement": 0.0, "dissipation": 0.0, "normal_work": 0.0, "electric_work": 0.0,
            "solver": "spectral", "zones": {"stick": 1, "slip": 2, "sign_changes": 0}
        });
        serde_json::from_value(json).expect("a record")
    }

    fn sample(slip: f64, sigma: f64) -> PointSample {
        PointSample {
            in_contact: true,
            slip_increment: slip,
            traction: 2.0,
            sigma_xx: sigma,
            strain: sigma / 10.0,
            ..PointSample::default()
        }
    }

    /// A hand-made cycle at one point: slip +1, +1, −3, +1 from the extreme gives s = 0, 1,
    /// 2, −1, 0 (δslip = 1.5); σ from 4 to −6 (range 10, tension 4, Δε/2 = 0.5); τ = 2.
    #[test]
    fn a_hand_made_cycle_gives_its_indicators() {
        use Regime::{ForwardSlip as F, ReverseSlip as R};
        let mut a = FatigueAnalysis::new(vec![0.5], 1.0);
        let steps = [
            (0, Regime::NormalLoading, 0.0, 0.0),
            (1, F, 9.0, 4.0),
            (2, R, 1.0, 1.0),
            (3, R, 1.0, 0.0),
            (4, R, -3.0, -6.0),
            (5, F, 1.0, 1.0),
            (6, F, 0.0, 2.0),
            (7, R, 5.0, 0.0),
        ];
        for (step, regime, slip, sigma) in steps {
            a.push(&record(step, regime), vec![sample(slip, sigma)]);
        }
        let (cycles, last) = a.finish();
        assert_eq!(cycles.len(), 1);
        assert_eq!(cycles[0].steps, (1, 6));
        let p = last.last().expect("a cycle").points[0];
        let close = |x: f64, y: f64| (x - y).abs() < 1e-15;
        assert!(close(p.slip_amplitude, 1.5), "{p:?}");
        assert!(close(cycles[0].max_local_slip, 1.5));
        assert!(close(p.sigma_max, 4.0) && close(p.sigma_min, -6.0));
        assert!(close(p.ruiz_f1, 3.0) && close(p.ruiz_f2, 12.0));
        assert!(close(p.swt, 4.0 * 0.5), "{p:?}");
    }
}
