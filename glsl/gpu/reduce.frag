#version 450
// Alg. 4-3 "accum": each output texel is the sum of a 2x2 block of the input (2x1 or
// 1x2 once one side of a tile is done), for up to 8 layers at once (one attachment
// per layer). Texels outside the input's valid size count as zero, which pads any size
// to the next power of two without copying.
layout(set = 0, binding = 0) uniform sampler2DArray src;
layout(push_constant) uniform Params {
    ivec2 src_size;
    ivec2 step;    // block size: 1 or 2 per axis
    int layers;    // layers to reduce (attachments bound)
} pc;
layout(location = 0) out vec4 s0;
layout(location = 1) out vec4 s1;
layout(location = 2) out vec4 s2;
layout(location = 3) out vec4 s3;
layout(location = 4) out vec4 s4;
layout(location = 5) out vec4 s5;
layout(location = 6) out vec4 s6;
layout(location = 7) out vec4 s7;

vec4 block(int layer) {
    ivec2 o = ivec2(gl_FragCoord.xy) * pc.step;
    vec4 s = vec4(0.0);
    for (int dy = 0; dy < pc.step.y; ++dy) {
        for (int dx = 0; dx < pc.step.x; ++dx) {
            ivec2 p = o + ivec2(dx, dy);
            if (all(lessThan(p, pc.src_size))) {
                s += texelFetch(src, ivec3(p, layer), 0);
            }
        }
    }
    return s;
}

void main() {
    s0 = block(0);
    if (pc.layers > 1) s1 = block(1);
    if (pc.layers > 2) s2 = block(2);
    if (pc.layers > 3) s3 = block(3);
    if (pc.layers > 4) s4 = block(4);
    if (pc.layers > 5) s5 = block(5);
    if (pc.layers > 6) s6 = block(6);
    if (pc.layers > 7) s7 = block(7);
}
