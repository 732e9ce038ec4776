//! The residuals of a step at fixed geometry (tangential module docs, "Equations"): the linear
//! problem at given stick ends and contact `(lo, hi, a, c)`, i.e. the pressure with the
//! eccentric punch (seed eqs. 46, 52, 54), the charge (eqs. 47, 53, 55) and the stick traction
//! (eqs. 43/60, 48/63), coupled through κq, w13 w and the slip traction, solved by the inner
//! fixed-point iteration; and the four dimensionless residuals (pressure consistency and
//! resultant, stick consistency and force) that the search drives to zero. With the inner
//! iteration's tolerances.

use std::cell::{Cell, RefCell};
use std::sync::Arc;

use crate::contact::memory::Memory;
use crate::contact::normal::arcsine_moment;
use crate::contact::pressure::{Discretisation, electric_resultants};
use crate::contact::{
    ChargeSplit, ContactModel, ContactState, Inherited, RememberedRoot, StickZone, kink_domain,
};
use crate::error::SolveFailure;
use crate::quadrature::{BoundedSeries, dot};

use super::Accelerations;
use super::inner::{InnerMaps, StickSums};
use super::kinks::{EndProbes, KinkMaps, KinkPoints, pressure_root, resolved};
use super::linalg::Anderson;

/// `(H'q̃ of the chain, remembered strain)` at the stick points.
type StickParts = (Vec<f64>, Vec<f64>);

/// `(S, inherited traction)` at the pressure points and at the charge points.
type SampleParts = (Vec<(f64, f64)>, Vec<(f64, f64)>);

/// The four geometric unknowns of a step: stick-zone ends and contact half-width and centre.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Geometry {
    pub(super) lo: f64,
    pub(super) hi: f64,
    pub(super) a: f64,
    pub(super) c: f64,
}

impl Geometry {
    /// A state's geometry (`None` without a stick zone).
    pub(super) fn of(state: &ContactState) -> Option<Self> {
        let zone = state.traction.stick.as_ref()?;
        Some(Self {
            lo: zone.lo,
            hi: zone.hi,
            a: state.half_width,
            c: state.centre,
        })
    }

    pub(super) fn values(&self) -> [f64; 4] {
        [self.lo, self.hi, self.a, self.c]
    }
}

/// Everything a step needs besides the geometry.
pub(super) struct StepProblem<'a> {
    pub(super) model: &'a ContactModel,
    pub(super) disc: &'a Discretisation,
    pub(super) memory: &'a Memory,
    pub(super) base: Option<&'a Arc<StickZone>>,
    /// Slip signs of the left and right slip zones.
    pub(super) signs: (f64, f64),
    pub(super) normal_load: f64,
    pub(super) tangential_load: f64,
    /// The last evaluation's [`InnerMaps`], whose matrices the next evaluation refills (one
    /// for all the attempts of a step).
    pub(super) scratch: &'a RefCell<InnerMaps>,
    /// The speed-ups in use (the accepted zones' tables).
    pub(super) accelerations: Accelerations,
    /// The count of the step's residual evaluations on its own grid, over all its attempts,
    /// which [`SlipOptions::step_evaluations`](super::SlipOptions::step_evaluations) bounds;
    /// `None` where they are not counted (the coarse grid's, a test's problem).
    pub(super) evaluations: Option<&'a Cell<usize>>,
}

