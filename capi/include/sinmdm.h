/*
 * # sinmdm-c
 *
 * The C ABI of the sinmdm runtime, for engines in C, C++, C# and anything else that calls C.
 * This text is the introduction of the header include/sinmdm.h, which cbindgen generates from
 * the crate (a test keeps it current). Built as a shared library (libsinmdm_c.so,
 * sinmdm_c.dll, libsinmdm_c.dylib) and a static one.
 *
 * Conventions, the same at every entry point:
 * - Version: SINMDM_VERSION_MAJOR, _MINOR and _PATCH are this header's, and
 *   sinmdm_version() gives the loaded library's as "MAJOR.MINOR.PATCH". A host checks at load
 *   that the library's major is the header's and, while the major is 0, its minor too (each 0.x
 *   minor may change behaviour, listed under CHANGES below); from 1 on, its minor at least.
 * - Status: every function returns a SinmdmStatus (the _free functions return nothing).
 *   On failure sinmdm_last_error() (per thread, valid until the next call on that thread)
 *   says why, naming the argument, field or file. One kind of mistake gets one status
 *   everywhere: a NULL pointer SINMDM_NULL_ARGUMENT; a value past its bound, an unknown
 *   constant or index, a reserved field that is not 0, malformed poses, a handle of another
 *   model SINMDM_INVALID_ARGUMENT; a short buffer SINMDM_BUFFER_TOO_SMALL. A panic inside
 *   the library is caught and returned as SINMDM_INTERNAL: nothing unwinds into the caller.
 * - Bounds: every count and size is checked against the SINMDM_MAX_* constants below before
 *   anything is read or allocated, and every size is computed in checked arithmetic.
 * - Handles are opaque and freed with their _free function (NULL is accepted there). A
 *   function that gives a handle through out sets *out to NULL first, so on failure it
 *   holds NULL, never a stale pointer. A run or stream takes the very model handle it was made
 *   with: another handle, even of the same file, is another model (SINMDM_INVALID_ARGUMENT).
 * - Buffers belong to the caller, with their capacity in elements. Strings are UTF-8 and
 *   NUL-terminated. An input array with a count of 0 is not read and may be NULL. Where a
 *   function takes a needed pointer (joint names, parents, rest offsets, contact joints), a
 *   NULL buffer asks for the size only and needed gets it; a buffer too small writes nothing
 *   and gives SINMDM_BUFFER_TOO_SMALL (with needed set). Pose buffers are sized from
 *   sinmdm_result_frames and SinmdmModelInfo::joints, and checked even for 0 frames.
 * - Memory handed in is read during the call only: sinmdm_model_open_bytes copies the
 *   bytes, reference poses are copied, nothing is kept.
 * - Runs in a game's frame: sinmdm_TASK_begin checks a request and gives an owned run;
 *   sinmdm_run_step(run, model, k, ...) takes at most k denoising steps (a step costs about
 *   1/50 of a default run); sinmdm_run_finish gives the batch (before the last step: a
 *   preview, the network's latest clean prediction); sinmdm_run_free cancels. A stream is
 *   prepared ahead with sinmdm_stream_step so sinmdm_stream_next never waits. Stepping a
 *   run any number of steps at a time gives the bits of the one-call task.
 * - Crowds: sinmdm_crowd_new holds many characters of one model, each a stream
 *   (sinmdm_crowd_join with SinmdmStreamOptions, sinmdm_crowd_leave at any frame,
 *   sinmdm_crowd_steer and sinmdm_crowd_supply per character); sinmdm_crowd_step steps
 *   every character short of frames together, one network call for many blocks, and
 *   sinmdm_crowd_next reads one character. A character is the same bits as its stream alone,
 *   whatever else is in the crowd and whatever threads is.
 * - Progress and cancel on a worker thread: sinmdm_model_set_progress sets a callback
 *   (userdata first) called after each step of a blocking task, the last included (never by
 *   sinmdm_run_step); returning SINMDM_PROGRESS_CANCEL after any step makes the call return
 *   SINMDM_CANCELLED with no result, and the model stays usable.
 * - Threads: a handle may move between threads but must be used by one thread at a time; a
 *   model and the runs and streams that run on it count as one. Different models may run at
 *   once on different threads. sinmdm_load_onnxruntime and sinmdm_last_error may be
 *   called from any thread. These are all the threads the library starts or has started:
 *   when onnxruntime is loaded (sinmdm_load_onnxruntime, or the first model opened),
 *   onnxruntime's environment may start threads of its own (at most one with onnxruntime
 *   1.31.1, which waits on a timer, and none where the environment variable CI is set), and
 *   they live until the process ends, since the environment is made once per process and never
 *   freed; for each run or stream block in progress (not a crowd's: it draws on the calling
 *   thread), one that draws the next step's noise (it ends on its own soon after the run is finished or freed,
 *   or the block is done); for a batch of several samples on a model opened with threads >
 *   1, up to threads - 1 that each run samples during a denoising call and are joined
 *   before it returns. onnxruntime runs the network on the calling thread (one intra-op
 *   thread, no pool).
 * - The same bits on every machine: the same model file, seed and arguments give the same
 *   poses whatever threads is and wherever a sample sits in its batch (each sample is its
 *   own onnxruntime call on one intra-op thread), through this ABI, the Rust API and the
 *   Python reference alike; threads changes speed only. What the bits still depend on is
 *   onnxruntime's choice of CPU kernels by instruction set (AVX2, AVX-512, NEON): machines
 *   with the same set agree (onnxruntime 1.17.0, 1.19.2, 1.20.1 and 1.31.1 gave the same bits
 *   on AVX2).
 * - Which sample is which: a batch's noise is one stream of the seed laid out sample after
 *   sample, so sample k of a batch is the same bits in every batch of more than k samples
 *   with the same seed and arguments, and a batch of count = 1 gives sample 0. To make crowd
 *   member k again alone, ask for count = k + 1 and read sample k (no seed gives member k
 *   in a batch of 1; another seed is another crowd).
 * - onnxruntime is loaded at run time, release 1.17 or later (tested with 1.17.0, 1.19.2,
 *   1.20.1 and 1.31.1). sinmdm_load_onnxruntime(path) names it;
 *   otherwise the first model opened looks, in order: ORT_DYLIB_PATH, next to the
 *   executable, next to this library, the system loader's search path, a developer
 *   checkout's .venv; when none loads, SINMDM_RUNTIME_LIBRARY's message names these
 *   five places in this order with what each gave. On Windows the loader's path reaches
 *   System32, where Windows may keep an onnxruntime.dll of its own and of another release:
 *   ship yours next to the executable (or the plugin) so it is found first. A release older
 *   than 1.17 is refused.
 * - Poses are in the model file's frame: right-handed, its up axis (sinmdm_model_info) and
 *   its units; quaternions are x, y, z, w. See the README's Embedding section for Unity and
 *   Unreal.
 * - Memory checkers: valgrind --leak-check=full --error-exitcode=1
 *   --suppressions=capi/tests/c/onnxruntime.supp HOST ARGS exits 0 on the project's C checks
 *   (the C ABI's tests run exactly that). The file suppresses only reports that are not the
 *   project's: glibc's loader reading a word at a time, onnxruntime 1.31.1 at start-up and its
 *   own thread reading freed memory as the process exits, and the 48-byte handle Rust's
 *   standard library keeps for each live thread that has called in ("possibly lost" at exit,
 *   freed when the thread ends).
 * - Compatibility: the layout of the structs here does not change; new abilities come as new
 *   functions.
 *
 * CHANGES (behaviour a host can notice; version 0.1.0 against earlier builds of this ABI):
 * - sinmdm_stream_next checks its buffers for 0 frames too: NULL gives
 *   SINMDM_NULL_ARGUMENT (it gave SINMDM_OK).
 * - A run or stream given another handle of the same model file gives
 *   SINMDM_INVALID_ARGUMENT (it worked); it takes the handle it was made with.
 * - A progress callback that cancels at the last step gives SINMDM_CANCELLED and no result
 *   (it gave SINMDM_OK and the result).
 * - SinmdmSteerFrame's and SinmdmSteerCommand's reserved other than 0, and more steering
 *   commands than frames, give SINMDM_INVALID_ARGUMENT (they were ignored).
 * - New: crowds (sinmdm_crowd_*, SINMDM_MAX_CROWD_CHARACTERS).
 * - New: the SINMDM_VERSION_* macros and sinmdm_model_values_per_frame (the factor of
 *   SINMDM_MAX_RUN_VALUES); the onnxruntime-not-found message names every place searched.
 */

