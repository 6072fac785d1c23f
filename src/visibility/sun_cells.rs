//! The sun's cells: the occluders binned by where they lie across the sun's direction, so that the shadow rays of
//! a point towards the sun test the triangles of one cell only, and a point whose whole sun cone provably misses
//! every one of them (or lies within one opaque triangle) casts no ray at all. The GPU's shadow rays to the sun
//! use them on every device (shaders/sun_cells.glsl mirrors this file name for name); the reference keeps its
//! f64 rays through the BVH, an independent computation of the same visible fractions.
//!
//! **Which triangles a point's sun rays can meet.** Every direction ω of the sun's disk lies within the half-angle
//! σ of the direction `l` to its centre. A point `q = x + tω` of such a ray lies at depth `(q − x)·l = t ω·l ≥
//! t cos σ` along `l` and at distance `t |ω − (ω·l) l| ≤ t sin σ` across it, so `|(q − x)⊥| ≤ tan σ (q − x)·l`.
//! A triangle whose corners lie at depths at most `z_T` (`z = p·l`) can therefore block a sun ray from `x` only
//! where `x`'s projection across `l` lies within `tan σ (z_T − z_x)` of the triangle's projection. Each triangle is
//! binned into the cells under its projection's bounding box grown by `tan σ (z_T − z_lo)` plus a margin, `z_lo`
//! at or below the depth of every ray origin: then the cell of `x`'s projection holds every triangle `x`'s sun rays
//! can meet (a delta sun is the case σ = 0; the lobes' samples over the disk lie within σ too).
//!
//! A ray from `x` moves towards the sun (`ω·l > 0`), so it cannot meet a triangle whose highest corner along `l`
//! lies at or below `x`'s depth: each cell's triangles are sorted by that height, highest first, and a point tests
//! only those above it (on a lit surface, its cell's triangles mostly lie below it).
//!
//! **Ray origins.** They lie on the scene's triangles, moved by Hanika's terminator offset (at most the distance
//! to the triangle's farthest corner) and the push along the face normal (`2⁻¹⁶` of the largest coordinate):
//! `z_lo` is the lowest corner depth less the longest edge and `2⁻¹²` of the largest coordinate.
//!
//! **Margin for f32.** The shader projects the origin in f32: a dot product of coordinates up to `M` (the largest
//! magnitude) with a unit axis stored in f32, then a subtraction and a scaling to cells: a few roundings of
//! `2⁻²⁴` relative on quantities below `2M`. The boxes are grown by `2⁻¹⁶ M` besides, some hundreds of times that,
//! so that an origin near a cell's side finds every triangle of either side in its cell.
//!
//! **Classification** ([`sun_triangle_class`]): the cone of half-angle σ about `l` from the ray origin `p` against
//! one triangle. The directions from `p` that meet the triangle form the wedge `{d : s (m_i·d) ≥ 0}` of the three
//! planes through `p` and its edges (`m_i = e_i × (c_{i+1} − c_i)`, `e_i = c_i − p`, `s` the sign of the triple
//! product `e_0·(e_1 × e_2)`). The cone misses the triangle where one plane has it wholly on its outer side
//! (`s m̂_i·l < −sin σ`), or where the triangle's own plane does (`p` on one side and every direction of the cone
//! leaving it: `h (n·l) ≥ 0` and `|n̂·l| > sin σ`, `h` the height of `p` above the plane); it lies within the
//! triangle where it is on the inner side of all three (`s m̂_i·l > sin σ`): every ray of the cone then meets
//! the triangle at some `t > 0`. A margin of `2⁻²⁰` on the sines leaves to the rays the directions that graze an
//! edge within rounding. First of all, a triangle that lies wholly below the tangent plane of the surface at `p`
//! (`n·(c_i − p) ≤ 0`, `n` the shading normal) misses every ray above that plane, and only those rays are cast:
//! a sample of the sun below the surface's horizon weighs nothing (the floor under a point, and the neighbours on
//! a convex surface, cost one test). A point whose cell's triangles all miss its cone sees the whole sun (the grid's rays all
//! get through: its fraction is exactly 1); one opaque triangle that holds the cone hides it (every ray blocked:
//! exactly 0 where the whole disk is above the surface's horizon). Anything else is a penumbra, and only there
//! does the grid cast its rays, each against the cell's triangles alone ([`sun_cells_occluded`]).
//!
//! Precision: `m_i` is formed from `e_i` and the edge vector `c_{i+1} − c_i`, not as `e_i × e_{i+1}`: for a small
//! triangle far from `p` the two `e` are nearly parallel and their cross product would cancel to the rounding of
//! their long components, where the edge vector carries the triangle's size with its own digits.

