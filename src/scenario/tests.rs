//! Parsing and every validation rule's message.

use super::*;
use crate::material::PiezoConstants;

/// Type errors read in the format's words: no Rust type names, no repeated position.
#[test]
fn parse_messages_show_no_rust_type_names() {
    let base: serde_json::Value = serde_json::from_str(DEFAULT_SCENARIO).unwrap();
    let cases = [
        ("friction", serde_json::json!("x"), "expected a number"),
        ("punch", serde_json::json!(3), "expected an object"),
        (
            "material",
            serde_json::json!("pzt4"),
            "expected an object with a `kind`",
        ),
        (
            "numerics",
            serde_json::json!({"collocation_points": -3}),
            "expected a whole number ≥ 0",
        ),
    ];
    for (field, value, expected) in cases {
        let mut v = base.clone();
        v[field] = value;
        let text = serde_json::to_string_pretty(&v).unwrap();
        let message = match parse(&text, Path::new("s.json")) {
            Err(e) => e.to_string(),
            Ok(_) => panic!("{field}: parsed"),
        };
        assert!(message.contains(expected), "{field}: {message}");
        for rust in ["f64", "usize", "u64", "struct", "enum", "Raw", " at line "] {
            assert!(!message.contains(rust), "{field}: {message}");
        }
    }
}

fn check(text: &str) -> Result<Scenario, Error> {
    let raw = parse(text, Path::new("t.json"))?;
    validate(raw).map_err(|issues| Error::InvalidScenario {
        path: "t.json".into(),
        issues,
    })
}

fn issues(text: &str) -> Vec<Issue> {
    match check(text) {
        Err(Error::InvalidScenario { issues, .. }) => issues,
        other => panic!("expected invalid scenario, got {other:?}"),
    }
}

#[test]
fn default_scenario_is_the_paper_baseline() {
    let s = default_scenario();
    assert_eq!(s.name, "baseline");
    assert!(
        matches!(s.model.electrode, Electrode::ConductingCharge { charge } if (charge - 6e-7).abs() < 1e-20)
    );
}

