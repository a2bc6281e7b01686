/* The C ABI from C: a shipped model opened, a crowd generated, an in-between of it, a stream in
 * two uneven chunks and a BVH written, every value printed as the bits of its float so the
 * Rust test can compare them with the Rust API's exactly; then what the header says of
 * versions, threads, batches, bounds, cancels, steering arrays and handles, each checked; then
 * every entry point fed bad arguments, each of which must give its status code and a message,
 * never a crash.
 *
 * Usage: api_check MODEL.onnx NOT_A_MODEL_FILE OUT.bvh STEERABLE_MODEL.onnx WORLD_ROOT_MODEL.onnx
 * (a heading-relative model, for the steering checks, and one with the world root, which refuses
 * steering)
 * Prints "<label> <hex> <hex> ..." lines, then "bad arguments: N checks" on success.
 *
 * Or: api_check --not-found, run where no onnxruntime can be found: the refusal must name every
 * place the header says is searched, in its order; prints "not found: N places" on success. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#ifdef __linux__
#include <dirent.h>
#endif

#include "sinmdm.h"

/* The threads onnxruntime's environment starts (the header's Threads): one with the 1.31.1
   the tests load. */
#ifndef ONNXRUNTIME_THREADS
#define ONNXRUNTIME_THREADS 1
#endif

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

/* Generates with `sampling` and writes sample 0 into `poses` (of the frames asked for). */
static void generate_into(SinmdmModel *model, const SinmdmSampling *sampling, Poses *poses) {
  SinmdmResult *result = NULL;
  CHECK_OK(sinmdm_generate(model, sampling, poses->frames, &result));
  SinmdmPoseBuffers buffers = buffers_of(poses);
  CHECK_OK(sinmdm_result_poses(result, 0, &buffers));
  sinmdm_result_free(result);
}

/* Generates `frames` frames with `sampling` and prints the first sample under `label`. */
static void print_generated(SinmdmModel *model, const SinmdmSampling *sampling, size_t frames,
                            size_t joints, const char *label) {
  Poses poses = poses_alloc(frames, joints);
  generate_into(model, sampling, &poses);
  print_poses(label, &poses);
  poses_free(&poses);
}

/* A progress callback that cancels once `*userdata` steps are done. */
static int32_t cancel_at(void *userdata, size_t done, size_t total) {
  (void)total;
  return done >= *(size_t *)userdata ? SINMDM_PROGRESS_CANCEL : SINMDM_PROGRESS_CONTINUE;
}

static int same_floats(const float *a, const float *b, size_t count) {
  return memcmp(a, b, count * sizeof(float)) == 0;
}

static int same_poses(const Poses *a, const Poses *b) {
  return same_floats(a->root, b->root, 3 * a->frames) &&
         same_floats(a->rot, b->rot, 4 * a->joints * a->frames) &&
         same_floats(a->trans, b->trans, 3 * a->joints * a->frames);
}

static void expect_true(int ok, const char *what) {
  checks++;
  if (!ok) {
    fprintf(stderr, "check failed: %s\n", what);
    failures++;
  }
}

/* Threads of this process now (Linux: /proc/self/task), or 0 where that cannot be read. */
static size_t threads_now(void) {
#ifdef __linux__
  DIR *dir = opendir("/proc/self/task");
  if (dir == NULL) return 0;
  size_t n = 0;
  struct dirent *entry;
  while ((entry = readdir(dir)) != NULL) {
    if (entry->d_name[0] != '.') n++;
  }
  closedir(dir);
  return n;
#else
  return 0;
#endif
}

/* The thread count once it is `want`, or after 5 s of waiting for it: a thread the library
   lets go (a run's noise thread) ends on its own just after. */
static size_t threads_settled(size_t want) {
  size_t n = threads_now();
  for (int i = 0; i < 500 && n != want; i++) {
    struct timespec pause = {0, 10 * 1000 * 1000};
    nanosleep(&pause, NULL);
    n = threads_now();
  }
  return n;
}

/* A progress callback that counts its calls in `*userdata` and asks to stop. */
static int32_t count_calls(void *userdata, size_t done, size_t total) {
  (void)done;
  (void)total;
  (*(size_t *)userdata)++;
  return SINMDM_PROGRESS_CANCEL;
}

/* A progress callback that counts in `userdata[1]` the steps after which the thread count is
   not `userdata[0]` (the threads that stay and the run's own), and goes on. */
static int32_t watch_threads(void *userdata, size_t done, size_t total) {
  (void)done;
  (void)total;
  size_t *watch = userdata;
  size_t n = threads_settled(watch[0]);
  if (n != 0 && n != watch[0]) watch[1]++;
  return SINMDM_PROGRESS_CONTINUE;
}

/* The poses of sample 0 of a finished run (freed), into `out`. */
static void finish_into(SinmdmRun *run, Poses *out) {
  SinmdmResult *result = NULL;
  CHECK_OK(sinmdm_run_finish(run, &result));
  SinmdmPoseBuffers b = buffers_of(out);
  CHECK_OK(sinmdm_result_poses(result, 0, &b));
  sinmdm_result_free(result);
  sinmdm_run_free(run);
}

