//! Presentation to a window: the window's surface and a swapchain on the same device the
//! algorithms run on. A frame is drawn offscreen (into a texture, like every texgeo
//! picture) and copied onto the acquired swapchain image, so what a window shows is
//! exactly what the offscreen renderer makes; the copy can be read back (screenshots).
//! Frames are synchronous — the frame's fence is waited before presenting — which keeps
//! the lifetime of everything a frame uses as simple as in `Context::submit`.

use std::sync::Arc;

use ash::vk;

use super::context::{Context, Device};
use super::error::{GpuError, Result, VkContext};
use super::memory::Buffer;
use super::pass::Recorder;
use super::texture::{TexFormat, Texture, Use};

/// A window's Vulkan surface (see [`Context::for_window`]). Keep the window open while
/// it exists.
pub struct Surface {
    dev: Arc<Device>,
    loader: ash::khr::surface::Instance,
    raw: vk::SurfaceKHR,
}

impl Surface {
    pub(crate) fn new(ctx: &Context, loader: ash::khr::surface::Instance, raw: vk::SurfaceKHR) -> Surface {
        Surface { dev: ctx.dev.clone(), loader, raw }
    }
}

impl Drop for Surface {
    fn drop(&mut self) {
        // SAFETY: swapchains hold an Arc<Surface>, so none is alive; the device (and with it
        // the instance) outlives us through `dev`.
        unsafe { self.loader.destroy_surface(self.raw, None) };
        let _ = &self.dev;
    }
}

/// What became of a frame.
#[derive(Debug, PartialEq, Eq)]
pub enum Presented {
    /// Shown; the swapchain still matches the window.
    Shown,
    /// Shown, but the window changed: recreate the swapchain before the next frame.
    Suboptimal,
    /// Not shown: the swapchain no longer matches the window; recreate it.
    OutOfDate,
}

/// The swapchain of a surface at one size.
pub struct Swapchain {
    dev: Arc<Device>,
    surface: Arc<Surface>,
    loader: ash::khr::swapchain::Device,
    raw: vk::SwapchainKHR,
    images: Vec<vk::Image>,
    format: vk::Format,
    extent: [u32; 2],
    /// Signalled when the acquired image is free; reusable once a frame's fence is waited.
    acquired: vk::Semaphore,
    /// One per image: signalled by the frame's submission, waited by its presentation.
    rendered: Vec<vk::Semaphore>,
}

