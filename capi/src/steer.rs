//! Steering through the C ABI: where a heading-relative model's character goes, frame by frame
//! and ahead of time, in a one-shot run (`sinmdm_steer`) or a stream (`sinmdm_stream_steer`),
//! and the range of commands its clip supports (`sinmdm_steer_limits`).

use sinmdm::Task;
use sinmdm::motion::math::Vec3;
use sinmdm::steer::{SteerFrame, SteerLimits};

use crate::limits::SINMDM_MAX_SAMPLE_FRAMES;
use crate::model::SinmdmModel;
use crate::result::SinmdmResult;
use crate::run::{SinmdmRun, begin, blocking};
use crate::sampling::{SinmdmSampling, request};
use crate::status::{Failure, SinmdmStatus, guard};
use crate::stream::SinmdmStream;
use crate::tasks::sampling_arg;
use crate::text::{handle, slice_arg};

/// A frame that asks for nothing: the model goes where it likes.
pub const SINMDM_STEER_FREE: u32 = 0;
/// A frame that asks for a forward speed and a turn rate.
pub const SINMDM_STEER_VELOCITY: u32 = 1;
/// A frame that asks for the root's position on the ground (facing the way the path goes).
pub const SINMDM_STEER_POSITION: u32 = 2;
/// A frame that asks for the direction the character faces (where it goes is the model's).
pub const SINMDM_STEER_FACING: u32 = 3;
/// A frame that asks for the root's position on the ground and, apart, the direction the
/// character faces (a path walked sideways or backwards).
pub const SINMDM_STEER_POSITION_FACING: u32 = 4;

/// One frame's steering command (file frame: the model's up axis and units).
#[repr(C)]
#[derive(Debug, Clone, Copy)]
pub struct SinmdmSteerFrame {
    /// `SINMDM_STEER_FREE`, `_VELOCITY`, `_POSITION`, `_FACING` or `_POSITION_FACING`.
    pub kind: u32,
    /// Set to 0 (it keeps the numbers below 8-byte aligned on every platform, 32-bit ones
    /// included, so the struct is 72 bytes everywhere).
    pub reserved: u32,
    /// `SINMDM_STEER_VELOCITY`: forward speed, file units per second.
    pub forward: f64,
    /// `SINMDM_STEER_VELOCITY`: turn rate, radians per second; positive turns left
    /// (counter-clockwise seen from above).
    pub turn: f64,
    /// `SINMDM_STEER_POSITION` and `_POSITION_FACING`: the root's position, file frame (the up
    /// component is ignored).
    pub position: [f64; 3],
    /// `SINMDM_STEER_FACING` and `_POSITION_FACING`: the direction the character faces, file
    /// frame (the up component is ignored; the rest must not be zero).
    pub facing: [f64; 3],
}

const _: () = assert!(std::mem::size_of::<SinmdmSteerFrame>() == 72);
const _: () = assert!(std::mem::offset_of!(SinmdmSteerFrame, forward) == 8);

/// The range of commands a model's clip supports (what is beyond it is clamped).
#[repr(C)]
#[derive(Debug, Clone, Copy, Default)]
pub struct SinmdmSteerLimits {
    /// Slowest forward speed, file units per second.
    pub forward_min: f64,
    /// Fastest forward speed, file units per second.
    pub forward_max: f64,
    /// Largest turn rate either way, radians per second.
    pub turn_max: f64,
    /// Fastest rightward speed (as a negative leftward one), file units per second.
    pub sideways_min: f64,
    /// Fastest leftward speed, file units per second.
    pub sideways_max: f64,
}

/// The library's commands from a caller array of at most `SINMDM_MAX_SAMPLE_FRAMES` frames.
///
/// # Safety
/// `frames` is readable for `count` values (or NULL with 0).
unsafe fn commands_arg(
    frames: *const SinmdmSteerFrame,
    count: usize,
) -> Result<Vec<SteerFrame>, Failure> {
    if count > SINMDM_MAX_SAMPLE_FRAMES {
        return Err(Failure::invalid(format!(
            "commands: {count} frames; at most {SINMDM_MAX_SAMPLE_FRAMES} (one per frame of the longest sample)"
        )));
    }
    let frames = unsafe { slice_arg(frames, count, "commands") }?;
    frames
        .iter()
        .enumerate()
        .map(|(i, f)| {
            let finite = |values: &[f64], what: &str| {
                if values.iter().all(|v| v.is_finite()) {
                    Ok(())
                } else {
                    Err(Failure::invalid(format!(
                        "commands[{i}].{what} must be finite, got {values:?}"
                    )))
                }
            };
            match f.kind {
                SINMDM_STEER_FREE => Ok(SteerFrame::Free),
                SINMDM_STEER_VELOCITY => {
                    finite(&[f.forward], "forward")?;
                    finite(&[f.turn], "turn")?;
                    Ok(SteerFrame::Velocity {
                        forward: f.forward,
                        turn: f.turn,
                    })
                }
                SINMDM_STEER_POSITION => {
                    finite(&f.position, "position")?;
                    Ok(SteerFrame::Position(Vec3(f.position)))
                }
                SINMDM_STEER_FACING => {
                    finite(&f.facing, "facing")?;
                    Ok(SteerFrame::Facing(Vec3(f.facing)))
                }
                SINMDM_STEER_POSITION_FACING => {
                    finite(&f.position, "position")?;
                    finite(&f.facing, "facing")?;
                    Ok(SteerFrame::PositionFacing {
                        position: Vec3(f.position),
                        facing: Vec3(f.facing),
                    })
                }
                other => Err(Failure::invalid(format!(
                    "commands[{i}].kind must be SINMDM_STEER_FREE (0), _VELOCITY (1), _POSITION (2), _FACING (3) or _POSITION_FACING (4), got {other}"
                ))),
            }
        })
        .collect()
}

