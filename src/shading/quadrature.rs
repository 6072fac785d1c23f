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

/// How a lobe grid places its `k` points on each axis' unit interval (`u ∈ (0, 1)`, before the axis' warp).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GridRule {
    /// `u = (i + ½)/k`, equal weights: second order on a smooth integrand, and the better of the two while the
    /// grid does not yet resolve the lobe (its points are evenly spread; Gauss–Legendre's thin out in the middle,
    /// about π/2 times as far apart).
    Midpoint,
    /// Gauss–Legendre's nodes and weights on (0, 1): exact for polynomials of degree 2k − 1, and converging faster
    /// than any power of 1/k on an analytic integrand once its features are resolved.
    GaussLegendre,
}

/// The most points a side with a Gauss–Legendre rule in [`gauss_legendre_table`] (the GPU's binding 13); a grid
/// of more takes the midpoint rule.
pub const GAUSS_LEGENDRE_MAX_SIDE: u32 = 256;

/// Every Gauss–Legendre rule of 1 to [`GAUSS_LEGENDRE_MAX_SIDE`] nodes on (0, 1), the rule of k nodes from offset
/// k(k − 1)/2, each node as f32 `(u, k·w)`: the weight over the midpoint rule's 1/k. The GPU reads this table
/// (binding 13) and the reference takes the same rounded values (as f64), so that both renderers place the same
/// points. Rounding to f32 moves a node by at most 3e-8 and the weights' sum from 1 by about k·3e-8 (7.6e-6 at
/// 256 nodes, in the worst case of every weight rounding one way; measured below), an error of the rule that both
/// renderers share. Computed once, in f64 ([`gauss_legendre`]: 16 ms for all 32 896 nodes).
pub fn gauss_legendre_table() -> &'static [[f32; 2]] {
    static TABLE: std::sync::OnceLock<Vec<[f32; 2]>> = std::sync::OnceLock::new();
    TABLE.get_or_init(|| {
        let mut table = Vec::with_capacity((GAUSS_LEGENDRE_MAX_SIDE * (GAUSS_LEGENDRE_MAX_SIDE + 1) / 2) as usize);
        for k in 1..=GAUSS_LEGENDRE_MAX_SIDE as usize {
            table.extend(
                gauss_legendre(k).iter().map(|&(x, w)| [(0.5 * (x + 1.0)) as f32, (0.5 * w * k as f64) as f32]),
            );
        }
        table
    })
}

/// Node `i` of `k` on one axis under `rule`: `(u, s)`, the point in (0, 1) and its weight times k, so that a grid
/// sums `value · s_i · s_j` and divides by k² as the midpoint rule does (whose s is exactly 1: its sums are
/// those of equal weights to the last bit). A Gauss–Legendre rule of more than [`GAUSS_LEGENDRE_MAX_SIDE`] nodes is
/// the midpoint rule's (callers choose through [`super::sky_lune::sky_grid_rule`], which never asks one).
pub fn grid_node(rule: GridRule, i: u32, k: u32) -> (f64, f64) {
    match rule {
        GridRule::GaussLegendre if k <= GAUSS_LEGENDRE_MAX_SIDE => {
            let [u, s] = gauss_legendre_table()[(k * (k - 1) / 2 + i) as usize];
            (u as f64, s as f64)
        }
        _ => ((i as f64 + 0.5) / k as f64, 1.0),
    }
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

    #[test]
    fn the_table_holds_each_rule_rounded_to_f32() {
        for k in [1u32, 2, 16, 27, 162, GAUSS_LEGENDRE_MAX_SIDE] {
            let rule = gauss_legendre(k as usize);
            let mut sum = 0.0;
            for i in 0..k {
                let (u, s) = grid_node(GridRule::GaussLegendre, i, k);
                let (x, w) = rule[i as usize];
                assert_eq!(u, (0.5 * (x + 1.0)) as f32 as f64, "{k}: node {i}");
                assert!((s / k as f64 - 0.5 * w).abs() <= 6e-8 * 0.5 * w, "{k}: weight {i}");
                sum += s;
            }
            // The rounded weights still sum to 1 (k, as s = k·w) to within what f32 keeps.
            assert!((sum / k as f64 - 1.0).abs() < 1e-6, "{k}: {}", sum / k as f64 - 1.0);
            // And integrate x^(2k−1) on (0, 1) to that accuracy (up to 16 nodes: a higher power magnifies the
            // nodes' rounding near 1 by its degree).
            if k > 16 {
                continue;
            }
            let deg = 2 * k as i32 - 1;
            let got: f64 = (0..k).map(|i| grid_node(GridRule::GaussLegendre, i, k)).map(|(u, s)| u.powi(deg) * s).sum();
            assert!((got / k as f64 * (deg + 1) as f64 - 1.0).abs() < 2e-6, "{k}: {got}");
        }
        assert_eq!(grid_node(GridRule::Midpoint, 3, 8), (3.5 / 8.0, 1.0));
        assert_eq!(grid_node(GridRule::GaussLegendre, 0, GAUSS_LEGENDRE_MAX_SIDE + 1).1, 1.0);
    }
}
