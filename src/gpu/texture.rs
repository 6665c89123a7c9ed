//! Textures: the texture era's only data structure. Every texture can be sampled
//! (`texelFetch`), rendered into (a render target), and copied to and from the host.
//! A texture with several layers is a 2D array: a volume whose slices are layers.

use std::cell::Cell;
use std::sync::Arc;

use ash::vk;
use gpu_allocator::MemoryLocation;
use gpu_allocator::vulkan::{Allocation, AllocationCreateDesc, AllocationScheme};

use super::context::{Context, Device};
use super::error::{GpuError, Result, VkContext};

/// Texel formats used by texgeo's passes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum TexFormat {
    /// Positions, signed inclusion values, reduction sums.
    Rgba32F,
    R32F,
    /// XOR accumulation (32 slices or flags per texel), "append id" lists.
    R32Ui,
    /// XOR accumulation, one bit per texel.
    R8Ui,
    /// Pictures (aspect function, PNG output, rendered meshes).
    Rgba8,
    /// Depth buffer of a rendered picture (a depth attachment, never sampled).
    Depth32F,
}

impl TexFormat {
    pub fn vk(self) -> vk::Format {
        match self {
            TexFormat::Rgba32F => vk::Format::R32G32B32A32_SFLOAT,
            TexFormat::R32F => vk::Format::R32_SFLOAT,
            TexFormat::R32Ui => vk::Format::R32_UINT,
            TexFormat::R8Ui => vk::Format::R8_UINT,
            TexFormat::Rgba8 => vk::Format::R8G8B8A8_UNORM,
            TexFormat::Depth32F => vk::Format::D32_SFLOAT,
        }
    }

    pub fn bytes_per_texel(self) -> u64 {
        match self {
            TexFormat::Rgba32F => 16,
            TexFormat::R32F | TexFormat::R32Ui | TexFormat::Rgba8 | TexFormat::Depth32F => 4,
            TexFormat::R8Ui => 1,
        }
    }

    /// Integer formats are the ones logic ops apply to (float targets ignore them).
    pub fn is_integer(self) -> bool {
        matches!(self, TexFormat::R32Ui | TexFormat::R8Ui)
    }

    pub fn is_depth(self) -> bool {
        self == TexFormat::Depth32F
    }

    pub(crate) fn aspect(self) -> vk::ImageAspectFlags {
        if self.is_depth() { vk::ImageAspectFlags::DEPTH } else { vk::ImageAspectFlags::COLOR }
    }
}

/// How a texture is about to be used; the recorder inserts the barrier between uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Use {
    Sampled,
    Attachment,
    CopySrc,
    CopyDst,
    /// Depth attachment (tested and written by a render pass).
    Depth,
}

impl Use {
    pub fn layout(self) -> vk::ImageLayout {
        match self {
            Use::Sampled => vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL,
            Use::Attachment => vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL,
            Use::CopySrc => vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
            Use::CopyDst => vk::ImageLayout::TRANSFER_DST_OPTIMAL,
            Use::Depth => vk::ImageLayout::DEPTH_ATTACHMENT_OPTIMAL,
        }
    }

    pub fn stage(self) -> vk::PipelineStageFlags2 {
        match self {
            Use::Sampled => vk::PipelineStageFlags2::VERTEX_SHADER | vk::PipelineStageFlags2::FRAGMENT_SHADER,
            Use::Attachment => vk::PipelineStageFlags2::COLOR_ATTACHMENT_OUTPUT,
            // Blits too: a window's frame is a blit of the rendered picture.
            Use::CopySrc | Use::CopyDst => vk::PipelineStageFlags2::COPY | vk::PipelineStageFlags2::BLIT,
            Use::Depth => {
                vk::PipelineStageFlags2::EARLY_FRAGMENT_TESTS | vk::PipelineStageFlags2::LATE_FRAGMENT_TESTS
            }
        }
    }

    pub fn access(self) -> vk::AccessFlags2 {
        match self {
            Use::Sampled => vk::AccessFlags2::SHADER_SAMPLED_READ,
            // Logic ops and LOAD read the attachment as well as write it.
            Use::Attachment => {
                vk::AccessFlags2::COLOR_ATTACHMENT_READ | vk::AccessFlags2::COLOR_ATTACHMENT_WRITE
            }
            Use::CopySrc => vk::AccessFlags2::TRANSFER_READ,
            Use::CopyDst => vk::AccessFlags2::TRANSFER_WRITE,
            Use::Depth => {
                vk::AccessFlags2::DEPTH_STENCIL_ATTACHMENT_READ
                    | vk::AccessFlags2::DEPTH_STENCIL_ATTACHMENT_WRITE
            }
        }
    }

    pub fn writes(self) -> bool {
        matches!(self, Use::Attachment | Use::CopyDst | Use::Depth)
    }
}

