//! Paths to steer along, made from where a model starts: a circle and a figure eight, walked at
//! a given speed, as per-frame positions in the model's file frame.

use crate::model_file::ModelMetadata;
use crate::motion::RootStart;
use crate::motion::features::heading::yaw;
use crate::motion::math::Vec3;

use super::SteerFrame;

/// The shapes [`path`] makes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Shape {
    /// A circle of this radius (file units), turning left from the start.
    Circle(f64),
    /// Two circles of this radius (file units) meeting at the start: left round the first, then
    /// right round the second, over and over.
    FigureEight(f64),
}

/// The start course of a heading-relative model: its root's canonical ground position and
/// facing at frame 0; `None` for another root layout.
pub fn start_course(metadata: &ModelMetadata) -> Option<(Vec3, f64)> {
    let RootStart {
        mut position,
        heading,
    } = RootStart::of(&metadata.layout)?;
    position[crate::motion::up::UP] = 0.0;
    Some((position, heading))
}

/// The clip's mean forward speed, file units per second (what a path is walked at unless told
/// otherwise); `None` for a model without a heading-relative root.
pub fn clip_speed(metadata: &ModelMetadata) -> Option<f64> {
    start_course(metadata)?;
    Some(f64::from(metadata.normalizer.mean[0]) * metadata.layout.fps)
}

/// `frames` positions along `shape` from the model's start position and facing, walked at
/// `speed` file units per second, in the file frame (as [`SteerFrame::Position`]).
pub fn path(
    metadata: &ModelMetadata,
    shape: Shape,
    speed: f64,
    frames: usize,
) -> Option<Vec<SteerFrame>> {
    let (start, heading) = start_course(metadata)?;
    let fps = metadata.layout.fps;
    let forward = yaw(heading) * Vec3::new(0.0, 0.0, 1.0);
    let left = yaw(heading) * Vec3::new(1.0, 0.0, 0.0);
    let to_file = metadata.layout.up.file_from_canonical();
    let along = |distance: f64| -> Vec3 {
        match shape {
            Shape::Circle(r) => {
                let a = distance / r;
                let centre = start + left * r;
                centre - left * (r * a.cos()) + forward * (r * a.sin())
            }
            Shape::FigureEight(r) => {
                let lap = std::f64::consts::TAU * r;
                let d = distance.rem_euclid(2.0 * lap);
                if d < lap {
                    let a = d / r;
                    start + left * r - left * (r * a.cos()) + forward * (r * a.sin())
                } else {
                    let a = (d - lap) / r;
                    start - left * r + left * (r * a.cos()) + forward * (r * a.sin())
                }
            }
        }
    };
    Some(
        (0..frames)
            .map(|f| SteerFrame::Position(to_file * along(speed * f as f64 / fps)))
            .collect(),
    )
}
