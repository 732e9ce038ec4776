//! Frictionless normal contact (η = 0): Hertz for an elastic half-plane, Zhou & Lee (2012) for
//! a conducting punch on a piezoelectric half-plane, and the insulating-punch variant
//! (formulas in the docs of [`crate::contact`]). Solved numerically with the same collocation
//! machinery as the frictional states, so the closed forms test that machinery.

use crate::error::SolveFailure;
use crate::quadrature::UnboundedSeries;

use super::pressure::{
    Discretisation, electric_resultants, solve_potential_charge, solve_pressure,
};
use super::{ContactModel, ContactState, Kinks, Traction};

/// Solve frictionless normal contact under load P (N/m) with the model's electrode.
pub fn solve_frictionless(
    model: &ContactModel,
    disc: &Discretisation,
    normal_load: f64,
) -> Result<ContactState, SolveFailure> {
    let split = model.charge_split(normal_load);
    let zero = |_: f64| 0.0;
    let pressure = solve_pressure(
        model,
        disc,
        split,
        normal_load,
        &zero,
        (f64::NAN, 0.0),
        true,
    )?;
    let a = pressure.half_width;
    let (charge, potential) = electric_resultants(model, a, normal_load, 0.0);
    let potential_charge = if split.conducting {
        let free = charge - model.pressure_charge(normal_load);
        solve_potential_charge(model, disc, a, pressure.centre, free, &zero)
    } else {
        UnboundedSeries::default()
    };
    let state = ContactState {
        normal_load,
        tangential_load: 0.0,
        charge,
        potential,
        half_width: a,
        centre: pressure.centre,
        pressure: pressure.pressure,
        pressure_kinks: Kinks::default(),
        split,
        potential_charge,
        charge_kinks: Kinks::default(),
        traction: Traction {
            friction: 0.0,
            left_sign: 0.0,
            right_sign: 0.0,
            stick: None,
        },
        shape_table: None,
    };
    if !(state.half_width.is_finite() && state.centre.is_finite()) {
        return Err(SolveFailure::NonFinite {
            field: "contact half-width or centre",
        });
    }
    if state
        .pressure
        .beta
        .iter()
        .chain(&state.potential_charge.gamma)
        .any(|v| !v.is_finite())
    {
        return Err(SolveFailure::NonFinite {
            field: "pressure or charge",
        });
    }
    Ok(state)
}
