//! Instance, device choice, queue, allocator and one-shot submission.
//!
//! `Context` is a cheap handle (an `Arc`) to the device; every resource keeps one, so
//! the device outlives whatever was made from it and destruction order is written once,
//! in `Device::drop`.

use std::ffi::CStr;
use std::mem::ManuallyDrop;
use std::sync::{Arc, Mutex};

use ash::vk;
use gpu_allocator::vulkan::{Allocator, AllocatorCreateDesc};

use super::error::{GpuError, Result, VkContext};
use super::pass::Recorder;
use super::validation;

/// Which physical device to use.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub enum DeviceChoice {
    /// The first discrete GPU, else integrated, else virtual, else a CPU device (lavapipe).
    #[default]
    Auto,
    /// Index in the order `texgeo info --all` lists devices.
    Index(usize),
    /// Case-insensitive part of the device or driver name; `lavapipe` also matches llvmpipe.
    Name(String),
}

impl DeviceChoice {
    /// `NAME|INDEX`, as given to `--device` or `TEXGEO_DEVICE`.
    pub fn parse(s: &str) -> DeviceChoice {
        match s.trim() {
            "" | "auto" => DeviceChoice::Auto,
            t => t.parse().map(DeviceChoice::Index).unwrap_or_else(|_| DeviceChoice::Name(t.to_string())),
        }
    }

    /// `explicit` if given, else `TEXGEO_DEVICE`, else `Auto`.
    pub fn from_env_or(explicit: Option<&str>) -> DeviceChoice {
        match explicit {
            Some(s) => DeviceChoice::parse(s),
            None => std::env::var("TEXGEO_DEVICE").map(|s| DeviceChoice::parse(&s)).unwrap_or_default(),
        }
    }
}

#[derive(Clone, Debug, Default)]
pub struct ContextOptions {
    pub device: DeviceChoice,
    /// `None`: follow `TEXGEO_VALIDATION`.
    pub validation: Option<bool>,
}

/// What `texgeo info` prints (`--json`: these fields) and benchmark reports quote.
#[derive(Clone, Debug, serde::Serialize)]
pub struct DeviceInfo {
    pub index: usize,
    pub name: String,
    pub kind: String,
    pub driver: String,
    pub driver_info: String,
    pub api_version: String,
    pub max_image_2d: u32,
    pub max_image_3d: u32,
    pub max_array_layers: u32,
    pub max_color_attachments: u32,
    pub max_push_constants: u32,
    pub max_vertex_attributes: u32,
    /// Fixed-point bits of sub-pixel precision of rasterized vertex positions.
    pub sub_pixel_bits: u32,
    /// Largest viewport width and height.
    pub max_viewport: [u32; 2],
    pub logic_op: bool,
    pub float64: bool,
    pub timestamps: bool,
    pub timestamp_period_ns: f32,
    pub push_descriptor: bool,
    pub vulkan13: bool,
    /// Sample counts offered for colour and depth render targets, as a bit mask
    /// (bit n set: 2^n samples per pixel).
    pub colour_samples: u32,
    pub depth_samples: u32,
    /// Features turned off by `TEXGEO_MASK_FEATURES` although the device has them.
    pub masked: Vec<String>,
}

/// Features `TEXGEO_MASK_FEATURES` (comma-separated) can hide from texgeo, so a run shows
/// what a device without them gets: the commands that need one refuse with a clear error,
/// reports mark the rows that need one as not measurable.
pub const MASKABLE_FEATURES: [&str; 3] = ["logic_op", "timestamps", "float64"];

/// The features `TEXGEO_MASK_FEATURES` asks to hide; an unknown name is an error.
fn masked_features() -> Result<Vec<String>> {
    let Ok(list) = std::env::var("TEXGEO_MASK_FEATURES") else { return Ok(Vec::new()) };
    let mut out = Vec::new();
    for name in list.split(',').map(str::trim).filter(|n| !n.is_empty()) {
        if !MASKABLE_FEATURES.contains(&name) {
            return Err(GpuError::Usage(format!(
                "TEXGEO_MASK_FEATURES: unknown feature '{name}' (known: {})",
                MASKABLE_FEATURES.join(", ")
            )));
        }
        if !out.iter().any(|m| m == name) {
            out.push(name.to_string());
        }
    }
    Ok(out)
}

impl DeviceInfo {
    /// Turns off the features in `masked` (names from [`MASKABLE_FEATURES`]).
    fn mask(&mut self, masked: &[String]) {
        for name in masked {
            let flag = match name.as_str() {
                "logic_op" => &mut self.logic_op,
                "timestamps" => &mut self.timestamps,
                "float64" => &mut self.float64,
                _ => continue,
            };
            if std::mem::replace(flag, false) {
                self.masked.push(name.clone());
            }
        }
    }

