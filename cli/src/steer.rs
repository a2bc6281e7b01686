//! `sinmdm steer`: motion whose root goes where it is told (a path, a circle, a figure eight, or
//! a schedule of speeds and turn rates), the body in the clip's style (the task is
//! `sinmdm::Task::Steer`; the model needs a heading-relative root).

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use clap::Args;

use crate::sampling::{SamplingArgs, run_task, seconds_to_frames};
use sinmdm::Generated;
use sinmdm::model_file::ModelMetadata;
use sinmdm::motion::features::heading::facing_against_travel;
use sinmdm::motion::math::Vec3;
use sinmdm::steer::follow::{facing_following, path_following, velocity_following};
use sinmdm::steer::paths::{Shape, clip_speed, path};
use sinmdm::steer::{SteerFrame, SteerLimits, facing_of_direction};
use sinmdm::tasks::{INBETWEEN_RAMP, Task};

pub(crate) const EXAMPLES: &str = "Examples:
  sinmdm steer -m onnx-models/human_zombie_walk_fair.onnx --circle 3 --seconds 20 -o out/circle.bvh
  sinmdm steer -m onnx-models/human_zombie_walk_fair.onnx --figure8 3 --count 8 -o out/eight.glb
  sinmdm steer -m zombie.onnx --velocity schedule.csv --seconds 12 -o out/steered.bvh --report
  sinmdm steer -m zombie.onnx --path path.csv -o out/along.bvh
  sinmdm steer -m zombie.onnx --circle 3 --face 1,0,0 -o out/strafe.bvh --report
  sinmdm steer -m zombie.onnx --face 0,1,0 --seconds 8 -o out/turned.bvh

--circle and --figure8 take the radius in character heights and start where the model's clip
starts, facing its way. --path reads one ground position per frame (x,y,z in the model's file
frame and units; the up component is ignored), or x,y,z,fx,fy,fz: the position and the
direction to face there. --velocity reads lines `seconds,speed,turn`: from that time on, forward
speed in file units per second and turn rate in degrees per second (positive turns left).
--face X,Y,Z (file frame) keeps the character facing that way: alone, it goes where the model
likes; with a path, it walks the path in that facing (sideways or backwards where the path asks).
Commands the clip never showed are clamped to its range, with a warning.";

/// Where a steered run goes: shared by `sinmdm steer` and `sinmdm eval`.
#[derive(Debug, Clone, Args)]
pub struct CourseArgs {
    /// Walk a circle of this radius, in character heights, turning left.
    #[arg(long, value_name = "R", group = "course")]
    pub circle: Option<f64>,
    /// Walk a figure eight of two circles of this radius, in character heights.
    #[arg(long, value_name = "R", group = "course")]
    pub figure8: Option<f64>,
    /// Follow a path: one ground position per frame, `x,y,z` per line (file frame and units),
    /// or `x,y,z,fx,fy,fz`: the position and the direction to face there.
    #[arg(long, value_name = "PATH.csv", group = "course")]
    pub path: Option<PathBuf>,
    /// Follow a schedule of velocities: lines `seconds,speed,turn` (file units per second,
    /// degrees per second), each holding until the next.
    #[arg(long, value_name = "SCHEDULE.csv", group = "course")]
    pub velocity: Option<PathBuf>,
    /// Face this direction, `x,y,z` in the file frame (the up component is ignored): alone, the
    /// model goes where it likes; with --circle, --figure8 or --path, the path is walked in this
    /// facing.
    #[arg(
        long,
        value_name = "X,Y,Z",
        conflicts_with = "velocity",
        allow_hyphen_values = true
    )]
    pub face: Option<String>,
    /// Speed along --circle and --figure8, file units per second (default: the clip's mean
    /// forward speed, or half its top speed when that is faster).
    #[arg(long)]
    pub speed: Option<f64>,
}

impl CourseArgs {
    /// Whether a course was given.
    pub fn given(&self) -> bool {
        self.circle.is_some()
            || self.figure8.is_some()
            || self.path.is_some()
            || self.velocity.is_some()
            || self.face.is_some()
    }

