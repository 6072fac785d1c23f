//! A first look at a frame, a sparse grid of small blocks of its pixels, drawn to learn whether the frame will run
//! out of llvmpipe's loop budget (`loop_budget`) where it slices the sun and disk lights itself (`slice_passes`).
//!
//! **Why.** A frame that runs out is drawn again with those lights' rows in passes, and the frame that ran out is
//! wasted, all of it: the pixels cut short are few (room.gltf at 128², k = 9: 167 pixels, in one blob of rows 76 to
//! 89), but every other pixel of the penumbrae has done its heavy rows too. On room.gltf at 512² (`--shadows ray
//! --visibility slices --shadow-samples 169`) that frame was some 130 of the render's 193 s. Passing the rows from
//! the start whatever the scene is no rule: where the frame fits, the passes cost more (sunset.glb at 512², k = 13:
//! 25.4 s in the frame, 28.9 s in passes).
//!
//! **What.** Before the first frame of a scene at a row count that has not run out yet, the frame is drawn in
//! [`probe_blocks`] only: a [`PROBE_BLOCK`]² block in the middle of every cell of a grid, [`PROBE_CELLS`] cells
//! along the shorter side (at most a 16th of the pixels; 1/64 at 512²), the scene drawn once a block under its
//! scissor, so that no other pixel is shaded. Its fragments keep [`LOOP_RESERVE`] of their budget's iterations in
//! reserve (their probe loop runs that many more, `layout::with_loop_probe`), so that a pixel within the reserve
//! of the limit is marked spent too: the pixels cut short are rare and clustered, the pixels near the limit about
//! them less so. Where any is marked, the frame takes the lights' rows in passes from the start. A probe may still
//! miss a frame that runs out (the frame is then drawn again, as without the probe), or pass the rows of a frame
//! that would have fitted (pixels within the reserve of the limit, none past it).
//!
//! Measured (AMD EPYC, 2 threads, Mesa 22.3.6; `render MODEL --shadows ray --visibility slices
//! --shadow-samples K² -v`, the "render" line, one run each, images bitwise those of the frame drawn again):
//! room.gltf at 512², k = 13: 193 s → 64 s (the probe 2.8 s); at 128², k = 9: 27.8 s → 10.3 s (1.3 s); where
//! the frame fits, sunset.glb at 512², k = 13: the probe 0.41 s of a 24 s frame, room.gltf at 128², k = 6: 0.59 s
//! of 10 s. Tried first and not kept: the frame drawn whole at 64² (one of llvmpipe's 64² tiles, so one thread,
//! and each SIMD group spanning more of the scene: a 14 s probe on room.gltf at 512², 1.5 to 2 s on sunset.glb's
//! 24 s frame); strips of 4 whole rows a 32nd of the image apart (room.gltf at 128²: the blob lay between them);
//! the block pattern drawn by a fragment shader that returns outside the blocks (llvmpipe runs the code after the
//! return masked, not skipped: 7.2 s on sunset.glb at 512²).
//!
//! Frames whose shorter side is under [`PROBED_FROM`] pixels draw no probe (a wasted frame of theirs costs little),
//! and only llvmpipe before Mesa 25 probes ([`probes`]); other devices have no such limit.

use std::time::Duration;

use super::layout::with_loop_probe;
use super::loop_budget::LOOP_PROBE_ITERATIONS;
use super::DeviceInfo;

/// The side of a probe's blocks \[pixels\]: llvmpipe shades 4 × 4 blocks, so a block aligned to 4 shades no pixel
/// outside it.
pub const PROBE_BLOCK: u32 = 4;
/// About how many cells of the probe's pattern lie along the frame's shorter side.
pub const PROBE_CELLS: u32 = 16;
/// The least spacing of the probe's blocks \[pixels\]: a probe shades at most a 16th of the frame's pixels.
pub const PROBE_MIN_SPACING: u32 = 4 * PROBE_BLOCK;
/// The shorter side \[pixels\] from which frames are probed: smaller ones, whose wasted frame costs little, are not.
pub const PROBED_FROM: u32 = 128;
/// The iterations of llvmpipe's loop budget (65 535) that a probe's fragment keeps in reserve: an eighth. (A
/// quarter sent room.gltf at 128² and k = 6, whose frame fits, to the passes.)
pub const LOOP_RESERVE: u32 = 8192;

/// A probe drawn before a frame: how many blocks it drew, whether some pixel of them came within
/// [`LOOP_RESERVE`] of the limit (the frame then took the sun's and disk lights' rows in passes from the start),
/// and what it cost.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Probe {
    pub blocks: usize,
    pub ran_out: bool,
    /// Drawing it and reading it back (part of the frame's render time).
    pub time: Duration,
}

impl Probe {
    /// The `-v` line's text.
    pub fn describe(&self) -> String {
        let outcome = if self.ran_out {
            "came near the loop budget's end, so the sun's and disk lights' slices were passed from the start"
        } else {
            "fitted the loop budget, so the frame sliced the sun and disk lights itself"
        };
        let (b, n, ms) = (PROBE_BLOCK, self.blocks, self.time.as_secs_f64() * 1e3);
        format!("a probe of the frame ({n} blocks of {b}x{b} pixels, {ms:.0} ms) {outcome} (gpu::frame_probe)")
    }
}