/* Stepped runs, cancel and prepared streams: the same bits as the one-call calls. */
static void check_stepping(SinmdmModel *model, size_t joints, const SinmdmPoses *reference) {
  SinmdmSampling sampling = {13, 1, 7, SINMDM_FEET_PLANTED, SINMDM_METHOD_ANCESTRAL, 0.0};
  Poses once = poses_alloc(40, joints);
  generate_into(model, &sampling, &once);
  size_t per_call[3] = {1, 3, SIZE_MAX};
  for (int i = 0; i < 3; i++) {
    SinmdmRun *run = NULL;
    CHECK_OK(sinmdm_generate_begin(model, &sampling, 40, &run));
    size_t done = 0, total = 0, calls = 0;
    while (done < 7 || total == 0) {
      CHECK_OK(sinmdm_run_step(run, model, per_call[i], &done, &total));
      calls++;
      if (calls > 100) break;
    }
    expect_true(total == 7, "a run of 7 steps says 7");
    Poses stepped = poses_alloc(40, joints);
    finish_into(run, &stepped);
    expect_true(same_poses(&stepped, &once), "stepped run differs from the one-call run");
    poses_free(&stepped);
  }
  /* An in-between stepped 2 at a time equals the one-call in-between. */
  SinmdmSpan keep[2] = {{0, 10}, {30, 40}};
  SinmdmResult *between = NULL;
  CHECK_OK(sinmdm_inbetween(model, &sampling, reference, keep, 2, 5, &between));
  Poses between_once = poses_alloc(40, joints), between_stepped = poses_alloc(40, joints);
  SinmdmPoseBuffers bb = buffers_of(&between_once);
  CHECK_OK(sinmdm_result_poses(between, 0, &bb));
  sinmdm_result_free(between);
  SinmdmRun *run = NULL;
  CHECK_OK(sinmdm_inbetween_begin(model, &sampling, reference, keep, 2, 5, &run));
  for (int k = 0; k < 4; k++) CHECK_OK(sinmdm_run_step(run, model, 2, NULL, NULL));
  finish_into(run, &between_stepped);
  expect_true(same_poses(&between_once, &between_stepped), "stepped in-between differs");
  poses_free(&between_once);
  poses_free(&between_stepped);

  /* Freed half way (cancel), finished early (a preview), finished before any step. */
  CHECK_OK(sinmdm_generate_begin(model, &sampling, 40, &run));
  CHECK_OK(sinmdm_run_step(run, model, 3, NULL, NULL));
  sinmdm_run_free(run);
  CHECK_OK(sinmdm_generate_begin(model, &sampling, 40, &run));
  CHECK_OK(sinmdm_run_step(run, model, 3, NULL, NULL));
  Poses preview = poses_alloc(40, joints);
  finish_into(run, &preview);
  expect_true(!same_poses(&preview, &once), "a preview is not the finished motion");
  poses_free(&preview);
  CHECK_OK(sinmdm_generate_begin(model, &sampling, 40, &run));
  SinmdmResult *nothing = NULL;
  EXPECT(SINMDM_INVALID_ARGUMENT, sinmdm_run_finish(run, &nothing));
  CHECK_OK(sinmdm_run_step(run, model, SIZE_MAX, NULL, NULL));
  CHECK_OK(sinmdm_run_finish(run, &nothing));
  sinmdm_result_free(nothing);
  EXPECT(SINMDM_INVALID_ARGUMENT, sinmdm_run_step(run, model, 1, NULL, NULL));
  EXPECT(SINMDM_INVALID_ARGUMENT, sinmdm_run_finish(run, &nothing));
  sinmdm_run_free(run);
  EXPECT(SINMDM_NULL_ARGUMENT, sinmdm_run_step(NULL, model, 1, NULL, NULL));
  EXPECT(SINMDM_NULL_ARGUMENT, sinmdm_generate_begin(model, &sampling, 40, NULL));

  /* A progress callback that cancels at step 3: CANCELLED, no result, the model usable. */
  size_t stop_at = 3;
  CHECK_OK(sinmdm_model_set_progress(model, cancel_at, &stop_at));
  SinmdmResult *cancelled = (SinmdmResult *)&stop_at;
  EXPECT(SINMDM_CANCELLED, sinmdm_generate(model, &sampling, 40, &cancelled));
  expect_true(cancelled == NULL, "a cancelled call gives no result");
  /* At the last step (done == total) too: CANCELLED and no result, as at any other. */
  stop_at = 7;
  cancelled = (SinmdmResult *)&stop_at;
  EXPECT(SINMDM_CANCELLED, sinmdm_generate(model, &sampling, 40, &cancelled));
  expect_true(cancelled == NULL, "a call cancelled at its last step gives no result");
  stop_at = SIZE_MAX;
  Poses after = poses_alloc(40, joints);
  generate_into(model, &sampling, &after);
  expect_true(same_poses(&after, &once), "the model after a cancel gives the same motion");
  /* A stepped run never calls the callback, so it is never cancelled. */
  size_t calls = 0;
  CHECK_OK(sinmdm_model_set_progress(model, count_calls, &calls));
  CHECK_OK(sinmdm_generate_begin(model, &sampling, 40, &run));
  CHECK_OK(sinmdm_run_step(run, model, SIZE_MAX, NULL, NULL));
  expect_true(calls == 0, "sinmdm_run_step does not call the progress callback");
  /* Refusals of run_finish leave the run as it was; the finish after them works. */
  EXPECT(SINMDM_NULL_ARGUMENT, sinmdm_run_finish(run, NULL));
  Poses stepped_on = poses_alloc(40, joints);
  finish_into(run, &stepped_on);
  expect_true(same_poses(&stepped_on, &once), "a run finished after a refused finish is whole");
  poses_free(&stepped_on);
  CHECK_OK(sinmdm_model_set_progress(model, NULL, NULL));
  poses_free(&after);

  /* A stream prepared ahead a step at a time, then read, equals a blocking stream. */
  SinmdmStreamOptions options = {11, 3, 30, SINMDM_FEET_PLANTED, NULL, 0, 0, SINMDM_METHOD_ANCESTRAL, 0.0};
  SinmdmStream *blocking = NULL, *prepared = NULL;
  CHECK_OK(sinmdm_stream_new(model, &options, &blocking));
  CHECK_OK(sinmdm_stream_new(model, &options, &prepared));
  for (int chunk = 0; chunk < 3; chunk++) {
    size_t n = chunk == 1 ? 45 : 20;
    Poses want = poses_alloc(n, joints), got = poses_alloc(n, joints);
    SinmdmPoseBuffers wb = buffers_of(&want), gb = buffers_of(&got);
    CHECK_OK(sinmdm_stream_next(blocking, model, n, &wb));
    size_t ready = 0, frames_of_game = 0;
    while (ready < n && frames_of_game < 100) {
      CHECK_OK(sinmdm_stream_step(prepared, model, 1, n, &ready, NULL, NULL));
      frames_of_game++;
    }
    CHECK_OK(sinmdm_stream_next(prepared, model, n, &gb));
    expect_true(same_poses(&want, &got), "a prepared stream differs from a blocking one");
    poses_free(&want);
    poses_free(&got);
  }
  sinmdm_stream_free(blocking);
  sinmdm_stream_free(prepared);
  poses_free(&once);
}