use glam::DVec3;

use super::ray_triangle::WatertightRay;

/// The most triangles above a point that its cell may hold for the point's rays to use it: a pixel in a penumbra
/// tests each of them once a ray (up to some 150 rays with a specular lobe), within llvmpipe's 65535 loop
/// iterations a fragment. A point with more (deep in a cell of a scene seen edge-on by a low sun) is
/// [`SunCone::Unknown`]: its sun rays walk the BVH or take the ray queries. The cells are refined until no cell
/// holds more, where they can.
pub const MAX_SUN_CELL_TRIANGLES: usize = 256;

/// The most triangles above a point that its classification tests where its cell holds more than
/// [`MAX_SUN_CELL_TRIANGLES`] above it: a cone proven clear or covered still casts no ray (one loop iteration a
/// triangle, well within llvmpipe's budget); only a penumbra there takes the traversal.
pub const MAX_SUN_CELL_CLASSIFIED: usize = 8192;

/// How many cells a triangle may be entered in on average before the cells are made coarser, unless the entries
/// are few in all (`FEW_SUN_CELL_ENTRIES`, 4 MiB on the device: quick to build and upload).
pub const ENTRIES_PER_TRIANGLE: usize = 4;
pub const FEW_SUN_CELL_ENTRIES: usize = 1 << 16;

/// The most entries (a triangle in a cell) the cells keep where the caller has no bound of its own: 2 Mi, 128 MiB
/// on the device (`gpu::sun_cells`: 64 bytes an entry), lavapipe's largest storage buffer.
pub const MAX_SUN_CELL_ENTRIES: usize = 1 << 21;

/// The margin on the sines of the classification: directions within it of an edge's plane are left to the rays.
pub const SUN_CONE_MARGIN: f64 = 1.0 / 1_048_576.0;

/// What one cell's triangles do to the sun's cone from a point (`SUN_CONE_*` in shaders/sun_cells.glsl).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SunCone {
    /// Every ray of the cone gets past every triangle: the whole sun is visible.
    Misses,
    /// One opaque triangle holds the whole cone: no ray gets through.
    Covered,
    /// Anything else: the grid's rays decide.
    Partial,
    /// Too many of the cell's triangles lie above the point: its rays take the traversal.
    Unknown,
}

/// The occluders binned across the sun's direction (see the module docs).
#[derive(Clone, Debug, PartialEq)]
pub struct SunCells {
    /// The unit direction to the sun's centre and two unit axes across it.
    pub l: DVec3,
    pub u: DVec3,
    pub v: DVec3,
    /// The projection `(x·u, x·v)` of the corner of cell (0, 0) \[m\].
    pub origin: [f64; 2],
    /// Cells per metre across `l` (one over a cell's side).
    pub per_metre: f64,
    /// Cells along `u` and `v`.
    pub dims: [u32; 2],
    /// Where each cell's triangles start in `triangles` (cell `i + dims[0] j`), and one past the last.
    pub starts: Vec<u32>,
    /// Indices of the triangles given to [`SunCells::build`], cell after cell.
    pub triangles: Vec<u32>,
    /// Each triangle's highest corner along `l` \[m\] (as built from), raised by the f32 margin: a ray from an
    /// origin at or above it cannot meet the triangle. A cell's triangles are sorted by it, highest first.
    pub tops: Vec<f64>,
}

