//! Steering through the C ABI: where a heading-relative model's character goes, frame by frame
//! and ahead of time, in a one-shot run (`sinmdm_steer`) or a stream (`sinmdm_stream_steer`),
//! and the range of commands its clip supports (`sinmdm_steer_limits`). Facings came later, so
//! by the C ABI's rule (struct layouts never change) they have their own command struct,
//! `SinmdmSteerCommand`, and functions (`sinmdm_steer_commands`, `_begin`,
//! `sinmdm_stream_steer_commands`, `sinmdm_steer_sideways_limits`).

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
use crate::text::{handle_mut, handle_ref, slice_arg};

/// A frame that asks for nothing: the model goes where it likes.
pub const SINMDM_STEER_FREE: u32 = 0;
/// A frame that asks for a forward speed and a turn rate.
pub const SINMDM_STEER_VELOCITY: u32 = 1;
/// A frame that asks for the root's position on the ground (facing the way the path goes).
pub const SINMDM_STEER_POSITION: u32 = 2;
/// A `SinmdmSteerCommand` that asks for the direction the character faces (where it goes is
/// the model's).
pub const SINMDM_STEER_FACING: u32 = 3;
/// A `SinmdmSteerCommand` that asks for the root's position on the ground and, apart, the
/// direction the character faces (a path walked sideways or backwards).
pub const SINMDM_STEER_POSITION_FACING: u32 = 4;

/// One frame's steering command (file frame: the model's up axis and units).
#[repr(C)]
#[derive(Debug, Clone, Copy)]
pub struct SinmdmSteerFrame {
    /// `SINMDM_STEER_FREE`, `SINMDM_STEER_VELOCITY` or `SINMDM_STEER_POSITION`.
    pub kind: u32,
    /// Set to 0; anything else gives `SINMDM_INVALID_ARGUMENT` (it keeps the numbers below
    /// 8-byte aligned on every platform, 32-bit ones included, so the struct is 48 bytes
    /// everywhere, and stays free for later use).
    pub reserved: u32,
    /// `SINMDM_STEER_VELOCITY`: forward speed, file units per second.
    pub forward: f64,
    /// `SINMDM_STEER_VELOCITY`: turn rate, radians per second; positive turns left
    /// (counter-clockwise seen from above).
    pub turn: f64,
    /// `SINMDM_STEER_POSITION`: the root's position, file frame (the up component is ignored).
    pub position: [f64; 3],
}

const _: () = assert!(std::mem::size_of::<SinmdmSteerFrame>() == 48);
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
}

/// One frame's steering command with every kind, facings included (file frame: the model's up
/// axis and units): `SinmdmSteerFrame` and a facing.
#[repr(C)]
#[derive(Debug, Clone, Copy)]
pub struct SinmdmSteerCommand {
    /// `SINMDM_STEER_FREE`, `_VELOCITY`, `_POSITION`, `_FACING` or `_POSITION_FACING`.
    pub kind: u32,
    /// Set to 0; anything else gives `SINMDM_INVALID_ARGUMENT` (it keeps the numbers below
    /// 8-byte aligned on every platform, 32-bit ones included, so the struct is 72 bytes
    /// everywhere, and stays free for later use).
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

const _: () = assert!(std::mem::size_of::<SinmdmSteerCommand>() == 72);
const _: () = assert!(std::mem::offset_of!(SinmdmSteerCommand, facing) == 48);

/// How fast a model's clip went sideways: a path walked in a facing of its own is followed no
/// faster sideways than this.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default)]
pub struct SinmdmSteerSideways {
    /// Fastest rightward speed, as a negative leftward one, file units per second.
    pub leftward_min: f64,
    /// Fastest leftward speed, file units per second.
    pub leftward_max: f64,
}

impl From<&SinmdmSteerFrame> for SinmdmSteerCommand {
    fn from(f: &SinmdmSteerFrame) -> SinmdmSteerCommand {
        SinmdmSteerCommand {
            kind: f.kind,
            reserved: f.reserved,
            forward: f.forward,
            turn: f.turn,
            position: f.position,
            facing: [0.0; 3],
        }
    }
}

/// The library's commands from a caller array of at most `SINMDM_MAX_SAMPLE_FRAMES` frames,
/// of kinds up to `last_kind` (the frame struct's kinds, or the command struct's).
///
/// # Safety
/// `frames` is readable for `count` values (or NULL with 0).
unsafe fn commands_arg<T>(
    frames: *const T,
    count: usize,
    last_kind: u32,
) -> Result<Vec<SteerFrame>, Failure>
where
    for<'a> &'a T: Into<SinmdmSteerCommand>,
{
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
            let f: SinmdmSteerCommand = f.into();
            if f.reserved != 0 {
                return Err(Failure::invalid(format!(
                    "commands[{i}].reserved must be 0, got {} (it is kept for later use)",
                    f.reserved
                )));
            }
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
                SINMDM_STEER_FACING if last_kind >= SINMDM_STEER_FACING => {
                    finite(&f.facing, "facing")?;
                    Ok(SteerFrame::Facing(Vec3(f.facing)))
                }
                SINMDM_STEER_POSITION_FACING if last_kind >= SINMDM_STEER_POSITION_FACING => {
                    finite(&f.position, "position")?;
                    finite(&f.facing, "facing")?;
                    Ok(SteerFrame::PositionFacing {
                        position: Vec3(f.position),
                        facing: Vec3(f.facing),
                    })
                }
                other if last_kind == SINMDM_STEER_POSITION => Err(Failure::invalid(format!(
                    "commands[{i}].kind must be SINMDM_STEER_FREE (0), _VELOCITY (1) or _POSITION (2), got {other} (facings take a SinmdmSteerCommand array: sinmdm_steer_commands)"
                ))),
                other => Err(Failure::invalid(format!(
                    "commands[{i}].kind must be SINMDM_STEER_FREE (0), _VELOCITY (1), _POSITION (2), _FACING (3) or _POSITION_FACING (4), got {other}"
                ))),
            }
        })
        .collect()
}