    /// "llvmpipe (LLVM 15.0.6, 256 bits) [llvmpipe, Mesa 22.3.6]".
    pub fn label(&self) -> String {
        format!("{} [{} {}]", self.name, self.driver, self.driver_info)
    }
}

pub(crate) struct Device {
    pub physical: vk::PhysicalDevice,
    pub raw: ash::Device,
    pub push_descriptor: ash::khr::push_descriptor::Device,
    pub queue: Mutex<vk::Queue>,
    pub command_pool: Mutex<vk::CommandPool>,
    pub allocator: ManuallyDrop<Mutex<Allocator>>,
    /// Failures seen where they cannot be returned (freeing memory in `Drop`): reported by
    /// the next [`Device::check_validation`] and at teardown.
    problems: Mutex<Vec<String>>,
    /// NEAREST, clamp-to-edge: the texture era reads texels with `texelFetch` only.
    pub sampler: vk::Sampler,
    /// Kept between runs in the user's cache folder ([`super::pipeline_cache`]).
    pub pipeline_cache: Mutex<super::pipeline_cache::PipelineCache>,
    pub info: DeviceInfo,
    /// Last, so it is destroyed after everything made from it (fields drop after
    /// `Device::drop`, in order).
    pub instance: Instance,
}

impl Drop for Device {
    fn drop(&mut self) {
        // SAFETY: every resource holds an Arc<Device>, so none is alive here; wait for
        // the queue, then destroy in reverse creation order (allocator before device); the
        // instance goes last, as the last field.
        let leaks = self.leaks();
        unsafe {
            let _ = self.raw.device_wait_idle();
            if let Ok(cache) = self.pipeline_cache.get_mut() {
                cache.save_and_destroy(&self.raw);
            }
            self.raw.destroy_sampler(self.sampler, None);
            if let Ok(pool) = self.command_pool.get_mut() {
                self.raw.destroy_command_pool(*pool, None);
            }
            ManuallyDrop::drop(&mut self.allocator);
            self.raw.destroy_device(None);
        }
        if let Some(log) = &self.instance.log {
            let errors = log.take();
            if !errors.is_empty() {
                crate::note!("Vulkan validation errors at teardown:\n{}", errors.join("\n"));
                if !std::thread::panicking() {
                    panic!("{} Vulkan validation error(s) were never reported", errors.len());
                }
            }
        }
        // Leaks and failed frees are bugs in texgeo: loud under validation (tests), a
        // warning otherwise (gpu-allocator itself would only log them).
        if !leaks.is_empty() {
            crate::note!("texgeo: GPU memory problems at teardown:\n{}", leaks.join("\n"));
            if self.instance.log.is_some() && !std::thread::panicking() {
                panic!("{} GPU memory problem(s) at teardown: {}", leaks.len(), leaks.join("; "));
            }
        }
    }
}

impl Device {
    /// Validation errors and memory problems since the last check, as an error.
    pub fn check_validation(&self) -> Result<()> {
        let errors = self.instance.log.as_ref().map(|log| log.take()).unwrap_or_default();
        if !errors.is_empty() {
            return Err(GpuError::Validation(errors));
        }
        let problems = self.problems.lock().map(|mut p| std::mem::take(&mut *p)).unwrap_or_default();
        if problems.is_empty() { Ok(()) } else { Err(GpuError::Release(problems)) }
    }

    /// Records a failure that happened where it could not be returned (in a `Drop`).
    pub fn report_problem(&self, problem: String) {
        match self.problems.lock() {
            Ok(mut p) => p.push(problem),
            Err(_) => crate::note!("texgeo: GPU problem: {problem}"),
        }
    }

    /// Frees `allocation` (of the resource `what`), recording a failure instead of ignoring it.
    pub fn free(&self, allocation: gpu_allocator::vulkan::Allocation, what: &str) {
        let freed = match self.allocator.lock() {
            Ok(mut a) => a.free(allocation).map_err(|e| e.to_string()),
            Err(_) => Err("the allocator lock is poisoned".into()),
        };
        if let Err(e) = freed {
            self.report_problem(format!("freeing the memory of {what}: {e}"));
        }
    }

