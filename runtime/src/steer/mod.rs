//! Steering a heading-relative model (SPEC section 5, "Steering"): where the character goes is
//! asked for frame by frame (a path on the ground, forward speed and turn rate, a facing, or a
//! path with a facing of its own), and the sampler pulls the root's slow motion to it while the
//! network makes the body to match.
//!
//! A command is an average over a stride, not a value per frame: a walk's hips speed up and
//! slow down within each step, and its facing sways. So steering sets only the **slow part** of
//! the root's rows. At every denoising step, for each steered row `r` of the prediction `x0`
//! (normalised): `x0[r] += lowpass(w (y[r] - x0[r]))`, where `y` is the target, `w` the
//! command's weight per frame (soft at the ends of a span of commands, 0 where nothing is
//! asked) and the low-pass a triangular kernel of [`STEER_REACH_SECONDS`]. The stride's rhythm
//! stays the model's.
//!
//! - **Velocity** commands target the forward row (speed / fps) and the turn row (turn rate /
//!   fps).
//! - **Path** commands give the ground position of each frame. Their displacement from frame to
//!   frame, turned into the facing the prediction has at that frame (re-integrated from its own
//!   turn rows at every step), targets the forward and leftward rows; the path's own turn
//!   targets the turn row. Where a span of path commands starts, the prediction's offset from
//!   the path, in position and in facing, fades out over [`FACING_CATCH_UP_SECONDS`]; after
//!   that the targets are the path's own steps (open loop: each pass re-reads the facing, and
//!   the low-pass keeps the integrated course on the path).
//! - **Facing** commands give the direction the character faces. The turn row is pulled, as a
//!   path's is, to a course that joins the commanded facing from the prediction's over
//!   [`FACING_CATCH_UP_SECONDS`] and then turns as the commands turn; the travel stays the
//!   model's. Given with a path, the facing replaces the path's direction and the travel still
//!   follows the path: a sideways walk (strafing) or a backward one. The travel, in the
//!   character's frame, is clamped to the clip's sideways range and its slowest forward speed
//!   (each taking in 0): a clip that never walked sideways follows a strafed path only as fast
//!   as it ever went sideways.
//!
//! Commands beyond what the clip showed are clamped ([`SteerLimits`]) and reported.

mod command;
pub mod follow;
pub mod lowpass;
pub mod paths;

use ndarray::ArrayViewMut2;

pub use command::{SteerFrame, check_commands, facing_of_direction};

use crate::model_file::ModelMetadata;
use crate::motion::RootStart;
use crate::motion::features::heading::{wrap, yaw};
use crate::motion::math::Vec3;
use crate::motion::up::UP;
use crate::soft_border::soft_mask;

/// The half-width of the steering low-pass, seconds: about a stride, so the commanded average
/// is over a whole step.
pub const STEER_REACH_SECONDS: f64 = 0.5;

/// The half-width of the low-pass on a path's facing, seconds: longer than a stride, so the
/// facing follows the path's direction on average and a clip's own turns away from its travel
/// (a stylised walk's backward glides) stay.
pub const FACING_REACH_SECONDS: f64 = 1.5;

/// Passes of the pull per denoising step (see [`Steering::apply`]).
pub const STEER_PASSES: usize = 4;

/// Over how long the offset between the prediction and a path, where a span of path commands
/// starts, fades out, seconds.
pub const FACING_CATCH_UP_SECONDS: f64 = 1.0;

/// The smallest turn rate steering allows, radians per second, whatever the clip: a clip that
/// walks straight still turns a quarter turn a second when asked (the heading-relative root
/// makes a turn the same data as a straight walk, turned).
pub const MIN_TURN_LIMIT: f64 = std::f64::consts::FRAC_PI_2;

/// The rows of a heading-relative root, in the features' order.
const FORWARD: usize = 0;
const LEFTWARD: usize = 1;
const TURN: usize = 2;

/// The range of commands a model's clip supports: its forward speed and turn rate, each as the
/// clip's mean plus or minus two standard deviations per frame (read from the model's
/// normaliser), the turn widened to at least [`MIN_TURN_LIMIT`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SteerLimits {
    /// Slowest and fastest forward speed, file units per second.
    pub forward: (f64, f64),
    /// Largest turn rate either way, radians per second.
    pub turn: f64,
    /// Slowest and fastest leftward speed (negative: rightward), file units per second: how
    /// fast a path given with a facing of its own can be walked sideways.
    pub sideways: (f64, f64),
}

