//! A bracketed scalar root finder for the geometric unknowns whose residuals have
//! square-root kinks (where Newton's method with a finite-difference Jacobian stalls).

/// Find a root of `f` in `[lower, upper]`, searching outward from `guess` for a sign change
/// (steps growing geometrically from `first_step`), then refining by the Illinois variant of
/// regula falsi to `tolerance`. Returns `None` when no sign change is found.
pub fn bracketed_root(
    f: &mut dyn FnMut(f64) -> f64,
    guess: f64,
    lower: f64,
    upper: f64,
    first_step: f64,
    tolerance: f64,
) -> Option<f64> {
    let x0 = guess.clamp(lower, upper);
    let f0 = f(x0);
    if f0 == 0.0 {
        return Some(x0);
    }
    if !f0.is_finite() {
        return None;
    }
    let mut bracket = None;
    let mut step = first_step.max(tolerance);
    let (mut left_done, mut right_done) = (false, false);
    while !(left_done && right_done) {
        for dir in [1.0, -1.0] {
            if (dir > 0.0 && right_done) || (dir < 0.0 && left_done) {
                continue;
            }
            let x1 = (x0 + dir * step).clamp(lower, upper);
            if (dir > 0.0 && x1 >= upper) || (dir < 0.0 && x1 <= lower) {
                if dir > 0.0 {
                    right_done = true
                } else {
                    left_done = true
                }
            }
            let f1 = f(x1);
            if f1.is_finite() && f1.signum() != f0.signum() {
                bracket = Some(if x1 > x0 {
                    (x0, f0, x1, f1)
                } else {
                    (x1, f1, x0, f0)
                });
                break;
            }
        }
        if bracket.is_some() {
            break;
        }
        step *= 2.0;
    }
    let (mut xl, mut fl, mut xr, mut fr) = bracket?;
    let mut side = 0;
    for _ in 0..200 {
        if (xr - xl) <= tolerance {
            break;
        }
        let xm = (xl * fr - xr * fl) / (fr - fl);
        let xm = if xm > xl && xm < xr {
            xm
        } else {
            0.5 * (xl + xr)
        };
        let fm = f(xm);
        if fm == 0.0 {
            return Some(xm);
        }
        if fm.signum() == fl.signum() {
            xl = xm;
            fl = fm;
            if side == -1 {
                fr *= 0.5;
            }
            side = -1;
        } else {
            xr = xm;
            fr = fm;
            if side == 1 {
                fl *= 0.5;
            }
            side = 1;
        }
    }
    Some(if fl.abs() < fr.abs() { xl } else { xr })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_roots_with_square_root_kinks() {
        let mut f = |x: f64| {
            if x > 0.3 {
                (x - 0.3).sqrt() - 0.2
            } else {
                -(0.3 - x).sqrt() - 0.2
            }
        };
        let r = bracketed_root(&mut f, 0.9, 0.0, 1.0, 0.01, 1e-14).unwrap();
        assert!((r - 0.34).abs() < 1e-12);
        let mut g = |x: f64| x * x + 1.0;
        assert!(bracketed_root(&mut g, 0.5, 0.0, 1.0, 0.01, 1e-12).is_none());
    }
}
