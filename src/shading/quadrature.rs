//! Gauss–Legendre quadrature: the deterministic numerical integration used where no closed form is used (and by
//! the tests that check the closed forms).

/// Nodes and weights of the `n`-point Gauss–Legendre rule on [−1, 1], exact for polynomials of degree 2n − 1.
/// Nodes by Newton's method on the Legendre polynomial from Chebyshev starting points (f64, converged to
/// machine precision).
pub fn gauss_legendre(n: usize) -> Vec<(f64, f64)> {
    assert!(n > 0, "a quadrature rule needs at least one node");
    let mut out = vec![(0.0, 0.0); n];
    for i in 0..n.div_ceil(2) {
        let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        let mut dp = 0.0;
        for _ in 0..100 {
            // P_n(x) and P_n'(x) by the three-term recurrence.
            let (mut p0, mut p1) = (1.0, x);
            for k in 2..=n {
                let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
                p0 = p1;
                p1 = p2;
            }
            let pn = if n == 1 { x } else { p1 };
            let pn_1 = if n == 1 { 1.0 } else { p0 };
            dp = n as f64 * (x * pn - pn_1) / (x * x - 1.0);
            let dx = pn / dp;
            x -= dx;
            if dx.abs() < 1e-16 {
                break;
            }
        }
        let w = 2.0 / ((1.0 - x * x) * dp * dp);
        out[i] = (-x, w);
        out[n - 1 - i] = (x, w);
    }
    out
}

/// `∫_a^b f` with the `n`-point Gauss–Legendre rule.
pub fn integrate(a: f64, b: f64, n: usize, mut f: impl FnMut(f64) -> f64) -> f64 {
    let (mid, half) = (0.5 * (a + b), 0.5 * (b - a));
    gauss_legendre(n).iter().map(|&(x, w)| w * f(mid + half * x)).sum::<f64>() * half
}

/// `∫_a^b f` by `panels` equal panels of `order`-point Gauss–Legendre: converges on near-singular integrands.
pub fn integrate_composite(a: f64, b: f64, panels: usize, order: usize, mut f: impl FnMut(f64) -> f64) -> f64 {
    let rule = gauss_legendre(order);
    let h = (b - a) / panels as f64;
    let mut sum = 0.0;
    for i in 0..panels {
        let mid = a + (i as f64 + 0.5) * h;
        sum += rule.iter().map(|&(x, w)| w * f(mid + 0.5 * h * x)).sum::<f64>() * 0.5 * h;
    }
    sum
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn integrates_polynomials_exactly_and_smooth_functions_closely() {
        for n in [1, 2, 5, 16, 64] {
            let rule = gauss_legendre(n);
            assert!((rule.iter().map(|p| p.1).sum::<f64>() - 2.0).abs() < 1e-14, "weights of {n}");
            let deg = 2 * n - 1;
            let got = integrate(0.0, 1.0, n, |x| x.powi(deg as i32));
            assert!((got - 1.0 / (deg as f64 + 1.0)).abs() < 1e-13, "{n}: {got}");
        }
        let got = integrate(0.0, std::f64::consts::PI, 20, f64::sin);
        assert!((got - 2.0).abs() < 1e-14, "{got}");
    }
}
