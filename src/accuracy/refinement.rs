//! The lobe grids' error estimated by refinement, where no derived bound covers it: a specular surface under disk
//! lights or the sky integrates its lobe over the light on a `k²` grid whose error depends on the lobe, the
//! light's size and distance and the surface's tilt (six angles of configuration, and measured tables of the
//! sky's grid show no bound that a scan could give cheaply: docs/accuracy.md, "Error bounds"). `--tolerance`
//! instead renders the image on a ladder of grids and estimates the finest one's error from the last three,
//! by Richardson extrapolation with the observed order of convergence, reported as Roache's grid convergence
//! index (GCI):
//!
//! Roache, P. J. (1994), "Perspective: A Method for Uniform Reporting of Grid Refinement Studies",
//! J. Fluids Eng. 116(3), 405–413 (the GCI with its factor of safety 1.25 for three grids and an observed order).
//!
//! **Ladder**: `k₀ = 4`, `kᵢ₊₁ = ⌈√2 kᵢ⌉` per axis (the samples at least doubled, as the converged reference refines),
//! to [`MAX_LOBE_GRID`]; everything else (sun model and grid, shadows) fixed, so that the images differ only by their
//! lobe grids (and rounding). Where a measured material is under the sun, its table's lookup has no derived curvature
//! for the sun's bound, and the sun's grid is refined on the same rungs (`sun_grid`). Where `--tolerance` holds in
//! penumbrae (its default; not `--tolerance-outside-penumbrae`) in a scene that shadows itself (shadow rays), every
//! grid is refined on the rungs, the visible fractions' shadow-ray grids too (`shadow_grid`): the penumbrae (below).
//!
//! **Model**: in its asymptotic range a grid of `k` per axis errs at a pixel by `e(k) = C k^−p`. The difference of
//! consecutive images, `dᵢ` (max over pixels, relative with the diff's floor, less the two renders' rounding,
//! twice the renderer's arithmetic), is then `C kᵢ₋₁^−p (1 − rᵢ^−p)` with `rᵢ = kᵢ / kᵢ₋₁`, so
//!
//! `dᵢ₋₁ / dᵢ = rᵢ₋₁^p (1 − rᵢ₋₁^−p) / (1 − rᵢ^−p)`            (solved for the observed order p by bisection)
//!
//! `eᵢ = dᵢ / (rᵢ^p − 1)`,  `GCI = 1.25 eᵢ`                      (the finest image's error, with Roache's factor)
//!
//! The ratios `rᵢ` differ a little (⌈·⌉), hence the general form rather than `ln(dᵢ₋₁/dᵢ)/ln r`. The order used
//! is at most 2, the midpoint rule's on a smooth integrand: an observed order above it is two grids agreeing by
//! chance, and would shrink the estimate. An order under [`MIN_ORDER`] (differences that do not shrink, or a
//! difference after one that vanished) says the grids are not yet in their asymptotic range: the ladder goes on.
//! Taking the max over pixels for both differences and applying one order to all is the "global norm" form of the
//! study; the maxima may sit at different pixels, so the order is a property of the image, not of a pixel.
//!
//! **What it is not**: a bound. It is an estimate that holds where the pixels' errors follow the model, which is
//! what `tests/accuracy.rs` measures against the converged reference on every scene of models/ and the BRDF chart
//! under disk lights and the sky.
//!
//! **Penumbrae.** Where an occluder's edge crosses a light, a count of rays jumps: the lobe grids' samples, which
//! cast a ray each, converge at first order or slower, erratically: the share of the cells the edge cuts shrinks
//! as `1/k`, their errors partly cancel (`k^−1.5` for an edge at a random angle), and a rung can agree with the
//! next by chance. The sun's, disk lights' and the sky's visible fractions locate the edges
//! (`shading::visibility::grid_fraction`) and converge at second order once the grid resolves the occluders (an
//! occluder thinner than the spacing is missed, then found: a jump), but a study cannot tell which part of a
//! pixel's error comes from which. The max over the image's pixels is
//! steadier than any one pixel (many pixels, many edge positions). The order used is at most 1 there
//! ([`MAX_ORDER_WITH_PENUMBRAE`], the jump's worst case: 2.4 times the estimate of an order-2 reading on rungs √2
//! apart), and an order under [`MIN_ORDER`] sends the ladder on. Still an estimate: `tests/shadows.rs` checks it
//! against the exact circular segment of a straight edge's penumbra, `tests/accuracy.rs` against a 181² render of
//! sunset.glb on the GPU.
//!
//! **Penumbrae by slices, where no lobe sample casts a ray.** The reference's slices (`shading::sky_slices`,
//! `sun_slices`, `disk_slices`) take each light's visible fraction exactly along one angle and by `4k²` midpoint
//! rows along the other, ψ. A row's visible weight is a function of ψ of bounded variation: each of finitely
//! many occluding triangles blocks an interval that moves continuously with ψ but where one of its edges lies in
//! the row's plane (a jump), so the weight is piecewise continuous with finitely many pieces. For such a function
//! Koksma's inequality bounds the error of an equal-weight rule by its variation times the points' star
//! discrepancy, `1/(2N)` for `N` midpoints: `|error| ≤ V / (2N)`, whatever the jumps. With `N = 4k²` rows that is
//! `O(k⁻²)`, order 2 on the ladder's `k`: where every light shadowed is taken by slices and every material the
//! meshes use is Lambertian (no lobe grid, so no lobe sample casting a ray: the ones that make penumbrae first
//! order), the order used is at most [`MAX_ORDER`], as without penumbrae ([`Ladder::with_sliced_penumbrae`]).
//! Measured on overcast.glb at 512²: the slices' images for k = 9, 13, 18 (`4k²` rows each) differ
//! by 3.3e-3 and 1.7e-3 at their largest, an observed order of 1.8 in `k` (first order in the rows), where the
//! cap of 1 had taken it as 1.
//!
//! **Orders past the midpoint's.** An observed order above 2 is cut to 2, but the cut alone keeps Roache's 1.25
//! for an order the study did not confirm: the rungs' maxima read past 2 where the last two rungs agree by chance
//! at the pixel whose error is largest, and that pixel's difference then understates its error. Measured on
//! room.gltf at 48 × 36, its skylight's penumbra by slices: the rows of k = 4, 6, 9, 13, 19 err
//! 6.0e-3, 1.5e-3, 2.3e-3, 1.0e-3, 1.7e-4 against `reference --converged --accuracy 1e-5` (not monotone), the
//! maxima of the rungs' differences read an order of 2.6, and the estimate at 9² with 1.25 was 1.6e-3, short of
//! the 2.3e-3 measured. Where the order observed lies more than 10% above the one used (Oberkampf and Roy's
//! criterion for an order that confirms the formal one), the factor of safety is Roache's for an unconfirmed order,
//! 3 ([`UNCONFIRMED_SAFETY_FACTOR`]): 3.7e-3 there. Under [`MAX_ORDER_WITH_PENUMBRAE`] the cap is the margin
//! already (the order read past 1 is the located edges' 2, and the cap takes 2.4 times its estimate), so the factor
//! stays 1.25. Below the order used, where Oberkampf and Roy take 3 as well, the study keeps 1.25: it uses the lower
//! order it observes, which makes the estimate larger by itself (`d₂/(r^p − 1)` grows as `p` falls: at `p` = 1.5 on
//! rungs √2 apart, about 1.5 times its value at 2), and an order under [`MIN_ORDER`] sends the ladder on.
//!
//! Oberkampf, W. L. and Roy, C. J. (2010), *Verification and Validation in Scientific Computing*, Cambridge
//! University Press, §8.6 (the GCI's factor of safety: 1.25 where the observed order is within 10% of the formal
//! one, 3 otherwise).

