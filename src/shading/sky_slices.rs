//! The sky's visible fraction by slices: exact along one angle, a midpoint rule along the other. The reference's
//! alternative to the located grid (`visibility::grid_fraction`) where its occluders are opaque triangles. The GPU
//! takes the same rows in passes, each row walking the occluders for its own triangles ([`sky_rows_weights`],
//! shaders/slices.glsl, `gpu::slice_passes`).
//!
//! The sphere of directions is cut into half great circles through a fixed axis `c` ([`SLICE_AXIS`]):
//! `ω(β, ψ) = cos β c + sin β p(ψ)`, `p(ψ) = cos ψ p₁ + sin ψ p₂`, `β ∈ [0, π]`, `ψ ∈ [0, 2π)`, the area element
//! `sin β dβ dψ`. The cosine-weighted visible fraction of the sky (`ω_y > 0`) seen from a surface of normal `n` is
//!
//! `V = ∫ dψ ∫_{sky, n·ω > 0, unblocked} (n·ω) sin β dβ / ∫ dψ ∫_{sky, n·ω > 0} (n·ω) sin β dβ`,
//!
//! with `(n·ω) sin β = (n·c) cos β sin β + (n·p) sin²β`. For one `ψ` the two horizons each keep one interval of β
//! ([`above`]), and the directions form the half-plane `{o + s c + t p : t ≥ 0}` through the rays' origin `o`. A
//! triangle that the plane cuts meets it in a segment, which blocks exactly the directions it subtends from `o`
//! (every ray towards the sky is infinitely long): an interval of β ([`blocked_interval`]). The inner integral
//! over what is left is closed-form ([`weight_integral`]); only the outer one is sampled, by midpoints in `ψ`
//! over the whole circle, a periodic integrand, continuous and piecewise smooth (its kinks where a corner of an
//! occluder's outline passes a row), so the rule converges at the second order in the rows without the grid's
//! cells, bisections and their budget.
//!
//! **Why a fixed, oblique axis.** The inner integrand jumps only where an occluder's edge lies in a slice plane:
//! an edge parallel to `c`, or one whose line meets the axis line through `o`. Slicing the sky's own lune (about
//! the horizontal `a ⊥ n`) made every edge parallel to `a` a jump at every pixel (a roof's edge over a floor:
//! midpoints then converge at first order, measured 1.5e-3 at 64 and at 256 rows); an axis along no direction
//! a scene is built on leaves only the pixels whose axis line meets an edge, a curve in the image, near which the
//! refinement of the converged reference slows down and reports them.
//!
//! Whether a ray *through* a segment counts as blocked is the segment's closed interval; rays at the interval's
//! ends graze an edge and have zero measure. The triangle containing `o` is never met: `o` is pushed off its
//! surface along the face normal (`visibility::shadow_ray_origin`).

use std::f64::consts::{FRAC_PI_2, PI};

use glam::DVec3;

use super::slice_buckets::{keep_gathered, midpoint_rows, take_kept, RowBuckets};
use super::visibility::{Shadowing, SliceReach};

/// The slices' axis: along no direction a scene is likely built on (module text), `(√2 − 1, 1, (√5 − 1)/2)`
/// normalised.
pub const SLICE_AXIS: [f64; 3] = [0.33232518133916444, 0.8023039599071088, 0.4958511165312262];

/// `∫_{b0}^{b1} sin²β dβ` for `0 ≤ b0 ≤ b1 ≤ π`, without the cancellation of `Δ/2 − cos(b0 + b1) sin Δ / 2` for a
/// short interval: written as `(Δ − sin Δ)/2 + sin Δ sin²((b0 + b1)/2)`, both terms non-negative, and `Δ − sin Δ`
/// by its series below 1/4 (where the subtraction would lose up to half the digits; the series' first omitted
/// term, `Δ¹³/13!`, is below 1e-15 of the sum there).
pub fn sin_squared_integral(b0: f64, b1: f64) -> f64 {
    let d = b1 - b0;
    if d <= 0.0 {
        return 0.0;
    }
    let d_minus_sin = if d < 0.25 {
        let d2 = d * d;
        d * d2 * (1.0 / 6.0 - d2 * (1.0 / 120.0 - d2 * (1.0 / 5040.0 - d2 * (1.0 / 362_880.0 - d2 / 39_916_800.0))))
    } else {
        d - d.sin()
    };
    let h = (0.5 * (b0 + b1)).sin();
    0.5 * d_minus_sin + d.sin() * h * h
}