impl Swapchain {
    /// A swapchain for `surface` at the surface's current size (or `size` where the
    /// platform lets the application choose). `old` is the swapchain it replaces.
    pub fn new(
        ctx: &Context,
        surface: &Arc<Surface>,
        size: [u32; 2],
        old: Option<&Swapchain>,
    ) -> Result<Swapchain> {
        let dev = ctx.dev.clone();
        let (physical, s) = (dev.physical, surface.raw);
        // SAFETY: valid physical device and surface of the same instance.
        let (caps, formats, modes) = unsafe {
            (
                surface.loader.get_physical_device_surface_capabilities(physical, s),
                surface.loader.get_physical_device_surface_formats(physical, s),
                surface.loader.get_physical_device_surface_present_modes(physical, s),
            )
        };
        let caps = caps.vk("vkGetPhysicalDeviceSurfaceCapabilitiesKHR")?;
        let formats = formats.vk("vkGetPhysicalDeviceSurfaceFormatsKHR")?;
        let modes = modes.vk("vkGetPhysicalDeviceSurfacePresentModesKHR")?;
        let extent = if caps.current_extent.width != u32::MAX {
            caps.current_extent
        } else {
            vk::Extent2D {
                width: size[0].clamp(caps.min_image_extent.width, caps.max_image_extent.width),
                height: size[1].clamp(caps.min_image_extent.height, caps.max_image_extent.height),
            }
        };
        if extent.width == 0 || extent.height == 0 {
            return Err(GpuError::Usage("the window has no area (minimized)".into()));
        }
        // Plain 8-bit UNORM, so the copied picture keeps its exact bytes.
        let format = [vk::Format::B8G8R8A8_UNORM, vk::Format::R8G8B8A8_UNORM]
            .into_iter()
            .find_map(|f| formats.iter().find(|sf| sf.format == f))
            .or(formats.first())
            .copied()
            .ok_or_else(|| GpuError::Unsupported("the surface offers no image format".into()))?;
        let usage = vk::ImageUsageFlags::TRANSFER_DST | vk::ImageUsageFlags::TRANSFER_SRC;
        if !caps.supported_usage_flags.contains(usage) {
            return Err(GpuError::Unsupported("swapchain images cannot be copied to and from".into()));
        }
        let mut count = caps.min_image_count + 1;
        if caps.max_image_count > 0 {
            count = count.min(caps.max_image_count);
        }
        let composite = [
            vk::CompositeAlphaFlagsKHR::OPAQUE,
            vk::CompositeAlphaFlagsKHR::INHERIT,
            vk::CompositeAlphaFlagsKHR::PRE_MULTIPLIED,
            vk::CompositeAlphaFlagsKHR::POST_MULTIPLIED,
        ]
        .into_iter()
        .find(|&c| caps.supported_composite_alpha.contains(c))
        .unwrap_or(vk::CompositeAlphaFlagsKHR::OPAQUE);
        // FIFO is always there and never tears; the viewer draws only when something changed.
        let mode =
            if modes.contains(&vk::PresentModeKHR::FIFO) { vk::PresentModeKHR::FIFO } else { modes[0] };
        let info = vk::SwapchainCreateInfoKHR::default()
            .surface(s)
            .min_image_count(count)
            .image_format(format.format)
            .image_color_space(format.color_space)
            .image_extent(extent)
            .image_array_layers(1)
            .image_usage(usage)
            .image_sharing_mode(vk::SharingMode::EXCLUSIVE)
            .pre_transform(caps.current_transform)
            .composite_alpha(composite)
            .present_mode(mode)
            .clipped(true)
            .old_swapchain(old.map_or(vk::SwapchainKHR::null(), |o| o.raw));
        let loader = ash::khr::swapchain::Device::new(&dev.instance.raw, &dev.raw);
        let mut chain = Swapchain {
            dev: dev.clone(),
            surface: surface.clone(),
            loader,
            raw: vk::SwapchainKHR::null(),
            images: Vec::new(),
            format: format.format,
            extent: [extent.width, extent.height],
            acquired: vk::Semaphore::null(),
            rendered: Vec::new(),
        };
        // From here on Drop destroys whatever was created.
        // SAFETY: valid device, surface and create info.
        chain.raw = unsafe { chain.loader.create_swapchain(&info, None) }.vk("vkCreateSwapchainKHR")?;
        // SAFETY: the swapchain was just created.
        chain.images =
            unsafe { chain.loader.get_swapchain_images(chain.raw) }.vk("vkGetSwapchainImagesKHR")?;
        let semaphore = || {
            // SAFETY: valid device.
            unsafe { dev.raw.create_semaphore(&vk::SemaphoreCreateInfo::default(), None) }
                .vk("vkCreateSemaphore")
        };
        chain.acquired = semaphore()?;
        for _ in 0..chain.images.len() {
            let s = semaphore()?;
            chain.rendered.push(s);
        }
        Ok(chain)
    }

    /// Width and height of the images, pixels.
    pub fn size(&self) -> [u32; 2] {
        self.extent
    }

    /// The images' format, e.g. `B8G8R8A8_UNORM`.
    pub fn format_name(&self) -> String {
        format!("{:?}", self.format)
    }