impl SunCells {
    /// Bins `triangles` (world corners \[m\]) for a sun in direction `l` (need not be unit) of angular radius
    /// `half_angle` \[rad\], in at most `max_entries` entries (a triangle in a cell). `None` where `l` is not a
    /// direction, or where even one cell would hold more (more triangles than that).
    pub fn build(triangles: &[[DVec3; 3]], l: DVec3, half_angle: f64, max_entries: usize) -> Option<Self> {
        let l = l.try_normalize()?;
        let u = crate::shading::orthonormal_to(l);
        let v = l.cross(u);
        let magnitude = triangles.iter().flatten().map(|p| p.abs().max_element()).fold(0.0, f64::max);
        let longest = triangles
            .iter()
            .map(|[a, b, c]| (*a - *b).length().max((*b - *c).length()).max((*c - *a).length()))
            .fold(0.0, f64::max);
        let z_min = triangles.iter().flatten().map(|p| p.dot(l)).fold(f64::INFINITY, f64::min);
        let z_lo = z_min - longest - magnitude / 4096.0;
        let margin = magnitude / 65_536.0 + f64::MIN_POSITIVE;
        // tan σ, a little more for the f32 directions of the rays.
        let spread = half_angle.max(0.0).tan() * (1.0 + 1.0 / 1024.0);
        // Each triangle's grown box across l: [u0, v0, u1, v1].
        let tops: Vec<f64> =
            triangles.iter().map(|t| t.iter().map(|p| p.dot(l)).fold(f64::NEG_INFINITY, f64::max) + margin).collect();
        let boxes: Vec<[f64; 4]> = triangles
            .iter()
            .zip(&tops)
            .map(|(t, &z_top)| {
                let grow = spread * (z_top - z_lo) + margin;
                let (us, vs) = (t.map(|p| p.dot(u)), t.map(|p| p.dot(v)));
                let lo = |a: [f64; 3]| a[0].min(a[1]).min(a[2]) - grow;
                let hi = |a: [f64; 3]| a[0].max(a[1]).max(a[2]) + grow;
                [lo(us), lo(vs), hi(us), hi(vs)]
            })
            .collect();
        let (mut u0, mut v0, mut u1, mut v1) = (f64::INFINITY, f64::INFINITY, f64::NEG_INFINITY, f64::NEG_INFINITY);
        for b in &boxes {
            (u0, v0, u1, v1) = (u0.min(b[0]), v0.min(b[1]), u1.max(b[2]), v1.max(b[3]));
        }
        if boxes.is_empty() || !(u0.is_finite() && v0.is_finite() && u1.is_finite() && v1.is_finite()) {
            return Some(Self {
                l,
                u,
                v,
                origin: [0.0; 2],
                per_metre: 0.0,
                dims: [0, 0],
                starts: vec![0],
                triangles: Vec::new(),
                tops,
            });
        }
        // About two cells a triangle over the projected area, at most 1024 a side, coarser while the entries would
        // pass `max_entries` or four a triangle; then halved while a cell holds more than MAX_SUN_CELL_TRIANGLES, the cells can still
        // shrink, the entries stay within bounds and halving still empties the fullest cell by a tenth (a cell
        // smaller than the triangles' growth gains little: every point there sees the same grown boxes).
        let area = ((u1 - u0) * (v1 - v0)).max(f64::MIN_POSITIVE);
        let longest_side = (u1 - u0).max(v1 - v0);
        let count = |side: f64| Grid::count(&boxes, [u0, v0, u1, v1], side);
        let mut side = (area / (2.0 * triangles.len() as f64)).sqrt().max(longest_side / 1024.0);
        let mut grid = count(side);
        // Where the triangles' growth spans many cells (a tall scene under a low sun), coarser, to at most
        // ENTRIES_PER_TRIANGLE entries a triangle: every entry is a copy to build and to upload each frame.
        let budget = max_entries.min((ENTRIES_PER_TRIANGLE * triangles.len()).max(FEW_SUN_CELL_ENTRIES));
        while grid.entries() > budget {
            if grid.dims == [1, 1] {
                return None;
            }
            side *= 1.5;
            grid = count(side);
        }
        for _ in 0..8 {
            let fullest = grid.fullest();
            if fullest <= MAX_SUN_CELL_TRIANGLES || longest_side / (side / 2.0) > 1024.0 {
                break;
            }
            let finer = count(side / 2.0);
            if finer.entries() > max_entries || finer.fullest() * 10 > fullest * 9 {
                break;
            }
            (grid, side) = (finer, side / 2.0);
        }
        let cells = Self::fill(&boxes, &tops, &grid, [l, u, v]);
        Some(cells)
    }