    /// Allocations still alive and failures not yet reported: at teardown, each is a leak
    /// or a lost error.
    fn leaks(&self) -> Vec<String> {
        let mut out: Vec<String> =
            self.problems.lock().map(|mut p| std::mem::take(&mut *p)).unwrap_or_default();
        if let Ok(a) = self.allocator.lock() {
            let report = a.generate_report();
            out.extend(
                report
                    .allocations
                    .iter()
                    .map(|r| format!("leaked GPU allocation '{}' ({} bytes)", r.name, r.size)),
            );
        }
        out
    }
}

/// A Vulkan device ready for texture-era GPGPU work.
#[derive(Clone)]
pub struct Context {
    pub(crate) dev: Arc<Device>,
}

/// The Vulkan instance and, with validation, its debug messenger and the log it fills.
pub(crate) struct Instance {
    entry: ash::Entry,
    pub raw: ash::Instance,
    debug: Option<(ash::ext::debug_utils::Instance, vk::DebugUtilsMessengerEXT)>,
    log: Option<Box<validation::Log>>,
}

impl Instance {
    fn new(validate: bool, extra_extensions: &[*const std::ffi::c_char]) -> Result<Instance> {
        // SAFETY: loading libvulkan; failure is reported, not assumed.
        let entry = unsafe { ash::Entry::load()? };
        let app = vk::ApplicationInfo::default()
            .application_name(c"texgeo")
            .engine_name(c"texgeo")
            .api_version(vk::API_VERSION_1_3);
        let mut layers = Vec::new();
        let mut extensions = extra_extensions.to_vec();
        if validate {
            // SAFETY: plain enumeration.
            let available = unsafe { entry.enumerate_instance_layer_properties() }
                .vk("vkEnumerateInstanceLayerProperties")?;
            let found =
                available.iter().any(|l| l.layer_name_as_c_str().is_ok_and(|n| n == validation::LAYER));
            if !found {
                return Err(GpuError::Unsupported(
                    "TEXGEO_VALIDATION is set but VK_LAYER_KHRONOS_validation is not installed; run tools/setup"
                        .into(),
                ));
            }
            layers.push(validation::LAYER.as_ptr());
            extensions.push(ash::ext::debug_utils::NAME.as_ptr());
            extensions.push(ash::ext::validation_features::NAME.as_ptr());
        }
        let enables = [vk::ValidationFeatureEnableEXT::SYNCHRONIZATION_VALIDATION];
        let mut features = vk::ValidationFeaturesEXT::default().enabled_validation_features(&enables);
        let mut info = vk::InstanceCreateInfo::default()
            .application_info(&app)
            .enabled_layer_names(&layers)
            .enabled_extension_names(&extensions);
        if validate {
            info = info.push_next(&mut features);
        }
        // SAFETY: all pointers in `info` outlive the call.
        let instance = unsafe { entry.create_instance(&info, None) }.vk("vkCreateInstance")?;
        let mut this = Instance { entry, raw: instance, debug: None, log: None };
        if validate {
            let log = Box::new(validation::Log::default());
            let loader = ash::ext::debug_utils::Instance::new(&this.entry, &this.raw);
            let messenger_info = vk::DebugUtilsMessengerCreateInfoEXT::default()
                .message_severity(
                    vk::DebugUtilsMessageSeverityFlagsEXT::ERROR
                        | vk::DebugUtilsMessageSeverityFlagsEXT::WARNING,
                )
                .message_type(
                    vk::DebugUtilsMessageTypeFlagsEXT::GENERAL
                        | vk::DebugUtilsMessageTypeFlagsEXT::VALIDATION
                        | vk::DebugUtilsMessageTypeFlagsEXT::PERFORMANCE,
                )
                .pfn_user_callback(Some(validation::callback))
                .user_data(&*log as *const validation::Log as *mut std::ffi::c_void);
            // SAFETY: the boxed log outlives the messenger (destroyed first in Device::drop).
            let messenger = unsafe { loader.create_debug_utils_messenger(&messenger_info, None) }
                .vk("vkCreateDebugUtilsMessengerEXT")?;
            this.debug = Some((loader, messenger));
            this.log = Some(log);
        }
        Ok(this)
    }
}

impl Drop for Instance {
    fn drop(&mut self) {
        // SAFETY: whatever was made from this instance (a device, a surface) is gone: the
        // device owns the instance as its last field, a pending surface borrows it.
        unsafe {
            if let Some((loader, messenger)) = self.debug.take() {
                loader.destroy_debug_utils_messenger(messenger, None);
            }
            self.raw.destroy_instance(None);
        }
    }
}