/// A pseudo-angle of the direction `(s, t)`, `t ≥ 0`, of the half-plane: `−s / (|s| + t)`, from −1 at β = 0 through
/// 0 at π/2 to 1 at π, increasing with β, so that intervals are sorted and merged without an `atan2` a corner
/// (the rows' sums took a quarter of their time in it); [`angle_of`] turns the few ends that count back into β.
pub fn pseudo_angle(s: f64, t: f64) -> f64 {
    -s / (s.abs() + t)
}

/// β of a pseudo-angle: `atan2(1 − |k|, −k)` (the direction `(−k, 1 − |k|)` is `(s, t)` scaled). Near the ends
/// `1 − |k|` keeps an absolute accuracy of an ulp of 1, so β does; the row's integral needs no more.
pub fn angle_of(k: f64) -> f64 {
    (1.0 - k.abs()).max(0.0).atan2(-k)
}

/// The segment in which the plane through the rays' origin of unit normal `m` cuts the triangle `tri` (corners
/// relative to that origin, in metres), in the plane's coordinates `(s, t) = (q·c, q·p)`; `None` where the plane
/// misses it, touches a corner, or holds it (which only a measure-zero set of rows meets).
pub fn slice_segment(tri: [DVec3; 3], c: DVec3, p: DVec3, m: DVec3) -> Option<[(f64, f64); 2]> {
    let dist = tri.map(|p| p.dot(m));
    let mut points = [(0.0, 0.0); 3];
    let mut n = 0;
    let in_plane = |q: DVec3| (q.dot(c), q.dot(p));
    for j in 0..3 {
        let k = (j + 1) % 3;
        if dist[j] == 0.0 {
            points[n] = in_plane(tri[j]);
            n += 1;
        }
        if (dist[j] < 0.0 && dist[k] > 0.0) || (dist[j] > 0.0 && dist[k] < 0.0) {
            // The crossing of edge j→k, interpolated from the nearer corner's side of the ratio (|r| ≤ 1).
            let r = dist[j] / (dist[j] - dist[k]);
            points[n] = in_plane(tri[j] + r * (tri[k] - tri[j]));
            n += 1;
        }
    }
    (n == 2).then_some([points[0], points[1]])
}

/// The part of `segment` where `a·(s, t) < b`, if any (`a` and `b` of a line of the slice's plane).
pub fn clip_segment(segment: [(f64, f64); 2], a: (f64, f64), b: f64) -> Option<[(f64, f64); 2]> {
    let [(s0, t0), (s1, t1)] = segment;
    let (f0, f1) = (a.0 * s0 + a.1 * t0 - b, a.0 * s1 + a.1 * t1 - b);
    if f0 >= 0.0 && f1 >= 0.0 {
        return None;
    }
    if f0 < 0.0 && f1 < 0.0 {
        return Some(segment);
    }
    let r = f0 / (f0 - f1);
    let cut = (s0 + r * (s1 - s0), t0 + r * (t1 - t0));
    Some(if f0 < 0.0 { [(s0, t0), cut] } else { [cut, (s1, t1)] })
}

/// The interval of β (the angle from `c` in the half-plane `{s c + t p : t ≥ 0}`, origin at the rays' origin) that
/// a segment of the slice's plane blocks, as pseudo-angles ([`pseudo_angle`]), if it does not pass through the
/// origin (rays towards a light at infinity, or a segment already clipped to what lies before a finite one).
pub fn segment_interval([(mut s0, mut t0), (mut s1, mut t1)]: [(f64, f64); 2]) -> Option<(f64, f64)> {
    if t0 < 0.0 && t1 < 0.0 {
        return None;
    }
    // Clipped to t ≥ 0: the part below the axis line is behind the half-plane (β would leave [0, π]).
    if t0 < 0.0 {
        s0 += (s1 - s0) * (-t0 / (t1 - t0));
        t0 = 0.0;
    } else if t1 < 0.0 {
        s1 += (s0 - s1) * (-t1 / (t0 - t1));
        t1 = 0.0;
    }
    // A segment through the origin (collinear with it, on both sides) blocks only its own line: nothing of measure.
    let cross = s0 * t1 - s1 * t0;
    if (s0 == 0.0 && t0 == 0.0) || (s1 == 0.0 && t1 == 0.0) || (cross == 0.0 && s0 * s1 + t0 * t1 < 0.0) {
        return None;
    }
    let (k0, k1) = (pseudo_angle(s0, t0), pseudo_angle(s1, t1));
    Some((k0.min(k1), k0.max(k1)))
}

/// The interval of β that the triangle `tri` (corners relative to the rays' origin, in metres) blocks for rays
/// towards a light at infinity: [`slice_segment`], then [`segment_interval`]. `m = c × p` is the plane's unit
/// normal.
pub fn blocked_interval(tri: [DVec3; 3], c: DVec3, p: DVec3, m: DVec3) -> Option<(f64, f64)> {
    slice_segment(tri, c, p, m).and_then(segment_interval)
}

