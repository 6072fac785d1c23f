//! Triangle coverage in fixed point: edge functions, the top-left fill rule, facing.
//!
//! Vertices are snapped to a grid of 1/2^bits pixel whose origin is a pixel centre (see
//! [`super::viewport::snap`]), so pixel `(i, j)`'s sample lies at `(i·2^bits, j·2^bits)` and every test below is
//! exact integer arithmetic.
//!
//! Rules (Vulkan spec, "Basic Polygon Rasterization"; y grows downwards):
//! - The triangle's signed area `S = (b − a) × (c − a)` on the snapped vertices decides facing: `S < 0` is
//!   counter-clockwise as seen on screen, the front face (`VK_FRONT_FACE_COUNTER_CLOCKWISE`). `S = 0`: nothing is
//!   drawn.
//! - With the vertices ordered so that `S > 0`, a sample `p` is inside when every edge function
//!   `E(a→b, p) = (b − a) × (p − a)` is positive, or zero on a *top* edge (horizontal, `dy = 0`, `dx > 0`: the
//!   other vertex lies below it) or a *left* edge (`dy < 0`).
//!
//! Consequences the tests check exhaustively: triangles sharing an edge never both cover a sample on it and
//! leave no gap; a sample on a shared vertex is covered exactly once by a closed fan around it.

/// One edge function `E(px, py) = a·px + b·py + c` on pixel indices, with `bias = 1` on top-left edges so that
/// the inside test is `E + bias > 0`.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Edge {
    a: i64,
    b: i64,
    c: i64,
    bias: i64,
}

/// An inclusive rectangle of pixels.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PixelRect {
    pub x0: u32,
    pub y0: u32,
    pub x1: u32,
    pub y1: u32,
}

/// A triangle ready to rasterize.
#[derive(Clone, Debug, PartialEq)]
pub struct RasterTriangle {
    edges: [Edge; 3],
    /// Pixels that may be covered, clipped to the image.
    pub bounds: PixelRect,
    /// Seen from its front side (counter-clockwise on screen).
    pub front_facing: bool,
    /// `order[k]` is the input vertex placed at position `k` (positions are reordered so that `S > 0`).
    pub order: [usize; 3],
}

impl RasterTriangle {
    /// Sets up a triangle from snapped vertices. `None` when it has zero area or covers no pixel of a
    /// `width × height` image.
    pub fn new(fixed: [[i64; 2]; 3], bits: u32, width: u32, height: u32) -> Option<Self> {
        let [p0, p1, p2] = fixed;
        let s = (p1[0] - p0[0]) * (p2[1] - p0[1]) - (p1[1] - p0[1]) * (p2[0] - p0[0]);
        if s == 0 {
            return None;
        }
        let front_facing = s < 0;
        let order = if s > 0 { [0, 1, 2] } else { [0, 2, 1] };
        let v = order.map(|i| fixed[i]);
        let one = 1i64 << bits;
        let edges = [0, 1, 2].map(|k| {
            let (a, b) = (v[k], v[(k + 1) % 3]);
            let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
            let top_left = dy < 0 || (dy == 0 && dx > 0);
            // E(p) = dx·(p.y − a.y) − dy·(p.x − a.x) with p = (px, py)·one.
            Edge { a: -dy * one, b: dx * one, c: dy * a[0] - dx * a[1], bias: top_left as i64 }
        });
        // Pixel range: samples at multiples of `one` within the vertices' extent.
        let ceil_div = |v: i64| v.div_euclid(one) + (v.rem_euclid(one) != 0) as i64;
        let (min_x, max_x) = (v.iter().map(|p| p[0]).min()?, v.iter().map(|p| p[0]).max()?);
        let (min_y, max_y) = (v.iter().map(|p| p[1]).min()?, v.iter().map(|p| p[1]).max()?);
        let x0 = ceil_div(min_x).max(0);
        let y0 = ceil_div(min_y).max(0);
        let x1 = max_x.div_euclid(one).min(width as i64 - 1);
        let y1 = max_y.div_euclid(one).min(height as i64 - 1);
        if x0 > x1 || y0 > y1 {
            return None;
        }
        let bounds = PixelRect { x0: x0 as u32, y0: y0 as u32, x1: x1 as u32, y1: y1 as u32 };
        Some(Self { edges, bounds, front_facing, order })
    }