fn describe(instance: &ash::Instance, index: usize, physical: vk::PhysicalDevice) -> DeviceInfo {
    let mut driver = vk::PhysicalDeviceDriverProperties::default();
    let mut props2 = vk::PhysicalDeviceProperties2::default().push_next(&mut driver);
    let mut f13 = vk::PhysicalDeviceVulkan13Features::default();
    let mut features2 = vk::PhysicalDeviceFeatures2::default().push_next(&mut f13);
    // SAFETY: valid physical device from this instance; the chains live on the stack.
    let (exts, props, features) = unsafe {
        instance.get_physical_device_properties2(physical, &mut props2);
        instance.get_physical_device_features2(physical, &mut features2);
        (
            instance.enumerate_device_extension_properties(physical).unwrap_or_default(),
            props2.properties,
            features2.features,
        )
    };
    let cstr = |s: &[std::ffi::c_char]| {
        // SAFETY: Vulkan fills these fixed arrays with NUL-terminated strings.
        unsafe { CStr::from_ptr(s.as_ptr()) }.to_string_lossy().into_owned()
    };
    let has_ext = |name: &CStr| exts.iter().any(|e| e.extension_name_as_c_str().is_ok_and(|n| n == name));
    let v = props.api_version;
    let limits = props.limits;
    DeviceInfo {
        index,
        name: cstr(&props.device_name),
        kind: format!("{:?}", props.device_type).to_lowercase().replace('_', " "),
        driver: cstr(&driver.driver_name),
        driver_info: cstr(&driver.driver_info),
        api_version: format!(
            "{}.{}.{}",
            vk::api_version_major(v),
            vk::api_version_minor(v),
            vk::api_version_patch(v)
        ),
        max_image_2d: limits.max_image_dimension2_d,
        max_image_3d: limits.max_image_dimension3_d,
        max_array_layers: limits.max_image_array_layers,
        max_color_attachments: limits.max_color_attachments,
        max_push_constants: limits.max_push_constants_size,
        max_vertex_attributes: limits.max_vertex_input_attributes,
        sub_pixel_bits: limits.sub_pixel_precision_bits,
        max_viewport: limits.max_viewport_dimensions,
        logic_op: features.logic_op == vk::TRUE,
        float64: features.shader_float64 == vk::TRUE,
        timestamps: limits.timestamp_compute_and_graphics == vk::TRUE,
        timestamp_period_ns: limits.timestamp_period,
        push_descriptor: has_ext(ash::khr::push_descriptor::NAME),
        vulkan13: vk::api_version_minor(v) >= 3
            && f13.dynamic_rendering == vk::TRUE
            && f13.synchronization2 == vk::TRUE,
        colour_samples: limits.framebuffer_color_sample_counts.as_raw(),
        depth_samples: limits.framebuffer_depth_sample_counts.as_raw(),
        masked: Vec::new(),
    }
}

fn is_lavapipe(info: &DeviceInfo) -> bool {
    info.name.to_lowercase().contains("llvmpipe") || info.driver.to_lowercase().contains("llvmpipe")
}

/// Every Vulkan device the loader sees, in index order.
pub fn list_devices() -> Result<Vec<DeviceInfo>> {
    let inst = Instance::new(false, &[])?;
    // SAFETY: plain enumeration on a live instance.
    let physicals = unsafe { inst.raw.enumerate_physical_devices() }.vk("vkEnumeratePhysicalDevices")?;
    let masked = masked_features()?;
    Ok(physicals
        .iter()
        .enumerate()
        .map(|(i, &p)| {
            let mut info = describe(&inst.raw, i, p);
            info.mask(&masked);
            info
        })
        .collect())
}

