//! Pictures (feature `render`): an RGB canvas with PNG output, a 5x7 label font, and charts.

pub mod canvas;
pub mod font;
pub mod plot;

pub use canvas::{Canvas, Rgb};
pub use plot::{Series, log_chart};