#[test]
fn unknown_field_is_named_with_line_and_column() {
    let text = "{\n \"frictoin\": 0.3 }";
    match check(text) {
        Err(Error::ParseScenario { message, line, .. }) => {
            assert!(message.contains("frictoin"), "{message}");
            assert_eq!(line, 2);
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn wrong_type_names_the_json_path() {
    let text = DEFAULT_SCENARIO.replace("\"radius\": 0.06", "\"radius\": \"big\"");
    match check(&text) {
        Err(Error::ParseScenario { at, .. }) => assert_eq!(at, "punch.radius"),
        other => panic!("{other:?}"),
    }
}

#[test]
fn every_problem_is_collected() {
    let text = DEFAULT_SCENARIO
        .replace("\"radius\": 0.06", "\"radius\": -0.06")
        .replace("\"friction\": 0.3", "\"friction\": -1")
        .replace("\"normal_load\": 2000.0", "\"normal_load\": 0");
    let paths: Vec<_> = issues(&text).into_iter().map(|i| i.path).collect();
    assert_eq!(
        paths,
        [
            "punch.radius",
            "normal_load",
            "friction",
            "tangential_history"
        ]
    );
    let msg = issues(&text)[0].to_string();
    assert_eq!(
        msg,
        "`punch.radius` = -0.06 m is invalid; it must be finite and > 0"
    );
}

/// The punch's shape: a `radius` or a `profile`, one of them; each profile's rules; the
/// spectral solver alone takes a cylinder only; a flat punch of half-width 0 is the cylinder.
#[test]
fn punch_profile_rules() {
    let with = |punch: &str, solver: &str| {
        DEFAULT_SCENARIO.replace("\"radius\": 0.06", punch).replace(
            "\"friction\": 0.3",
            &format!("\"friction\": 0.3, \"numerics\": {{\"solver\": \"{solver}\"}}"),
        )
    };
    let messages =
        |text: &str| -> Vec<String> { issues(text).iter().map(|i| i.to_string()).collect() };
    let flat = |b: &str| {
        format!(
            "\"profile\": {{\"kind\": \"flat_rounded\", \"flat_half_width\": {b}, \"radius\": 0.06}}"
        )
    };
    let power = |n: &str| {
        format!(
            "\"profile\": {{\"kind\": \"power_law\", \"coefficient\": 10.0, \"exponent\": {n}}}"
        )
    };
    assert_eq!(
        messages(&with(&flat("-0.001"), "auto")),
        ["`punch.profile.flat_half_width` = -0.001 m is invalid; it must be finite and ≥ 0"]
    );
    assert_eq!(
        messages(&with(&power("0.5"), "auto")),
        [
            "`punch.profile.exponent` = 0.5 is invalid; it must lie in [1, 20] (below 1 the profile is not convex and has a cusp at its tip)"
        ]
    );
    assert_eq!(
        messages(&with(&flat("1e-5"), "spectral")),
        [
            "`numerics.solver` = \"spectral\" is invalid with a punch that is not a cylinder; it must be \"auto\" or \"general\" (the spectral solver takes a cylinder only)"
        ]
    );
    assert_eq!(
        messages(&with(&format!("\"radius\": 0.06, {}", power("4")), "auto")),
        [
            "`punch.profile` = a profile beside `punch.radius` is invalid; it must be one or the other"
        ]
    );
    assert_eq!(
        messages(&with("\"kind\": \"x\"", "auto").replace("\"kind\": \"x\", ", "")),
        [
            "`punch` = an object without `radius` or `profile` is invalid; it must give one of them (a cylinder's `radius`, or a `profile`)"
        ]
    );
    let model = |text: &str| {
        validate(parse(text, Path::new("t")).unwrap())
            .unwrap()
            .model
    };
    assert_eq!(
        model(&with(&flat("1e-5"), "auto")).profile,
        Profile::flat_rounded(1e-5, 0.06)
    );
    assert!(model(&with(&flat("0"), "spectral")).profile.is_cylinder());
    assert_eq!(
        model(&with(&power("4"), "general")).profile,
        Profile::power_law(10.0, 4.0)
    );
    let cylinder = "\"profile\": {\"kind\": \"cylinder\", \"radius\": 0.06}";
    assert_eq!(
        model(&with(cylinder, "spectral")).profile,
        Profile::cylinder(0.06)
    );
}

/// A tabulated profile: its rules name the point (`punch.profile.points[i]`) and the rule; a
/// table too short for the contact names the half-width it must reach; a table of a cylinder
/// is refused by the spectral solver like any profile but the cylinder's formula.
#[test]
fn tabulated_profile_rules() {
    let table = |points: &str, solver: &str| {
        DEFAULT_SCENARIO
            .replace(
                "\"radius\": 0.06",
                &format!("\"profile\": {{\"kind\": \"tabulated\", \"points\": {points}}}"),
            )
            .replace(
                "\"friction\": 0.3",
                &format!("\"friction\": 0.3, \"numerics\": {{\"solver\": \"{solver}\"}}"),
            )
    };
    let messages =
        |text: &str| -> Vec<String> { issues(text).iter().map(|i| i.to_string()).collect() };
    assert_eq!(
        messages(&table(
            "[[0, 0], [1e-4, 1e-7], [2e-4, 2e-7], [3e-4, 4e-7]]",
            "auto"
        )),
        [
            "`punch.profile.points[0]` = [0.0, 0.0] is invalid; it is a corner of the profile (a straight run of slope 1.0000e-3 meets another slope there), and the profile must have a continuous slope (round the corner with more points)"
        ]
    );
    let concave = messages(&table(
        "[[0, 0], [1e-4, 1e-7], [2e-4, 4e-7], [3e-4, 5e-7]]",
        "auto",
    ));
    assert_eq!(concave.len(), 1);
    assert!(
        concave[0].starts_with(
            "`punch.profile.points[2]` = [0.0002, 4e-7] is invalid; it makes the profile concave"
        ),
        "{concave:?}"
    );
    assert_eq!(
        messages(&table("[[0, 0], [1e-4, 1e-7]]", "auto")),
        [
            "`punch.profile.points` = 2 point(s) is invalid; a table needs at least 3 `[x, h]` points"
        ]
    );
    // The default contact (P = 2000 N/m on PZT-4, R = 60 mm) has a ≈ 3.7e−5 m: a table of its
    // cylinder to 4e−5 m is too short, to 2e−4 m long enough.
    let cylinder = |extent: f64| {
        let points: Vec<String> = (0..=20)
            .map(|i| {
                let x = extent * f64::from(i) / 20.0;
                format!("[{x:e}, {:e}]", x * x / 0.12)
            })
            .collect();
        format!("[{}]", points.join(", "))
    };
    let short = messages(&table(&cylinder(4e-5), "auto"));
    assert_eq!(short.len(), 1);
    assert!(
        short[0].starts_with(
            "`punch.profile.points` = a table to x = 4.0000e-5 m is invalid for this contact"
        ) && short[0].contains("the table must reach at least 1.25 a"),
        "{short:?}"
    );
    assert!(validate(parse(&table(&cylinder(2e-4), "auto"), Path::new("t")).unwrap()).is_ok());
    assert_eq!(
        issues(&table(&cylinder(2e-4), "spectral"))[0].path,
        "numerics.solver"
    );
}

#[test]
fn electric_load_on_elastic_material_is_rejected() {
    let text = r#"{"material": {"kind": "elastic", "shear_modulus": 27.3e9, "poisson_ratio": 0.3},
        "punch": {"radius": 0.01, "electrode": {"kind": "conducting", "charge": 1e-7}},
        "friction": 0.3, "normal_load": 2240}"#;
    assert_eq!(issues(text)[0].path, "punch.electrode");
}

#[test]
fn unknown_preset_and_bad_constants_are_named() {
    let text = DEFAULT_SCENARIO.replace("\"pzt4\"", "\"pzt99\"");
    assert_eq!(issues(&text)[0].path, "material.name");
    let text = r#"{"material": {"kind": "piezoelectric", "c11": 139e9, "c13": 74.3e9, "c33": 115e9, "c44": -1,
        "e31": -5.2, "e33": 15.1, "e15": 12.7, "eps11": 6.461e-9, "eps33": 5.62e-9},
        "punch": {"radius": 0.06, "electrode": {"kind": "conducting", "charge": 6e-7}},
        "friction": 0.3, "normal_load": 2000}"#;
    assert_eq!(issues(text)[0].path, "material.c44");
}