fn choose(instance: &ash::Instance, choice: &DeviceChoice) -> Result<(vk::PhysicalDevice, DeviceInfo)> {
    // SAFETY: plain enumeration on a live instance.
    let physicals = unsafe { instance.enumerate_physical_devices() }.vk("vkEnumeratePhysicalDevices")?;
    let all: Vec<_> = physicals.iter().enumerate().map(|(i, &p)| (p, describe(instance, i, p))).collect();
    if all.is_empty() {
        return Err(GpuError::NoDevice(
            "the Vulkan loader found no device; run tools/setup (installs lavapipe)".into(),
        ));
    }
    let names = || all.iter().map(|(_, d)| format!("{}: {}", d.index, d.name)).collect::<Vec<_>>().join(", ");
    let picked = match choice {
        DeviceChoice::Index(i) => all
            .get(*i)
            .ok_or_else(|| GpuError::NoDevice(format!("no device with index {i} (devices: {})", names())))?,
        DeviceChoice::Name(n) => {
            let n = n.to_lowercase();
            all.iter()
                .find(|(_, d)| {
                    (n == "lavapipe" && is_lavapipe(d))
                        || d.name.to_lowercase().contains(&n)
                        || d.driver.to_lowercase().contains(&n)
                })
                .ok_or_else(|| {
                    GpuError::NoDevice(format!("no device matches '{n}' (devices: {})", names()))
                })?
        }
        DeviceChoice::Auto => {
            let rank = |d: &DeviceInfo| match d.kind.as_str() {
                "discrete gpu" => 0,
                "integrated gpu" => 1,
                "virtual gpu" => 2,
                "cpu" => 3,
                _ => 4,
            };
            all.iter()
                .filter(|(_, d)| d.vulkan13 && d.push_descriptor)
                .min_by_key(|(_, d)| rank(d))
                .unwrap_or(&all[0])
        }
    };
    let (p, mut info) = picked.clone();
    info.mask(&masked_features()?);
    if !info.vulkan13 {
        return Err(GpuError::Unsupported(format!(
            "device '{}' lacks Vulkan 1.3 dynamic rendering / synchronization2 (API {})",
            info.name, info.api_version
        )));
    }
    if !info.push_descriptor {
        return Err(GpuError::Unsupported(format!("device '{}' lacks VK_KHR_push_descriptor", info.name)));
    }
    Ok((p, info))
}

/// A window surface made before the device exists; destroyed here unless handed on.
struct PendingSurface<'a> {
    inst: &'a Instance,
    loader: ash::khr::surface::Instance,
    raw: vk::SurfaceKHR,
}

impl Drop for PendingSurface<'_> {
    fn drop(&mut self) {
        if self.raw != vk::SurfaceKHR::null() {
            // SAFETY: the surface was made from this instance and nothing uses it.
            unsafe { self.loader.destroy_surface(self.raw, None) };
        }
        let _ = self.inst;
    }
}

/// The new device and its command pool and sampler while `Context::create` still runs:
/// destroyed in reverse order if a later step fails, handed on by [`Partial::keep`].
struct Partial<'a> {
    raw: &'a ash::Device,
    pool: vk::CommandPool,
    sampler: vk::Sampler,
}

impl Partial<'_> {
    fn keep(self) -> (vk::CommandPool, vk::Sampler) {
        let kept = (self.pool, self.sampler);
        // Disarmed (it owns no memory): the device goes on to live in `Device`.
        std::mem::forget(self);
        kept
    }
}

impl Drop for Partial<'_> {
    fn drop(&mut self) {
        // SAFETY: nothing uses these yet; null handles are ignored.
        unsafe {
            self.raw.destroy_sampler(self.sampler, None);
            self.raw.destroy_command_pool(self.pool, None);
            self.raw.destroy_device(None);
        }
    }
}

impl<'a> PendingSurface<'a> {
    /// The surface of `window` on `display`.
    fn new(
        inst: &'a Instance,
        display: raw_window_handle::RawDisplayHandle,
        window: raw_window_handle::RawWindowHandle,
    ) -> Result<PendingSurface<'a>> {
        // SAFETY: the handles come from a live window the caller keeps open while the
        // surface exists.
        let raw = unsafe { ash_window::create_surface(&inst.entry, &inst.raw, display, window, None) }
            .vk("vkCreate…SurfaceKHR")?;
        Ok(PendingSurface { inst, loader: ash::khr::surface::Instance::new(&inst.entry, &inst.raw), raw })
    }
}

/// The first queue family of `physical` with graphics that (with a surface) presents to it.
fn graphics_queue_family(
    inst: &Instance,
    physical: vk::PhysicalDevice,
    info: &DeviceInfo,
    surface: Option<&PendingSurface>,
) -> Result<u32> {
    // SAFETY: valid physical device.
    let families = unsafe { inst.raw.get_physical_device_queue_family_properties(physical) };
    let presents = |i: usize| match surface {
        // SAFETY: valid physical device, family index and surface.
        Some(p) => unsafe { p.loader.get_physical_device_surface_support(physical, i as u32, p.raw) }
            .unwrap_or(false),
        None => true,
    };
    let family = (0..families.len())
        .find(|&i| families[i].queue_flags.contains(vk::QueueFlags::GRAPHICS) && presents(i))
        .ok_or_else(|| {
            GpuError::NoDevice(format!(
                "device '{}' has no graphics queue{}",
                info.name,
                if surface.is_some() { " that presents to this window" } else { "" }
            ))
        })?;
    Ok(family as u32)
}

