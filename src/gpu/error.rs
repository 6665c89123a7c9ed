use std::sync::{Mutex, MutexGuard};

use ash::vk;

pub type Result<T, E = GpuError> = std::result::Result<T, E>;

/// GPU failures. Messages include their cause's text and expose no `source`, so an error
/// chain prints each cause once.
#[derive(Debug, thiserror::Error)]
pub enum GpuError {
    #[error("cannot load the Vulkan library (libvulkan.so.1): {0}; run tools/setup")]
    Loading(ash::LoadingError),
    #[error("Vulkan call {call} failed: {result}")]
    Vk { call: &'static str, result: vk::Result },
    #[error("no usable Vulkan device: {0}")]
    NoDevice(String),
    #[error("{0}")]
    Unsupported(String),
    #[error("GPU memory: {0}")]
    Memory(gpu_allocator::AllocationError),
    #[error("shader {shader}: {message}")]
    Shader { shader: String, message: String },
    /// A request the caller can fix (sizes, bindings, ranges).
    #[error("{0}")]
    Usage(String),
    /// A broken invariant of texgeo's own GPU code (a bug, not bad input).
    #[error("internal GPU error (a texgeo bug): {0}")]
    Internal(&'static str),
    /// A lock of the device's shared state held by a thread that panicked (see [`lock`]).
    #[error("internal GPU error (a texgeo bug): the {0} lock was poisoned by an earlier panic")]
    Poisoned(&'static str),
    /// Memory that could not be freed (reported after the fact, from a `Drop`).
    #[error("GPU memory could not be released: {}", .0.join("; "))]
    Release(Vec<String>),
    #[error("Vulkan validation reported {} error(s):\n{}", .0.len(), .0.join("\n"))]
    Validation(Vec<String>),
}

impl GpuError {
    /// True when the failure means there is no working Vulkan driver or device here
    /// (rather than a problem with the request), so a CPU method is the way out.
    pub fn is_missing_driver(&self) -> bool {
        matches!(self, GpuError::Loading(_) | GpuError::NoDevice(_))
            || matches!(self, GpuError::Vk { result, .. } if *result == vk::Result::ERROR_INCOMPATIBLE_DRIVER
                || *result == vk::Result::ERROR_INITIALIZATION_FAILED)
    }
}

impl From<ash::LoadingError> for GpuError {
    fn from(e: ash::LoadingError) -> GpuError {
        GpuError::Loading(e)
    }
}

impl From<gpu_allocator::AllocationError> for GpuError {
    fn from(e: gpu_allocator::AllocationError) -> GpuError {
        GpuError::Memory(e)
    }
}

/// Locks one of the device's shared parts (`what`: "queue", "allocator" …); a poisoned
/// lock is the same error everywhere.
pub(crate) fn lock<'a, T>(mutex: &'a Mutex<T>, what: &'static str) -> Result<MutexGuard<'a, T>> {
    mutex.lock().map_err(|_| GpuError::Poisoned(what))
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
