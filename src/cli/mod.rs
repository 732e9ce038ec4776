//! The `fretsim` command: parse the arguments (`args`), call the library, map errors to exit
//! codes (0 success, 1 the solver failed on a valid scenario, 2 bad input or usage). The binary
//! (`src/main.rs`) only sets the allocator and calls [`main`].

mod args;

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::Parser;

use crate::error::Error;
use crate::io::{self, folder};
use crate::{material, scenario};
use args::{Cli, Command};

/// The command: parse the process's arguments, run what they ask for, report an error on
/// stderr and return its exit code.
pub fn main() -> ExitCode {
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

impl crate::history::Observer for Progress {
    fn on_step(&mut self, record: &crate::history::StepRecord, _: crate::history::StateView<'_>) {
        if let (Some(b), true) = (&self.0, record.step > 0) {
            b.set_position(record.step as u64);
            b.set_message(format!("steps, Q = {:.1} N/m", record.q));
        }
    }
}

fn dispatch(command: Command) -> Result<(), Error> {
    match command {
        Command::Run {
            scenario,
            out,
            resume,
            quiet,
        } => run(scenario, out, resume, quiet),
        Command::Sweep {
            scenario,
            vary,
            out,
            shard,
            runs,
            quiet,
        } => sweep(
            &scenario,
            &vary,
            out,
            io::SweepOptions { shard, runs },
            quiet,
        ),
        Command::Check { scenario: path } => {
            let sc = scenario::load(&path)?;
            println!("{}: valid ({})", path.display(), sc.name);
            Ok(())
        }
        Command::Materials { name, json } => materials(name, json),
    }
}

/// `fretsim run`: the output folder is claimed before the solve, so that a folder that may
/// not be written is refused before any time is spent. With `--resume DIR`, the checkpoint an
/// interrupted run left in DIR is read (and checked against the scenario) first.
fn run(
    path: Option<PathBuf>,
    out: Option<PathBuf>,
    resume: Option<PathBuf>,
    quiet: bool,
) -> Result<(), Error> {
    let sc = match &path {
        Some(p) => scenario::load(p)?,
        None => scenario::default_scenario(),
    };
    let protected = folder::Protected::new(path.as_deref());
    let (out, folder, resume) = match resume {
        Some(dir) => {
            let (folder, resume) = folder::RunFolder::claim_resuming(&dir, &protected, |s, r| {
                io::checkpoint::read_checkpoint(&sc, s, r, &dir)
            })?;
            match &resume {
                Some(r) => eprintln!(
                    "fretsim: resuming {} after step {} from its checkpoint",
                    dir.display(),
                    r.step
                ),
                None => eprintln!(
                    "fretsim: {} holds no checkpoint of an interrupted run; running from the start",
                    dir.display()
                ),
            }
            (dir, folder, resume)
        }
        None => {
            let out = out.unwrap_or_else(|| PathBuf::from("output").join(&sc.name));
            let folder = folder::RunFolder::claim(&out, &protected)?;
            (out, folder, None)
        }
    };
    let total = sc.history.as_ref().map_or(0, |h| h.steps().len() as u64);
    let mut progress = Progress::new(total, quiet);
    let result = io::run_resumed(&sc, folder, resume, &mut progress).and_then(|mut result| {
        match result.solution.failure.take() {
            None => Ok(result),
            Some(failure) => Err(failure),
        }
    });
    progress.finish();
    let result = match result {
        Ok(result) => result,
        Err(e) => {
            if matches!(e, Error::Solve { .. }) {
                eprintln!(
                    "fretsim: what was solved and failure.json are in {}",
                    out.display()
                );
            }
            return Err(e);
        }
    };
    let n = &result.solution.summary.normal_loading;
    let by = match n.solver {
        crate::history::SolverKind::Spectral => String::new(),
        crate::history::SolverKind::General => format!(
            " (general solver: {} stick and {} slip zones)",
            n.zones.stick, n.zones.slip
        ),
    };
    if sc.normal_load > 0.0 {
        println!(
            "{}: a = {:.6e} m, b/a = {:.6}, C = {:.6e} 1/m, p0 = {:.6e} Pa{by} -> {}",
            sc.name,
            n.half_width,
            n.stick_ratio,
            n.strain_slope,
            n.peak_pressure,
            result.out_dir.display()
        );
    } else {
        println!(
            "{}: from the unloaded punch (normal_load 0), general solver -> {}",
            sc.name,
            result.out_dir.display()
        );
    }
    for w in &result.solution.summary.warnings {
        eprintln!("fretsim: warning: {w}");
    }
    Ok(())
}

/// `fretsim sweep`: exits 1 when any variant failed.
fn sweep(
    path: &Path,
    vary: &[io::Vary],
    out: Option<PathBuf>,
    options: io::SweepOptions,
    quiet: bool,
) -> Result<(), Error> {
    let sc = scenario::load(path)?;
    let text = std::fs::read_to_string(path).map_err(|source| Error::ReadScenario {
        path: path.to_path_buf(),
        source,
    })?;
    let out = out.unwrap_or_else(|| PathBuf::from("output").join(format!("{}-sweep", sc.name)));
    let variants = io::sweep::shard_count(io::sweep::variant_count(vary, path)?, options.shard);
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
    let protected = folder::Protected::new(Some(path));
    let result = io::sweep(&text, path, vary, options, &out, &protected, &on_variant);
    progress.finish();
    let result = result?;
    println!(
        "{}: {} variant(s), {} failed -> {}",
        path.display(),
        result.variants,
        result.failed,
        result.csv.display()
    );
    result.check().map(|_| ())
}

/// `fretsim materials`: a table with units, or JSON with `--json`.
fn materials(name: Option<String>, json: bool) -> Result<(), Error> {
    let list: Vec<_> = material::presets()
        .into_iter()
        .filter(|p| {
            name.as_deref()
                .is_none_or(|n| material::preset(n).is_some_and(|q| q.name == p.name))
        })
        .collect();
    if list.is_empty() {
        let names: Vec<_> = material::presets().iter().map(|p| p.name).collect();
        return Err(Error::InvalidScenario {
            path: "<command line>".into(),
            issues: vec![crate::error::Issue::new(
                "NAME",
                format!(
                    "\"{}\" is not a preset; it must be one of {}",
                    name.unwrap_or_default(),
                    names.join(", ")
                ),
            )],
        });
    }
    if json {
        let rows: Vec<_> = list
            .iter()
            .map(|p| {
                let model = crate::contact::ContactModel::new(
                    p.material,
                    crate::contact::Profile::cylinder(1.0),
                    0.0,
                    crate::contact::Electrode::None,
                );
                serde_json::json!({
                    "name": p.name, "source": p.source, "material": p.material,
                    "derived": io::summary::derived(&model, 1.0),
                })
            })
            .collect();
        println!(
            "{}",
            serde_json::to_string_pretty(&rows).expect("serialisable")
        );
        return Ok(());
    }
    print!("{}", materials_table(&list));
    Ok(())
}

/// The presets as text tables with units: the piezoelectric constants, the elastic ones, and
/// the sources.
fn materials_table(list: &[material::Preset]) -> String {
    use std::fmt::Write;
    let mut out = String::new();
    let piezo: Vec<_> = list
        .iter()
        .filter_map(|p| match p.material {
            material::Material::Piezoelectric(c) => Some((p.name, c)),
            material::Material::Elastic(_) => None,
        })
        .collect();
    if !piezo.is_empty() {
        out.push_str("piezoelectric (poled along z)\n");
        let _ = writeln!(
            out,
            "{:<10} {:>8} {:>8} {:>8} {:>8} {:>8} {:>8} {:>8} {:>9} {:>9}",
            "name", "c11", "c13", "c33", "c44", "e31", "e33", "e15", "eps11", "eps33"
        );
        let _ = writeln!(
            out,
            "{:<10} {:>8} {:>8} {:>8} {:>8} {:>8} {:>8} {:>8} {:>9} {:>9}",
            "", "GPa", "GPa", "GPa", "GPa", "C/m²", "C/m²", "C/m²", "nF/m", "nF/m"
        );
        for (name, c) in &piezo {
            let _ = writeln!(
                out,
                "{name:<10} {:>8.2} {:>8.2} {:>8.2} {:>8.2} {:>8.3} {:>8.3} {:>8.3} {:>9.4} {:>9.4}",
                c.c11 / 1e9,
                c.c13 / 1e9,
                c.c33 / 1e9,
                c.c44 / 1e9,
                c.e31,
                c.e33,
                c.e15,
                c.eps11 / 1e-9,
                c.eps33 / 1e-9
            );
        }
    }
    let elastic: Vec<_> = list
        .iter()
        .filter_map(|p| match p.material {
            material::Material::Elastic(c) => Some((p.name, c)),
            material::Material::Piezoelectric(_) => None,
        })
        .collect();
    if !elastic.is_empty() {
        if !out.is_empty() {
            out.push('\n');
        }
        out.push_str("isotropic elastic\n");
        let _ = writeln!(
            out,
            "{:<10} {:>8} {:>8} {:>8}\n{:<10} {:>8} {:>8} {:>8}",
            "name", "E", "mu", "nu", "", "GPa", "GPa", "-"
        );
        for (name, c) in &elastic {
            let _ = writeln!(
                out,
                "{name:<10} {:>8.2} {:>8.2} {:>8.3}",
                c.youngs_modulus() / 1e9,
                c.shear_modulus / 1e9,
                c.poisson_ratio
            );
        }
    }
    out.push_str("\nsources\n");
    for p in list {
        let _ = writeln!(out, "{:<10} {}", p.name, p.source);
    }
    out
}