impl StepProblem<'_> {
    pub(super) fn valid(&self, g: &Geometry) -> bool {
        g.a > 0.0 && g.lo > g.c - g.a && g.hi < g.c + g.a && g.hi - g.lo > 1e-9 * g.a
    }

    /// Solve the linear problem at fixed geometry (pressure, charge and stick traction, coupled
    /// through κq, w13 w and the slip traction, by fixed-point iteration from `guess`) and
    /// return the four residuals (pressure consistency and resultant, stick consistency and
    /// force, each made dimensionless), the state, and whether the inner iteration reached
    /// [`INNER_TOLERANCE`] (it stops at `inner_tolerance`, see [`inner_tolerance`]; an uncoupled
    /// problem is solved exactly in one pass).
    pub(super) fn evaluate(
        &self,
        g: &Geometry,
        guess: &ContactState,
        inner_tolerance: f64,
    ) -> Result<([f64; 4], ContactState, bool), SolveFailure> {
        self.evaluate_with(g, guess, self.inherited_link(g), inner_tolerance)
    }

    /// The base zone's inherited correction at the stick ends of `g` (`None` without a base
    /// zone).
    fn inherited_link(&self, g: &Geometry) -> Option<Arc<Inherited>> {
        self.base
            .and_then(|b| b.inheritance_for(g.lo, g.hi, self.disc.nodes()))
    }

    /// As [`Self::evaluate`], with the inherited correction chosen by the caller (the
    /// finite-difference Jacobian keeps the base point's choice so that it does not straddle
    /// a switch).
    pub(super) fn evaluate_with(
        &self,
        g: &Geometry,
        guess: &ContactState,
        inherited: Option<Arc<Inherited>>,
        inner_tolerance: f64,
    ) -> Result<([f64; 4], ContactState, bool), SolveFailure> {
        if let Some(count) = self.evaluations {
            count.set(count.get() + 1);
        }
        let m = self.disc.nodes();
        let k = Couplings::new(self.model, guess.split);
        let points = Points::new(self.disc, g);
        // The remembered stick ends inside the zone and the parts of q̃ that carry their kinks
        // beyond them (tangential module docs, "Kinks at the stick ends").
        let interior = match (&inherited, k.coupled) {
            (Some(z), true) => z.interior_roots(g.lo, g.hi),
            _ => Vec::new(),
        };
        // The part of q̃ fixed by the geometry: the inherited chain and the extras.
        let closed = self.closed_zone(g, guess, inherited, &interior, &k);
        // Parts of the stick right-hand side that do not change in the inner iteration (with
        // no charge unknown, whatever charge the state carries is among them).
        let fixed = self.fixed_stick_terms(guess, &points, &closed, &k);
        let inherited_force = closed.correction_integral();
        let mut state = self.trial_state(g, guess, &closed);
        let mixed = (self.signs.0 - self.signs.1).abs() > 0.0;
        // The traction at the pressure and charge points is `η p S + q̃_own + q̃_inherited`;
        // S and the inherited part depend on the geometry only, so they are evaluated once.
        let sample_parts = self.sample_parts(&points, &closed, &state, k.conducting);
        let fixed_c = &sample_parts.1;
        let (np, nc) = (points.pressure.len(), fixed_c.len());
        let sample_points: Vec<f64> = points
            .pressure
            .iter()
            .chain(&points.charge[..nc])
            .copied()
            .collect();
        let coefficients = Coefficients {
            local_over_y11: k.local / k.y11,
            shape: (!mixed).then_some(k.eta * self.signs.0),
            charge: k.conducting.then_some(k.w13 / k.y11),
        };
        let maps = self.rebuilt_maps(&state, &points.stick, &sample_points, coefficients);
        // The kinks of p and w: at the new stick ends, whose q̃ roots are unknowns of the inner
        // iteration, estimated from q̃ at `END_PROBE` and twice that of the half-width inside
        // each end (nearer where a remembered end is close, see `EndProbes`), and at the
        // remembered stick ends inside the zone, whose roots the chain carries.
        let interior_points: Vec<f64> = interior.iter().map(|r| r.at).collect();
        let probes = EndProbes::new(g, m, &closed, &interior_points);
        let kinks = if k.coupled {
            let at = KinkPoints {
                pressure: &points.pressure,
                charge: &points.charge[..nc],
                stick: &points.stick,
                samples: &sample_points,
                nodes: &maps.node_points,
            };
            self.kink_maps(g, &state, &interior, at, &k)
        } else {
            KinkMaps::default()
        };
        let inner = InnerIteration {
            problem: self,
            g,
            k: &k,
            points: &points,
            np,
            nc,
            maps: &maps,
            kinks: &kinks,
            probes: &probes,
            fixed: &fixed,
            fixed_samples: &sample_parts,
            mixed,
        };
        let unknowns = np + nc + if k.coupled { 2 } else { 0 };
        let mut buffers = InnerBuffers::new(m, np + nc, maps.own_rows.len(), unknowns, &maps);
        // The inner unknown: q at the pressure points, then at the charge points, then (when
        // coupled) q̃'s root coefficients at the new ends, times √h (Pa).
        let mut x = inner.starting_traction(guess, &closed, &sample_points, &mut buffers);
        if k.coupled {
            x.extend(inner.starting_roots(guess, &closed));
        }
        // Pressure (seed eqs. 46, 52, 54), charge (eqs. 47, 53, 55) and stick traction
        // (eqs. 43/60, 48/63), coupled, by the inner fixed-point iteration.
        let (lambda_p, lambda_q, full) = inner.solve(x, &mut state, &mut buffers, inner_tolerance);
        self.scratch.replace(maps);
        state.shape_table = None;
        let p_scale = g.a * k.scale;
        let residual = self.residuals(
            g,
            &state,
            [lambda_p, lambda_q],
            p_scale,
            points.half,
            inherited_force,
        );
        Ok((residual, state, full))
    }

    /// The part of q̃ that the geometry fixes: the inherited chain `inherited` and the extras,
    /// the roots that the friction part no longer carries beyond the remembered stick ends
    /// `interior` whose slip sign changed (tangential module docs, "Kinks at the stick
    /// ends"), on the zone `[lo, hi]` with this step's end signs and no own series yet.
    fn closed_zone(
        &self,
        g: &Geometry,
        guess: &ContactState,
        inherited: Option<Arc<Inherited>>,
        interior: &[RememberedRoot],
        k: &Couplings,
    ) -> StickZone {
        let m = self.disc.nodes();
        let (kappa, ystar, eta) = (k.kappa, k.ystar, k.eta);
        let new_zone = StickZone {
            end_signs: [self.signs.0, self.signs.1],
            tables: self.accelerations.zone_tables(),
            ..StickZone::new(g.lo, g.hi, BoundedSeries::default(), 0.0)
        };
        let negligible = 1e-14 * eta * guess.pressure_at(guess.centre).abs();
        let extras: Vec<(f64, f64, f64)> = interior
            .iter()
            .filter_map(|r| {
                let (u, v) = kink_domain(r.at, r.side, g.c, g.a);
                let root = pressure_root(r.side, kappa / ystar, eta, r.sign, r.root)
                    * resolved(v - u, g.a, m);
                let (u, v) = if r.side > 0.0 {
                    (r.at, g.hi)
                } else {
                    (g.lo, r.at)
                };
                let change = r.carried_sign - new_zone.end_sign_shape(r.at);
                let amplitude = change * eta * root / (v - u).sqrt();
                // An extra below 1e−14 of η p0 is round-off (a sign change of 1e−17 at a
                // point of a mixed state's blend); kept, it would stop the chain collapsing.
                (amplitude.abs() * 0.5 * (v - u) > negligible).then_some((u, v, amplitude))
            })
            .collect();
        StickZone {
            inherited,
            extras,
            ..new_zone
        }
    }

    /// The terms of the stick equation's right-hand side (seed eqs. 43/60, over y11) that the
    /// inner iteration does not change, at the stick points: the remembered strain over y11,
    /// less `H'` of the fixed part of q̃ (`closed`), plus, with no charge unknown (insulating
    /// punch), `w13/y11` times the charge the state carries.
    fn fixed_stick_terms(
        &self,
        guess: &ContactState,
        points: &Points,
        closed: &StickZone,
        k: &Couplings,
    ) -> Vec<f64> {
        let stick_parts = self.stick_parts(points, closed);
        let (chain_cauchy, remembered) = (&stick_parts.0, &stick_parts.1);
        points
            .stick
            .iter()
            .zip(chain_cauchy)
            .zip(remembered)
            .map(|((&x, h), strain)| {
                let fixed_charge = if k.conducting {
                    0.0
                } else {
                    k.w13 * guess.potential_charge_at(x) / k.y11
                };
                strain / k.y11 - h + fixed_charge
            })
            .collect()
    }

    /// `H'` of the fixed part of q̃ and the remembered strain at the stick points.
    fn stick_parts(&self, points: &Points, closed: &StickZone) -> StickParts {
        let m = self.disc.nodes();
        let (mut chain, mut remembered) = (Vec::with_capacity(m), Vec::with_capacity(m));
        closed.correction_cauchys_into(&points.stick, &mut chain);
        self.memory
            .strains_into(self.model, &points.stick, &mut remembered);
        (chain, remembered)
    }

    /// The state the inner iteration starts from and updates: `guess` with this evaluation's
    /// geometry, load, friction, slip signs and fixed part of q̃ (`closed`).
    fn trial_state(&self, g: &Geometry, guess: &ContactState, closed: &StickZone) -> ContactState {
        let mut state = guess.clone();
        state.shape_table = None;
        state.half_width = g.a;
        state.centre = g.c;
        state.tangential_load = self.tangential_load;
        state.traction.friction = self.model.friction;
        state.traction.left_sign = self.signs.0;
        state.traction.right_sign = self.signs.1;
        state.traction.stick = Some(closed.clone());
        state
    }

    /// `(S, inherited traction)` at the pressure points and (conducting punch) at the charge
    /// points, the parts of the traction there that depend on the geometry only.
    fn sample_parts(
        &self,
        points: &Points,
        closed: &StickZone,
        state: &ContactState,
        conducting: bool,
    ) -> SampleParts {
        let sampled = |points: &[f64]| -> Vec<(f64, f64)> {
            let mut inherited = Vec::with_capacity(points.len());
            closed.corrections_into(points, &mut inherited);
            points
                .iter()
                .zip(inherited)
                .map(|(&x, inh)| (state.slip_shape(x), inh))
                .collect()
        };
        let charge = if conducting {
            sampled(&points.charge)
        } else {
            Vec::new()
        };
        (sampled(&points.pressure), charge)
    }

    /// The inner iteration's maps ([`InnerMaps`]) at `state`'s geometry, refilled into the
    /// matrices of the step's last evaluation (`scratch`, which the caller gives back). This
    /// saves allocating and zeroing the matrices at every evaluation; every entry is written
    /// again, so the maps, and the result, are those built afresh.
    fn rebuilt_maps(
        &self,
        state: &ContactState,
        stick_points: &[f64],
        sample_points: &[f64],
        coefficients: Coefficients,
    ) -> InnerMaps {
        let mut maps = self.scratch.take();
        maps.rebuild(
            state,
            stick_points,
            sample_points,
            self.disc.nodes(),
            coefficients,
        );
        maps
    }

    /// The kink terms of p and w ([`KinkMaps`]) at the new stick ends and at the remembered
    /// stick ends `interior`, at the points `at`.
    fn kink_maps(
        &self,
        g: &Geometry,
        state: &ContactState,
        interior: &[RememberedRoot],
        at: KinkPoints<'_>,
        k: &Couplings,
    ) -> KinkMaps {
        let mut points = vec![
            (g.lo, -1.0, 0.0, self.signs.0),
            (g.hi, 1.0, 0.0, self.signs.1),
        ];
        points.extend(interior.iter().map(|r| (r.at, r.side, r.root, r.sign)));
        KinkMaps::new(
            state,
            &points,
            at,
            self.disc.nodes(),
            [k.kappa / k.ystar, k.w13_over_y33, k.eta],
        )
    }

    /// The four residuals of the solved `state`, each dimensionless: the pressure's
    /// consistency (its multiplier λp over `p_scale`) and resultant, the stick traction's
    /// consistency (its multiplier λq over η p0) and force (seed eqs. 48/63: the stick zone's
    /// own correction over its half-width `half`, the inherited force and the slip
    /// traction's).
    fn residuals(
        &self,
        g: &Geometry,
        state: &ContactState,
        [lambda_p, lambda_q]: [f64; 2],
        p_scale: f64,
        half: f64,
        inherited_force: f64,
    ) -> [f64; 4] {
        let eta = self.model.friction;
        let p0 = state.pressure_at(g.c).abs().max(1e-300);
        let pressure_force = state.pressure_force();
        let stick = state.traction.stick.as_ref().expect("set above");
        let shape_force = if (self.signs.0 - self.signs.1).abs() > 0.0 {
            // ∫ p S dx over the contact, piecewise by the graded rule.
            state.contact_integral(None, &|xs, out| {
                state.pressures_into(xs, out);
                for (p, &x) in out.iter_mut().zip(xs) {
                    *p *= state.slip_shape(x);
                }
            })
        } else {
            self.signs.1 * pressure_force
        };
        let q_force = half * stick.correction.integral() + inherited_force + eta * shape_force;
        [
            lambda_p / p_scale,
            (pressure_force - self.normal_load) / self.normal_load,
            lambda_q / (eta * p0),
            (q_force - self.tangential_load) / (eta * self.normal_load),
        ]
    }
}

