//! The cost of a run's steps by blocks of its phases, in memory: whether the cost of a step
//! grows with the length of the history (docs/performance.md, "cost of a step flat over a
//! long history"). Each step's time is the wall time since the step before (its solve, its
//! increments and the analyses of the run), so blocks compare like with like; the normal
//! loading and the analyses at the end are left out. Nothing is written.
//!
//! ```sh
//! cargo run --release --example step_times -- benches/scenarios/random_variable_amplitude_1000.json 100
//! ```

use std::path::Path;
use std::time::Instant;

use fretsim::history::{Observer, SolverKind, StateView, StepRecord};

/// Each step's phase, wall time since the step before (s), and whether the general solver
/// took it.
struct Clock {
    last: Instant,
    steps: Vec<(usize, f64, bool)>,
}

impl Observer for Clock {
    fn on_step(&mut self, record: &StepRecord, _state: StateView<'_>) {
        let now = Instant::now();
        let general = record.solver == SolverKind::General;
        self.steps
            .push((record.phase, (now - self.last).as_secs_f64(), general));
        self.last = now;
    }
}

fn main() -> Result<(), fretsim::Error> {
    let mut args = std::env::args().skip(1);
    let path = args.next().expect("a scenario file");
    let block: usize = args
        .next()
        .map_or(100, |b| b.parse().expect("phases a block"));
    let scenario = fretsim::load(Path::new(&path))?;
    let mut clock = Clock {
        last: Instant::now(),
        steps: Vec::new(),
    };
    let start = Instant::now();
    let solution = fretsim::solve(&scenario, &mut clock)?;
    if let Some(failure) = &solution.failure {
        eprintln!("stopped: {failure:?}");
    }
    println!(
        "{}: {} steps in {:.2} s",
        scenario.name,
        clock.steps.len(),
        start.elapsed().as_secs_f64()
    );
    let last_phase = clock.steps.iter().map(|s| s.0).max().unwrap_or(0);
    let mut first = None;
    for lo in (1..=last_phase).step_by(block) {
        let hi = lo + block - 1;
        let steps: Vec<_> = (clock.steps.iter())
            .filter(|s| (lo..=hi).contains(&s.0))
            .collect();
        let time: f64 = steps.iter().map(|s| s.1).sum();
        let general = steps.iter().filter(|s| s.2).count();
        let ratio = time / *first.get_or_insert(time);
        println!(
            "phases {lo:5}–{hi:5}: {:5} steps ({general:5} general) {time:8.3} s, {:5.2} ms a \
             step, {ratio:.2} × the first block",
            steps.len(),
            1e3 * time / steps.len().max(1) as f64
        );
    }
    Ok(())
}