static void steer_velocity(SinmdmSteerFrame *frames, size_t count, double forward, double turn) {
  for (size_t i = 0; i < count; i++) {
    SinmdmSteerFrame f = {SINMDM_STEER_VELOCITY, 0, forward, turn, {0.0, 0.0, 0.0}};
    frames[i] = f;
  }
}

/* Steering the zombie walk (a heading-relative model): its limits, a one-shot run of 40 frames
   at 12 units/s turning 0.3 rad/s, a stream told 10 units/s turning -0.2 rad/s, and the
   refusals: a world-root model, a bad kind, a non-finite value, a NULL array. */
static void check_steering(const char *path, const char *world_path) {
  SinmdmModel *zombie = NULL, *world = NULL;
  CHECK_OK(sinmdm_model_open(path, 1, &zombie));
  CHECK_OK(sinmdm_model_open(world_path, 1, &world));
  SinmdmModelInfo info;
  CHECK_OK(sinmdm_model_info(zombie, &info));
  SinmdmSteerLimits limits;
  CHECK_OK(sinmdm_steer_limits(zombie, &limits));
  expect_true(limits.forward_max > limits.forward_min && limits.turn_max > 0.0,
              "steering limits are a range");
  SinmdmSteerFrame commands[60];
  steer_velocity(commands, 40, 12.0, 0.3);
  SinmdmSampling once = {3, 1, 4, SINMDM_FEET_PLANTED, SINMDM_METHOD_ANCESTRAL, 0.0};
  SinmdmResult *steered = NULL;
  CHECK_OK(sinmdm_steer(zombie, &once, 40, commands, 40, 5, &steered));
  Poses steer_poses = poses_alloc(40, info.joints);
  SinmdmPoseBuffers bs = buffers_of(&steer_poses);
  CHECK_OK(sinmdm_result_poses(steered, 0, &bs));
  print_poses("steer", &steer_poses);
  sinmdm_result_free(steered);
  /* Facing commands (SinmdmSteerCommand): 20 frames facing (1, 0.5) on the ground (+Z is
     up), then 20 at positions (0.5 i, 0.2 i) facing +Y. */
  SinmdmSteerCommand faced[40];
  for (size_t i = 0; i < 40; i++) {
    SinmdmSteerCommand facing = {SINMDM_STEER_FACING, 0, 0.0, 0.0, {0.0, 0.0, 0.0}, {1.0, 0.5, 0.0}};
    SinmdmSteerCommand both = {SINMDM_STEER_POSITION_FACING, 0, 0.0, 0.0,
                               {0.5 * (double)i, 0.2 * (double)i, 0.0}, {0.0, 1.0, 0.0}};
    faced[i] = i < 20 ? facing : both;
  }
  expect_true(sizeof(SinmdmSteerCommand) == 72 && sizeof(SinmdmSteerFrame) == 48,
              "steering structs are 72 and 48 bytes");
  CHECK_OK(sinmdm_steer_commands(zombie, &once, 40, faced, 40, 5, &steered));
  CHECK_OK(sinmdm_result_poses(steered, 0, &bs));
  print_poses("steerfacing", &steer_poses);
  sinmdm_result_free(steered);
  SinmdmSteerSideways sideways;
  CHECK_OK(sinmdm_steer_sideways_limits(zombie, &sideways));
  expect_true(sideways.leftward_min < sideways.leftward_max, "sideways limits are a range");
  /* A facing straight up has no direction on the ground; the frame struct takes no facings. */
  SinmdmResult *refused = NULL;
  faced[0].facing[0] = 0.0;
  faced[0].facing[1] = 0.0;
  faced[0].facing[2] = 2.0;
  EXPECT(SINMDM_INVALID_ARGUMENT, sinmdm_steer_commands(zombie, &once, 40, faced, 40, 5, &refused));
  expect_true(refused == NULL, "a refused steer writes no result");
  SinmdmSteerFrame old_kind[1] = {{SINMDM_STEER_FACING, 0, 0.0, 0.0, {1.0, 0.0, 0.0}}};
  EXPECT(SINMDM_INVALID_ARGUMENT, sinmdm_steer(zombie, &once, 40, old_kind, 1, 5, &refused));
  poses_free(&steer_poses);

  SinmdmStreamOptions options = {11, 3, 30, SINMDM_FEET_PLANTED, NULL, 0, 0, SINMDM_METHOD_ANCESTRAL, 0.0};
  SinmdmStream *stream = NULL;
  CHECK_OK(sinmdm_stream_new(zombie, &options, &stream));
  steer_velocity(commands, 60, 10.0, -0.2);
  CHECK_OK(sinmdm_stream_steer(stream, commands, 60));
  Poses a = poses_alloc(20, info.joints), b = poses_alloc(25, info.joints);
  SinmdmPoseBuffers ba = buffers_of(&a), bb = buffers_of(&b);
  CHECK_OK(sinmdm_stream_next(stream, zombie, 20, &ba));
  CHECK_OK(sinmdm_stream_next(stream, zombie, 25, &bb));
  print_poses("steerstream20", &a);
  print_poses("steerstream25", &b);
  poses_free(&a);
  poses_free(&b);

  SinmdmResult *unused = NULL;
  EXPECT(SINMDM_INVALID_ARGUMENT, sinmdm_steer_limits(world, &limits));
  EXPECT(SINMDM_INVALID_ARGUMENT, sinmdm_steer(world, &once, 40, commands, 40, 5, &unused));
  SinmdmStream *world_stream = NULL;
  CHECK_OK(sinmdm_stream_new(world, &options, &world_stream));
  EXPECT(SINMDM_INVALID_ARGUMENT, sinmdm_stream_steer(world_stream, commands, 1));
  sinmdm_stream_free(world_stream);
  commands[3].kind = 7;
  EXPECT(SINMDM_INVALID_ARGUMENT, sinmdm_stream_steer(stream, commands, 10));
  commands[3].kind = SINMDM_STEER_POSITION;
  commands[3].position[1] = NAN;
  EXPECT(SINMDM_INVALID_ARGUMENT, sinmdm_steer(zombie, &once, 40, commands, 10, 5, &unused));
  EXPECT(SINMDM_NULL_ARGUMENT, sinmdm_stream_steer(stream, NULL, 3));
  /* An empty array (NULL with a count of 0) adds nothing and succeeds. */
  CHECK_OK(sinmdm_stream_steer(stream, NULL, 0));
  CHECK_OK(sinmdm_stream_steer_commands(stream, NULL, 0));
  /* A reserved field that is not 0, and more commands than frames, are refused. */
  steer_velocity(commands, 40, 12.0, 0.3);
  EXPECT(SINMDM_INVALID_ARGUMENT, sinmdm_steer(zombie, &once, 30, commands, 40, 5, &unused));
  SinmdmRun *not_begun = NULL;
  EXPECT(SINMDM_INVALID_ARGUMENT, sinmdm_steer_begin(zombie, &once, 30, commands, 31, 5, &not_begun));
  commands[2].reserved = 7;
  EXPECT(SINMDM_INVALID_ARGUMENT, sinmdm_steer(zombie, &once, 40, commands, 40, 5, &unused));
  EXPECT(SINMDM_INVALID_ARGUMENT, sinmdm_stream_steer(stream, commands, 10));
  SinmdmSteerCommand reserved_command = {SINMDM_STEER_FACING, 7, 0.0, 0.0, {0.0, 0.0, 0.0}, {1.0, 0.0, 0.0}};
  EXPECT(SINMDM_INVALID_ARGUMENT, sinmdm_stream_steer_commands(stream, &reserved_command, 1));
  EXPECT(SINMDM_INVALID_ARGUMENT,
         sinmdm_steer_commands(zombie, &once, 40, &reserved_command, 1, 5, &unused));
  expect_true(unused == NULL && not_begun == NULL, "a refused steer gives no handle");
  EXPECT(SINMDM_NULL_ARGUMENT, sinmdm_steer_limits(NULL, &limits));
  EXPECT(SINMDM_NULL_ARGUMENT, sinmdm_steer_limits(zombie, NULL));
  sinmdm_stream_free(stream);
  sinmdm_model_free(zombie);
  sinmdm_model_free(world);
}

