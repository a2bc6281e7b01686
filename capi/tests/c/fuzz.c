/* A fuzz of the C ABI: random argument values over every entry point (sizes near their bounds
 * and past them, NaN and infinities, NULLs, handles of the other model, spent runs), CASES
 * cases from a fixed seed. Every call must return a known status with a message when it
 * fails, never SINMDM_INTERNAL, and the program must not crash. Memory the library is told
 * about is always really there: a fuzz cannot lie about a buffer's size without being the bug.
 *
 * Usage: fuzz MODEL_A.onnx MODEL_B.onnx WORK_DIR CASES (model B a heading-relative one, which
 * steering takes)
 * Prints "fuzz: N cases" and a count per status on success. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sinmdm.h"

static uint64_t rng_state = 0x9e3779b97f4a7c15ull;
static uint64_t next_random(void) {
  rng_state ^= rng_state << 13;
  rng_state ^= rng_state >> 7;
  rng_state ^= rng_state << 17;
  return rng_state;
}
static size_t pick(size_t n) { return (size_t)(next_random() % n); }
static int coin(void) { return (int)(next_random() & 1); }

static long counts[16];
static long cases = 0;
static const char *current = "";

/* Every status must be known, never INTERNAL, and a failure must say why. */
static void seen(SinmdmStatus status) {
  int s = (int)status;
  if (s < 0 || s > 10 || status == SINMDM_INTERNAL ||
      (status != SINMDM_OK && strlen(sinmdm_last_error()) == 0)) {
    fprintf(stderr, "case %ld (%s): status %d, message '%s'\n", cases, current, s,
            sinmdm_last_error());
    exit(1);
  }
  counts[s]++;
}

#define CALL(name, call) \
  do {                   \
    current = name;      \
    seen(call);          \
  } while (0)

/* Sizes: small, around each bound, and at the edge of size_t. A size just inside a bound is
 * valid and may be slow to run (a sample of 100 000 frames), so it comes one time in 20. */
static size_t any_size(size_t bound) {
  switch (pick(40)) {
    case 0: return 0;
    case 1: return 1;
    case 2: return 2 + pick(40);
    case 3: return bound > 0 ? bound - 1 : 0;
    case 4: return bound;
    case 5: return bound + 1;
    case 6: return SIZE_MAX;
    case 7: return SIZE_MAX - 29;
    case 8: return SIZE_MAX / 2;
    case 9: return (size_t)UINT32_MAX + 1;
    default: return pick(64);
  }
}

static double any_double(void) {
  double pool[] = {0.0, 0.5, 1.0, -1.0, 2.0, 1e-9, 1e30, -1e30, NAN, INFINITY, -INFINITY};
  return pool[pick(sizeof pool / sizeof pool[0])];
}

static uint32_t any_u32(void) {
  uint32_t pool[] = {0, 1, 2, 3, 7, 1000, 1001, 5000, UINT32_MAX, UINT32_MAX - 1, 1u << 31};
  return pool[pick(sizeof pool / sizeof pool[0])];
}

/* Step counts a valid run may take in the fuzz: few, so the fuzz stays quick. */
static uint32_t few_steps(void) { return coin() ? 1 + (uint32_t)pick(3) : any_u32(); }

#define POOL 8
typedef struct Model {
  SinmdmModel *handle;
  size_t joints;
} Model;
static Model models[2];
static SinmdmRun *runs[POOL];
static SinmdmResult *results[POOL];
static SinmdmStream *streams[POOL];
static SinmdmCrowd *crowds[POOL];

/* A live handle of a pool, NULL now and then. */
#define ANY_OF(pool) (coin() && pool[pick(POOL)] ? pool[pick(POOL)] : pool[pick(POOL)])

static void keep(void **pool, void *handle, void (*free_fn)(void *)) {
  if (handle == NULL) return;
  size_t slot = pick(POOL);
  if (pool[slot] != NULL) free_fn(pool[slot]);
  pool[slot] = handle;
}
static void free_run(void *p) { sinmdm_run_free(p); }
static void free_result(void *p) { sinmdm_result_free(p); }
static void free_stream(void *p) { sinmdm_stream_free(p); }
static void free_crowd(void *p) { sinmdm_crowd_free(p); }