use crate::compare::{default_floor, pixel_difference};
use crate::film::Image;

/// The finest lobe grid the ladder renders [per axis].
pub const MAX_LOBE_GRID: u32 = 192;
/// The first rung [per axis].
pub const FIRST_LOBE_GRID: u32 = 4;
/// The order below which the grids are taken as not yet in their asymptotic range.
pub const MIN_ORDER: f64 = 0.5;
/// The highest order used: the midpoint rule's on a smooth integrand.
pub const MAX_ORDER: f64 = 2.0;
/// The highest order used where the shadow rays' grids are refined: a jump's (an occluder's edge across a
/// light), whose count of rays (the lobe samples') errs by `O(1/k)` at worst (module text, "Penumbrae").
pub const MAX_ORDER_WITH_PENUMBRAE: f64 = 1.0;
/// Roache's factor of safety for a study of three grids whose observed order confirms the one used.
pub const SAFETY_FACTOR: f64 = 1.25;
/// Roache's factor of safety where the order is not confirmed (his two-grid factor): used where the observed
/// order exceeds [`MAX_ORDER`] by more than [`CONFIRMING_FRACTION`] of it (module text, "Orders past the
/// midpoint's").
pub const UNCONFIRMED_SAFETY_FACTOR: f64 = 3.0;
/// How far above the order used an observed order may lie and still confirm it (a fraction of the order): 10%,
/// Oberkampf and Roy's criterion (module text).
pub const CONFIRMING_FRACTION: f64 = 0.1;