#ifndef SINMDM_H
#define SINMDM_H

/* Generated from capi/src by cbindgen (capi/tests/header.rs checks it is current). Do not edit. */

#include <stdarg.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>

/*
 Keyframe order: each pass over the reference's beats in an order drawn from the seed (the
 default).
 */
#define SINMDM_DANCE_ORDER_SHUFFLED 0

/*
 Keyframe order: the reference's own, over and over.
 */
#define SINMDM_DANCE_ORDER_REFERENCE 1

/*
 Beat level: the one that brings the music's tempo nearest the reference's (the default).
 */
#define SINMDM_DANCE_LEVEL_AUTO 0

/*
 Beat level: every music beat carries a keyframe.
 */
#define SINMDM_DANCE_LEVEL_EVERY 1

/*
 Beat level: every other music beat, from the first.
 */
#define SINMDM_DANCE_LEVEL_EVERY_OTHER 2

/*
 Beat level: every music beat and the frame half-way to the next.
 */
#define SINMDM_DANCE_LEVEL_HALF 3

/*
 Default half-width of a keyframe window, in frames (`hold` of 0 takes it too); the
 library's `DANCE_HOLD`, which a test keeps equal.
 */
#define SINMDM_DANCE_HOLD 12

/*
 Default soft border of a keyframe window, in frames (the library's `DANCE_RAMP`).
 */
#define SINMDM_DANCE_RAMP 13

/*
 The longest sample a task makes, and the longest stream chunk or block, in frames
 (`SinmdmPoses.frames`, `frames` of `sinmdm_generate` and `sinmdm_stream_next`, a task's
 length after expansion).
 */
#define SINMDM_MAX_SAMPLE_FRAMES 100000

/*
 The widest soft border (`ramp`) of a task's kept spans, in frames.
 */
#define SINMDM_MAX_RAMP_FRAMES 100000

/*
 The largest crowd one run makes (`SinmdmSampling.count`).
 */
#define SINMDM_MAX_SAMPLES 1024

/*
 The most characters a crowd holds at once (`sinmdm_crowd_join`).
 */
#define SINMDM_MAX_CROWD_CHARACTERS 65536

/*
 The largest working set one run may need, in f32 values (1 GiB): a request is refused
 before anything runs when `count x frames x values` passes it, `values` being what
 `sinmdm_model_values_per_frame` gives for the model: `max(F + 8 C, 12 x joints)`, with F
 `SinmdmModelInfo::features` and C the network's channels (64 in the shipped models).
 */
#define SINMDM_MAX_RUN_VALUES (1 << 28)

/*
 The most threads a model runs samples on (`threads` of `sinmdm_model_open*`; 0 = every core).
 */
#define SINMDM_MAX_THREADS 1024

/*
 The most spans a task takes (`span_count`): each covers at least one frame of at most
 `SINMDM_MAX_SAMPLE_FRAMES`.
 */
#define SINMDM_MAX_SPANS 100000

/*
 The most joint indices a composition takes (`joint_count`, `compose_joint_count`): four times
 the most joints a skeleton may have (repeats are allowed).
 */
#define SINMDM_MAX_JOINT_INDICES 16384

/*
 The largest model `sinmdm_model_open_bytes` takes, in bytes (protobuf's 2 GiB limit on an
 ONNX file).
 */
#define SINMDM_MAX_MODEL_BYTES 2147483647

/*
 A progress callback's answer: go on.
 */
#define SINMDM_PROGRESS_CONTINUE 0

/*
 A progress callback's answer: stop the run (any value but 0 does the same).
 */
#define SINMDM_PROGRESS_CANCEL 1

/*
 The major version of this header: a library of another major may break it.
 */
#define SINMDM_VERSION_MAJOR 0

/*
 The minor version of this header: a newer minor adds (and, while the major is 0, may change
 what the header's CHANGES list).
 */
#define SINMDM_VERSION_MINOR 1

/*
 The patch version of this header: fixes only.
 */
#define SINMDM_VERSION_PATCH 0

/*
 Respaced sampling steps of the command line (the library's `DEFAULT_STEPS`); what a `steps`
 of 0 gives in `SinmdmSampling` (a stream's is `SINMDM_DEFAULT_STREAM_STEPS`).
 */
#define SINMDM_DEFAULT_STEPS 50

/*
 Respaced sampling steps per block of a stream (the library's `DEFAULT_STREAM_STEPS`); what a
 `steps` of 0 gives in `SinmdmStreamOptions`.
 */
#define SINMDM_DEFAULT_STREAM_STEPS 20

/*
 A `steps` value that runs all of the model's diffusion steps T (slow; the reference quality).
 */
#define SINMDM_ALL_STEPS UINT32_MAX

/*
 Feet: contact points held still on the ground (the default).
 */
#define SINMDM_FEET_PLANTED 0

/*
 Feet: the network's motion untouched.
 */
#define SINMDM_FEET_RAW 1

/*
 Sampling method: ancestral DDPM (the paper's sampler; the default).
 */
#define SINMDM_METHOD_ANCESTRAL 0

/*
 Sampling method: DDIM, with `eta` the share of the ancestral noise (0: deterministic).
 */
#define SINMDM_METHOD_DDIM 1

/*
 Sampling method: DPM-Solver++(2M), deterministic, good motion in fewer steps.
 */
