#version 450
#extension GL_GOOGLE_include_directive : require
// One Catmull-Clark level of every fragment mesh: positions, with OpenSubdiv's sharp
// rules and Chaikin creasing (see refine.glsl).
#define SHARP 1
#define DATA 0
#define CHAIKIN 1
#include "refine.glsl"
