//! What the general solver's steps leave for later ones, only to go faster ([`Recall`]): the
//! solvers of the last meshes (the influence matrices and their factors, the cost of a
//! handover) and the last steps, each with the state it began from and its loads.
//!
//! A step is a pure function of its solver (the model and the mesh), the state it begins from
//! and its loads ([`Solver::step`]), so a step that begins from a state equal to the bit to a
//! remembered step's, on a solver of the same mesh and under the same loads, has the
//! remembered result, bit for bit. In a steady cycle of a coupled contact every phase begins
//! with steps the general solver takes (the end layers, module docs of [`crate::history`]),
//! from turning states that repeat to round-off (the spectral solver evaluates their tractions
//! through chains of earlier stick zones that are not the same objects from cycle to cycle);
//! adopted with their element means rounded ([`Solver::adopt_rounded`]) they are one state
//! to the bit, and their steps are recalled: their cost no longer grows with the length of
//! the history.
//!
//! One `Recall` serves one run of one model (`history::continue_run` owns it); it is not
//! state: a run resumed from a checkpoint starts with an empty one and solves the steps the
//! uninterrupted run recalled, to the same bits. Switched by
//! [`crate::contact::Accelerations::general_recall`], which also chooses the rounded
//! adoption.

use std::collections::VecDeque;
use std::sync::Arc;

use super::{Drive, GeneralState, Loads, Mesh, Options, Solver, StepReport};
use crate::contact::ContactModel;
use crate::error::SolveFailure;

/// Solvers kept: the meshes of the two phase starts of a cycle, twice (each holds two dense
/// matrices of its elements: about 5 MB at 550 elements).
const SOLVERS: usize = 4;
/// Steps kept.
const STEPS: usize = 32;

/// A remembered step.
#[derive(Debug)]
struct Step {
    solver: Arc<Solver>,
    from: GeneralState,
    loads: Loads,
    drive: Drive,
    /// The outer tolerance it was solved to.
    tolerance: f64,
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

    /// Whether it remembers (and the handed-over states are adopted rounded).
    pub fn enabled(&self) -> bool {
        self.enabled
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
        // A step on a solver no longer kept can never be recalled (a solver is only ever
        // handed out again from `solvers`), and would keep that solver's matrices alive.
        let kept = &self.solvers;
        self.steps
            .retain(|step| kept.iter().any(|s| Arc::ptr_eq(s, &step.solver)));
        solver
    }

    /// The distinct solvers alive in the recall (kept, or held by a remembered step).
    #[cfg(test)]
    fn solvers_alive(&self) -> usize {
        let mut alive: Vec<&Arc<Solver>> = self.solvers.iter().collect();
        for step in &self.steps {
            if !alive.iter().any(|s| Arc::ptr_eq(s, &step.solver)) {
                alive.push(&step.solver);
            }
        }
        alive.len()
    }

    /// `solver.step(from, loads)`, or the remembered result of the same step.
    pub fn step(
        &mut self,
        solver: &Arc<Solver>,
        from: &GeneralState,
        loads: Loads,
    ) -> Result<(GeneralState, StepReport), SolveFailure> {
        self.step_with(solver, from, loads, Drive::Load)
    }

    /// `solver.step_with(from, loads, drive)`, or the remembered result of the same step.
    pub fn step_with(
        &mut self,
        solver: &Arc<Solver>,
        from: &GeneralState,
        loads: Loads,
        drive: Drive,
    ) -> Result<(GeneralState, StepReport), SolveFailure> {
        self.step_to(solver, from, loads, drive, solver.options.tolerance)
    }

    /// `solver.step_to_tolerance(from, loads, tolerance)`, or the remembered result of the
    /// same step to the same tolerance.
    pub fn step_to_tolerance(
        &mut self,
        solver: &Arc<Solver>,
        from: &GeneralState,
        loads: Loads,
        tolerance: f64,
    ) -> Result<(GeneralState, StepReport), SolveFailure> {
        self.step_to(solver, from, loads, Drive::Load, tolerance)
    }