impl SteerLimits {
    /// The limits of a heading-relative model; `None` for another root layout.
    pub fn of(metadata: &ModelMetadata) -> Option<SteerLimits> {
        metadata.layout.root.as_ref()?.heading.as_ref()?;
        let fps = metadata.layout.fps;
        let n = &metadata.normalizer;
        let row = |r: usize| (f64::from(n.mean[r]) * fps, f64::from(n.std[r]) * fps);
        let (fm, fs) = row(FORWARD);
        let (tm, ts) = row(TURN);
        let (lm, ls) = row(LEFTWARD);
        Some(SteerLimits {
            forward: (fm - 2.0 * fs, fm + 2.0 * fs),
            turn: (tm.abs() + 2.0 * ts).max(MIN_TURN_LIMIT),
            sideways: (lm - 2.0 * ls, lm + 2.0 * ls),
        })
    }
}

/// One frame's goal, canonical frame, per frame.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Goal {
    Free,
    /// Forward displacement and turn per frame.
    Velocity {
        forward: f64,
        turn: f64,
    },
    /// The root's ground position (up component 0), the facing (its own, or `None` for the
    /// path's direction), or both.
    Course {
        position: Option<Vec3>,
        facing: Option<f64>,
    },
}

impl Goal {
    fn position(&self) -> Option<Vec3> {
        match *self {
            Goal::Course { position, .. } => position,
            _ => None,
        }
    }
}

/// The steering of one sampling run: a goal per frame of its window, from a known course.
#[derive(Debug, Clone, PartialEq)]
pub struct Steering {
    goals: Vec<Goal>,
    /// Per frame, how strongly its goal pulls (soft at the ends of a span of commands).
    weights: Vec<f64>,
    /// The frame whose course is known; goals are read after it.
    anchor: usize,
    /// The root's canonical position and facing at the anchor frame.
    course: RootStart,
    /// Mean and standard deviation of the forward, leftward and turn rows.
    mean: [f64; 3],
    std: [f64; 3],
    /// Low-pass half-width of the travel rows and of the turn row, and catch-up time, frames.
    reach: usize,
    turn_reach: usize,
    catch_up: f64,
    /// The fastest the root may go, per frame.
    max_step: f64,
    /// The clip's slowest forward step and its range of leftward steps, per frame, each widened
    /// to take in 0 (a path walked with a facing of its own is clamped to them).
    backward_floor: f64,
    sideways_range: (f64, f64),
}

/// A steering built from commands, and what was clamped on the way.
#[derive(Debug, Clone, PartialEq)]
pub struct SteeringPlan {
    /// The guidance (`None` when no frame asks for anything).
    pub steering: Option<Steering>,
    /// One line per kind of command the clip never showed, clamped to its range.
    pub warnings: Vec<String>,
}