/* A crowd of the zombie walk on two threads: a steered character is the same bits as the steered
   stream alone ("crowdsteer" against "steerstream"), with a stranger beside it that leaves
   between its reads and another that joins; and the crowd's refusals. */
static void check_crowd(const char *path, const char *world_path) {
  SinmdmModel *zombie = NULL, *world = NULL;
  CHECK_OK(sinmdm_model_open(path, 2, &zombie));
  CHECK_OK(sinmdm_model_open(world_path, 1, &world));
  SinmdmModelInfo info;
  CHECK_OK(sinmdm_model_info(zombie, &info));
  SinmdmCrowd *crowd = NULL;
  CHECK_OK(sinmdm_crowd_new(zombie, &crowd));
  SinmdmStreamOptions stranger = {12, 3, 30, SINMDM_FEET_RAW, NULL, 0, 0, SINMDM_METHOD_ANCESTRAL, 0.0};
  SinmdmStreamOptions steered = {11, 3, 30, SINMDM_FEET_PLANTED, NULL, 0, 0, SINMDM_METHOD_ANCESTRAL, 0.0};
  SinmdmStreamOptions late = {13, 5, 40, SINMDM_FEET_PLANTED, NULL, 0, 0, SINMDM_METHOD_ANCESTRAL, 0.0};
  uint64_t first = 99, second = 99, third = 99;
  CHECK_OK(sinmdm_crowd_join(crowd, &stranger, &first));
  CHECK_OK(sinmdm_crowd_join(crowd, &steered, &second));
  expect_true(first == 0 && second == 1, "characters are numbered from 0 in the order they join");
  SinmdmSteerCommand commands[60];
  for (size_t i = 0; i < 60; i++) {
    SinmdmSteerCommand c = {SINMDM_STEER_VELOCITY, 0, 10.0, -0.2, {0.0, 0.0, 0.0}, {0.0, 0.0, 0.0}};
    commands[i] = c;
  }
  CHECK_OK(sinmdm_crowd_steer(crowd, second, commands, 60));
  size_t steps = 0, waiting = 0, count = 0;
  CHECK_OK(sinmdm_crowd_step(crowd, zombie, 2, 45, &steps, &waiting));
  expect_true(steps == 2 && waiting == 2, "a step each of three-step blocks leaves both waiting");
  CHECK_OK(sinmdm_crowd_step(crowd, zombie, 100, 45, NULL, &waiting));
  expect_true(waiting == 0, "enough steps prepare every character");
  Poses a = poses_alloc(20, info.joints), b = poses_alloc(25, info.joints);
  SinmdmPoseBuffers ba = buffers_of(&a), bb = buffers_of(&b);
  CHECK_OK(sinmdm_crowd_next(crowd, zombie, second, 20, &ba));
  CHECK_OK(sinmdm_crowd_leave(crowd, first));
  CHECK_OK(sinmdm_crowd_join(crowd, &late, &third));
  CHECK_OK(sinmdm_crowd_count(crowd, &count));
  expect_true(third == 2 && count == 2, "a number is never given again");
  CHECK_OK(sinmdm_crowd_step(crowd, zombie, 100, 30, NULL, NULL));
  CHECK_OK(sinmdm_crowd_next(crowd, zombie, second, 25, &bb));
  print_poses("crowdsteer20", &a);
  print_poses("crowdsteer25", &b);

  /* Refusals: a character not in the crowd, another model, bounds, NULLs. */
  EXPECT(SINMDM_INVALID_ARGUMENT, sinmdm_crowd_leave(crowd, first));
  EXPECT(SINMDM_INVALID_ARGUMENT, sinmdm_crowd_next(crowd, zombie, 77, 1, &ba));
  EXPECT(SINMDM_INVALID_ARGUMENT, sinmdm_crowd_steer(crowd, 77, commands, 1));
  EXPECT(SINMDM_INVALID_ARGUMENT, sinmdm_crowd_step(crowd, world, 1, 1, NULL, NULL));
  EXPECT(SINMDM_INVALID_ARGUMENT, sinmdm_crowd_next(crowd, world, second, 1, &ba));
  EXPECT(SINMDM_INVALID_ARGUMENT,
         sinmdm_crowd_step(crowd, zombie, 1, SINMDM_MAX_SAMPLE_FRAMES + 1, NULL, NULL));
  EXPECT(SINMDM_INVALID_ARGUMENT,
         sinmdm_crowd_next(crowd, zombie, second, SINMDM_MAX_SAMPLE_FRAMES + 1, &ba));
  EXPECT(SINMDM_NULL_ARGUMENT, sinmdm_crowd_next(crowd, zombie, second, 0, NULL));
  EXPECT(SINMDM_NULL_ARGUMENT, sinmdm_crowd_join(crowd, NULL, &third));
  EXPECT(SINMDM_NULL_ARGUMENT, sinmdm_crowd_join(crowd, &late, NULL));
  EXPECT(SINMDM_NULL_ARGUMENT, sinmdm_crowd_step(NULL, zombie, 1, 1, NULL, NULL));
  EXPECT(SINMDM_NULL_ARGUMENT, sinmdm_crowd_count(crowd, NULL));
  SinmdmStreamOptions bad = {1, 3, 1, SINMDM_FEET_PLANTED, NULL, 0, 0, SINMDM_METHOD_ANCESTRAL, 0.0};
  EXPECT(SINMDM_INVALID_ARGUMENT, sinmdm_crowd_join(crowd, &bad, &third));
  SinmdmCrowd *refused = NULL;
  EXPECT(SINMDM_NULL_ARGUMENT, sinmdm_crowd_new(NULL, &refused));
  expect_true(refused == NULL, "a refused crowd gives no handle");
  CHECK_OK(sinmdm_crowd_count(crowd, &count));
  expect_true(count == 2, "refusals change no character");
  poses_free(&a);
  poses_free(&b);
  sinmdm_crowd_free(crowd);
  sinmdm_crowd_free(NULL);
  sinmdm_model_free(zombie);
  sinmdm_model_free(world);
}

