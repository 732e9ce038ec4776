//! A seeded mutation fuzz of the scenario files (issue 35): every file in `scenarios/` is
//! mutated — numbers replaced by extreme values, fields deleted, duplicated or retyped, arrays
//! emptied, the text truncated or followed by more text — and each case must be answered with
//! a result, never a panic or an abort. In-process through the library's parse and validate
//! (and the normal solve of the cases that validate), then a smaller sample through the
//! command (`check`, and `run` into a temporary folder), whose exit code must be 0, 1 or 2,
//! with nothing written on exit 2.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

use fretsim::error::Error;
use serde_json::Value;

/// The PRNG's seed: the cases are the same on every run.
const SEED: u64 = 0x35_f0_22_ed;
/// Mutated cases per scenario file, in-process.
const CASES_PER_FILE: usize = 300;

/// A longer campaign by hand: `FRETSIM_FUZZ_CASES` (cases per file) and `FRETSIM_FUZZ_SEED`.
fn campaign() -> (u64, usize) {
    let var = |name: &str| std::env::var(name).ok().and_then(|v| v.parse().ok());
    (
        var("FRETSIM_FUZZ_SEED").unwrap_or(SEED),
        var("FRETSIM_FUZZ_CASES").map_or(CASES_PER_FILE, |n: u64| n as usize),
    )
}
/// Cases through the command, spread over the files.
const COMMAND_CASES: usize = 160;
/// `run` only the valid cases this short (load steps) and this small (M), to stay fast.
const RUN_MAX_STEPS: usize = 400;
const RUN_MAX_M: usize = 128;

/// SplitMix64 (Steele, Lea & Flood 2014): a tiny PRNG with a fixed seed.
struct SplitMix(u64);

impl SplitMix {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// Uniform in `0..n` (n > 0).
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }

    fn pick<'a, T>(&mut self, items: &'a [T]) -> &'a T {
        &items[self.below(items.len())]
    }
}

/// Numbers that break naive code: zero, signs, the ends of f64, huge integers.
const EXTREME_NUMBERS: &[&str] = &[
    "0",
    "-1",
    "-0.0",
    "1e-300",
    "-1e-300",
    "1e300",
    "-1e300",
    "1.7976931348623157e308",
    "5e-324",
    "1000000000000000000",
    "18446744073709551615",
    "-9223372036854775808",
    "4294967296",
    "2.5",
    "1e20",
    "3221225472",
    "2.56e-90",
    "1.27e301",
];

/// Values of the wrong type (and strings that look like numbers).
const OTHER_VALUES: &[&str] = &[
    "\"NaN\"",
    "\"inf\"",
    "\"-Infinity\"",
    "\"\"",
    "\"1e3\"",
    "null",
    "true",
    "[]",
    "{}",
    "[1e300, -1e300]",
    "\"../../x\"",
];

/// Trailing or inserted junk.
const JUNK: &[&str] = &[
    "}",
    "{}",
    "x",
    "\n{\"a\": 1}",
    ",",
    "]",
    "\u{0}",
    "NaN",
    "//",
];

fn scenario_files() -> Vec<(PathBuf, String)> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .expect("scenarios/")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "json"))
        .collect();
    files.sort();
    files
        .into_iter()
        .map(|p| {
            let text = std::fs::read_to_string(&p).expect("scenario file");
            (p, text)
        })
        .collect()
}

/// JSON pointers of every node (objects' fields, arrays' elements) below the root.
fn pointers(v: &Value, at: String, out: &mut Vec<String>) {
    match v {
        Value::Object(m) => {
            for (k, x) in m {
                let p = format!("{at}/{k}");
                out.push(p.clone());
                pointers(x, p, out);
            }
        }
        Value::Array(a) => {
            for (i, x) in a.iter().enumerate() {
                let p = format!("{at}/{i}");
                out.push(p.clone());
                pointers(x, p, out);
            }
        }
        _ => {}
    }
}

