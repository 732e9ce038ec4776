//! The residuals of a step at fixed geometry (tangential module docs, "Equations"): the linear
//! problem at given stick ends and contact `(lo, hi, a, c)`, i.e. the pressure with the
//! eccentric punch (seed eqs. 46, 52, 54), the charge (eqs. 47, 53, 55) and the stick traction
//! (eqs. 43/60, 48/63), coupled through κq, w13 w and the slip traction, solved by the inner
//! fixed-point iteration; and the four dimensionless residuals (pressure consistency and
//! resultant, stick consistency and force) that the search drives to zero. With the inner
//! iteration's tolerances.

use std::cell::RefCell;
use std::sync::Arc;

use crate::contact::memory::Memory;
use crate::contact::normal::arcsine_moment;
use crate::contact::pressure::{Discretisation, electric_resultants};
use crate::contact::{ContactModel, ContactState, Inherited, StickZone, kink_domain};
use crate::error::SolveFailure;
use crate::quadrature::{BoundedSeries, dot};

use super::inner::{InnerMaps, StickSums};
use super::kinks::{EndProbes, KinkMaps, KinkPoints, pressure_root, resolved};
use super::linalg::Anderson;
use super::reuse::{PartsKey, Reused};

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
    /// The inherited link of the last evaluation, whose fade table the next evaluation reuses
    /// when its ramps have hardly moved ([`Inherited::reusing_table_of`]; one for all the
    /// attempts of a step, on both grids).
    pub(super) last_link: &'a RefCell<Option<Arc<Inherited>>>,
    /// The parts of the last evaluations that depend on the geometry through the stick
    /// points or through the sample points alone ([`Reused`]; one for all the attempts of a
    /// step, on both grids).
    pub(super) reused: &'a RefCell<Reused>,
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
        let inherited = self
            .base
            .and_then(|b| b.inheritance_for(g.lo, g.hi, self.disc.nodes()))
            .map(|link| {
                let last = self.last_link.borrow();
                match (Arc::try_unwrap(link), last.as_deref()) {
                    (Ok(link), Some(built)) => Arc::new(link.reusing_table_of(built)),
                    (Ok(link), None) => Arc::new(link),
                    (Err(shared), _) => shared,
                }
            });
        let evaluated = self.evaluate_with(g, guess, inherited.clone(), inner_tolerance);
        if inherited.is_some() {
            *self.last_link.borrow_mut() = inherited;
        }
        evaluated
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
        let (model, disc) = (self.model, self.disc);
        let m = disc.nodes();
        let split = guess.split;
        let ystar = model.pressure_compliance(split);
        let kappa = model.pressure_shear_coupling(split);
        let y11 = model.compliance.y11;
        let eta = model.friction;
        let w13 = model.compliance.electric.map_or(0.0, |e| e.w13);
        let local = model.local_pressure_strain(split);
        let potential_control = matches!(
            model.electrode,
            crate::contact::Electrode::ConductingPotential { .. }
        );
        let (mid, half) = (0.5 * (g.lo + g.hi), 0.5 * (g.hi - g.lo));
        // Collocation points mapped onto an interval `centre ± half`.
        let mapped = |points: &[f64], centre: f64, half: f64| -> Vec<f64> {
            points.iter().map(|t| centre + half * t).collect()
        };
        let stick_points = mapped(&disc.bounded.collocation, mid, half);
        let pressure_points = mapped(&disc.bounded.collocation, g.c, g.a);
        let charge_points = mapped(&disc.unbounded.collocation, g.c, g.a);
        let electric = split
            .conducting
            .then_some(model.compliance.electric)
            .flatten();
        let w13_over_y33 = electric.map_or(0.0, |e| e.w13 / e.y33);
        let coupled = model.stick_end_kinks && (kappa.abs() > 0.0 || w13_over_y33.abs() > 0.0);
        // The remembered stick ends inside the zone and the parts of q̃ that carry their kinks
        // beyond them (tangential module docs, "Kinks at the stick ends").
        let interior = match (&inherited, coupled) {
            (Some(z), true) => z.interior_roots(g.lo, g.hi),
            _ => Vec::new(),
        };
        let new_zone = StickZone {
            end_signs: [self.signs.0, self.signs.1],
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
        // The part of q̃ fixed by the geometry: the inherited chain and the extras.
        let closed = StickZone {
            inherited: inherited.clone(),
            extras,
            ..new_zone
        };
        // Parts of the stick right-hand side that do not change in the inner iteration (with
        // no charge unknown, whatever charge the state carries is among them).
        let stick_parts = Reused::get_or_make(
            &mut self.reused.borrow_mut().stick,
            PartsKey::new(m, (mid, half), &closed, [0.0; 2]),
            || {
                let (mut chain, mut remembered) = (Vec::with_capacity(m), Vec::with_capacity(m));
                closed.correction_cauchys_into(&stick_points, &mut chain);
                self.memory
                    .strains_into(model, &stick_points, &mut remembered);
                (chain, remembered)
            },
        );
        let (chain_cauchy, remembered) = (&stick_parts.0, &stick_parts.1);
        let fixed: Vec<f64> = stick_points
            .iter()
            .zip(chain_cauchy)
            .zip(remembered)
            .map(|((&x, h), strain)| {
                let fixed_charge = if split.conducting {
                    0.0
                } else {
                    w13 * guess.potential_charge_at(x) / y11
                };
                strain / y11 - h + fixed_charge
            })
            .collect();
        let inherited_force = closed.correction_integral();
        let mut state = guess.clone();
        state.shape_table = None;
        state.half_width = g.a;
        state.centre = g.c;
        state.tangential_load = self.tangential_load;
        state.traction.friction = eta;
        state.traction.left_sign = self.signs.0;
        state.traction.right_sign = self.signs.1;
        state.traction.stick = Some(closed.clone());
        let mixed = (self.signs.0 - self.signs.1).abs() > 0.0;
        // The traction at the pressure and charge points is `η p S + q̃_own + q̃_inherited`;
        // S and the inherited part depend on the geometry only, so they are evaluated once.
        let sampled = |points: &[f64]| -> Vec<(f64, f64)> {
            let mut inherited = Vec::with_capacity(points.len());
            closed.corrections_into(points, &mut inherited);
            points
                .iter()
                .zip(inherited)
                .map(|(&x, inh)| (state.slip_shape(x), inh))
                .collect()
        };
        let ends = if mixed { [g.lo, g.hi] } else { [0.0; 2] };
        let sample_parts = Reused::get_or_make(
            &mut self.reused.borrow_mut().samples,
            PartsKey::new(m, (g.c, g.a), &closed, ends),
            || {
                let charge = if split.conducting {
                    sampled(&charge_points)
                } else {
                    Vec::new()
                };
                (sampled(&pressure_points), charge)
            },
        );
        let (fixed_p, fixed_c) = (&sample_parts.0, &sample_parts.1);
        let (np, nc) = (pressure_points.len(), fixed_c.len());
        let sample_points: Vec<f64> = pressure_points
            .iter()
            .chain(&charge_points[..nc])
            .copied()
            .collect();
        let mut maps = self.scratch.take();
        maps.rebuild(
            &state,
            &stick_points,
            &sample_points,
            m,
            Coefficients {
                local_over_y11: local / y11,
                shape: (!mixed).then_some(eta * self.signs.0),
                charge: split.conducting.then_some(w13 / y11),
            },
        );
        // The kinks of p and w: at the new stick ends, whose q̃ roots are unknowns of the inner
        // iteration, estimated from q̃ at `END_PROBE` and twice that of the half-width inside
        // each end (nearer where a remembered end is close, see `EndProbes`), and at the
        // remembered stick ends inside the zone, whose roots the chain carries.
        let interior_points: Vec<f64> = interior.iter().map(|r| r.at).collect();
        let probes = EndProbes::new(g, m, &closed, &interior_points);
        let kinks = if coupled {
            let mut points = vec![
                (g.lo, -1.0, 0.0, self.signs.0),
                (g.hi, 1.0, 0.0, self.signs.1),
            ];
            points.extend(interior.iter().map(|r| (r.at, r.side, r.root, r.sign)));
            KinkMaps::new(
                &state,
                &points,
                KinkPoints {
                    pressure: &pressure_points,
                    charge: &charge_points[..nc],
                    stick: &stick_points,
                    samples: &sample_points,
                    nodes: &maps.node_points,
                },
                m,
                [kappa / ystar, w13_over_y33, eta],
            )
        } else {
            KinkMaps::default()
        };
        // The inner unknown: q at the pressure points, then at the charge points, then (when
        // coupled) q̃'s root coefficients at the new ends, times √h (Pa).
        // The starting traction. When the guess's own series sits on the same inherited zone
        // (the previous iterate, or the previous step of the phase), its coefficients at this
        // geometry's points with this evaluation's chain and S: two products per point instead
        // of a walk of the guess's chain. Otherwise the guess's traction itself.
        let guess_zone = guess.traction.stick.as_ref();
        let same_chain = guess_zone.is_some_and(|z| {
            z.correction.beta.len() == m
                && guess.pressure.beta.len() == m
                && match (&z.inherited, &closed.inherited) {
                    (Some(u), Some(v)) => Arc::ptr_eq(&u.zone, &v.zone),
                    (None, None) => true,
                    _ => false,
                }
        });
        let (mut p_samples, mut own_samples) = (vec![0.0; np + nc], vec![0.0; np + nc]);
        let mut own_inside = vec![0.0; maps.own_rows.len()];
        let mut x: Vec<f64> = if same_chain {
            let own = &guess_zone.expect("same chain").correction.beta;
            disc.bounded_at_collocation(&guess.pressure.beta, &mut p_samples);
            maps.own_at_samples_into(own, &mut own_inside, &mut own_samples);
            fixed_p
                .iter()
                .chain(fixed_c)
                .zip(&sample_points)
                .enumerate()
                .map(|(k, ((shape, inh), &xs))| {
                    let p = p_samples[k] + guess.kinks_at(&guess.pressure_kinks, xs);
                    eta * p * shape + own_samples[k] + inh
                })
                .collect()
        } else {
            let mut x = Vec::with_capacity(sample_points.len() + 2);
            guess.tractions_into(&sample_points, &mut x);
            x
        };
        // The root unknowns: on the same chain (the previous iterate, or the previous step of the
        // phase) the guess's own roots, which its inner iteration converged; otherwise q̃ of the
        // guess probed at this geometry's probe points. (Probed on the same chain, they were off
        // by the ends' move over the probe distance, 1e−2 of the half-width: the first pass
        // changed them ten times more than the traction, so the stored roots save inner
        // passes.)
        if coupled {
            x.extend(guess_zone.map_or([0.0; 2], |z| {
                if same_chain {
                    [
                        z.end_roots[0] * probes.scale[0],
                        z.end_roots[1] * probes.scale[1],
                    ]
                } else {
                    probes.scaled_roots(|x| z.correction_at(x))
                }
            }));
        }
        let mut fx = vec![0.0; x.len()];
        let mut rhs = vec![0.0; m + 1];
        let mut beta_p = vec![0.0; m];
        let mut beta_q = vec![0.0; m];
        let mut gamma = vec![0.0; m];
        let mut srhs = vec![0.0; m + 1];
        let mut crhs = vec![0.0; m.saturating_sub(1)];
        let mut work = vec![0.0; m + 1];
        let mut stick_sums = StickSums::new(m);
        let mut p_nodes = vec![0.0; maps.shape_nodes.rows()];
        // The kink terms' roots and amplitudes of p and w, refilled in each pass.
        let (mut roots, mut amp, mut w_amp) = (Vec::new(), Vec::new(), Vec::new());
        let scale = model.pressure_scale(split);
        let p_scale = g.a * scale;
        let (mut lambda_p, mut lambda_q) = (0.0, 0.0);
        let mut full = false;
        let mut accel = Anderson::new(5);
        for _ in 0..100 {
            // Pressure for the current shear traction (seed eqs. 52, 54, 56), less the Cauchy
            // transform of its kinks.
            let ends = if coupled {
                [
                    x[np + nc] / probes.scale[0],
                    x[np + nc + 1] / probes.scale[1],
                ]
            } else {
                [0.0; 2]
            };
            kinks.roots_into(ends, &mut roots);
            kinks.pressure_amplitudes_into(&roots, &mut amp);
            w_amp.clear();
            w_amp.resize(amp.len(), 0.0);
            for ((r, &xp), q) in rhs.iter_mut().zip(&pressure_points).zip(&x[..np]) {
                *r = -xp * scale - kappa / ystar * q;
            }
            kinks.cauchy_at_pressure.add_apply(&amp, -1.0, &mut rhs);
            lambda_p = disc.bounded.solve_coefficients(&rhs, &mut beta_p);
            state.pressure.beta.clone_from(&beta_p);
            kinks.kinks_into(&amp, &mut state.pressure_kinks);
            // Charge (seed eqs. 53, 55, 41–42) for the current shear traction. The arcsine
            // moment of q fixes Γ under potential control; under charge control it only gives
            // φ0 and is evaluated once for the accepted state.
            if split.conducting {
                let e = model
                    .compliance
                    .electric
                    .expect("conducting punch on a piezoelectric half-plane");
                let j_q = if potential_control {
                    arcsine_moment(&state)
                } else {
                    0.0
                };
                let (charge, potential) = electric_resultants(model, g.a, self.normal_load, j_q);
                state.charge = charge;
                state.potential = potential;
                let free = charge - model.pressure_charge(self.normal_load);
                kinks.charge_amplitudes_into(&roots, &mut w_amp);
                kinks.kinks_into(&w_amp, &mut state.charge_kinks);
                for (r, q) in crhs.iter_mut().zip(&x[np..np + nc]) {
                    *r = -e.w13 / e.y33 * q;
                }
                kinks.cauchy_at_charge.add_apply(&w_amp, -1.0, &mut crhs);
                let kinks_force =
                    state.potential_charge_force() - g.a * state.potential_charge.integral();
                disc.unbounded
                    .solve_coefficients(&crhs, (free - kinks_force) / g.a, &mut gamma);
                state.potential_charge.gamma.clone_from(&gamma);
            }
            // Stick traction (seed eqs. 50–51/58–59, 60, 63); `H'(pS)` is `s H'p` when both slip
            // zones have the same sign s.
            maps.stick_terms(&beta_p, &gamma, &mut stick_sums, &mut srhs, &mut work);
            if let Some(eta_s) = maps.coefficients.shape {
                kinks.cauchy_at_stick.add_apply(&amp, -eta_s, &mut srhs);
            }
            // The remembered kinks' terms reach into the stick zone: their local parts.
            kinks.at_stick.add_apply(&amp, local / y11, &mut srhs);
            kinks.at_stick.add_apply(&w_amp, w13 / y11, &mut srhs);
            if mixed {
                maps.shape_nodes.apply(&beta_p, &mut p_nodes);
                kinks.cauchy_at_stick.add_apply(&amp, 1.0, &mut work);
                kinks.at_nodes.add_apply(&amp, 1.0, &mut p_nodes);
                for (i, r) in srhs.iter_mut().enumerate() {
                    let shape =
                        maps.stick_shape[i] * work[i] + dot(maps.shape_weights.row(i), &p_nodes);
                    *r -= eta * shape;
                }
            }
            for (r, f) in srhs.iter_mut().zip(&fixed) {
                *r += f;
            }
            lambda_q = disc.bounded.solve_coefficients(&srhs, &mut beta_q);
            // p at the sample points (sine transforms) and q̃'s own part there (its map).
            disc.bounded_at_collocation(&beta_p, &mut p_samples);
            kinks.at_samples.add_apply(&amp, 1.0, &mut p_samples);
            maps.own_at_samples_into(&beta_q, &mut own_inside, &mut own_samples);
            for (k, (shape, inh)) in fixed_p.iter().chain(fixed_c).enumerate() {
                fx[k] = eta * p_samples[k] * shape + own_samples[k] + inh;
            }
            if coupled {
                let [left, right] = probes.scaled_roots_of(&beta_q);
                fx[np + nc] = left;
                fx[np + nc + 1] = right;
            }
            if let Some(stick) = state.traction.stick.as_mut() {
                stick.correction.beta.clone_from(&beta_q);
                stick.end_roots = ends;
            }
            let p0 = state.pressure_at(g.c).abs().max(1e-300);
            let change = fx
                .iter()
                .zip(&x)
                .map(|(n, o)| (n - o).abs())
                .fold(0.0, f64::max)
                / (eta * p0);
            let exact = kappa == 0.0 && !split.conducting;
            if exact || change < inner_tolerance {
                full = exact || change < INNER_TOLERANCE;
                break;
            }
            accel.next(&mut x, &fx);
        }
        self.scratch.replace(maps);
        state.shape_table = None;
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
        let residual = [
            lambda_p / p_scale,
            (pressure_force - self.normal_load) / self.normal_load,
            lambda_q / (eta * p0),
            (q_force - self.tangential_load) / (eta * self.normal_load),
        ];
        Ok((residual, state, full))
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