/* The library's version is the header's: "MAJOR.MINOR.PATCH" of the SINMDM_VERSION_* macros. */
static void check_version(void) {
  unsigned major = 999, minor = 999, patch = 999;
  int parsed = sscanf(sinmdm_version(), "%u.%u.%u", &major, &minor, &patch);
  expect_true(parsed == 3 && major == SINMDM_VERSION_MAJOR && minor == SINMDM_VERSION_MINOR &&
                  patch == SINMDM_VERSION_PATCH,
              "sinmdm_version() reads SINMDM_VERSION_MAJOR.MINOR.PATCH");
}

/* What the header says of batches, bounds, threads and handles: sample k of a crowd is sample k
   of any crowd of more than k samples (count 1 gives sample 0); a request past
   SINMDM_MAX_RUN_VALUES by sinmdm_model_values_per_frame is refused; a run has one thread of
   its own, gone once it is freed, and a crowd's threads are joined before a call returns; a
   run or stream takes only the handle it was made with; stream_next checks its buffers for 0
   frames too. */
static void check_header_word(SinmdmModel *model, const char *model_path, const SinmdmModelInfo *info,
                              const Poses *sample0, const Poses *sample1, size_t threads_loaded,
                              SinmdmStream *stream, SinmdmPoseBuffers *chunk_buffers) {
  size_t joints = info->joints;
  /* Batches: sample 0 alone (count 1) and samples 0 and 1 of a crowd of 3 are the crowd of
     2's, bit for bit. */
  SinmdmSampling alone = {7, 1, 4, SINMDM_FEET_PLANTED, SINMDM_METHOD_ANCESTRAL, 0.0};
  Poses first = poses_alloc(40, joints);
  generate_into(model, &alone, &first);
  expect_true(same_poses(&first, sample0), "count 1 gives sample 0 of a crowd with its seed");
  SinmdmSampling three = alone;
  three.count = 3;
  SinmdmResult *crowd = NULL;
  CHECK_OK(sinmdm_generate(model, &three, 40, &crowd));
  Poses again0 = poses_alloc(40, joints), again1 = poses_alloc(40, joints);
  SinmdmPoseBuffers b0 = buffers_of(&again0), b1 = buffers_of(&again1);
  CHECK_OK(sinmdm_result_poses(crowd, 0, &b0));
  CHECK_OK(sinmdm_result_poses(crowd, 1, &b1));
  expect_true(same_poses(&again0, sample0) && same_poses(&again1, sample1),
              "samples 0 and 1 of a crowd of 3 are those of a crowd of 2");
  expect_true(!same_poses(&first, &again1), "sample 1 is not sample 0");
  sinmdm_result_free(crowd);
  poses_free(&first);
  poses_free(&again0);
  poses_free(&again1);

  /* The run-size bound in terms a host has. */
  size_t values = 0;
  CHECK_OK(sinmdm_model_values_per_frame(model, &values));
  expect_true(values >= info->features + 8 && values >= 12 * joints,
              "values per frame is max(F + 8 C, 12 x joints)");
  size_t crowd_size = SINMDM_MAX_SAMPLES;
  size_t too_long = (size_t)SINMDM_MAX_RUN_VALUES / (crowd_size * values) + 1;
  SinmdmSampling big = {1, (uint32_t)crowd_size, 2, SINMDM_FEET_RAW, SINMDM_METHOD_ANCESTRAL, 0.0};
  SinmdmRun *run = NULL;
  EXPECT(SINMDM_INVALID_ARGUMENT, sinmdm_generate_begin(model, &big, too_long, &run));
  expect_true(strstr(sinmdm_last_error(), "GiB") != NULL, "the first refused length is the size bound's");
  EXPECT(SINMDM_NULL_ARGUMENT, sinmdm_model_values_per_frame(NULL, &values));
  EXPECT(SINMDM_NULL_ARGUMENT, sinmdm_model_values_per_frame(model, NULL));

  /* Threads: a run begun has its noise thread, gone once the run is freed. */
  SinmdmSampling small = {3, 1, 3, SINMDM_FEET_RAW, SINMDM_METHOD_ANCESTRAL, 0.0};
  expect_true(threads_settled(threads_loaded) == threads_loaded, "no thread is left before a run");
  CHECK_OK(sinmdm_generate_begin(model, &small, 40, &run));
  CHECK_OK(sinmdm_run_step(run, model, 1, NULL, NULL));
  size_t during = threads_now();
  expect_true(during == 0 || during == threads_loaded + 1, "a run in progress has one thread of its own");

  /* Handles: a second handle of the same file is another model to a run and a stream. */
  SinmdmModel *twin = NULL;
  CHECK_OK(sinmdm_model_open(model_path, 1, &twin));
  EXPECT(SINMDM_INVALID_ARGUMENT, sinmdm_run_step(run, twin, 1, NULL, NULL));
  EXPECT(SINMDM_INVALID_ARGUMENT, sinmdm_stream_next(stream, twin, 1, chunk_buffers));
  EXPECT(SINMDM_INVALID_ARGUMENT, sinmdm_stream_step(stream, twin, 1, 1, NULL, NULL, NULL));
  sinmdm_model_free(twin);
  sinmdm_run_free(run);
  size_t after = threads_settled(threads_loaded);
  expect_true(after == 0 || after == threads_loaded, "a freed run's thread ends");

  /* A crowd on a model of 2 threads: after each step (in the callback) the run's noise thread
     is the only one besides the loaded ones, the denoising thread having been joined. */
  SinmdmModel *pair = NULL;
  CHECK_OK(sinmdm_model_open(model_path, 2, &pair));
  size_t watch[2] = {threads_loaded + 1, 0};
  CHECK_OK(sinmdm_model_set_progress(pair, watch_threads, watch));
  SinmdmSampling two = small;
  two.count = 2;
  SinmdmResult *pair_result = NULL;
  CHECK_OK(sinmdm_generate(pair, &two, 40, &pair_result));
  expect_true(watch[1] == 0, "a crowd's denoising threads are joined before each step ends");
  sinmdm_result_free(pair_result);
  sinmdm_model_free(pair);
  after = threads_settled(threads_loaded);
  expect_true(after == 0 || after == threads_loaded, "a crowd's run thread ends with it");

  /* stream_next checks its buffers whatever the frames: NULL is refused for 0 frames too. */
  EXPECT(SINMDM_NULL_ARGUMENT, sinmdm_stream_next(stream, model, 0, NULL));
  CHECK_OK(sinmdm_stream_next(stream, model, 0, chunk_buffers));
}