/// The logical device: one queue of `queue_family`, the features texgeo uses (logic op
/// and f64 where the device has them, dynamic rendering, synchronization2), push
/// descriptors, and the swapchain when it presents.
fn create_device(
    inst: &Instance,
    physical: vk::PhysicalDevice,
    info: &DeviceInfo,
    queue_family: u32,
    presents: bool,
) -> Result<ash::Device> {
    let priorities = [1.0];
    let queue_info =
        [vk::DeviceQueueCreateInfo::default().queue_family_index(queue_family).queue_priorities(&priorities)];
    let features = vk::PhysicalDeviceFeatures::default()
        .logic_op(info.logic_op)
        .shader_float64(info.float64)
        .independent_blend(true);
    let mut f13 =
        vk::PhysicalDeviceVulkan13Features::default().dynamic_rendering(true).synchronization2(true);
    let mut extensions = vec![ash::khr::push_descriptor::NAME.as_ptr()];
    if presents {
        extensions.push(ash::khr::swapchain::NAME.as_ptr());
    }
    let device_info = vk::DeviceCreateInfo::default()
        .queue_create_infos(&queue_info)
        .enabled_extension_names(&extensions)
        .enabled_features(&features)
        .push_next(&mut f13);
    // SAFETY: all pointers in device_info outlive the call.
    unsafe { inst.raw.create_device(physical, &device_info, None) }.vk("vkCreateDevice")
}

/// The command pool, the nearest-texel sampler and the allocator every pass of the
/// device `raw` shares; `raw` is destroyed if one of them cannot be made.
fn shared_objects(
    inst: &Instance,
    physical: vk::PhysicalDevice,
    raw: &ash::Device,
    queue_family: u32,
) -> Result<(vk::CommandPool, vk::Sampler, Allocator)> {
    let pool_info = vk::CommandPoolCreateInfo::default()
        .queue_family_index(queue_family)
        .flags(vk::CommandPoolCreateFlags::TRANSIENT | vk::CommandPoolCreateFlags::RESET_COMMAND_BUFFER);
    let sampler_info = vk::SamplerCreateInfo::default()
        .mag_filter(vk::Filter::NEAREST)
        .min_filter(vk::Filter::NEAREST)
        .mipmap_mode(vk::SamplerMipmapMode::NEAREST)
        .address_mode_u(vk::SamplerAddressMode::CLAMP_TO_EDGE)
        .address_mode_v(vk::SamplerAddressMode::CLAMP_TO_EDGE)
        .address_mode_w(vk::SamplerAddressMode::CLAMP_TO_EDGE);
    // Leaks are reported by `Device::drop` itself, loudly (gpu-allocator would only log).
    let mut debug_settings = gpu_allocator::AllocatorDebugSettings::default();
    debug_settings.log_leaks_on_shutdown = false;
    let mut partial = Partial { raw, pool: vk::CommandPool::null(), sampler: vk::Sampler::null() };
    // SAFETY: valid device and create infos; `partial` destroys what exists if a step fails.
    partial.pool = unsafe { raw.create_command_pool(&pool_info, None) }.vk("vkCreateCommandPool")?;
    // SAFETY: as above.
    partial.sampler = unsafe { raw.create_sampler(&sampler_info, None) }.vk("vkCreateSampler")?;
    let allocator = Allocator::new(&AllocatorCreateDesc {
        instance: inst.raw.clone(),
        device: raw.clone(),
        physical_device: physical,
        debug_settings,
        buffer_device_address: false,
        allocation_sizes: Default::default(),
    })?;
    let (pool, sampler) = partial.keep();
    Ok((pool, sampler, allocator))
}

impl Context {
    /// Opens the device `options` ask for (defaults: `TEXGEO_DEVICE`, `TEXGEO_VALIDATION`).
    pub fn new(options: &ContextOptions) -> Result<Context> {
        Ok(Context::create(options, None)?.0)
    }

    /// Opens a device that can also present to the window `window` of `display`
    /// (the raw handles of winit or any other windowing library): the instance gets the
    /// platform's surface extensions, the device the swapchain extension and a graphics
    /// queue that presents to the window's surface.
    pub fn for_window(
        options: &ContextOptions,
        display: raw_window_handle::RawDisplayHandle,
        window: raw_window_handle::RawWindowHandle,
    ) -> Result<(Context, super::present::Surface)> {
        let (ctx, surface) = Context::create(options, Some((display, window)))?;
        let (loader, raw) = surface.ok_or_else(|| GpuError::Usage("no surface was created".into()))?;
        Ok((ctx.clone(), super::present::Surface::new(&ctx, loader, raw)))
    }

