use fretsim::contact::normal::{NormalOptions, solve_normal};
use fretsim::contact::pressure::Discretisation;
use fretsim::contact::tangential::SlipOptions;
use fretsim::contact::{graded_cumulative, graded_cumulative_coarse};
use fretsim::history::{DriverState, LoadPoint, NoObserver, advance};
use fretsim::scenario::default_scenario;
fn main() {
    let sc = default_scenario();
    let disc = Discretisation::new(64);
    let normal = solve_normal(&sc.model, &disc, sc.normal_load, NormalOptions::default()).unwrap();
    let mut d = DriverState::after_normal_loading(&normal);
    let steps = sc.history.as_ref().unwrap().steps();
    let mut old = d.state.clone();
    for (i, (_, t, q)) in steps.into_iter().enumerate().take(28) {
        old = d.state.clone();
        advance(
            &sc.model,
            &disc,
            &mut d,
            LoadPoint { step: i + 1, t, q },
            SlipOptions::default(),
            &mut NoObserver,
        )
        .unwrap();
    }
    let new = &d.state;
    let a = new.half_width;
    let st = new.traction.stick.as_ref().unwrap();
    let q_mean = |x: f64| 0.5 * (old.traction_at(x) + new.traction_at(x));
    let d_strain = |x: f64| new.strain_at(&sc.model, x) - old.strain_at(&sc.model, x);
    let mut breaks = new.traction_breakpoints();
    breaks.extend(old.traction_breakpoints());
    breaks.extend([
        old.centre - old.half_width,
        old.centre + old.half_width,
        new.centre - new.half_width,
        new.centre + new.half_width,
    ]);
    let left_end = (old.centre - old.half_width).min(new.centre - new.half_width);
    let right_end = (old.centre + old.half_width).max(new.centre + new.half_width);
    for (from, to) in [(left_end, st.lo), (st.hi, right_end)] {
        let mut pts: Vec<f64> = breaks
            .iter()
            .copied()
            .filter(|x| *x > from && *x < to)
            .collect();
        pts.extend([from, to]);
        pts.sort_by(f64::total_cmp);
        pts.dedup();
        println!(
            "zone [{:.6},{:.6}] pieces {:?}",
            from / a,
            to / a,
            pts.iter()
                .map(|p| format!("{:.6}", p / a))
                .collect::<Vec<_>>()
        );
        for w in pts.windows(2) {
            let f = graded_cumulative(w.to_vec(), &d_strain).total;
            let c = graded_cumulative_coarse(w.to_vec(), &d_strain).total;
            let fq = graded_cumulative(w.to_vec(), &q_mean).total;
            let cq = graded_cumulative_coarse(w.to_vec(), &q_mean).total;
            println!(
                "  [{:.6},{:.6}] strain rel diff {:.2e} (|int| {:.3e}), q rel diff {:.2e}",
                w[0] / a,
                w[1] / a,
                (f - c).abs() / f.abs().max(1e-300),
                f.abs(),
                (fq - cq).abs() / fq.abs().max(1e-300)
            );
        }
    }
    let (x0, x1) = (-0.569840 * a, -0.522144 * a);
    let n = 400;
    let vals: Vec<(f64, f64, f64)> = (0..=n)
        .map(|i| {
            let x = x0 + (x1 - x0) * i as f64 / n as f64;
            (x, new.strain_at(&sc.model, x), old.strain_at(&sc.model, x))
        })
        .collect();
    let mut worst = Vec::new();
    for k in 1..n {
        let d2n = vals[k + 1].1 - 2.0 * vals[k].1 + vals[k - 1].1;
        let d2o = vals[k + 1].2 - 2.0 * vals[k].2 + vals[k - 1].2;
        worst.push((d2n.abs(), d2o.abs(), vals[k].0 / a));
    }
    let mn = worst.iter().cloned().fold(
        (0.0f64, 0.0f64, 0.0f64),
        |m, w| if w.0 > m.0 { w } else { m },
    );
    let mo = worst.iter().cloned().fold(
        (0.0f64, 0.0f64, 0.0f64),
        |m, w| if w.1 > m.1 { w } else { m },
    );
    let medn = {
        let mut v: Vec<f64> = worst.iter().map(|w| w.0).collect();
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    let medo = {
        let mut v: Vec<f64> = worst.iter().map(|w| w.1).collect();
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    println!(
        "new: max d2 {:.3e} at {:.6} (median {:.3e}); old: max d2 {:.3e} at {:.6} (median {:.3e})",
        mn.0, mn.2, medn, mo.1, mo.2, medo
    );
    let z = old.traction.stick.as_ref().unwrap();
    println!(
        "old stick [{:.6},{:.6}] kink {} new stick [{:.6},{:.6}]",
        z.lo / a,
        z.hi / a,
        z.kink,
        st.lo / a,
        st.hi / a
    );
    for l in st.links() {
        println!(
            " link zone [{:.6},{:.6}] kink {} ramps {:?} {:?}",
            l.zone.lo / a,
            l.zone.hi / a,
            l.zone.kink,
            l.ramp_lo.map(|r| (r.0 / a, r.1 / a)),
            l.ramp_hi.map(|r| (r.0 / a, r.1 / a))
        );
    }
}
#[allow(dead_code)]
fn unused() {}