/// The parent pointer and last key of `pointer`.
fn split(pointer: &str) -> (&str, &str) {
    pointer.rsplit_once('/').expect("pointer below the root")
}

/// Fields the schema knows but the files often leave out, to be added with odd values.
const OPTIONAL_FIELDS: &[(&str, &str)] = &[
    ("", "name"),
    ("", "reference_distance"),
    ("/numerics", "collocation_points"),
    ("/numerics", "cycle_tolerance"),
    ("/tangential_history", "repeats"),
    ("/tangential_history", "steps_per_segment"),
    ("/tangential_history", "max_step"),
    ("/output", "snapshots"),
    ("/output", "field_points"),
];

/// Replace the node at `pointer` by the JSON text `raw` (spliced into the serialised text, so
/// that numbers beyond f64 and u64 keep their spelling).
fn replace_text(v: &Value, pointer: &str, raw: &str) -> String {
    const MARK: &str = "\"@@fuzz@@\"";
    let mut v = v.clone();
    let Some(node) = v.pointer_mut(pointer) else {
        // The parent was not an object (an earlier mutation retyped it).
        return v.to_string();
    };
    *node = Value::String("@@fuzz@@".into());
    serde_json::to_string_pretty(&v)
        .expect("serialises")
        .replacen(MARK, raw, 1)
}

/// One structural mutation of the scenario `v`, as text.
fn mutate_value(rng: &mut SplitMix, v: &Value) -> String {
    let mut all = Vec::new();
    pointers(v, String::new(), &mut all);
    let numbers: Vec<&String> = all
        .iter()
        .filter(|p| v.pointer(p).is_some_and(Value::is_number))
        .collect();
    let target = rng.pick(&all).clone();
    match rng.below(12) {
        0..=4 => {
            let number = rng.pick(&numbers).to_string();
            replace_text(v, &number, rng.pick::<&str>(EXTREME_NUMBERS))
        }
        5 => replace_text(v, &target, rng.pick::<&str>(EXTREME_NUMBERS)),
        6 => replace_text(v, &target, rng.pick::<&str>(OTHER_VALUES)),
        7 => {
            // Delete the node.
            let mut v = v.clone();
            let (parent, key) = split(&target);
            match v.pointer_mut(parent).expect("parent") {
                Value::Object(m) => {
                    m.remove(key);
                }
                Value::Array(a) => {
                    a.remove(key.parse::<usize>().expect("index"));
                }
                _ => unreachable!("parents are containers"),
            }
            v.to_string()
        }
        8 => {
            // Duplicate the node: a repeated key in an object, a repeated element in an array.
            let mut v = v.clone();
            let (parent, key) = split(&target);
            let node = v.pointer(&target).expect("node").clone();
            match v.pointer_mut(parent).expect("parent") {
                Value::Array(a) => {
                    let n = 1 + rng.below(3);
                    for _ in 0..n {
                        a.push(node.clone());
                    }
                    v.to_string()
                }
                _ => {
                    let text = serde_json::to_string(&node).expect("serialises");
                    let whole = v.to_string();
                    let needle = format!("\"{key}\":");
                    whole.replacen(&needle, &format!("\"{key}\":{text},\"{key}\":"), 1)
                }
            }
        }
        9 => {
            // An odd value in an optional field (added when absent).
            let (parent, key) = *rng.pick(OPTIONAL_FIELDS);
            let mut v = v.clone();
            if v.pointer(parent).is_none() {
                v.as_object_mut()
                    .expect("object")
                    .insert(parent.trim_start_matches('/').into(), serde_json::json!({}));
            }
            if let Some(Value::Object(m)) = v.pointer_mut(parent) {
                m.insert(key.into(), Value::Null);
            }
            let value = if rng.below(2) == 0 {
                rng.pick(EXTREME_NUMBERS)
            } else {
                rng.pick(OTHER_VALUES)
            };
            replace_text(&v, &format!("{parent}/{key}"), value)
        }
        10 if rng.below(4) == 0 => {
            // An unknown field.
            let mut v = v.clone();
            let (parent, _) = split(&target);
            if let Some(Value::Object(m)) = v.pointer_mut(parent) {
                m.insert("fuzz_field".into(), serde_json::json!(1));
            }
            v.to_string()
        }
        10 => {
            // Empty a container or turn a scalar into an array of itself.
            let mut v = v.clone();
            let node = v.pointer_mut(&target).expect("node");
            let emptied = match &*node {
                Value::Array(_) => Value::Array(Vec::new()),
                Value::Object(_) => serde_json::json!({}),
                other => Value::Array(vec![other.clone()]),
            };
            *node = emptied;
            v.to_string()
        }
        _ => {
            // A long history: many snapshots, or a big repeat count.
            let mut v = v.clone();
            let n = [10_001usize, 50_000, 3][rng.below(3)];
            let times: Vec<f64> = (0..n).map(|i| i as f64 * 1e-6).collect();
            let out = v
                .as_object_mut()
                .expect("object")
                .entry("output")
                .or_insert_with(|| serde_json::json!({}));
            if let Some(m) = out.as_object_mut() {
                m.insert("snapshots".into(), serde_json::json!(times));
            }
            v.to_string()
        }
    }
}