/* Poses input: real sizes for up to FRAMES frames of the larger skeleton. */
#define FRAMES 64
#define MAX_JOINTS_HERE 64
static float roots[3 * FRAMES], rotations[4 * MAX_JOINTS_HERE * FRAMES],
    translations[3 * MAX_JOINTS_HERE * FRAMES];

static SinmdmPoses any_poses(void) {
  /* Frames the arrays really hold, or counts past the bound (refused before any read). */
  size_t frames_pool[] = {0, 1, 10, 40, FRAMES, SINMDM_MAX_SAMPLE_FRAMES + 1, SIZE_MAX};
  size_t frames = frames_pool[pick(sizeof frames_pool / sizeof frames_pool[0])];
  SinmdmPoses poses = {frames, coin() || coin() ? roots : NULL, pick(6) ? rotations : NULL,
                       coin() ? translations : NULL};
  return poses;
}

static void fill_poses(void) {
  for (size_t i = 0; i < sizeof roots / sizeof roots[0]; i++) roots[i] = (float)(i % 7) * 0.1f;
  for (size_t i = 0; i < sizeof rotations / sizeof rotations[0]; i++) {
    switch (pick(40)) {
      case 0: rotations[i] = NAN; break;
      case 1: rotations[i] = INFINITY; break;
      case 2: rotations[i] = 0.0f; break;
      default: rotations[i] = (i % 4 == 3) ? 1.0f : 0.0f;
    }
  }
  for (size_t i = 0; i < sizeof translations / sizeof translations[0]; i++)
    translations[i] = (float)(i % 5);
}

static SinmdmSampling any_sampling(void) {
  SinmdmSampling s = {next_random(), pick(3) ? 1 + (uint32_t)pick(3) : any_u32(), few_steps(),
                      pick(4) ? (uint32_t)pick(2) : any_u32(),
                      pick(4) ? (uint32_t)pick(3) : any_u32(), coin() ? 0.5 : any_double()};
  return s;
}

static SinmdmSpan spans[8];
static size_t any_span_count(void) {
  for (size_t i = 0; i < 8; i++) {
    spans[i].start = coin() ? pick(50) : any_size(SINMDM_MAX_SAMPLE_FRAMES);
    spans[i].end = coin() ? spans[i].start + pick(30) : any_size(SINMDM_MAX_SAMPLE_FRAMES);
  }
  size_t count_pool[] = {0, 1, 2, 8, SINMDM_MAX_SPANS + 1, SIZE_MAX};
  return count_pool[pick(sizeof count_pool / sizeof count_pool[0])];
}
/* A span array the count says, or NULL (only counts up to 8 point at real memory). */
static const SinmdmSpan *span_array(size_t count) {
  if (count <= 8) return pick(5) ? spans : NULL;
  return pick(2) ? NULL : spans;
}

static size_t joint_indices[8];
static size_t any_joint_count(void) {
  for (size_t i = 0; i < 8; i++) joint_indices[i] = coin() ? pick(40) : any_size(4096);
  size_t pool[] = {0, 1, 3, 8, SINMDM_MAX_JOINT_INDICES + 1, SIZE_MAX};
  return pool[pick(sizeof pool / sizeof pool[0])];
}
static const size_t *joint_array(size_t count) {
  if (count <= 8) return pick(5) ? joint_indices : NULL;
  return pick(2) ? NULL : joint_indices;
}

/* Output buffers: capacities never above what is really allocated. */
#define OUT_FRAMES 128
static float out_roots[3 * OUT_FRAMES], out_rot[4 * MAX_JOINTS_HERE * OUT_FRAMES],
    out_trans[3 * MAX_JOINTS_HERE * OUT_FRAMES];
static SinmdmPoseBuffers any_buffers(void) {
  SinmdmPoseBuffers b = {coin() || coin() ? out_roots : NULL, pick(3 * OUT_FRAMES + 1),
                         pick(5) ? out_rot : NULL, pick(4 * MAX_JOINTS_HERE * OUT_FRAMES + 1),
                         coin() ? out_trans : NULL, pick(3 * MAX_JOINTS_HERE * OUT_FRAMES + 1)};
  if (coin()) { /* full buffers, so some calls succeed */
    b.root_positions_capacity = 3 * OUT_FRAMES;
    b.rotations_capacity = 4 * MAX_JOINTS_HERE * OUT_FRAMES;
    b.translations_capacity = 3 * MAX_JOINTS_HERE * OUT_FRAMES;
  }
  return b;
}