/// The interval of β on the half circle `cos β c + sin β p` where `k·ω ≥ 0`: `k·ω = R cos(β − φ)` with
/// `φ = atan2(k·p, k·c)`, non-negative on `[φ − π/2, φ + π/2]` (mod 2π), of which `[0, π]` keeps one interval.
pub fn above(k: DVec3, c: DVec3, p: DVec3) -> (f64, f64) {
    let phi = k.dot(p).atan2(k.dot(c));
    if phi < -FRAC_PI_2 {
        (phi + 1.5 * PI, PI)
    } else if phi <= FRAC_PI_2 {
        (0.0, phi + FRAC_PI_2)
    } else {
        (phi - FRAC_PI_2, PI)
    }
}

/// `∫_{b0}^{b1} (n·ω) sin β dβ = (n·c) ∫ cos β sin β + (n·p) ∫ sin²β`, the first as
/// `(sin²b1 − sin²b0)/2 = sin(b1 − b0) sin(b1 + b0)/2` (no cancellation for a short interval).
pub fn weight_integral(n_c: f64, n_p: f64, b0: f64, b1: f64) -> f64 {
    if b1 <= b0 {
        return 0.0;
    }
    0.5 * n_c * (b1 - b0).sin() * (b1 + b0).sin() + n_p * sin_squared_integral(b0, b1)
}

/// The weight over `[lo, hi]` (β) less the union of `blocked` (pseudo-angles, sorted here), by the gaps between
/// them; a gap's end at the span's own end keeps its exact β.
pub fn visible_weight(n_c: f64, n_p: f64, span: (f64, f64), blocked: &mut [(f64, f64)]) -> f64 {
    let keys = (beta_key(span.0), beta_key(span.1));
    gaps_weight(blocked, (span, keys), angle_of, |b0, b1| weight_integral(n_c, n_p, b0, b1))
}

/// The pseudo-angle of β ([`pseudo_angle`] of its direction), by which [`visible_weight`] compares a span's ends
/// with the intervals.
fn beta_key(b: f64) -> f64 {
    pseudo_angle(b.cos(), b.sin())
}

/// The sum of `weight` over the gaps that the union of `blocked` (pseudo-angles, sorted here by their starts)
/// leaves in `[lo, hi]` (angles whose pseudo-angles are `key_lo` and `key_hi`; `angle` turns a pseudo-angle
/// back): one walk in order of the starts, a gap wherever the next start lies beyond the furthest end reached; a
/// gap's end at the span's own end keeps its exact angle. The union's walk of [`visible_weight`] (β) and of
/// `slices_about_centre::visible_weight_about_centre` (γ).
pub fn gaps_weight(
    blocked: &mut [(f64, f64)],
    ((lo, hi), (key_lo, key_hi)): ((f64, f64), (f64, f64)),
    angle: impl Fn(f64) -> f64,
    weight: impl Fn(f64, f64) -> f64,
) -> f64 {
    blocked.sort_unstable_by(|x, y| x.0.total_cmp(&y.0));
    let mut visible = 0.0;
    let mut reached = key_lo;
    let at = |k: f64| {
        if k == key_lo {
            lo
        } else if k == key_hi {
            hi
        } else {
            angle(k)
        }
    };
    for &(k0, k1) in blocked.iter() {
        if k0 >= key_hi {
            break;
        }
        if k0 > reached {
            visible += weight(at(reached), at(k0));
        }
        reached = reached.max(k1);
    }
    if reached < key_hi {
        visible += weight(at(reached), hi);
    }
    visible
}

