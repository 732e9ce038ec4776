//! The bench table from criterion's saved results: the median time per iteration of every
//! benchmark of `cargo bench --bench core`, one row per group and one column per M, with the
//! exponent of a least-squares fit `time ∝ M^k` over M = 64 … 512.
//!
//! ```sh
//! cargo bench --bench core
//! cargo run --release --example bench_table              # medians
//! cargo run --release --example bench_table -- --best    # fastest sample of each bench
//! ```
//!
//! Criterion's console line reports the slope of its linear sampling (time against iterations
//! per sample), which bursts of host slowness in a few samples pull up; the median over the
//! samples (`estimates.json`, `median.point_estimate`) is what the performance targets are
//! stated in. `--best` gives the fastest sample's time per iteration (`sample.json`), the
//! floor least disturbed by a busy host. Results are read
//! from `target/criterion` (or `$CARGO_TARGET_DIR/criterion`, or the folder given as the last
//! argument); nothing is written.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde::Deserialize;

/// The part of criterion's `benchmark.json` that names a bench.
#[derive(Deserialize)]
struct BenchmarkId {
    group_id: String,
    value_str: Option<String>,
}

/// The part of criterion's `estimates.json` that is read.
#[derive(Deserialize)]
struct Estimates {
    median: Estimate,
}

#[derive(Deserialize)]
struct Estimate {
    /// Nanoseconds per iteration.
    point_estimate: f64,
}

/// Criterion's `sample.json`: iterations and total nanoseconds of each sample.
#[derive(Deserialize)]
struct Sample {
    iters: Vec<f64>,
    times: Vec<f64>,
}

/// Which time of a bench the table shows.
#[derive(Clone, Copy)]
enum Statistic {
    Median,
    Best,
}

/// The exponent k of the least-squares fit `ln t = k ln M + b` over the points with
/// `lo ≤ M ≤ hi`; `None` with fewer than two such points.
fn fitted_exponent(points: &[(f64, f64)], lo: f64, hi: f64) -> Option<f64> {
    let logs: Vec<(f64, f64)> = points
        .iter()
        .filter(|(m, t)| (lo..=hi).contains(m) && *t > 0.0)
        .map(|(m, t)| (m.ln(), t.ln()))
        .collect();
    if logs.len() < 2 {
        return None;
    }
    let n = logs.len() as f64;
    let (mx, my) = logs
        .iter()
        .fold((0.0, 0.0), |(a, b), (x, y)| (a + x / n, b + y / n));
    let sxy: f64 = logs.iter().map(|(x, y)| (x - mx) * (y - my)).sum();
    let sxx: f64 = logs.iter().map(|(x, _)| (x - mx) * (x - mx)).sum();
    Some(sxy / sxx)
}

/// A time in nanoseconds to three significant digits in ns, µs, ms or s.
fn format_time(ns: f64) -> String {
    let (value, unit) = if ns < 1e3 {
        (ns, "ns")
    } else if ns < 1e6 {
        (ns / 1e3, "µs")
    } else if ns < 1e9 {
        (ns / 1e6, "ms")
    } else {
        (ns / 1e9, "s")
    };
    let decimals = if value >= 100.0 {
        0
    } else if value >= 10.0 {
        1
    } else {
        2
    };
    format!("{value:.decimals$} {unit}")
}

/// The time per iteration of the fastest sample.
fn best_of(sample: &Sample) -> Option<f64> {
    sample
        .iters
        .iter()
        .zip(&sample.times)
        .map(|(n, t)| t / n)
        .min_by(f64::total_cmp)
}

fn read_json<T: serde::de::DeserializeOwned>(path: &Path) -> Result<T, String> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    serde_json::from_str(&text).map_err(|e| format!("{}: {e}", path.display()))
}

/// Every bench's `(group, M, time)` under `root` (criterion's folder).
fn collect(root: &Path, statistic: Statistic) -> Result<Vec<(String, f64, f64)>, String> {
    let mut found = Vec::new();
    let groups = std::fs::read_dir(root).map_err(|e| format!("{}: {e}", root.display()))?;
    for group in groups.flatten() {
        let Ok(entries) = std::fs::read_dir(group.path()) else {
            continue;
        };
        for entry in entries.flatten() {
            let new = entry.path().join("new");
            let id = new.join("benchmark.json");
            if !id.is_file() {
                continue;
            }
            let id: BenchmarkId = read_json(&id)?;
            let Some(m) = id.value_str.as_deref().and_then(|v| v.parse::<f64>().ok()) else {
                continue;
            };
            let time = match statistic {
                Statistic::Median => {
                    read_json::<Estimates>(&new.join("estimates.json"))?
                        .median
                        .point_estimate
                }
                Statistic::Best => {
                    let sample: Sample = read_json(&new.join("sample.json"))?;
                    best_of(&sample).ok_or_else(|| format!("{}: no samples", new.display()))?
                }
            };
            found.push((id.group_id, m, time));
        }
    }
    Ok(found)
}