    /// Distance \[pixels\] from the sample of pixel `(x, y)` to the nearest of the three edge lines.
    pub fn edge_distance(&self, x: u32, y: u32, bits: u32) -> f64 {
        let one = (1i64 << bits) as f64;
        self.edges
            .iter()
            .map(|e| {
                let value = (e.a * x as i64 + e.b * y as i64 + e.c) as f64;
                // |∇E| in fixed units per pixel is one·|edge|; E itself is in fixed² units.
                value.abs() / ((e.a as f64).hypot(e.b as f64) * one)
            })
            .fold(f64::INFINITY, f64::min)
    }

    /// Whether the sample of pixel `(x, y)` is covered.
    pub fn covers(&self, x: u32, y: u32) -> bool {
        self.edges.iter().all(|e| e.a * x as i64 + e.b * y as i64 + e.c + e.bias > 0)
    }

    /// Calls `f(x, y)` for every covered pixel with `y0 ≤ y < y1`, row by row, left to right.
    pub fn for_each_covered(&self, y0: u32, y1: u32, mut f: impl FnMut(u32, u32)) {
        let (ya, yb) = (self.bounds.y0.max(y0), self.bounds.y1.min(y1.saturating_sub(1)));
        if ya > yb {
            return;
        }
        let x0 = self.bounds.x0;
        for y in ya..=yb {
            // Incremental evaluation along the row.
            let mut e = self.edges.map(|e| e.a * x0 as i64 + e.b * y as i64 + e.c + e.bias);
            for x in x0..=self.bounds.x1 {
                if e[0] > 0 && e[1] > 0 && e[2] > 0 {
                    f(x, y);
                }
                for (value, edge) in e.iter_mut().zip(&self.edges) {
                    *value += edge.a;
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const BITS: u32 = 8;
    const ONE: i64 = 1 << BITS;

    fn coverage(tri: [[i64; 2]; 3], w: u32, h: u32) -> Vec<(u32, u32)> {
        let mut v = Vec::new();
        if let Some(t) = RasterTriangle::new(tri, BITS, w, h) {
            t.for_each_covered(0, h, |x, y| v.push((x, y)));
        }
        v
    }

    /// Brute force over all samples with exact rational arithmetic: the definition, written independently.
    fn brute(tri: [[i64; 2]; 3], w: u32, h: u32) -> Vec<(u32, u32)> {
        let s = (tri[1][0] - tri[0][0]) * (tri[2][1] - tri[0][1]) - (tri[1][1] - tri[0][1]) * (tri[2][0] - tri[0][0]);
        if s == 0 {
            return vec![];
        }
        let v = if s > 0 { tri } else { [tri[0], tri[2], tri[1]] };
        let mut out = Vec::new();
        for y in 0..h {
            for x in 0..w {
                let p = [x as i64 * ONE, y as i64 * ONE];
                let inside = (0..3).all(|k| {
                    let (a, b) = (v[k], v[(k + 1) % 3]);
                    let e = (b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0]);
                    let top = b[1] == a[1] && b[0] > a[0];
                    let left = b[1] < a[1];
                    e > 0 || (e == 0 && (top || left))
                });
                if inside {
                    out.push((x, y));
                }
            }
        }
        out
    }

    /// A small deterministic generator (xorshift), so the tests need no crate.
    struct Rng(u64);
    impl Rng {
        fn next(&mut self) -> u64 {
            self.0 ^= self.0 << 13;
            self.0 ^= self.0 >> 7;
            self.0 ^= self.0 << 17;
            self.0
        }
        /// A coordinate in [−1, n+1] pixels, on the sample grid half of the time (to create ties).
        fn coord(&mut self, n: i64) -> i64 {
            let whole = (self.next() % (n as u64 + 3)) as i64 - 1;
            if self.next().is_multiple_of(2) {
                whole * ONE
            } else {
                whole * ONE + (self.next() % ONE as u64) as i64
            }
        }
    }

    #[test]
    fn agrees_with_the_definition_on_random_triangles_with_ties() {
        let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
        for _ in 0..4000 {
            let tri = [0, 1, 2].map(|_| [rng.coord(12), rng.coord(12)]);
            assert_eq!(coverage(tri, 12, 12), brute(tri, 12, 12), "{tri:?}");
        }
    }

    #[test]
    fn shared_edges_cover_each_sample_exactly_once() {
        let mut rng = Rng(12345);
        for _ in 0..3000 {
            // A convex or concave quad a-b-c-d split along a-c: the two halves share the edge a-c.
            let q = [0, 1, 2, 3].map(|_| [rng.coord(10), rng.coord(10)]);
            let t1 = [q[0], q[1], q[2]];
            let t2 = [q[0], q[2], q[3]];
            let (c1, c2) = (coverage(t1, 10, 10), coverage(t2, 10, 10));
            let s1 = (t1[1][0] - t1[0][0]) * (t1[2][1] - t1[0][1]) - (t1[1][1] - t1[0][1]) * (t1[2][0] - t1[0][0]);
            let s2 = (t2[1][0] - t2[0][0]) * (t2[2][1] - t2[0][1]) - (t2[1][1] - t2[0][1]) * (t2[2][0] - t2[0][0]);
            if s1 != 0 && s2 != 0 && (s1 > 0) == (s2 > 0) {
                // Same winding: the halves lie on opposite sides of a-c and must not overlap.
                for p in &c1 {
                    assert!(!c2.contains(p), "{q:?}: sample {p:?} covered twice");
                }
            }
        }
    }

    #[test]
    fn closed_fan_around_a_sample_covers_it_once() {
        // Vertex at the centre of pixel (5, 5), fan of 8 triangles around it, including axis-aligned edges.
        let c = [5 * ONE, 5 * ONE];
        let ring: Vec<[i64; 2]> = [(2, 0), (2, 2), (0, 2), (-2, 2), (-2, 0), (-2, -2), (0, -2), (2, -2)]
            .iter()
            .map(|(dx, dy)| [c[0] + dx * ONE + 37, c[1] + dy * ONE - 11])
            .collect();
        let mut count = std::collections::HashMap::new();
        for i in 0..ring.len() {
            for p in coverage([c, ring[i], ring[(i + 1) % ring.len()]], 12, 12) {
                *count.entry(p).or_insert(0) += 1;
            }
        }
        assert_eq!(count.get(&(5, 5)), Some(&1));
        assert!(count.values().all(|&n| n == 1), "{count:?}");
    }

    #[test]
    fn axis_aligned_rectangle_includes_top_and_left_edges_only() {
        // Rectangle with corners exactly on samples (2,3) and (6,8): covers x in 2..6, y in 3..8.
        let (a, b, c, d) = ([2 * ONE, 3 * ONE], [6 * ONE, 3 * ONE], [6 * ONE, 8 * ONE], [2 * ONE, 8 * ONE]);
        let mut got = coverage([a, c, b], 10, 10);
        got.extend(coverage([a, d, c], 10, 10));
        got.sort();
        let mut want: Vec<(u32, u32)> = (3..8).flat_map(|y| (2..6).map(move |x| (x, y))).collect();
        want.sort();
        assert_eq!(got, want);
    }

    #[test]
    fn facing_and_vertex_order() {
        // On screen (y down), (0,0) → (0,4) → (4,0) runs counter-clockwise: front-facing.
        let ccw = [[0, 0], [0, 4 * ONE], [4 * ONE, 0]];
        let t = RasterTriangle::new(ccw, BITS, 8, 8).unwrap();
        assert!(t.front_facing);
        let cw = [[0, 0], [4 * ONE, 0], [0, 4 * ONE]];
        assert!(!RasterTriangle::new(cw, BITS, 8, 8).unwrap().front_facing);
        // Coverage does not depend on the starting vertex or the winding.
        assert_eq!(coverage(ccw, 8, 8), coverage(cw, 8, 8));
        assert_eq!(coverage(ccw, 8, 8), coverage([ccw[1], ccw[2], ccw[0]], 8, 8));
        // Degenerate: nothing.
        assert!(RasterTriangle::new([[0, 0], [ONE, ONE], [2 * ONE, 2 * ONE]], BITS, 8, 8).is_none());
    }

    #[test]
    fn off_screen_parts_are_cut_by_the_bounds() {
        let big = [[-100 * ONE, -100 * ONE], [300 * ONE, -100 * ONE], [-100 * ONE, 300 * ONE]];
        let c = coverage(big, 4, 3);
        assert_eq!(c.len(), 12);
        assert!(RasterTriangle::new([[20 * ONE, 0], [30 * ONE, 0], [20 * ONE, 5 * ONE]], BITS, 4, 4).is_none());
    }
}
