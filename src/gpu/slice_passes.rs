//! The lights' visible fractions by slices on the GPU, in passes, where one fragment cannot take all of a light's
//! rows within llvmpipe's loop budget (65 535 iterations a fragment, every loop together, `loop_budget`).
//!
//! **The sky, always.** The reference slices the sky through occluders (`shading::sky_slices`: half great circles
//! through a fixed axis, each row's blocked intervals exact, midpoints in the rows' angle). The sun's and disk
//! lights' slices on the GPU gather the occluders in the light's cone once a pixel (`MAX_SLICE_TRIANGLES`, 1024); a
//! pixel's sky reaches every occluder above its horizons, on overcast.glb the whole teapot (2256 triangles), and a
//! wedge of rows about the axis does not narrow that where the axis line from the point passes through the teapot
//! (measured at 64 × 48: wedges of 45° gathered up to all 2256). A row's plane cuts far fewer, so each row walks the
//! BVH for its own (shaders/slices.glsl, `sky_rows_weights`: on overcast.glb some 80 of llvmpipe's loop iterations
//! a row for 155 boxes, and 20 for the 38 triangles met), and the rows are taken in passes before the frame.
//!
//! **The sun and disk lights, where the frame runs out.** Their slices gather once a pixel and cut the gathered
//! triangles row by row in the frame (`sun_rows_weights`, `disk_rows_weights` over every row). Under a wide disk
//! light a penumbra's pixel gathers hundreds of triangles, and 4k² rows of them pass the budget (room.gltf's
//! skylight over its sphere at k = 9: 324 rows, 25 pixels cut short at 64 × 64). A frame cut short where it sliced
//! them itself is drawn again with their rows taken in passes ([`passable`]: the sun's and every disk's), each
//! pass gathering again and cutting only its rows.
//!
//! Each pass draws the scene with the variant `QUANTITY_LIGHT_ROWS`, its light (`ROWS_OF_*`) and rows named in
//! the light buffer, and its fragment writes the rows' visible and unoccluded weights; the host sums the passes per
//! pixel in f64 ([`RowSums`]) and the frame reads each pixel's fraction from a buffer, a layer a light
//! ([`read_bits`]: `READ_SKY`, `READ_SUN`, `READ_DISKS`).
//!
//! The passes start as [`first_passes`] cuts the rows, at most [`ROWS_A_PASS`] each. A pass that the limiter cuts
//! short is split in two and drawn again ([`refusal`]; a single row still cut short refuses the image); a pass whose
//! walk meets more triangles than a fragment keeps (`MAX_SLICE_TRIANGLES`) refuses it at once ([`overflowed`]).
//! The sums are those of the reference's rows in another order (f32 within a pass), so a light with nothing in the
//! way still reads exactly 1 ([`RowSums::fractions`]: `rows_fraction`'s rule).

use crate::film::Image;
use crate::shading::sky_slices::rows_fraction;

use super::layout::{READ_DISKS, READ_SKY, READ_SUN, ROWS_OF_DISK, ROWS_OF_SKY, ROWS_OF_SUN};
use super::loop_budget::LOOP_BUDGET_SPENT;
use super::slice_gather::{MAX_SLICE_TRIANGLES, SLICES_OVERFLOWED};

/// The most rows a pass takes at first: at some 100 iterations a row (overcast.glb: 80 for the walk, 20 for the
/// triangles it meets), 128 rows spend a fifth of the loop budget, leaving room for pixels whose rows cut more
/// (at 256 rows a pass, k = 8 at 64 × 48, some pixels were cut short and the pass was split).
pub const ROWS_A_PASS: u32 = 128;

/// The passes `(first row, rows)` that cover `rows` rows in order, at most [`ROWS_A_PASS`] rows each, their sizes
/// differing by at most one.
pub fn first_passes(rows: u32) -> Vec<(u32, u32)> {
    let passes = rows.div_ceil(ROWS_A_PASS).max(1);
    (0..passes)
        .map(|j| {
            let first = (j as u64 * rows as u64 / passes as u64) as u32;
            let next = ((j as u64 + 1) * rows as u64 / passes as u64) as u32;
            (first, next - first)
        })
        .filter(|&(_, count)| count > 0)
        .collect()
}

/// Why a pass's image cannot be summed ([`refusal`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Refusal {
    /// A pixel with a row whose walk met more triangles than a fragment keeps: a row's own limit, which no split
    /// of the passes lifts; the image is refused ([`overflowed`]).
    Overflowed,
    /// A pixel whose loops the limiter cut short: the pass is split in two and drawn again.
    LoopBudget,
}

/// Why a pass's image cannot be summed, if it cannot: the coverage alphas `SLICES_OVERFLOWED` and
/// `LOOP_BUDGET_SPENT`.
pub fn refusal(image: &Image) -> Option<Refusal> {
    if image.alpha_count_and_first(SLICES_OVERFLOWED).is_some() {
        Some(Refusal::Overflowed)
    } else if image.alpha_count_and_first(LOOP_BUDGET_SPENT).is_some() {
        Some(Refusal::LoopBudget)
    } else {
        None
    }
}

