#version 450
#extension GL_GOOGLE_include_directive : require
// The sharpness data of the next level of sharp fragment meshes, uniform creasing (see refine.glsl).
#define SHARP 1
#define DATA 1
#define CHAIKIN 0
#include "refine.glsl"
