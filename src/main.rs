//! The `fretsim` command: parse arguments, call the library, map errors to exit codes
//! (0 success, 1 the solver failed on a valid scenario, 2 bad input or usage).

use std::path::PathBuf;
use std::process::ExitCode;

use clap::Parser;
use fretsim::cli::{Cli, Command};
use fretsim::error::Error;
use fretsim::{app, material, scenario};

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
            let result = app::run(&sc, &out)?;
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
        } => {
            let sc = scenario::load(&path)?;
            let text = std::fs::read_to_string(&path).map_err(|source| Error::ReadScenario {
                path: path.clone(),
                source,
            })?;
            let bytes = app::sweep(&text, &path, &vary, shard)?;
            let out =
                out.unwrap_or_else(|| PathBuf::from("output").join(format!("{}-sweep", sc.name)));
            let name = match shard {
                Some(s) => format!("sweep-{}-of-{}.csv", s.index, s.count),
                None => "sweep.csv".to_string(),
            };
            fretsim::output::write_atomic(&out.join(&name), &bytes)?;
            println!("{} -> {}", path.display(), out.join(name).display());
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