/// Writes the range of commands `model`'s clip supports to `out`; `SINMDM_INVALID_ARGUMENT`
/// for a model without a heading-relative root (it cannot be steered).
///
/// # Safety
/// `model` is a live handle; `out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sinmdm_steer_limits(
    model: *const SinmdmModel,
    out: *mut SinmdmSteerLimits,
) -> SinmdmStatus {
    guard(|| {
        let m = unsafe { handle(model.cast_mut(), "model") }?;
        let out = unsafe { handle(out, "out") }?;
        let limits = SteerLimits::of(m.model.metadata()).ok_or_else(|| {
            Failure::invalid(
                "the model has no heading-relative root, so it cannot be steered (train it with --root-layout heading)",
            )
        })?;
        *out = SinmdmSteerLimits {
            forward_min: limits.forward.0,
            forward_max: limits.forward.1,
            turn_max: limits.turn,
            sideways_min: limits.sideways.0,
            sideways_max: limits.sideways.1,
        };
        Ok(())
    })
}

/// Begins a steered run (see `sinmdm_steer` and `sinmdm_run_step`).
///
/// # Safety
/// As `sinmdm_steer`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sinmdm_steer_begin(
    model: *mut SinmdmModel,
    sampling: *const SinmdmSampling,
    frames: usize,
    commands: *const SinmdmSteerFrame,
    command_count: usize,
    ramp: usize,
    out: *mut *mut SinmdmRun,
) -> SinmdmStatus {
    unsafe {
        begin(model, out, |_| {
            let sampling = sampling_arg(sampling)?;
            let commands = commands_arg(commands, command_count)?;
            request(
                &sampling,
                Task::Steer {
                    frames,
                    commands,
                    ramp,
                },
            )
        })
    }
}

/// New motion of `frames` frames whose root goes where `commands` say (one per frame from
/// frame 0; frames past them are free), from the model's start position and facing, soft over
/// `ramp` frames where commands start and stop (the same motion as `sinmdm steer` for the same
/// commands, seed and settings). Needs a heading-relative model.
///
/// # Safety
/// Pointers as their types' documentation says; `commands` readable for `command_count`
/// values.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sinmdm_steer(
    model: *mut SinmdmModel,
    sampling: *const SinmdmSampling,
    frames: usize,
    commands: *const SinmdmSteerFrame,
    command_count: usize,
    ramp: usize,
    out: *mut *mut SinmdmResult,
) -> SinmdmStatus {
    unsafe {
        blocking(model, out, |run| {
            sinmdm_steer_begin(model, sampling, frames, commands, command_count, ramp, run)
        })
    }
}

/// Steering commands for the frames after the last commanded one (the first call commands
/// frame 0 on; command `i` given in all belongs to stream frame `i`). A block uses the
/// commands given when it starts, so give them at least `2 x block + 10` frames ahead of what
/// has been handed out (`block`: the stream's block frames, the training clip's length by
/// default), plus whatever `sinmdm_stream_step` prepared ahead; commands for frames a block
/// has already started on are not used. `SINMDM_INVALID_ARGUMENT` for a model without a
/// heading-relative root or a value that is not finite.
///
/// # Safety
/// `stream` is a live handle; `commands` readable for `count` values.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sinmdm_stream_steer(
    stream: *mut SinmdmStream,
    commands: *const SinmdmSteerFrame,
    count: usize,
) -> SinmdmStatus {
    guard(|| {
        let stream = unsafe { handle(stream, "stream") }?;
        let commands = unsafe { commands_arg(commands, count) }?;
        stream.stream.steer(&commands)?;
        Ok(())
    })
}