    fn step_to(
        &mut self,
        solver: &Arc<Solver>,
        from: &GeneralState,
        loads: Loads,
        drive: Drive,
        tolerance: f64,
    ) -> Result<(GeneralState, StepReport), SolveFailure> {
        if !self.enabled {
            return solver.step_to(from, loads, drive, tolerance);
        }
        let found = self.steps.iter().position(|s| {
            Arc::ptr_eq(&s.solver, solver)
                && same_loads(s.loads, loads)
                && same_drive(s.drive, drive)
                && s.tolerance.to_bits() == tolerance.to_bits()
                && same_state(&s.from, from)
        });
        if let Some(k) = found {
            self.recalled_steps += 1;
            let step = self.steps.remove(k).expect("found");
            let result = step.result.clone();
            self.steps.push_front(step);
            return Ok(result);
        }
        let result = solver.step_to(from, loads, drive, tolerance)?;
        self.steps.push_front(Step {
            solver: Arc::clone(solver),
            from: from.clone(),
            loads,
            drive,
            tolerance,
            result: result.clone(),
        });
        self.steps.truncate(STEPS);
        Ok(result)
    }
}

/// Whether `a` and `b` are equal to the bit.
pub(super) fn same_bits(a: &[f64], b: &[f64]) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits())
}

fn same_loads(a: Loads, b: Loads) -> bool {
    same_bits(
        &[a.normal, a.tangential, a.electric],
        &[b.normal, b.tangential, b.electric],
    )
}

fn same_drive(a: Drive, b: Drive) -> bool {
    match (a, b) {
        (Drive::Load, Drive::Load) => true,
        (Drive::Displacement(x), Drive::Displacement(y)) => x.to_bits() == y.to_bits(),
        _ => false,
    }
}

/// Equal to the bit (a derived `==` would take −0.0 for 0.0).
fn same_state(a: &GeneralState, b: &GeneralState) -> bool {
    a.codes == b.codes
        && same_loads(a.loads, b.loads)
        && same_bits(
            &[a.approach, a.shift, a.potential],
            &[b.approach, b.shift, b.potential],
        )
        && same_bits(&a.pressure, &b.pressure)
        && same_bits(&a.shear, &b.shear)
        && same_bits(&a.charge, &b.charge)
        && same_bits(&a.displacement, &b.displacement)
        && same_bits(&a.slip, &b.slip)
        && same_bits(&a.mesh.edges, &b.mesh.edges)
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
            bulk_stress: 0.0,
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

    /// A step from a state equal to the bit to a remembered step's, on a mesh built again,
    /// takes the remembered result, which is the result of solving it; a state 1e−14 away, or
    /// a recall switched off, is solved.
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
        let recalled = recall.step(&again, &state.clone(), back).unwrap();
        assert_eq!(recall.recalled_steps, 1);
        assert!(same_state(&recalled.0, &first.0));
        assert!(same_state(&solver.step(&state, back).unwrap().0, &first.0));

        let nearby = perturbed(&state, 1e-14);
        recall.step(&solver, &nearby, back).unwrap();
        assert_eq!(recall.recalled_steps, 1, "a state 1e−14 away is solved");

        // Steps on many meshes (each phase start of a history has its own): no more solvers
        // stay alive than are kept, whatever the steps remembered.
        for k in 1..=2 * SOLVERS {
            let other = Mesh::uniform(-1.25 * 4.2e-5, 1.25 * 4.2e-5, 200 + k);
            let solver = recall.solver(&model, other.clone(), Options::default());
            let from = GeneralState::unloaded(other);
            let pressed = Loads {
                tangential: 0.0,
                ..back
            };
            recall.step(&solver, &from, pressed).unwrap();
        }
        assert_eq!(recall.solvers_alive(), SOLVERS);

        let mut off = Recall::new(false);
        let one = off.solver(&model, mesh.clone(), Options::default());
        let two = off.solver(&model, mesh, Options::default());
        assert!(!Arc::ptr_eq(&one, &two));
        off.step(&one, &state, back).unwrap();
        off.step(&one, &state, back).unwrap();
        assert_eq!((off.recalled_steps, off.reused_solvers), (0, 0));
    }
}