/// A 2D texture (or 2D array when `layers > 1`), usable as sampled input, render target
/// and copy source/destination.
pub struct Texture {
    dev: Arc<Device>,
    pub(crate) image: vk::Image,
    /// View over all layers (2D, or 2D array when layered): what shaders sample.
    pub(crate) view: vk::ImageView,
    /// View over all layers as a 2D array, for `sampler2DArray` (equals `view` when layered).
    pub(crate) array_view: vk::ImageView,
    /// One 2D view per layer, for rendering into a single layer.
    pub(crate) layer_views: Vec<vk::ImageView>,
    allocation: Option<Allocation>,
    format: TexFormat,
    width: u32,
    height: u32,
    layers: u32,
    samples: u32,
    /// The use recorded last; `None` before the first use (undefined contents).
    pub(crate) last_use: Cell<Option<Use>>,
}

impl Texture {
    /// A `width`×`height` texture.
    pub fn new(ctx: &Context, format: TexFormat, width: u32, height: u32, name: &str) -> Result<Texture> {
        Texture::new_layered(ctx, format, width, height, 1, name)
    }

    /// A `width`×`height`×`layers` texture (a volume; one layer per slice).
    pub fn new_layered(
        ctx: &Context,
        format: TexFormat,
        width: u32,
        height: u32,
        layers: u32,
        name: &str,
    ) -> Result<Texture> {
        if format.is_depth() {
            return Err(GpuError::Usage(format!(
                "texture '{name}': depth buffers are made with Texture::target"
            )));
        }
        Texture::create(ctx, format, [width, height, layers], 1, name)
    }

    /// A render target for pictures: a colour (`Rgba8`, …) or depth (`Depth32F`) attachment
    /// with `samples` samples per pixel (1, 2, 4 or 8: what the device offers). A
    /// single-sample colour target can also be sampled and copied like any texture; a
    /// multisampled one is only rendered into and resolved, a depth buffer only tested.
    pub fn target(
        ctx: &Context,
        format: TexFormat,
        width: u32,
        height: u32,
        samples: u32,
        name: &str,
    ) -> Result<Texture> {
        Texture::create(ctx, format, [width, height, 1], samples, name)
    }

    fn create(ctx: &Context, format: TexFormat, size: [u32; 3], samples: u32, name: &str) -> Result<Texture> {
        let [width, height, layers] = size;
        let info = &ctx.dev.info;
        if width == 0 || height == 0 || layers == 0 {
            return Err(GpuError::Usage(format!(
                "texture '{name}' has a zero size ({width}×{height}×{layers})"
            )));
        }
        if width > info.max_image_2d || height > info.max_image_2d || layers > info.max_array_layers {
            return Err(GpuError::Unsupported(format!(
                "texture '{name}' of {width}×{height}×{layers} exceeds the device limits \
                 ({0}×{0}×{1} on {2})",
                info.max_image_2d, info.max_array_layers, info.name
            )));
        }
        let dev = ctx.dev.clone();
        // SAFETY: plain query on the context's physical device.
        let props =
            unsafe { dev.instance.raw.get_physical_device_format_properties(dev.physical, format.vk()) };
        let (needed, usage) = if format.is_depth() {
            (vk::FormatFeatureFlags::DEPTH_STENCIL_ATTACHMENT, vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT)
        } else if samples > 1 {
            (vk::FormatFeatureFlags::COLOR_ATTACHMENT, vk::ImageUsageFlags::COLOR_ATTACHMENT)
        } else {
            (
                vk::FormatFeatureFlags::SAMPLED_IMAGE
                    | vk::FormatFeatureFlags::COLOR_ATTACHMENT
                    | vk::FormatFeatureFlags::TRANSFER_SRC
                    | vk::FormatFeatureFlags::TRANSFER_DST,
                vk::ImageUsageFlags::SAMPLED
                    | vk::ImageUsageFlags::COLOR_ATTACHMENT
                    | vk::ImageUsageFlags::TRANSFER_SRC
                    | vk::ImageUsageFlags::TRANSFER_DST,
            )
        };
        if !props.optimal_tiling_features.contains(needed) {
            return Err(GpuError::Unsupported(format!(
                "device '{}' cannot sample, render and copy {format:?} textures",
                info.name
            )));
        }
        let sample_count = vk::SampleCountFlags::from_raw(samples);
        let offered = if format.is_depth() { info.depth_samples } else { info.colour_samples };
        if !samples.is_power_of_two() || offered & samples == 0 {
            return Err(GpuError::Unsupported(format!(
                "device '{}' offers no {samples}-sample {format:?} targets",
                info.name
            )));
        }
        let image_info = vk::ImageCreateInfo::default()
            .image_type(vk::ImageType::TYPE_2D)
            .format(format.vk())
            .extent(vk::Extent3D { width, height, depth: 1 })
            .mip_levels(1)
            .array_layers(layers)
            .samples(sample_count)
            .tiling(vk::ImageTiling::OPTIMAL)
            .usage(usage)
            .sharing_mode(vk::SharingMode::EXCLUSIVE)
            .initial_layout(vk::ImageLayout::UNDEFINED);
        // SAFETY: valid device and create info.
        let image = unsafe { dev.raw.create_image(&image_info, None) }.vk("vkCreateImage")?;
        let mut tex = Texture {
            dev,
            image,
            view: vk::ImageView::null(),
            array_view: vk::ImageView::null(),
            layer_views: Vec::new(),
            allocation: None,
            format,
            width,
            height,
            layers,
            samples,
            last_use: Cell::new(None),
        };
        // From here on `tex`'s Drop cleans up whatever was created if a step fails.
        // SAFETY: the image was just created.
        let requirements = unsafe { tex.dev.raw.get_image_memory_requirements(image) };
        let allocation =
            super::error::lock(&tex.dev.allocator, "allocator")?.allocate(&AllocationCreateDesc {
                name,
                requirements,
                location: MemoryLocation::GpuOnly,
                linear: false,
                allocation_scheme: AllocationScheme::GpuAllocatorManaged,
            })?;
        let allocation = tex.allocation.insert(allocation);
        // SAFETY: memory allocated for this image's requirements.
        unsafe { tex.dev.raw.bind_image_memory(image, allocation.memory(), allocation.offset()) }
            .vk("vkBindImageMemory")?;
        let view_type =
            if layers > 1 { vk::ImageViewType::TYPE_2D_ARRAY } else { vk::ImageViewType::TYPE_2D };
        tex.view = tex.make_view(view_type, 0, layers)?;
        if layers > 1 {
            tex.array_view = tex.view;
            for layer in 0..layers {
                let v = tex.make_view(vk::ImageViewType::TYPE_2D, layer, 1)?;
                tex.layer_views.push(v);
            }
        } else {
            tex.array_view = tex.make_view(vk::ImageViewType::TYPE_2D_ARRAY, 0, 1)?;
        }
        Ok(tex)
    }

