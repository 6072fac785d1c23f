//! Which rows of a point's slices may cut each occluding triangle, from one walk of the occluders a point instead
//! of one a row.
//!
//! A light's slices (`sky_slices`, `sun_slices`, `disk_slices`) are half-planes `{o + s c + t p : t ≥ 0}` about
//! one axis `c` through the rays' origin `o`, the rows' directions `p` turning about it (the sky's over the whole
//! turn, the sun's and a disk light's across the light). A triangle is cut by a row's half-plane only if the row's
//! azimuth lies in the triangle's **azimuth range** about the axis: projected along `c` onto the plane across it,
//! the triangle is a triangle in 2D whose directions from the origin form an arc. That arc is the shortest one
//! holding its three corners' azimuths when it is shorter than a half-turn; a longer one means that the projection
//! surrounds (or touches) the origin, so that every half-plane may cut the triangle. So one walk of the occluders'
//! tree (culled by the slices' half-spaces, cone and near side, not by any plane) gathers the triangles, and each
//! goes to the rows inside its arc ([`RowBuckets::gather`], then [`RowBuckets::file`]); a row then cuts only its
//! own triangles, which the exact per-row test (`sky_slices::blocked_interval`, `disk_slices`' clipped one) still
//! decides.
//!
//! A point refined grid after grid (the converged reference, `--tolerance`'s refined pixels) walks the same tree
//! with the same walk at each grid: [`with_pixel_cache`] keeps each light's gathered triangles and their arcs from
//! one grid to the next, so that only their filing under the new rows is done again.
//!
//! The walk per row cost 42% of a sliced reference (overcast.glb at 128², 324 rows a pixel, `perf`), and grows
//! with the rows, where this one walk does not.
//!
//! **Conservative by construction.** Extra triangles in a row change nothing (their test finds no segment, or a
//! segment whose interval lies outside the row's span, which the union of intervals ignores), so each arc is
//! widened by [`ARC_MARGIN`] and any doubt (a corner within rounding of the axis, an arc of nearly a half-turn)
//! sends the triangle to every row. Azimuths are compared as **diamond angles** ([`diamond_angle`]): monotone in
//! the angle, with the opposite direction exactly 2 further on (of 4 a turn), so the half-turn test is exact and no
//! `atan2` is spent a corner.

use std::f64::consts::TAU;

use glam::DVec3;

use super::visibility::{Shadowing, SliceReach};

/// The widening of each arc on both sides, in diamond-angle units (4 a turn): far above the rounding of a corner's
/// azimuth (a few ulps of its coordinates relative to its distance from the axis), far below a row's spacing.
pub const ARC_MARGIN: f64 = 1e-9;

/// The diamond angle of the direction `(x, y)` in [0, 4): 0 along +x, 1 along +y, 2 along −x, 3 along −y, linear
/// in `y/(|x| + |y|)` within each quadrant, so monotone in the angle; `(−x, −y)` lies exactly 2 further on (mod 4).
/// `(0, 0)` gives 0 (the caller sends a corner on the axis to every row before asking).
pub fn diamond_angle(x: f64, y: f64) -> f64 {
    let a = x.abs() + y.abs();
    if a == 0.0 {
        return 0.0;
    }
    if y >= 0.0 {
        if x >= 0.0 {
            y / a
        } else {
            1.0 - x / a
        }
    } else if x <= 0.0 {
        2.0 - y / a
    } else {
        3.0 + x / a
    }
}

