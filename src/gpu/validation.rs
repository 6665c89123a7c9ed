//! `TEXGEO_VALIDATION=1`: the Khronos validation layer with synchronization validation.
//! Every error it reports is collected; the next submission returns it as
//! `GpuError::Validation`, and a context dropped with unreported errors panics, so a
//! test cannot pass while the layer complains (lavapipe often computes the right answer
//! despite a missing barrier, so wrong output alone would not catch it).

use std::ffi::CStr;
use std::sync::Mutex;

use ash::vk;

pub(crate) const LAYER: &CStr = c"VK_LAYER_KHRONOS_validation";

/// Whether the environment asks for validation.
pub(crate) fn requested() -> bool {
    std::env::var("TEXGEO_VALIDATION").is_ok_and(|v| !v.is_empty() && v != "0")
}

/// Whether the Khronos validation layer is installed (the Vulkan loader lists it).
pub fn installed() -> bool {
    // SAFETY: loading libvulkan; a failure means no layer either.
    let Ok(entry) = (unsafe { ash::Entry::load() }) else { return false };
    // SAFETY: plain enumeration.
    unsafe { entry.enumerate_instance_layer_properties() }
        .is_ok_and(|layers| layers.iter().any(|l| l.layer_name_as_c_str().is_ok_and(|n| n == LAYER)))
}

#[derive(Default)]
pub(crate) struct Log {
    errors: Mutex<Vec<String>>,
}

impl Log {
    /// Errors logged since the last call.
    pub fn take(&self) -> Vec<String> {
        self.errors.lock().map(|mut e| std::mem::take(&mut *e)).unwrap_or_default()
    }

    fn push(&self, message: String) {
        if let Ok(mut e) = self.errors.lock() {
            e.push(message);
        }
    }
}

/// The messenger callback; `user_data` is the `Log` owned (boxed) by the context.
pub(crate) unsafe extern "system" fn callback(
    severity: vk::DebugUtilsMessageSeverityFlagsEXT,
    _types: vk::DebugUtilsMessageTypeFlagsEXT,
    data: *const vk::DebugUtilsMessengerCallbackDataEXT<'_>,
    user_data: *mut std::ffi::c_void,
) -> vk::Bool32 {
    if severity.contains(vk::DebugUtilsMessageSeverityFlagsEXT::ERROR)
        && !data.is_null()
        && !user_data.is_null()
    {
        // SAFETY: the layer passes valid callback data; user_data is the context's boxed Log,
        // which outlives the messenger.
        let (data, log) = unsafe { (&*data, &*(user_data as *const Log)) };
        let message = if data.p_message.is_null() {
            "(no message)".to_string()
        } else {
            // SAFETY: non-null p_message is a NUL-terminated string per the spec.
            unsafe { CStr::from_ptr(data.p_message) }.to_string_lossy().into_owned()
        };
        log.push(message);
    }
    vk::FALSE
}