/// The next rung after `k`: the samples at least doubled, `⌈√2 k⌉` (the converged reference's doubling too).
pub fn next_grid(k: u32) -> u32 {
    ((k as f64) * std::f64::consts::SQRT_2).ceil() as u32
}

/// The rungs, coarsest first: 4, 6, 9, 13, 19, 27, 39, 56, 80, 114, 162.
pub fn ladder() -> Vec<u32> {
    let mut v = vec![FIRST_LOBE_GRID];
    while next_grid(*v.last().unwrap()) <= MAX_LOBE_GRID {
        v.push(next_grid(*v.last().unwrap()));
    }
    v
}

/// The max relative difference of two renders of the same view (the diff's floor from the finer one's peak),
/// over the pixels either covers; a NaN or an infinity counts as infinite.
pub fn max_difference(coarse: &Image, fine: &Image) -> f64 {
    max_difference_where(coarse, fine, None)
}

/// [`max_difference`] over the pixels `mask` flags only (row-major; `None`: all), the floor still the whole
/// image's: a part of the image measured as the diff measures the whole.
pub fn max_difference_where(coarse: &Image, fine: &Image, mask: Option<&[bool]>) -> f64 {
    let floor = default_floor(fine);
    coarse
        .pixels()
        .iter()
        .zip(fine.pixels())
        .enumerate()
        .filter(|&(i, (a, b))| (a[3] > 0.0 || b[3] > 0.0) && mask.is_none_or(|m| m[i]))
        .map(|(_, (&a, &b))| pixel_difference(a, b, floor).rel)
        .fold(0.0, f64::max)
}