    /// The boxes binned into `grid`'s cells (counting sort), each cell's triangles sorted by their tops, highest
    /// first.
    fn fill(boxes: &[[f64; 4]], tops: &[f64], grid: &Grid, [l, u, v]: [DVec3; 3]) -> Self {
        let starts = grid.starts.clone();
        let mut fill = starts.clone();
        let mut triangles = vec![0u32; *starts.last().unwrap() as usize];
        for (t, b) in boxes.iter().enumerate() {
            let (us, vs) = grid.span(b);
            for j in vs {
                for i in us.clone() {
                    let c = (i + grid.dims[0] * j) as usize;
                    triangles[fill[c] as usize] = t as u32;
                    fill[c] += 1;
                }
            }
        }
        for c in 0..starts.len() - 1 {
            let cell = &mut triangles[starts[c] as usize..starts[c + 1] as usize];
            cell.sort_unstable_by(|a, b| tops[*b as usize].total_cmp(&tops[*a as usize]));
        }
        let origin = [grid.origin[0], grid.origin[1]];
        Self { l, u, v, origin, per_metre: grid.per_metre, dims: grid.dims, starts, triangles, tops: tops.to_vec() }
    }

    /// The triangles of cell `c` (indices into the list built from), highest top first.
    pub fn cell(&self, c: usize) -> &[u32] {
        &self.triangles[self.starts[c] as usize..self.starts[c + 1] as usize]
    }

    /// The most triangles a cell holds.
    pub fn fullest(&self) -> usize {
        self.starts.windows(2).map(|w| (w[1] - w[0]) as usize).max().unwrap_or(0)
    }
}

/// The cells of one side over the grown boxes' extent, and how many boxes each holds (as `SunCells::starts`):
/// counted before any is filled, so that choosing the side costs one pass over the boxes a try.
struct Grid {
    origin: [f64; 2],
    per_metre: f64,
    dims: [u32; 2],
    starts: Vec<u32>,
}

impl Grid {
    /// Cells of `side` \[m\] over `[u0, v0, u1, v1]`, and the boxes counted into them.
    fn count(boxes: &[[f64; 4]], [u0, v0, u1, v1]: [f64; 4], side: f64) -> Self {
        let per_metre = 1.0 / side;
        let dims = [((u1 - u0) * per_metre).ceil().max(1.0) as u32, ((v1 - v0) * per_metre).ceil().max(1.0) as u32];
        let mut grid = Grid { origin: [u0, v0], per_metre, dims, starts: vec![0; (dims[0] * dims[1]) as usize + 1] };
        for b in boxes {
            let (us, vs) = grid.span(b);
            for j in vs {
                for i in us.clone() {
                    grid.starts[(i + dims[0] * j) as usize + 1] += 1;
                }
            }
        }
        for c in 1..grid.starts.len() {
            grid.starts[c] += grid.starts[c - 1];
        }
        grid
    }

    /// The cells a box covers, along u and along v.
    fn span(&self, b: &[f64; 4]) -> (std::ops::RangeInclusive<u32>, std::ops::RangeInclusive<u32>) {
        let cell = |x: f64, n: u32| ((x * self.per_metre).floor().max(0.0) as u32).min(n - 1);
        let [u0, v0] = self.origin;
        (
            cell(b[0] - u0, self.dims[0])..=cell(b[2] - u0, self.dims[0]),
            cell(b[1] - v0, self.dims[1])..=cell(b[3] - v0, self.dims[1]),
        )
    }

    fn entries(&self) -> usize {
        *self.starts.last().unwrap() as usize
    }

    fn fullest(&self) -> usize {
        self.starts.windows(2).map(|w| (w[1] - w[0]) as usize).max().unwrap_or(0)
    }
}

/// The cell whose triangles the sun rays from `origin` can meet, or `None` where it lies outside every cell (no
/// triangle's grown box reaches it: nothing blocks its sun).
pub fn sun_cell_of(cells: &SunCells, origin: DVec3) -> Option<usize> {
    let i = ((origin.dot(cells.u) - cells.origin[0]) * cells.per_metre).floor();
    let j = ((origin.dot(cells.v) - cells.origin[1]) * cells.per_metre).floor();
    let inside = i >= 0.0 && j >= 0.0 && i < cells.dims[0] as f64 && j < cells.dims[1] as f64;
    inside.then(|| i as usize + cells.dims[0] as usize * j as usize)
}

/// The entries of `origin`'s cell whose tops lie above its depth along `l` (the only triangles its sun rays can
/// meet), as a range of `cells.triangles`: found by bisection, the cell's tops being sorted highest first. Empty
/// outside every cell.
pub fn sun_cell_range(cells: &SunCells, origin: DVec3) -> std::ops::Range<usize> {
    let Some(c) = sun_cell_of(cells, origin) else { return 0..0 };
    let depth = origin.dot(cells.l);
    let (start, end) = (cells.starts[c] as usize, cells.starts[c + 1] as usize);
    let above = cells.triangles[start..end].partition_point(|&t| cells.tops[t as usize] > depth);
    start..start + above
}