/// The lights whose slices a frame may pass, given whether the sun is sliced and how many disk lights are: the
/// sun's slot ([`ROWS_OF_SUN`]) and every disk's (`ROWS_OF_DISK + i`). A frame that slices them itself and runs
/// out of the loop budget passes them all (the renderer), every disk together (one bit, `READ_DISKS`).
pub fn passable(sun: bool, disks: usize) -> Vec<u32> {
    let sun = sun.then_some(ROWS_OF_SUN);
    sun.into_iter().chain((0..disks as u32).map(|i| ROWS_OF_DISK + i)).collect()
}

/// The `READ_*` bits of the lights `slots` whose fractions the frame reads from the passes' layers.
pub fn read_bits(slots: &[u32]) -> u32 {
    slots.iter().fold(0, |bits, &slot| {
        bits | match slot {
            ROWS_OF_SKY => READ_SKY,
            ROWS_OF_SUN => READ_SUN,
            _ => READ_DISKS,
        }
    })
}

/// The lights that `read_bits` names, for `-v` ("the sky, the sun, disk lights"), or `None` where it names none.
pub fn passed_lights(bits: u32) -> Option<String> {
    let names = [(READ_SKY, "the sky"), (READ_SUN, "the sun"), (READ_DISKS, "disk lights")];
    let named: Vec<_> = names.iter().filter(|(bit, _)| bits & bit != 0).map(|(_, name)| *name).collect();
    (!named.is_empty()).then(|| named.join(", "))
}

/// A light slot's name (`ROWS_OF_*`) for messages: "the sky", "the sun", "disk light i".
pub fn light_name(slot: u32) -> String {
    match slot {
        ROWS_OF_SKY => "the sky".to_string(),
        ROWS_OF_SUN => "the sun".to_string(),
        _ => format!("disk light {}", slot - ROWS_OF_DISK),
    }
}

/// Why a pass of `light`'s slices (its first row and rows) whose walk met more triangles than a fragment keeps (a
/// sky row's, the sun's or a disk light's cone) refuses the image.
pub fn overflowed(image: &Image, light: &str, (first, count): (u32, u32)) -> String {
    let (pixels, (x, y)) = image.alpha_count_and_first(SLICES_OVERFLOWED).unwrap_or((0, (0, 0)));
    format!(
        "--visibility slices: {light}'s slices (rows {first} to {}) meet more than {MAX_SLICE_TRIANGLES} triangles \
         at {pixels} pixel(s) (the first at ({x}, {y})), more than the GPU's slices gather a fragment; \
         --visibility grid casts rays there, and `sunshade reference --visibility slices` has no such limit",
        first + count - 1
    )
}

/// The passes' weights summed per pixel: visible and unoccluded, f64, and the pixels a pass could not slice.
pub struct RowSums {
    visible: Vec<f64>,
    total: Vec<f64>,
    unsliceable: Vec<bool>,
}

impl RowSums {
    pub fn new(pixels: usize) -> Self {
        Self { visible: vec![0.0; pixels], total: vec![0.0; pixels], unsliceable: vec![false; pixels] }
    }

    /// Adds one pass's image: (visible, whole) in red and green; a negative visible weight where the pixel's
    /// slices could not be taken (an alpha-masked occluder, `SLICES_UNSLICEABLE`).
    pub fn add(&mut self, pass: &Image) {
        for (i, p) in pass.pixels().iter().enumerate() {
            if p[0] < 0.0 {
                self.unsliceable[i] = true;
            } else {
                self.visible[i] += p[0] as f64;
                self.total[i] += p[1] as f64;
            }
        }
    }

    /// Each pixel's visible fraction, `rows_fraction` of its sums (exactly 1 where every row was clear, and where
    /// the sky gives nothing), or −1 where some pass could not slice it: the frame then casts the grid's rays there,
    /// as the reference does.
    pub fn fractions(&self) -> Vec<f32> {
        (0..self.visible.len())
            .map(|i| if self.unsliceable[i] { -1.0 } else { rows_fraction(self.visible[i], self.total[i]) as f32 })
            .collect()
    }
}

/// The lights' fractions the passes have left, one layer a light slot (`ROWS_OF_*`), on the host: a frame drawn
/// again after its loop budget ran out passes more lights without drawing the earlier ones' passes again.
pub struct PassedFractions {
    pixels: usize,
    layers: Vec<(u32, Vec<f32>)>,
}

impl PassedFractions {
    pub fn new(pixels: usize) -> Self {
        Self { pixels, layers: Vec::new() }
    }

    /// Whether light `slot`'s fractions are here.
    pub fn has(&self, slot: u32) -> bool {
        self.layers.iter().any(|(s, _)| *s == slot)
    }

