//! The `fretsim` command: parse arguments, call the library, map errors to exit codes
//! (0 success, 1 the solver failed on a valid scenario, 2 bad input or usage).

use std::path::PathBuf;
use std::process::ExitCode;

use clap::Parser;
use fretsim::cli::{Cli, Command};
use fretsim::error::Error;
use fretsim::{app, material, scenario};

/// mimalloc instead of the system allocator: the solver makes many small allocations per step
/// (the per-evaluation point lists, maps and batches). Built without transparent huge pages
/// (the crate's `no_thp` feature) to keep the peak memory small. The library itself sets no
/// allocator; the dependency is the default feature `mimalloc`.
#[cfg(feature = "mimalloc")]
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

fn main() -> ExitCode {
    let cli = Cli::parse();
    match dispatch(cli.command) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("fretsim: error: {e}");
            ExitCode::from(e.exit_code())
        }
    }
}

/// Progress bar over the load steps (hidden with --quiet or when stderr is not a terminal).
struct Progress(Option<indicatif::ProgressBar>);

impl Progress {
    fn new(total: u64, quiet: bool) -> Self {
        use std::io::IsTerminal;
        if quiet || total == 0 || !std::io::stderr().is_terminal() {
            return Self(None);
        }
        let bar = indicatif::ProgressBar::new(total);
        bar.set_style(
            indicatif::ProgressStyle::with_template("{bar:40} {pos}/{len} {msg}")
                .expect("valid template"),
        );
        Self(Some(bar))
    }

    fn finish(&self) {
        if let Some(b) = &self.0 {
            b.finish_and_clear();
        }
    }
}

impl fretsim::history::Observer for Progress {
    fn on_step(
        &mut self,
        record: &fretsim::history::StepRecord,
        _: &fretsim::contact::ContactState,
    ) {
        if let (Some(b), true) = (&self.0, record.step > 0) {
            b.set_position(record.step as u64);
            b.set_message(format!("steps, Q = {:.1} N/m", record.q));
        }
    }
}

fn dispatch(command: Command) -> Result<(), Error> {
    match command {
        Command::Run {
            scenario: path,
            out,
            quiet,
        } => {
            let sc = match &path {
                Some(p) => scenario::load(p)?,
                None => scenario::default_scenario(),
            };
            let out = out.unwrap_or_else(|| PathBuf::from("output").join(&sc.name));
            let total = sc.history.as_ref().map_or(0, |h| h.steps().len() as u64);
            let mut progress = Progress::new(total, quiet);
            let result = app::run_with(&sc, &out, &mut progress);
            progress.finish();
            let result = result?;
            if !quiet {
                let n = &result.summary.normal_loading;
                println!(
                    "{}: a = {:.6e} m, b/a = {:.6}, C = {:.6e} 1/m, p0 = {:.6e} Pa -> {}",
                    sc.name,
                    n.half_width,
                    n.stick_ratio,
                    n.strain_slope,
                    n.peak_pressure,
                    result.out_dir.display()
                );
                for w in &result.summary.warnings {
                    eprintln!("fretsim: warning: {w}");
                }
            }
            Ok(())
        }
        Command::Sweep {
            scenario: path,
            vary,
            out,
            shard,
            runs,
            quiet,
        } => {
            let sc = scenario::load(&path)?;
            let text = std::fs::read_to_string(&path).map_err(|source| Error::ReadScenario {
                path: path.clone(),
                source,
            })?;
            let out =
                out.unwrap_or_else(|| PathBuf::from("output").join(format!("{}-sweep", sc.name)));
            let total = vary.iter().map(|v| v.values.len()).product::<usize>();
            let variants = (0..total)
                .filter(|i| shard.is_none_or(|s| i % s.count == s.index - 1))
                .count();
            let progress = Progress::new(variants as u64, quiet);
            let bar = progress.0.clone();
            if let Some(b) = &bar {
                b.set_message("variants");
            }
            let done = std::sync::atomic::AtomicU64::new(0);
            let on_variant = move || {
                let n = done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
                if let Some(b) = &bar {
                    b.set_position(n);
                }
            };
            let options = app::SweepOptions { shard, runs };
            let result = app::sweep(&text, &path, &vary, options, &out, &on_variant);
            progress.finish();
            let result = result?;
            if !quiet {
                println!(
                    "{}: {} variant(s), {} failed -> {}",
                    path.display(),
                    result.variants,
                    result.failed,
                    result.csv.display()
                );
            }
            Ok(())
        }
        Command::Check { scenario: path } => {
            let sc = scenario::load(&path)?;
            println!("{}: valid ({})", path.display(), sc.name);
            Ok(())
        }
        Command::Materials { name, json } => {
            let list: Vec<_> = material::presets()
                .into_iter()
                .filter(|p| {
                    name.as_deref()
                        .is_none_or(|n| material::preset(n).is_some_and(|q| q.name == p.name))
                })
                .collect();
            if list.is_empty() {
                return Err(Error::InvalidScenario {
                    path: "<command line>".into(),
                    issues: vec![fretsim::error::Issue::new(
                        "NAME",
                        format!("\"{}\" is not a preset", name.unwrap_or_default()),
                    )],
                });
            }
            let rows: Vec<_> = list
                .iter()
                .map(|p| {
                    serde_json::json!({
                        "name": p.name, "source": p.source, "material": p.material,
                        "derived": app::derived(&fretsim::contact::ContactModel::new(p.material, 1.0, 0.0, fretsim::contact::Electrode::None), 1.0),
                    })
                })
                .collect();
            if json {
                println!(
                    "{}",
                    serde_json::to_string_pretty(&rows).expect("serialisable")
                );
            } else {
                for p in &list {
                    println!("{:<10} {}", p.name, p.source);
                    println!("           {:?}", p.material);
                }
            }
            Ok(())
        }
    }
}