/// Builds the steering of a window of `commands.len()` frames whose course at frame `anchor`
/// is `course` (canonical), soft over `ramp` frames at the ends of each span of commands.
/// Fails for a model without a heading-relative root.
pub fn plan_steering(
    metadata: &ModelMetadata,
    commands: &[SteerFrame],
    anchor: usize,
    course: RootStart,
    ramp: usize,
) -> Result<SteeringPlan, String> {
    let limits = SteerLimits::of(metadata).ok_or_else(|| {
        "steering needs a model with a heading-relative root (train it with --root-layout heading)"
            .to_string()
    })?;
    check_commands(metadata, commands)?;
    let layout = &metadata.layout;
    let fps = layout.fps;
    let mut warnings = Vec::new();
    let goals = goals_of(metadata, commands, &limits, &mut warnings);
    // A path faster than the clip ever went is followed at the clip's top speed.
    let top = limits.forward.1.max(0.0);
    // A path with a facing of its own asks for travel in the facing's frame: sideways or
    // backwards faster than the clip went is followed at the clip's pace.
    let sideways = (limits.sideways.0.min(0.0), limits.sideways.1.max(0.0));
    let slowest = limits.forward.0.min(0.0);
    warn_of_fast_paths(&goals, fps, top, (sideways, slowest), &mut warnings);
    let asked: Vec<bool> = goals
        .iter()
        .enumerate()
        .map(|(i, g)| i > anchor && *g != Goal::Free)
        .collect();
    if !asked.contains(&true) {
        return Ok(SteeringPlan {
            steering: None,
            warnings,
        });
    }
    let weights = soft_mask(&asked, ramp).into_iter().map(f64::from).collect();
    // A path's facing is pulled over a longer reach than its travel: the course is followed on
    // average, and a clip's own turns away from its travel (a glide) stay. A commanded facing
    // is pulled as the travel is.
    let reach = (STEER_REACH_SECONDS * fps).round() as usize;
    let on_path = goals.iter().skip(anchor + 1).any(|g| {
        matches!(
            g,
            Goal::Course {
                position: Some(_),
                facing: None
            }
        )
    });
    let turn_reach = if on_path {
        (FACING_REACH_SECONDS * fps).round() as usize
    } else {
        reach
    };
    let n = &metadata.normalizer;
    let rows = [FORWARD, LEFTWARD, TURN];
    Ok(SteeringPlan {
        steering: Some(Steering {
            goals,
            weights,
            anchor,
            course: RootStart {
                position: Vec3::new(course.position[0], 0.0, course.position[2]),
                heading: course.heading,
            },
            mean: rows.map(|r| f64::from(n.mean[r])),
            std: rows.map(|r| f64::from(n.std[r])),
            reach,
            turn_reach,
            catch_up: (FACING_CATCH_UP_SECONDS * fps).max(1.0),
            max_step: top / fps,
            backward_floor: slowest / fps,
            sideways_range: (sideways.0 / fps, sideways.1 / fps),
        }),
        warnings,
    })
}

/// Adds `line` to `warnings` unless it is there already.
fn warn_once(warnings: &mut Vec<String>, line: String) {
    if !warnings.contains(&line) {
        warnings.push(line);
    }
}

/// Each command as a goal in the canonical frame, per frame; speeds and turns beyond the
/// clip's `limits` clamped, with a warning.
fn goals_of(
    metadata: &ModelMetadata,
    commands: &[SteerFrame],
    limits: &SteerLimits,
    warnings: &mut Vec<String>,
) -> Vec<Goal> {
    let fps = metadata.layout.fps;
    let to_canonical = metadata.layout.up.canonical_from_file();
    let mut warn = |line: String| warn_once(warnings, line);
    commands
        .iter()
        .map(|c| match *c {
            SteerFrame::Free => Goal::Free,
            SteerFrame::Velocity { forward, turn } => {
                let (lo, hi) = limits.forward;
                let f = forward.clamp(lo, hi);
                if f != forward {
                    warn(format!(
                        "forward speeds beyond the clip's {lo:.3} to {hi:.3} units/s were clamped"
                    ));
                }
                let t = turn.clamp(-limits.turn, limits.turn);
                if t != turn {
                    warn(format!(
                        "turn rates beyond the clip's {:.0} degrees/s were clamped",
                        limits.turn.to_degrees()
                    ));
                }
                Goal::Velocity {
                    forward: f / fps,
                    turn: t / fps,
                }
            }
            SteerFrame::Position(_) | SteerFrame::Facing(_) | SteerFrame::PositionFacing { .. } => {
                let position = c.position().map(|p| {
                    let mut q = to_canonical * p;
                    q[UP] = 0.0;
                    q
                });
                let facing = c.facing().and_then(|d| facing_of_direction(metadata, d));
                Goal::Course { position, facing }
            }
        })
        .collect()
}

