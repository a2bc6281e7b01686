//! # sinmdm-c
//!
//! The C ABI of the sinmdm runtime, for engines in C, C++, C# and anything else that calls C.
//! This text is the introduction of the header `include/sinmdm.h`, which cbindgen generates from
//! the crate (a test keeps it current). Built as a shared library (`libsinmdm_c.so`,
//! `sinmdm_c.dll`, `libsinmdm_c.dylib`) and a static one.
//!
//! Conventions, the same at every entry point:
//! - Version: `SINMDM_VERSION_MAJOR`, `_MINOR` and `_PATCH` are this header's, and
//!   `sinmdm_version()` gives the loaded library's as "MAJOR.MINOR.PATCH". A host checks at load
//!   that the library's major is the header's and, while the major is 0, its minor too (each 0.x
//!   minor may change behaviour, listed under CHANGES below); from 1 on, its minor at least.
//! - Status: every function returns a `SinmdmStatus` (the `_free` functions return nothing).
//!   On failure `sinmdm_last_error()` (per thread, valid until the next call on that thread)
//!   says why, naming the argument, field or file. One kind of mistake gets one status
//!   everywhere: a NULL pointer `SINMDM_NULL_ARGUMENT`; a value past its bound, an unknown
//!   constant or index, a `reserved` field that is not 0, malformed poses, a handle of another
//!   model `SINMDM_INVALID_ARGUMENT`; a short buffer `SINMDM_BUFFER_TOO_SMALL`. A panic inside
//!   the library is caught and returned as `SINMDM_INTERNAL`: nothing unwinds into the caller.
//! - Bounds: every count and size is checked against the `SINMDM_MAX_*` constants below before
//!   anything is read or allocated, and every size is computed in checked arithmetic.
//! - Handles are opaque and freed with their `_free` function (NULL is accepted there). A
//!   function that gives a handle through `out` sets `*out` to NULL first, so on failure it
//!   holds NULL, never a stale pointer. A run or stream takes the very model handle it was made
//!   with: another handle, even of the same file, is another model (`SINMDM_INVALID_ARGUMENT`).
//! - Buffers belong to the caller, with their capacity in elements. Strings are UTF-8 and
//!   NUL-terminated. An input array with a count of 0 is not read and may be NULL. Where a
//!   function takes a `needed` pointer (joint names, parents, rest offsets, contact joints), a
//!   NULL buffer asks for the size only and `needed` gets it; a buffer too small writes nothing
//!   and gives `SINMDM_BUFFER_TOO_SMALL` (with `needed` set). Pose buffers are sized from
//!   `sinmdm_result_frames` and `SinmdmModelInfo::joints`, and checked even for 0 frames.
//! - Memory handed in is read during the call only: `sinmdm_model_open_bytes` copies the
//!   bytes, reference poses are copied, nothing is kept.
//! - Runs in a game's frame: `sinmdm_TASK_begin` checks a request and gives an owned run;
//!   `sinmdm_run_step(run, model, k, ...)` takes at most k denoising steps (a step costs about
//!   1/50 of a default run); `sinmdm_run_finish` gives the batch (before the last step: a
//!   preview, the network's latest clean prediction); `sinmdm_run_free` cancels. A stream is
//!   prepared ahead with `sinmdm_stream_step` so `sinmdm_stream_next` never waits. Stepping a
//!   run any number of steps at a time gives the bits of the one-call task.
//! - Crowds: `sinmdm_crowd_new` holds many characters of one model, each a stream
//!   (`sinmdm_crowd_join` with `SinmdmStreamOptions`, `sinmdm_crowd_leave` at any frame,
//!   `sinmdm_crowd_steer` and `sinmdm_crowd_supply` per character); `sinmdm_crowd_step` steps
//!   every character short of frames together, one network call for many blocks, and
//!   `sinmdm_crowd_next` reads one character. A character is the same bits as its stream alone,
//!   whatever else is in the crowd and whatever `threads` is.
//! - Progress and cancel on a worker thread: `sinmdm_model_set_progress` sets a callback
//!   (`userdata` first) called after each step of a blocking task, the last included (never by
//!   `sinmdm_run_step`); returning `SINMDM_PROGRESS_CANCEL` after any step makes the call return
//!   `SINMDM_CANCELLED` with no result, and the model stays usable.
//! - Threads: a handle may move between threads but must be used by one thread at a time; a
//!   model and the runs and streams that run on it count as one. Different models may run at
//!   once on different threads. `sinmdm_load_onnxruntime` and `sinmdm_last_error` may be
//!   called from any thread. These are all the threads the library starts or has started:
//!   when onnxruntime is loaded (`sinmdm_load_onnxruntime`, or the first model opened),
//!   onnxruntime's environment may start threads of its own (at most one with onnxruntime
//!   1.31.1, which waits on a timer, and none where the environment variable `CI` is set), and
//!   they live until the process ends, since the environment is made once per process and never
//!   freed; for each run or stream block in progress (not a crowd's: it draws on the calling
//!   thread), one that draws the next step's noise (it ends on its own soon after the run is finished or freed,
//!   or the block is done); for a batch of several samples on a model opened with `threads` >
//!   1, up to `threads - 1` that each run samples during a denoising call and are joined
//!   before it returns. onnxruntime runs the network on the calling thread (one intra-op
//!   thread, no pool).
//! - The same bits on every machine: the same model file, seed and arguments give the same
//!   poses whatever `threads` is and wherever a sample sits in its batch (each sample is its
//!   own onnxruntime call on one intra-op thread), through this ABI, the Rust API and the
//!   Python reference alike; `threads` changes speed only. What the bits still depend on is
//!   onnxruntime's choice of CPU kernels by instruction set (AVX2, AVX-512, NEON): machines
//!   with the same set agree (onnxruntime 1.17.0, 1.19.2, 1.20.1 and 1.31.1 gave the same bits
//!   on AVX2).
//! - Which sample is which: a batch's noise is one stream of the seed laid out sample after
//!   sample, so sample k of a batch is the same bits in every batch of more than k samples
//!   with the same seed and arguments, and a batch of `count = 1` gives sample 0. To make crowd
//!   member k again alone, ask for `count = k + 1` and read sample k (no seed gives member k
//!   in a batch of 1; another seed is another crowd).
//! - onnxruntime is loaded at run time, release 1.17 or later (tested with 1.17.0, 1.19.2,
//!   1.20.1 and 1.31.1). `sinmdm_load_onnxruntime(path)` names it;
//!   otherwise the first model opened looks, in order: `ORT_DYLIB_PATH`, next to the
//!   executable, next to this library, the system loader's search path, a developer
//!   checkout's `.venv`; when none loads, `SINMDM_RUNTIME_LIBRARY`'s message names these
//!   five places in this order with what each gave. On Windows the loader's path reaches
//!   System32, where Windows may keep an onnxruntime.dll of its own and of another release:
//!   ship yours next to the executable (or the plugin) so it is found first. A release older
//!   than 1.17 is refused.
//! - Poses are in the model file's frame: right-handed, its up axis (`sinmdm_model_info`) and
//!   its units; quaternions are `x, y, z, w`. See the README's Embedding section for Unity and
//!   Unreal.
//! - Memory checkers: `valgrind --leak-check=full --error-exitcode=1
//!   --suppressions=capi/tests/c/onnxruntime.supp HOST ARGS` exits 0 on the project's C checks
//!   (the C ABI's tests run exactly that). The file suppresses only reports that are not the
//!   project's: glibc's loader reading a word at a time, onnxruntime 1.31.1 at start-up and its
//!   own thread reading freed memory as the process exits, and the 48-byte handle Rust's
//!   standard library keeps for each live thread that has called in ("possibly lost" at exit,
//!   freed when the thread ends).
//! - Compatibility: the layout of the structs here does not change; new abilities come as new
//!   functions.
//!
//! CHANGES (behaviour a host can notice; version 0.1.0 against earlier builds of this ABI):
//! - `sinmdm_stream_next` checks its buffers for 0 frames too: NULL gives
//!   `SINMDM_NULL_ARGUMENT` (it gave `SINMDM_OK`).
//! - A run or stream given another handle of the same model file gives
//!   `SINMDM_INVALID_ARGUMENT` (it worked); it takes the handle it was made with.
//! - A progress callback that cancels at the last step gives `SINMDM_CANCELLED` and no result
//!   (it gave `SINMDM_OK` and the result).
//! - `SinmdmSteerFrame`'s and `SinmdmSteerCommand`'s `reserved` other than 0, and more steering
//!   commands than frames, give `SINMDM_INVALID_ARGUMENT` (they were ignored).
//! - New: crowds (`sinmdm_crowd_*`, `SINMDM_MAX_CROWD_CHARACTERS`).
//! - New: the `SINMDM_VERSION_*` macros and `sinmdm_model_values_per_frame` (the factor of
//!   `SINMDM_MAX_RUN_VALUES`); the onnxruntime-not-found message names every place searched.