#define SINMDM_METHOD_DPM2M 2

/*
 A frame that asks for nothing: the model goes where it likes.
 */
#define SINMDM_STEER_FREE 0

/*
 A frame that asks for a forward speed and a turn rate.
 */
#define SINMDM_STEER_VELOCITY 1

/*
 A frame that asks for the root's position on the ground (facing the way the path goes).
 */
#define SINMDM_STEER_POSITION 2

/*
 A `SinmdmSteerCommand` that asks for the direction the character faces (where it goes is
 the model's).
 */
#define SINMDM_STEER_FACING 3

/*
 A `SinmdmSteerCommand` that asks for the root's position on the ground and, apart, the
 direction the character faces (a path walked sideways or backwards).
 */
#define SINMDM_STEER_POSITION_FACING 4

/*
 What a call did. Every function returns one; on anything but `SINMDM_OK`,
 `sinmdm_last_error` says why, in words that name the argument, field or file. One kind of
 mistake always gets the same status, whichever function it is made at.
 */
typedef enum SinmdmStatus {
  /*
   It worked.
   */
  SINMDM_OK = 0,
  /*
   A pointer that must not be NULL was NULL.
   */
  SINMDM_NULL_ARGUMENT = 1,
  /*
   An argument outside its documented range, or malformed: a count, length, step count,
   ramp, span, joint index, factor, share or thread count past its bound (`SINMDM_MAX_*`),
   an unknown constant, a string that is not UTF-8, poses that do not fit the skeleton, a
   handle used with another model, or a call its handle's state does not allow.
   */
  SINMDM_INVALID_ARGUMENT = 2,
  /*
   An output buffer too small; nothing was written and the message gives the size needed
   (pass a NULL buffer to ask for it).
   */
  SINMDM_BUFFER_TOO_SMALL = 3,
  /*
   A joint name the skeleton does not have.
   */
  SINMDM_UNKNOWN_JOINT = 4,
  /*
   onnxruntime could not be found or loaded (the message lists where it was looked for).
   */
  SINMDM_RUNTIME_LIBRARY = 5,
  /*
   A model file that could not be opened or is not a valid model.
   */
  SINMDM_BAD_MODEL = 6,
  /*
   A valid request whose run failed inside onnxruntime (out of memory, say).
   */
  SINMDM_TASK_FAILED = 7,
  /*
   Reading or writing a file failed.
   */
  SINMDM_IO = 8,
  /*
   A bug in the library (a caught panic); the handle involved should be freed.
   */
  SINMDM_INTERNAL = 9,
  /*
   A blocking task's progress callback asked to stop, after any step, the last included: the
   call gives no result and the model can be used on. Only blocking tasks call the callback,
   so a stepped run (`sinmdm_run_step`) never gives this; a host stops one by freeing it.
   */
  SINMDM_CANCELLED = 10,
} SinmdmStatus;

/*
 A crowd (opaque): characters of one model, each an endless stream, made together.
 */
typedef struct SinmdmCrowd SinmdmCrowd;

/*
 An open model (opaque): the network and its metadata.
 */
typedef struct SinmdmModel SinmdmModel;

/*
 A generated batch (opaque).
 */
typedef struct SinmdmResult SinmdmResult;

/*
 A task being run (opaque): it owns its plan, schedule, guidance, noise and sample, not the
 model; each step is given the model it was begun on.
 */
typedef struct SinmdmRun SinmdmRun;

/*
 A stream (opaque): motion handed out a chunk at a time, forever, in flat memory.
 */
typedef struct SinmdmStream SinmdmStream;

/*
 How a stream makes its motion; zeros give the defaults.
 */
typedef struct SinmdmStreamOptions {
  /*
   Seed of the portable noise.
   */
  uint64_t seed;
  /*
   Respaced denoising steps per block; 0 for `SINMDM_DEFAULT_STREAM_STEPS`, `SINMDM_ALL_STEPS` for
   all of the model's T.
   */
  uint32_t steps;
  /*
   Frames each block makes final; 0 for the length of the model's training clip.
   */
  uint32_t block_frames;
  /*
   `SINMDM_FEET_PLANTED` or `SINMDM_FEET_RAW`.
   */
  uint32_t feet;
  /*
   Joints taken from poses supplied with `sinmdm_stream_supply` (NULL with count 0: none).
   */
  const size_t *compose_joints;
  /*
   Entries of `compose_joints`.
   */
  size_t compose_joint_count;
  /*
   Not 0: the root's travel and height also come from the supplied poses.
   */
  int32_t compose_root;
  /*
   `SINMDM_METHOD_ANCESTRAL` (0, the default), `SINMDM_METHOD_DDIM` or `SINMDM_METHOD_DPM2M`.
   */
  uint32_t method;
  /*
   DDIM's share of the ancestral noise, 0 to 1.
   */
  double eta;
} SinmdmStreamOptions;

/*
 One frame's steering command with every kind, facings included (file frame: the model's up
 axis and units): `SinmdmSteerFrame` and a facing.
 */
typedef struct SinmdmSteerCommand {
  /*
   `SINMDM_STEER_FREE`, `_VELOCITY`, `_POSITION`, `_FACING` or `_POSITION_FACING`.
   */
  uint32_t kind;
  /*
   Set to 0; anything else gives `SINMDM_INVALID_ARGUMENT` (it keeps the numbers below
   8-byte aligned on every platform, 32-bit ones included, so the struct is 72 bytes
   everywhere, and stays free for later use).
   */
  uint32_t reserved;
  /*
   `SINMDM_STEER_VELOCITY`: forward speed, file units per second.
   */
  double forward;
  /*
   `SINMDM_STEER_VELOCITY`: turn rate, radians per second; positive turns left
   (counter-clockwise seen from above).
   */
  double turn;
  /*
   `SINMDM_STEER_POSITION` and `_POSITION_FACING`: the root's position, file frame (the up
   component is ignored).
   */
  double position[3];
  /*
   `SINMDM_STEER_FACING` and `_POSITION_FACING`: the direction the character faces, file
   frame (the up component is ignored; the rest must not be zero).
   */
  double facing[3];
} SinmdmSteerCommand;

/*
 Poses given to the library, `frames` of them for the model's `joints` joints, as flat
 arrays in the model file's frame and units.
 */
typedef struct SinmdmPoses {
  /*
   Frames.
   */
  size_t frames;
  /*
   The root joint's position per frame: `3 x frames` floats.
   */
  const float *root_positions;
  /*
   Every joint's local rotation per frame, `x, y, z, w`: `4 x joints x frames` floats.
   */
  const float *rotations;
  /*
   Every joint's local translation per frame: `3 x joints x frames` floats, or NULL for
   the rest offsets (what a skeleton without stretching has).
   */
  const float *translations;
} SinmdmPoses;