/// The material and electrode coefficients of one evaluation, for the state's charge split.
struct Couplings {
    /// Y*, the pressure equation's compliance.
    ystar: f64,
    /// κ, the pressure equation's coupling to q.
    kappa: f64,
    y11: f64,
    /// η, the friction coefficient.
    eta: f64,
    /// w13 (zero on an elastic half-plane).
    w13: f64,
    /// `w12 + χ w13`, the pressure's local term in the stick equation.
    local: f64,
    /// Whether the punch's potential is prescribed (its charge then follows from q).
    potential_control: bool,
    /// Whether the charge is an unknown (conducting punch).
    conducting: bool,
    /// w13/y33 for a conducting punch, else zero.
    w13_over_y33: f64,
    /// Whether the kinks at the stick ends are carried ([`KinkMaps`]): with the option on and
    /// q coupled to p or w.
    coupled: bool,
    /// The pressure equation's right-hand side per unit x (1/(R Y*) for the cylinder).
    scale: f64,
}

impl Couplings {
    fn new(model: &ContactModel, split: ChargeSplit) -> Self {
        let kappa = model.pressure_shear_coupling(split);
        let electric = split
            .conducting
            .then_some(model.compliance.electric)
            .flatten();
        let w13_over_y33 = electric.map_or(0.0, |e| e.w13 / e.y33);
        Self {
            ystar: model.pressure_compliance(split),
            kappa,
            y11: model.compliance.y11,
            eta: model.friction,
            w13: model.compliance.electric.map_or(0.0, |e| e.w13),
            local: model.local_pressure_strain(split),
            potential_control: matches!(
                model.electrode,
                crate::contact::Electrode::ConductingPotential { .. }
            ),
            conducting: split.conducting,
            w13_over_y33,
            coupled: model.stick_end_kinks && (kappa.abs() > 0.0 || w13_over_y33.abs() > 0.0),
            scale: model.pressure_scale(split),
        }
    }
}

