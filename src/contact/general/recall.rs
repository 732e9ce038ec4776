//! What the general solver's steps leave for later ones, only to go faster ([`Recall`]): the
//! solvers of the last meshes (the influence matrices and their factors, the cost of a
//! handover) and the last steps, each with the state it began from and its loads.
//!
//! A step is a function of its solver (the model and the mesh), the state it begins from and
//! its loads ([`Solver::step`]), continuous in the state (the tangential programme is strictly
//! convex). A step that begins, on a solver of the same mesh (equal to the bit) and under the
//! same loads (to the bit), from a state within [`MATCH`] of a remembered step's takes the
//! remembered result: it differs from the step solved afresh by about the difference of the
//! states, far below the solver's tolerance. In a steady cycle of a coupled contact every phase
//! begins with steps the general solver takes (the end layers, module docs of
//! [`crate::history`]), from turning states that repeat: those steps are recalled, and their
//! cost no longer grows with the length of the history.
//!
//! One `Recall` serves one run of one model (`history::continue_run` owns it); it is not
//! state: a run resumed from a checkpoint starts with an empty one and takes the same steps.
//! Switched by [`crate::contact::Accelerations::general_recall`].

use std::collections::VecDeque;
use std::sync::Arc;

use super::{GeneralState, Loads, Mesh, Options, Solver, StepReport};
use crate::contact::ContactModel;
use crate::error::SolveFailure;

/// Solvers kept: the meshes of the two phase starts of a cycle, twice (each holds two dense
/// matrices of its elements: about 5 MB at 550 elements).
const SOLVERS: usize = 4;
/// Steps kept.
const STEPS: usize = 32;

/// How close a state must be to a remembered step's to take its result: relative to each
/// field's largest magnitude, four orders below the solver's outer tolerance
/// ([`Options::tolerance`], 1e−8). The turning states of a steady cycle repeat their geometry
/// to the bit and their tractions to round-off (about 1e−15: the spectral solver evaluates them
/// through chains of earlier stick zones that are not the same objects from cycle to cycle).
pub const MATCH: f64 = 1e-12;

/// A remembered step.
#[derive(Debug)]
struct Step {
    solver: Arc<Solver>,
    from: GeneralState,
    loads: Loads,
    result: (GeneralState, StepReport),
}

/// The solvers of the last meshes and the last steps (module docs).
#[derive(Debug, Default)]
pub struct Recall {
    enabled: bool,
    solvers: VecDeque<Arc<Solver>>,
    steps: VecDeque<Step>,
    /// Steps returned from memory.
    pub recalled_steps: usize,
    /// Solvers reused for a mesh built again.
    pub reused_solvers: usize,
}

impl Recall {
    /// A recall that remembers when `enabled`, and otherwise builds every solver and solves
    /// every step (the reference path).
    pub fn new(enabled: bool) -> Self {
        Self {
            enabled,
            ..Self::default()
        }
    }

    /// The solver of `model` on `mesh`: a kept one on a mesh equal to the bit, or a new one.
    pub fn solver(&mut self, model: &ContactModel, mesh: Mesh, options: Options) -> Arc<Solver> {
        if !self.enabled {
            return Arc::new(Solver::new(model, mesh, options));
        }
        if let Some(k) = self
            .solvers
            .iter()
            .position(|s| s.options == options && same_bits(&s.mesh.edges, &mesh.edges))
        {
            self.reused_solvers += 1;
            let solver = self.solvers.remove(k).expect("found");
            self.solvers.push_front(Arc::clone(&solver));
            return solver;
        }
        let solver = Arc::new(Solver::new(model, mesh, options));
        self.solvers.push_front(Arc::clone(&solver));
        self.solvers.truncate(SOLVERS);
        solver
    }

    /// `solver.step(from, loads)`, or the remembered result of the same step.
    pub fn step(
        &mut self,
        solver: &Arc<Solver>,
        from: &GeneralState,
        loads: Loads,
    ) -> Result<(GeneralState, StepReport), SolveFailure> {
        if !self.enabled {
            return solver.step(from, loads);
        }
        let found = self.steps.iter().position(|s| {
            Arc::ptr_eq(&s.solver, solver)
                && same_loads(s.loads, loads)
                && close_state(&s.from, from)
        });
        if let Some(k) = found {
            self.recalled_steps += 1;
            let step = self.steps.remove(k).expect("found");
            let result = step.result.clone();
            self.steps.push_front(step);
            return Ok(result);
        }
        let result = solver.step(from, loads)?;
        self.steps.push_front(Step {
            solver: Arc::clone(solver),
            from: from.clone(),
            loads,
            result: result.clone(),
        });
        self.steps.truncate(STEPS);
        Ok(result)
    }
}

fn same_bits(a: &[f64], b: &[f64]) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits())
}

fn same_loads(a: Loads, b: Loads) -> bool {
    same_bits(
        &[a.normal, a.tangential, a.electric],
        &[b.normal, b.tangential, b.electric],
    )
}