/// Warns of a path faster than the clip's `top` speed, and of a path with a facing of its own
/// that asks for sideways or backward speeds beyond the clip's (`pace`: the sideways range and
/// the slowest forward speed, each taking in 0).
fn warn_of_fast_paths(
    goals: &[Goal],
    fps: f64,
    top: f64,
    pace: ((f64, f64), f64),
    warnings: &mut Vec<String>,
) {
    let (sideways, slowest) = pace;
    let mut warn = |line: String| warn_once(warnings, line);
    for pair in goals.windows(2) {
        if let (Some(a), Some(b)) = (pair[0].position(), pair[1].position())
            && (b - a).norm() * fps > top * 1.0001
        {
            warn(format!(
                "the path goes faster than the clip's {top:.3} units/s; it is followed at that speed"
            ));
            break;
        }
    }
    for pair in goals.windows(2) {
        if let (
            Some(a),
            Goal::Course {
                position: Some(b),
                facing: Some(h),
            },
        ) = (pair[0].position(), pair[1])
        {
            let local = yaw(h).transpose() * (b - a);
            let (f, l) = (local[2] * fps, local[0] * fps);
            let (lo, hi) = sideways;
            let beyond = |v: f64, bound: f64| (v - bound).abs() > 1e-4 * bound.abs() + 1e-12;
            if (l < lo && beyond(l, lo)) || (l > hi && beyond(l, hi)) {
                warn(format!(
                    "the path with its facing asks for sideways speeds beyond the clip's {lo:.3} to {hi:.3} units/s; they are clamped, so the path is followed more slowly"
                ));
            }
            if f < slowest && beyond(f, slowest) {
                warn(format!(
                    "the path with its facing asks for backward speeds beyond the clip's slowest {slowest:.3} units/s; they are clamped, so the path is followed more slowly"
                ));
            }
        }
    }
}

impl Steering {
    /// Frames of the window it steers.
    pub fn frames(&self) -> usize {
        self.goals.len()
    }

    /// Per frame of the window, whether a command sets where the root goes (a velocity, or a
    /// position on a path), as opposed to nothing or a facing alone. Foot planting leaves the
    /// root of those frames where the steering put it: carried along with the feet instead, it
    /// would go at the pace of the model's strides rather than the commanded one.
    pub fn travel_commanded(&self) -> Vec<bool> {
        self.goals
            .iter()
            .enumerate()
            .map(|(i, goal)| {
                i > self.anchor
                    && matches!(
                        goal,
                        Goal::Velocity { .. }
                            | Goal::Course {
                                position: Some(_),
                                ..
                            }
                    )
            })
            .collect()
    }

    /// Pulls the slow part of the root rows of one normalised prediction `[F, N]` to the goals,
    /// [`STEER_PASSES`] times: a path's targets follow the prediction's course, which each pass
    /// changes.
    pub fn apply(&self, mut x0: ArrayViewMut2<'_, f32>) {
        for _ in 0..STEER_PASSES {
            self.pass(x0.view_mut());
        }
    }

    /// The direction a path span without a facing leaves in at frame `i` (standing at `p`):
    /// its first step, or, standing still, its step to the next frame, or the facing before.
    fn leading_direction(&self, i: usize, p: Vec3, path_step: Vec3, heading_before: f64) -> f64 {
        let mut lead = path_step;
        if lead.norm() <= 1e-12
            && let Some(next) = self.goals.get(i + 1).and_then(Goal::position)
        {
            lead = next - p;
            lead[UP] = 0.0;
        }
        if lead.norm() > 1e-12 {
            lead[0].atan2(lead[2])
        } else {
            heading_before
        }
    }

    /// The forward and leftward step that makes the ground step `want` facing `heading`, no
    /// faster than the clip goes; with a facing of its own (`own_facing`) no more sideways or
    /// backwards than the clip went.
    fn travel(&self, mut want: Vec3, heading: f64, own_facing: bool) -> (f64, f64) {
        let speed = want.norm();
        if speed > self.max_step && speed > 0.0 {
            want = want * (self.max_step / speed);
        }
        let local = yaw(heading).transpose() * want;
        let (mut ahead, mut aside) = (local[2], local[0]);
        if own_facing {
            ahead = ahead.max(self.backward_floor);
            aside = aside.max(self.sideways_range.0).min(self.sideways_range.1);
        }
        (ahead, aside)
    }