/* The fuzz's progress callback: cancel after one step, so no blocking task runs long. */
static int32_t one_step(void *userdata, size_t done, size_t total) {
  (void)userdata;
  (void)total;
  return done >= 1 ? SINMDM_PROGRESS_CANCEL : SINMDM_PROGRESS_CONTINUE;
}

static Model *any_model(void) { return &models[pick(2)]; }
static SinmdmModel *any_model_handle(void) { return pick(8) ? any_model()->handle : NULL; }

static void one_case(const char *model_a, const char *work) {
  Model *m = any_model();
  SinmdmModel *model = pick(10) ? m->handle : NULL;
  SinmdmSampling sampling = any_sampling();
  const SinmdmSampling *sampling_ptr = pick(10) ? &sampling : NULL;
  SinmdmPoses poses = any_poses();
  const SinmdmPoses *poses_ptr = pick(10) ? &poses : NULL;
  SinmdmRun *run = NULL;
  SinmdmResult *result = NULL;
  SinmdmStream *stream = NULL;
  SinmdmCrowd *crowd = NULL;
  SinmdmRun **run_out = pick(10) ? &run : NULL;
  SinmdmResult **result_out = pick(10) ? &result : NULL;
  size_t needed = 0;
  switch (pick(33)) {
    case 0: {
      SinmdmModel *opened = NULL;
      const char *paths[] = {NULL, "", "/no/such/model.onnx", model_a, work};
      CALL("model_open", sinmdm_model_open(paths[pick(5)], any_u32(), pick(8) ? &opened : NULL));
      sinmdm_model_free(opened);
      break;
    }
    case 1: {
      SinmdmModel *opened = NULL;
      static const uint8_t junk[32] = {0x08, 0x07, 0x12, 0x00, 0xff};
      size_t length = coin() ? pick(sizeof junk + 1) : any_size(SINMDM_MAX_MODEL_BYTES);
      if (length > sizeof junk && length <= SINMDM_MAX_MODEL_BYTES) length = sizeof junk;
      CALL("model_open_bytes",
           sinmdm_model_open_bytes(coin() ? junk : NULL, length, any_u32(), &opened));
      sinmdm_model_free(opened);
      break;
    }
    case 2: {
      SinmdmModelInfo info;
      CALL("model_info", sinmdm_model_info(model, pick(8) ? &info : NULL));
      break;
    }
    case 3: {
      char name[16];
      CALL("model_joint_name", sinmdm_model_joint_name(model, any_size(m->joints), coin() ? name : NULL,
                                                        pick(sizeof name + 1), coin() ? &needed : NULL));
      break;
    }
    case 4: {
      const char *names[] = {NULL, "", "Hips", "\xff\xfe", "Spine1", "a very long name that is in no skeleton"};
      size_t index;
      CALL("model_find_joint", sinmdm_model_find_joint(model, names[pick(6)], pick(8) ? &index : NULL));
      break;
    }
    case 5: {
      int32_t parents[MAX_JOINTS_HERE];
      CALL("model_parents", sinmdm_model_parents(model, coin() ? parents : NULL,
                                                 pick(MAX_JOINTS_HERE + 1), coin() ? &needed : NULL));
      break;
    }
    case 6: {
      float offsets[3 * MAX_JOINTS_HERE];
      CALL("model_rest_offsets", sinmdm_model_rest_offsets(model, coin() ? offsets : NULL,
                                                           pick(3 * MAX_JOINTS_HERE + 1),
                                                           coin() ? &needed : NULL));
      break;
    }
    case 7: {
      size_t contacts[16];
      CALL("model_contact_joints", sinmdm_model_contact_joints(model, coin() ? contacts : NULL,
                                                               pick(17), coin() ? &needed : NULL));
      break;
    }
    case 8:
      CALL("generate", sinmdm_generate(model, sampling_ptr, any_size(SINMDM_MAX_SAMPLE_FRAMES), result_out));
      break;
    case 9:
      CALL("generate_begin",
           sinmdm_generate_begin(model, sampling_ptr, pick(4) ? 40 : any_size(SINMDM_MAX_SAMPLE_FRAMES), run_out));
      break;
    case 10:
    case 11: {
      size_t count = any_span_count();
      if (coin())
        CALL("inbetween", sinmdm_inbetween(model, sampling_ptr, poses_ptr, span_array(count), count,
                                           any_size(SINMDM_MAX_RAMP_FRAMES), result_out));
      else
        CALL("inbetween_begin", sinmdm_inbetween_begin(model, sampling_ptr, poses_ptr, span_array(count),
                                                       count, any_size(SINMDM_MAX_RAMP_FRAMES), run_out));
      break;
    }
    case 12: {
      size_t prefix = coin() ? pick(20) : any_size(SINMDM_MAX_SAMPLE_FRAMES);
      size_t suffix = coin() ? pick(20) : any_size(SINMDM_MAX_SAMPLE_FRAMES);
      if (coin())
        CALL("expand", sinmdm_expand(model, sampling_ptr, poses_ptr, prefix, suffix,
                                     any_size(SINMDM_MAX_RAMP_FRAMES), result_out));
      else
        CALL("expand_begin", sinmdm_expand_begin(model, sampling_ptr, poses_ptr, prefix, suffix,
                                                 any_size(SINMDM_MAX_RAMP_FRAMES), run_out));
      break;
    }
    case 13: {
      size_t joints = any_joint_count(), count = any_span_count();
      if (coin())
        CALL("compose", sinmdm_compose(model, sampling_ptr, poses_ptr, joint_array(joints), joints,
                                       (int32_t)pick(3) - 1, span_array(count), count,
                                       any_size(SINMDM_MAX_RAMP_FRAMES), result_out));
      else
        CALL("compose_begin",
             sinmdm_compose_begin(model, sampling_ptr, poses_ptr, joint_array(joints), joints,
                                  (int32_t)pick(3) - 1, span_array(count), count,
                                  any_size(SINMDM_MAX_RAMP_FRAMES), run_out));
      break;
    }
    case 14: {
      size_t factor = coin() ? 1 + pick(8) : any_size(SINMDM_MAX_SAMPLE_FRAMES);
      double share = coin() ? 0.1 : any_double();
      if (coin())
        CALL("harmonize", sinmdm_harmonize(model, sampling_ptr, poses_ptr, factor, share, result_out));
      else
        CALL("harmonize_begin",
             sinmdm_harmonize_begin(model, sampling_ptr, poses_ptr, factor, share, run_out));
      break;
    }
    case 15:
    case 16: {
      size_t done = 0, total = 0;
      size_t steps[] = {0, 1, 2, 3};
      CALL("run_step", sinmdm_run_step(ANY_OF(runs), any_model_handle(), steps[pick(4)],
                                       coin() ? &done : NULL, coin() ? &total : NULL));
      break;
    }
    case 17:
      CALL("run_finish", sinmdm_run_finish(ANY_OF(runs), result_out));
      break;
    case 18: {
      size_t slot = pick(POOL);
      sinmdm_run_free(runs[slot]);
      runs[slot] = NULL;
      break;
    }
    case 19: {
      size_t value;
      if (coin())
        CALL("result_count", sinmdm_result_count(ANY_OF(results), coin() ? &value : NULL));
      else
        CALL("result_frames", sinmdm_result_frames(ANY_OF(results), coin() ? &value : NULL));
      break;
    }
    case 20: {
      SinmdmPoseBuffers b = any_buffers();
      CALL("result_poses", sinmdm_result_poses(ANY_OF(results), any_size(4), pick(10) ? &b : NULL));
      break;
    }
    case 21: {
      size_t slot = pick(POOL);
      sinmdm_result_free(results[slot]);
      results[slot] = NULL;
      break;
    }
    case 22: {
      size_t joints = any_joint_count();
      uint32_t steps_pool[] = {1, 2, 3, 5000, UINT32_MAX - 1};
      uint32_t blocks_pool[] = {5, 30, 45, 60, UINT32_MAX, 200000};
      SinmdmStreamOptions options = {next_random(), steps_pool[pick(5)], blocks_pool[pick(6)],
                                     pick(4) ? (uint32_t)pick(2) : any_u32(), joint_array(joints), joints,
                                     (int32_t)pick(3) - 1, pick(4) ? (uint32_t)pick(3) : any_u32(),
                                     coin() ? 0.0 : any_double()};
      CALL("stream_new", sinmdm_stream_new(model, pick(10) ? &options : NULL, pick(10) ? &stream : NULL));
      break;
    }
    case 23: {
      SinmdmPoseBuffers b = any_buffers();
      size_t frames_pool[] = {0, 1, 20, 45, SINMDM_MAX_SAMPLE_FRAMES + 1, SIZE_MAX};
      CALL("stream_next", sinmdm_stream_next(ANY_OF(streams), any_model_handle(),
                                             frames_pool[pick(6)], pick(10) ? &b : NULL));
      break;
    }
    case 24: {
      size_t ready, done, total;
      CALL("stream_step", sinmdm_stream_step(ANY_OF(streams), any_model_handle(), pick(3),
                                             coin() ? 1 + pick(60) : any_size(SINMDM_MAX_SAMPLE_FRAMES),
                                             coin() ? &ready : NULL, coin() ? &done : NULL,
                                             coin() ? &total : NULL));
      break;
    }
    case 25:
      CALL("stream_supply", sinmdm_stream_supply(ANY_OF(streams), any_model_handle(), poses_ptr));
      break;
    case 26: {
      size_t slot = pick(POOL);
      sinmdm_stream_free(streams[slot]);
      streams[slot] = NULL;
      break;
    }
    case 27: {
      char path[512];
      snprintf(path, sizeof path, "%s/fuzz.bvh", work);
      const char *paths[] = {NULL, "", "/no/such/folder/x.bvh", path};
      CALL("write_bvh", sinmdm_write_bvh(model, poses_ptr, paths[pick(4)]));
      break;
    }
    case 28: {
      const char *paths[] = {NULL, "", "/no/such/libonnxruntime.so", model_a};
      CALL("load_onnxruntime", sinmdm_load_onnxruntime(paths[pick(4)]));
      break;
    }
    case 29: {
      /* Dance: beat arrays of any values and counts, any constants. */
      static size_t reference_beats[8], music_beats[8];
      for (size_t i = 0; i < 8; i++) {
        reference_beats[i] = coin() ? 5 + 6 * i + pick(3) : any_size(SINMDM_MAX_SAMPLE_FRAMES);
        music_beats[i] = coin() ? 4 + 7 * i : any_size(SINMDM_MAX_SAMPLE_FRAMES);
      }
      size_t counts[] = {0, 1, 2, 5, 8, SINMDM_MAX_SAMPLE_FRAMES + 1, SIZE_MAX};
      size_t reference_count = counts[pick(7)], music_count = counts[pick(7)];
      if (coin()) {
        reference_count = reference_count > 8 ? 8 : reference_count;
        music_count = music_count > 8 ? 8 : music_count;
      }
      SinmdmDance dance = {(reference_count <= 8 || coin()) && pick(5) ? reference_beats : NULL, reference_count,
                           (music_count <= 8 || coin()) && pick(5) ? music_beats : NULL, music_count,
                           coin() ? 60 : any_size(SINMDM_MAX_SAMPLE_FRAMES), any_size(8),
                           any_size(SINMDM_MAX_RAMP_FRAMES), pick(4) ? (uint32_t)pick(2) : any_u32(),
                           pick(4) ? (uint32_t)pick(4) : any_u32(), pick(4) ? (uint32_t)pick(2) : any_u32()};
      if (reference_count > 8 && dance.reference_beats != NULL) dance.reference_beats = NULL;
      if (music_count > 8 && dance.music_beats != NULL) dance.music_beats = NULL;
      const SinmdmDance *dance_ptr = pick(10) ? &dance : NULL;
      size_t beats[16];
      switch (pick(3)) {
        case 0:
          CALL("dance", sinmdm_dance(model, sampling_ptr, poses_ptr, dance_ptr, result_out));
          break;
        case 1:
          CALL("dance_begin", sinmdm_dance_begin(model, sampling_ptr, poses_ptr, dance_ptr, run_out));
          break;
        default:
          CALL("dance_reference_beats",
               sinmdm_dance_reference_beats(model, poses_ptr, coin() ? beats : NULL, pick(17),
                                            coin() ? &needed : NULL));
          break;
      }
      break;
    }
    case 30: {
      /* Steering: commands of any kind and value (NaN, infinities, unknown kinds), counts past
         the bound, NULL arrays, either model (only model B can be steered). */
      static SinmdmSteerFrame commands[16];
      static SinmdmSteerCommand full[16];
      /* One command in four calls has a reserved field that is not 0 (refused), so the rest
         reach the steering itself. */
      size_t odd_reserved = pick(4) ? 16 : pick(16);
      for (size_t i = 0; i < 16; i++) {
        SinmdmSteerFrame f = {pick(4) ? (uint32_t)pick(5) : any_u32(), i == odd_reserved ? any_u32() : 0,
                              coin() ? 12.0 : any_double(),
                              coin() ? 0.2 : any_double(),
                              {coin() ? 1.0 * i : any_double(), any_double(), coin() ? -2.0 * i : any_double()}};
        commands[i] = f;
        SinmdmSteerCommand c = {f.kind, f.reserved, f.forward, f.turn,
                                {f.position[0], f.position[1], f.position[2]},
                                {coin() ? 1.0 : any_double(), pick(3) ? 0.0 : any_double(), coin() ? 0.5 : any_double()}};
        full[i] = c;
      }
      size_t counts[] = {0, 1, 7, 16, SINMDM_MAX_SAMPLE_FRAMES + 1, SIZE_MAX};
      size_t count = counts[pick(6)];
      const SinmdmSteerFrame *commands_ptr = (count <= 16 || coin()) && pick(6) ? commands : NULL;
      if (count > 16 && commands_ptr != NULL) commands_ptr = NULL;
      const SinmdmSteerCommand *full_ptr = commands_ptr != NULL ? full : NULL;
      SinmdmSteerSideways sideways;
      size_t frames = coin() ? 30 + pick(20) : any_size(SINMDM_MAX_SAMPLE_FRAMES);
      size_t ramp = coin() ? pick(12) : any_size(SINMDM_MAX_RAMP_FRAMES);
      SinmdmSteerLimits limits;
      switch (pick(8)) {
        case 0:
          CALL("steer", sinmdm_steer(model, sampling_ptr, frames, commands_ptr, count, ramp, result_out));
          break;
        case 4:
          CALL("steer_commands", sinmdm_steer_commands(model, sampling_ptr, frames, full_ptr, count, ramp, result_out));
          break;
        case 5:
          CALL("steer_commands_begin",
               sinmdm_steer_commands_begin(model, sampling_ptr, frames, full_ptr, count, ramp, run_out));
          break;
        case 6:
          CALL("steer_sideways_limits", sinmdm_steer_sideways_limits(model, coin() ? &sideways : NULL));
          break;
        case 7:
          CALL("stream_steer_commands", sinmdm_stream_steer_commands(ANY_OF(streams), full_ptr, count));
          break;
        case 1:
          CALL("steer_begin", sinmdm_steer_begin(model, sampling_ptr, frames, commands_ptr, count, ramp, run_out));
          break;
        case 2:
          CALL("steer_limits", sinmdm_steer_limits(model, coin() ? &limits : NULL));
          break;
        default:
          CALL("stream_steer", sinmdm_stream_steer(ANY_OF(streams), commands_ptr, count));
          break;
      }
      break;
    }
    case 31: {
      /* Crowds: characters of any options, numbers that are and are not in the crowd, either
         model, bounds and NULLs. */
      uint32_t steps_pool[] = {1, 2, 3, UINT32_MAX - 1};
      uint32_t blocks_pool[] = {5, 30, 45, UINT32_MAX, 200000};
      SinmdmStreamOptions options = {next_random(), steps_pool[pick(4)], blocks_pool[pick(5)],
                                     pick(4) ? (uint32_t)pick(2) : any_u32(), NULL, 0, 0,
                                     pick(4) ? (uint32_t)pick(3) : any_u32(), coin() ? 0.0 : any_double()};
      uint64_t id = coin() ? pick(4) : next_random();
      size_t steps, waiting, count;
      SinmdmPoseBuffers b = any_buffers();
      size_t frames_pool[] = {0, 1, 20, 45, SINMDM_MAX_SAMPLE_FRAMES + 1, SIZE_MAX};
      static SinmdmSteerCommand told[4];
      for (size_t i = 0; i < 4; i++) {
        SinmdmSteerCommand c = {pick(4) ? SINMDM_STEER_VELOCITY : any_u32(), 0, coin() ? 12.0 : any_double(),
                                coin() ? 0.2 : any_double(), {0.0, 0.0, 0.0}, {1.0, 0.0, 0.0}};
        told[i] = c;
      }
      switch (pick(9)) {
        case 0:
          CALL("crowd_new", sinmdm_crowd_new(model, pick(10) ? &crowd : NULL));
          break;
        case 1:
        case 2:
          CALL("crowd_join", sinmdm_crowd_join(ANY_OF(crowds), pick(10) ? &options : NULL, pick(10) ? &id : NULL));
          break;
        case 3:
          CALL("crowd_leave", sinmdm_crowd_leave(ANY_OF(crowds), id));
          break;
        case 4:
          CALL("crowd_count", sinmdm_crowd_count(ANY_OF(crowds), coin() ? &count : NULL));
          break;
        case 5:
          CALL("crowd_steer", sinmdm_crowd_steer(ANY_OF(crowds), id, pick(6) ? told : NULL, pick(5)));
          break;
        case 6:
          CALL("crowd_supply", sinmdm_crowd_supply(ANY_OF(crowds), any_model_handle(), id, poses_ptr));
          break;
        case 7:
          CALL("crowd_step", sinmdm_crowd_step(ANY_OF(crowds), any_model_handle(), pick(3),
                                               coin() ? 1 + pick(60) : any_size(SINMDM_MAX_SAMPLE_FRAMES),
                                               coin() ? &steps : NULL, coin() ? &waiting : NULL));
          break;
        default:
          CALL("crowd_next", sinmdm_crowd_next(ANY_OF(crowds), any_model_handle(), id,
                                               frames_pool[pick(6)], pick(10) ? &b : NULL));
          break;
      }
      if (pick(20) == 0) {
        size_t slot = pick(POOL);
        sinmdm_crowd_free(crowds[slot]);
        crowds[slot] = NULL;
      }
      break;
    }
    default:
      CALL("model_set_progress", sinmdm_model_set_progress(model, coin() ? one_step : NULL, NULL));
      if (model == NULL) break;
      CALL("model_set_progress", sinmdm_model_set_progress(model, one_step, NULL));
      break;
  }
  if (run != NULL) keep((void **)runs, run, free_run);
  if (result != NULL) keep((void **)results, result, free_result);
  if (stream != NULL) keep((void **)streams, stream, free_stream);
  if (crowd != NULL) keep((void **)crowds, crowd, free_crowd);
  if (strlen(sinmdm_version()) == 0) exit(1);
}

