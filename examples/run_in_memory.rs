//! Run a scenario with the library, in memory, and read its results: the normal-loading
//! state, the stick zone at each turning point of Q (and which solver took the step), the
//! friction work of each cycle and the verdict. Nothing is written.
//!
//! ```sh
//! cargo run --release --example run_in_memory                        # the built-in baseline
//! cargo run --release --example run_in_memory -- scenarios/figure3_history.json
//! ```

use std::path::Path;

use fretsim::history::NoObserver;

fn main() -> Result<(), fretsim::Error> {
    let scenario = match std::env::args().nth(1) {
        Some(path) => fretsim::load(Path::new(&path))?,
        None => fretsim::default_scenario(),
    };
    let solution = fretsim::solve(&scenario, &mut NoObserver)?;
    let n = &solution.summary.normal_loading;
    let a = n.half_width;
    println!(
        "{}: a = {a:.6e} m, b/a = {:.6}, p0 = {:.4e} Pa",
        scenario.name, n.stick_ratio, n.peak_pressure
    );
    let Some(history) = &solution.summary.history else {
        return Ok(());
    };
    println!("turning points (stick zone in units of a):");
    for r in &history.turning_points {
        println!(
            "  step {:4}  Q = {:9.3} N/m  stick [{:+.4}, {:+.4}]  {} zones  ({})",
            r.step,
            r.q,
            r.stick_lo / a,
            r.stick_hi / a,
            r.zones.stick + r.zones.slip,
            r.solver.word()
        );
    }
    for c in &solution.cycles {
        println!(
            "cycle {}: friction work {:.6e} J/m, loop area {:.6e} J/m",
            c.cycle, c.friction_work, c.loop_area
        );
    }
    println!("verdict: {:?}", history.verdict);
    if let Some(failure) = &solution.failure {
        println!("stopped: {failure}");
    }
    Ok(())
}