/* Where no onnxruntime can be found: the refusal names every place the header lists, in its
   order, and a model open refuses alike. */
static int check_not_found(void) {
  const char *places[5] = {"ORT_DYLIB_PATH", "next to the executable", "next to this library",
                           "the system loader's search path", "a developer checkout's .venv"};
  SinmdmStatus status = sinmdm_load_onnxruntime(NULL);
  const char *message = sinmdm_last_error();
  const char *at = strstr(message, "Tried, in order:");
  if (status != SINMDM_RUNTIME_LIBRARY || at == NULL) {
    fprintf(stderr, "no onnxruntime gave %d: '%s'\n", (int)status, message);
    return 1;
  }
  for (int i = 0; i < 5; i++) {
    const char *found = strstr(at, places[i]);
    if (found == NULL) {
      fprintf(stderr, "the refusal does not name '%s' after the places before it: '%s'\n", places[i], message);
      return 1;
    }
    at = found + strlen(places[i]);
  }
  printf("%s\n", message);
  const uint8_t junk[8] = {0x08, 0x01, 0x12, 0x04, 'j', 'u', 'n', 'k'};
  SinmdmModel *none = NULL;
  status = sinmdm_model_open_bytes(junk, sizeof junk, 1, &none);
  if (status != SINMDM_RUNTIME_LIBRARY || strstr(sinmdm_last_error(), places[4]) == NULL) {
    fprintf(stderr, "a model open without onnxruntime gave %d: '%s'\n", (int)status, sinmdm_last_error());
    return 1;
  }
  printf("not found: 5 places\n");
  return 0;
}