/// One text mutation: truncate, append, insert or delete.
fn mutate_text(rng: &mut SplitMix, text: &str) -> String {
    let cut = |at: usize| {
        let mut at = at.min(text.len());
        while !text.is_char_boundary(at) {
            at -= 1;
        }
        at
    };
    match rng.below(4) {
        0 => text[..cut(rng.below(text.len()))].to_string(),
        1 => format!("{text}{}", rng.pick(JUNK)),
        2 => {
            let at = cut(rng.below(text.len()));
            format!("{}{}{}", &text[..at], rng.pick(JUNK), &text[at..])
        }
        _ => {
            let a = cut(rng.below(text.len()));
            let b = cut(a + 1 + rng.below(8));
            format!("{}{}", &text[..a], &text[b..])
        }
    }
}

/// A mutated case of a file: one or two mutations of the structure, sometimes
/// followed by a mutation of the text.
fn case(rng: &mut SplitMix, text: &str) -> String {
    let mut v: Value = serde_json::from_str(text).expect("scenario files are JSON");
    let mut out = v.to_string();
    for _ in 0..1 + rng.below(2) {
        out = mutate_value(rng, &v);
        match serde_json::from_str(&out) {
            Ok(next) => v = next,
            Err(_) => break,
        }
    }
    if rng.below(8) == 0 {
        out = mutate_text(rng, &out);
    }
    out
}

/// Parse and validate `text` (what `scenario::load` does after reading the file), then
/// solve the normal loading of a valid case. Panics are the failures.
fn answer(text: &str) -> Result<fretsim::scenario::Scenario, Error> {
    let raw = fretsim::scenario::parse(text, Path::new("fuzz.json"))?;
    let sc = fretsim::scenario::validate(raw).map_err(|issues| Error::InvalidScenario {
        path: "fuzz.json".into(),
        issues,
    })?;
    if sc.collocation_points <= RUN_MAX_M {
        let disc = fretsim::contact::pressure::Discretisation::new(sc.collocation_points);
        let _ = fretsim::contact::normal::solve_normal(
            &sc.model,
            &disc,
            sc.normal_load,
            fretsim::contact::normal::NormalOptions::default(),
        );
    }
    Ok(sc)
}

fn steps_of(sc: &fretsim::scenario::Scenario) -> usize {
    sc.history.as_ref().map_or(0, |h| h.steps().len())
}

