use ash::vk;

pub type Result<T, E = GpuError> = std::result::Result<T, E>;

#[derive(Debug, thiserror::Error)]
pub enum GpuError {
    #[error("cannot load the Vulkan library (libvulkan.so.1): {0}; run tools/setup")]
    Loading(#[from] ash::LoadingError),
    #[error("Vulkan call {call} failed: {result}")]
    Vk { call: &'static str, result: vk::Result },
    #[error("no usable Vulkan device: {0}")]
    NoDevice(String),
    #[error("{0}")]
    Unsupported(String),
    #[error("GPU memory: {0}")]
    Memory(#[from] gpu_allocator::AllocationError),
    #[error("shader {shader}: {message}")]
    Shader { shader: String, message: String },
    #[error("{0}")]
    Usage(String),
    #[error("Vulkan validation reported {} error(s):\n{}", .0.len(), .0.join("\n"))]
    Validation(Vec<String>),
}

/// Attaches the name of the failing Vulkan call to a `vk::Result`.
pub(crate) trait VkContext<T> {
    fn vk(self, call: &'static str) -> Result<T>;
}

impl<T> VkContext<T> for std::result::Result<T, vk::Result> {
    fn vk(self, call: &'static str) -> Result<T> {
        self.map_err(|result| GpuError::Vk { call, result })
    }
}