/// The collocation points of one evaluation: the bounded grid's on the stick zone
/// `mid ± half`, the bounded and the unbounded grid's on the contact `c ± a`.
struct Points {
    half: f64,
    stick: Vec<f64>,
    pressure: Vec<f64>,
    charge: Vec<f64>,
}

impl Points {
    fn new(disc: &Discretisation, g: &Geometry) -> Self {
        let (mid, half) = (0.5 * (g.lo + g.hi), 0.5 * (g.hi - g.lo));
        // Collocation points mapped onto an interval `centre ± half`.
        let mapped = |points: &[f64], centre: f64, half: f64| -> Vec<f64> {
            points.iter().map(|t| centre + half * t).collect()
        };
        Self {
            half,
            stick: mapped(&disc.bounded.collocation, mid, half),
            pressure: mapped(&disc.bounded.collocation, g.c, g.a),
            charge: mapped(&disc.unbounded.collocation, g.c, g.a),
        }
    }
}

/// The buffers of one evaluation's inner iteration, each written before it is read in a pass.
struct InnerBuffers {
    /// The next iterate of the inner unknown.
    fx: Vec<f64>,
    /// The pressure equation's right-hand side at the pressure points.
    rhs: Vec<f64>,
    beta_p: Vec<f64>,
    beta_q: Vec<f64>,
    gamma: Vec<f64>,
    /// The stick equation's right-hand side at the stick points.
    srhs: Vec<f64>,
    /// The charge equation's right-hand side at the charge points.
    crhs: Vec<f64>,
    work: Vec<f64>,
    stick_sums: StickSums,
    p_nodes: Vec<f64>,
    /// The kink terms' roots and amplitudes of p and w, refilled in each pass.
    roots: Vec<f64>,
    amp: Vec<f64>,
    w_amp: Vec<f64>,
    /// p at the sample points, q̃'s own part there, and its rows inside the stick zone.
    p_samples: Vec<f64>,
    own_samples: Vec<f64>,
    own_inside: Vec<f64>,
}

