/* The smallest engine: open a model, make 4 seconds of motion, read its poses, write a BVH.
 *
 *   cc generate.c -I capi/include -L target/release -lsinmdm_c -o generate
 *   ./generate onnx-models/human_walk_cmu.onnx walk.bvh
 *
 * onnxruntime is found through ORT_DYLIB_PATH (or call sinmdm_load_onnxruntime with the copy
 * your engine ships). */
#include <stdio.h>
#include <stdlib.h>

#include "sinmdm.h"

static int fail(const char *what) {
  fprintf(stderr, "%s: %s\n", what, sinmdm_last_error());
  return 1;
}

int main(int argc, char **argv) {
  if (argc != 3) {
    fprintf(stderr, "usage: generate MODEL.onnx OUT.bvh\n");
    return 2;
  }
  SinmdmModel *model = NULL;
  if (sinmdm_model_open(argv[1], 0, &model) != SINMDM_OK) return fail("open");
  SinmdmModelInfo info;
  sinmdm_model_info(model, &info);
  size_t frames = (size_t)(4 * info.fps);

  SinmdmSampling sampling = {.seed = 1, .count = 1, .steps = SINMDM_DEFAULT_STEPS,
                             .feet = SINMDM_FEET_PLANTED};
  SinmdmResult *result = NULL;
  if (sinmdm_generate(model, &sampling, frames, &result) != SINMDM_OK) return fail("generate");

  /* Caller-owned buffers: root position, then x,y,z,w per joint, then offsets per joint. */
  float *root = malloc(3 * frames * sizeof(float));
  float *rotations = malloc(4 * info.joints * frames * sizeof(float));
  float *translations = malloc(3 * info.joints * frames * sizeof(float));
  SinmdmPoseBuffers buffers = {root, 3 * frames, rotations, 4 * info.joints * frames,
                               translations, 3 * info.joints * frames};
  if (sinmdm_result_poses(result, 0, &buffers) != SINMDM_OK) return fail("poses");
  printf("%zu frames of %zu joints; the root ends at (%.1f, %.1f, %.1f)\n", frames, info.joints,
         root[3 * (frames - 1)], root[3 * (frames - 1) + 1], root[3 * (frames - 1) + 2]);

  SinmdmPoses poses = {frames, root, rotations, translations};
  if (sinmdm_write_bvh(model, &poses, argv[2]) != SINMDM_OK) return fail("write");
  printf("wrote %s\n", argv[2]);

  free(root);
  free(rotations);
  free(translations);
  sinmdm_result_free(result);
  sinmdm_model_free(model);
  return 0;
}