/// The azimuth range of a triangle (corners relative to the origin) about the axis, as a diamond-angle arc
/// `(start, length)` widened by [`ARC_MARGIN`], or `None` where every row may cut it (the projection surrounds or
/// touches the axis, or a corner lies within rounding of it).
pub fn azimuth_arc(tri: &[DVec3; 3], p1: DVec3, p2: DVec3) -> Option<(f64, f64)> {
    let mut a = [0.0; 3];
    for (j, q) in tri.iter().enumerate() {
        let (x, y) = (q.dot(p1), q.dot(p2));
        // A corner this near the axis relative to its distance has an azimuth that rounding decides.
        let r = x.abs() + y.abs();
        if r * r <= 1e-24 * q.length_squared() {
            return None;
        }
        a[j] = diamond_angle(x, y);
    }
    // Sorted by a network of three exchanges.
    let (lo, hi) = (a[0].min(a[1]), a[0].max(a[1]));
    let a = [lo.min(a[2]), hi.min(a[2]).max(lo), hi.max(a[2])];
    // The largest gap between neighbours on the circle; the arc is the rest, starting after that gap.
    let gaps = [a[1] - a[0], a[2] - a[1], a[0] + 4.0 - a[2]];
    let (largest, &gap) = gaps.iter().enumerate().max_by(|x, y| x.1.total_cmp(y.1)).expect("three gaps");
    let length = 4.0 - gap;
    if length + 2.0 * ARC_MARGIN >= 2.0 {
        return None;
    }
    let start = a[(largest + 1) % 3];
    Some((start - ARC_MARGIN, length + 2.0 * ARC_MARGIN))
}

/// The triangles each row may cut: a counting sort of (row, triangle) pairs, filled once a point.
#[derive(Default)]
pub struct RowBuckets {
    /// The gathered triangles, corners relative to the origin \[m\].
    triangles: Vec<[DVec3; 3]>,
    /// Row `i`'s triangles are `members[start[i]..start[i + 1]]`.
    start: Vec<u32>,
    members: Vec<u32>,
    /// The rows' diamond angles, ascending (their azimuths ascend in [0, 2π)).
    row_angles: Vec<f64>,
    /// Each triangle's rows: two ranges of indices (the second empty unless its arc wraps past angle 0).
    ranges: Vec<[(usize, usize); 2]>,
    /// The counting sort's next free slot a row.
    next: Vec<u32>,
    /// The frame `(e1, e2)` across the axis, and each gathered triangle's [`azimuth_arc`] in it: found once a
    /// gathering, whatever rows it is filed under.
    frame: (DVec3, DVec3),
    arcs: Vec<Option<(f64, f64)>>,
}

impl RowBuckets {
    /// Gathers the triangles of one walk within `walk` (the slices' half-spaces, cone and near side) that `keep`
    /// keeps (a light's own test of a whole triangle, once rather than once a row), with their arcs about the axis
    /// in `frame` (`(e1, e2)`, an orthonormal pair across the axis). False where the occluders cannot be sliced.
    /// [`RowBuckets::file`] then files them under the rows, as often as a finer grid of the same point asks
    /// ([`with_pixel_cache`]).
    pub fn gather(
        &mut self,
        s: &Shadowing,
        walk: &SliceReach,
        frame: (DVec3, DVec3),
        keep: impl Fn(&[DVec3; 3]) -> bool,
    ) -> bool {
        self.triangles.clear();
        let origin = walk.origin;
        let triangles = &mut self.triangles;
        let gather = &mut |tri: [DVec3; 3]| {
            let tri = tri.map(|x| x - origin);
            if keep(&tri) {
                triangles.push(tri);
            }
        };
        let sliced = s.occluders.slice_triangles(walk, gather);
        self.frame = frame;
        self.arcs.clear();
        self.arcs.extend(self.triangles.iter().map(|tri| azimuth_arc(tri, frame.0, frame.1)));
        sliced
    }