/// What the triangle `corners` does to the cone of half-angle asin(`sin_sigma`) about the unit `l` from `origin`
/// (see the module docs): misses every ray of it above the horizon of the surface's normal `n` (the rays the grid
/// and the lobes cast: their samples below it weigh nothing), holds it (every ray of it meets the triangle at
/// `t > 0`), or neither.
pub fn sun_triangle_class(origin: DVec3, n: DVec3, l: DVec3, sin_sigma: f64, corners: [DVec3; 3]) -> SunCone {
    if corners.iter().all(|c| n.dot(*c - origin) <= 0.0) {
        return SunCone::Misses;
    }
    cone_triangle_class(origin, l, sin_sigma, corners)
}

/// What the triangle `corners` does to the cone of half-angle asin(`sin_sigma`) about the unit `l` from `origin`,
/// its rays of any length and direction within it (no surface's horizon): [`sun_triangle_class`] after its
/// tangent plane; disk lights' cones use it too (`visibility::disk_cone`).
pub fn cone_triangle_class(origin: DVec3, l: DVec3, sin_sigma: f64, corners: [DVec3; 3]) -> SunCone {
    let limit = sin_sigma + SUN_CONE_MARGIN;
    let [c0, c1, c2] = corners;
    let normal = (c1 - c0).cross(c2 - c0);
    let h = normal.dot(origin - c0);
    let n_l = normal.dot(l);
    let n_len = normal.length();
    if h * n_l >= 0.0 && n_l.abs() > limit * n_len {
        return SunCone::Misses;
    }
    let e = [c0 - origin, c1 - origin, c2 - origin];
    let triple = e[0].dot(e[1].cross(e[2]));
    if triple == 0.0 {
        return SunCone::Partial;
    }
    let s = triple.signum();
    let mut inside = true;
    for i in 0..3 {
        let edge = corners[(i + 1) % 3] - corners[i];
        let m = e[i].cross(edge);
        let m_len = m.length();
        if m_len == 0.0 {
            return SunCone::Partial;
        }
        let c = s * m.dot(l);
        if c < -limit * m_len {
            return SunCone::Misses;
        }
        inside &= c > limit * m_len;
    }
    if inside {
        SunCone::Covered
    } else {
        SunCone::Partial
    }
}

/// What the cell's triangles do to the sun's cone from `origin` on a surface of normal `n`: [`SunCone::Covered`]
/// where one of them that is `opaque` holds it, [`SunCone::Misses`] where all miss its rays above the surface's
/// horizon, else [`SunCone::Partial`], or [`SunCone::Unknown`] where more than [`MAX_SUN_CELL_TRIANGLES`] lie above
/// it (its rays then take the traversal; more than [`MAX_SUN_CELL_CLASSIFIED`]: not classified at all).
pub fn sun_cone_class(
    cells: &SunCells,
    triangles: &[[DVec3; 3]],
    opaque: impl Fn(usize) -> bool,
    origin: DVec3,
    n: DVec3,
    sin_sigma: f64,
) -> SunCone {
    let range = sun_cell_range(cells, origin);
    if range.len() > MAX_SUN_CELL_CLASSIFIED {
        return SunCone::Unknown;
    }
    let past_rays = range.len() > MAX_SUN_CELL_TRIANGLES;
    let mut partial = false;
    for &t in &cells.triangles[range] {
        match sun_triangle_class(origin, n, cells.l, sin_sigma, triangles[t as usize]) {
            SunCone::Misses => {}
            SunCone::Covered if opaque(t as usize) => return SunCone::Covered,
            _ => partial = true,
        }
    }
    match (partial, past_rays) {
        (false, _) => SunCone::Misses,
        (true, false) => SunCone::Partial,
        (true, true) => SunCone::Unknown,
    }
}

/// Whether the sun rays from `origin` can be tested against its cell: at most [`MAX_SUN_CELL_TRIANGLES`] of its
/// triangles lie above it.
pub fn sun_cells_usable(cells: &SunCells, origin: DVec3) -> bool {
    sun_cell_range(cells, origin).len() <= MAX_SUN_CELL_TRIANGLES
}

