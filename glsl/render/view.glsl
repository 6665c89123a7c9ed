// The camera of a rendered picture (`src/render/renderer.rs`, `ViewBlock`): scene
// coordinates are relative to the scene's origin (its bounding-box centre), so f32 keeps
// the precision of large coordinates.
layout(set = 0, binding = 0) uniform ViewBlock {
    mat4 proj;       // eye space to Vulkan clip space (y down, depth 0..1)
    mat4 view;       // scene to eye space
    vec4 viewport;   // width, height (pixels), line depth bias (fraction of eye distance), unused
} u;