    /// The commands of `frames` frames (a --path brings its own length), checked against the
    /// model (it must have a heading-relative root).
    pub fn commands(&self, metadata: &ModelMetadata, frames: usize) -> Result<Vec<SteerFrame>> {
        let Some(limits) = SteerLimits::of(metadata) else {
            bail!(
                "the model has no heading-relative root: steering needs a model trained with --root-layout heading"
            );
        };
        let fps = metadata.layout.fps;
        let height = metadata.layout.skeleton_height;
        let speed = match self.speed {
            Some(s) if s.is_finite() && s > 0.0 => s,
            Some(s) => bail!("--speed must be a positive number of units per second, got {s}"),
            None => clip_speed(metadata)
                .unwrap_or(0.0)
                .max(limits.forward.1 * 0.5),
        };
        let radius = |r: f64, flag: &str| -> Result<f64> {
            if r.is_finite() && r > 0.0 {
                Ok(r * height)
            } else {
                bail!("{flag} takes a positive radius in character heights, got {r}")
            }
        };
        let commands = if let Some(r) = self.circle {
            path(
                metadata,
                Shape::Circle(radius(r, "--circle")?),
                speed,
                frames,
            )
        } else if let Some(r) = self.figure8 {
            path(
                metadata,
                Shape::FigureEight(radius(r, "--figure8")?),
                speed,
                frames,
            )
        } else if let Some(file) = &self.path {
            Some(read_path(file)?)
        } else if let Some(file) = &self.velocity {
            Some(read_velocities(file, fps, frames)?)
        } else if self.face.is_some() {
            Some(vec![SteerFrame::Free; frames])
        } else {
            bail!(
                "say where to go: --circle R, --figure8 R, --path PATH.csv, --velocity SCHEDULE.csv or --face X,Y,Z"
            )
        };
        let commands = commands.context("the model has no heading-relative root")?;
        let Some(face) = &self.face else {
            return Ok(commands);
        };
        let facing = Vec3(parse_direction(face)?);
        if facing_of_direction(metadata, facing).is_none() {
            bail!(
                "--face {face}: the direction has no part on the ground (the model's up axis is {})",
                metadata.layout.up
            );
        }
        if commands.iter().any(|c| c.facing().is_some()) {
            bail!(
                "--face with a path that gives its own facings (six numbers a line): give one or the other"
            );
        }
        Ok(commands
            .into_iter()
            .map(|c| match c.position() {
                Some(position) => SteerFrame::PositionFacing { position, facing },
                None => SteerFrame::Facing(facing),
            })
            .collect())
    }
}

/// Arguments of `sinmdm steer`.
#[derive(Debug, Args)]
pub struct SteerArgs {
    #[command(flatten)]
    sampling: SamplingArgs,
    #[command(flatten)]
    course: CourseArgs,
    /// Length in seconds (default 20; a --path sets it by its frames).
    #[arg(long)]
    seconds: Option<f64>,
    /// Print how closely each sample followed: distance from the path, progress round it,
    /// facing against travel, speed and turn against the schedule.
    #[arg(long)]
    report: bool,
}

/// Runs `sinmdm steer`.
pub fn run(args: &SteerArgs) -> Result<()> {
    let mut model = args.sampling.open_model()?;
    let metadata = model.metadata().clone();
    let fps = metadata.layout.fps;
    let given_frames = args
        .seconds
        .map(|s| seconds_to_frames(s, fps))
        .transpose()?;
    let frames = given_frames.unwrap_or((20.0 * fps).round() as usize);
    let commands = args.course.commands(&metadata, frames)?;
    let frames = if args.course.path.is_some() {
        given_frames.unwrap_or(commands.len())
    } else {
        frames
    };
    let task = Task::Steer {
        frames,
        commands: commands.clone(),
        ramp: INBETWEEN_RAMP,
    };
    let generated = run_task(&args.sampling, &mut model, task)?;
    if args.report {
        print_following(&generated, &metadata, &commands);
    }
    Ok(())
}

/// One line per sample: how closely it did what `commands` asked.
pub fn print_following(generated: &Generated, metadata: &ModelMetadata, commands: &[SteerFrame]) {
    let layout = generated.layout();
    let fps = layout.fps;
    for i in 0..generated.count() {
        let raw = generated.features.index_axis(ndarray::Axis(0), i);
        let mut line = format!("sample {i}:");
        if let Some(p) = path_following(layout, raw, commands) {
            line += &format!(
                " path distance mean {:.3} max {:.3} heights, progress {:.2};",
                p.mean_distance, p.max_distance, p.progress
            );
        }
        if let Some(v) = velocity_following(layout, raw, commands, (2.0 * fps) as usize)
            && !v.forward.is_empty()
        {
            let worst = |pairs: &[(f64, f64)], floor: f64| {
                pairs
                    .iter()
                    .map(|(a, b)| (b - a).abs() / a.abs().max(floor))
                    .fold(0.0, f64::max)
            };
            line += &format!(
                " speed off by at most {:.0} %, turn by at most {:.0} % (2 s windows; turn against at least 10 degrees/s);",
                100.0 * worst(&v.forward, 1e-9),
                100.0 * worst(&v.turn, 10f64.to_radians())
            );
        }
        if let Some(f) = facing_following(metadata, raw, commands) {
            line += &format!(
                " facing off the commanded one by {:.1} degrees at the median, {:.1} at the 90th percentile;",
                f.median, f.p90
            );
        }
        if let Some((median, over)) = facing_against_travel(layout, raw).and_then(facing_summary) {
            line += &format!(
                " facing against travel median {median:.1} degrees, {:.0} % over 45",
                100.0 * over
            );
        }
        println!("{line}");
    }
}