impl InnerBuffers {
    fn new(m: usize, samples: usize, inside: usize, unknowns: usize, maps: &InnerMaps) -> Self {
        Self {
            fx: vec![0.0; unknowns],
            rhs: vec![0.0; m + 1],
            beta_p: vec![0.0; m],
            beta_q: vec![0.0; m],
            gamma: vec![0.0; m],
            srhs: vec![0.0; m + 1],
            crhs: vec![0.0; m.saturating_sub(1)],
            work: vec![0.0; m + 1],
            stick_sums: StickSums::new(m),
            p_nodes: vec![0.0; maps.shape_nodes.rows()],
            roots: Vec::new(),
            amp: Vec::new(),
            w_amp: Vec::new(),
            p_samples: vec![0.0; samples],
            own_samples: vec![0.0; samples],
            own_inside: vec![0.0; inside],
        }
    }
}

/// The inner iteration of one evaluation (tangential module docs, "Equations"): at fixed
/// geometry, the pressure, the charge and the stick traction in turn for the current shear
/// traction at the sample points (and, when coupled, q̃'s roots at the new stick ends), a
/// fixed-point iteration with Anderson acceleration.
struct InnerIteration<'e> {
    problem: &'e StepProblem<'e>,
    g: &'e Geometry,
    k: &'e Couplings,
    points: &'e Points,
    /// The numbers of pressure and charge points among the sample points.
    np: usize,
    nc: usize,
    maps: &'e InnerMaps,
    kinks: &'e KinkMaps,
    probes: &'e EndProbes,
    /// The stick right-hand side's fixed terms ([`StepProblem::fixed_stick_terms`]).
    fixed: &'e [f64],
    /// `(S, inherited traction)` at the pressure and at the charge points.
    fixed_samples: &'e SampleParts,
    mixed: bool,
}