#[test]
fn text_after_the_object_is_rejected_with_line_and_column() {
    let text = format!("{DEFAULT_SCENARIO}\n{{}}");
    match check(&text) {
        Err(e @ Error::ParseScenario { line, column, .. }) => {
            assert_eq!((line, column), (14, 1));
            assert_eq!(
                e.to_string(),
                "t.json: invalid scenario at `.` (line 14, column 1): trailing characters \
                 (text after the scenario's JSON object)"
            );
        }
        other => panic!("{other:?}"),
    }
    assert!(check(&format!("{DEFAULT_SCENARIO}\n \n")).is_ok());
}

#[test]
fn name_must_be_a_plain_name() {
    for bad in ["../evil", "a/b", "", ".", "..", "a b", "c:\\x"] {
        let text = DEFAULT_SCENARIO.replace("\"baseline\"", &format!("{bad:?}"));
        let found = issues(&text);
        assert_eq!(found[0].path, "name", "{bad}");
    }
    let text = DEFAULT_SCENARIO.replace("\"baseline\"", "\"../evil\"");
    assert_eq!(
        issues(&text)[0].to_string(),
        "`name` = \"../evil\" is invalid; it must be a plain name of ASCII letters, digits, `-`, `_` and `.`, \
         not empty, `.` or `..` (it names the folder output/<name>)"
    );
    let text = DEFAULT_SCENARIO.replace("\"baseline\"", "\"run-2_b.v1\"");
    assert!(check(&text).is_ok());
}

#[test]
fn collocation_points_are_limited() {
    let text = DEFAULT_SCENARIO.replacen(
        "\"friction\": 0.3,",
        "\"friction\": 0.3, \"numerics\": {\"collocation_points\": 1025},",
        1,
    );
    assert_eq!(
        issues(&text)[0].to_string(),
        "`numerics.collocation_points` = 1025 is invalid; it must lie in [8, 1024]"
    );
}

#[test]
fn stroh_failure_is_an_issue_at_the_material() {
    let failure =
        crate::halfplane::SurfaceCompliance::try_of(&Material::Piezoelectric(PiezoConstants {
            c44: 2.56e-90,
            ..crate::material::PZT4
        }))
        .unwrap_err();
    let raw = RawMaterial::Piezoelectric(crate::material::PZT4);
    let issue = material_issue(&raw, &failure);
    assert_eq!(issue.path, "material");
    assert!(
        issue.message.starts_with(
            "these constants are invalid; they must give a half-plane surface response ("
        ),
        "{issue}"
    );
}

