// Push constants shared by xor.vert and xor.frag.
layout(push_constant) uniform Params {
    vec2 size;   // target size in texels
    uint value;  // bits XORed into every covered texel
} pc;
