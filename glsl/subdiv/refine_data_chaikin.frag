#version 450
#extension GL_GOOGLE_include_directive : require
// The sharpness data of the next level of sharp fragment meshes, Chaikin creasing (see refine.glsl).
#define SHARP 1
#define DATA 1
#define CHAIKIN 1
#include "refine.glsl"
