//! Root of a scalar function on a bracket, by the Illinois variant of regula falsi: it keeps
//! the bracket (so it cannot jump to another root) and converges superlinearly.

/// Finds θ in [a, b] with f(θ) = 0, given f(a) ≥ 0 > f(b) or f(a) ≤ 0 < f(b). Returns the
/// end of the final bracket on the side of `a`, so the answer never lies past the crossing.
pub fn illinois(mut f: impl FnMut(f64) -> f64, mut a: f64, mut b: f64, tol: f64) -> f64 {
    let (mut fa, mut fb) = (f(a), f(b));
    if fa == 0.0 {
        return a;
    }
    let mut side = 0;
    for _ in 0..200 {
        if (b - a).abs() <= tol {
            break;
        }
        let c = (a * fb - b * fa) / (fb - fa);
        let c = if c > a.min(b) && c < a.max(b) {
            c
        } else {
            0.5 * (a + b)
        };
        let fc = f(c);
        if fc == 0.0 {
            return c;
        }
        if (fc > 0.0) == (fa > 0.0) {
            a = c;
            fa = fc;
            if side == -1 {
                fb *= 0.5;
            }
            side = -1;
        } else {
            b = c;
            fb = fc;
            if side == 1 {
                fa *= 0.5;
            }
            side = 1;
        }
    }
    a
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_the_root_inside_the_bracket() {
        let r = illinois(|x| x * x - 2.0, 0.0, 2.0, 1e-14);
        assert!((r - 2f64.sqrt()).abs() < 1e-13);
        let r = illinois(|x| (x - 0.3).powi(3), 1.0, 0.0, 1e-14);
        assert!((r - 0.3).abs() < 1e-4, "{r}");
    }
}