int main(int argc, char **argv) {
  if (argc != 5) {
    fprintf(stderr, "usage: fuzz MODEL_A.onnx MODEL_B.onnx WORK_DIR CASES\n");
    return 2;
  }
  long total = atol(argv[4]);
  for (int i = 0; i < 2; i++) {
    if (sinmdm_model_open(argv[1 + i], 1, &models[i].handle) != SINMDM_OK) {
      fprintf(stderr, "open %s: %s\n", argv[1 + i], sinmdm_last_error());
      return 1;
    }
    SinmdmModelInfo info;
    sinmdm_model_info(models[i].handle, &info);
    models[i].joints = info.joints;
    if (info.joints > MAX_JOINTS_HERE) {
      fprintf(stderr, "a model of %zu joints is larger than the fuzz's buffers\n", info.joints);
      return 1;
    }
    /* Blocking tasks stop after one step: the fuzz is about arguments, not long runs. */
    sinmdm_model_set_progress(models[i].handle, one_step, NULL);
  }
  fill_poses();
  for (cases = 0; cases < total; cases++) {
    if (cases % 500 == 0) fill_poses();
    one_case(argv[1], argv[3]);
  }
  for (int i = 0; i < POOL; i++) {
    sinmdm_run_free(runs[i]);
    sinmdm_result_free(results[i]);
    sinmdm_stream_free(streams[i]);
    sinmdm_crowd_free(crowds[i]);
  }
  sinmdm_model_free(models[0].handle);
  sinmdm_model_free(models[1].handle);
  if (sinmdm_live_handles() != 0) {
    fprintf(stderr, "%zu handles still alive after freeing every one\n", sinmdm_live_handles());
    return 1;
  }
  printf("fuzz: %ld cases\n", cases);
  for (int s = 0; s <= 10; s++) printf("status %d: %ld\n", s, counts[s]);
  return 0;
}