    /// The instance (with the window's surface extensions), the window's surface, the
    /// physical device, a graphics queue family (that presents to the surface), the
    /// logical device and what every pass shares (command pool, sampler, allocator,
    /// pipeline cache); then the validation messages so far are checked.
    #[allow(clippy::type_complexity)]
    fn create(
        options: &ContextOptions,
        window: Option<(raw_window_handle::RawDisplayHandle, raw_window_handle::RawWindowHandle)>,
    ) -> Result<(Context, Option<(ash::khr::surface::Instance, vk::SurfaceKHR)>)> {
        let validate = options.validation.unwrap_or_else(validation::requested);
        let surface_extensions = match window {
            Some((display, _)) => ash_window::enumerate_required_extensions(display)
                .vk("vkEnumerateInstanceExtensionProperties (surface extensions)")?,
            None => &[],
        };
        let inst = Instance::new(validate, surface_extensions)?;
        let mut pending =
            window.map(|(display, handle)| PendingSurface::new(&inst, display, handle)).transpose()?;
        let (physical, info) = choose(&inst.raw, &options.device)?;
        let queue_family = graphics_queue_family(&inst, physical, &info, pending.as_ref())?;
        let raw = create_device(&inst, physical, &info, queue_family, pending.is_some())?;
        // SAFETY: the queue family and index exist (created above).
        let queue = unsafe { raw.get_device_queue(queue_family, 0) };
        let (command_pool, sampler, allocator) = shared_objects(&inst, physical, &raw, queue_family)?;
        let push_descriptor = ash::khr::push_descriptor::Device::new(&inst.raw, &raw);
        // SAFETY: valid physical device.
        let props = unsafe { inst.raw.get_physical_device_properties(physical) };
        let pipeline_cache =
            super::pipeline_cache::PipelineCache::open(&raw, super::pipeline_cache::Identity::of(&props));
        // The surface now outlives this function in the caller's `Surface`.
        let surface = pending.as_mut().map(|p| (p.loader.clone(), std::mem::take(&mut p.raw)));
        drop(pending);
        // The device owns the instance from here on and destroys it last.
        let dev = Device {
            physical,
            raw,
            push_descriptor,
            queue: Mutex::new(queue),
            command_pool: Mutex::new(command_pool),
            allocator: ManuallyDrop::new(Mutex::new(allocator)),
            problems: Mutex::new(Vec::new()),
            sampler,
            pipeline_cache: Mutex::new(pipeline_cache),
            info,
            instance: inst,
        };
        let ctx = Context { dev: Arc::new(dev) };
        if let Err(e) = ctx.dev.check_validation() {
            if let Some((loader, raw)) = surface {
                // SAFETY: nothing else uses the surface yet.
                unsafe { loader.destroy_surface(raw, None) };
            }
            return Err(e);
        }
        Ok((ctx, surface))
    }

    /// Default options: device from `TEXGEO_DEVICE`, validation from `TEXGEO_VALIDATION`.
    pub fn from_env() -> Result<Context> {
        Context::new(&ContextOptions::default())
    }

    pub fn info(&self) -> &DeviceInfo {
        &self.dev.info
    }

    /// Allocations gpu-allocator holds for this device right now (buffers and textures
    /// alive); a program that dropped all its resources must see 0.
    pub fn live_allocations(&self) -> usize {
        self.dev.allocator.lock().map(|a| a.generate_report().allocations.len()).unwrap_or(0)
    }

    /// Whether the validation layer is on for this context.
    pub fn validating(&self) -> bool {
        self.dev.instance.log.is_some()
    }

    /// Records commands with `record`, submits them, waits, and reports validation errors.
    /// The one-shot style of the texture era: upload, draw, read back, done.
    pub fn submit<T>(&self, record: impl FnOnce(&mut Recorder) -> Result<T>) -> Result<T> {
        self.submit_synced(None, record)
    }