/// The rows of finite numbers of a CSV-like file (commas, semicolons, spaces or tabs between
/// them), each with its line number, every row as wide as one of `widths`; a first line that is
/// not numbers is a header. `what` names the columns in errors.
fn numbers(file: &Path, widths: &[usize], what: &str) -> Result<Vec<(usize, Vec<f64>)>> {
    let text = sinmdm::files::read_text_file(file, "a steering file")
        .with_context(|| format!("cannot read {}", file.display()))?;
    let mut rows = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let fields: Vec<&str> = line
            .split([',', ';', ' ', '\t'])
            .map(str::trim)
            .filter(|s| !s.is_empty())
            .collect();
        if fields.is_empty() {
            continue;
        }
        let values: Result<Vec<f64>, _> = fields.iter().map(|f| f.parse::<f64>()).collect();
        match values {
            Ok(v) if widths.contains(&v.len()) && v.iter().all(|x| x.is_finite()) => {
                rows.push((i + 1, v))
            }
            Err(_) if i == 0 => continue,
            _ => bail!(
                "{} line {}: expected {what}, got '{line}'",
                file.display(),
                i + 1
            ),
        }
    }
    Ok(rows)
}

/// Three numbers `x,y,z` (commas, semicolons or spaces between them).
fn parse_direction(text: &str) -> Result<[f64; 3]> {
    let values: Vec<f64> = text
        .split([',', ';', ' '])
        .filter(|s| !s.trim().is_empty())
        .map(|s| s.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .with_context(|| format!("--face takes three numbers x,y,z, got '{text}'"))?;
    match values.as_slice() {
        &[x, y, z] if values.iter().all(|v| v.is_finite()) => Ok([x, y, z]),
        _ => bail!("--face takes three finite numbers x,y,z, got '{text}'"),
    }
}

/// One position per frame, `x,y,z` per line, or `x,y,z,fx,fy,fz` with the direction to face.
fn read_path(file: &Path) -> Result<Vec<SteerFrame>> {
    let rows = numbers(
        file,
        &[3, 6],
        "three numbers x,y,z or six x,y,z,fx,fy,fz (a position and the direction to face)",
    )?;
    if rows.len() < 2 {
        bail!("{}: a path needs at least two positions", file.display());
    }
    Ok(rows
        .into_iter()
        .map(|(_, v)| {
            let position = Vec3([v[0], v[1], v[2]]);
            match v[..] {
                [_, _, _, fx, fy, fz] => SteerFrame::PositionFacing {
                    position,
                    facing: Vec3([fx, fy, fz]),
                },
                _ => SteerFrame::Position(position),
            }
        })
        .collect())
}

/// Lines `seconds,speed,turn` (turn in degrees per second), each holding until the next, as
/// per-frame velocity commands over `frames` frames.
fn read_velocities(file: &Path, fps: f64, frames: usize) -> Result<Vec<SteerFrame>> {
    let rows = numbers(file, &[3], "three numbers seconds,speed,turn")?;
    if rows.is_empty() {
        bail!("{}: the schedule is empty", file.display());
    }
    for pair in rows.windows(2) {
        if pair[1].1[0] <= pair[0].1[0] {
            bail!("{} line {}: times must increase", file.display(), pair[1].0);
        }
    }
    Ok((0..frames)
        .map(|f| {
            let t = f as f64 / fps;
            match rows.iter().rev().find(|(_, e)| e[0] <= t) {
                Some((_, e)) => SteerFrame::Velocity {
                    forward: e[1],
                    turn: e[2].to_radians(),
                },
                None => SteerFrame::Free,
            }
        })
        .collect())
}

/// The median and the share over 45 degrees of a list of facing-against-travel angles.
fn facing_summary(mut angles: Vec<f64>) -> Option<(f64, f64)> {
    if angles.is_empty() {
        return None;
    }
    angles.sort_by(f64::total_cmp);
    let over = angles.iter().filter(|&&a| a > 45.0).count() as f64 / angles.len() as f64;
    Some((angles[angles.len() / 2], over))
}

/// For a heading-relative model: the facing against travel of the clip and of all samples
/// pooled (the clip's own style of walking, such as backward glides, against the samples').
pub fn print_facing(generated: &Generated, clip: ndarray::ArrayView2<'_, f32>) {
    let layout = generated.layout();
    let Some(of_clip) = facing_against_travel(layout, clip).and_then(facing_summary) else {
        return;
    };
    let pooled: Vec<f64> = (0..generated.count())
        .filter_map(|i| {
            facing_against_travel(layout, generated.features.index_axis(ndarray::Axis(0), i))
        })
        .flatten()
        .collect();
    if let Some((median, over)) = facing_summary(pooled) {
        println!(
            "facing against travel while moving: clip median {:.1} degrees ({:.0} % over 45), samples {:.1} degrees ({:.0} % over 45)",
            of_clip.0,
            100.0 * of_clip.1,
            median,
            100.0 * over
        );
    }
}
