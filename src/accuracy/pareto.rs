//! The Pareto front of a sweep: the settings no other setting beats in both cost and error.

/// For each point `(cost, error)`, whether it is on the front: no other point has a cost and an error both no
/// larger and one of them smaller. Equal points are on the front together; a NaN coordinate is never on it.
pub fn pareto_front(points: &[(f64, f64)]) -> Vec<bool> {
    let dominates = |a: (f64, f64), b: (f64, f64)| a.0 <= b.0 && a.1 <= b.1 && (a.0 < b.0 || a.1 < b.1);
    points.iter().map(|&p| !p.0.is_nan() && !p.1.is_nan() && !points.iter().any(|&q| dominates(q, p))).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_front_of_a_small_sweep() {
        // (ms, error): the cheapest, the most accurate, one in between, and two dominated ones.
        let points = [(1.0, 1e-1), (10.0, 1e-5), (3.0, 1e-3), (4.0, 2e-3), (12.0, 1e-5)];
        assert_eq!(pareto_front(&points), [true, true, true, false, false]);
    }

    #[test]
    fn ties_and_nan() {
        assert_eq!(pareto_front(&[(1.0, 1.0), (1.0, 1.0)]), [true, true]);
        assert_eq!(pareto_front(&[(1.0, f64::NAN), (2.0, 1.0)]), [false, true]);
    }

    #[test]
    fn no_point_on_the_front_is_dominated_and_every_other_is() {
        // A deterministic scatter of 200 points (a linear congruential generator).
        let mut state = 12345u64;
        let mut next = || {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let points: Vec<(f64, f64)> = (0..200).map(|_| ((next() * 8.0).round(), (next() * 8.0).round())).collect();
        let front = pareto_front(&points);
        for (i, &p) in points.iter().enumerate() {
            let dominated = points.iter().any(|&q| q.0 <= p.0 && q.1 <= p.1 && q != p);
            assert_eq!(front[i], !dominated, "{p:?}");
        }
        assert!(front.iter().any(|&f| f));
    }
}
