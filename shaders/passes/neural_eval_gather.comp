// The split query's gather pass over a flat query list (body: lib/neural_eval_gather_main.glsl).
#version 460
#include "lib/neural_eval_gather_main.glsl"
