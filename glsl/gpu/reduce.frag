#version 450
// Alg. 4-3 "accum": each output texel is the sum of a 2x2 block of the input.
// Texels outside the input's valid size count as zero, which pads any size up to
// the next power of two without copying.
layout(set = 0, binding = 0) uniform sampler2D src;
layout(push_constant) uniform Params {
    ivec2 src_size;
} pc;
layout(location = 0) out vec4 sum;

void main() {
    ivec2 o = ivec2(gl_FragCoord.xy) * 2;
    vec4 s = vec4(0.0);
    for (int dy = 0; dy < 2; ++dy) {
        for (int dx = 0; dx < 2; ++dx) {
            ivec2 p = o + ivec2(dx, dy);
            if (all(lessThan(p, pc.src_size))) {
                s += texelFetch(src, p, 0);
            }
        }
    }
    sum = s;
}