/// One row of a light's slices: the visible weight over `span` (β) of the half circle in the row's plane, whose
/// unoccluded weight is `whole`, less the union of the `intervals` its triangles block. `blocked` is the rows'
/// shared buffer.
pub fn row_visible_weight(
    intervals: impl Iterator<Item = (f64, f64)>,
    (n_c, n_p): (f64, f64),
    (span, whole): ((f64, f64), f64),
    blocked: &mut Vec<(f64, f64)>,
) -> f64 {
    // Only the intervals that reach into the span are kept: gaps_weight passes over the others without effect (one
    // that starts at or past the span's end, or ends at or before its start), and one that covers the whole span
    // leaves nothing, whatever the rest: the same weight, bit for bit, with fewer intervals to make and to sort
    // (a sun's chord, half a degree long, is mostly wholly in or wholly out of a triangle's interval).
    //
    // An interval that overlaps or touches the last one kept is merged into it: the union, and so every gap, is
    // the same, bounded by the same ends, so the walk adds the same weights in the same order, bit for bit. A
    // row's triangles come in the tree's order, neighbours in a mesh one after another, so a body's chain of
    // overlapping intervals becomes one, and the sort that follows has a few to order instead of hundreds.
    let (key_lo, key_hi) = (beta_key(span.0), beta_key(span.1));
    blocked.clear();
    let mut any = false;
    for (k0, k1) in intervals {
        any = true;
        if k0 <= key_lo && k1 >= key_hi {
            return 0.0;
        }
        if k0 < key_hi && k1 > key_lo {
            match blocked.last_mut() {
                Some(last) if k0 <= last.1 && k1 >= last.0 => *last = (last.0.min(k0), last.1.max(k1)),
                _ => blocked.push((k0, k1)),
            }
        }
    }
    if any {
        gaps_weight(blocked, (span, (key_lo, key_hi)), angle_of, |b0, b1| weight_integral(n_c, n_p, b0, b1))
    } else {
        whole
    }
}

/// Row `i` of `rows` at the midpoint `u = π (i + ½) / rows` of `[0, π]`: `(sin u, cos u)`. A light's rows run along
/// `ψ = ψ_mid − ψ_half cos u` (weight `ψ_half sin u`), so that chords whose length falls to zero like a square root
/// at both ends of `ψ` leave a smooth integrand in `u` (`sun_slices`, `disk_slices`).
pub fn cosine_row(i: u32, rows: u32) -> (f64, f64) {
    (std::f64::consts::PI * (i as f64 + 0.5) / rows as f64).sin_cos()
}

/// One of a light's rows across it ([`cosine_rows`]): `sin u` (its weight's factor), `ψ`, `sin ψ`, `cos ψ` and its
/// direction `p = cos ψ h + sin ψ q`.
#[derive(Clone, Copy, Debug)]
pub struct CosineRow {
    pub sin_u: f64,
    pub psi: f64,
    pub sin_psi: f64,
    pub cos_psi: f64,
    pub p: DVec3,
}

/// The `rows` rows [`cosine_row`] spaces along `ψ = ψ_mid − ψ_half cos u` across a light in direction `h`, `q`
/// across it, ascending in ψ.
pub fn cosine_rows(h: DVec3, q: DVec3, (psi_mid, psi_half): (f64, f64), rows: u32) -> Vec<CosineRow> {
    (0..rows)
        .map(|i| {
            let (sin_u, cos_u) = cosine_row(i, rows);
            let psi = psi_mid - psi_half * cos_u;
            let (sin_psi, cos_psi) = psi.sin_cos();
            CosineRow { sin_u, psi, sin_psi, cos_psi, p: cos_psi * h + sin_psi * q }
        })
        .collect()
}

/// `Σ visible / Σ total` over a light's rows: exactly 1 where every row was clear (the same sums), and 1 where the
/// light gives nothing.
pub fn rows_fraction(visible: f64, total: f64) -> f64 {
    if visible == total || total <= 0.0 {
        1.0
    } else {
        visible / total
    }
}

/// The rows `taken` of a light's rows, the part the sky's, the sun's and disk lights' slices share: one walk within
/// `reach` gathers the triangles `keep` keeps (a light's own test of a whole triangle, [`RowBuckets::gather`], with
/// their arcs in `frame` across the axis);
/// where it keeps none, `(0, 0)` at once, before any row is made (every row clear, whichever rows are taken: the
/// fraction is 1, [`rows_fraction`]). Otherwise `rows()` makes the rows, each filed with its triangles
/// ([`RowBuckets::file`]: `direction` a row's unit direction), and `row(i, row, buckets,
/// blocked)` gives row `i`'s visible and unoccluded weights (`None` where the row gives nothing; `blocked` the
/// rows' shared buffer), summed in the rows' order over those taken. `None` where the occluders cannot be sliced.
/// Within [`with_pixel_cache`](super::slice_buckets::with_pixel_cache) the gathering of a walk is kept for the
/// same walk at the next grid (only the filing is done again). (The GPU takes a light's rows in passes where one
/// fragment cannot take them all, `gpu::slice_passes`.)
pub fn sliced_rows_weights<R>(
    s: &Shadowing,
    reach: &SliceReach,
    keep: impl Fn(&[DVec3; 3]) -> bool,
    (frame, rows, direction): ((DVec3, DVec3), impl FnOnce() -> Vec<R>, impl Fn(&R) -> DVec3),
    taken: std::ops::Range<u32>,
    mut row: impl FnMut(usize, &R, &RowBuckets, &mut Vec<(f64, f64)>) -> Option<(f64, f64)>,
) -> Option<(f64, f64)> {
    let mut buckets = match take_kept(reach, frame) {
        Some(kept) => kept,
        None => {
            let mut fresh = RowBuckets::default();
            if !fresh.gather(s, reach, frame, keep) {
                return None;
            }
            fresh
        }
    };
    if buckets.is_empty() {
        keep_gathered(reach, frame, buckets);
        return Some((0.0, 0.0));
    }
    let rows = rows();
    buckets.file(rows.iter().map(direction));
    let (mut visible, mut total) = (0.0, 0.0);
    let mut blocked = Vec::new();
    let taken = taken.start as usize..taken.end as usize;
    for (i, r) in rows.iter().enumerate().skip(taken.start).take(taken.len()) {
        if let Some((v, w)) = row(i, r, &buckets, &mut blocked) {
            visible += v;
            total += w;
        }
    }
    keep_gathered(reach, frame, buckets);
    Some((visible, total))
}