/// Whether the ray from `origin` along `direction` (within the sun's cone) meets a triangle of its cell that
/// `blocks` it (given the triangle and the hit's distance): the cell's triangles above the origin are every one it
/// can meet. A ray that leaves above the surface's tangent plane (normal `n`, `n·direction > 0`) cannot meet a
/// triangle wholly below that plane, which is skipped before the ray test. `None` where the triangles above the
/// origin are too many ([`sun_cells_usable`]).
pub fn sun_cells_occluded(
    cells: &SunCells,
    triangles: &[[DVec3; 3]],
    mut blocks: impl FnMut(usize, f64) -> bool,
    (origin, n): (DVec3, DVec3),
    direction: DVec3,
) -> Option<bool> {
    let range = sun_cell_range(cells, origin);
    if range.len() > MAX_SUN_CELL_TRIANGLES {
        return None;
    }
    let Some(ray) = WatertightRay::new(origin, direction) else { return Some(false) };
    let leaves_above = n.dot(direction) > 0.0;
    Some(cells.triangles[range].iter().any(|&t| {
        let t = t as usize;
        let below = leaves_above && triangles[t].iter().all(|c| n.dot(*c - origin) <= 0.0);
        !below && ray.intersect(triangles[t], 0.0, f64::INFINITY).is_some_and(|hit| blocks(t, hit))
    }))
}