    /// Files each gathered triangle under the rows inside its arc about the axis, `rows` the rows' unit directions
    /// `p` across it, their azimuths in the gathering's frame from `e1` towards `e2` ascending in [0, 2π).
    pub fn file(&mut self, rows: impl Iterator<Item = DVec3>) {
        let (e1, e2) = self.frame;
        self.row_angles.clear();
        self.row_angles.extend(rows.map(|p| diamond_angle(p.dot(e1), p.dot(e2))));
        let rows = self.row_angles.len();
        // Each triangle's rows as a range of indices (two where its arc wraps past angle 0), found once.
        let angles = &self.row_angles;
        let from = |x: f64| angles.partition_point(|&r| r < x);
        let to = |x: f64| angles.partition_point(|&r| r <= x);
        self.ranges.clear();
        self.ranges.extend(self.arcs.iter().map(|&arc| match arc {
            None => [(0, rows), (0, 0)],
            Some((start, length)) => {
                let lo = start.rem_euclid(4.0);
                let hi = lo + length;
                if hi < 4.0 {
                    [(from(lo), to(hi)), (0, 0)]
                } else {
                    [(from(lo), rows), (0, to(hi - 4.0))]
                }
            }
        }));
        self.start.clear();
        self.start.resize(rows + 1, 0);
        for &(a, b) in self.ranges.iter().flatten() {
            for i in a..b {
                self.start[i + 1] += 1;
            }
        }
        for i in 0..rows {
            self.start[i + 1] += self.start[i];
        }
        self.members.clear();
        self.members.resize(self.start[rows] as usize, 0);
        self.next.clear();
        self.next.extend_from_slice(&self.start[..rows]);
        for (t, two) in self.ranges.iter().enumerate() {
            for &(a, b) in two {
                for i in a..b {
                    self.members[self.next[i] as usize] = t as u32;
                    self.next[i] += 1;
                }
            }
        }
    }

    /// Whether the walk kept no triangle (then every row is clear).
    pub fn is_empty(&self) -> bool {
        self.triangles.is_empty()
    }

    /// The triangles row `i` may cut, corners relative to the origin \[m\].
    pub fn row(&self, i: usize) -> impl Iterator<Item = &[DVec3; 3]> {
        let (a, b) = (self.start[i] as usize, self.start[i + 1] as usize);
        self.members[a..b].iter().map(|&t| &self.triangles[t as usize])
    }
}

/// What one light's walk gathered at one point: the walk ([`SliceReach`]) and the rows' frame, compared bit for bit.
/// A point's lights differ in their walks (the sky's has no cone and no near side, the sun's a cone without a near
/// side, a disk light's a near side), and the triangles a light keeps follow from its walk's geometry.
#[derive(Clone, Copy, PartialEq, Eq)]
struct GatherKey([u64; 30]);

impl GatherKey {
    /// The walk's and the frame's numbers as bits (an absent cone, near side or row as NaNs, which no present
    /// one has).
    fn new(r: &SliceReach, (e1, e2): (DVec3, DVec3)) -> Self {
        let none = DVec3::splat(f64::NAN);
        let (axis, cos, sin) = r.cone.unwrap_or((none, f64::NAN, f64::NAN));
        let (k, b) = r.beyond.unwrap_or((none, f64::NAN));
        let (p, m) = r.row.unwrap_or((none, none));
        let vectors = [r.origin, r.above[0], r.above[1], axis, k, p, m, e1, e2];
        let scalars = [cos, sin, b];
        let mut key = [0u64; 30];
        let numbers = vectors.iter().flat_map(|v| v.to_array()).chain(scalars);
        for (slot, x) in key.iter_mut().zip(numbers) {
            *slot = x.to_bits();
        }
        Self(key)
    }
}

/// The most gatherings a pixel keeps (one a light: the sun, the sky, disk lights).
const PIXEL_CACHE_ENTRIES: usize = 8;

thread_local! {
    /// The gatherings kept while a pixel is shaded at its grids in turn (`None` outside [`with_pixel_cache`]).
    static PIXEL_CACHE: std::cell::RefCell<Option<Vec<(GatherKey, RowBuckets)>>> = const { std::cell::RefCell::new(None) };
}

/// Runs `f` (one pixel shaded at successive grids, on this thread: the refinements of `accuracy::converged`) with
/// each light's gathering kept from one grid to the next: a finer grid of the same point walks the same tree
/// with the same walk and keeps the same triangles with the same arcs, so only their filing under the new rows is
/// done again. Nothing outlives `f`, so no other pixel, scene or occluders can meet what it kept.
pub fn with_pixel_cache<T>(f: impl FnOnce() -> T) -> T {
    let before = PIXEL_CACHE.with(|c| c.borrow_mut().replace(Vec::new()));
    let result = f();
    PIXEL_CACHE.with(|c| *c.borrow_mut() = before);
    result
}