#[test]
fn mutated_scenarios_never_panic_in_the_library() {
    let started = Instant::now();
    let (seed, cases) = campaign();
    let mut rng = SplitMix(seed);
    let (mut valid, mut invalid, mut unparsed) = (0, 0, 0);
    for (path, text) in scenario_files() {
        for k in 0..cases {
            let mutated = case(&mut rng, &text);
            let outcome = std::panic::catch_unwind(|| answer(&mutated));
            let Ok(result) = outcome else {
                panic!("case {k} of {} panicked; input:\n{mutated}", path.display());
            };
            match result {
                Ok(sc) => {
                    valid += 1;
                    let steps = steps_of(&sc);
                    assert!(steps <= fretsim::scenario::MAX_LOAD_STEPS, "{steps} steps");
                }
                Err(Error::InvalidScenario { issues, .. }) => {
                    invalid += 1;
                    assert!(!issues.is_empty());
                    for issue in issues {
                        assert!(
                            !issue.path.is_empty() && issue.message.contains("invalid"),
                            "case {k} of {}: an issue must name a path and a rule: {issue}",
                            path.display()
                        );
                    }
                }
                Err(Error::ParseScenario { line, .. }) => {
                    unparsed += 1;
                    assert!(line >= 1);
                }
                Err(other) => panic!("case {k} of {}: unexpected {other}", path.display()),
            }
        }
    }
    eprintln!(
        "fuzz (seed {seed:#x}): {} cases in-process, {valid} valid, {invalid} invalid, {unparsed} unparsed, {:.2} s",
        valid + invalid + unparsed,
        started.elapsed().as_secs_f64()
    );
    assert!(valid > 0 && invalid > 0 && unparsed > 0);
}

/// Everything below `dir`, as relative paths (empty when it does not exist).
fn written(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        let Ok(entries) = std::fs::read_dir(&d) else {
            continue;
        };
        for e in entries.flatten() {
            let p = e.path();
            if p.is_dir() {
                stack.push(p.clone());
            }
            out.push(p);
        }
    }
    out
}

fn exit_code(status: std::process::ExitStatus, what: &str, input: &str) -> i32 {
    let Some(code) = status.code() else {
        panic!("{what} ended by a signal ({status}); input:\n{input}");
    };
    assert!(
        matches!(code, 0..=2),
        "{what} exited with {code} (not 0, 1 or 2); input:\n{input}"
    );
    code
}

#[test]
fn mutated_scenarios_exit_0_1_or_2_from_the_command() {
    let started = Instant::now();
    let files = scenario_files();
    let mut rng = SplitMix(SEED ^ 0xc0ffee);
    let tmp = tempfile::tempdir().expect("temp dir");
    let (mut runs, mut codes) = (0, [0usize; 3]);
    for k in 0..COMMAND_CASES {
        let (_, text) = &files[k % files.len()];
        let mutated = case(&mut rng, text);
        let file = tmp.path().join(format!("case_{k}.json"));
        std::fs::write(&file, &mutated).expect("write case");
        let check = Command::new(env!("CARGO_BIN_EXE_fretsim"))
            .arg("check")
            .arg(&file)
            .output()
            .expect("fretsim runs");
        let code = exit_code(check.status, "check", &mutated);
        codes[code as usize] += 1;
        if code == 0 {
            let sc = fretsim::scenario::load(&file).expect("check said valid");
            if steps_of(&sc) > RUN_MAX_STEPS || sc.collocation_points > RUN_MAX_M {
                continue;
            }
        }
        let out = tmp.path().join(format!("out_{k}"));
        let run = Command::new(env!("CARGO_BIN_EXE_fretsim"))
            .arg("run")
            .arg(&file)
            .arg("--out")
            .arg(&out)
            .arg("--quiet")
            .output()
            .expect("fretsim runs");
        runs += 1;
        let code = exit_code(run.status, "run", &mutated);
        if code == 2 {
            assert!(
                written(&out).is_empty(),
                "run exited 2 but wrote {:?}; input:\n{mutated}",
                written(&out)
            );
        }
    }
    eprintln!(
        "fuzz (seed {:#x}): {COMMAND_CASES} cases through `check` (exit 0/1/2: {codes:?}), {runs} through `run`, {:.2} s",
        SEED ^ 0xc0ffee,
        started.elapsed().as_secs_f64()
    );
    assert!(codes[0] > 0 && codes[2] > 0);
}