#![warn(missing_docs)]

mod crowd;
mod dance;
mod limits;
mod model;
mod poses;
mod result;
mod run;
mod sampling;
mod status;
mod steer;
mod stream;
mod tasks;
mod text;

pub use crowd::{
    SinmdmCrowd, sinmdm_crowd_count, sinmdm_crowd_free, sinmdm_crowd_join, sinmdm_crowd_leave,
    sinmdm_crowd_new, sinmdm_crowd_next, sinmdm_crowd_steer, sinmdm_crowd_step,
    sinmdm_crowd_supply,
};
pub use dance::{
    SINMDM_DANCE_HOLD, SINMDM_DANCE_LEVEL_AUTO, SINMDM_DANCE_LEVEL_EVERY,
    SINMDM_DANCE_LEVEL_EVERY_OTHER, SINMDM_DANCE_LEVEL_HALF, SINMDM_DANCE_ORDER_REFERENCE,
    SINMDM_DANCE_ORDER_SHUFFLED, SINMDM_DANCE_RAMP, SinmdmDance, sinmdm_dance, sinmdm_dance_begin,
    sinmdm_dance_reference_beats,
};
pub use limits::{
    SINMDM_MAX_CROWD_CHARACTERS, SINMDM_MAX_JOINT_INDICES, SINMDM_MAX_MODEL_BYTES,
    SINMDM_MAX_RAMP_FRAMES, SINMDM_MAX_RUN_VALUES, SINMDM_MAX_SAMPLE_FRAMES, SINMDM_MAX_SAMPLES,
    SINMDM_MAX_THREADS,
};
pub use model::{
    SINMDM_PROGRESS_CANCEL, SINMDM_PROGRESS_CONTINUE, SINMDM_VERSION_MAJOR, SINMDM_VERSION_MINOR,
    SINMDM_VERSION_PATCH, SinmdmModel, SinmdmModelInfo, SinmdmProgressFn, sinmdm_load_onnxruntime,
    sinmdm_model_contact_joints, sinmdm_model_find_joint, sinmdm_model_free, sinmdm_model_info,
    sinmdm_model_joint_name, sinmdm_model_open, sinmdm_model_open_bytes, sinmdm_model_parents,
    sinmdm_model_rest_offsets, sinmdm_model_set_progress, sinmdm_model_values_per_frame,
    sinmdm_version,
};
pub use poses::{SinmdmPoseBuffers, SinmdmPoses, sinmdm_write_bvh};
pub use result::{
    SinmdmResult, sinmdm_result_count, sinmdm_result_frames, sinmdm_result_free,
    sinmdm_result_poses,
};
pub use run::{SinmdmRun, sinmdm_run_finish, sinmdm_run_free, sinmdm_run_step};
pub use sampling::{
    SINMDM_ALL_STEPS, SINMDM_DEFAULT_STEPS, SINMDM_DEFAULT_STREAM_STEPS, SINMDM_FEET_PLANTED,
    SINMDM_FEET_RAW, SINMDM_METHOD_ANCESTRAL, SINMDM_METHOD_DDIM, SINMDM_METHOD_DPM2M,
    SinmdmSampling, SinmdmSpan,
};
pub use status::{SinmdmStatus, sinmdm_last_error};
pub use steer::{
    SINMDM_STEER_FACING, SINMDM_STEER_FREE, SINMDM_STEER_POSITION, SINMDM_STEER_POSITION_FACING,
    SINMDM_STEER_VELOCITY, SinmdmSteerCommand, SinmdmSteerFrame, SinmdmSteerLimits,
    SinmdmSteerSideways, sinmdm_steer, sinmdm_steer_begin, sinmdm_steer_commands,
    sinmdm_steer_commands_begin, sinmdm_steer_limits, sinmdm_steer_sideways_limits,
    sinmdm_stream_steer, sinmdm_stream_steer_commands,
};
pub use stream::{
    SinmdmStream, SinmdmStreamOptions, sinmdm_stream_free, sinmdm_stream_new, sinmdm_stream_next,
    sinmdm_stream_step, sinmdm_stream_supply,
};
pub use tasks::{
    sinmdm_compose, sinmdm_compose_begin, sinmdm_expand, sinmdm_expand_begin, sinmdm_generate,
    sinmdm_generate_begin, sinmdm_harmonize, sinmdm_harmonize_begin, sinmdm_inbetween,
    sinmdm_inbetween_begin,
};
pub use text::sinmdm_live_handles;