/*
 Caller-owned arrays the library fills with poses; capacities are in floats. Needed: root
 positions `3 x frames`, rotations `4 x joints x frames`, translations `3 x joints x frames`
 (translations may be NULL when not wanted).
 */
typedef struct SinmdmPoseBuffers {
  /*
   Root position per frame.
   */
  float *root_positions;
  /*
   Capacity of `root_positions`.
   */
  size_t root_positions_capacity;
  /*
   Local rotation (`x, y, z, w`) per frame and joint.
   */
  float *rotations;
  /*
   Capacity of `rotations`.
   */
  size_t rotations_capacity;
  /*
   Local translation per frame and joint, or NULL.
   */
  float *translations;
  /*
   Capacity of `translations`.
   */
  size_t translations_capacity;
} SinmdmPoseBuffers;

/*
 Sampling settings shared by every task. The same model, settings and arguments give the same
 poses, here, in Rust and in the Python reference.
 */
typedef struct SinmdmSampling {
  /*
   Seed of the portable noise.
   */
  uint64_t seed;
  /*
   Samples in the batch (a crowd when more than 1).
   */
  uint32_t count;
  /*
   Respaced denoising steps; 0 for `SINMDM_DEFAULT_STEPS`, `SINMDM_ALL_STEPS` for all of
   the model's T.
   */
  uint32_t steps;
  /*
   `SINMDM_FEET_PLANTED` or `SINMDM_FEET_RAW`.
   */
  uint32_t feet;
  /*
   `SINMDM_METHOD_ANCESTRAL` (0, the default), `SINMDM_METHOD_DDIM` or `SINMDM_METHOD_DPM2M`.
   */
  uint32_t method;
  /*
   DDIM's share of the ancestral noise, 0 to 1 (ignored by the other methods).
   */
  double eta;
} SinmdmSampling;

/*
 A dance's beats and placement. Beat frames are at the model's frame rate, increasing.
 */
typedef struct SinmdmDance {
  /*
   The reference's beats (frames of the reference poses), e.g. from
   `sinmdm_dance_reference_beats`.
   */
  const size_t *reference_beats;
  /*
   Values in `reference_beats`.
   */
  size_t reference_beat_count;
  /*
   The music's beats (frames of the output).
   */
  const size_t *music_beats;
  /*
   Values in `music_beats`.
   */
  size_t music_beat_count;
  /*
   Frames of the output.
   */
  size_t frames;
  /*
   Half-width of each keyframe window in frames; 0 takes `SINMDM_DANCE_HOLD`.
   */
  size_t hold;
  /*
   Soft border on the kept side of each window, in frames (at most `hold + 1` is used).
   */
  size_t ramp;
  /*
   `SINMDM_DANCE_ORDER_*`.
   */
  uint32_t order;
  /*
   `SINMDM_DANCE_LEVEL_*`.
   */
  uint32_t level;
  /*
   1: the root's travel and height in each window come from the reference; 0: generated.
   */
  uint32_t keep_root;
} SinmdmDance;

/*
 A progress callback: called after each denoising step of a blocking task on the model it was
 set on, with the host's `userdata` first, then the steps done and the steps in all. Return
 `SINMDM_PROGRESS_CONTINUE` to go on, or `SINMDM_PROGRESS_CANCEL` (any value but 0) to stop:
 the call then returns `SINMDM_CANCELLED` and gives no result. It runs on the thread that
 made the call and must not call back into the library with the same model.
 */
typedef int32_t (*SinmdmProgressFn)(void *userdata, size_t done, size_t total);

/*
 The facts of a model an engine needs to hold its poses.
 */
typedef struct SinmdmModelInfo {
  /*
   Joints in the skeleton (End Sites are not joints).
   */
  size_t joints;
  /*
   Feature rows of the network.
   */
  size_t features;
  /*
   Contact joints (their indices: `sinmdm_model_contact_joints`).
   */
  size_t contact_joints;
  /*
   Frames per second of the motion it makes.
   */
  double fps;
  /*
   The figure's height in file units (a human clip in centimetres is about 170).
   */
  double skeleton_height;
  /*
   The file's up axis as a unit vector (0,1,0 for Y-up, 0,0,1 for Z-up).
   */
  double up[3];
  /*
   Frames of the clip the model was trained on.
   */
  size_t clip_frames;
  /*
   The network's receptive field in frames.
   */
  size_t receptive_field;
  /*
   Diffusion steps T (the most a run can take).
   */
  size_t diffusion_steps;
} SinmdmModelInfo;

/*
 The range of commands a model's clip supports (what is beyond it is clamped).
 */
typedef struct SinmdmSteerLimits {
  /*
   Slowest forward speed, file units per second.
   */
  double forward_min;
  /*
   Fastest forward speed, file units per second.
   */
  double forward_max;
  /*
   Largest turn rate either way, radians per second.
   */
  double turn_max;
} SinmdmSteerLimits;

/*
 One frame's steering command (file frame: the model's up axis and units).
 */
typedef struct SinmdmSteerFrame {
  /*
   `SINMDM_STEER_FREE`, `SINMDM_STEER_VELOCITY` or `SINMDM_STEER_POSITION`.
   */
  uint32_t kind;
  /*
   Set to 0; anything else gives `SINMDM_INVALID_ARGUMENT` (it keeps the numbers below
   8-byte aligned on every platform, 32-bit ones included, so the struct is 48 bytes
   everywhere, and stays free for later use).
   */
  uint32_t reserved;
  /*
   `SINMDM_STEER_VELOCITY`: forward speed, file units per second.
   */
  double forward;
  /*
   `SINMDM_STEER_VELOCITY`: turn rate, radians per second; positive turns left
   (counter-clockwise seen from above).
   */
  double turn;
  /*
   `SINMDM_STEER_POSITION`: the root's position, file frame (the up component is ignored).
   */
  double position[3];
} SinmdmSteerFrame;

/*
 How fast a model's clip went sideways: a path walked in a facing of its own is followed no
 faster sideways than this.
 */
typedef struct SinmdmSteerSideways {
  /*
   Fastest rightward speed, as a negative leftward one, file units per second.
   */
  double leftward_min;
  /*
   Fastest leftward speed, file units per second.
   */
  double leftward_max;
} SinmdmSteerSideways;

/*
 A span of frames `start..end` (end excluded).
 */
typedef struct SinmdmSpan {
  /*
   First frame.
   */
  size_t start;
  /*
   One past the last frame.
   */
  size_t end;
} SinmdmSpan;