    fn make_view(&self, ty: vk::ImageViewType, base_layer: u32, count: u32) -> Result<vk::ImageView> {
        let info = vk::ImageViewCreateInfo::default()
            .image(self.image)
            .view_type(ty)
            .format(self.format.vk())
            .subresource_range(
                vk::ImageSubresourceRange::default()
                    .aspect_mask(self.format.aspect())
                    .level_count(1)
                    .base_array_layer(base_layer)
                    .layer_count(count),
            );
        // SAFETY: the image is bound to memory; the range lies inside it.
        unsafe { self.dev.raw.create_image_view(&info, None) }.vk("vkCreateImageView")
    }

    pub fn format(&self) -> TexFormat {
        self.format
    }

    pub fn width(&self) -> u32 {
        self.width
    }

    pub fn height(&self) -> u32 {
        self.height
    }

    pub fn layers(&self) -> u32 {
        self.layers
    }

    /// Samples per pixel (1 unless made by [`Texture::target`] with more).
    pub fn samples(&self) -> u32 {
        self.samples
    }

    /// Whether it can be sampled, uploaded to and copied (single-sample colour textures).
    pub(crate) fn copyable(&self) -> bool {
        self.samples == 1 && !self.format.is_depth()
    }

    /// Bytes of one layer, tightly packed.
    pub fn layer_bytes(&self) -> u64 {
        self.width as u64 * self.height as u64 * self.format.bytes_per_texel()
    }

    /// The view rendering writes to for `layer`.
    pub(crate) fn target_view(&self, layer: u32) -> Result<vk::ImageView> {
        if layer >= self.layers {
            return Err(GpuError::Usage(format!("layer {layer} of a {}-layer texture", self.layers)));
        }
        Ok(if self.layers == 1 { self.view } else { self.layer_views[layer as usize] })
    }

    pub(crate) fn same_device(&self, ctx: &Context) -> bool {
        Arc::ptr_eq(&self.dev, &ctx.dev)
    }
}

impl Drop for Texture {
    fn drop(&mut self) {
        // SAFETY: submissions wait for completion, so the image is idle; null handles are ignored.
        unsafe {
            for &v in &self.layer_views {
                self.dev.raw.destroy_image_view(v, None);
            }
            if self.array_view != self.view {
                self.dev.raw.destroy_image_view(self.array_view, None);
            }
            self.dev.raw.destroy_image_view(self.view, None);
            self.dev.raw.destroy_image(self.image, None);
        }
        if let Some(a) = self.allocation.take() {
            self.dev.free(a, "a texture");
        }
    }
}
