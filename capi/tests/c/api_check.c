/* The C ABI from C: a shipped model opened, a crowd generated, an in-between of it, a stream in
 * two uneven chunks and a BVH written, every value printed as the bits of its float so the
 * Rust test can compare them with the Rust API's exactly; then every entry point fed bad
 * arguments, each of which must give its status code and a message, never a crash.
 *
 * Usage: api_check MODEL.onnx NOT_A_MODEL_FILE OUT.bvh
 * Prints "<label> <hex> <hex> ..." lines, then "bad arguments: N checks" on success. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sinmdm.h"

static int failures = 0;
static int checks = 0;

#define CHECK_OK(call)                                                              \
  do {                                                                              \
    SinmdmStatus s_ = (call);                                                       \
    if (s_ != SINMDM_OK) {                                                          \
      fprintf(stderr, "%s:%d: %s gave %d: %s\n", __FILE__, __LINE__, #call, (int)s_, \
              sinmdm_last_error());                                                 \
      exit(1);                                                                      \
    }                                                                               \
  } while (0)

/* A call that must fail with `expected` and say why. */
#define EXPECT(expected, call)                                                          \
  do {                                                                                  \
    SinmdmStatus s_ = (call);                                                           \
    checks++;                                                                           \
    if (s_ != (expected) || strlen(sinmdm_last_error()) == 0) {                         \
      fprintf(stderr, "%s:%d: %s gave %d (wanted %d): '%s'\n", __FILE__, __LINE__, #call, \
              (int)s_, (int)(expected), sinmdm_last_error());                           \
      failures++;                                                                       \
    }                                                                                   \
  } while (0)

static void print_floats(const char *label, const float *values, size_t count) {
  printf("%s", label);
  for (size_t i = 0; i < count; i++) {
    uint32_t bits;
    memcpy(&bits, &values[i], sizeof bits);
    printf(" %08x", bits);
  }
  printf("\n");
}

typedef struct Poses {
  size_t frames, joints;
  float *root, *rot, *trans;
} Poses;

static Poses poses_alloc(size_t frames, size_t joints) {
  Poses p = {frames, joints, calloc(3 * frames, sizeof(float)),
             calloc(4 * joints * frames, sizeof(float)),
             calloc(3 * joints * frames, sizeof(float))};
  return p;
}

static SinmdmPoseBuffers buffers_of(Poses *p) {
  SinmdmPoseBuffers b = {p->root, 3 * p->frames, p->rot, 4 * p->joints * p->frames,
                         p->trans, 3 * p->joints * p->frames};
  return b;
}

static SinmdmPoses input_of(const Poses *p) {
  SinmdmPoses in = {p->frames, p->root, p->rot, p->trans};
  return in;
}

static void print_poses(const char *label, const Poses *p) {
  char name[64];
  snprintf(name, sizeof name, "%s.root", label);
  print_floats(name, p->root, 3 * p->frames);
  snprintf(name, sizeof name, "%s.rotations", label);
  print_floats(name, p->rot, 4 * p->joints * p->frames);
  snprintf(name, sizeof name, "%s.translations", label);
  print_floats(name, p->trans, 3 * p->joints * p->frames);
}

static void poses_free(Poses *p) {
  free(p->root);
  free(p->rot);
  free(p->trans);
}

/* Generates `frames` frames with `sampling` and prints the first sample under `label`. */
static void print_generated(SinmdmModel *model, const SinmdmSampling *sampling, size_t frames,
                            size_t joints, const char *label) {
  SinmdmResult *result = NULL;
  CHECK_OK(sinmdm_generate(model, sampling, frames, &result));
  Poses poses = poses_alloc(frames, joints);
  SinmdmPoseBuffers buffers = buffers_of(&poses);
  CHECK_OK(sinmdm_result_poses(result, 0, &buffers));
  print_poses(label, &poses);
  poses_free(&poses);
  sinmdm_result_free(result);
}