/// The gathering kept for this walk and frame, taken out of the cache (`None`: none kept, or no cache).
pub(crate) fn take_kept(reach: &SliceReach, frame: (DVec3, DVec3)) -> Option<RowBuckets> {
    PIXEL_CACHE.with(|c| {
        let mut c = c.borrow_mut();
        let entries = c.as_mut()?;
        let key = GatherKey::new(reach, frame);
        let i = entries.iter().position(|(k, _)| *k == key)?;
        Some(entries.remove(i).1)
    })
}

/// Keeps `buckets` for this walk and frame where a cache is on ([`with_pixel_cache`]), the oldest dropped past
/// [`PIXEL_CACHE_ENTRIES`].
pub(crate) fn keep_gathered(reach: &SliceReach, frame: (DVec3, DVec3), buckets: RowBuckets) {
    PIXEL_CACHE.with(|c| {
        if let Some(entries) = c.borrow_mut().as_mut() {
            if entries.len() == PIXEL_CACHE_ENTRIES {
                entries.remove(0);
            }
            entries.push((GatherKey::new(reach, frame), buckets));
        }
    });
}

/// The angles of `rows` midpoint rows over the whole circle \[rad\], ascending in (0, 2π).
pub fn midpoint_rows(rows: u32) -> impl Iterator<Item = f64> {
    (0..rows).map(move |i| TAU * (i as f64 + 0.5) / rows as f64)
}

/// The frame across an axis in which rows `p(ψ) = cos ψ h + sin ψ q`, `ψ ∈ (−π/2, π/2)` ascending (the sun's and
/// disk lights' slices about an axis across the light's direction `h`), have ascending azimuths: `(−q, h)`, in
/// which `p(ψ)` lies at `π/2 + ψ`.
pub fn frame_about(h: DVec3, q: DVec3) -> (DVec3, DVec3) {
    (-q, h)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn diamond_angles_increase_with_the_angle_and_opposites_lie_two_apart() {
        let mut last = -1.0;
        for i in 0..4096 {
            let t = TAU * i as f64 / 4096.0;
            let (s, c) = t.sin_cos();
            let d = diamond_angle(c, s);
            assert!(d > last && (0.0..4.0).contains(&d), "{t}: {d} after {last}");
            last = d;
            let opposite = diamond_angle(-c, -s);
            assert!(((opposite - d).rem_euclid(4.0) - 2.0).abs() < 1e-15, "{t}: {d} {opposite}");
        }
    }

    /// Every half-plane that cuts a triangle (by brute force: the plane separates its corners and the cut lies on
    /// the half-plane's side) lies in its arc.
    #[test]
    fn every_row_that_cuts_a_triangle_lies_in_its_arc() {
        let (p1, p2) = (DVec3::X, DVec3::Y);
        let mut r = crate::test_rng::uniform(0x2545f4914f6cdd1d);
        let mut surrounding = 0;
        for _ in 0..2000 {
            let tri = [0, 1, 2].map(|_| DVec3::new(r(), r(), r()) * 3.0);
            let arc = azimuth_arc(&tri, p1, p2);
            surrounding += arc.is_none() as u32;
            for i in 0..720 {
                let psi = TAU * (i as f64 + 0.5) / 720.0;
                let (s, c) = psi.sin_cos();
                let p = c * p1 + s * p2;
                let m = DVec3::Z.cross(p);
                let cut = crate::shading::sky_slices::blocked_interval(tri, DVec3::Z, p, m).is_some();
                let inside = arc.is_none_or(|(start, length)| (diamond_angle(c, s) - start).rem_euclid(4.0) <= length);
                assert!(!cut || inside, "{tri:?} row {psi}: cut outside its arc {arc:?}");
            }
        }
        // Both kinds occur: arcs, and projections around the axis.
        assert!(surrounding > 20 && surrounding < 1900, "{surrounding}");
    }
}