/// The order `p` of `e(k) = C k^−p` that three grids `k₀ < k₁ < k₂` with differences `d₁ = |I₁ − I₀|` and
/// `d₂ = |I₂ − I₁|` show: the root of `d₁/d₂ = r₁^p (1 − r₁^−p)/(1 − r₂^−p)`. The right side grows with p
/// (from `ln r₁/ln r₂ · 1` at p → 0 to ∞), so bisection on [0, 16] finds it; `None` where `d₁/d₂` is below the
/// right side's value at 0 (differences that do not shrink: no positive order) or either difference is not
/// finite and positive. Above 16 the order is returned as 16 (far past [`MAX_ORDER`], where it is cut anyway).
pub fn observed_order(k: [u32; 3], d1: f64, d2: f64) -> Option<f64> {
    if !(d1.is_finite() && d2.is_finite() && d1 > 0.0 && d2 > 0.0) {
        return None;
    }
    let (r1, r2) = (k[1] as f64 / k[0] as f64, k[2] as f64 / k[1] as f64);
    // r^p − 1 by exp_m1 keeps its digits at small p (where `powf` − 1 would cancel).
    let ratio = |p: f64| (p * r1.ln()).exp_m1() / (-(p * r2.ln())).exp_m1().abs();
    let target = d1 / d2;
    let at_zero = r1.ln() / r2.ln();
    if target <= at_zero {
        return None;
    }
    let (mut lo, mut hi) = (0.0f64, 16.0f64);
    if ratio(hi) <= target {
        return Some(hi);
    }
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if ratio(mid) < target {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    Some(0.5 * (lo + hi))
}

/// The factor of safety on an estimate whose order is cut to `max_order`: Roache's 1.25 where the order
/// observed confirms it, his 3 where it lies more than [`CONFIRMING_FRACTION`] above the midpoint's
/// [`MAX_ORDER`] (two rungs agreeing by chance: module text, "Orders past the midpoint's"). Under a cap below
/// the midpoint's (penumbrae cast by lobe rays, [`MAX_ORDER_WITH_PENUMBRAE`]) the cap itself is the margin: the
/// order read there is the located edges' 2, not chance, and the cap already takes 2.4 times its estimate.
fn safety_factor(observed: f64, max_order: f64) -> f64 {
    if max_order >= MAX_ORDER && observed > (1.0 + CONFIRMING_FRACTION) * MAX_ORDER {
        UNCONFIRMED_SAFETY_FACTOR
    } else {
        SAFETY_FACTOR
    }
}

/// The estimate of one study: the finest grid, its estimated max relative error (the GCI), the order used (the
/// observed one, cut to the ladder's cap), the order observed, the factor of safety applied and the ladder's last
/// two differences (less rounding); `sun_grid`: whether the sun's grid was refined on the
/// ladder too (a measured material under the sun, or penumbrae), so that the estimate covers it instead of the
/// sun's bound; `shadow_grid`: whether the visible fractions' shadow-ray grids were, so that it covers penumbrae.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LobeEstimate {
    pub samples_per_axis: u32,
    pub gci: f64,
    pub order: f64,
    pub observed_order: f64,
    pub safety_factor: f64,
    pub differences: [f64; 2],
    pub sun_grid: bool,
    pub shadow_grid: bool,
}

impl LobeEstimate {
    /// For the prediction's terms: "lobe grids under disk lights and the sky 19², estimated by refinement
    /// (observed order 1.80, Roache's GCI):"; where the order observed is cut, "(observed order 2.61, taken as
    /// 2.00, Roache's GCI with a factor of safety of 3):".
    pub fn term(&self) -> String {
        self.term_of("")
    }

    /// [`Self::term`] of one material's study: "lobe grids under disk lights and the sky of material 'Ward' 27²,
    /// estimated by refinement (...):".
    pub fn term_for(&self, material: &str) -> String {
        self.term_of(&format!(" of {material}"))
    }

    fn term_of(&self, whose: &str) -> String {
        format!(
            "{}{whose} {}², estimated by refinement (observed order {:.2}{}, Roache's GCI{}):",
            match (self.sun_grid, self.shadow_grid) {
                (_, true) => "every grid (the sun's, the lobes', the shadow rays': penumbrae included)",
                (true, false) => "the sun's grid and the lobe grids",
                (false, false) => "lobe grids under disk lights and the sky",
            },
            self.samples_per_axis,
            self.observed_order,
            if self.observed_order > self.order { format!(", taken as {:.2}", self.order) } else { String::new() },
            if self.safety_factor != SAFETY_FACTOR {
                format!(" with a factor of safety of {}", self.safety_factor)
            } else {
                String::new()
            }
        )
    }
}