/// A light's visible fraction by all its `rows` ([`sliced_rows_weights`] of every row, [`rows_fraction`]).
pub fn sliced_fraction<R>(
    s: &Shadowing,
    reach: &SliceReach,
    keep: impl Fn(&[DVec3; 3]) -> bool,
    (frame, rows, direction): ((DVec3, DVec3), impl FnOnce() -> Vec<R>, impl Fn(&R) -> DVec3),
    count: u32,
    row: impl FnMut(usize, &R, &RowBuckets, &mut Vec<(f64, f64)>) -> Option<(f64, f64)>,
) -> Option<f64> {
    let (visible, total) = sliced_rows_weights(s, reach, keep, (frame, rows, direction), 0..count, row)?;
    Some(rows_fraction(visible, total))
}

/// The sky's row of direction `p` about the axis `c` for a surface of unit normal `n` ([`sky_row`]).
struct SkyRow {
    /// `(n·c, n·p)`.
    n_cp: (f64, f64),
    /// The span of β above both horizons, and its unoccluded weight.
    span: (f64, f64),
    whole: f64,
}

/// The sky's row of direction `p`, or `None` where it gives the sky nothing.
fn sky_row(n: DVec3, c: DVec3, p: DVec3) -> Option<SkyRow> {
    let (ground, surface) = (above(DVec3::Y, c, p), above(n, c, p));
    let span = (ground.0.max(surface.0), ground.1.min(surface.1));
    let (n_c, n_p) = (n.dot(c), n.dot(p));
    let whole = weight_integral(n_c, n_p, span.0, span.1);
    (whole > 0.0).then_some(SkyRow { n_cp: (n_c, n_p), span, whole })
}

/// The sky's cosine-weighted visible fraction from `s.origin` on a surface of unit normal `n`, by `rows` slices
/// (module text), or `None` where the occluders cannot be sliced (a triangle partly cut away by an alpha mask):
/// then the caller casts rays. Exactly 1 where no row meets an occluder (the same sums), and 1 where the sky
/// gives nothing (a surface facing straight down).
pub fn sky_visible_fraction_sliced(s: &Shadowing, n: DVec3, rows: u32) -> Option<f64> {
    let (c, p1, p2) = sky_frame();
    let count = rows.max(1);
    let rows = || {
        midpoint_rows(count)
            .map(|psi| {
                let (sin_p, cos_p) = psi.sin_cos();
                cos_p * p1 + sin_p * p2
            })
            .collect()
    };
    // One walk for all rows: the triangles above both horizons, each filed under the rows its arc about the axis
    // holds (`slice_buckets`); a row then tests only its own.
    let reach = SliceReach { origin: s.origin, above: [DVec3::Y, n], cone: None, beyond: None, row: None };
    sliced_fraction(
        s,
        &reach,
        |_| true,
        ((p1, p2), rows, |&p: &DVec3| p),
        count,
        |i, &p, buckets, blocked| {
            let SkyRow { n_cp: (n_c, n_p), span, whole } = sky_row(n, c, p)?;
            let m = c.cross(p);
            let row = buckets.row(i).filter_map(|&tri| blocked_interval(tri, c, p, m));
            Some((row_visible_weight(row, (n_c, n_p), (span, whole), blocked), whole))
        },
    )
}

/// The slices' axis `c` and the frame `(p₁, p₂)` across it whose azimuths the rows' midpoints ψ run in:
/// `p₁ = c × z` normalised, `p₂ = c × p₁`.
fn sky_frame() -> (DVec3, DVec3, DVec3) {
    let c = DVec3::from_array(SLICE_AXIS);
    let p1 = c.cross(DVec3::Z).normalize();
    (c, p1, c.cross(p1))
}

