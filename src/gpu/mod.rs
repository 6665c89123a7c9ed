//! The texture-era GPU machinery, written once (SPEC §0): device and validation,
//! memory, textures and render targets, pipelines from reflected SPIR-V, draw passes
//! (full-target quad, points, triangles, logic-op XOR), ping-pong, reduction, readback;
//! the pipeline cache kept between runs.
//! Every `vk::` call of texgeo lives under this module; algorithms only see the types
//! re-exported here.

mod context;
mod error;
mod memory;
mod pass;
mod pipeline;
pub mod pipeline_cache;
mod present;
mod reduce;
mod scatter;
mod texture;
mod timer;
mod validation;
mod xor;

pub use context::{Context, ContextOptions, DeviceChoice, DeviceInfo, MASKABLE_FEATURES, list_devices};
pub use error::{GpuError, Result};
pub use memory::Buffer;
pub use memory::{Pod, as_bytes, from_bytes};
pub use pass::{Attachment, Load, PingPong, Recorder, Rect, RenderScope, Targets};
pub use pipeline::{Blend, DepthTest, Pipeline, PipelineDesc, Raster, Topology};
pub use present::{Presented, Surface, Swapchain};
pub use reduce::{MAX_LAYERS, Reducer, reduce_sum};
pub use scatter::{Datum, Scatter};
pub use texture::{TexFormat, Texture};
pub use timer::Timestamps;
pub use validation::installed as validation_layer_installed;
pub use xor::XorRaster;

/// A compiled shader embedded in the binary (see `build.rs`).
pub struct Shader {
    /// Source path, e.g. `glsl/gpu/reduce.frag` (used in error messages).
    pub path: &'static str,
    pub spirv: &'static [u8],
}

/// Every shader under `glsl/`, compiled at build time.
pub mod shaders {
    include!(concat!(env!("OUT_DIR"), "/shaders.rs"));
}