/// The inputs of the fault campaign (issue 35): each was an abort (134) or a panic (101);
/// each is now exit 2 from `check` and `run`, with the field's path on stderr and nothing
/// written.
#[test]
fn issue_35_inputs_exit_2_name_the_field_and_write_nothing() {
    let base: Value = serde_json::from_str(fretsim::scenario::DEFAULT_SCENARIO).expect("JSON");
    let with = |pointer: &str, raw: &str| replace_text(&base, pointer, raw);
    let piezo = |name: &str, value: &str| {
        let mut v = base.clone();
        v["material"] = serde_json::json!({"kind": "piezoelectric", "c11": 139e9, "c13": 74.3e9,
            "c33": 115e9, "c44": 25.6e9, "e31": -5.2, "e33": 15.1, "e15": 12.7,
            "eps11": 64.61e-10, "eps33": 56.2e-10});
        replace_text(&v, &format!("/material/{name}"), value)
    };
    let snapshots: Vec<String> = (0..=10_000)
        .map(|i| format!("{}", i as f64 * 1e-3))
        .collect();
    let cases: Vec<(String, &str)> = vec![
        (
            with("/tangential_history/repeats", "1000000000000000000"),
            "`tangential_history`",
        ),
        (
            with("/tangential_history/points/1/1", "0.5").replacen(
                "\"repeats\": 3",
                "\"repeats\": 3, \"steps_per_segment\": 1000000000000000",
                1,
            ),
            "`tangential_history`",
        ),
        (
            with(
                "/tangential_history/unit",
                "\"fraction_of_limit\", \"max_step\": 1e-300",
            ),
            "`tangential_history`",
        ),
        (piezo("c44", "2.56e-90"), "`material.c44`"),
        (piezo("e15", "1.27e301"), "`material.e15`"),
        (piezo("eps11", "1e308"), "`material.eps11`"),
        (
            format!("{}\n{{}}", fretsim::scenario::DEFAULT_SCENARIO),
            "line 14, column 1",
        ),
        (with("/name", "\"../escape\""), "`name`"),
        (
            with(
                "/friction",
                "0.3, \"numerics\": {\"collocation_points\": 4096}",
            ),
            "`numerics.collocation_points`",
        ),
        (
            with("/friction", "0.3, \"output\": {\"field_points\": 4000000}"),
            "`output.field_points`",
        ),
        (
            with(
                "/friction",
                &format!(
                    "0.3, \"output\": {{\"snapshots\": [{}]}}",
                    snapshots.join(",")
                ),
            ),
            "`output.snapshots`",
        ),
    ];
    let tmp = tempfile::tempdir().expect("temp dir");
    for (k, (text, named)) in cases.iter().enumerate() {
        let file = tmp.path().join(format!("bad_{k}.json"));
        std::fs::write(&file, text).expect("write case");
        let out = tmp.path().join(format!("out_{k}"));
        for args in [vec!["check"], vec!["run", "--quiet", "--out"]] {
            let mut command = Command::new(env!("CARGO_BIN_EXE_fretsim"));
            command.args(&args[..1]).arg(&file).args(&args[1..]);
            if args.len() > 1 {
                command.arg(&out);
            }
            let done = command.output().expect("fretsim runs");
            let stderr = String::from_utf8_lossy(&done.stderr);
            assert_eq!(done.status.code(), Some(2), "case {k} {args:?}: {stderr}");
            assert!(
                stderr.contains(named),
                "case {k}: {stderr} should name {named}"
            );
        }
        assert!(
            written(&out).is_empty(),
            "case {k} wrote {:?}",
            written(&out)
        );
    }
}