/// The probe's blocks for a frame of `width × height` pixels, `(x, y, side)`: a [`PROBE_BLOCK`]² block in the
/// middle of every cell of a grid whose spacing is the shorter side over [`PROBE_CELLS`], aligned to
/// [`PROBE_BLOCK`], and at least [`PROBE_MIN_SPACING`]; `None` for frames whose shorter side is under
/// [`PROBED_FROM`] pixels.
pub fn probe_blocks(width: u32, height: u32) -> Option<Vec<(u32, u32, u32)>> {
    if width.min(height) < PROBED_FROM {
        return None;
    }
    let spacing = (width.min(height) / PROBE_CELLS / PROBE_BLOCK * PROBE_BLOCK).max(PROBE_MIN_SPACING);
    let corner = (spacing - PROBE_BLOCK) / 2 / PROBE_BLOCK * PROBE_BLOCK;
    let along = |side: u32| (0..side / spacing).map(move |j| j * spacing + corner);
    Some(along(height).flat_map(|y| along(width).map(move |x| (x, y, PROBE_BLOCK))).collect())
}

/// The frame's light buffer (`layout::lights_bytes`, its passes' word set) for its probe: the probe loop runs
/// [`LOOP_RESERVE`] iterations more.
pub fn probe_light_bytes(frame: &[u8]) -> Vec<u8> {
    with_loop_probe(frame, LOOP_PROBE_ITERATIONS + LOOP_RESERVE)
}

/// Whether a device's first frames are probed: its driver is llvmpipe (lavapipe), whose shaders carry the loop
/// limiter, before Mesa 25 ([`probed_driver`]).
pub fn probes(info: &DeviceInfo) -> bool {
    // The device's name ("llvmpipe (LLVM 15.0.6, 256 bits)") where the driver gives no name of its own.
    let name = if info.driver_name.is_empty() { &info.name } else { &info.driver_name };
    probed_driver(name, &info.driver_info)
}

/// Whether a driver (its name and info, e.g. "llvmpipe" and "Mesa 22.3.6 (LLVM 15.0.6)") is probed: llvmpipe
/// before Mesa 25. Mesa 22.3.6's cuts loops short; Mesa 25.0.7's did not in the same checks (docs/platform.md), and
/// there the probe would only cost its blocks (0.24 s of sunset.glb's 7 s frame at 512², k = 13). The versions
/// between are not known here, so they probe; so does an llvmpipe whose version cannot be read.
pub fn probed_driver(name: &str, info: &str) -> bool {
    let major = info.split_once("Mesa ").and_then(|(_, v)| v.split('.').next()?.parse::<u32>().ok());
    name.contains("llvmpipe") && major.is_none_or(|m| m < 25)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn llvmpipe_before_mesa_25_is_probed() {
        assert!(probed_driver("llvmpipe", "Mesa 22.3.6 (LLVM 15.0.6)"));
        assert!(probed_driver("llvmpipe", "Mesa 24.2.8-1ubuntu1 (LLVM 19.1.1)"));
        assert!(probed_driver("llvmpipe", "a build without a version"));
        assert!(!probed_driver("llvmpipe", "Mesa 25.0.7-2~bpo12+1 (LLVM 15.0.6)"));
        assert!(!probed_driver("llvmpipe", "Mesa 26.1.0"));
        assert!(!probed_driver("NVIDIA", "570.86.16"));
    }

    #[test]
    fn the_probe_is_a_block_a_cell_at_most_a_16th_of_the_frame_and_small_frames_have_none() {
        assert_eq!(probe_blocks(127, 512), None);
        assert_eq!(probe_blocks(512, 100), None);
        assert_eq!(probe_blocks(128, 128).map(|b| b.len()), Some(64));
        let blocks = probe_blocks(512, 512).unwrap();
        assert_eq!((blocks.len(), blocks[0], blocks[17]), (256, (12, 12, 4), (44, 44, 4)));
        for (w, h) in [(128u32, 128u32), (129, 300), (256, 256), (640, 480), (1000, 999), (4096, 2160), (16384, 128)] {
            let blocks = probe_blocks(w, h).unwrap();
            let spacing = (w.min(h) / PROBE_CELLS / 4 * 4).max(PROBE_MIN_SPACING);
            // A block in every whole cell, each inside its cell and the frame, aligned to llvmpipe's 4 x 4 blocks.
            assert_eq!(blocks.len() as u32, (w / spacing) * (h / spacing), "{w}x{h}");
            for &(x, y, side) in &blocks {
                assert_eq!((x % 4, y % 4, side), (0, 0, PROBE_BLOCK), "{w}x{h}");
                assert!(
                    x % spacing + side <= spacing && y % spacing + side <= spacing && x + side <= w && y + side <= h
                );
            }
            // At most a 16th of the pixels, and at least PROBE_CELLS blocks along the shorter side where it allows.
            assert!(blocks.len() as u32 * PROBE_BLOCK * PROBE_BLOCK * 16 <= w * h, "{w}x{h}: {}", blocks.len());
            assert!(w.min(h) / spacing >= (w.min(h) / PROBE_MIN_SPACING).min(PROBE_CELLS), "{w}x{h}");
        }
    }
}
