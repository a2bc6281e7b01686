//! Pictures of motion for sinmdm: an RGB canvas with PNG output, a 5x7 label font, charts, and
//! stick-figure renders of motion as GIF animations or PNG contact sheets.

#![warn(missing_docs)]

pub mod animation;
pub mod canvas;
pub mod figure;
pub mod font;
pub mod plot;

pub use animation::{AnimationError, gif_bytes};
pub use canvas::{Canvas, Rgb};
pub use figure::{Camera, Figure, RenderOptions, contact_sheet, render_frame};
pub use plot::{Series, log_chart};