int main(int argc, char **argv) {
  if (argc != 4) {
    fprintf(stderr, "usage: api_check MODEL.onnx NOT_A_MODEL OUT.bvh\n");
    return 2;
  }
  CHECK_OK(sinmdm_load_onnxruntime(NULL));
  SinmdmModel *model = NULL;
  CHECK_OK(sinmdm_model_open(argv[1], 1, &model));
  SinmdmModelInfo info;
  CHECK_OK(sinmdm_model_info(model, &info));
  printf("info joints=%zu features=%zu fps=%g up=%g,%g,%g\n", info.joints, info.features,
         info.fps, info.up[0], info.up[1], info.up[2]);
  size_t joints = info.joints;

  size_t needed = 0;
  CHECK_OK(sinmdm_model_joint_name(model, 0, NULL, 0, &needed));
  char *name = malloc(needed);
  CHECK_OK(sinmdm_model_joint_name(model, 0, name, needed, NULL));
  size_t found = 99;
  CHECK_OK(sinmdm_model_find_joint(model, name, &found));
  printf("joint0 %s %zu\n", name, found);
  free(name);
  int32_t *parents = malloc(joints * sizeof(int32_t));
  CHECK_OK(sinmdm_model_parents(model, parents, joints));
  printf("parents");
  for (size_t j = 0; j < joints; j++) printf(" %d", parents[j]);
  printf("\n");
  free(parents);

  /* A crowd of two, 40 frames, planted feet. */
  SinmdmSampling sampling = {7, 2, 4, SINMDM_FEET_PLANTED, SINMDM_METHOD_ANCESTRAL, 0.0};
  SinmdmResult *result = NULL;
  CHECK_OK(sinmdm_generate(model, &sampling, 40, &result));
  size_t count = 0, frames = 0;
  CHECK_OK(sinmdm_result_count(result, &count));
  CHECK_OK(sinmdm_result_frames(result, &frames));
  printf("generated %zu %zu\n", count, frames);
  Poses sample0 = poses_alloc(frames, joints), sample1 = poses_alloc(frames, joints);
  SinmdmPoseBuffers b0 = buffers_of(&sample0), b1 = buffers_of(&sample1);
  CHECK_OK(sinmdm_result_poses(result, 0, &b0));
  CHECK_OK(sinmdm_result_poses(result, 1, &b1));
  print_poses("generate1", &sample1);

  /* A few-step deterministic sample. */
  SinmdmSampling few = {5, 1, 8, SINMDM_FEET_RAW, SINMDM_METHOD_DPM2M, 0.0};
  print_generated(model, &few, 40, joints, "dpm2m");

  /* Zeroed steps: the default step count (SINMDM_DEFAULT_STEPS). */
  SinmdmSampling zeroed = {9, 1, 0, SINMDM_FEET_RAW, SINMDM_METHOD_ANCESTRAL, 0.0};
  print_generated(model, &zeroed, 30, joints, "default_steps");

  /* An in-between of sample 0: keep 0..10 and 30..40. */
  SinmdmPoses reference = input_of(&sample0);
  SinmdmSpan keep[2] = {{0, 10}, {30, 40}};
  SinmdmSampling once = {3, 1, 4, SINMDM_FEET_PLANTED, SINMDM_METHOD_ANCESTRAL, 0.0};
  SinmdmResult *between = NULL;
  CHECK_OK(sinmdm_inbetween(model, &once, &reference, keep, 2, 5, &between));
  Poses filled = poses_alloc(40, joints);
  SinmdmPoseBuffers bf = buffers_of(&filled);
  CHECK_OK(sinmdm_result_poses(between, 0, &bf));
  print_poses("inbetween", &filled);

  /* A stream in chunks of 20 and 25 frames. */
  SinmdmStreamOptions stream_options = {11, 3, 30, SINMDM_FEET_PLANTED, NULL, 0, 0, SINMDM_METHOD_ANCESTRAL, 0.0};
  SinmdmStream *stream = NULL;
  CHECK_OK(sinmdm_stream_new(model, &stream_options, &stream));
  Poses chunk_a = poses_alloc(20, joints), chunk_b = poses_alloc(25, joints);
  SinmdmPoseBuffers ba = buffers_of(&chunk_a), bb = buffers_of(&chunk_b);
  CHECK_OK(sinmdm_stream_next(stream, model, 20, &ba));
  CHECK_OK(sinmdm_stream_next(stream, model, 25, &bb));
  print_poses("stream20", &chunk_a);
  print_poses("stream25", &chunk_b);

  CHECK_OK(sinmdm_write_bvh(model, &reference, argv[3]));

  /* Bad arguments: a status code and a message each, never a crash. */
  int32_t one_parent_early[1];
  EXPECT(SINMDM_RUNTIME_LIBRARY, sinmdm_load_onnxruntime("/no/such/libonnxruntime.so"));
  EXPECT(SINMDM_NULL_ARGUMENT, sinmdm_model_rest_offsets(model, NULL, 0));
  EXPECT(SINMDM_NULL_ARGUMENT, sinmdm_model_parents(NULL, one_parent_early, 1));
  EXPECT(SINMDM_NULL_ARGUMENT, sinmdm_stream_supply(NULL, model, &reference));
  EXPECT(SINMDM_NULL_ARGUMENT, sinmdm_stream_supply(stream, model, NULL));
  SinmdmModel *none = NULL;
  EXPECT(SINMDM_NULL_ARGUMENT, sinmdm_model_open(NULL, 1, &none));
  EXPECT(SINMDM_NULL_ARGUMENT, sinmdm_model_open(argv[1], 1, NULL));
  EXPECT(SINMDM_BAD_MODEL, sinmdm_model_open(argv[2], 1, &none));
  EXPECT(SINMDM_BAD_MODEL, sinmdm_model_open("/no/such/model.onnx", 1, &none));
  const uint8_t junk[16] = {0x08, 0x01, 0x12, 0x04, 'j', 'u', 'n', 'k'};
  EXPECT(SINMDM_BAD_MODEL, sinmdm_model_open_bytes(junk, sizeof junk, 1, &none));
  EXPECT(SINMDM_NULL_ARGUMENT, sinmdm_model_open_bytes(NULL, 10, 1, &none));
  EXPECT(SINMDM_NULL_ARGUMENT, sinmdm_model_info(NULL, &info));
  EXPECT(SINMDM_NULL_ARGUMENT, sinmdm_model_info(model, NULL));
  char small[2];
  EXPECT(SINMDM_BUFFER_TOO_SMALL, sinmdm_model_joint_name(model, 0, small, sizeof small, NULL));
  EXPECT(SINMDM_INVALID_ARGUMENT, sinmdm_model_joint_name(model, 100000, NULL, 0, &needed));
  EXPECT(SINMDM_UNKNOWN_JOINT, sinmdm_model_find_joint(model, "NoSuchJoint", &found));
  EXPECT(SINMDM_NULL_ARGUMENT, sinmdm_model_find_joint(model, NULL, &found));
  int32_t one_parent[1];
  EXPECT(SINMDM_BUFFER_TOO_SMALL, sinmdm_model_parents(model, one_parent, 1));
  float one_offset[3];
  EXPECT(SINMDM_BUFFER_TOO_SMALL, sinmdm_model_rest_offsets(model, one_offset, 3));
  EXPECT(SINMDM_NULL_ARGUMENT, sinmdm_model_contact_joints(model, NULL, 0));
  SinmdmResult *unused = NULL;
  EXPECT(SINMDM_NULL_ARGUMENT, sinmdm_generate(NULL, &sampling, 10, &unused));
  EXPECT(SINMDM_NULL_ARGUMENT, sinmdm_generate(model, NULL, 10, &unused));
  EXPECT(SINMDM_NULL_ARGUMENT, sinmdm_generate(model, &sampling, 10, NULL));
  EXPECT(SINMDM_TASK_FAILED, sinmdm_generate(model, &sampling, 0, &unused));
  SinmdmSampling no_samples = {1, 0, 2, SINMDM_FEET_RAW, SINMDM_METHOD_ANCESTRAL, 0.0};
  EXPECT(SINMDM_TASK_FAILED, sinmdm_generate(model, &no_samples, 10, &unused));
  SinmdmSampling bad_feet = {1, 1, 2, 7, SINMDM_METHOD_ANCESTRAL, 0.0};
  EXPECT(SINMDM_INVALID_ARGUMENT, sinmdm_generate(model, &bad_feet, 10, &unused));
  SinmdmSampling bad_method = {1, 1, 2, SINMDM_FEET_RAW, 9, 0.0};
  EXPECT(SINMDM_INVALID_ARGUMENT, sinmdm_generate(model, &bad_method, 10, &unused));
  SinmdmSampling bad_eta = {1, 1, 2, SINMDM_FEET_RAW, SINMDM_METHOD_DDIM, 3.0};
  EXPECT(SINMDM_INVALID_ARGUMENT, sinmdm_generate(model, &bad_eta, 10, &unused));
  SinmdmSampling too_many_steps = {1, 1, 100000, SINMDM_FEET_RAW, SINMDM_METHOD_ANCESTRAL, 0.0};
  EXPECT(SINMDM_TASK_FAILED, sinmdm_generate(model, &too_many_steps, 10, &unused));
  SinmdmSpan past_end[1] = {{30, 50}};
  EXPECT(SINMDM_TASK_FAILED, sinmdm_inbetween(model, &once, &reference, past_end, 1, 5, &unused));
  EXPECT(SINMDM_NULL_ARGUMENT, sinmdm_inbetween(model, &once, &reference, NULL, 1, 5, &unused));
  EXPECT(SINMDM_NULL_ARGUMENT, sinmdm_inbetween(model, &once, NULL, keep, 2, 5, &unused));
  SinmdmPoses no_rotations = {40, sample0.root, NULL, NULL};
  EXPECT(SINMDM_NULL_ARGUMENT, sinmdm_expand(model, &once, &no_rotations, 5, 5, 3, &unused));
  SinmdmPoses zero_frames = {0, sample0.root, sample0.rot, NULL};
  EXPECT(SINMDM_INVALID_ARGUMENT, sinmdm_expand(model, &once, &zero_frames, 5, 5, 3, &unused));
  Poses broken = poses_alloc(40, joints); /* all-zero quaternions */
  SinmdmPoses broken_in = input_of(&broken);
  EXPECT(SINMDM_INVALID_ARGUMENT, sinmdm_harmonize(model, &once, &broken_in, 2, 0.02, &unused));
  EXPECT(SINMDM_TASK_FAILED, sinmdm_harmonize(model, &once, &reference, 2, 5.0, &unused));
  size_t bad_joint[1] = {100000};
  EXPECT(SINMDM_TASK_FAILED,
         sinmdm_compose(model, &once, &reference, bad_joint, 1, 0, NULL, 0, 5, &unused));
  EXPECT(SINMDM_NULL_ARGUMENT, sinmdm_compose(model, &once, &reference, NULL, 2, 0, NULL, 0, 5, &unused));
  EXPECT(SINMDM_NULL_ARGUMENT, sinmdm_result_count(NULL, &count));
  EXPECT(SINMDM_NULL_ARGUMENT, sinmdm_result_frames(result, NULL));
  EXPECT(SINMDM_INVALID_ARGUMENT, sinmdm_result_poses(result, 5, &b0));
  SinmdmPoseBuffers short_buffers = b0;
  short_buffers.rotations_capacity = 3;
  EXPECT(SINMDM_BUFFER_TOO_SMALL, sinmdm_result_poses(result, 0, &short_buffers));
  EXPECT(SINMDM_NULL_ARGUMENT, sinmdm_result_poses(result, 0, NULL));
  SinmdmStreamOptions tiny_blocks = {1, 2, 5, SINMDM_FEET_RAW, NULL, 0, 0, SINMDM_METHOD_ANCESTRAL, 0.0};
  SinmdmStream *no_stream = NULL;
  EXPECT(SINMDM_TASK_FAILED, sinmdm_stream_new(model, &tiny_blocks, &no_stream));
  EXPECT(SINMDM_NULL_ARGUMENT, sinmdm_stream_new(NULL, &stream_options, &no_stream));
  EXPECT(SINMDM_NULL_ARGUMENT, sinmdm_stream_next(NULL, model, 10, &ba));
  EXPECT(SINMDM_NULL_ARGUMENT, sinmdm_stream_next(stream, NULL, 10, &ba));
  EXPECT(SINMDM_BUFFER_TOO_SMALL, sinmdm_stream_next(stream, model, 21, &ba));
  EXPECT(SINMDM_INVALID_ARGUMENT, sinmdm_stream_supply(stream, model, &broken_in));
  EXPECT(SINMDM_NULL_ARGUMENT, sinmdm_write_bvh(model, &reference, NULL));
  EXPECT(SINMDM_IO, sinmdm_write_bvh(model, &reference, "/no/such/folder/out.bvh"));
  sinmdm_result_free(NULL);
  sinmdm_stream_free(NULL);
  sinmdm_model_free(NULL);

  poses_free(&broken);
  poses_free(&chunk_a);
  poses_free(&chunk_b);
  poses_free(&filled);
  poses_free(&sample0);
  poses_free(&sample1);
  sinmdm_stream_free(stream);
  sinmdm_result_free(between);
  sinmdm_result_free(result);
  sinmdm_model_free(model);
  if (failures > 0) {
    fprintf(stderr, "%d of %d bad-argument checks failed\n", failures, checks);
    return 1;
  }
  printf("bad arguments: %d checks\n", checks);
  return 0;
}