/// One pass of the sky's slices, the GPU's unit of work (`gpu::slice_passes`, shaders/slices.glsl): the rows
/// `first .. first + count` of [`sky_visible_fraction_sliced`]'s `rows`, each walking the occluders for the
/// triangles its own half-plane may cut (`SliceReach::row`; a pixel's sky reaches more triangles than a fragment
/// gathers, a row's plane some hundred); `(visible, whole)` summed over them, or `None` where the occluders cannot
/// be sliced. Over passes covering every row, `rows_fraction` of the sums is the fraction by slices (the same rows,
/// the same triangles a row: tested).
pub fn sky_rows_weights(s: &Shadowing, n: DVec3, rows: u32, first: u32, count: u32) -> Option<(f64, f64)> {
    let (c, p1, p2) = sky_frame();
    let rows = rows.max(1);
    let (mut visible, mut total) = (0.0, 0.0);
    let mut triangles = Vec::new();
    let mut blocked = Vec::new();
    for i in first..first + count {
        let psi = std::f64::consts::TAU * (i as f64 + 0.5) / rows as f64;
        let (sin_p, cos_p) = psi.sin_cos();
        let p = cos_p * p1 + sin_p * p2;
        let Some(SkyRow { n_cp, span, whole }) = sky_row(n, c, p) else { continue };
        let m = c.cross(p);
        let reach = SliceReach { origin: s.origin, above: [DVec3::Y, n], cone: None, beyond: None, row: Some((p, m)) };
        triangles.clear();
        if !s.occluders.slice_triangles(&reach, &mut |tri| triangles.push(tri.map(|x| x - s.origin))) {
            return None;
        }
        let row = triangles.iter().filter_map(|&tri| blocked_interval(tri, c, p, m));
        visible += row_visible_weight(row, n_cp, (span, whole), &mut blocked);
        total += whole;
    }
    Some((visible, total))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shading::lights::sky::sky_visible_fraction;
    use crate::shading::visibility::{slice_rows, test_shadowing};
    use crate::shading::{Occlusion, Unoccluded};
    use crate::visibility::Bvh;

    fn shadowing(occ: &dyn Occlusion, k: u32) -> Shadowing<'_> {
        test_shadowing(occ, DVec3::ZERO, k)
    }

    /// Merging each interval into the last one kept where they overlap or touch leaves a row's weight as the walk
    /// over every interval gives it, bit for bit: chains of overlapping intervals (a mesh's neighbours), touching
    /// ones, nested ones, equal starts, intervals past the span's ends, in shuffled and in chained orders.
    #[test]
    fn merged_intervals_give_every_intervals_weight() {
        let mut r = crate::test_rng::uniform(0x9e3779b97f4a7c15);
        let (mut merged_away, mut rows) = (0usize, 0usize);
        for case in 0..4000 {
            let (n_c, n_p) = (r(), 0.5 + 0.5 * r().abs());
            let span = (0.4 + 0.3 * r(), 2.2 + 0.3 * r());
            let count = 1 + (case % 40);
            // Chains: each interval starts inside the one before (or at its end, or past it), in pseudo-angles.
            let mut k = -1.0 + 0.2 * r();
            let mut intervals: Vec<(f64, f64)> = (0..count)
                .map(|i| {
                    let start = if i % 7 == 3 { k + 0.05 * r().abs() } else { k - 0.02 * r().abs() };
                    let end = start + 0.01 + 0.08 * r().abs();
                    k = if i % 5 == 0 { end } else { 0.5 * (start + end) };
                    (start.clamp(-1.0, 1.0), end.clamp(-1.0, 1.0))
                })
                .collect();
            if case % 3 == 0 {
                // Shuffled: few merge.
                for i in (1..intervals.len()).rev() {
                    let j = ((r().abs() * (i + 1) as f64) as usize).min(i);
                    intervals.swap(i, j);
                }
            }
            let whole = weight_integral(n_c, n_p, span.0, span.1);
            let mut buffer = Vec::new();
            let got = row_visible_weight(intervals.iter().copied(), (n_c, n_p), (span, whole), &mut buffer);
            // The walk over every interval, none merged (what the merge must not change).
            let keys = (beta_key(span.0), beta_key(span.1));
            let covering = intervals.iter().any(|&(k0, k1)| k0 <= keys.0 && k1 >= keys.1);
            let mut all: Vec<(f64, f64)> =
                intervals.iter().copied().filter(|&(k0, k1)| k0 < keys.1 && k1 > keys.0).collect();
            let expected = if covering {
                0.0
            } else {
                gaps_weight(&mut all, (span, keys), angle_of, |b0, b1| weight_integral(n_c, n_p, b0, b1))
            };
            assert_eq!(got.to_bits(), expected.to_bits(), "case {case}: {intervals:?}");
            merged_away += all.len() - buffer.len().min(all.len());
            rows += 1;
        }
        // Not vacuous: intervals were merged.
        assert!(merged_away > rows, "{merged_away} merged over {rows} rows");
    }

    /// The roof `{y = 1, x cos θ + z sin θ < e}` as two triangles reaching `r` metres.
    fn roof(edge: f64, theta: f64, r: f64) -> Bvh {
        let (c, s) = (theta.cos(), theta.sin());
        // Along the edge u = (−s, 0, c); across it, towards the roof, −(c, 0, s).
        let at = |along: f64, across: f64| {
            DVec3::new(edge * c - along * s - across * c, 1.0, edge * s + along * c - across * s)
        };
        let (p, q, r2, t) = (at(-r, 0.0), at(r, 0.0), at(r, r), at(-r, r));
        Bvh::new(vec![[p, q, r2], [p, r2, t]])
    }

    #[test]
    fn sin_squared_integral_matches_its_textbook_form_and_keeps_short_intervals() {
        for (b0, b1) in [(0.0, PI), (0.3, 1.9), (1.0, 1.2), (2.5, 3.0), (0.1, 0.35)] {
            let textbook = 0.5 * (b1 - b0) - 0.25 * ((2.0 * b1).sin() - (2.0 * b0).sin());
            assert!((sin_squared_integral(b0, b1) - textbook).abs() < 1e-15, "{b0} {b1}");
        }
        // A short interval at the lune's end: ∫₀^Δ sin² = Δ³/3 − Δ⁵/15 + …; the textbook form keeps no digit.
        let d = 1e-6;
        let want = d * d * d / 3.0;
        assert!((sin_squared_integral(0.0, d) / want - 1.0).abs() < 1e-12);
        let textbook = 0.5 * d - 0.25 * (2.0 * d).sin();
        assert!((textbook / want - 1.0).abs() > 1e-6, "the textbook form lost digits: {textbook:e}");
    }

    #[test]
    fn a_roof_over_a_floor_takes_its_closed_form() {
        // The floor's truth (visibility.rs' test of the located grid): ½ (1 − e/√(1 + e²)); a roof reaching 1e4 m
        // misses the directions within 1e-4 rad of the horizon, whose projected solid angle is ~1e-8 of the sky's.
        for edge in [0.3, -0.7, 0.0] {
            for theta in [0.0f64, 0.4, 1.1] {
                let occ = roof(edge, theta, 1e4);
                let truth = 0.5 * (1.0 - edge / (1.0 + edge * edge).sqrt());
                let mut errors = Vec::new();
                for rows in [64, 256, 1024] {
                    let got = sky_visible_fraction_sliced(&shadowing(&occ, 6), DVec3::Y, rows).unwrap();
                    errors.push((got - truth).abs());
                }
                // Second order in the rows (or better: a straight edge leaves the row integrand smooth).
                assert!(errors[2] < 1e-6, "edge {edge} θ {theta}: {errors:?}");
                assert!(errors[1] < 1e-5, "edge {edge} θ {theta}: {errors:?}");
            }
        }
    }

    #[test]
    fn slices_agree_with_the_located_grid_on_tilted_surfaces() {
        // The located grid converges at the second order (visibility.rs); at 512² it errs below 2.5/512² ≈ 1e-5.
        for (edge, theta) in [(0.3, 0.4), (-0.7, 1.1)] {
            let occ = roof(edge, theta, 1e4);
            for n in [DVec3::new(0.3, 1.0, 0.2).normalize(), DVec3::new(-0.8, 0.3, 0.2).normalize()] {
                let grid = sky_visible_fraction(&shadowing(&occ, 512), n);
                let sliced = sky_visible_fraction_sliced(&shadowing(&occ, 6), n, 2048).unwrap();
                assert!((grid - sliced).abs() < 1.5e-5, "edge {edge} θ {theta} n {n}: grid {grid} slices {sliced}");
            }
        }
    }

    /// `count` random triangles of corners within `size` \[m\] of centres scattered over a few metres above the
    /// origin's floor (seeded by `seed`).
    fn scattered_above(seed: u64, count: usize, size: f64) -> Vec<[DVec3; 3]> {
        let mut r = crate::test_rng::uniform(seed);
        (0..count)
            .map(|_| {
                let centre = DVec3::new(3.0 * r(), 0.2 + 2.0 * r().abs(), 3.0 * r());
                [0, 1, 2].map(|_| centre + size * DVec3::new(r(), r(), r()))
            })
            .collect()
    }

    /// The rows' buckets (`slice_buckets`) leave out no triangle a row's half-plane cuts: the fraction equals,
    /// to the bit, every row testing every triangle.
    #[test]
    fn buckets_give_what_every_row_testing_every_triangle_gives() {
        let tris = scattered_above(0x9e3779b97f4a7c15, 300, 0.6);
        let occ = Bvh::new(tris.clone());
        let c = DVec3::from_array(SLICE_AXIS);
        let p1 = c.cross(DVec3::Z).normalize();
        let p2 = c.cross(p1);
        for n in [DVec3::Y, DVec3::new(0.3, 1.0, 0.2).normalize(), DVec3::new(-0.8, 0.3, 0.2).normalize()] {
            let rows = 96;
            let (mut visible, mut total) = (0.0, 0.0);
            for psi in midpoint_rows(rows) {
                let (sin_p, cos_p) = psi.sin_cos();
                let p = cos_p * p1 + sin_p * p2;
                let Some(SkyRow { n_cp: (n_c, n_p), span, whole }) = sky_row(n, c, p) else { continue };
                let m = c.cross(p);
                let mut blocked: Vec<_> = tris.iter().filter_map(|&t| blocked_interval(t, c, p, m)).collect();
                visible += if blocked.is_empty() { whole } else { visible_weight(n_c, n_p, span, &mut blocked) };
                total += whole;
            }
            let every = rows_fraction(visible, total);
            let got = sky_visible_fraction_sliced(&shadowing(&occ, 6), n, rows).unwrap();
            assert!(every > 0.05 && every < 0.95, "{n}: {every}");
            assert_eq!(got, every, "{n}");
        }
    }

    /// The GPU's passes (a walk a row, [`sky_rows_weights`]) sum to the reference's fraction by slices (one walk
    /// for all rows, buckets), however the rows are cut into passes.
    #[test]
    fn passes_of_rows_walking_for_their_own_give_the_fraction_by_slices() {
        let occ = Bvh::new(scattered_above(0x2545f4914f6cdd1d, 400, 0.5));
        for n in [DVec3::Y, DVec3::new(0.3, 1.0, 0.2).normalize(), DVec3::new(-0.8, 0.3, 0.2).normalize()] {
            let s = shadowing(&occ, 6);
            let rows = slice_rows(6);
            let whole = sky_visible_fraction_sliced(&s, n, rows).unwrap();
            assert!(whole > 0.05 && whole < 0.95, "{n}: {whole}");
            for cuts in [vec![0, rows], vec![0, 1, 50, 51, 143, rows], vec![0, 7, 100, rows - 1, rows]] {
                let (mut visible, mut total) = (0.0, 0.0);
                for pass in cuts.windows(2) {
                    let (v, t) = sky_rows_weights(&s, n, rows, pass[0], pass[1] - pass[0]).unwrap();
                    visible += v;
                    total += t;
                }
                let passes = rows_fraction(visible, total);
                assert!((passes - whole).abs() < 1e-13, "{n} {cuts:?}: {passes} against {whole}");
            }
            assert_eq!(sky_rows_weights(&shadowing(&Unoccluded, 6), n, rows, 3, 40).map(|(v, t)| v == t), Some(true));
        }
    }

    #[test]
    fn nothing_above_is_exactly_one_and_a_box_over_the_point_is_zero() {
        for n in [DVec3::Y, DVec3::new(0.3, 1.0, 0.2).normalize(), DVec3::new(-0.8, -0.3, 0.2).normalize()] {
            assert_eq!(sky_visible_fraction_sliced(&shadowing(&Unoccluded, 6), n, 64), Some(1.0));
            // A closed cube of side 2 around the origin hides the whole sky.
            let c = |x: f64, y: f64, z: f64| DVec3::new(x, y, z);
            let v = [
                c(-1., -1., -1.),
                c(1., -1., -1.),
                c(1., 1., -1.),
                c(-1., 1., -1.),
                c(-1., -1., 1.),
                c(1., -1., 1.),
                c(1., 1., 1.),
                c(-1., 1., 1.),
            ];
            let faces = [[0, 1, 2, 3], [4, 5, 6, 7], [0, 1, 5, 4], [3, 2, 6, 7], [0, 3, 7, 4], [1, 2, 6, 5]];
            let tris = faces.iter().flat_map(|f| [[v[f[0]], v[f[1]], v[f[2]]], [v[f[0]], v[f[2]], v[f[3]]]]).collect();
            let occ = Bvh::new(tris);
            let got = sky_visible_fraction_sliced(&shadowing(&occ, 6), n, 64).unwrap();
            assert!(got.abs() < 1e-15, "{n}: {got}");
        }
    }
}