    /// Draws one frame: acquires an image, lets `draw` record the picture into an RGBA8
    /// texture (`draw` returns it), copies the picture onto the image (scaled if the sizes
    /// differ), waits for the GPU and presents. With `capture`, the image as presented is
    /// also read back and returned as RGBA8 rows, top first.
    pub fn present<'t, E: From<GpuError>>(
        &mut self,
        ctx: &Context,
        capture: bool,
        draw: impl FnOnce(&mut Recorder) -> std::result::Result<&'t Texture, E>,
    ) -> std::result::Result<(Presented, Option<Vec<u8>>), E> {
        // SAFETY: valid swapchain; the semaphore is unsignalled (previous frames waited).
        let acquired =
            unsafe { self.loader.acquire_next_image(self.raw, u64::MAX, self.acquired, vk::Fence::null()) };
        let (index, suboptimal) = match acquired {
            Ok(r) => r,
            Err(vk::Result::ERROR_OUT_OF_DATE_KHR) => return Ok((Presented::OutOfDate, None)),
            Err(e) => return Err(GpuError::Vk { call: "vkAcquireNextImageKHR", result: e }.into()),
        };
        let image = self.images[index as usize];
        let [w, h] = self.extent;
        let readback =
            if capture { Some(Buffer::readback(&self.dev, u64::from(w) * u64::from(h) * 4)?) } else { None };
        let mut failure = None;
        let sync = (self.acquired, self.rendered[index as usize]);
        let submitted = ctx.submit_synced(Some(sync), |rec| {
            let picture = match draw(rec) {
                Ok(t) => t,
                Err(e) => {
                    failure = Some(e);
                    return Err(GpuError::Usage("the frame's picture failed".into()));
                }
            };
            self.record_copy(rec, picture, image, readback.as_ref())
        });
        if let Some(e) = failure {
            // The acquired semaphore was waited by nothing: start over with a fresh one.
            self.replace_acquired()?;
            return Err(e);
        }
        if let Err(e) = submitted {
            self.replace_acquired()?;
            return Err(e.into());
        }
        let waits = [self.rendered[index as usize]];
        let chains = [self.raw];
        let indices = [index];
        let info =
            vk::PresentInfoKHR::default().wait_semaphores(&waits).swapchains(&chains).image_indices(&indices);
        let queue = super::error::lock(&self.dev.queue, "queue")?;
        // SAFETY: the image was acquired and its copy submitted, signalling `waits`.
        let shown = unsafe { self.loader.queue_present(*queue, &info) };
        drop(queue);
        ctx.check_validation()?;
        let status = match shown {
            Ok(false) if !suboptimal => Presented::Shown,
            Ok(_) => Presented::Suboptimal,
            Err(vk::Result::ERROR_OUT_OF_DATE_KHR) => Presented::OutOfDate,
            Err(e) => return Err(GpuError::Vk { call: "vkQueuePresentKHR", result: e }.into()),
        };
        let pixels = match readback {
            Some(b) => {
                let mut bytes = b.bytes()?.to_vec();
                if self.format == vk::Format::B8G8R8A8_UNORM || self.format == vk::Format::B8G8R8A8_SRGB {
                    bytes.chunks_exact_mut(4).for_each(|p| p.swap(0, 2));
                }
                Some(bytes)
            }
            None => None,
        };
        Ok((status, pixels))
    }

    fn replace_acquired(&mut self) -> Result<()> {
        // SAFETY: no submission uses the old semaphore any more (device waited).
        unsafe {
            let _ = self.dev.raw.device_wait_idle();
            self.dev.raw.destroy_semaphore(self.acquired, None);
            self.acquired = vk::Semaphore::null();
            self.acquired = self
                .dev
                .raw
                .create_semaphore(&vk::SemaphoreCreateInfo::default(), None)
                .vk("vkCreateSemaphore")?;
        }
        Ok(())
    }

    /// Copies `picture` onto the swapchain `image`, optionally into `readback`, and leaves
    /// the image ready to present.
    fn record_copy(
        &self,
        rec: &mut Recorder,
        picture: &Texture,
        image: vk::Image,
        readback: Option<&Buffer>,
    ) -> Result<()> {
        if !picture.copyable() || picture.format() != TexFormat::Rgba8 {
            return Err(GpuError::Usage(format!(
                "a frame shows a single-sample RGBA8 picture, not a {}-sample {:?}",
                picture.samples(),
                picture.format()
            )));
        }
        let cmd = rec.command_buffer();
        rec.use_texture(picture, Use::CopySrc);
        let range = vk::ImageSubresourceRange::default()
            .aspect_mask(vk::ImageAspectFlags::COLOR)
            .level_count(1)
            .layer_count(1);
        let barrier = |old, new, src_stage, src_access, dst_stage, dst_access| {
            vk::ImageMemoryBarrier2::default()
                .src_stage_mask(src_stage)
                .src_access_mask(src_access)
                .dst_stage_mask(dst_stage)
                .dst_access_mask(dst_access)
                .old_layout(old)
                .new_layout(new)
                .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
                .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
                .image(image)
                .subresource_range(range)
        };
        let dev = &self.dev.raw;
        let transfer = vk::PipelineStageFlags2::ALL_TRANSFER;
        // The acquire semaphore is waited at ALL_TRANSFER: the first barrier chains to it.
        let to_dst = [barrier(
            vk::ImageLayout::UNDEFINED,
            vk::ImageLayout::TRANSFER_DST_OPTIMAL,
            transfer,
            vk::AccessFlags2::NONE,
            transfer,
            vk::AccessFlags2::TRANSFER_WRITE,
        )];
        let [w, h] = self.extent;
        let layers =
            vk::ImageSubresourceLayers::default().aspect_mask(vk::ImageAspectFlags::COLOR).layer_count(1);
        let corner = |x: u32, y: u32| vk::Offset3D { x: x as i32, y: y as i32, z: 1 };
        let blit = [vk::ImageBlit::default()
            .src_subresource(layers)
            .src_offsets([vk::Offset3D::default(), corner(picture.width(), picture.height())])
            .dst_subresource(layers)
            .dst_offsets([vk::Offset3D::default(), corner(w, h)])];
        // SAFETY: recording; the picture is in TRANSFER_SRC layout (use_texture above), the
        // image transitions to TRANSFER_DST first.
        unsafe {
            dev.cmd_pipeline_barrier2(cmd, &vk::DependencyInfo::default().image_memory_barriers(&to_dst));
            dev.cmd_blit_image(
                cmd,
                picture.image,
                vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                image,
                vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                &blit,
                vk::Filter::NEAREST,
            );
        }
        let mut last = vk::ImageLayout::TRANSFER_DST_OPTIMAL;
        if let Some(buffer) = readback {
            let to_src = [barrier(
                last,
                vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                transfer,
                vk::AccessFlags2::TRANSFER_WRITE,
                transfer,
                vk::AccessFlags2::TRANSFER_READ,
            )];
            let region = [vk::BufferImageCopy::default()
                .image_subresource(layers)
                .image_extent(vk::Extent3D { width: w, height: h, depth: 1 })];
            let host = [vk::MemoryBarrier2::default()
                .src_stage_mask(transfer)
                .src_access_mask(vk::AccessFlags2::TRANSFER_WRITE)
                .dst_stage_mask(vk::PipelineStageFlags2::HOST)
                .dst_access_mask(vk::AccessFlags2::HOST_READ)];
            // SAFETY: the buffer holds w×h×4 bytes (made for this extent) and outlives the
            // submission (the caller waits for it).
            unsafe {
                dev.cmd_pipeline_barrier2(cmd, &vk::DependencyInfo::default().image_memory_barriers(&to_src));
                dev.cmd_copy_image_to_buffer(
                    cmd,
                    image,
                    vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                    buffer.raw,
                    &region,
                );
                dev.cmd_pipeline_barrier2(cmd, &vk::DependencyInfo::default().memory_barriers(&host));
            }
            last = vk::ImageLayout::TRANSFER_SRC_OPTIMAL;
        }
        let to_present = [barrier(
            last,
            vk::ImageLayout::PRESENT_SRC_KHR,
            transfer,
            vk::AccessFlags2::TRANSFER_WRITE,
            vk::PipelineStageFlags2::NONE,
            vk::AccessFlags2::NONE,
        )];
        // SAFETY: recording state.
        unsafe {
            dev.cmd_pipeline_barrier2(cmd, &vk::DependencyInfo::default().image_memory_barriers(&to_present))
        };
        Ok(())
    }
}

impl Drop for Swapchain {
    fn drop(&mut self) {
        // SAFETY: wait until no frame uses the semaphores or images; then destroy in
        // reverse creation order (null handles are ignored).
        unsafe {
            let _ = self.dev.raw.device_wait_idle();
            for &s in &self.rendered {
                self.dev.raw.destroy_semaphore(s, None);
            }
            self.dev.raw.destroy_semaphore(self.acquired, None);
            self.loader.destroy_swapchain(self.raw, None);
        }
        let _ = &self.surface;
    }
}