/// The running study: the grids rendered and the images' differences so far.
pub struct Ladder {
    /// Twice the renderer's arithmetic error: what two renders of the same integral may differ by in rounding.
    noise: f64,
    grids: Vec<u32>,
    differences: Vec<f64>,
    /// Whether the sun's grid is refined with the lobe grids.
    sun_grid: bool,
    /// Whether the shadow-ray grids are.
    shadow_grid: bool,
    /// Whether those grids are slices' rows with no lobe sample casting a ray (module text): order 2 at most.
    sliced_penumbrae: bool,
}

impl Ladder {
    /// A study on a renderer whose arithmetic errs by `arithmetic` (relative), refining the sun's grid and the
    /// shadow-ray grids with the lobe grids or not.
    pub fn new(arithmetic: f64, sun_grid: bool, shadow_grid: bool) -> Self {
        Self {
            noise: 2.0 * arithmetic,
            grids: Vec::new(),
            differences: Vec::new(),
            sun_grid,
            shadow_grid,
            sliced_penumbrae: false,
        }
    }

    /// The same study where the shadow grids refined are the rows of slices and no lobe sample casts a ray
    /// (every material the meshes use Lambertian): their error is `O(k⁻²)` however an occluder's edges lie
    /// (module text, "Penumbrae by slices"), so the order used is at most [`MAX_ORDER`].
    pub fn with_sliced_penumbrae(mut self) -> Self {
        self.sliced_penumbrae = true;
        self
    }

    /// The highest order the estimate uses: [`MAX_ORDER_WITH_PENUMBRAE`] where the shadow rays' grids are
    /// refined (unless [`Self::with_sliced_penumbrae`]), else [`MAX_ORDER`].
    fn max_order(&self) -> f64 {
        if self.shadow_grid && !self.sliced_penumbrae {
            MAX_ORDER_WITH_PENUMBRAE
        } else {
            MAX_ORDER
        }
    }

    /// Records the image of grid `k` given the previous rung's image (`None` for the first).
    pub fn push(&mut self, k: u32, previous: Option<&Image>, image: &Image) {
        self.push_where(k, previous, image, None);
    }

    /// [`Self::push`] measuring only the pixels `mask` flags (one material's: a study per material).
    pub fn push_where(&mut self, k: u32, previous: Option<&Image>, image: &Image, mask: Option<&[bool]>) {
        if let Some(prev) = previous {
            self.differences.push((max_difference_where(prev, image, mask) - self.noise).max(0.0));
        }
        self.grids.push(k);
    }