    /// Like [`Context::submit`]; with `sync`, the submission waits on the first semaphore
    /// (before its transfers) and signals the second (a swapchain frame).
    pub(crate) fn submit_synced<T>(
        &self,
        sync: Option<(vk::Semaphore, vk::Semaphore)>,
        record: impl FnOnce(&mut Recorder) -> Result<T>,
    ) -> Result<T> {
        let dev = &self.dev;
        let pool = super::error::lock(&dev.command_pool, "command pool")?;
        let alloc = vk::CommandBufferAllocateInfo::default()
            .command_pool(*pool)
            .level(vk::CommandBufferLevel::PRIMARY)
            .command_buffer_count(1);
        // SAFETY: the pool is locked for the whole recording and submission.
        let cmd = unsafe { dev.raw.allocate_command_buffers(&alloc) }.vk("vkAllocateCommandBuffers")?[0];
        let result = (|| {
            let begin =
                vk::CommandBufferBeginInfo::default().flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT);
            // SAFETY: fresh command buffer.
            unsafe { dev.raw.begin_command_buffer(cmd, &begin) }.vk("vkBeginCommandBuffer")?;
            let mut recorder = Recorder::new(dev, cmd);
            let value = record(&mut recorder)?;
            // SAFETY: recording started above.
            unsafe { dev.raw.end_command_buffer(cmd) }.vk("vkEndCommandBuffer")?;
            let fence_info = vk::FenceCreateInfo::default();
            // SAFETY: valid device.
            let fence = unsafe { dev.raw.create_fence(&fence_info, None) }.vk("vkCreateFence")?;
            let cmds = [vk::CommandBufferSubmitInfo::default().command_buffer(cmd)];
            let semaphores =
                |stage: vk::PipelineStageFlags2,
                 pick: fn(&(vk::Semaphore, vk::Semaphore)) -> vk::Semaphore| {
                    let info = |s| vk::SemaphoreSubmitInfo::default().semaphore(s).stage_mask(stage);
                    sync.iter().map(|pair| info(pick(pair))).collect::<Vec<_>>()
                };
            let waits = semaphores(vk::PipelineStageFlags2::ALL_TRANSFER, |&(wait, _)| wait);
            let signals = semaphores(vk::PipelineStageFlags2::ALL_COMMANDS, |&(_, signal)| signal);
            let submit = [vk::SubmitInfo2::default()
                .command_buffer_infos(&cmds)
                .wait_semaphore_infos(&waits)
                .signal_semaphore_infos(&signals)];
            let waited = (|| {
                let queue = super::error::lock(&dev.queue, "queue")?;
                // SAFETY: the command buffer is complete; the fence is unsignalled.
                unsafe { dev.raw.queue_submit2(*queue, &submit, fence) }.vk("vkQueueSubmit2")?;
                drop(queue);
                // SAFETY: waiting on our own fence.
                unsafe { dev.raw.wait_for_fences(&[fence], true, u64::MAX) }.vk("vkWaitForFences")
            })();
            // SAFETY: the fence is signalled or was never submitted.
            unsafe { dev.raw.destroy_fence(fence, None) };
            waited?;
            Ok(value)
        })();
        // SAFETY: the command buffer is no longer executing (fence waited) or never ran.
        unsafe { dev.raw.free_command_buffers(*pool, &[cmd]) };
        drop(pool);
        dev.check_validation()?;
        result
    }

    /// Returns `GpuError::Validation` if the layer logged errors since the last check.
    pub fn check_validation(&self) -> Result<()> {
        self.dev.check_validation()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_poisoned_lock_is_the_same_error_everywhere() {
        let ctx = Context::new(&ContextOptions::default()).expect("a Vulkan device (tools/setup)");
        let dev = ctx.dev.clone();
        let poisoner = std::thread::spawn(move || {
            let _queue = dev.queue.lock();
            panic!("a panic while the queue is locked (expected by this test)");
        });
        assert!(poisoner.join().is_err());
        let err = ctx.submit(|_| Ok(())).expect_err("a submission through a poisoned queue lock");
        assert!(matches!(err, GpuError::Poisoned("queue")), "{err}");
    }

    #[test]
    fn a_leaked_allocation_fails_at_teardown() {
        let options = ContextOptions { validation: Some(true), ..ContextOptions::default() };
        let ctx = Context::new(&options).expect("a Vulkan device with the validation layer (tools/setup)");
        let requirements = vk::MemoryRequirements { size: 256, alignment: 16, memory_type_bits: !0 };
        let leaked = ctx
            .dev
            .allocator
            .lock()
            .unwrap()
            .allocate(&gpu_allocator::vulkan::AllocationCreateDesc {
                name: "leaky test allocation",
                requirements,
                location: gpu_allocator::MemoryLocation::CpuToGpu,
                linear: true,
                allocation_scheme: gpu_allocator::vulkan::AllocationScheme::GpuAllocatorManaged,
            })
            .unwrap();
        std::mem::forget(leaked);
        let teardown = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| drop(ctx)));
        let message = teardown.expect_err("a leak must fail loudly").downcast::<String>().unwrap();
        assert!(
            message.contains("leaky test allocation (256 bytes)")
                || message.contains("'leaky test allocation'"),
            "{message}"
        );
    }
}
