//! Small raster plots for the measuring commands (`bench --pareto --plot`): a canvas with lines, markers and
//! 8×8 bitmap text (the public-domain font8x8 glyphs), and a log-log scatter chart with its Pareto front. No
//! fonts or system libraries are needed, so a plot is the same on every machine.

mod canvas;
pub mod false_color;
mod log_log;

pub use canvas::{Canvas, Rgb};
pub use log_log::{LogLogChart, Point};