/// Whether the sun's ray from `origin` (on a surface of normal `n`) along `direction` (within its cone) gets
/// through: by the cells where there are some and the point is within their bound, else by the caller's
/// `occluded` (the BVH's walk, or the device's ray queries on the GPU).
pub fn sun_visible_along(
    cells: Option<&SunCells>,
    triangles: &[[DVec3; 3]],
    blocks: impl FnMut(usize, f64) -> bool,
    origin_and_normal: (DVec3, DVec3),
    direction: DVec3,
    occluded: impl FnOnce() -> bool,
) -> bool {
    match cells.and_then(|cells| sun_cells_occluded(cells, triangles, blocks, origin_and_normal, direction)) {
        Some(blocked) => !blocked,
        None => !occluded(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shading::visibility::concentric_disk;

    /// Uniform in [0, 1) from the tests' shared generator (`crate::test_rng`, in [−1, 1)).
    fn unit(r: &mut impl FnMut() -> f64) -> f64 {
        0.5 * (r() + 1.0)
    }

    /// A point of the cube of side `scale` about the origin.
    fn point(r: &mut impl FnMut() -> f64, scale: f64) -> DVec3 {
        DVec3::new(r(), r(), r()) * (0.5 * scale)
    }

    /// The sun's rays from `origin` through a k × k grid of the disk of radius tan σ (and its centre).
    fn cone_rays(l: DVec3, sigma: f64, k: u32) -> Vec<DVec3> {
        let t = crate::shading::orthonormal_to(l);
        let b = l.cross(t);
        let r = sigma.tan();
        let mut rays = vec![l];
        for i in 0..=k {
            for j in 0..=k {
                let (x, y) = concentric_disk(i as f64 / k as f64, j as f64 / k as f64);
                rays.push((l + r * (x * t + y * b)).normalize());
            }
        }
        rays
    }

    /// The classification is a proof: where a triangle misses the cone no ray of it meets the triangle, where it
    /// holds it every ray does; and the cell of every origin holds every triangle a ray of the cone meets, so the
    /// cell's answer is the brute-force answer over all triangles. Random triangle soups at scales 1 mm to 10 km,
    /// suns of 0.1° to 5° and low over the horizon.
    #[test]
    fn the_cells_and_the_classes_agree_with_every_ray_against_every_triangle() {
        let mut r = crate::test_rng::uniform(0x9e37_79b9_7f4a_7c15);
        let (mut misses, mut covered, mut partial) = (0, 0, 0);
        for case in 0..24 {
            let scale = [1e-3, 1.0, 1e4][case % 3];
            let sigma = [0.1f64, 0.53, 5.0][(case / 3) % 3].to_radians() / 2.0;
            let l = DVec3::new(0.5 * r(), 0.05 + unit(&mut r), 0.5 * r()).normalize();
            let triangles: Vec<[DVec3; 3]> = (0..60)
                .map(|_| {
                    let c = point(&mut r, scale);
                    let size = scale * (0.02 + 0.3 * unit(&mut r));
                    [c + point(&mut r, size), c + point(&mut r, size), c + point(&mut r, size)]
                })
                .collect();
            let cells = SunCells::build(&triangles, l, sigma, MAX_SUN_CELL_ENTRIES).expect("60 triangles fit");
            for _ in 0..400 {
                // Origins on the triangles (where shading points lie), pushed off them along the face normal as
                // the renderers push shadow rays' origins (2^-16 of the largest corner coordinate), on either side.
                let t = triangles[(unit(&mut r) * 60.0) as usize];
                let (a, b) = (unit(&mut r), unit(&mut r));
                let (a, b) = if a + b > 1.0 { (1.0 - a, 1.0 - b) } else { (a, b) };
                let push = t.iter().map(|p| p.abs().max_element()).fold(0.0, f64::max) / 65_536.0;
                let side = if r() < 0.0 { -1.0 } else { 1.0 };
                let face = (t[1] - t[0]).cross(t[2] - t[0]).normalize();
                let origin = t[0] + a * (t[1] - t[0]) + b * (t[2] - t[0]) + side * push * face;
                // A shading normal on that side, leaning from the face's by up to some 30 degrees.
                let n = (side * face + point(&mut r, 1.0)).normalize();
                let rays = cone_rays(l, sigma, 6);
                for (index, tri) in triangles.iter().enumerate() {
                    let meets = |d: &&DVec3| {
                        WatertightRay::new(origin, **d).unwrap().intersect(*tri, 0.0, f64::INFINITY).is_some()
                    };
                    let count = rays.iter().filter(meets).count();
                    // The rays that are cast: above the surface's horizon.
                    let cast = rays.iter().filter(|d| n.dot(**d) > 0.0).filter(meets).count();
                    match sun_triangle_class(origin, n, l, sigma.sin(), *tri) {
                        SunCone::Misses => assert_eq!(cast, 0, "case {case}: a ray meets a triangle said to miss"),
                        SunCone::Covered => assert_eq!(count, rays.len(), "case {case}: a ray passes a cover"),
                        SunCone::Partial | SunCone::Unknown => {}
                    }
                    if count > 0 {
                        let c = sun_cell_of(&cells, origin).expect("a ray meets a triangle: the origin has a cell");
                        assert!(cells.cell(c).contains(&(index as u32)), "case {case}: the cell lacks a triangle");
                        let above = &cells.triangles[sun_cell_range(&cells, origin)];
                        assert!(above.contains(&(index as u32)), "case {case}: a hit triangle lies below the cut");
                    }
                }
                match sun_cone_class(&cells, &triangles, |_| true, origin, n, sigma.sin()) {
                    SunCone::Misses => misses += 1,
                    SunCone::Covered => covered += 1,
                    SunCone::Partial => partial += 1,
                    SunCone::Unknown => panic!("case {case}: 60 triangles fill no cell"),
                }
                // Every ray that is cast (above the surface's horizon) gets the brute-force answer.
                for d in rays.iter().filter(|d| n.dot(**d) > 0.0) {
                    let all = triangles.iter().any(|tri| {
                        WatertightRay::new(origin, *d).unwrap().intersect(*tri, 0.0, f64::INFINITY).is_some()
                    });
                    assert_eq!(sun_cells_occluded(&cells, &triangles, |_, _| true, (origin, n), *d), Some(all));
                    let visible = sun_visible_along(Some(&cells), &triangles, |_, _| true, (origin, n), *d, || true);
                    assert_eq!(visible, !all);
                }
            }
        }
        // Each class occurs (the test would pass vacuously otherwise).
        assert!(misses > 100 && covered > 100 && partial > 100, "{misses} {covered} {partial}");
    }

    /// A floor under one small occluder: most of the floor's cells are empty or hold only the floor, whose own
    /// triangle misses the cone from above it; the cells stay within their bound.
    #[test]
    fn a_floor_point_away_from_the_occluder_sees_the_whole_sun() {
        let floor = [
            [DVec3::new(-5.0, 0.0, -5.0), DVec3::new(5.0, 0.0, -5.0), DVec3::new(5.0, 0.0, 5.0)],
            [DVec3::new(-5.0, 0.0, -5.0), DVec3::new(5.0, 0.0, 5.0), DVec3::new(-5.0, 0.0, 5.0)],
        ];
        let block = [DVec3::new(-0.5, 1.0, -0.5), DVec3::new(0.5, 1.0, -0.5), DVec3::new(0.0, 1.0, 0.5)];
        let triangles = vec![floor[0], floor[1], block];
        let sigma = 0.53f64.to_radians() / 2.0;
        let cells = SunCells::build(&triangles, DVec3::Y, sigma, MAX_SUN_CELL_ENTRIES).unwrap();
        assert!(cells.fullest() <= MAX_SUN_CELL_TRIANGLES);
        let above = |x: f64, z: f64| DVec3::new(x, 1e-4, z);
        let class = |p| sun_cone_class(&cells, &triangles, |_| true, p, DVec3::Y, sigma.sin());
        assert_eq!(class(above(3.0, 3.0)), SunCone::Misses);
        assert_eq!(class(above(0.0, 0.0)), SunCone::Covered);
        assert_eq!(class(above(0.0, -0.5)), SunCone::Partial);
        // A masked (not opaque) cover leaves the decision to the rays.
        let masked = sun_cone_class(&cells, &triangles, |t| t != 2, above(0.0, 0.0), DVec3::Y, sigma.sin());
        assert_eq!(masked, SunCone::Partial);
    }

    /// The entries stay within the caller's bound: coarser cells where the fine ones would pass it, none where
    /// even one cell would.
    #[test]
    fn the_cells_keep_within_their_entries() {
        let triangles: Vec<[DVec3; 3]> = (0..900)
            .map(|i| {
                let (x, z) = ((i % 30) as f64 * 0.1, (i / 30) as f64 * 0.1);
                [DVec3::new(x, 0.0, z), DVec3::new(x + 0.3, 0.0, z), DVec3::new(x, 0.0, z + 0.3)]
            })
            .collect();
        let free = SunCells::build(&triangles, DVec3::Y, 0.0046, MAX_SUN_CELL_ENTRIES).unwrap();
        let bounded = SunCells::build(&triangles, DVec3::Y, 0.0046, 2000).unwrap();
        assert!(free.triangles.len() > 2000 && bounded.triangles.len() <= 2000, "{}", free.triangles.len());
        assert!(SunCells::build(&triangles, DVec3::Y, 0.0046, 899).is_none());
    }

    /// Too many triangles over one spot (a stack of 400 coincident squares) cannot be split into cells: a point
    /// under more than MAX_SUN_CELL_TRIANGLES of them leaves its rays to the traversal, one above most of them (or
    /// beside the stack) keeps the cells.
    #[test]
    fn a_point_under_a_stack_deeper_than_a_cell_holds_takes_the_traversal() {
        let mut triangles: Vec<[DVec3; 3]> = (0..400)
            .map(|i| {
                let y = i as f64 * 0.01;
                [DVec3::new(0.0, y, 0.0), DVec3::new(1.0, y, 0.0), DVec3::new(0.0, y, 1.0)]
            })
            .collect();
        triangles.push([DVec3::new(5.0, 0.0, 5.0), DVec3::new(6.0, 0.0, 5.0), DVec3::new(5.0, 0.0, 6.0)]);
        let cells = SunCells::build(&triangles, DVec3::Y, 0.0046, MAX_SUN_CELL_ENTRIES).unwrap();
        assert!(cells.fullest() > MAX_SUN_CELL_TRIANGLES);
        let class = |p| sun_cone_class(&cells, &triangles, |_| true, p, DVec3::Y, 0.0046);
        // Under all 400: too many for its rays, but the classification still proves it covered; at the stack's
        // edge a penumbra, left to the traversal.
        let under = DVec3::new(0.2, -0.1, 0.2);
        assert_eq!(class(under), SunCone::Covered);
        assert_eq!(class(DVec3::new(0.5, -0.1, 0.0)), SunCone::Unknown);
        assert!(!sun_cells_usable(&cells, under));
        assert_eq!(sun_cells_occluded(&cells, &triangles, |_, _| true, (under, DVec3::Y), DVec3::Y), None);
        assert!(!sun_visible_along(Some(&cells), &triangles, |_, _| true, (under, DVec3::Y), DVec3::Y, || true));
        // Between the 300th and the 301st square: 99 above it.
        let high = DVec3::new(0.2, 3.005, 0.2);
        assert_eq!(sun_cell_range(&cells, high).len(), 99);
        assert_eq!(class(high), SunCone::Covered);
        let beside = DVec3::new(5.2, -0.1, 5.2);
        assert!(sun_cells_usable(&cells, beside));
        assert_eq!(class(beside), SunCone::Covered);
    }
}