    /// Light `slot`'s fractions, one a pixel ([`RowSums::fractions`]).
    pub fn insert(&mut self, slot: u32, fractions: Vec<f32>) {
        debug_assert_eq!(fractions.len(), self.pixels);
        self.layers.push((slot, fractions));
    }

    /// Binding 13's contents: a layer a slot up to the last held, −1 in the slots not held; `None` where none is.
    pub fn layered(&self) -> Option<Vec<f32>> {
        let count = self.layers.iter().map(|(s, _)| *s as usize + 1).max()?;
        let mut out = vec![-1.0; count * self.pixels];
        for (slot, layer) in &self.layers {
            let at = *slot as usize * self.pixels;
            out[at..at + self.pixels].copy_from_slice(layer);
        }
        Some(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_first_passes_cover_every_row_once_in_order() {
        for rows in [1u32, 3, 8, 9, 64, 100, 324, 676, 2916, 6084] {
            let passes = first_passes(rows);
            let mut next = 0;
            for &(first, count) in &passes {
                assert_eq!(first, next, "{rows}: {passes:?}");
                assert!((1..=ROWS_A_PASS).contains(&count), "{rows}: {passes:?}");
                next = first + count;
            }
            assert_eq!(next, rows);
            assert_eq!(passes.len() as u32, rows.div_ceil(ROWS_A_PASS));
            let sizes = passes.iter().map(|p| p.1);
            assert!(sizes.clone().max().unwrap() - sizes.min().unwrap() <= 1);
        }
    }

    #[test]
    fn the_passable_lights_and_their_bits() {
        assert_eq!(passable(false, 0), Vec::<u32>::new());
        assert_eq!(passable(true, 0), vec![ROWS_OF_SUN]);
        assert_eq!(passable(true, 2), vec![ROWS_OF_SUN, ROWS_OF_DISK, ROWS_OF_DISK + 1]);
        assert_eq!(passable(false, 1), vec![ROWS_OF_DISK]);
        assert_eq!(read_bits(&[]), 0);
        assert_eq!(read_bits(&[ROWS_OF_SKY]), READ_SKY);
        assert_eq!(read_bits(&[ROWS_OF_SKY, ROWS_OF_SUN, ROWS_OF_DISK + 3]), READ_SKY | READ_SUN | READ_DISKS);
        assert_eq!(read_bits(&[ROWS_OF_DISK, ROWS_OF_DISK + 1]), READ_DISKS);
        assert_eq!(light_name(ROWS_OF_SKY), "the sky");
        assert_eq!(passed_lights(0), None);
        assert_eq!(passed_lights(READ_SKY | READ_DISKS).as_deref(), Some("the sky, disk lights"));
        assert_eq!(light_name(ROWS_OF_DISK + 1), "disk light 1");
    }

    #[test]
    fn passed_fractions_lay_each_light_in_its_slot() {
        let mut f = PassedFractions::new(2);
        assert_eq!(f.layered(), None);
        f.insert(ROWS_OF_DISK, vec![0.5, 0.25]);
        f.insert(ROWS_OF_SKY, vec![1.0, 0.75]);
        assert!(f.has(ROWS_OF_SKY) && f.has(ROWS_OF_DISK) && !f.has(ROWS_OF_SUN));
        assert_eq!(f.layered(), Some(vec![1.0, 0.75, -1.0, -1.0, 0.5, 0.25]));
    }

    #[test]
    fn sums_keep_a_clear_sky_exactly_one_and_name_what_could_not_be_sliced() {
        let mut a = Image::new(3, 1);
        let mut b = Image::new(3, 1);
        // Pixel 0 clear in both passes, pixel 1 half hidden in the second, pixel 2 unsliceable in the first.
        a.pixels_mut().copy_from_slice(&[[0.3, 0.3, 0.0, 1.0], [0.2, 0.2, 0.0, 1.0], [-1.0, 0.0, 0.0, 1.0]]);
        b.pixels_mut().copy_from_slice(&[[0.7, 0.7, 0.0, 1.0], [0.1, 0.2, 0.0, 1.0], [0.5, 0.5, 0.0, 1.0]]);
        let mut sums = RowSums::new(3);
        sums.add(&a);
        sums.add(&b);
        let f = sums.fractions();
        assert_eq!(f[0], 1.0);
        assert!((f[1] - 0.75).abs() < 1e-7, "{f:?}");
        assert_eq!(f[2], -1.0);
        assert_eq!(refusal(&a), None);
        a.pixels_mut()[0][3] = LOOP_BUDGET_SPENT;
        assert_eq!(refusal(&a), Some(Refusal::LoopBudget));
        a.pixels_mut()[1][3] = SLICES_OVERFLOWED;
        assert_eq!(refusal(&a), Some(Refusal::Overflowed));
        let e = overflowed(&a, "the sky", (17, 4));
        assert!(
            e.contains("the sky's slices")
                && e.contains("rows 17 to 20")
                && e.contains("1 pixel(s)")
                && e.contains("(1, 0)"),
            "{e}"
        );
    }
}