    /// The estimate for the last grid once three are in, `None` where the grids are not in their asymptotic range
    /// (module text). Two differences of zero (the grids agree to rounding) estimate zero.
    pub fn estimate(&self) -> Option<LobeEstimate> {
        let n = self.grids.len();
        if n < 3 {
            return None;
        }
        let k = [self.grids[n - 3], self.grids[n - 2], self.grids[n - 1]];
        let (d1, d2) = (self.differences[n - 3], self.differences[n - 2]);
        let done = |gci: f64, order: f64, observed_order: f64, safety_factor: f64| LobeEstimate {
            samples_per_axis: k[2],
            gci,
            order,
            observed_order,
            safety_factor,
            differences: [d1, d2],
            sun_grid: self.sun_grid,
            shadow_grid: self.shadow_grid,
        };
        if d2 == 0.0 {
            // The last two grids agree to rounding; after a difference that vanished too, or one that shrank to
            // nothing (an order past any bound, cut to MAX_ORDER), the finest grid's error is its rounding.
            return Some(done(0.0, self.max_order(), self.max_order(), SAFETY_FACTOR));
        }
        let order = observed_order(k, d1, d2)?;
        if order < MIN_ORDER {
            return None;
        }
        let p = order.min(self.max_order());
        let r = k[2] as f64 / k[1] as f64;
        let fs = safety_factor(order, self.max_order());
        Some(done(fs * d2 / (p * r.ln()).exp_m1(), p, order, fs))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_ladder_at_least_doubles_the_samples() {
        let l = ladder();
        assert_eq!(l, vec![4, 6, 9, 13, 19, 27, 39, 56, 80, 114, 162]);
        assert!(l.windows(2).all(|w| w[1] * w[1] >= 2 * w[0] * w[0]));
    }

    /// The observed order of an exact power law is its exponent, for rungs of unequal ratios.
    #[test]
    fn the_observed_order_of_a_power_law_is_its_exponent() {
        for p in [0.6, 1.0, 1.5, 2.0, 3.0] {
            for k in [[4u32, 6, 9], [9, 13, 19], [27, 39, 56]] {
                let e = |k: u32| 0.3 * (k as f64).powf(-p);
                let (d1, d2) = (e(k[0]) - e(k[1]), e(k[1]) - e(k[2]));
                let got = observed_order(k, d1, d2).unwrap();
                assert!((got - p).abs() < 1e-9, "p {p}, k {k:?}: {got}");
            }
        }
        // Differences that do not shrink have no positive order.
        assert_eq!(observed_order([4, 6, 9], 1e-3, 1e-3), None);
        assert_eq!(observed_order([4, 6, 9], 0.0, 1e-3), None);
    }

    fn flat(w: u32, v: f32) -> Image {
        let mut img = Image::new(w, 1);
        for p in img.pixels_mut() {
            *p = [v, v, v, 1.0];
        }
        img
    }

    /// On a power law of order 1 or 2 the GCI bounds the finest image's true error, and is within a factor of
    /// 1.25 of it (the safety factor alone, the model being exact).
    #[test]
    fn the_gci_covers_an_exact_power_law() {
        for p in [1.0, 2.0] {
            let truth = 1.0f32;
            // A small amplitude, so that the differences relative to the pixel's value follow the power law
            // (relative to a value that moves by 10%, the observed order of p = 1 reads 0.9).
            let value = |k: u32| truth + 0.01 * (k as f32).powf(-p as f32);
            let mut ladder = Ladder::new(0.0, false, false);
            let mut prev: Option<Image> = None;
            for &k in &[4u32, 6, 9] {
                let img = flat(4, value(k));
                ladder.push(k, prev.as_ref(), &img);
                prev = Some(img);
            }
            let e = ladder.estimate().unwrap();
            let true_error = (value(9) - truth) as f64 / value(9) as f64;
            assert!(e.gci >= true_error && e.gci <= 1.3 * true_error, "p {p}: {e:?} against {true_error:.3e}");
        }
    }

    /// On a power law of order 2 the study of shadow grids takes the order as 1 (a jump's), so its estimate is
    /// 2.4 times an order 2's on rungs √2 apart; by slices without lobe rays it takes the 2 it observes.
    #[test]
    fn sliced_penumbrae_take_the_order_they_observe_up_to_two() {
        let value = |k: u32| 1.0f32 + 0.01 * (k as f32).powi(-2);
        let estimate = |ladder: Ladder| {
            let mut ladder = ladder;
            let mut prev: Option<Image> = None;
            for &k in &[9u32, 13, 19] {
                let img = flat(4, value(k));
                ladder.push(k, prev.as_ref(), &img);
                prev = Some(img);
            }
            ladder.estimate().unwrap()
        };
        let rays = estimate(Ladder::new(0.0, false, true));
        let sliced = estimate(Ladder::new(0.0, false, true).with_sliced_penumbrae());
        let true_error = (value(19) - 1.0) as f64 / value(19) as f64;
        assert_eq!(rays.order, MAX_ORDER_WITH_PENUMBRAE);
        assert!((sliced.order - 2.0).abs() < 1e-3, "{sliced:?}");
        assert!(sliced.gci >= true_error && sliced.gci <= 1.3 * true_error, "{sliced:?} against {true_error:.3e}");
        assert!(rays.gci > 2.0 * sliced.gci, "{rays:?} against {sliced:?}");
        // Observed above 2 (two rungs agreeing by chance), it is cut to 2 either way.
        let fast = |k: u32| 1.0f32 + 0.01 * (k as f32).powi(-4);
        let mut ladder = Ladder::new(0.0, false, true).with_sliced_penumbrae();
        let mut prev: Option<Image> = None;
        for &k in &[9u32, 13, 19] {
            let img = flat(4, fast(k));
            ladder.push(k, prev.as_ref(), &img);
            prev = Some(img);
        }
        assert_eq!(ladder.estimate().unwrap().order, MAX_ORDER);
    }

    /// room.gltf's case (48 × 36, its skylight's penumbra by slices): the image's largest early
    /// difference sits where the rows settle fast, while at another pixel two rungs agree by chance, each still
    /// off by more than they differ. The order read from the maxima (3.1) is past the midpoint's; Roache's 1.25
    /// on the order cut to 2 falls short of that pixel's error, his unconfirmed 3 covers it.
    #[test]
    fn an_order_past_the_midpoints_takes_the_unconfirmed_factor() {
        // Relative errors at rungs 4, 6, 9 of two pixels whose truth is 1.
        let settles = [4.5e-3f32, 0.0, 0.0];
        let agrees_by_chance = [2.3e-3f32, 1.0e-3, 2.3e-3];
        let mut ladder = Ladder::new(0.0, false, true).with_sliced_penumbrae();
        let mut prev: Option<Image> = None;
        for (i, &k) in [4u32, 6, 9].iter().enumerate() {
            let mut img = Image::new(2, 1);
            for (p, e) in img.pixels_mut().iter_mut().zip([settles[i], agrees_by_chance[i]]) {
                *p = [1.0 + e, 1.0 + e, 1.0 + e, 1.0];
            }
            ladder.push(k, prev.as_ref(), &img);
            prev = Some(img);
        }
        let e = ladder.estimate().unwrap();
        let true_error = 2.3e-3 / 1.0023;
        assert!(e.observed_order > 3.0 && e.order == MAX_ORDER, "{e:?}");
        assert_eq!(e.safety_factor, UNCONFIRMED_SAFETY_FACTOR);
        assert!(e.gci >= true_error, "{e:?} against {true_error:.3e}");
        assert!(e.gci * SAFETY_FACTOR / UNCONFIRMED_SAFETY_FACTOR < true_error, "{e:?}");
        assert!(e.term().contains("taken as 2.00") && e.term().contains("factor of safety of 3"), "{}", e.term());
        // Under the cap of lobe rays' penumbrae the cap is the margin: the factor stays 1.25.
        assert_eq!(safety_factor(3.1, MAX_ORDER_WITH_PENUMBRAE), SAFETY_FACTOR);
        // An order that confirms the midpoint's (within 10%) keeps it too.
        assert_eq!(safety_factor(2.2, MAX_ORDER), SAFETY_FACTOR);
    }

    /// Differences that grow, or one after a vanished one, are not in the asymptotic range; two agreeing to
    /// rounding estimate zero.
    #[test]
    fn the_study_refuses_grids_out_of_range() {
        let run = |values: [f32; 3], arithmetic: f64| {
            let mut ladder = Ladder::new(arithmetic, false, false);
            let mut prev: Option<Image> = None;
            for (i, &v) in values.iter().enumerate() {
                let img = flat(2, v);
                ladder.push([4, 6, 9][i], prev.as_ref(), &img);
                prev = Some(img);
            }
            ladder.estimate()
        };
        assert_eq!(run([1.0, 1.01, 1.03], 0.0), None);
        assert_eq!(run([1.0, 1.0, 1.01], 0.0), None);
        assert_eq!(run([1.0, 1.0, 1.0], 0.0).map(|e| e.gci), Some(0.0));
        // Within the rounding of two renders: zero as well.
        assert_eq!(run([1.0, 1.000_01, 1.0], 1e-5).map(|e| e.gci), Some(0.0));
    }
}
