//! A log-log scatter chart: one point per setting, the Pareto front drawn through its points, every point
//! labelled (with a short tag the table beside it explains).

use super::canvas::{Canvas, Rgb, GLYPH};

/// One point: coordinates (both > 0 to be drawn on log axes; smaller values are drawn at the axis' lower end), a
/// short label, and whether it is on the front.
#[derive(Clone, Debug, PartialEq)]
pub struct Point {
    pub x: f64,
    pub y: f64,
    pub label: String,
    pub front: bool,
}

/// A chart: title, axis titles and points.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LogLogChart {
    pub title: String,
    pub x_title: String,
    pub y_title: String,
    pub points: Vec<Point>,
}

const BLACK: Rgb = [0, 0, 0];
const GRID: Rgb = [225, 225, 225];
const OFF_FRONT: Rgb = [120, 120, 120];
// The Okabe-Ito palette's vermillion: distinct from grey for every common colour-vision deficiency.
const FRONT: Rgb = [213, 94, 0];

/// The decades that enclose `values` (positive, finite): (lowest exponent, highest exponent), at least one apart.
fn decades(values: impl Iterator<Item = f64>, fallback: (i32, i32)) -> (i32, i32) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values.filter(|v| v.is_finite() && *v > 0.0) {
        lo = lo.min(v.log10());
        hi = hi.max(v.log10());
    }
    if !lo.is_finite() {
        return fallback;
    }
    let (lo, hi) = (lo.floor() as i32, hi.ceil() as i32);
    (lo, hi.max(lo + 1))
}

/// "1e-3", or the plain number for 10⁰..10³.
fn decade_label(e: i32) -> String {
    if (0..=3).contains(&e) {
        format!("{}", 10i32.pow(e as u32))
    } else {
        format!("1e{e}")
    }
}

impl LogLogChart {
    /// Draws the chart into the rectangle of `canvas` at `(x, y)` of `width × height` pixels.
    pub fn draw(&self, canvas: &mut Canvas, (x, y): (i32, i32), (width, height): (i32, i32)) {
        let (left, right, top, bottom) = (x + 70, x + width - 20, y + 28, y + height - 44);
        let (xd, yd) =
            (decades(self.points.iter().map(|p| p.x), (0, 1)), decades(self.points.iter().map(|p| p.y), (-6, -1)));
        let px = |v: f64| -> i32 {
            let t = (v.max(10f64.powi(xd.0)).log10() - xd.0 as f64) / (xd.1 - xd.0) as f64;
            left + (t * (right - left) as f64).round() as i32
        };
        let py = |v: f64| -> i32 {
            let t = (v.max(10f64.powi(yd.0)).log10() - yd.0 as f64) / (yd.1 - yd.0) as f64;
            bottom - (t * (bottom - top) as f64).round() as i32
        };
        // Grid and ticks at every decade.
        for e in xd.0..=xd.1 {
            let gx = px(10f64.powi(e));
            canvas.line((gx, top), (gx, bottom), GRID, 1);
            let label = decade_label(e);
            canvas.text((gx - Canvas::text_width(&label, 1) / 2, bottom + 6), &label, BLACK, 1);
        }
        for e in yd.0..=yd.1 {
            let gy = py(10f64.powi(e));
            canvas.line((left, gy), (right, gy), GRID, 1);
            let label = decade_label(e);
            canvas.text((left - 6 - Canvas::text_width(&label, 1), gy - GLYPH / 2), &label, BLACK, 1);
        }
        canvas.line((left, top), (left, bottom), BLACK, 1);
        canvas.line((left, bottom), (right, bottom), BLACK, 1);
        canvas.text((left, y + 6), &self.title, BLACK, 1);
        let xt = Canvas::text_width(&self.x_title, 1);
        canvas.text(((left + right - xt) / 2, bottom + 24), &self.x_title, BLACK, 1);
        let yt = Canvas::text_width(&self.y_title, 1);
        canvas.text_up((x + 6, (top + bottom + yt) / 2), &self.y_title, BLACK);
        // The front, cheapest first.
        let mut front: Vec<&Point> = self.points.iter().filter(|p| p.front).collect();
        front.sort_by(|a, b| a.x.total_cmp(&b.x));
        for pair in front.windows(2) {
            canvas.line((px(pair[0].x), py(pair[0].y)), (px(pair[1].x), py(pair[1].y)), FRONT, 2);
        }
        // Markers, then labels placed where they overlap nothing drawn as a label yet.
        let mut taken: Vec<(i32, i32, i32, i32)> = Vec::new();
        for p in &self.points {
            let (cx, cy) = (px(p.x), py(p.y));
            let c = if p.front { FRONT } else { OFF_FRONT };
            canvas.fill((cx - 3, cy - 3), (cx + 3, cy + 3), c);
            taken.push((cx - 3, cy - 3, cx + 3, cy + 3));
        }
        for p in &self.points {
            let (cx, cy) = (px(p.x), py(p.y));
            let w = Canvas::text_width(&p.label, 1);
            let candidates = [
                (cx + 6, cy - GLYPH / 2),
                (cx - 6 - w, cy - GLYPH / 2),
                (cx - w / 2, cy - 6 - GLYPH),
                (cx - w / 2, cy + 6),
                (cx + 6, cy - GLYPH - 4),
                (cx + 6, cy + 4),
                (cx - 6 - w, cy - GLYPH - 4),
                (cx - 6 - w, cy + 4),
            ];
            let free = |&(lx, ly): &(i32, i32)| {
                taken.iter().all(|&(x0, y0, x1, y1)| lx + w < x0 || lx > x1 || ly + GLYPH < y0 || ly > y1)
            };
            let at = candidates.iter().copied().find(free).unwrap_or(candidates[0]);
            taken.push((at.0, at.1, at.0 + w, at.1 + GLYPH));
            canvas.text(at, &p.label, if p.front { FRONT } else { OFF_FRONT }, 1);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn decades_enclose_the_values() {
        assert_eq!(decades([0.5, 30.0].into_iter(), (0, 1)), (-1, 2));
        assert_eq!(decades([1e-4].into_iter(), (0, 1)), (-4, -3));
        assert_eq!(decades([0.0, f64::NAN].into_iter(), (0, 1)), (0, 1));
    }

    #[test]
    fn points_are_drawn_where_their_coordinates_say() {
        let chart = LogLogChart {
            title: "t".into(),
            x_title: "frame [ms]".into(),
            y_title: "max rel".into(),
            points: vec![
                Point { x: 1.0, y: 1e-2, label: "1".into(), front: true },
                Point { x: 100.0, y: 1e-5, label: "2".into(), front: true },
                Point { x: 100.0, y: 1e-2, label: "3".into(), front: false },
            ],
        };
        let mut canvas = Canvas::new(400, 300);
        chart.draw(&mut canvas, (0, 0), (400, 300));
        // Axes: x from 1 to 100 over [70, 380], y from 1e-5 to 1e-2 over [256, 28].
        assert_eq!(canvas.get(70, 28), FRONT, "the cheapest point, top left");
        assert_eq!(canvas.get(380, 256), FRONT, "the most accurate, bottom right");
        assert_eq!(canvas.get(380, 28), OFF_FRONT, "the dominated one, top right");
        // The front line passes through the middle of the chart's diagonal.
        let (mx, my) = (225, 142);
        assert!((my - 3..=my + 3).any(|y| canvas.get(mx, y) == FRONT));
    }
}