    fn pass(&self, mut x0: ArrayViewMut2<'_, f32>) {
        let n = self.goals.len();
        let raw = |r: usize| -> Vec<f64> {
            x0.row(r)
                .iter()
                .map(|&v| f64::from(v) * self.std[r] + self.mean[r])
                .collect()
        };
        let (forward, leftward, turn) = (raw(FORWARD), raw(LEFTWARD), raw(TURN));
        // The prediction's own course from the anchor on.
        let mut heading = vec![self.course.heading; n];
        let mut position = vec![self.course.position; n];
        for i in self.anchor + 1..n {
            heading[i] = heading[i - 1] + turn[i];
            let mut step = yaw(heading[i]) * Vec3::new(leftward[i], 0.0, forward[i]);
            step[UP] = 0.0;
            position[i] = position[i - 1] + step;
        }
        let mut targets: [Vec<Option<f64>>; 3] = [vec![None; n], vec![None; n], vec![None; n]];
        // A span of path goals starts from where the prediction stands before it (the anchor's
        // known course for a span that starts right after it): its offset from the path, in
        // position and in facing, fades out linearly over the catch-up time, so the targets
        // are a course that joins the path (each frame's target is a step of that course, not
        // a correction of the prediction's error, which would pile up along the span).
        let mut span: Option<(usize, Vec3, f64, (bool, bool))> = None;
        let mut last_direction = 0.0;
        for i in self.anchor + 1..n {
            match self.goals[i] {
                Goal::Free => span = None,
                Goal::Velocity { forward, turn } => {
                    targets[FORWARD][i] = Some(forward);
                    targets[TURN][i] = Some(turn);
                    span = None;
                }
                Goal::Course {
                    position: goal_position,
                    facing,
                } => {
                    let parts = (goal_position.is_some(), facing.is_some());
                    // Without a position, the travel is free and the offset unused.
                    let p = goal_position.unwrap_or(position[i - 1]);
                    let before = self.goals[i - 1].position().unwrap_or(p);
                    let mut path_step = p - before;
                    path_step[UP] = 0.0;
                    if span.is_some_and(|s| s.3 != parts) {
                        span = None;
                    }
                    let (start, offset, facing_offset, _) = match span {
                        Some(s) => s,
                        None => {
                            // The direction the span leaves in: its commanded facing, or the
                            // path's first step, or, for a span that starts after other
                            // goals, its step to the next frame (or the facing, standing
                            // still).
                            let direction = match facing {
                                Some(f) => f,
                                None => self.leading_direction(i, p, path_step, heading[i - 1]),
                            };
                            last_direction = heading[i - 1] + wrap(direction - heading[i - 1]);
                            let mut offset = before - position[i - 1];
                            offset[UP] = 0.0;
                            let s = (i, offset, heading[i - 1] - last_direction, parts);
                            span = Some(s);
                            s
                        }
                    };
                    let fade =
                        |frame: usize| (1.0 - (frame + 1 - start) as f64 / self.catch_up).max(0.0);
                    let (now, then) = (fade(i), if i > start { fade(i - 1) } else { 1.0 });
                    if goal_position.is_some() {
                        // The wanted step: the path's, less the part of the offset this frame
                        // takes away; no faster than the clip goes.
                        let want = path_step + offset * (then - now);
                        let (ahead, aside) = self.travel(want, heading[i], facing.is_some());
                        targets[FORWARD][i] = Some(ahead);
                        targets[LEFTWARD][i] = Some(aside);
                    }
                    // The wanted facing: the commanded one or the path's direction (unwrapped
                    // along the span), plus what is left of the start's facing offset.
                    let direction = match facing {
                        Some(f) => last_direction + wrap(f - last_direction),
                        None if path_step.norm() > 1e-12 => {
                            last_direction + wrap(path_step[0].atan2(path_step[2]) - last_direction)
                        }
                        None => last_direction,
                    };
                    let wanted = |d: f64, f: f64| d + facing_offset * f;
                    targets[TURN][i] = Some(wanted(direction, now) - wanted(last_direction, then));
                    last_direction = direction;
                }
            }
        }
        for (k, row) in [FORWARD, LEFTWARD, TURN].into_iter().enumerate() {
            if targets[k].iter().all(Option::is_none) {
                continue;
            }
            let current = [&forward, &leftward, &turn][k];
            let pull: Vec<f64> = (0..n)
                .map(|i| targets[k][i].map_or(0.0, |t| self.weights[i] * (t - current[i])))
                .collect();
            let reach = if k == TURN {
                self.turn_reach
            } else {
                self.reach
            };
            let slow = lowpass::triangular(&pull, reach);
            for (v, d) in x0.row_mut(row).iter_mut().zip(slow) {
                *v = (f64::from(*v) + d / self.std[k]) as f32;
            }
        }
    }
}