impl InnerIteration<'_> {
    /// Iterate from the inner unknown `x` until the largest change of the traction in a pass,
    /// relative to `η p0`, is below `inner_tolerance` (at most 100 passes), leaving the
    /// solution's series in `state`; return the pressure's and the stick traction's
    /// consistency multipliers λp and λq of the last pass and whether the change reached
    /// [`INNER_TOLERANCE`].
    fn solve(
        &self,
        mut x: Vec<f64>,
        state: &mut ContactState,
        b: &mut InnerBuffers,
        inner_tolerance: f64,
    ) -> (f64, f64, bool) {
        let (np, nc) = (self.np, self.nc);
        let (mut lambda_p, mut lambda_q) = (0.0, 0.0);
        let mut full = false;
        let mut accel = Anderson::new(5);
        for _ in 0..100 {
            let ends = if self.k.coupled {
                [
                    x[np + nc] / self.probes.scale[0],
                    x[np + nc + 1] / self.probes.scale[1],
                ]
            } else {
                [0.0; 2]
            };
            lambda_p = self.pressure_pass(&x[..np], ends, state, b);
            if self.k.conducting {
                self.charge_pass(&x[np..np + nc], state, b);
            }
            lambda_q = self.stick_pass(b);
            self.next_traction(ends, state, b);
            let p0 = state.pressure_at(self.g.c).abs().max(1e-300);
            let change =
                b.fx.iter()
                    .zip(&x)
                    .map(|(n, o)| (n - o).abs())
                    .fold(0.0, f64::max)
                    / (self.k.eta * p0);
            let exact = self.k.kappa == 0.0 && !self.k.conducting;
            if exact || change < inner_tolerance {
                full = exact || change < INNER_TOLERANCE;
                break;
            }
            accel.next(&mut x, &b.fx);
        }
        (lambda_p, lambda_q, full)
    }

    /// Pressure for the current shear traction `q` at the pressure points (seed eqs. 52, 54,
    /// 56), less the Cauchy transform of its kinks, whose roots follow from q̃'s roots `ends`
    /// at the new stick ends; into `state`. Returns the consistency multiplier λp.
    fn pressure_pass(
        &self,
        q: &[f64],
        ends: [f64; 2],
        state: &mut ContactState,
        b: &mut InnerBuffers,
    ) -> f64 {
        let (kappa, ystar, scale) = (self.k.kappa, self.k.ystar, self.k.scale);
        let kinks = self.kinks;
        kinks.roots_into(ends, &mut b.roots);
        kinks.pressure_amplitudes_into(&b.roots, &mut b.amp);
        b.w_amp.clear();
        b.w_amp.resize(b.amp.len(), 0.0);
        for ((r, &xp), q) in b.rhs.iter_mut().zip(&self.points.pressure).zip(q) {
            *r = -xp * scale - kappa / ystar * q;
        }
        kinks.cauchy_at_pressure.add_apply(&b.amp, -1.0, &mut b.rhs);
        let lambda_p = self
            .problem
            .disc
            .bounded
            .solve_coefficients(&b.rhs, &mut b.beta_p);
        state.pressure.beta.clone_from(&b.beta_p);
        kinks.kinks_into(&b.amp, &mut state.pressure_kinks);
        lambda_p
    }

    /// Charge (seed eqs. 53, 55, 41–42) for the current shear traction `q` at the charge
    /// points; into `state`. The arcsine moment of q fixes Γ under potential control; under
    /// charge control it only gives φ0 and is evaluated once for the accepted state.
    fn charge_pass(&self, q: &[f64], state: &mut ContactState, b: &mut InnerBuffers) {
        let (model, g, kinks) = (self.problem.model, self.g, self.kinks);
        let normal_load = self.problem.normal_load;
        let e = model
            .compliance
            .electric
            .expect("conducting punch on a piezoelectric half-plane");
        let j_q = if self.k.potential_control {
            arcsine_moment(state)
        } else {
            0.0
        };
        let (charge, potential) = electric_resultants(model, g.a, normal_load, j_q);
        state.charge = charge;
        state.potential = potential;
        let free = charge - model.pressure_charge(normal_load);
        kinks.charge_amplitudes_into(&b.roots, &mut b.w_amp);
        kinks.kinks_into(&b.w_amp, &mut state.charge_kinks);
        for (r, q) in b.crhs.iter_mut().zip(q) {
            *r = -e.w13 / e.y33 * q;
        }
        kinks
            .cauchy_at_charge
            .add_apply(&b.w_amp, -1.0, &mut b.crhs);
        let kinks_force = state.potential_charge_force() - g.a * state.potential_charge.integral();
        self.problem.disc.unbounded.solve_coefficients(
            &b.crhs,
            (free - kinks_force) / g.a,
            &mut b.gamma,
        );
        state.potential_charge.gamma.clone_from(&b.gamma);
    }

    /// Stick traction (seed eqs. 50–51/58–59, 60, 63) for the pressure and charge of this
    /// pass; returns the consistency multiplier λq. `H'(pS)` is `s H'p` when both slip zones
    /// have the same sign s.
    fn stick_pass(&self, b: &mut InnerBuffers) -> f64 {
        let (maps, kinks) = (self.maps, self.kinks);
        let (eta, local, w13, y11) = (self.k.eta, self.k.local, self.k.w13, self.k.y11);
        maps.stick_terms(
            &b.beta_p,
            &b.gamma,
            &mut b.stick_sums,
            &mut b.srhs,
            &mut b.work,
        );
        if let Some(eta_s) = maps.coefficients.shape {
            kinks.cauchy_at_stick.add_apply(&b.amp, -eta_s, &mut b.srhs);
        }
        // The remembered kinks' terms reach into the stick zone: their local parts.
        kinks.at_stick.add_apply(&b.amp, local / y11, &mut b.srhs);
        kinks.at_stick.add_apply(&b.w_amp, w13 / y11, &mut b.srhs);
        if self.mixed {
            maps.shape_nodes.apply(&b.beta_p, &mut b.p_nodes);
            kinks.cauchy_at_stick.add_apply(&b.amp, 1.0, &mut b.work);
            kinks.at_nodes.add_apply(&b.amp, 1.0, &mut b.p_nodes);
            for (i, r) in b.srhs.iter_mut().enumerate() {
                let shape =
                    maps.stick_shape[i] * b.work[i] + dot(maps.shape_weights.row(i), &b.p_nodes);
                *r -= eta * shape;
            }
        }
        for (r, f) in b.srhs.iter_mut().zip(self.fixed) {
            *r += f;
        }
        self.problem
            .disc
            .bounded
            .solve_coefficients(&b.srhs, &mut b.beta_q)
    }

    /// The next iterate of the inner unknown into `b.fx`: the traction `η p S + q̃_own +
    /// q̃_inherited` at the sample points (p by sine transforms, q̃'s own part by its map)
    /// and, when coupled, q̃'s roots at the new ends; q̃'s own series and the roots `ends` of
    /// this pass into `state`'s stick zone.
    fn next_traction(&self, ends: [f64; 2], state: &mut ContactState, b: &mut InnerBuffers) {
        let (np, nc, eta) = (self.np, self.nc, self.k.eta);
        let (fixed_p, fixed_c) = (&self.fixed_samples.0, &self.fixed_samples.1);
        self.problem
            .disc
            .bounded_at_collocation(&b.beta_p, &mut b.p_samples);
        self.kinks
            .at_samples
            .add_apply(&b.amp, 1.0, &mut b.p_samples);
        self.maps
            .own_at_samples_into(&b.beta_q, &mut b.own_inside, &mut b.own_samples);
        for (k, (shape, inh)) in fixed_p.iter().chain(fixed_c).enumerate() {
            b.fx[k] = eta * b.p_samples[k] * shape + b.own_samples[k] + inh;
        }
        if self.k.coupled {
            let [left, right] = self.probes.scaled_roots_of(&b.beta_q);
            b.fx[np + nc] = left;
            b.fx[np + nc + 1] = right;
        }
        if let Some(stick) = state.traction.stick.as_mut() {
            stick.correction.beta.clone_from(&b.beta_q);
            stick.end_roots = ends;
        }
    }

    /// Whether `guess`'s own series sits on the same inherited zone as this evaluation's
    /// `closed` (the previous iterate, or the previous step of the phase), on this grid: then
    /// its coefficients give the inner iteration's start at this geometry
    /// ([`Self::starting_traction`], [`Self::starting_roots`]).
    fn same_chain(&self, guess: &ContactState, closed: &StickZone) -> bool {
        let m = self.problem.disc.nodes();
        guess.traction.stick.as_ref().is_some_and(|z| {
            z.correction.beta.len() == m
                && guess.pressure.beta.len() == m
                && match (&z.inherited, &closed.inherited) {
                    (Some(u), Some(v)) => Arc::ptr_eq(&u.zone, &v.zone),
                    (None, None) => true,
                    _ => false,
                }
        })
    }

    /// The starting traction at the sample points. When the guess's own series sits on the
    /// same inherited zone ([`Self::same_chain`]), its coefficients at this geometry's points
    /// with this evaluation's chain and S: two products per point instead of a walk of the
    /// guess's chain. Otherwise the guess's traction itself. The start only speeds up the
    /// iteration, which stops at the same inner tolerance from either: the solution changes
    /// within that tolerance.
    fn starting_traction(
        &self,
        guess: &ContactState,
        closed: &StickZone,
        sample_points: &[f64],
        b: &mut InnerBuffers,
    ) -> Vec<f64> {
        let (fixed_p, fixed_c) = (&self.fixed_samples.0, &self.fixed_samples.1);
        if self.same_chain(guess, closed) {
            let guess_zone = guess.traction.stick.as_ref();
            let own = &guess_zone.expect("same chain").correction.beta;
            self.problem
                .disc
                .bounded_at_collocation(&guess.pressure.beta, &mut b.p_samples);
            self.maps
                .own_at_samples_into(own, &mut b.own_inside, &mut b.own_samples);
            fixed_p
                .iter()
                .chain(fixed_c)
                .zip(sample_points)
                .enumerate()
                .map(|(k, ((shape, inh), &xs))| {
                    let p = b.p_samples[k] + guess.kinks_at(&guess.pressure_kinks, xs);
                    self.k.eta * p * shape + b.own_samples[k] + inh
                })
                .collect()
        } else {
            let mut x = Vec::with_capacity(sample_points.len() + 2);
            guess.tractions_into(sample_points, &mut x);
            x
        }
    }

    /// The root unknowns' start: on the same chain ([`Self::same_chain`]: the previous
    /// iterate, or the previous step of the phase) the guess's own roots, which its inner
    /// iteration converged; otherwise q̃ of the guess probed at this geometry's probe points.
    /// (Probed on the same chain, they were off by the ends' move over the probe distance,
    /// 1e−2 of the half-width: the first pass changed them ten times more than the traction,
    /// so the stored roots save inner passes.) The start only speeds up the iteration, which
    /// stops at the same inner tolerance from either: the solution changes within that
    /// tolerance.
    fn starting_roots(&self, guess: &ContactState, closed: &StickZone) -> [f64; 2] {
        let same_chain = self.same_chain(guess, closed);
        let probes = self.probes;
        guess.traction.stick.as_ref().map_or([0.0; 2], |z| {
            if same_chain {
                [
                    z.end_roots[0] * probes.scale[0],
                    z.end_roots[1] * probes.scale[1],
                ]
            } else {
                probes.scaled_roots(|x| z.correction_at(x))
            }
        })
    }
}