/// The markdown table of `results`, groups in alphabetical order.
fn table(results: &[(String, f64, f64)], statistic: Statistic) -> String {
    let mut sizes: Vec<f64> = results.iter().map(|r| r.1).collect();
    sizes.sort_by(f64::total_cmp);
    sizes.dedup();
    let mut groups: BTreeMap<&str, Vec<(f64, f64)>> = BTreeMap::new();
    for (g, m, t) in results {
        groups.entry(g).or_default().push((*m, *t));
    }
    let label = match statistic {
        Statistic::Median => "median",
        Statistic::Best => "fastest sample",
    };
    let mut out = format!("| bench ({label}) |");
    for m in &sizes {
        out += &format!(" M = {m} |");
    }
    out += " exponent, M = 64 … 512 |\n|---|";
    out += &"---|".repeat(sizes.len() + 1);
    out.push('\n');
    for (g, points) in &groups {
        out += &format!("| `{g}` |");
        for m in &sizes {
            let cell = points
                .iter()
                .find(|(pm, _)| pm == m)
                .map_or_else(|| "–".to_string(), |(_, t)| format_time(*t));
            out += &format!(" {cell} |");
        }
        let k =
            fitted_exponent(points, 64.0, 512.0).map_or_else(|| "–".into(), |k| format!("{k:.2}"));
        out += &format!(" {k} |\n");
    }
    out
}

fn main() -> std::process::ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let statistic = if args.iter().any(|a| a == "--best") {
        Statistic::Best
    } else {
        Statistic::Median
    };
    let root = args
        .iter()
        .rfind(|a| !a.starts_with("--"))
        .map(PathBuf::from)
        .unwrap_or_else(|| {
            let target =
                std::env::var_os("CARGO_TARGET_DIR").map_or("target".into(), PathBuf::from);
            target.join("criterion")
        });
    match collect(&root, statistic) {
        Ok(results) if results.is_empty() => {
            eprintln!(
                "no bench results under {} (run `cargo bench --bench core` first)",
                root.display()
            );
            std::process::ExitCode::FAILURE
        }
        Ok(results) => {
            print!("{}", table(&results, statistic));
            std::process::ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("error: {e}");
            std::process::ExitCode::FAILURE
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_fit_recovers_a_power_law_over_the_range_only() {
        // t = 3 M^1.7 on 64 … 512, and points outside the range that do not follow it.
        let mut points: Vec<(f64, f64)> = [64.0, 128.0, 256.0, 512.0]
            .iter()
            .map(|&m| (m, 3.0 * f64::powf(m, 1.7)))
            .collect();
        points.push((32.0, 1.0));
        points.push((1024.0, 1.0));
        let k = fitted_exponent(&points, 64.0, 512.0).unwrap();
        assert!((k - 1.7).abs() < 1e-12, "{k}");
        assert!(fitted_exponent(&points[..1], 64.0, 512.0).is_none());
    }

    #[test]
    fn the_fit_is_least_squares() {
        // ln t = 0, ln 2·1, 0 at ln M = 0, 1, 2 (M = 1, e, e²): slope 0 by least squares.
        let e = std::f64::consts::E;
        let points = [(1.0, 1.0), (e, e * e), (e * e, 1.0)];
        assert!(fitted_exponent(&points, 0.0, 10.0).unwrap().abs() < 1e-12);
    }

    #[test]
    fn times_read_in_three_significant_digits() {
        assert_eq!(format_time(512.0), "512 ns");
        assert_eq!(format_time(95_100.0), "95.1 µs");
        assert_eq!(format_time(1_428_903.4), "1.43 ms");
        assert_eq!(format_time(629_000_000.0), "629 ms");
        assert_eq!(format_time(2.5e9), "2.50 s");
    }

    #[test]
    fn the_best_sample_is_the_fastest_per_iteration() {
        let sample = Sample {
            iters: vec![64.0, 128.0, 192.0],
            // 1.5, 1.25 and 1.375 ms per iteration: the largest total is not the slowest.
            times: vec![96e6, 160e6, 264e6],
        };
        let best = best_of(&sample).unwrap();
        assert!((best - 1.25e6).abs() < 1e-6, "{best}");
    }

    #[test]
    fn the_table_has_a_row_per_group_and_a_dash_where_a_size_is_missing() {
        let results = vec![
            ("solve/a".to_string(), 64.0, 1e6),
            ("solve/a".to_string(), 128.0, 4e6),
            ("kernel/b".to_string(), 64.0, 2e3),
        ];
        let t = table(&results, Statistic::Median);
        let lines: Vec<&str> = t.lines().collect();
        assert_eq!(lines.len(), 4);
        assert_eq!(
            lines[0],
            "| bench (median) | M = 64 | M = 128 | exponent, M = 64 … 512 |"
        );
        assert_eq!(lines[2], "| `kernel/b` | 2.00 µs | – | – |");
        assert_eq!(lines[3], "| `solve/a` | 1.00 ms | 4.00 ms | 2.00 |");
    }
}
