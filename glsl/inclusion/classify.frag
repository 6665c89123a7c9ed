#version 450
// Alg. 4-2, phase 1: write the values summed by the point-vertex to its texel, one
// attachment per four query points.
layout(location = 0) flat in vec4 v[8];
layout(location = 0) out vec4 o0;
layout(location = 1) out vec4 o1;
layout(location = 2) out vec4 o2;
layout(location = 3) out vec4 o3;
layout(location = 4) out vec4 o4;
layout(location = 5) out vec4 o5;
layout(location = 6) out vec4 o6;
layout(location = 7) out vec4 o7;
void main() {
    o0 = v[0]; o1 = v[1]; o2 = v[2]; o3 = v[3];
    o4 = v[4]; o5 = v[5]; o6 = v[6]; o7 = v[7];
}