/// The steering limits of a live `model`, or why it has none.
///
/// # Safety
/// `model` is a live handle (or NULL, refused).
unsafe fn limits_of(model: *const SinmdmModel) -> Result<SteerLimits, Failure> {
    let m = unsafe { handle_ref(model, "model") }?;
    SteerLimits::of(m.model.metadata()).ok_or_else(|| {
        Failure::invalid(
            "the model has no heading-relative root, so it cannot be steered (train it with --root-layout heading)",
        )
    })
}

/// Begins a steered run from a caller array of either command struct (kinds up to
/// `last_kind`).
///
/// # Safety
/// As `sinmdm_steer`.
#[allow(clippy::too_many_arguments)]
unsafe fn steer_begin<T>(
    model: *mut SinmdmModel,
    sampling: *const SinmdmSampling,
    frames: usize,
    commands: *const T,
    command_count: usize,
    last_kind: u32,
    ramp: usize,
    out: *mut *mut SinmdmRun,
) -> SinmdmStatus
where
    for<'a> &'a T: Into<SinmdmSteerCommand>,
{
    unsafe {
        begin(model, out, |_| {
            let sampling = sampling_arg(sampling)?;
            if command_count > frames {
                return Err(Failure::invalid(format!(
                    "command_count is {command_count} for {frames} frames: one command per frame at most (more would be ignored)"
                )));
            }
            let commands = commands_arg(commands, command_count, last_kind)?;
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

/// Queues a stream's steering commands from a caller array of either command struct.
///
/// # Safety
/// As `sinmdm_stream_steer`.
unsafe fn stream_steer<T>(
    stream: *mut SinmdmStream,
    commands: *const T,
    count: usize,
    last_kind: u32,
) -> SinmdmStatus
where
    for<'a> &'a T: Into<SinmdmSteerCommand>,
{
    guard(|| {
        let stream = unsafe { handle_mut(stream, "stream") }?;
        unsafe { steer_stream(&mut stream.stream, commands, count, last_kind) }
    })
}

/// Queues steering commands from a caller array of either command struct on `stream`.
///
/// # Safety
/// `commands` readable for `count` values.
pub(crate) unsafe fn steer_stream<T>(
    stream: &mut sinmdm::Stream,
    commands: *const T,
    count: usize,
    last_kind: u32,
) -> Result<(), Failure>
where
    for<'a> &'a T: Into<SinmdmSteerCommand>,
{
    let commands = unsafe { commands_arg(commands, count, last_kind) }?;
    stream.steer(&commands)?;
    Ok(())
}

impl From<&SinmdmSteerCommand> for SinmdmSteerCommand {
    fn from(c: &SinmdmSteerCommand) -> SinmdmSteerCommand {
        *c
    }
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
        let limits = unsafe { limits_of(model) }?;
        let out = unsafe { handle_mut(out, "out") }?;
        *out = SinmdmSteerLimits {
            forward_min: limits.forward.0,
            forward_max: limits.forward.1,
            turn_max: limits.turn,
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
        steer_begin(
            model,
            sampling,
            frames,
            commands,
            command_count,
            SINMDM_STEER_POSITION,
            ramp,
            out,
        )
    }
}

/// New motion of `frames` frames whose root goes where `commands` say (one per frame from
/// frame 0; frames past them are free), from the model's start position and facing, soft over
/// `ramp` frames where commands start and stop (the same motion as `sinmdm steer` for the same
/// commands, seed and settings). Needs a heading-relative model. More commands than `frames`,
/// or a `reserved` that is not 0, give `SINMDM_INVALID_ARGUMENT`.
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
/// heading-relative root, a value that is not finite or a `reserved` that is not 0. A `count`
/// of 0 adds nothing and succeeds (`commands` may then be NULL), as any empty array does.
///
/// # Safety
/// `stream` is a live handle; `commands` readable for `count` values.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sinmdm_stream_steer(
    stream: *mut SinmdmStream,
    commands: *const SinmdmSteerFrame,
    count: usize,
) -> SinmdmStatus {
    unsafe { stream_steer(stream, commands, count, SINMDM_STEER_POSITION) }
}

/// Begins a steered run with commands of every kind, facings included (see
/// `sinmdm_steer_commands` and `sinmdm_run_step`).
///
/// # Safety
/// As `sinmdm_steer_commands`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sinmdm_steer_commands_begin(
    model: *mut SinmdmModel,
    sampling: *const SinmdmSampling,
    frames: usize,
    commands: *const SinmdmSteerCommand,
    command_count: usize,
    ramp: usize,
    out: *mut *mut SinmdmRun,
) -> SinmdmStatus {
    unsafe {
        steer_begin(
            model,
            sampling,
            frames,
            commands,
            command_count,
            SINMDM_STEER_POSITION_FACING,
            ramp,
            out,
        )
    }
}

/// `sinmdm_steer` with commands of every kind: a facing alone (`SINMDM_STEER_FACING`) or with
/// a position (`SINMDM_STEER_POSITION_FACING`) as well. `SINMDM_INVALID_ARGUMENT` for a facing
/// with no direction on the ground.
///
/// # Safety
/// Pointers as their types' documentation says; `commands` readable for `command_count`
/// values.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sinmdm_steer_commands(
    model: *mut SinmdmModel,
    sampling: *const SinmdmSampling,
    frames: usize,
    commands: *const SinmdmSteerCommand,
    command_count: usize,
    ramp: usize,
    out: *mut *mut SinmdmResult,
) -> SinmdmStatus {
    unsafe {
        blocking(model, out, |run| {
            sinmdm_steer_commands_begin(model, sampling, frames, commands, command_count, ramp, run)
        })
    }
}

/// `sinmdm_stream_steer` with commands of every kind, facings included; the two add to the
/// same queue of commands.
///
/// # Safety
/// `stream` is a live handle; `commands` readable for `count` values.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sinmdm_stream_steer_commands(
    stream: *mut SinmdmStream,
    commands: *const SinmdmSteerCommand,
    count: usize,
) -> SinmdmStatus {
    unsafe { stream_steer(stream, commands, count, SINMDM_STEER_POSITION_FACING) }
}

/// Writes how fast `model`'s clip went sideways to `out` (what a path walked in a facing of
/// its own is clamped to); `SINMDM_INVALID_ARGUMENT` for a model without a heading-relative
/// root.
///
/// # Safety
/// `model` is a live handle; `out` writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn sinmdm_steer_sideways_limits(
    model: *const SinmdmModel,
    out: *mut SinmdmSteerSideways,
) -> SinmdmStatus {
    guard(|| {
        let limits = unsafe { limits_of(model) }?;
        let out = unsafe { handle_mut(out, "out") }?;
        *out = SinmdmSteerSideways {
            leftward_min: limits.sideways.0,
            leftward_max: limits.sideways.1,
        };
        Ok(())
    })
}
