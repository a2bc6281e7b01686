/* sinmdm: single-motion diffusion runtime, C ABI. See README.md, section Embedding. */

#ifndef SINMDM_H
#define SINMDM_H

/* Generated from capi/src by cbindgen (capi/tests/header.rs checks it is current). Do not edit. */

#include <stdarg.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>

/*
 Respaced sampling steps of the command line (the library's `DEFAULT_STEPS`); what a `steps`
 of 0 gives in `SinmdmSampling` and `SinmdmStreamOptions`.
 */
#define SINMDM_DEFAULT_STEPS 50

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
 What a call did. Every function returns one; on anything but `SINMDM_OK`,
 `sinmdm_last_error` says why, in words that name the argument, field or file.
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
   An argument out of range or malformed (a count, an index, a string that is not UTF-8,
   poses that do not fit the skeleton).
   */
  SINMDM_INVALID_ARGUMENT = 2,
  /*
   An output buffer too small; the message gives the size needed.
   */
  SINMDM_BUFFER_TOO_SMALL = 3,
  /*
   A joint name the skeleton does not have.
   */
  SINMDM_UNKNOWN_JOINT = 4,
  /*
   onnxruntime could not be loaded.
   */
  SINMDM_RUNTIME_LIBRARY = 5,
  /*
   A model file that could not be opened or is not a valid model.
   */
  SINMDM_BAD_MODEL = 6,
  /*
   A request the model refused (spans, lengths, counts), or a run that failed.
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
} SinmdmStatus;

/*
 An open model (opaque): the network and its metadata.
 */
typedef struct SinmdmModel SinmdmModel;

/*
 A generated batch (opaque).
 */
typedef struct SinmdmResult SinmdmResult;

/*
 A stream (opaque): motion handed out a chunk at a time, forever, in flat memory.
 */
typedef struct SinmdmStream SinmdmStream;

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
 How a stream makes its motion; zeros give the defaults.
 */
typedef struct SinmdmStreamOptions {
  /*
   Seed of the portable noise.
   */
  uint64_t seed;
  /*
   Respaced denoising steps per block; 0 for `SINMDM_DEFAULT_STEPS`, `SINMDM_ALL_STEPS` for
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

#ifdef __cplusplus
extern "C" {
#endif // __cplusplus

/*
 The library's version, a static NUL-terminated string.
 */
const char *sinmdm_version(void);

/*
 Loads onnxruntime from the shared library at `path` (an engine that ships its own copy), or
 finds it when `path` is NULL (`ORT_DYLIB_PATH`, then the project's `.venv`). Opening a model
 does this on its own with NULL; call it first to choose the library. Asking for a second,
 different library once one is loaded fails.

 # Safety
 `path` is NULL or a NUL-terminated string.
 */
enum SinmdmStatus sinmdm_load_onnxruntime(const char *path);

/*
 Opens the model file at `path`, running it on `threads` threads (0: every core), and writes
 its handle to `out`. The file is checked before anything runs: a file that is not a model
 gives `SINMDM_BAD_MODEL` and names the field or problem.

 # Safety
 `path` is a NUL-terminated string; `out` is writable.
 */
enum SinmdmStatus sinmdm_model_open(const char *path, uint32_t threads, struct SinmdmModel **out);

/*
 Opens a model from the `length` bytes at `bytes` (a file the engine read or packed itself).

 # Safety
 `bytes` is readable for `length` bytes; `out` is writable.
 */
enum SinmdmStatus sinmdm_model_open_bytes(const uint8_t *bytes,
                                          size_t length,
                                          uint32_t threads,
                                          struct SinmdmModel **out);

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
 Copies the name of joint `joint` into `buffer` (see the size convention in the header's
 introduction); `needed` gets its size with the NUL.

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
 values (at least the joint count).

 # Safety
 `model` is a live handle; `parents` writable for `capacity` values.
 */
enum SinmdmStatus sinmdm_model_parents(const struct SinmdmModel *model,
                                       int32_t *parents,
                                       size_t capacity);

/*
 Writes every joint's rest offset from its parent (x, y, z; file units) to `offsets`, which
 holds `capacity` floats (at least 3 x the joint count).

 # Safety
 `model` is a live handle; `offsets` writable for `capacity` floats.
 */
enum SinmdmStatus sinmdm_model_rest_offsets(const struct SinmdmModel *model,
                                            float *offsets,
                                            size_t capacity);

/*
 Writes the contact joints' indices (feet, paws: where planting holds the motion on the
 ground) to `joints`, which holds `capacity` values (`SinmdmModelInfo::contact_joints`).

 # Safety
 `model` is a live handle; `joints` writable for `capacity` values.
 */
enum SinmdmStatus sinmdm_model_contact_joints(const struct SinmdmModel *model,
                                              size_t *joints,
                                              size_t capacity);

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
 New motion of `frames` frames.

 # Safety
 `model` is a live handle, `sampling` readable, `out` writable.
 */
enum SinmdmStatus sinmdm_generate(struct SinmdmModel *model,
                                  const struct SinmdmSampling *sampling,
                                  size_t frames,
                                  struct SinmdmResult **out);

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
 Expansion: the `reference` poses in the middle, `prefix` new frames before and `suffix`
 after.

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
 Harmonization (style transfer): the `content` poses' low frequencies (down-sampled by
 `factor`) in the model's style, the last `free_share` of steps left free.

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
 The message of the last failed call on this thread ("" after a call that worked). The text
 belongs to the library and stays valid until the next call on the same thread; copy it to
 keep it. Never NULL.
 */
const char *sinmdm_last_error(void);

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
 0 on), for a stream with composed joints. Poses supplied at least
 `2 x block_frames + 10` frames ahead of what has been handed out make the stream's motion
 independent of chunk sizes.

 # Safety
 `stream` and `model` are live handles (the stream's model); `poses` as its documentation says.
 */
enum SinmdmStatus sinmdm_stream_supply(struct SinmdmStream *stream,
                                       const struct SinmdmModel *model,
                                       const struct SinmdmPoses *poses);

/*
 Makes the next `frames` frames on `model` (the model the stream was made with) and writes
 their poses into `buffers`. The motion is the same whatever chunk sizes are asked for.

 # Safety
 `stream` and `model` are live handles; `buffers` as its documentation says.
 */
enum SinmdmStatus sinmdm_stream_next(struct SinmdmStream *stream,
                                     struct SinmdmModel *model,
                                     size_t frames,
                                     const struct SinmdmPoseBuffers *buffers);

/*
 Frees a stream (NULL is fine).

 # Safety
 `stream` is NULL or a handle from this library, not used again.
 */
void sinmdm_stream_free(struct SinmdmStream *stream);

#ifdef __cplusplus
}  // extern "C"
#endif  // __cplusplus

#endif  /* SINMDM_H */