#[test]
fn conducting_needs_exactly_one_electric_load() {
    let text = DEFAULT_SCENARIO.replace("\"charge\": 6e-7", "\"charge\": 6e-7, \"potential\": 1.0");
    assert_eq!(issues(&text)[0].path, "punch.electrode");
}

mod history {
    use super::*;

    fn issues_of(text: &str) -> Vec<Issue> {
        validate(parse(text, Path::new("t.json")).unwrap())
            .err()
            .unwrap_or_default()
    }

    #[test]
    fn history_rules_name_the_point() {
        let base = DEFAULT_SCENARIO.replace(
            "[[0.0, 0.0], [1.0, 0.5]]",
            "[[0.0, 0.0], [1.0, 1.2], [0.5, 0.1]]",
        );
        let paths: Vec<_> = issues_of(&base).into_iter().map(|i| i.path).collect();
        assert_eq!(
            paths,
            [
                "tangential_history.points[1].q",
                "tangential_history.points[2].t"
            ]
        );
        let newton = DEFAULT_SCENARIO
            .replace("\"fraction_of_limit\"", "\"newton_per_metre\"")
            .replace("[[0.0, 0.0], [1.0, 0.5]]", "[[0.0, 0.0], [1.0, 600.0]]");
        let found = issues_of(&newton);
        assert_eq!(found[0].path, "tangential_history.points[1].q");
        assert!(
            found[0].message.contains("|Q| < ηP = 600"),
            "{}",
            found[0].message
        );
        let backwards =
            DEFAULT_SCENARIO.replace("[[2.0, -0.5], [4.0, 0.5]]", "[[2.0, -0.5], [1.0, 0.5]]");
        assert!(
            issues_of(&backwards)
                .iter()
                .any(|i| i.path == "tangential_history.cycle[1].t")
        );
    }

    fn with_output(output: &str) -> String {
        DEFAULT_SCENARIO.replacen(
            "\"friction\": 0.3,",
            &format!("\"friction\": 0.3, \"output\": {output},"),
            1,
        )
    }