#ifdef __cplusplus
extern "C" {
#endif // __cplusplus

/*
 Makes an empty crowd of `model` and writes its handle to `out`.

 # Safety
 `model` is a live handle; `out` writable.
 */
enum SinmdmStatus sinmdm_crowd_new(const struct SinmdmModel *model, struct SinmdmCrowd **out);

/*
 Adds a character whose motion is a stream with `options` (as `sinmdm_stream_new` takes
 them) and writes its number to `id`: numbers count up from 0 and are never given again. At
 most `SINMDM_MAX_CROWD_CHARACTERS` characters at once.

 # Safety
 `crowd` is a live handle; `options` readable (its joint array as it says); `id` writable.
 */
enum SinmdmStatus sinmdm_crowd_join(struct SinmdmCrowd *crowd,
                                    const struct SinmdmStreamOptions *options,
                                    uint64_t *id);

/*
 Takes character `id` out of the crowd (its motion ends); `SINMDM_INVALID_ARGUMENT` if no
 such character is in it.

 # Safety
 `crowd` is a live handle.
 */
enum SinmdmStatus sinmdm_crowd_leave(struct SinmdmCrowd *crowd, uint64_t id);

/*
 Characters in the crowd, written to `count`.

 # Safety
 `crowd` is a live handle; `count` writable.
 */
enum SinmdmStatus sinmdm_crowd_count(const struct SinmdmCrowd *crowd, size_t *count);

/*
 Queues character `id`'s steering commands, as `sinmdm_stream_steer_commands` does for a
 stream.

 # Safety
 `crowd` is a live handle; `commands` readable for `count` values.
 */
enum SinmdmStatus sinmdm_crowd_steer(struct SinmdmCrowd *crowd,
                                     uint64_t id,
                                     const struct SinmdmSteerCommand *commands,
                                     size_t count);

/*
 Supplies character `id`'s poses for the frames after the last supplied ones, as
 `sinmdm_stream_supply` does for a stream made with composed joints.

 # Safety
 `crowd` and `model` are live handles (the crowd's model); `poses` as its documentation says.
 */
enum SinmdmStatus sinmdm_crowd_supply(struct SinmdmCrowd *crowd,
                                      const struct SinmdmModel *model,
                                      uint64_t id,
                                      const struct SinmdmPoses *poses);

/*
 Prepares frames ahead on `model` (the crowd's), spending at most `max_steps` denoising steps
 (one step of one character each): in rounds, each character with fewer than `ahead` frames
 (at most `SINMDM_MAX_SAMPLE_FRAMES`) ready takes one step, those with the fewest ready first,
 all of a round through the network together. A game calls it each frame with the steps it
 can afford, then reads each character with `sinmdm_crowd_next`, which then never waits.
 `steps` (if not NULL) gets the steps taken, `waiting` (if not NULL) the characters still
 short of `ahead` frames.

 # Safety
 `crowd` and `model` are live handles; `steps` and `waiting` NULL or writable.
 */
enum SinmdmStatus sinmdm_crowd_step(struct SinmdmCrowd *crowd,
                                    struct SinmdmModel *model,
                                    size_t max_steps,
                                    size_t ahead,
                                    size_t *steps,
                                    size_t *waiting);

/*
 Character `id`'s next `frames` frames (at most `SINMDM_MAX_SAMPLE_FRAMES`) into `buffers`,
 the same bits as its stream alone; frames not yet prepared by `sinmdm_crowd_step` are made
 for this character alone on `model` (the crowd's). `buffers` is checked as for
 `sinmdm_stream_next`.

 # Safety
 `crowd` and `model` are live handles; `buffers` as its documentation says.
 */
enum SinmdmStatus sinmdm_crowd_next(struct SinmdmCrowd *crowd,
                                    struct SinmdmModel *model,
                                    uint64_t id,
                                    size_t frames,
                                    const struct SinmdmPoseBuffers *buffers);

/*
 Frees a crowd and its characters (NULL is fine).

 # Safety
 `crowd` is NULL or a handle from this library, not used again.
 */
void sinmdm_crowd_free(struct SinmdmCrowd *crowd);

/*
 Writes the beats of the `reference` poses that a dance places (its speed minima on the
 dance's own beat; frames of the reference) to `beats`, which holds `capacity` values;
 `needed` (if not NULL) gets their count, also for a NULL `beats` (a size query).

 # Safety
 `model` is a live handle; `reference` readable; `beats` NULL or writable for `capacity`
 values; `needed` NULL or writable.
 */
enum SinmdmStatus sinmdm_dance_reference_beats(const struct SinmdmModel *model,
                                               const struct SinmdmPoses *reference,
                                               size_t *beats,
                                               size_t capacity,
                                               size_t *needed);

/*
 Begins a dance (see `sinmdm_dance` and `sinmdm_run_step`).

 # Safety
 As `sinmdm_dance`.
 */
enum SinmdmStatus sinmdm_dance_begin(struct SinmdmModel *model,
                                     const struct SinmdmSampling *sampling,
                                     const struct SinmdmPoses *reference,
                                     const struct SinmdmDance *dance,
                                     struct SinmdmRun **out);

/*
 A dance: windows of the `reference` poses around its beats placed on the music's beats,
 the motion between them generated (the same motion as `sinmdm dance` for the same beats,
 seed and settings).

 # Safety
 Pointers as their types' documentation says; the arrays of `dance` readable for their
 counts.
 */
enum SinmdmStatus sinmdm_dance(struct SinmdmModel *model,
                               const struct SinmdmSampling *sampling,
                               const struct SinmdmPoses *reference,
                               const struct SinmdmDance *dance,
                               struct SinmdmResult **out);

/*
 The loaded library's version, `"MAJOR.MINOR.PATCH"`, a static NUL-terminated string. A host
 checks it at load against `SINMDM_VERSION_MAJOR` and `_MINOR` (see the introduction's
 Version), since the header it was built with may not be the library's.
 */
const char *sinmdm_version(void);

/*
 Loads onnxruntime from the shared library at `path` (an engine that ships its own copy), or
 finds it when `path` is NULL, in this order: `ORT_DYLIB_PATH`, next to the executable, next
 to this library, the system loader's search path, a developer checkout's `.venv`. A release
 older than 1.17 is refused and the search goes on. Opening a model does this on its own with
 NULL; call it first to choose the library. Asking for a second, different library once one
 is loaded fails.

 # Safety
 `path` is NULL or a NUL-terminated string.
 */
enum SinmdmStatus sinmdm_load_onnxruntime(const char *path);

/*
 Opens the model file at `path` and writes its handle to `out`. `threads` is how many samples
 of a batch run at once, each on its own thread (0: every core; at most
 `SINMDM_MAX_THREADS`); it changes speed, never values. The file is checked before anything
 runs: a file that is not a model gives `SINMDM_BAD_MODEL` and names the field or problem.

 # Safety
 `path` is a NUL-terminated string; `out` is writable.
 */
enum SinmdmStatus sinmdm_model_open(const char *path, uint32_t threads, struct SinmdmModel **out);

/*
 Opens a model from the `length` bytes at `bytes` (a file the engine read or packed itself).
 The bytes are copied: they may be freed as soon as the call returns.

 # Safety
 `bytes` is readable for `length` bytes; `out` is writable.
 */
enum SinmdmStatus sinmdm_model_open_bytes(const uint8_t *bytes,
                                          size_t length,
                                          uint32_t threads,
                                          struct SinmdmModel **out);

/*
 Sets the progress callback of the blocking tasks run on `model` (`sinmdm_generate` and the
 other tasks), with the host's `userdata` handed back to it; a NULL `callback` removes it.
 Meant for a host that runs tasks on a worker thread and wants to show progress or cancel;
 a game that spreads a run over frames uses `sinmdm_*_begin` and `sinmdm_run_step` instead.

 # Safety
 `model` is a live handle; `callback` NULL or a function as `SinmdmProgressFn` says, which
 with `userdata` stays valid while it is set.
 */
enum SinmdmStatus sinmdm_model_set_progress(struct SinmdmModel *model,
                                            SinmdmProgressFn callback,
                                            void *userdata);

/*
 Frees a model (NULL is fine). Streams made on it must not be advanced afterwards.

 # Safety
 `model` is NULL or a handle from `sinmdm_model_open*`, not used again.
 */
void sinmdm_model_free(struct SinmdmModel *model);

/*
 Writes the model's facts to `info`.

 # Safety
 `model` is a live handle; `info` is writable.
 */
enum SinmdmStatus sinmdm_model_info(const struct SinmdmModel *model, struct SinmdmModelInfo *info);

/*
 Writes to `values` the f32 values one frame of one sample needs while a run is made on
 `model`: `max(F + 8 C, 12 x joints)`, with F `SinmdmModelInfo::features` and C the
 network's channels. A request of `count` samples of `frames` frames is refused with
 `SINMDM_INVALID_ARGUMENT` when `count x frames x values` passes `SINMDM_MAX_RUN_VALUES`; a
 function rather than a field, since the layout of `SinmdmModelInfo` does not change.

 # Safety
 `model` is a live handle; `values` is writable.
 */
enum SinmdmStatus sinmdm_model_values_per_frame(const struct SinmdmModel *model, size_t *values);

/*
 Copies the name of joint `joint` into `buffer` of `capacity` bytes; `needed` (if not NULL)
 gets its size with the NUL, also when the buffer is NULL (a size query) or too small.

 # Safety
 `model` is a live handle; `buffer` NULL or writable for `capacity` bytes; `needed` NULL or
 writable.
 */
enum SinmdmStatus sinmdm_model_joint_name(const struct SinmdmModel *model,
                                          size_t joint,
                                          char *buffer,
                                          size_t capacity,
                                          size_t *needed);

/*
 Writes the index of the joint called `name` to `index`, or fails with
 `SINMDM_UNKNOWN_JOINT` (the message lists the joints).

 # Safety
 `model` is a live handle; `name` a NUL-terminated string; `index` writable.
 */
enum SinmdmStatus sinmdm_model_find_joint(const struct SinmdmModel *model,
                                          const char *name,
                                          size_t *index);

/*
 Writes every joint's parent index (-1 for the root) to `parents`, which holds `capacity`
 values; `needed` (if not NULL) gets the joint count, also for a NULL `parents` (a size query).

 # Safety
 `model` is a live handle; `parents` NULL or writable for `capacity` values; `needed` NULL
 or writable.
 */
enum SinmdmStatus sinmdm_model_parents(const struct SinmdmModel *model,
                                       int32_t *parents,
                                       size_t capacity,
                                       size_t *needed);

/*
 Writes every joint's rest offset from its parent (x, y, z; file units) to `offsets`, which
 holds `capacity` floats; `needed` (if not NULL) gets 3 x the joint count, also for a NULL
 `offsets` (a size query).

 # Safety
 `model` is a live handle; `offsets` NULL or writable for `capacity` floats; `needed` NULL or
 writable.
 */
enum SinmdmStatus sinmdm_model_rest_offsets(const struct SinmdmModel *model,
                                            float *offsets,
                                            size_t capacity,
                                            size_t *needed);

/*
 Writes the contact joints' indices (feet, paws: where planting holds the motion on the
 ground) to `joints`, which holds `capacity` values; `needed` (if not NULL) gets their count
 (`SinmdmModelInfo::contact_joints`), also for a NULL `joints` (a size query).

 # Safety
 `model` is a live handle; `joints` NULL or writable for `capacity` values; `needed` NULL or
 writable.
 */
enum SinmdmStatus sinmdm_model_contact_joints(const struct SinmdmModel *model,
                                              size_t *joints,
                                              size_t capacity,
                                              size_t *needed);

/*
 Writes `poses` of the model's skeleton to the BVH file `path` (at the model's frame rate,
 with the skeleton, channels and up axis of its training clip), atomically: the file
 appears whole or not at all.

 # Safety
 `model` is a live handle; `poses` as its documentation says; `path` NUL-terminated.
 */
enum SinmdmStatus sinmdm_write_bvh(const struct SinmdmModel *model,
                                   const struct SinmdmPoses *poses,
                                   const char *path);

/*
 Writes the number of samples in the batch to `count`.

 # Safety
 `result` is a live handle; `count` writable.
 */
enum SinmdmStatus sinmdm_result_count(const struct SinmdmResult *result, size_t *count);

/*
 Writes the frames per sample to `frames`.

 # Safety
 `result` is a live handle; `frames` writable.
 */
enum SinmdmStatus sinmdm_result_frames(const struct SinmdmResult *result, size_t *frames);

/*
 Writes sample `sample`'s poses (feet as the sampling asked) into `buffers`.

 # Safety
 `result` is a live handle; `buffers` as its documentation says.
 */
enum SinmdmStatus sinmdm_result_poses(const struct SinmdmResult *result,
                                      size_t sample,
                                      const struct SinmdmPoseBuffers *buffers);

/*
 Frees a batch (NULL is fine).

 # Safety
 `result` is NULL or a handle from this library, not used again.
 */
void sinmdm_result_free(struct SinmdmResult *result);

/*
 Takes up to `max_steps` denoising steps of `run` on `model` (the model it was begun on),
 and writes the steps taken so far and in all to `done` and `total` (each may be NULL). One
 step costs about a 50th of the whole run at the default step count; 0 steps only reports.
 `model` is the very handle the run was begun on: another handle, even of the same file,
 gives `SINMDM_INVALID_ARGUMENT` (a handle and its runs are one for the threading rule). The
 progress callback is not called here: a stepped run is never cancelled, only freed.

 # Safety
 `run` and `model` are live handles; `done` and `total` NULL or writable.
 */
enum SinmdmStatus sinmdm_run_step(struct SinmdmRun *run,
                                  struct SinmdmModel *model,
                                  size_t max_steps,
                                  size_t *done,
                                  size_t *total);

/*
 Finishes `run` and writes its batch to `out`: the motion once every step is taken, or,
 before that, the network's latest prediction of the clean motion (a preview; a run that has
 taken no step has none and gives `SINMDM_INVALID_ARGUMENT`). The run is spent afterwards:
 free it with `sinmdm_run_free`. Which failures spend it: the refusals (`SINMDM_NULL_ARGUMENT`
 for a NULL `run` or `out`; `SINMDM_INVALID_ARGUMENT` for a spent run or one with no step
 taken) leave it as it was, to be stepped and finished again; only `SINMDM_INTERNAL` (a
 caught panic while the batch is made) spends it without a result.

 # Safety
 `run` is a live handle; `out` writable.
 */
enum SinmdmStatus sinmdm_run_finish(struct SinmdmRun *run, struct SinmdmResult **out);

/*
 Frees a run (NULL is fine); freeing one before it is finished cancels it.

 # Safety
 `run` is NULL or a handle from this library, not used again.
 */
void sinmdm_run_free(struct SinmdmRun *run);

/*
 The message of the last failed call on this thread ("" after a call that worked). The text
 belongs to the library and stays valid until the next call on the same thread; copy it to
 keep it. Never NULL.
 */
const char *sinmdm_last_error(void);

/*
 Writes the range of commands `model`'s clip supports to `out`; `SINMDM_INVALID_ARGUMENT`
 for a model without a heading-relative root (it cannot be steered).

 # Safety
 `model` is a live handle; `out` writable.
 */
enum SinmdmStatus sinmdm_steer_limits(const struct SinmdmModel *model,
                                      struct SinmdmSteerLimits *out);

/*
 Begins a steered run (see `sinmdm_steer` and `sinmdm_run_step`).

 # Safety
 As `sinmdm_steer`.
 */
enum SinmdmStatus sinmdm_steer_begin(struct SinmdmModel *model,
                                     const struct SinmdmSampling *sampling,
                                     size_t frames,
                                     const struct SinmdmSteerFrame *commands,
                                     size_t command_count,
                                     size_t ramp,
                                     struct SinmdmRun **out);

/*
 New motion of `frames` frames whose root goes where `commands` say (one per frame from
 frame 0; frames past them are free), from the model's start position and facing, soft over
 `ramp` frames where commands start and stop (the same motion as `sinmdm steer` for the same
 commands, seed and settings). Needs a heading-relative model. More commands than `frames`,
 or a `reserved` that is not 0, give `SINMDM_INVALID_ARGUMENT`.

 # Safety
 Pointers as their types' documentation says; `commands` readable for `command_count`
 values.
 */
enum SinmdmStatus sinmdm_steer(struct SinmdmModel *model,
                               const struct SinmdmSampling *sampling,
                               size_t frames,
                               const struct SinmdmSteerFrame *commands,
                               size_t command_count,
                               size_t ramp,
                               struct SinmdmResult **out);

/*
 Steering commands for the frames after the last commanded one (the first call commands
 frame 0 on; command `i` given in all belongs to stream frame `i`). A block uses the
 commands given when it starts, so give them at least `2 x block + 10` frames ahead of what
 has been handed out (`block`: the stream's block frames, the training clip's length by
 default), plus whatever `sinmdm_stream_step` prepared ahead; commands for frames a block
 has already started on are not used. `SINMDM_INVALID_ARGUMENT` for a model without a
 heading-relative root, a value that is not finite or a `reserved` that is not 0. A `count`
 of 0 adds nothing and succeeds (`commands` may then be NULL), as any empty array does.

 # Safety
 `stream` is a live handle; `commands` readable for `count` values.
 */
enum SinmdmStatus sinmdm_stream_steer(struct SinmdmStream *stream,
                                      const struct SinmdmSteerFrame *commands,
                                      size_t count);

/*
 Begins a steered run with commands of every kind, facings included (see
 `sinmdm_steer_commands` and `sinmdm_run_step`).

 # Safety
 As `sinmdm_steer_commands`.
 */
enum SinmdmStatus sinmdm_steer_commands_begin(struct SinmdmModel *model,
                                              const struct SinmdmSampling *sampling,
                                              size_t frames,
                                              const struct SinmdmSteerCommand *commands,
                                              size_t command_count,
                                              size_t ramp,
                                              struct SinmdmRun **out);

/*
 `sinmdm_steer` with commands of every kind: a facing alone (`SINMDM_STEER_FACING`) or with
 a position (`SINMDM_STEER_POSITION_FACING`) as well. `SINMDM_INVALID_ARGUMENT` for a facing
 with no direction on the ground.

 # Safety
 Pointers as their types' documentation says; `commands` readable for `command_count`
 values.
 */
enum SinmdmStatus sinmdm_steer_commands(struct SinmdmModel *model,
                                        const struct SinmdmSampling *sampling,
                                        size_t frames,
                                        const struct SinmdmSteerCommand *commands,
                                        size_t command_count,
                                        size_t ramp,
                                        struct SinmdmResult **out);

/*
 `sinmdm_stream_steer` with commands of every kind, facings included; the two add to the
 same queue of commands.

 # Safety
 `stream` is a live handle; `commands` readable for `count` values.
 */
enum SinmdmStatus sinmdm_stream_steer_commands(struct SinmdmStream *stream,
                                               const struct SinmdmSteerCommand *commands,
                                               size_t count);

/*
 Writes how fast `model`'s clip went sideways to `out` (what a path walked in a facing of
 its own is clamped to); `SINMDM_INVALID_ARGUMENT` for a model without a heading-relative
 root.

 # Safety
 `model` is a live handle; `out` writable.
 */
enum SinmdmStatus sinmdm_steer_sideways_limits(const struct SinmdmModel *model,
                                               struct SinmdmSteerSideways *out);

/*
 Makes a stream of `model`'s motion with `options` and writes its handle to `out`.

 # Safety
 `model` is a live handle; `options` readable (its joint array as it says); `out` writable.
 */
enum SinmdmStatus sinmdm_stream_new(const struct SinmdmModel *model,
                                    const struct SinmdmStreamOptions *options,
                                    struct SinmdmStream **out);

/*
 Supplies poses for the frames after the last supplied ones (the first call supplies frame
 0 on), for a stream made with composed joints (`SINMDM_INVALID_ARGUMENT` for one without).
 Poses supplied at least `2 x block_frames + 10` frames ahead of what has been handed out
 make the stream's motion independent of chunk sizes.

 # Safety
 `stream` and `model` are live handles (the stream's model); `poses` as its documentation says.
 */
enum SinmdmStatus sinmdm_stream_supply(struct SinmdmStream *stream,
                                       const struct SinmdmModel *model,
                                       const struct SinmdmPoses *poses);

/*
 Makes the next `frames` frames (at most `SINMDM_MAX_SAMPLE_FRAMES`) on `model` (the model
 the stream was made with) and writes their poses into `buffers`. The motion is the same
 whatever chunk sizes are asked for. It runs the network only for frames not yet prepared
 by `sinmdm_stream_step`. `buffers` is checked as for any other `frames`, 0 included: NULL
 (or a NULL array but `translations`) gives `SINMDM_NULL_ARGUMENT` and hands out nothing. A
 stream is advanced on the very handle it was made with: another handle, even of the same
 file, gives `SINMDM_INVALID_ARGUMENT`, as in `sinmdm_stream_step` and `sinmdm_stream_supply`.

 # Safety
 `stream` and `model` are live handles; `buffers` as its documentation says.
 */
enum SinmdmStatus sinmdm_stream_next(struct SinmdmStream *stream,
                                     struct SinmdmModel *model,
                                     size_t frames,
                                     const struct SinmdmPoseBuffers *buffers);

/*
 Prepares frames ahead on `model` (the stream's), spending at most `max_steps` denoising
 steps: while fewer than `ahead` frames (at most `SINMDM_MAX_SAMPLE_FRAMES`) are ready, the
 next block is made a step at a time. A game calls it each frame with a small `max_steps`
 and reads with `sinmdm_stream_next`, which then never waits when enough frames are ready;
 the motion is the same bits as without preparing (for a stream with composed joints, when
 poses are supplied at least `ahead + 2 x block_frames + 10` frames past those handed out).
 `ready` (if not NULL) gets the frames
 ready now; `done` and `total` (if not NULL) the steps of the block in the making (0 of 0
 when none is).

 # Safety
 `stream` and `model` are live handles; `ready`, `done` and `total` NULL or writable.
 */
enum SinmdmStatus sinmdm_stream_step(struct SinmdmStream *stream,
                                     struct SinmdmModel *model,
                                     size_t max_steps,
                                     size_t ahead,
                                     size_t *ready,
                                     size_t *done,
                                     size_t *total);

/*
 Frees a stream (NULL is fine).

 # Safety
 `stream` is NULL or a handle from this library, not used again.
 */
void sinmdm_stream_free(struct SinmdmStream *stream);

/*
 Begins new motion of `frames` frames (see `sinmdm_run_step`).

 # Safety
 `model` is a live handle, `sampling` readable, `out` writable.
 */
enum SinmdmStatus sinmdm_generate_begin(struct SinmdmModel *model,
                                        const struct SinmdmSampling *sampling,
                                        size_t frames,
                                        struct SinmdmRun **out);

/*
 New motion of `frames` frames.

 # Safety
 `model` is a live handle, `sampling` readable, `out` writable.
 */
enum SinmdmStatus sinmdm_generate(struct SinmdmModel *model,
                                  const struct SinmdmSampling *sampling,
                                  size_t frames,
                                  struct SinmdmResult **out);

/*
 Begins an in-between (see `sinmdm_inbetween` and `sinmdm_run_step`).

 # Safety
 As `sinmdm_inbetween`.
 */
enum SinmdmStatus sinmdm_inbetween_begin(struct SinmdmModel *model,
                                         const struct SinmdmSampling *sampling,
                                         const struct SinmdmPoses *reference,
                                         const struct SinmdmSpan *keep,
                                         size_t span_count,
                                         size_t ramp,
                                         struct SinmdmRun **out);

/*
 In-betweening: keeps the `span_count` spans `keep` of the `reference` poses (soft borders
 of `ramp` frames) and generates the gaps.

 # Safety
 Pointers as their types' documentation says; `keep` readable for `span_count` spans.
 */
enum SinmdmStatus sinmdm_inbetween(struct SinmdmModel *model,
                                   const struct SinmdmSampling *sampling,
                                   const struct SinmdmPoses *reference,
                                   const struct SinmdmSpan *keep,
                                   size_t span_count,
                                   size_t ramp,
                                   struct SinmdmResult **out);

/*
 Begins an expansion (see `sinmdm_expand` and `sinmdm_run_step`).

 # Safety
 As `sinmdm_expand`.
 */
enum SinmdmStatus sinmdm_expand_begin(struct SinmdmModel *model,
                                      const struct SinmdmSampling *sampling,
                                      const struct SinmdmPoses *reference,
                                      size_t prefix,
                                      size_t suffix,
                                      size_t ramp,
                                      struct SinmdmRun **out);

/*
 Expansion: the `reference` poses in the middle, `prefix` new frames before and `suffix`
 after (all together at most `SINMDM_MAX_SAMPLE_FRAMES`).

 # Safety
 Pointers as their types' documentation says.
 */
enum SinmdmStatus sinmdm_expand(struct SinmdmModel *model,
                                const struct SinmdmSampling *sampling,
                                const struct SinmdmPoses *reference,
                                size_t prefix,
                                size_t suffix,
                                size_t ramp,
                                struct SinmdmResult **out);

/*
 Begins a composition (see `sinmdm_compose` and `sinmdm_run_step`).

 # Safety
 As `sinmdm_compose`.
 */
enum SinmdmStatus sinmdm_compose_begin(struct SinmdmModel *model,
                                       const struct SinmdmSampling *sampling,
                                       const struct SinmdmPoses *reference,
                                       const size_t *joints,
                                       size_t joint_count,
                                       int32_t root,
                                       const struct SinmdmSpan *spans_in,
                                       size_t span_count,
                                       size_t ramp,
                                       struct SinmdmRun **out);

/*
 Composition: the `joint_count` `joints` (and the root's travel when `root` is not 0) taken
 from the `reference` poses on the `span_count` `spans` (every frame when 0), the rest of
 the body generated.

 # Safety
 Pointers as their types' documentation says; `joints` readable for `joint_count` values,
 `spans` for `span_count` spans.
 */
enum SinmdmStatus sinmdm_compose(struct SinmdmModel *model,
                                 const struct SinmdmSampling *sampling,
                                 const struct SinmdmPoses *reference,
                                 const size_t *joints,
                                 size_t joint_count,
                                 int32_t root,
                                 const struct SinmdmSpan *spans_in,
                                 size_t span_count,
                                 size_t ramp,
                                 struct SinmdmResult **out);

/*
 Begins a harmonization (see `sinmdm_harmonize` and `sinmdm_run_step`).

 # Safety
 As `sinmdm_harmonize`.
 */
enum SinmdmStatus sinmdm_harmonize_begin(struct SinmdmModel *model,
                                         const struct SinmdmSampling *sampling,
                                         const struct SinmdmPoses *content,
                                         size_t factor,
                                         double free_share,
                                         struct SinmdmRun **out);

/*
 Harmonization (style transfer): the `content` poses' low frequencies (down-sampled by
 `factor`, 1 to the content's frames) in the model's style, the last `free_share` (0 to 1)
 of steps left free.

 # Safety
 Pointers as their types' documentation says.
 */
enum SinmdmStatus sinmdm_harmonize(struct SinmdmModel *model,
                                   const struct SinmdmSampling *sampling,
                                   const struct SinmdmPoses *content,
                                   size_t factor,
                                   double free_share,
                                   struct SinmdmResult **out);

/*
 How many handles (models, runs, results, streams) are alive: given out and not freed. A
 host can check it for leaks, for example after its last `_free` at shutdown.
 */
size_t sinmdm_live_handles(void);

#ifdef __cplusplus
}  // extern "C"
#endif  // __cplusplus

#endif  /* SINMDM_H */