int main(int argc, char **argv) {
  if (argc == 2 && strcmp(argv[1], "--not-found") == 0) return check_not_found();
  if (argc != 6) {
    fprintf(stderr,
            "usage: api_check MODEL.onnx NOT_A_MODEL OUT.bvh STEERABLE_MODEL.onnx WORLD_ROOT_MODEL.onnx\n");
    return 2;
  }
  check_version();
  /* Loading onnxruntime starts the threads the header lists for it, which stay. */
  size_t threads_at_start = threads_now();
  CHECK_OK(sinmdm_load_onnxruntime(NULL));
  /* At most the header's count: onnxruntime 1.31.1 starts its timer thread, except where the
     environment variable CI is set (as on the project's CI), where it starts none. Settled, as
     a thread may show a moment late on a loaded machine. */
  size_t threads_loaded = threads_settled(threads_at_start + ONNXRUNTIME_THREADS);
  if (threads_at_start != 0 && (threads_loaded < threads_at_start ||
                                threads_loaded > threads_at_start + ONNXRUNTIME_THREADS)) {
    fprintf(stderr, "threads: %zu before loading onnxruntime, %zu after (at most +%d)\n",
            threads_at_start, threads_loaded, ONNXRUNTIME_THREADS);
  }
  expect_true(threads_at_start == 0 || (threads_loaded >= threads_at_start &&
                                        threads_loaded <= threads_at_start + ONNXRUNTIME_THREADS),
              "loading onnxruntime starts at most the threads the header lists");
  SinmdmModel *model = NULL;
  CHECK_OK(sinmdm_model_open(argv[1], 1, &model));
  expect_true(threads_at_start == 0 || threads_now() == threads_loaded, "opening a model starts no thread");
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
  size_t parents_needed = 0;
  CHECK_OK(sinmdm_model_parents(model, NULL, 0, &parents_needed));
  if (parents_needed != joints) {
    fprintf(stderr, "size query of parents gave %zu, not %zu\n", parents_needed, joints);
    return 1;
  }
  CHECK_OK(sinmdm_model_parents(model, parents, joints, NULL));
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

  /* The reference's dance beats (a size query first), then a dance of 50 frames on music
     beats every 12 frames from reference beats every 12 frames, the order shuffled. */
  size_t beat_count = 0;
  SinmdmStatus beats_status = sinmdm_dance_reference_beats(model, &reference, NULL, 0, &beat_count);
  float beats_summary[2] = {(float)beats_status, (float)(beats_status == SINMDM_OK ? beat_count : 0)};
  print_floats("dancebeats.status", beats_summary, 2);
  size_t reference_beats[3] = {8, 20, 32};
  size_t music_beats[4] = {5, 17, 29, 41};
  SinmdmDance dance = {reference_beats, 3, music_beats, 4, 50, 0, 3,
                       SINMDM_DANCE_ORDER_SHUFFLED, SINMDM_DANCE_LEVEL_AUTO, 1};
  SinmdmResult *danced = NULL;
  CHECK_OK(sinmdm_dance(model, &once, &reference, &dance, &danced));
  Poses dance_poses = poses_alloc(50, joints);
  SinmdmPoseBuffers bd = buffers_of(&dance_poses);
  CHECK_OK(sinmdm_result_poses(danced, 0, &bd));
  print_poses("dance", &dance_poses);
  poses_free(&dance_poses);
  sinmdm_result_free(danced);

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

  check_steering(argv[4], argv[5]);
  check_crowd(argv[4], argv[5]);

  CHECK_OK(sinmdm_write_bvh(model, &reference, argv[3]));

  check_stepping(model, joints, &reference);

  check_header_word(model, argv[1], &info, &sample0, &sample1, threads_loaded, stream, &ba);

  /* Bad arguments: a status code and a message each, never a crash. */
  int32_t one_parent_early[1];
  EXPECT(SINMDM_RUNTIME_LIBRARY, sinmdm_load_onnxruntime("/no/such/libonnxruntime.so"));
  EXPECT(SINMDM_NULL_ARGUMENT, sinmdm_model_rest_offsets(NULL, NULL, 0, NULL));
  EXPECT(SINMDM_NULL_ARGUMENT, sinmdm_model_parents(NULL, one_parent_early, 1, NULL));
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
  EXPECT(SINMDM_BUFFER_TOO_SMALL, sinmdm_model_parents(model, one_parent, 1, NULL));
  float one_offset[3];
  EXPECT(SINMDM_BUFFER_TOO_SMALL, sinmdm_model_rest_offsets(model, one_offset, 3, NULL));
  EXPECT(SINMDM_NULL_ARGUMENT, sinmdm_model_contact_joints(NULL, NULL, 0, NULL));
  SinmdmResult *unused = NULL;
  EXPECT(SINMDM_NULL_ARGUMENT, sinmdm_generate(NULL, &sampling, 10, &unused));
  EXPECT(SINMDM_NULL_ARGUMENT, sinmdm_generate(model, NULL, 10, &unused));
  EXPECT(SINMDM_NULL_ARGUMENT, sinmdm_generate(model, &sampling, 10, NULL));
  EXPECT(SINMDM_INVALID_ARGUMENT, sinmdm_generate(model, &sampling, 0, &unused));
  SinmdmSampling no_samples = {1, 0, 2, SINMDM_FEET_RAW, SINMDM_METHOD_ANCESTRAL, 0.0};
  EXPECT(SINMDM_INVALID_ARGUMENT, sinmdm_generate(model, &no_samples, 10, &unused));
  SinmdmSampling bad_feet = {1, 1, 2, 7, SINMDM_METHOD_ANCESTRAL, 0.0};
  EXPECT(SINMDM_INVALID_ARGUMENT, sinmdm_generate(model, &bad_feet, 10, &unused));
  SinmdmSampling bad_method = {1, 1, 2, SINMDM_FEET_RAW, 9, 0.0};
  EXPECT(SINMDM_INVALID_ARGUMENT, sinmdm_generate(model, &bad_method, 10, &unused));
  SinmdmSampling bad_eta = {1, 1, 2, SINMDM_FEET_RAW, SINMDM_METHOD_DDIM, 3.0};
  EXPECT(SINMDM_INVALID_ARGUMENT, sinmdm_generate(model, &bad_eta, 10, &unused));
  SinmdmSampling too_many_steps = {1, 1, 100000, SINMDM_FEET_RAW, SINMDM_METHOD_ANCESTRAL, 0.0};
  EXPECT(SINMDM_INVALID_ARGUMENT, sinmdm_generate(model, &too_many_steps, 10, &unused));
  SinmdmSpan past_end[1] = {{30, 50}};
  EXPECT(SINMDM_INVALID_ARGUMENT, sinmdm_inbetween(model, &once, &reference, past_end, 1, 5, &unused));
  EXPECT(SINMDM_NULL_ARGUMENT, sinmdm_inbetween(model, &once, &reference, NULL, 1, 5, &unused));
  EXPECT(SINMDM_NULL_ARGUMENT, sinmdm_inbetween(model, &once, NULL, keep, 2, 5, &unused));
  {
    size_t ref_beats[3] = {8, 20, 32}, song[4] = {5, 17, 29, 41}, late[2] = {5, 60};
    SinmdmDance bad = {ref_beats, 3, song, 4, 50, 0, 3, 7, SINMDM_DANCE_LEVEL_AUTO, 1};
    EXPECT(SINMDM_INVALID_ARGUMENT, sinmdm_dance(model, &once, &reference, &bad, &unused));
    bad.order = SINMDM_DANCE_ORDER_REFERENCE;
    bad.level = 9;
    EXPECT(SINMDM_INVALID_ARGUMENT, sinmdm_dance(model, &once, &reference, &bad, &unused));
    bad.level = SINMDM_DANCE_LEVEL_AUTO;
    bad.keep_root = 2;
    EXPECT(SINMDM_INVALID_ARGUMENT, sinmdm_dance(model, &once, &reference, &bad, &unused));
    bad.keep_root = 1;
    bad.music_beats = late;
    bad.music_beat_count = 2;
    EXPECT(SINMDM_INVALID_ARGUMENT, sinmdm_dance(model, &once, &reference, &bad, &unused));
    bad.music_beats = NULL;
    EXPECT(SINMDM_NULL_ARGUMENT, sinmdm_dance(model, &once, &reference, &bad, &unused));
    bad.music_beats = song;
    bad.music_beat_count = (size_t)SINMDM_MAX_SAMPLE_FRAMES + 1;
    EXPECT(SINMDM_INVALID_ARGUMENT, sinmdm_dance(model, &once, &reference, &bad, &unused));
    EXPECT(SINMDM_NULL_ARGUMENT, sinmdm_dance(model, &once, &reference, NULL, &unused));
  }
  SinmdmPoses no_rotations = {40, sample0.root, NULL, NULL};
  EXPECT(SINMDM_NULL_ARGUMENT, sinmdm_expand(model, &once, &no_rotations, 5, 5, 3, &unused));
  SinmdmPoses zero_frames = {0, sample0.root, sample0.rot, NULL};
  EXPECT(SINMDM_INVALID_ARGUMENT, sinmdm_expand(model, &once, &zero_frames, 5, 5, 3, &unused));
  Poses broken = poses_alloc(40, joints); /* all-zero quaternions */
  SinmdmPoses broken_in = input_of(&broken);
  EXPECT(SINMDM_INVALID_ARGUMENT, sinmdm_harmonize(model, &once, &broken_in, 2, 0.02, &unused));
  EXPECT(SINMDM_INVALID_ARGUMENT, sinmdm_harmonize(model, &once, &reference, 2, 5.0, &unused));
  size_t bad_joint[1] = {100000};
  EXPECT(SINMDM_INVALID_ARGUMENT,
         sinmdm_compose(model, &once, &reference, bad_joint, 1, 0, NULL, 0, 5, &unused));
  SinmdmStreamOptions bad_compose = {1, 2, 30, SINMDM_FEET_RAW, bad_joint, 1, 0, SINMDM_METHOD_ANCESTRAL, 0.0};
  SinmdmStream *not_made = NULL;
  EXPECT(SINMDM_INVALID_ARGUMENT, sinmdm_stream_new(model, &bad_compose, &not_made));
  EXPECT(SINMDM_INVALID_ARGUMENT, sinmdm_model_joint_name(model, 100000, NULL, 0, &needed));
  /* Sizes at the edge of size_t: refused, never wrapped, never a caught panic. */
  EXPECT(SINMDM_INVALID_ARGUMENT, sinmdm_expand(model, &once, &reference, SIZE_MAX, 5, 3, &unused));
  EXPECT(SINMDM_INVALID_ARGUMENT, sinmdm_expand(model, &once, &reference, 5, SIZE_MAX, 3, &unused));
  EXPECT(SINMDM_INVALID_ARGUMENT, sinmdm_expand(model, &once, &reference, SIZE_MAX - 29, 0, 3, &unused));
  EXPECT(SINMDM_INVALID_ARGUMENT, sinmdm_expand(model, &once, &reference, 5, 5, SIZE_MAX, &unused));
  EXPECT(SINMDM_INVALID_ARGUMENT, sinmdm_inbetween(model, &once, &reference, keep, 2, SIZE_MAX, &unused));
  EXPECT(SINMDM_INVALID_ARGUMENT, sinmdm_inbetween(model, &once, &reference, keep, SIZE_MAX, 5, &unused));
  EXPECT(SINMDM_INVALID_ARGUMENT, sinmdm_compose(model, &once, &reference, bad_joint, SIZE_MAX, 0, NULL, 0, 5, &unused));
  EXPECT(SINMDM_INVALID_ARGUMENT, sinmdm_stream_next(stream, model, SIZE_MAX, &ba));
  EXPECT(SINMDM_INVALID_ARGUMENT, sinmdm_harmonize(model, &once, &reference, 0, 0.5, &unused));
  EXPECT(SINMDM_INVALID_ARGUMENT, sinmdm_harmonize(model, &once, &reference, 2, NAN, &unused));
  EXPECT(SINMDM_INVALID_ARGUMENT, sinmdm_model_open(argv[1], UINT32_MAX, &none));
  EXPECT(SINMDM_INVALID_ARGUMENT, sinmdm_model_open_bytes(junk, SIZE_MAX, 1, &none));
  EXPECT(SINMDM_INVALID_ARGUMENT, sinmdm_stream_supply(stream, model, &reference));
  /* *out is NULL after a failure, not left as it was. */
  SinmdmResult *stale = (SinmdmResult *)&checks;
  EXPECT(SINMDM_INVALID_ARGUMENT, sinmdm_generate(model, &sampling, 0, &stale));
  checks++;
  if (stale != NULL) {
    fprintf(stderr, "a failed call left *out as it was\n");
    failures++;
  }
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
  EXPECT(SINMDM_INVALID_ARGUMENT, sinmdm_stream_new(model, &tiny_blocks, &no_stream));
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
  checks++;
  if (sinmdm_live_handles() != 0) {
    fprintf(stderr, "%zu handles alive after every free\n", sinmdm_live_handles());
    failures++;
  }
  if (failures > 0) {
    fprintf(stderr, "%d of %d bad-argument checks failed\n", failures, checks);
    return 1;
  }
  printf("bad arguments: %d checks\n", checks);
  return 0;
}
