#version 450
#extension GL_GOOGLE_include_directive : require
// One Catmull-Clark level of fragment meshes without sharpness data: the smooth masks
// only (see refine.glsl).
#define SHARP 0
#define DATA 0
#define CHAIKIN 0
#include "refine.glsl"