/// The same state to [`MATCH`]: the same element codes and loads, and every field within
/// `MATCH` of its largest magnitude.
fn close_state(a: &GeneralState, b: &GeneralState) -> bool {
    let close = |x: &[f64], y: &[f64]| {
        let scale = x.iter().chain(y).fold(0.0_f64, |m, v| m.max(v.abs()));
        x.len() == y.len()
            && x
                .iter()
                .zip(y)
                .all(|(u, v)| (u - v).abs() <= MATCH * scale)
    };
    a.codes == b.codes
        && same_loads(a.loads, b.loads)
        && same_bits(&a.mesh.edges, &b.mesh.edges)
        && [
            (a.approach, b.approach),
            (a.shift, b.shift),
            (a.potential, b.potential),
        ]
        .iter()
        .all(|&(u, v)| close(&[u], &[v]))
        && close(&a.pressure, &b.pressure)
        && close(&a.shear, &b.shear)
        && close(&a.charge, &b.charge)
        && close(&a.displacement, &b.displacement)
        && close(&a.slip, &b.slip)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::general::{ElementState, Focus};
    use crate::contact::{Electrode, Profile};
    use crate::material::{Material, PZT4};

    /// PZT-4 under a conducting cylinder (the default contact), on a mesh graded towards the
    /// ends of its Hertz-like contact, loaded to P and then to Q = 0.3 ηP.
    fn loaded() -> (ContactModel, Mesh, GeneralState, Loads) {
        let model = ContactModel::new(
            Material::Piezoelectric(PZT4),
            Profile::cylinder(0.06),
            0.3,
            Electrode::ConductingCharge { charge: 6e-7 },
        );
        let a = 4.2e-5;
        let focus = [Focus {
            at: a,
            size: 2e-3 * a,
        }];
        let mesh = Mesh::symmetric(1.25 * a, &focus, 1.08, 0.02 * a);
        let solver = Solver::new(&model, mesh.clone(), Options::default());
        let normal = Loads {
            normal: 2000.0,
            tangential: 0.0,
            electric: 6e-7,
        };
        let (pressed, _) = solver
            .step(&GeneralState::unloaded(mesh.clone()), normal)
            .unwrap();
        let sheared = Loads {
            tangential: 0.3 * 0.3 * 2000.0,
            ..normal
        };
        let (state, _) = solver.step(&pressed, sheared).unwrap();
        assert!(state.length_of(ElementState::Stick) > 0.0);
        let back = Loads {
            tangential: 0.1 * 0.3 * 2000.0,
            ..normal
        };
        (model, mesh, state, back)
    }

    /// The state with every traction scaled by `1 + factor`.
    fn perturbed(state: &GeneralState, factor: f64) -> GeneralState {
        let mut out = state.clone();
        for v in out.pressure.iter_mut().chain(out.shear.iter_mut()) {
            *v *= 1.0 + factor;
        }
        out
    }

    /// A step from a state within `MATCH` of a remembered step's, on a mesh built again, takes
    /// the remembered result; a state farther away, or a recall switched off, is solved; and
    /// the recalled result agrees with the step solved afresh from the nearby state (1e−14
    /// away) far within the solver's outer tolerance (measured: 1.0e−13 of p_max; the bound
    /// is the tolerance, 1e−8, what two solutions of one step may differ by).
    #[test]
    fn a_repeated_step_is_recalled_and_a_different_one_is_solved() {
        let (model, mesh, state, back) = loaded();
        let mut recall = Recall::new(true);
        let solver = recall.solver(&model, mesh.clone(), Options::default());
        let first = recall.step(&solver, &state, back).unwrap();
        assert_eq!(recall.recalled_steps, 0);

        let again = recall.solver(&model, mesh.clone(), Options::default());
        assert!(Arc::ptr_eq(&solver, &again));
        assert_eq!(recall.reused_solvers, 1);
        let nearby = perturbed(&state, 1e-14);
        let recalled = recall.step(&again, &nearby, back).unwrap();
        assert_eq!(recall.recalled_steps, 1);
        assert!(recalled.0 == first.0);

        let fresh = solver.step(&nearby, back).unwrap();
        let pmax = fresh.0.pressure.iter().cloned().fold(0.0, f64::max);
        let worst = fresh
            .0
            .pressure
            .iter()
            .zip(&recalled.0.pressure)
            .chain(fresh.0.shear.iter().zip(&recalled.0.shear))
            .map(|(x, y)| (x - y).abs() / pmax)
            .fold(0.0, f64::max);
        println!("recalled against solved afresh: {worst:e} of p_max");
        assert!(worst <= Options::default().tolerance, "{worst:e}");

        let farther = perturbed(&state, 1e-6);
        recall.step(&solver, &farther, back).unwrap();
        assert_eq!(recall.recalled_steps, 1, "a state 1e−6 away is solved");

        let mut off = Recall::new(false);
        let one = off.solver(&model, mesh.clone(), Options::default());
        let two = off.solver(&model, mesh, Options::default());
        assert!(!Arc::ptr_eq(&one, &two));
        off.step(&one, &state, back).unwrap();
        off.step(&one, &state, back).unwrap();
        assert_eq!((off.recalled_steps, off.reused_solvers), (0, 0));
    }
}