    #[test]
    fn output_rules_name_the_field() {
        // The default history spans [0, 13] s.
        let found = issues_of(&with_output(
            r#"{"snapshots": [1.0, 0.5, 14.0, 14.0000001], "field_points": 402}"#,
        ));
        let paths: Vec<_> = found.iter().map(|i| i.path.as_str()).collect();
        assert_eq!(
            paths,
            [
                "output.field_points",
                "output.snapshots[1]",
                "output.snapshots[2]",
                "output.snapshots[3]",
                "output.snapshots[3]",
            ]
        );
        assert_eq!(
            found[0].to_string(),
            "`output.field_points` = 402 is invalid; it must be a multiple of 4 in [16, 100000] (so that no sample falls on a contact end)"
        );
        assert!(found[1].message.contains("must be > previous t = 1 s"));
        assert!(
            found[2]
                .message
                .contains("must lie within the history's span [0, 13] s")
        );
        assert!(found[4].message.contains("first 6 decimals"));
        let no_history = r#"{"material": {"kind": "preset", "name": "pzt4"},
            "punch": {"radius": 0.06, "electrode": {"kind": "conducting", "charge": 6e-7}},
            "friction": 0.3, "normal_load": 2000, "output": {"snapshots": [1.0]}}"#;
        let found = issues_of(no_history);
        assert_eq!(found[0].path, "output.snapshots");
        assert!(found[0].message.contains("without a `tangential_history`"));
    }

    #[test]
    fn subsurface_rules_name_the_field() {
        let found = issues_of(&with_output(
            r#"{"subsurface": {"depth": 0.0, "x_range": [1.0, -1.0], "nx": 1, "nz": 5000}}"#,
        ));
        let shown: Vec<String> = found.iter().map(|i| i.to_string()).collect();
        assert_eq!(
            shown,
            [
                "`output.subsurface.depth` = 0 is invalid; it must be in (0, 100] (the deepest row, z/a)",
                "`output.subsurface.x_range[1]` = -1 is invalid; it must be > x_range[0] = 1 (x/a)",
                "`output.subsurface.nx` = 1 is invalid; it must be in [2, 1001]",
                "`output.subsurface.nz` = 5000 is invalid; it must be in [2, 1001]",
            ]
        );
        let found = issues_of(&with_output(
            r#"{"subsurface": {"depth": 1e9, "x_range": [-200.0, 0.0], "nx": 1000, "nz": 1000}}"#,
        ));
        let shown: Vec<String> = found.iter().map(|i| i.to_string()).collect();
        assert_eq!(
            shown,
            [
                "`output.subsurface.depth` = 1000000000 is invalid; it must be in (0, 100] (the deepest row, z/a)",
                "`output.subsurface.x_range[0]` = -200 is invalid; it must be finite and within [−100, 100] (x/a)",
                "`output.subsurface` = nx·nz = 1000000 points is invalid; it must be at most 250000",
            ]
        );
        // Every field has a default; absent, nothing below the surface is asked for.
        let s = check(&with_output(r#"{"subsurface": {}}"#)).unwrap();
        assert_eq!(
            s.raw.output.subsurface,
            Some(RawSubsurface {
                depth: 2.0,
                x_range: [-2.0, 2.0],
                nx: 81,
                nz: 41
            })
        );
        assert!(default_scenario().raw.output.subsurface.is_none());
        match check(&with_output(r#"{"subsurface": {"depht": 1.0}}"#)) {
            Err(Error::ParseScenario { message, .. }) => {
                assert!(message.contains("depht"), "{message}")
            }
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn snapshot_times_off_the_step_grid_become_history_points() {
        // Default history: 10 steps on [0, 1] (max step 0.05 ηP over 0.5 ηP), so 0.3 is a step
        // time and 0.35 is not. Splitting [0, 1] at 0.35 regrids [0, 0.35] into 10 steps
        // 0.035 s apart, so 0.3 is then added as well; 0 and 13 (the ends) add nothing.
        let text = with_output(r#"{"snapshots": [0.0, 0.3, 0.35, 13.0]}"#);
        let s = validate(parse(&text, Path::new("t.json")).unwrap()).unwrap();
        let h = s.history.unwrap();
        assert_eq!(h.points.len(), 10);
        let added: Vec<(f64, f64)> = h.points[1..3].to_vec();
        assert!((added[0].0 - 0.3).abs() < 1e-15 && (added[0].1 - 90.0).abs() < 1e-9);
        assert!((added[1].0 - 0.35).abs() < 1e-15 && (added[1].1 - 105.0).abs() < 1e-9);
        assert_eq!(s.snapshots, [0.0, 0.3, 0.35, 13.0]);
        assert!((s.time_tolerance - 1.3e-8).abs() < 1e-20);
        assert_eq!(snapshot_stem(-0.0), "t_0.000000");
        assert_eq!(snapshot_stem(2.5), "t_2.500000");
    }

    #[test]
    fn load_steps_are_counted_and_limited_before_expanding() {
        // The default history: ramp 0, lead-in 10, then 3 × (20 + 20) steps (max step 30 N/m
        // over 300 N/m and 10 per segment): 130 steps.
        let s = default_scenario();
        let h = s.history.as_ref().unwrap();
        assert_eq!(load_step_count(h) as usize, 130);
        let raw = s.raw.tangential_history.as_ref().unwrap();
        assert_eq!(
            raw.load_steps(&|p| (p[1] * 600.0, 600.0), 600.0, h.max_step) as usize,
            130
        );
        let text = DEFAULT_SCENARIO.replace("\"repeats\": 3", "\"repeats\": 1000000000000000000");
        let found = issues_of(&text);
        assert_eq!(found.len(), 1);
        assert_eq!(
            found[0].to_string(),
            "`tangential_history` = 4.000e19 load steps (2 points, 2 cycle points × 1000000000000000000 repeats, \
             steps_per_segment = 10, max_step = 3e1 N/m) is invalid; it must be at most 500000"
        );
        let just = DEFAULT_SCENARIO.replace("\"repeats\": 3", "\"repeats\": 12499");
        assert!(validate(parse(&just, Path::new("t.json")).unwrap()).is_ok());
        let over = DEFAULT_SCENARIO.replace("\"repeats\": 3", "\"repeats\": 12500");
        assert!(issues_of(&over)[0].message.starts_with("500010 load steps"));
        let tiny =
            DEFAULT_SCENARIO.replace("\"repeats\": 3", "\"repeats\": 3, \"max_step\": 1e-300");
        assert_eq!(issues_of(&tiny)[0].path, "tangential_history");
    }

    #[test]
    fn snapshots_are_limited() {
        let times: Vec<String> = (0..=MAX_SNAPSHOTS)
            .map(|i| format!("{}", i as f64 * 1e-3))
            .collect();
        let found = issues_of(&with_output(&format!(
            "{{\"snapshots\": [{}]}}",
            times.join(", ")
        )));
        assert_eq!(found.len(), 1);
        assert_eq!(
            found[0].to_string(),
            "`output.snapshots` = 10001 times is invalid; it must hold at most 10000"
        );
    }

    /// The former rule, one time at a time over the whole step list: the oracle.
    #[allow(clippy::doc_lazy_continuation)]
    /// Make `t` a step time of `history`: if no step (nor the end of normal loading, nor the first
    /// point) falls within `tol` of it, add the point `(t, Q(t))` of the piecewise-linear history.
    /// Q(t) is unchanged; the segment that held `t` is split in two, each cut into steps by the
    /// usual rule. Returns whether a point was added.
    fn insert_snapshot_point_by_rescanning(
        history: &mut crate::history::LoadHistory,
        t: f64,
        tol: f64,
    ) -> bool {
        let Some(&(t0, _)) = history.points.first() else {
            return false;
        };
        let on_grid = (t - t0).abs() <= tol
            || history
                .steps()
                .iter()
                .any(|&(_, ts, _)| (ts - t).abs() <= tol);
        if on_grid {
            return false;
        }
        let Some(k) = history
            .points
            .windows(2)
            .position(|w| w[0].0 < t && t < w[1].0)
        else {
            return false;
        };
        let ((ta, qa), (tb, qb)) = (history.points[k], history.points[k + 1]);
        let q = qa + (t - ta) / (tb - ta) * (qb - qa);
        history.points.insert(k + 1, (t, q));
        true
    }

    #[test]
    fn snapshot_points_match_rescanning_after_every_addition() {
        // Random histories and snapshot sets (fixed seed): the same points as the former
        // rule, which rescanned every time against every step after each addition.
        let mut state = 0x5eed_u64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        for case in 0..300 {
            let n = 2 + (next() * 6.0) as usize;
            let mut t = 0.0;
            let points: Vec<(f64, f64)> = (0..n)
                .map(|_| {
                    let p = (t, 2.0 * next() - 1.0);
                    t += 0.1 + next() * 3.0;
                    p
                })
                .collect();
            let base = crate::history::LoadHistory {
                points,
                punch: None,
                steps_per_segment: 1 + (next() * 12.0) as usize,
                max_step: 0.02 + next() * 0.3,
                control: crate::history::Control::Load,
                max_displacement_step: f64::INFINITY,
            };
            let span = base.points.last().unwrap().0;
            let mut snaps: Vec<f64> = (0..(next() * 40.0) as usize)
                .map(|_| {
                    let s = next() * span;
                    // Half of them on a step time, to exercise the tolerance.
                    if next() < 0.5 {
                        let steps = base.steps();
                        steps[(next() * steps.len() as f64) as usize].1
                    } else {
                        s
                    }
                })
                .collect();
            snaps.sort_by(f64::total_cmp);
            snaps.dedup();
            let tol = 1e-9 * span;
            let mut fast = base.clone();
            insert_snapshot_points(&mut fast, &snaps, tol);
            let mut slow = base.clone();
            while snaps
                .iter()
                .any(|&t| insert_snapshot_point_by_rescanning(&mut slow, t, tol))
            {}
            assert_eq!(fast, slow, "case {case}");
        }
    }

    #[test]
    fn ten_thousand_snapshots_are_placed_quickly() {
        let times: Vec<String> = (1..=MAX_SNAPSHOTS)
            .map(|i| format!("{}", i as f64 * 1e-4))
            .collect();
        let text = with_output(&format!("{{\"snapshots\": [{}]}}", times.join(", ")));
        let started = std::time::Instant::now();
        let s = validate(parse(&text, Path::new("t.json")).unwrap()).unwrap();
        assert!(s.history.unwrap().points.len() > 1000);
        assert!(
            started.elapsed().as_secs_f64() < 5.0,
            "{:?}",
            started.elapsed()
        );
    }

    #[test]
    fn default_history_has_three_cycles_in_newtons() {
        let s = default_scenario();
        let h = s.history.unwrap();
        assert_eq!(h.points.len(), 8);
        assert!((h.points[1].1 - 300.0).abs() < 1e-9 && (h.points[2].1 + 300.0).abs() < 1e-9);
        assert!((h.max_step - 30.0).abs() < 1e-9);
    }
}