/// Tolerance of the inner iteration: the largest change of the traction in a pass, relative
/// to `η p0`.
pub(super) const INNER_TOLERANCE: f64 = 1e-14;

/// The inner tolerance of a trial iterate when the current residual norm is `residual`: an
/// inexact Newton method, whose residuals need only be accurate to a small fraction (here
/// 1e−3) of the residual being reduced; never looser than 1e−8 nor tighter than
/// [`INNER_TOLERANCE`]. A step is accepted only on a residual evaluated at the full tolerance,
/// so the loose trials save inner passes without changing the accepted states. The first step
/// after a reversal, whose failed attempts wander, reacts to the inner tolerance erratically.
pub(super) fn inner_tolerance(residual: f64) -> f64 {
    (1e-3 * residual).clamp(INNER_TOLERANCE, LOOSEST_INNER_TOLERANCE)
}

/// The loosest inner tolerance of a trial iterate ([`inner_tolerance`]).
pub(super) const LOOSEST_INNER_TOLERANCE: f64 = 1e-8;

/// The inner tolerance of the finite-difference Jacobian's evaluations: its differences over
/// steps of 1e−6 a change the residuals by about 1e−6, so 1e−11 leaves 1e−5 of the Jacobian,
/// and a tighter tolerance would cost inner passes without changing the states.
pub(super) const JACOBIAN_INNER_TOLERANCE: f64 = 1e-11;

/// The coefficients that scale the rows of [`InnerMaps`].
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct Coefficients {
    /// `(w12 + χ w13)/y11`: the pressure's local term in the stick equation.
    pub(super) local_over_y11: f64,
    /// `η s` when both slip zones have the sign s (the `−η s H'p` term folded into the
    /// pressure rows); `None` for mixed signs, whose `H'(pS)` is assembled separately.
    pub(super) shape: Option<f64>,
    /// `w13/y11` when the charge is an unknown (conducting punch).
    pub(super) charge: Option<f64>,
}
